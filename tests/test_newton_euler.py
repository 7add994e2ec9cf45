"""Newton-Euler inverse dynamics (bmc_functions.dynamics.newton_euler) against known truth.

- statics: a chain at rest under a known ground load, moments by hand;
- a pendulum: the analytic moment I_pivot * theta'' + m g d sin(theta);
- a generator: a seeded three-segment chain moving in 3D, its derivatives exact
  (product rule on elemental rotations of sinusoids), the true joint loads from the
  equations of the whole subsystem below each joint (no recursion), and the joint powers
  checked against the rate of change of the chain's mechanical energy.
"""

import warnings

import numpy as np
import pytest

from bmc_functions import (SegmentMotion, inverse_dynamics, rot_x, rot_y, rot_z,
                           segment_motion)
from bmc_functions.dynamics.newton_euler import (_BLOCK, GRAVITY_Y_UP, STANDARD_GRAVITY,
                                                 unchecked_inverse_dynamics)
from bmc_functions.dynamics import newton_euler
from bmc_functions.rigid_body.motion import matrix_rows

G = np.array([0.0, -STANDARD_GRAVITY, 0.0])


def still(R, com):
    frames = len(com)
    zero = np.zeros((frames, 3))
    return SegmentMotion(zero, zero, zero)


# --- statics ---------------------------------------------------------------------------

def test_a_chain_at_rest_under_a_known_ground_force():
    """Two segments, horizontal x and vertical y, in the x-y plane (z out of it).

    Foot: 1 kg, centre of mass 0.1 m in front of the ankle (x), ground force 500 N up at
    0.15 m in front of the ankle, free moment 2 N m about y. Shank: 3 kg, vertical, its
    centre of mass 0.2 m above the ankle, the knee 0.4 m above.
    """
    frames = 4
    R = np.repeat(np.eye(3)[None], frames, axis=0)
    ankle, knee = np.zeros((frames, 3)), np.tile([0.0, 0.4, 0.0], (frames, 1))
    com = [np.tile([0.1, 0.0, 0.0], (frames, 1)), np.tile([0.0, 0.2, 0.0], (frames, 1))]
    force = np.tile([0.0, 500.0, 0.0], (frames, 1))
    cop = np.tile([0.15, -0.05, 0.0], (frames, 1))      # below and in front of the ankle
    free = np.tile([0.0, 2.0, 0.0], (frames, 1))
    loads = inverse_dynamics([R, R], com, [ankle, knee], [1.0, 3.0],
                             [np.zeros((3, 3))] * 2, motion=[still(R, c) for c in com],
                             force=force, cop=cop, free_moment=free)
    g = STANDARD_GRAVITY
    # ankle: f = m(a - g) - F = (0, 1*g - 500, 0); moment about the ankle:
    # -(cop - ankle) x F - T - (c - ankle) x m g = -(0.15*500) z - 2 y + 0.1*g z
    assert loads.force[0] == pytest.approx(np.tile([0, g - 500, 0], (frames, 1)), abs=1e-12)
    assert loads.moment[0] == pytest.approx(np.tile([0, -2.0, -75 + 0.1 * g], (frames, 1)),
                                            abs=1e-12)
    # knee: f = (0, 4 g - 500, 0); the shank's weight acts on the vertical line of the
    # knee (no moment), the ankle's load is carried up unchanged (vertical forces on the
    # same line): moment = ankle moment
    assert loads.force[1] == pytest.approx(np.tile([0, 4 * g - 500, 0], (frames, 1)),
                                           abs=1e-12)
    assert loads.moment[1] == pytest.approx(loads.moment[0], abs=1e-12)
    assert loads.power == pytest.approx(np.zeros((2, frames)), abs=1e-12)
    # expressed in a frame turned 90 degrees about z: x' = y, y' = -x
    turned = np.repeat(rot_z(np.pi / 2)[None], frames, axis=0)
    rotated = inverse_dynamics([R, R], com, [ankle, knee], [1.0, 3.0],
                               [np.zeros((3, 3))] * 2, motion=[still(R, c) for c in com],
                               force=force, cop=cop, free_moment=free,
                               express_in=[turned, turned])
    assert rotated.moment_local[0, 0] == pytest.approx([-2.0, 0.0, -75 + 0.1 * g])


