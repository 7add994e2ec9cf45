"""Plug-in Gait's upper-body checks (bmc_functions/models/plug_in_gait/upper_body_checks.py):
each class of mistake injected into the shipped FullBody trial (static + Movement) or into
a hand-built body at the boundary its docstring states. Oracles: Vicon's own joint centres
stored in the trial (TRXO, RCLO, RRAO) for the chord distances, the clean trial's angles
for what must not change."""

import warnings

import numpy as np
import pytest

from bmc_functions import plug_in_gait, read_c3d
from bmc_functions.examples import example_file
from bmc_functions.models.plug_in_gait import checks, load_subject
from bmc_functions.models.plug_in_gait import upper_body_checks as upper

from helpers import SHARED_DATA, load_data_script, needs_shared, swapped

STATIC = read_c3d(example_file("plug_in_gait/Static_trial.c3d"))
DYNAMIC = read_c3d(example_file("plug_in_gait/Movement_trial.c3d"))
VSK, _ = load_subject(example_file("plug_in_gait/Test.vsk"))
RADIUS = 7.0                       # the shared subject's 14 mm markers
ARMS = ("shoulder", "elbow", "wrist")
CHECK_WORDS = ("swapped", "impossible", "doubtful", "no joint centre", "(0, 0, 0)",
               "where no body", "beside", "nearer", "below")


def arrays(df, names):
    return {name: df[name].to_numpy().astype(float) for name in names}


@pytest.fixture(scope="module")
def clean():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = plug_in_gait(STATIC, VSK)
        angles = model.angles(DYNAMIC)
        static_angles = model.angles(STATIC)
    return model, angles, static_angles, [str(w.message) for w in caught]


def columns(angles, joints, side=None):
    return [c for c in angles.columns if c[0] in joints and (side is None or c[1] == side)]


# --- no false alarm ----------------------------------------------------------------------------

def test_no_false_alarm_on_the_shipped_full_body_trials(clean):
    _, angles, static_angles, messages = clean
    assert not [m for m in messages if any(word in m for word in CHECK_WORDS)], messages
    assert not angles.isna().any().any() and not static_angles.isna().any().any()


def test_no_false_alarm_on_the_synthetic_full_body():
    gen = load_data_script("generate_plug_in_gait_data")
    trial, _, _ = gen.make_trial(400, upper_body=True)
    static, _, _ = gen.make_trial(50, static=True, upper_body=True)
    subject = {k: v for k, v in gen.SUBJECT.items() if "Static" not in k}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plug_in_gait(static, subject).angles(trial)
    assert not [w for w in caught if any(word in str(w.message) for word in CHECK_WORDS)]


def _ezc3d_points(path):
    ezc3d = pytest.importorskip("ezc3d")
    c3d = ezc3d.c3d(str(path))
    labels = c3d["parameters"]["POINT"]["LABELS"]["value"]
    xyz = c3d["data"]["points"][:3].astype(float)
    points = {label: xyz[:, k].T.copy() for k, label in enumerate(labels)
              if labels.index(label) == k}
    for values in points.values():
        values[(values == 0).all(axis=1)] = np.nan
    return points


@needs_shared("walks_with_plates/newwalk.c3d", "walks_with_plates/Walk1.c3d")
@pytest.mark.parametrize("name", ["newwalk", "Walk1"])
def test_no_false_alarm_on_the_shared_walks_with_arms(name):
    """Motion Analysis's Helen Hayes walks carry SHO and ELB (no thorax markers): the
    sides are judged along LASI - RASI, every frame passes."""
    points = _ezc3d_points(SHARED_DATA / "walks_with_plates" / f"{name}.c3d")
    leg = float(np.nanmedian(np.linalg.norm(points["LASI"] - points["LANK"], axis=1)))
    mine = {k: points[k] for k in ("LASI", "RASI", "LSHO", "RSHO", "LELB", "RELB")}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        flagged = upper.check_upper_body_markers(mine, leg, name)
    assert not flagged.any()


# --- measurements: ranges --------------------------------------------------------------------

@pytest.mark.parametrize("name, value, low, high", [
    ("LeftShoulderOffset", 5.0, "10", "200"), ("RightElbowWidth", 9.2, "25", "250"),
    ("LeftElbowWidth", 960.0, "25", "250"), ("LeftWristWidth", 610.0, "15", "180"),
    ("LeftHandThickness", 300.0, "8", "100"), ("HeadOffset", 16.0, "-1.571", "1.571")])