def test_rate_path_at_rest_and_swing_without_a_load():
    """Differentiating a still chain gives zero motion: only gravity (swing, no force)."""
    frames = 10
    R = np.repeat(rot_x(0.3)[None], frames, axis=0)
    com = np.tile([0.0, -0.2, 0.05], (frames, 1))
    loads = inverse_dynamics([R], [com], [np.zeros((frames, 3))], [2.0], [np.eye(3) * 0.1],
                             rate=100)
    assert loads.force[0] == pytest.approx(np.tile(-2.0 * G, (frames, 1)))
    assert loads.moment[0] == pytest.approx(np.cross(-com, 2.0 * G))


def test_a_nan_load_frame_gives_nan_joint_loads_in_that_frame_only():
    frames = 5
    R = np.repeat(np.eye(3)[None], frames, axis=0)
    force = np.tile([0.0, 100.0, 0.0], (frames, 1))
    force[2] = np.nan
    loads = inverse_dynamics([R, R], [np.zeros((frames, 3))] * 2, [np.zeros((frames, 3))] * 2,
                             [1.0, 1.0], [np.eye(3) * 0.01] * 2, rate=100, force=force,
                             cop=np.zeros((frames, 3)))
    assert np.isnan(loads.moment[:, 2]).all() and not np.isnan(loads.moment[:, [0, 1, 3]]).any()


def test_without_a_cop_the_load_acts_about_the_lab_origin():
    """force with cop=None: free_moment is the load's whole moment about the lab origin,
    q x F + T; the same joint loads as cop=q, free_moment=T (what kinetics relies on), and
    different from them when the moment about the origin is left out."""
    rng = np.random.default_rng(29)
    frames = 6
    R = [rot_z(rng.uniform(-1, 1, frames)) for _ in range(2)]
    com = [rng.normal(0, 0.3, (frames, 3)) for _ in range(2)]
    joint = [rng.normal(0, 0.3, (frames, 3)) for _ in range(2)]
    force = rng.normal(0, 300, (frames, 3))
    cop = rng.normal(0, 0.5, (frames, 3))
    free = rng.normal(0, 5, (frames, 3))
    common = dict(motion=[still(r, c) for r, c in zip(R, com)])
    args = (R, com, joint, [1.0, 3.0], [np.eye(3) * 0.05] * 2)
    at_cop = inverse_dynamics(*args, force=force, cop=cop, free_moment=free, **common)
    about_origin = inverse_dynamics(*args, force=force, free_moment=np.cross(cop, force)
                                    + free, **common)
    for name in ("force", "moment", "moment_local", "power"):
        assert getattr(about_origin, name) == pytest.approx(getattr(at_cop, name),
                                                            abs=1e-9)
    at_origin = inverse_dynamics(*args, force=force, free_moment=free, **common)
    # the moment differs by the load's moment about the origin, carried up the chain
    assert at_origin.moment[0] - at_cop.moment[0] == pytest.approx(np.cross(cop, force))


# --- a pendulum ------------------------------------------------------------------------

def pendulum(t, amplitude=0.6, frequency=1.3):
    """A rod swinging about z through the origin: theta, theta', theta''."""
    w = 2 * np.pi * frequency
    return (amplitude * np.sin(w * t), amplitude * w * np.cos(w * t),
            -amplitude * w ** 2 * np.sin(w * t))


@pytest.mark.parametrize("exact", [True, False])
def test_a_pendulum_needs_the_analytic_moment(exact):
    """M = I_pivot theta'' + m g d sin(theta), about z, the rod hanging along -y."""
    rate = 2000.0
    t = np.arange(0, 1.0, 1 / rate)
    theta, dtheta, ddtheta = pendulum(t)
    m, d, k = 2.5, 0.3, 0.12           # kg, pivot to centre of mass (m), gyration (m)
    R = rot_z(theta)
    com = np.einsum("fij,j->fi", R, [0.0, -d, 0.0])
    inertia = np.diag([m * k ** 2, 0.01, m * k ** 2])
    expected = (m * k ** 2 + m * d ** 2) * ddtheta + m * STANDARD_GRAVITY * d * np.sin(theta)
    if exact:
        omega = np.c_[0 * t, 0 * t, dtheta]
        alpha = np.c_[0 * t, 0 * t, ddtheta]
        acceleration = d * np.c_[ddtheta * np.cos(theta) - dtheta ** 2 * np.sin(theta),
                                 ddtheta * np.sin(theta) + dtheta ** 2 * np.cos(theta),
                                 0 * t]
        loads = inverse_dynamics([R], [com], [np.zeros_like(com)], [m], [inertia],
                                 motion=[SegmentMotion(omega, alpha, acceleration)])
        assert loads.moment[0] == pytest.approx(np.c_[0 * t, 0 * t, expected], abs=1e-9)
        assert loads.power[0] == pytest.approx(expected * dtheta, abs=1e-9)
    else:                   # by differences: an error of order h^2, largest at the ends
        loads = inverse_dynamics([R], [com], [np.zeros_like(com)], [m], [inertia], rate=rate)
        error = np.abs(loads.moment[0, 2:-2, 2] - expected[2:-2])
        assert error.max() < 1e-4 * np.abs(expected).max()


# --- a generator: a seeded three-segment chain in 3D -------------------------------------

SKEW = [np.array([[0, 0, 0], [0, 0, -1], [0, 1, 0]]), np.array([[0, 0, 1], [0, 0, 0], [-1, 0, 0]]),
        np.array([[0, -1, 0], [1, 0, 0], [0, 0, 0]])]


def waves(rng, times, count):
    """`count` sinusoids a sin(2 pi f t + p) and their first two derivatives: (3, count, F)."""
    a, f, p = (rng.uniform(lo, hi, (count, 1)) for lo, hi in
               ((0.1, 0.6), (0.5, 2.0), (0, 2 * np.pi)))
    w = 2 * np.pi * f
    phase = w * times + p
    return np.stack([a * np.sin(phase), a * w * np.cos(phase), -a * w ** 2 * np.sin(phase)])


def elemental(axis, angle):
    """Rotation about a coordinate axis and its first two time derivatives, each (F, 3, 3):
    E' = theta' K E and E'' = (theta'' K + theta'^2 K K) E, K the axis' skew matrix."""
    E = [rot_x, rot_y, rot_z][axis](angle[0])
    K = SKEW[axis]
    return (E, angle[1][:, None, None] * (K @ E),
            (angle[2][:, None, None] * K + angle[1][:, None, None] ** 2 * (K @ K)) @ E)


def product(A, B):
    """(value, first, second derivative) of A B from those of A and B (product rule)."""
    return (A[0] @ B[0], A[1] @ B[0] + A[0] @ B[1],
            A[2] @ B[0] + 2 * A[1] @ B[1] + A[0] @ B[2])


def generated_chain(seed, times):
    """A thigh-shank-foot chain with a known motion: each segment turned by Z-Y-X
    sinusoids, the hip moving forwards; every pose with its exact first and second time
    derivatives (the product rule on the elemental rotations: no differencing)."""
    rng = np.random.default_rng(seed)
    frames = len(times)
    hip_wave = waves(rng, times, 3)
    hip = [wave.T * [0.1, 0.05, 0.05] for wave in hip_wave]     # position, velocity, acc.
    hip[0] += [0.0, 0.9, 0.0]
    hip[0][:, 0] += 0.3 * times                                    # walking forwards
    hip[1][:, 0] += 0.3
    poses = []
    for _ in range(3):
        angles = waves(rng, times, 3)
        R = product(product(elemental(2, angles[:, 0]), elemental(1, angles[:, 1])),
                    elemental(0, angles[:, 2]))
        poses.append(R)

    def point(origin, R, local):               # origin + R local, with derivatives
        return [origin[k] + R[k] @ np.asarray(local, dtype=float) for k in range(3)]

    thigh, shank, foot = poses
    knee = point(hip, thigh, [0, -0.42, 0])
    ankle = point(knee, shank, [0, -0.40, 0])
    coms = [point(ankle, foot, rng.uniform(-0.03, 0.03, 3) + [0.06, -0.04, 0]),
            point(knee, shank, rng.uniform(-0.05, 0.05, 3) + [0, -0.17, 0]),
            point(hip, thigh, rng.uniform(-0.05, 0.05, 3) + [0, -0.18, 0])]
    chain = {"R": [], "motion": [], "times": times, "mass": [1.1, 3.4, 8.2], "inertia": [],
             "com": [c[0] for c in coms], "velocity": [c[1] for c in coms],
             "joint": [ankle[0], knee[0], hip[0]], "joint_velocity": [ankle[1], knee[1], hip[1]]}
    for R, com in zip([foot, shank, thigh], coms):
        Rt = np.swapaxes(R[0], 1, 2)
        chain["R"].append(R[0])
        chain["motion"].append(SegmentMotion(vee(R[1] @ Rt), vee(R[2] @ Rt), com[2]))
        A = rng.normal(size=(3, 3)) * 0.02
        chain["inertia"].append(A @ A.T + np.eye(3) * 0.01)     # full, positive definite
    contact = point(ankle, foot, [0.12, -0.07, 0.01])           # a point of the foot
    chain["q"], chain["q_velocity"] = contact[0], contact[1]
    chain["force"] = rng.normal([30, 700, -20], [20, 100, 20], size=(frames, 3))
    chain["free"] = rng.normal(0, 3, size=(frames, 3))
    return chain