def test_an_upper_body_measurement_in_the_wrong_unit_is_refused(name, value, low, high):
    unit = "rad" if name == "HeadOffset" else "mm"
    with pytest.raises(ValueError, match=rf"subject: {name} = {value:g} is impossible "
                                         rf"\(expected {low} to {high} {unit}"):
        plug_in_gait(STATIC, {**VSK, name: value})


@pytest.mark.parametrize("name, bounds", list(upper.UPPER_BODY_RANGES.items()))
def test_range_boundaries(name, bounds):
    """Each bound: the value at it passes its class, just beyond it the next class."""
    low, doubt_low, doubt_high, high = bounds
    step = 1e-6
    ranges = upper.UPPER_BODY_RANGES
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for value in (doubt_low, doubt_high):
            checks.check_measurement_ranges({name: value}, ranges=ranges)
    for value in (doubt_low - step, doubt_high + step, low, high):
        with pytest.warns(RuntimeWarning, match=rf"doubtful measurement\(s\) {name} = "):
            checks.check_measurement_ranges({name: value}, ranges=ranges)
    for value in (low - step, high + step):
        with pytest.raises(ValueError, match=rf"{name} = .* is impossible"):
            checks.check_measurement_ranges({name: value}, ranges=ranges)


# --- measurements: chord offsets against the markers (Vicon's centres as oracle) ---------------

def _distance(marker, centre):
    return float(np.nanmedian(np.linalg.norm(DYNAMIC[marker].to_numpy()
                                             - DYNAMIC[centre].to_numpy(), axis=1)))


@pytest.mark.parametrize("name, marker, centre, half", [
    ("RightShoulderOffset", "RSHO", "TRXO", False), ("RightElbowWidth", "RELB", "RCLO", True),
    ("RightHandThickness", "RFIN", "RRAO", True)])
def test_a_chord_offset_against_its_markers(name, marker, centre, half):
    """The offset (measurement, or half of it, plus the radius) against the median distance
    from the marker to Vicon's proximal centre: an error at it, a doubt beyond half of it."""
    distance = _distance(marker, centre)
    points = arrays(DYNAMIC, [n for n in DYNAMIC.columns.get_level_values(0).unique()
                              if n in upper.UPPER_BODY_CHECKED])

    def value(offset):
        return (offset - RADIUS) * (2 if half else 1)

    def run(offset):
        upper.check_upper_body_measurements(points, {**VSK, "MarkerDiameter": 14.0,
                                                     name: value(offset)}, "walk")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run(upper.CHORD_DOUBT * distance - 0.5)
    with pytest.warns(RuntimeWarning, match=rf"doubtful measurement\(s\) {name} = "):
        run(upper.CHORD_DOUBT * distance + 0.5)
    with pytest.warns(RuntimeWarning, match=name):
        run(distance - 0.5)
    with pytest.raises(ValueError, match=rf"subject: {name} = .* {marker}'s median distance "
                                         rf"{distance:.0f} mm .* no joint centre exists"):
        run(distance + 0.5)


# --- markers swapped: the whole trial, then a run of frames --------------------------------

@pytest.mark.parametrize("a, b, message", [
    ("LSHO", "RSHO", "RSHO lies to the subject's left of LSHO"),
    ("LELB", "RELB", "RELB lies to the subject's left of LELB"),
    ("LFHD", "RFHD", "RFHD lies to the subject's left of LFHD"),
    ("CLAV", "STRN", "CLAV lies below STRN along the trunk"),
    ("C7", "T10", "C7 lies below T10 along the trunk"),
    ("LWRA", "RWRA", "LWRA is not beside LWRB"),
    ("LELB", "LWRA", "LWRA is not beside LWRB"),
    ("LFIN", "LWRB", "LWRB is at least as far from LELB as LFIN is")])
def test_a_pair_swapped_in_every_frame_is_an_error(clean, a, b, message):
    model = clean[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError, match=rf"in every frame of .* \(323\), {message}"):
            model.angles(swapped(DYNAMIC, a, b))


@pytest.mark.parametrize("a, b, message, hit", [
    ("LSHO", "RSHO", "RSHO lies to the subject's left of LSHO", ARMS),
    ("CLAV", "STRN", "CLAV lies below STRN", ("thorax", "neck", "spine") + ARMS),
    ("LFIN", "LWRB", "LWRB is at least as far from LELB as LFIN is", "left arm")])