def vee(W):
    """The vector of the skew-symmetric part of W (R' R^T = [omega]x; the skew part of
    R'' R^T is [alpha]x, since R' R'^T is symmetric)."""
    return 0.5 * np.stack([W[:, 2, 1] - W[:, 1, 2], W[:, 0, 2] - W[:, 2, 0],
                           W[:, 1, 0] - W[:, 0, 1]], axis=-1)


@pytest.fixture(scope="module")
def generated():
    return generated_chain(29, np.linspace(0.0, 1.0, 41))


def test_the_generator_differentiates_itself_right(generated):
    """Its exact derivatives agree with central differences of its own poses (1e-5)."""
    fine = generated_chain(29, np.arange(0.0, 0.02, 1e-4))
    for k in range(3):
        velocity = np.gradient(fine["com"][k], 1e-4, axis=0)
        assert np.abs(velocity - fine["velocity"][k])[1:-1].max() < 1e-5
        dR = np.gradient(fine["R"][k], 1e-4, axis=0)
        omega = vee(dR @ np.swapaxes(fine["R"][k], 1, 2))
        assert np.abs(omega - fine["motion"][k].omega)[1:-1].max() < 1e-5
        alpha = np.gradient(fine["motion"][k].omega, 1e-4, axis=0)
        assert np.abs(alpha - fine["motion"][k].alpha)[1:-1].max() < 1e-4
        a = np.gradient(fine["velocity"][k], 1e-4, axis=0)
        assert np.abs(a - fine["motion"][k].acceleration)[1:-1].max() < 1e-4


def true_loads(chain, j):
    """Force and moment at joint j from the equations of segments 0..j together."""
    force, cop, free = chain["force"], chain["q"], chain["free"]
    p = chain["joint"][j]
    f = -force.copy()
    m = -np.cross(cop - p, force) - free
    for i in range(j + 1):
        R, (omega, alpha, a) = chain["R"][i], chain["motion"][i]
        I_lab = R @ chain["inertia"][i] @ np.swapaxes(R, 1, 2)
        inertial = chain["mass"][i] * (a - G)
        f += inertial
        m += (np.einsum("fij,fj->fi", I_lab, alpha)
              + np.cross(omega, np.einsum("fij,fj->fi", I_lab, omega))
              + np.cross(chain["com"][i] - p, inertial))
    return f, m


def recovered(chain, **options):
    return inverse_dynamics(chain["R"], chain["com"], chain["joint"], chain["mass"],
                            chain["inertia"], force=chain["force"], cop=chain["q"],
                            free_moment=chain["free"], **options)


def test_a_generated_chain_recovers_the_subsystem_loads_to_1e_9(generated):
    loads = recovered(generated, motion=generated["motion"])
    for j in range(3):
        f, m = true_loads(generated, j)
        assert np.abs(loads.force[j] - f).max() < 1e-9, j
        assert np.abs(loads.moment[j] - m).max() < 1e-9, j
        local = np.einsum("fki,fk->fi", generated["R"][j], m)
        assert np.abs(loads.moment_local[j] - local).max() < 1e-9


def test_joint_powers_add_up_to_the_rate_of_change_of_energy(generated):
    """d(KE + PE)/dt = sum of joint powers (fixed base: the top one is M . omega_thigh)
    + the hip force's power + the ground load's power on the foot's material point."""
    chain = generated
    loads = recovered(chain, motion=chain["motion"])
    power_in = loads.power.sum(axis=0)
    hip_force_power = np.einsum("fi,fi->f", loads.force[2], chain["joint_velocity"][2])
    ground = (np.einsum("fi,fi->f", chain["force"], chain["q_velocity"])
              + np.einsum("fi,fi->f", chain["free"], chain["motion"][0].omega))
    d_energy = np.zeros(len(chain["times"]))
    for i in range(3):
        R, (omega, alpha, a) = chain["R"][i], chain["motion"][i]
        I_lab = R @ chain["inertia"][i] @ np.swapaxes(R, 1, 2)
        v = chain["velocity"][i]
        # d/dt (m v.v/2 + omega.I omega/2 - m g.c) = m v.a + omega.(I alpha) - m g.v
        d_energy += chain["mass"][i] * (np.einsum("fi,fi->f", v, a) - v @ G)
        d_energy += np.einsum("fi,fi->f", omega, np.einsum("fij,fj->fi", I_lab, alpha))
    assert np.abs(power_in + hip_force_power + ground - d_energy).max() < 1e-8


def test_differentiating_a_finely_sampled_generated_chain_converges():
    """The rate= path: poses sampled at 1000 Hz, errors of order h^2 (not 1e-9)."""
    chain = generated_chain(7, np.arange(0.0, 0.5, 1e-3))
    exact = recovered(chain, motion=chain["motion"])
    estimated = recovered(chain, rate=1000.0)
    inner = slice(3, -3)
    scale = np.abs(exact.moment).max()
    assert np.abs(estimated.moment[:, inner] - exact.moment[:, inner]).max() < 1e-3 * scale
    assert np.abs(estimated.force[:, inner] - exact.force[:, inner]).max() < 1e-3 * 700


def test_segment_motion_of_a_uniform_rotation_and_a_parabola():
    t = np.arange(50) / 100
    motion = segment_motion(rot_y(3 * t), np.c_[0 * t, 2 * t ** 2, 0 * t], 100)
    assert motion.omega[:, 1] == pytest.approx(np.sin(0.03) * 100, rel=1e-12)
    assert motion.alpha == pytest.approx(np.zeros((50, 3)), abs=1e-9)
    assert motion.acceleration[:, 1] == pytest.approx(np.full(50, 4.0))


# --- bad input ---------------------------------------------------------------------------

def chain_of(frames=4, count=2):
    R = np.repeat(np.eye(3)[None], frames, axis=0)
    zero = np.zeros((frames, 3))
    return [R] * count, [zero] * count, [zero] * count, [1.0] * count, [np.eye(3)] * count


@pytest.mark.parametrize("change, match", [
    (lambda a: {**a, "com": a["com"][:1]}, r"com must give one entry per segment \(2"),
    (lambda a: {**a, "joint": [np.zeros((3, 3))] * 2},
     r"joint\[0\] must have shape \(4, 3\); got \(3, 3\)"),
    (lambda a: {**a, "inertia": [np.eye(2)] * 2},
     r"inertia\[0\] must have shape \(4, 3, 3\) or \(3, 3\); got \(2, 2\)"),
    (lambda a: {**a, "R": [a["R"][0] * 2] * 2}, r"R(\[0\])? is not a rotation matrix"),
    (lambda a: {**a, "R": [a["R"][0] * 2] * 2, "rate": None, "motion": [None, None]},
     r"R\[0\] is not a rotation matrix"),
    (lambda a: {**a, "R": [a["R"][0], a["R"][0][:3]]}, r"R must be a non-empty sequence"),
    (lambda a: {**a, "rate": None}, r"give either rate .* or motion; got neither"),
    (lambda a: {**a, "motion": []}, r"give either rate .* or motion; got both"),
    (lambda a: {**a, "force": np.zeros((3, 3))}, r"force must have shape \(frames, 3\) = "
                                                 r"\(4, 3\); got \(3, 3\)"),
    (lambda a: {**a, "force": np.zeros((4, 3)), "cop": np.zeros((4, 2))},
     r"cop must have shape \(\.\.\., 3\)"),
    (lambda a: {**a, "gravity": [0, np.nan, 0]}, r"gravity"),
    (lambda a: {**a, "rate": None, "motion": [still(None, np.zeros((3, 3)))] * 2},
     r"motion\[0\] must hold three \(frames, 3\) = \(4, 3\) arrays"),
])
def test_bad_input_is_refused_naming_the_argument(change, match):
    R, com, joint, mass, inertia = chain_of()
    arguments = change({"R": R, "com": com, "joint": joint, "mass": mass,
                        "inertia": inertia, "rate": 100.0})
    with pytest.raises(ValueError, match=match):
        inverse_dynamics(**arguments)