def test_a_pair_swapped_in_a_run_of_frames_is_nan_there_only(clean, a, b, message, hit):
    """Only the frames of the run, and only the angles that use the blamed markers (the
    FIN test blames FIN and WRB: every angle of that arm uses WRB)."""
    model, angles, _, _ = clean
    rows = slice(100, 130)
    with pytest.warns(RuntimeWarning, match=rf"30 of 323 frames .*{message}"):
        result = model.angles(swapped(DYNAMIC, a, b, rows))
    hit = (columns(angles, ARMS, "left") if hit == "left arm" else columns(angles, hit))
    assert result[hit].iloc[rows].isna().all().all()
    rest = [c for c in angles.columns if c not in hit]
    np.testing.assert_array_equal(result[rest].to_numpy(), angles[rest].to_numpy())
    outside = np.r_[0:100, 130:len(angles)]
    np.testing.assert_array_equal(result[hit].iloc[outside].to_numpy(),
                                  angles[hit].iloc[outside].to_numpy())


# --- boundaries of the order tests, on a hand-built body ---------------------------------------

def body(**moved):
    """One frame: ASIS midpoint at (0, 0, 900), the thorax markers' centroid straight above
    it (so 'up' is z and the thorax's left is y), an arm in the y = 200 plane."""
    points = {"LASI": [0, 120, 900], "RASI": [0, -120, 900], "CLAV": [100, 0, 1400],
              "C7": [-100, 0, 1450], "STRN": [100, 0, 1250], "T10": [-100, 0, 1200],
              "LSHO": [0, 180, 1420], "RSHO": [0, -180, 1420],
              "LELB": [0, 200, 1120], "LWRA": [100, 230, 1120], "LWRB": [100, 170, 1120],
              "LFIN": [200, 200, 1120]}
    points.update(moved)
    return {k: np.array([v], dtype=float) for k, v in points.items()}


def flags(points):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return bool(upper.check_upper_body_markers(points, 880.0)[0])
        except ValueError:       # one frame flagged is every frame: an error
            return True


def test_boundary_strn_below_clav():
    assert not flags(body(STRN=[100, 0, 1399]))
    assert flags(body(STRN=[100, 0, 1401]))


def test_boundary_shoulders_sides():
    assert not flags(body(LSHO=[0, -179, 1420]))
    assert flags(body(LSHO=[0, -181, 1420]))


def test_boundary_wrist_bar_against_the_forearm():
    """Bar 60 mm (WRA, WRB at y = 200 +- 30): flagged once the bar's markers are nearer
    ELB than 60 / 0.6 = 100 mm, at x = sqrt(100^2 - 30^2) = 95.39 mm."""
    x = np.sqrt(100.0 ** 2 - 30.0 ** 2)
    ok = body(LWRA=[x + 0.1, 230, 1120], LWRB=[x + 0.1, 170, 1120])
    bad = body(LWRA=[x - 0.1, 230, 1120], LWRB=[x - 0.1, 170, 1120])
    assert not flags(ok) and flags(bad)


def test_boundary_finger_beyond_the_wrist_bar():
    reach = float(np.linalg.norm([100, 30]))           # ELB to either bar marker
    assert not flags(body(LFIN=[reach + 0.1, 200, 1120]))
    assert flags(body(LFIN=[reach - 0.1, 200, 1120]))


def test_boundary_far_from_the_pelvis():
    limit = upper.FAR_FROM_PELVIS * 880.0
    assert not flags(body(LFIN=[limit - 1, 0, 900]))
    points = body(LFIN=[limit + 1, 0, 900])
    with pytest.raises(ValueError, match=r"in every frame of the trial \(1\), LFIN is more "
                                         r"than 1760 mm from the pelvis"):
        upper.check_upper_body_markers(points, 880.0)


# --- zeros and far markers: NaN in what depends on them ------------------------------------

def test_a_far_finger_marker_is_nan_in_the_right_wrist_only(clean):
    model, angles, _, _ = clean
    df = DYNAMIC.copy()
    df.loc[df.index[50:60], "RFIN"] = df.loc[df.index[50:60], "RFIN"].to_numpy() + 5000.0
    with pytest.warns(RuntimeWarning, match=r"10 of 323 frames .*RFIN in 10"):
        result = model.angles(df)
    wrist = columns(angles, ("wrist",), "right")
    assert result[wrist].iloc[50:60].isna().all().all()
    rest = [c for c in angles.columns if c not in wrist]
    np.testing.assert_array_equal(result[rest].to_numpy(), angles[rest].to_numpy())