def test_segment_motion_refuses_a_com_of_other_frames():
    with pytest.raises(ValueError, match=r"com must have shape \(frames, 3\) = \(4, 3\)"):
        segment_motion(np.repeat(np.eye(3)[None], 4, axis=0), np.zeros((5, 3)), 100)


@pytest.mark.parametrize("mass", [-1.0, 0.0, np.nan, np.inf])
def test_mass_not_positive_or_not_finite_is_refused(mass):
    R = np.repeat(np.eye(3)[None], 5, axis=0)
    with pytest.raises(ValueError, match=r"mass must hold finite masses > 0"):
        inverse_dynamics([R], [np.zeros((5, 3))], [np.zeros((5, 3))], [mass],
                         [np.eye(3) * 0.01], rate=100)


def test_asymmetric_inertia_is_refused_and_a_symmetric_one_is_not():
    R = np.repeat(np.eye(3)[None], 5, axis=0)
    args = ([R], [np.zeros((5, 3))], [np.zeros((5, 3))], [1.0])
    with pytest.raises(ValueError, match=r"inertia\[0\] must be symmetric"):
        inverse_dynamics(*args, [np.triu(np.ones((3, 3)))], rate=100)
    tensor = np.array([[0.1, 0.02, 0.0], [0.02, 0.2, 0.0], [0.0, 0.0, 0.3]])
    inverse_dynamics(*args, [tensor], rate=100)          # symmetric with products: fine


@pytest.mark.parametrize("constant_load", [False, True])
def test_the_unchecked_path_gives_the_checked_one(constant_load):
    """unchecked_inverse_dynamics (the models' own path: matrix rows, principal moments,
    the load about the lab origin) equals inverse_dynamics with the same arguments, for a
    load per frame and for one load held over every frame (the checked path stretches it)."""
    chain = generated_chain(3, np.arange(0.0, 0.3, 0.01))
    frames = len(chain["times"])
    moments = [np.array([0.011, 0.004, 0.012]) * (k + 1) for k in range(3)]
    force, free = chain["force"], chain["free"]
    if constant_load:
        force, free = force[0], free[0]
    checked = inverse_dynamics(chain["R"], chain["com"], chain["joint"], chain["mass"],
                               [np.diag(m) for m in moments], rate=100.0, force=force,
                               free_moment=free)
    fast = unchecked_inverse_dynamics(
        [matrix_rows(R) for R in chain["R"]], chain["com"], chain["joint"], chain["mass"],
        [np.repeat(m[:, None], frames, axis=1) for m in moments], 100.0, force, free,
        GRAVITY_Y_UP, np.zeros((frames, 3)))
    for name in ("force", "moment", "moment_local", "power"):
        expected, got = getattr(checked, name), getattr(fast, name)
        assert np.abs(got - expected).max() <= 1e-12 * np.abs(expected).max(), name


def test_the_recursion_in_blocks_of_frames_gives_the_whole_at_once(monkeypatch):
    """_solve runs a block of frames at a time (newton_euler._BLOCK): a chain longer than
    two blocks, with a full inertia tensor per segment (checked path) or principal moments
    (unchecked path), a per-frame load, a NaN frame at a block's edge and a moving base,
    has the numbers (bit for bit, every field) of the whole chain in one block, and,
    with its motion given, of the chain cut into pieces whose edges fall inside blocks."""
    chain = generated_chain(31, np.arange(2 * _BLOCK + 37) / 1000.0)
    frames = len(chain["times"])
    chain["force"][_BLOCK - 1] = np.nan                      # a gap at a block's edge
    base = np.random.default_rng(5).normal(size=(frames, 3))
    moments = [np.array([0.011, 0.004, 0.012]) * (k + 1) for k in range(3)]

    def checked(part=slice(None)):
        return inverse_dynamics([R[part] for R in chain["R"]], [c[part] for c in chain["com"]],
                                [p[part] for p in chain["joint"]], chain["mass"],
                                chain["inertia"], force=chain["force"][part],
                                free_moment=chain["free"][part], base_omega=base[part],
                                motion=[SegmentMotion(*(v[part] for v in m))
                                        for m in chain["motion"]])

    def unchecked():
        return unchecked_inverse_dynamics(
            [matrix_rows(R) for R in chain["R"]], chain["com"], chain["joint"], chain["mass"],
            [np.repeat(m[:, None], frames, axis=1) for m in moments], 100.0,
            chain["force"], chain["free"], GRAVITY_Y_UP, base)

    def same(first, second):
        for k, name in enumerate(first._fields):
            assert np.array_equal(first[k], second[k], equal_nan=True), name

    edges = [0, 1000, _BLOCK + 5, frames]                     # inside blocks, not at them
    pieces = [checked(slice(a, b)) for a, b in zip(edges[:-1], edges[1:])]
    blocked = checked(), unchecked()
    same(blocked[0], type(blocked[0])(*(np.concatenate(parts, axis=1)
                                         for parts in zip(*pieces))))
    assert np.isnan(blocked[0].force[:, _BLOCK - 1]).all()
    monkeypatch.setattr(newton_euler, "_BLOCK", 10 * frames)       # one block
    same(blocked[0], checked())
    same(blocked[1], unchecked())


def test_gravity_per_frame_and_a_base_of_another_length_across_blocks():
    """Gravity given per frame, (frames, 3), is gravity for every frame in every block of
    the recursion (bit for bit the constant one's numbers, as before the blocks); a
    gravity or base_omega of another trial's length is refused naming it, at a length
    that is a whole number of blocks too (it is not cut to fit)."""
    chain = generated_chain(32, np.arange(_BLOCK + 1) / 1000.0)
    frames = len(chain["times"])

    def solve(**options):
        return inverse_dynamics(chain["R"], chain["com"], chain["joint"], chain["mass"],
                                chain["inertia"], force=chain["force"],
                                free_moment=chain["free"], rate=1000.0, **options)
    constant = solve(gravity=GRAVITY_Y_UP)
    per_frame = solve(gravity=np.tile(GRAVITY_Y_UP, (frames, 1)))
    for k, name in enumerate(constant._fields):
        assert np.array_equal(constant[k], per_frame[k], equal_nan=True), name
    for name, value in (("gravity", np.tile(GRAVITY_Y_UP, (frames - 1, 1))),
                        ("base_omega", np.zeros((frames + 1, 3)))):
        with pytest.raises(ValueError, match=rf"{name} must have shape \(3,\) \(one for every "
                                             rf"frame\) or \(frames, 3\) = \({frames}, 3\)"):
            solve(**{name: value})
    whole = generated_chain(33, np.arange(_BLOCK) / 1000.0)
    with pytest.raises(ValueError, match=r"base_omega must have shape .* got shape \(4097, 3\)"):
        inverse_dynamics(whole["R"], whole["com"], whole["joint"], whole["mass"],
                         whole["inertia"], rate=1000.0, base_omega=np.ones((_BLOCK + 1, 3)))