@pytest.mark.parametrize("label, joints, side", [
    ("LWRB", ARMS, "left"), ("RFHD", ("head", "neck"), None),
    ("CLAV", ("thorax", "neck", "spine") + ARMS, None)])
def test_a_zeroed_marker_is_a_gap_in_what_uses_it(clean, label, joints, side):
    model, angles, _, _ = clean
    df = DYNAMIC.copy()
    df.loc[df.index[200:220], label] = 0.0
    with pytest.warns(RuntimeWarning, match=rf"20 of 323 frames have undefined segments "
                                            rf"\({label} missing in 20\)"), \
            pytest.warns(RuntimeWarning, match=rf"\(0, 0, 0\).*{label} in 20 frames"):
        result = model.angles(df)
    hit = columns(angles, joints, side)
    assert result[hit].iloc[200:220].isna().all().all()
    rest = [c for c in angles.columns if c not in hit]
    np.testing.assert_array_equal(result[rest].to_numpy(), angles[rest].to_numpy())


def test_a_marker_zeroed_in_every_frame_leaves_its_segments_out(clean):
    model, angles, _, _ = clean
    df = DYNAMIC.copy()
    df.loc[:, "LSHO"] = 0.0
    with pytest.warns(RuntimeWarning, match=r"\(0, 0, 0\).*LSHO in 323 frames"):
        result = model.angles(df)
    assert not [c for c in result.columns if c[0] in ARMS and c[1] == "left"]
    assert len(result.columns) == len(angles.columns) - 7       # shoulder 3, elbow 1, wrist 3
    np.testing.assert_array_equal(result.to_numpy(), angles[result.columns].to_numpy())


# --- a marker that jumps for a few frames ----------------------------------------------------

def test_boundary_a_jump_of_the_finger_marker():
    """21 equal frames; in frame 10 FIN moves along the arm so that its distance to both
    bar markers (equal, 104.4 mm) grows by the tolerance (0.05 leg lengths = 44 mm) +- 0.5
    mm: flagged beyond it, not before."""
    tolerance = upper.UPPER_PAIRS[("LWRA", "LFIN")] * 880.0
    assert tolerance == 44.0
    d = float(np.hypot(100.0, 30.0))

    def run(change):
        points = {k: np.repeat(v, 21, axis=0) for k, v in body().items()}
        shift = np.sqrt((d + change) ** 2 - 30.0 ** 2) - 100.0
        points["LFIN"][10, 0] += shift
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            flagged = upper.check_upper_body_markers(points, 880.0)
        return flagged, np.isnan(points["LFIN"][:, 0]), [str(w.message) for w in caught]
    flagged, nan, messages = run(tolerance - 0.5)
    assert not flagged.any() and not nan.any() and not messages
    flagged, nan, messages = run(tolerance + 0.5)
    assert flagged.tolist() == [i == 10 for i in range(21)] and nan[10] and nan.sum() == 1
    assert len(messages) == 1 and "1 of 21 frames" in messages[0] and "LFIN in 1" in messages[0]


def test_a_ghost_head_marker_is_nan_in_the_head_and_neck_only(clean):
    model, angles, _, _ = clean
    df = DYNAMIC.copy()
    rows = df.index[40:45]
    lfhd = df.loc[rows, "LFHD"].to_numpy()
    others = sum(df.loc[rows, m].to_numpy() for m in ("RFHD", "LBHD", "RBHD")) / 3.0
    outward = (lfhd - others) / np.linalg.norm(lfhd - others, axis=1, keepdims=True)
    df.loc[rows, "LFHD"] = lfhd + 80.0 * outward      # 80 mm away from the head
    with pytest.warns(RuntimeWarning, match=r"5 of 323 frames .*jumped.*LFHD in 5"):
        result = model.angles(df)
    hit = columns(angles, ("head", "neck"))
    assert result[hit].iloc[40:45].isna().all().all()
    rest = [c for c in angles.columns if c not in hit]
    np.testing.assert_array_equal(result[rest].to_numpy(), angles[rest].to_numpy())