def _median_test(com, joint, force=None, cop=None):
    """check_metres' decision as the median of the norms takes it (its exact test): the
    message's median, or None."""
    pairs = [(c, j) for c, j in zip(com, joint)]
    if force is not None:
        loaded = np.linalg.norm(np.broadcast_to(force, joint[0].shape), axis=-1) > 0
        pairs.append((np.broadcast_to(cop, joint[0].shape)[loaded], joint[0][loaded]))
    for first, second in pairs:
        distance = np.linalg.norm(first - second, axis=-1)
        distance = distance[np.isfinite(distance)]
        if distance.size and np.median(distance) > newton_euler.MAX_SEGMENT_LENGTH:
            return f"{np.median(distance):.4g}"
    return None


# a coordinate of 1e200 overflows the norm's squares in the exact test, as it always did
@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
@pytest.mark.parametrize("frames", [1, 2, 5, 6, 1001])
def test_check_metres_decides_as_the_median_of_the_distances(frames):
    """check_metres counts the distances below 2.72 m (minus 1e-9 of it) and takes the
    median only when that count cannot settle it: the same decision and message as the
    median of every frame's distance, at the median's edge (about half the frames just
    above, an even or odd count, the middle two either side), with NaN, infinite and
    huge coordinates, and for the ground load's point in its loaded frames only."""
    rng = np.random.default_rng(frames)
    limit = newton_euler.MAX_SEGMENT_LENGTH
    direction = rng.normal(size=(frames, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    cases = 0
    for above in range(max(frames // 2 - 1, 0), min(frames // 2 + 3, frames + 1)):
        for length in (limit, limit * (1 + 1e-16), np.nextafter(limit, 9), 2 * limit,
                       limit * (1 - 1e-10)):
            lengths = np.full(frames, limit * (1 - 1e-3))
            lengths[rng.permutation(frames)[:above]] = length
            joint = rng.normal(size=(frames, 3))
            com = joint + lengths[:, None] * direction
            for spoil in (None, np.nan, np.inf, 1e200):
                c = com.copy()
                if spoil is not None:
                    c[rng.integers(frames)] = spoil
                force = rng.normal(size=(frames, 3))
                force[rng.random(frames) < 0.4] = 0.0
                for kind, args in (("com", ([c], [joint])),
                                   ("cop", ([joint], [joint], force, c))):
                    expected = _median_test(*args)
                    if expected is None:
                        newton_euler.check_metres(*args, *(None,) * (4 - len(args)))
                    else:
                        with pytest.raises(ValueError, match=rf"{kind}(\[0\])? must be "
                                           rf"within .* got {expected} apart"):
                            newton_euler.check_metres(*args, *(None,) * (4 - len(args)))
                    cases += expected is not None
    assert cases > 0


def _recorded(function, *args):
    """(the error's message or None, the warnings' messages) of function(*args)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            function(*args)
            error = None
        except ValueError as exc:
            error = str(exc)
    return error, [str(w.message) for w in caught]


def _plain_check_metres(com, joint, force, cop):
    """check_metres as the median of the norms alone: its error, the same message."""
    median = _median_test(com, joint, force, cop)
    if median is not None:
        raise ValueError(f"got {median} apart")


@pytest.mark.parametrize("case", ["float32", "one vector", "huge unloaded cop",
                                  "overflowing com"])
def test_check_metres_warns_and_decides_as_the_plain_median(case):
    """Inputs outside the counting's (frames, 3) float64 arrays, and huge numbers where
    no load acts: the same decision and the same warnings as the plain median (an
    overflow warned once, a frame without load not read)."""
    rng = np.random.default_rng(3)
    joint = rng.normal(size=(50, 3))
    com, force, cop = joint + 0.2, rng.normal(size=(50, 3)), joint + 0.05
    if case == "float32":
        joint, com, force, cop = (a.astype(np.float32) * 1e3 for a in (joint, com, force, cop))
    elif case == "one vector":
        joint, com, force, cop = joint[0], com[0] * 5, force[0], cop[0]
    elif case == "huge unloaded cop":
        force[::2], cop[::2], joint[::2] = 0.0, 1.7e308, -1.7e308
    else:
        com[:3], joint[:3] = 1e308, -1e308
    expected = _recorded(_plain_check_metres, [com], [joint], force, cop)
    error, messages = _recorded(newton_euler.check_metres, [com], [joint], force, cop)
    assert (error is None) == (expected[0] is None)
    if error is not None:
        assert expected[0] in error
    assert messages == expected[1]
