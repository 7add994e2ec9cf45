"""The force-plate reader (bmc_functions/files/force_plates.py).

Oracles: hand derivations of the centre of pressure and free moment on synthetic C3D files
written with ezc3d (types 2, 3 and 4, known loads and origins); ezc3d's own force-plate
module (``extract_forceplat_data=True``) on every shared file (not on the synthetic files:
ezc3d's Python writer stores FORCE_PLATFORM:USED, TYPE and CHANNEL as floats, which its
force-plate module refuses); Vicon Nexus's stored
ground reaction force of the shared stair descent (resampling to the marker rate).
"""

import warnings

import numpy as np
import pandas as pd
import pytest

from bmc_functions import (assign_plates, force_plate_events, read_c3d, read_force_plates,
                           resample_force_plates)
from bmc_functions.files import force_plates as fp
from helpers import SHARED_DATA, needs_shared

ezc3d = pytest.importorskip("ezc3d")

PIG = SHARED_DATA / "plug_in_gait" / "Movement_trial.c3d"
WALKS = SHARED_DATA / "walks_with_plates"
SHARED_PLATES = ["walks_with_plates/Walk1.c3d", "walks_with_plates/newwalk.c3d",
                 "walks_with_plates/gait_with_emg.c3d",
                 "walks_with_plates/codamotion_gaitwands_19970212.c3d",
                 "force_plates/codamotion_gaitwands_20150204.c3d",
                 "plug_in_gait/Movement_trial.c3d", "plug_in_gait/Static_trial.c3d"]

RATE, POINT_RATE, N = 1000.0, 100.0, 1000       # 1 s of analog samples, 100 marker frames


def corners_at(x0, y0, length=600.0, width=400.0):
    """Corners (4, 3) of a plate with its x along the lab's y, its y along the lab's x and
    its z down (the order of the shared Vicon file's corners)."""
    return np.array([[x0 + width, y0 + length, 0.0], [x0 + width, y0, 0.0], [x0, y0, 0.0],
                     [x0, y0 + length, 0.0]])


def stance(start=0.2, stop=0.8, peak=600.0):
    """A foot's vertical load (N) over the N samples: a half sine from start to stop (s)."""
    t = np.arange(N) / RATE
    inside = (t > start) & (t < stop)
    return np.where(inside, peak * np.sin(np.pi * (t - start) / (stop - start)), 0.0)


def type2_channels(load, cop, torque, origin):
    """Channels (N, 6) of a type 2 plate (ground on body, plate frame z down) for a load
    `load` (N, upward) at the plate-frame point `cop` (N, 2) from the surface's centre,
    a small shear, and the free moment `torque` (N·mm), about the sensors' origin O with
    `origin` the vector from O to the surface's centre."""
    force = np.column_stack([0.1 * load, -0.05 * load, -load])
    p = np.column_stack([cop, np.zeros(N)])
    moment_c = np.cross(p, force) + np.column_stack([np.zeros((N, 2)), torque])
    moment_o = moment_c - np.cross(force, np.asarray(origin, float))
    return np.column_stack([force, moment_o])


def write_plates(path, plates, *, units="mm", markers=None, zero=(0, 0),
                 moment_unit="Nmm", scale=1.0):
    """A C3D file (ezc3d) with `plates` (dicts of type, channels (N, k), corners (4, 3,
    mm), origin (3, as stored, mm), cal (6, 6) for type 4) and `markers` (label ->
    (frames, 3) mm), every length written in `units` (`scale` per mm)."""
    c3d = ezc3d.c3d()
    labels = list(markers or {"RHEE": np.zeros((int(N / RATE * POINT_RATE), 3))})
    xyz = np.stack([np.asarray((markers or {})[label] if markers else
                               np.zeros((int(N / RATE * POINT_RATE), 3))) * scale
                    for label in labels], axis=1)
    c3d["parameters"]["POINT"]["RATE"]["value"] = [POINT_RATE]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(labels)
    c3d["parameters"]["POINT"]["UNITS"]["value"] = [units]
    points = np.ones((4, len(labels), xyz.shape[0]))
    points[:3] = xyz.transpose(2, 1, 0)
    c3d["data"]["points"] = points
    channels = [p["channels"] * np.r_[np.ones(3), np.full(p["channels"].shape[1] - 3,
                                                          scale if p["type"] == 2 else 1)]
                for p in plates]
    analogs = np.concatenate(channels, axis=1).T
    c3d["parameters"]["ANALOG"]["RATE"]["value"] = [RATE]
    c3d["parameters"]["ANALOG"]["LABELS"]["value"] = tuple(f"A{i}" for i in range(len(analogs)))
    c3d["parameters"]["ANALOG"]["UNITS"]["value"] = tuple(
        unit for p in plates for unit in (["N"] * 3 + [moment_unit] * 3 if p["type"] != 3
                                          else ["N"] * 8))
    c3d["data"]["analogs"] = analogs[None]
    width = max(p["channels"].shape[1] for p in plates)
    channel = np.zeros((width, len(plates)), dtype=int)
    first = 1
    for k, p in enumerate(plates):
        channel[:p["channels"].shape[1], k] = np.arange(first, first + p["channels"].shape[1])
        first += p["channels"].shape[1]
    c3d.add_parameter("FORCE_PLATFORM", "USED", [len(plates)])
    c3d.add_parameter("FORCE_PLATFORM", "TYPE", [p["type"] for p in plates])
    c3d.add_parameter("FORCE_PLATFORM", "ZERO", list(zero))
    c3d.add_parameter("FORCE_PLATFORM", "CHANNEL", channel.tolist())
    c3d.add_parameter("FORCE_PLATFORM", "CORNERS",
                      (np.stack([p["corners"].T for p in plates], axis=2) * scale).tolist())
    c3d.add_parameter("FORCE_PLATFORM", "ORIGIN",
                      (np.stack([np.asarray(p["origin"], float) for p in plates], axis=1)
                       * scale).tolist())
    if any(p["type"] == 4 for p in plates):
        cal = np.stack([p.get("cal", np.eye(6)) for p in plates], axis=2)
        c3d.add_parameter("FORCE_PLATFORM", "CAL_MATRIX", cal.tolist())
    c3d.write(str(path))
    return path


def stored_channels(path, plate_rows):
    """The channels as the file stores them (float32), read back with ezc3d."""
    return ezc3d.c3d(str(path))["data"]["analogs"][0][plate_rows].T.astype(float)


def hand_cop_and_torque(force, moment_o, r):
    """The textbook formulas, component by component (plate frame)."""
    fx, fy, fz = force.T
    mx, my, mz = moment_o.T
    dx, dy, dz = r
    fz = np.where(fz == 0, np.nan, fz)
    px = (-my - fz * dx + fx * dz) / fz
    py = (mx + fy * dz - fz * dy) / fz
    tz = (mz + fx * dy - fy * dx) - px * fy + py * fx
    return px, py, tz


# --- synthetic plates: hand derivations -----------------------------------------------

@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    """A type 2 plate (origin stored with z negative) and a type 4 plate (calibration
    matrix, origin stored Vicon's way, z positive) under known loads."""
    rng = np.random.default_rng(29)
    load = stance()
    cop_a = np.column_stack([np.linspace(-120, 150, N), np.linspace(-30, 20, N)])
    cop_b = np.column_stack([np.linspace(100, -90, N), np.full(N, 35.0)])
    torque = 3000.0 * np.sin(np.linspace(0, 3, N)) * (load > 0)
    r_a, r_b = np.array([1.5, -2.0, -40.0]), np.array([-0.7, 1.1, -38.0])
    cal = np.eye(6) + 0.02 * rng.standard_normal((6, 6))
    plates = [dict(type=2, channels=type2_channels(load, cop_a, torque, r_a),
                   corners=corners_at(0.0, 0.0), origin=r_a),
              dict(type=4, channels=type2_channels(load, cop_b, -torque, r_b)
                   @ np.linalg.inv(cal).T, corners=corners_at(500.0, 0.0), origin=-r_b,
                   cal=cal)]
    path = write_plates(tmp_path_factory.mktemp("plates") / "two.c3d", plates)
    truth = {"cop": [cop_a, cop_b], "torque": [torque, -torque], "r": [r_a, r_b],
             "cal": cal, "load": load, "corners": [p["corners"] for p in plates]}
    return path, truth


def test_type_2_and_4_plates_match_the_hand_derivation_to_1e9(synthetic):
    path, truth = synthetic
    plates = read_force_plates(path, zero="none")
    for k, rows in ((1, slice(0, 6)), (2, slice(6, 12))):
        raw = stored_channels(path, rows)
        if k == 2:                                          # type 4: [F; M] = C v, C as
            cal = np.asarray(ezc3d.c3d(str(path))["parameters"]["FORCE_PLATFORM"]  # stored
                             ["CAL_MATRIX"]["value"], dtype=float)[:, :, 1]
            raw = raw @ cal.T
        force, moment = raw[:, :3], raw[:, 3:]
        stored = np.asarray(ezc3d.c3d(str(path))["parameters"]["FORCE_PLATFORM"]["ORIGIN"]
                            ["value"], dtype=float)[:, k - 1]
        r = -stored if stored[2] > 0 else stored         # Vicon's sign: the opposite vector
        np.testing.assert_allclose(r, truth["r"][k - 1], atol=1e-5)
        px, py, tz = hand_cop_and_torque(force, moment, r)
        loaded = -force[:, 2] >= fp.COP_THRESHOLD
        table = plates[k]
        centre = truth["corners"][k - 1].mean(axis=0)
        # plate x = lab y, plate y = lab x, plate z = -lab z
        expected = {"force_x": force[:, 1], "force_y": force[:, 0], "force_z": -force[:, 2],
                    "cop_x": centre[0] + py, "cop_y": centre[1] + px,
                    "free_moment_z": -tz}
        for column, values in expected.items():
            got = table[column].to_numpy()
            where = loaded if column.startswith(("cop", "free")) else slice(None)
            np.testing.assert_allclose(got[where], values[where], rtol=0, atol=1e-9,
                                       err_msg=f"plate {k} {column}")
        assert table.loc[loaded, ["cop_z", "free_moment_x", "free_moment_y"]].abs().max().max() \
            < 1e-9
        assert table.loc[~loaded, ["cop_x", "free_moment_z"]].isna().all().all()
        # the moment about the surface's centre (lab: plate x, y, z -> lab y, x, -z)
        moment_c = moment + np.cross(force, r)
        np.testing.assert_allclose(table[["moment_x", "moment_y", "moment_z"]].to_numpy(),
                                   moment_c[:, [1, 0, 2]] * [1, 1, -1], atol=1e-9)
        # and the truth the channels were made from (float32 storage: 1e-3 mm)
        np.testing.assert_allclose(table["cop_y"].to_numpy()[loaded] - centre[1],
                                   truth["cop"][k - 1][loaded, 0], atol=2e-3)
        np.testing.assert_allclose(-table["free_moment_z"].to_numpy()[loaded],
                                   truth["torque"][k - 1][loaded], atol=0.05)


def test_a_kistler_type_3_plate_follows_kistlers_formulae(tmp_path):
    rng = np.random.default_rng(3)
    load = stance()
    eight = np.column_stack([0.05 * load, 0.04 * load, -0.02 * load, 0.01 * load]
                            + [-load * w for w in (0.2, 0.3, 0.25, 0.25)])
    eight += rng.normal(0.0, 0.5, eight.shape)
    a, b, az0 = 120.0, 200.0, -58.0
    path = write_plates(tmp_path / "kistler.c3d",
                        [dict(type=3, channels=eight, corners=corners_at(0.0, 0.0),
                              origin=[a, b, az0])])
    f = stored_channels(path, slice(0, 8)).T
    fx, fy, fz = f[0] + f[1], f[2] + f[3], f[4] + f[5] + f[6] + f[7]
    mx = b * (f[4] + f[5] - f[6] - f[7])
    my = a * (-f[4] + f[5] + f[6] - f[7])
    mz = b * (-f[0] + f[1]) + a * (f[2] - f[3])
    ax, ay = (fx * az0 - my) / fz, (fy * az0 + mx) / fz        # Kistler's manual
    tz = mz - fy * ax + fx * ay
    table = read_force_plates(path, zero="none")[1]
    loaded = -fz >= fp.COP_THRESHOLD
    np.testing.assert_allclose(table["cop_x"].to_numpy()[loaded], 200.0 + ay[loaded], atol=1e-9)
    np.testing.assert_allclose(table["cop_y"].to_numpy()[loaded], 300.0 + ax[loaded], atol=1e-9)
    np.testing.assert_allclose(table["free_moment_z"].to_numpy()[loaded], -tz[loaded],
                               atol=1e-9)


def test_a_file_in_metres_gives_the_same_loads_in_millimetres(synthetic, tmp_path):
    path, truth = synthetic
    load = truth["load"]
    plate = dict(type=2, channels=type2_channels(load, np.zeros((N, 2)) + [50.0, -20.0],
                                                 np.zeros(N), truth["r"][0]),
                 corners=corners_at(0.0, 0.0), origin=truth["r"][0])
    in_mm = read_force_plates(write_plates(tmp_path / "mm.c3d", [plate]))
    in_m = read_force_plates(write_plates(tmp_path / "m.c3d", [plate], units="m",
                                          moment_unit="Nm", scale=1e-3))
    assert in_m.attrs["file_units"] == "m" and in_m.attrs["units"]["position"] == "mm"
    np.testing.assert_allclose(in_m.to_numpy(), in_mm.to_numpy(), rtol=1e-5, atol=1e-3)
    np.testing.assert_allclose(in_m.attrs["plates"][0]["corners"], plate["corners"],
                               rtol=1e-6)


def test_an_unknown_plate_type_is_named_with_the_supported_ones(synthetic, tmp_path):
    _, truth = synthetic
    plate = dict(type=7, channels=np.zeros((N, 6)), corners=corners_at(0.0, 0.0),
                 origin=[0.0, 0.0, -40.0])
    path = write_plates(tmp_path / "type7.c3d", [plate])
    message = r"force plate 1: FORCE_PLATFORM:TYPE is 7; the supported plate types are 1, 2, 3, 4"
    with pytest.raises(ValueError, match=message):
        read_force_plates(path)
    with pytest.raises(ValueError, match=message):       # not ezc3d's "not supported yet"
        force_plate_events(path, {"RHEEL": "RHEE"})


def test_corners_all_zero_are_called_missing_not_no_contact(tmp_path):
    plate = dict(type=2, channels=type2_channels(stance(), np.zeros((N, 2)), np.zeros(N),
                                                 [0, 0, -40.0]),
                 corners=np.zeros((4, 3)), origin=[0.0, 0.0, -40.0])
    path = write_plates(tmp_path / "no_corners.c3d", [plate])
    with pytest.raises(ValueError, match=r"corners \(FORCE_PLATFORM:CORNERS\) are all zero.*"
                                         r"missing corners"):
        read_force_plates(path)
    with pytest.raises(ValueError, match="missing corners"):
        force_plate_events(path, {"RHEEL": "RHEE"})


def test_the_centre_of_pressure_is_nan_below_the_threshold(synthetic):
    path, truth = synthetic
    plates = read_force_plates(path, cop_threshold=300.0)
    load = plates[1]["force_z"].to_numpy()
    assert np.isnan(plates[1]["cop_x"].to_numpy()[load < 300.0]).all()
    assert np.isfinite(plates[1]["cop_x"].to_numpy()[load >= 300.0]).all()
    assert np.isfinite(plates[1]["force_z"]).all()


def test_zeroing_an_unloaded_plate(tmp_path):
    channels = type2_channels(stance(), np.zeros((N, 2)), np.zeros(N), [0, 0, -40.0])
    offset = np.array([3.0, -2.0, -45.0, 500.0, -800.0, 100.0])
    plate = dict(type=2, channels=channels + offset, corners=corners_at(0.0, 0.0),
                 origin=[0.0, 0.0, -40.0])
    path = write_plates(tmp_path / "offset.c3d", [plate], zero=(1, 10))
    with pytest.warns(RuntimeWarning, match=r"plate 1 reads 45 N unloaded \(not zeroed: "
                                            r"zero='none'; zero='unloaded' removes it\)"):
        read_force_plates(path, zero="none")
    for zero in ("unloaded", "file"):                    # frames 1-10: unloaded too
        plates = read_force_plates(path, zero=zero)
        np.testing.assert_allclose(plates.attrs["plates"][0]["zero"], offset, atol=1e-3)
        np.testing.assert_allclose(plates[1]["force_z"].to_numpy(), stance(), atol=1e-3)


def test_resampled_centre_of_pressure_comes_from_the_averaged_force_and_moment(synthetic):
    path, _ = synthetic
    plates = read_force_plates(path)
    frames = resample_force_plates(plates)
    for k in (1, 2):
        cop, free = fp.cop_from_moment(
            plates[k][["force_x", "force_y", "force_z"]].to_numpy(),
            plates[k][["moment_x", "moment_y", "moment_z"]].to_numpy(),
            np.mean(plates.attrs["plates"][k - 1]["corners"], axis=0),
            plates.attrs["plates"][k - 1]["normal"])
        # at the analog rate, the same as plate_loads' (another frame, same point)
        np.testing.assert_allclose(cop, plates[k][["cop_x", "cop_y", "cop_z"]].to_numpy(),
                                   atol=1e-9)
        np.testing.assert_allclose(free, plates[k][["free_moment_x", "free_moment_y",
                                                    "free_moment_z"]].to_numpy(), atol=1e-7)
        loaded = frames[k]["force_z"].to_numpy() >= fp.COP_THRESHOLD
        assert np.isfinite(frames[k]["cop_x"].to_numpy()[loaded]).all()
        assert np.isnan(frames[k]["cop_x"].to_numpy()[~loaded]).all()


def test_resampling_averages_the_samples_centred_on_each_frame():
    plates = pd.DataFrame(np.arange(40.0)[:, None],
                          columns=pd.MultiIndex.from_tuples([(1, "force_z")]),
                          index=pd.Index(np.arange(40) / 1000.0, name="time"))
    plates.attrs = {"rate": 1000.0, "point_rate": 250.0}           # 4 samples a frame
    frames = resample_force_plates(plates)
    # frame 1 at sample 4: samples 2..6 weighted 1/2, 1, 1, 1, 1/2 -> 4
    np.testing.assert_allclose(frames[(1, "force_z")].to_numpy()[1:-1], np.arange(4, 36, 4.0))
    assert frames.attrs["rate"] == 250.0 and len(frames) == 10
    plates.attrs["point_rate"] = 300.0
    with pytest.raises(ValueError, match="not a whole multiple of the marker rate"):
        resample_force_plates(plates)


# --- the shared files -----------------------------------------------------------------

@needs_shared()
@pytest.mark.parametrize("name", SHARED_PLATES)
def test_every_shared_file_agrees_with_ezc3d(name):
    path = SHARED_DATA / name
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        mine = read_force_plates(path, zero="none")
    theirs = ezc3d.c3d(str(path), extract_forceplat_data=True)["data"]["platform"]
    to_mm = 1000.0 if mine.attrs["file_units"] == "m" else 1.0
    for k, plate in enumerate(theirs, start=1):
        loaded = mine[k]["force_z"].to_numpy() >= fp.COP_THRESHOLD
        np.testing.assert_allclose(mine[k][["force_x", "force_y", "force_z"]].to_numpy(),
                                   plate["force"].T, atol=1e-9)
        np.testing.assert_allclose(mine[k][["cop_x", "cop_y", "cop_z"]].to_numpy()[loaded],
                                   plate["center_of_pressure"].T[loaded] * to_mm, atol=1e-9)
        np.testing.assert_allclose(
            mine[k][["free_moment_x", "free_moment_y", "free_moment_z"]].to_numpy()[loaded],
            plate["Tz"].T[loaded] * to_mm, atol=1e-8)
        np.testing.assert_allclose(               # about the surface's centre, any load
            mine[k][["moment_x", "moment_y", "moment_z"]].to_numpy(),
            plate["moment"].T * to_mm, atol=1e-8)


@needs_shared("plug_in_gait/Movement_trial.c3d")
def test_vicon_averages_the_nine_samples_centred_on_each_frame():
    c3d = ezc3d.c3d(str(PIG))
    labels = c3d["parameters"]["POINT"]["LABELS"]["value"]
    plates = read_force_plates(PIG)
    analog = plates[[(k, q) for k in (1, 4) for q in ("force_x", "force_y", "force_z")]]
    frames = resample_force_plates(plates)
    n, r = len(frames), 9
    for side, plate in (("L", 1), ("R", 4)):        # the plates Vicon assigned
        vicon = c3d["data"]["points"][:3, labels.index(f"{side}GroundReactionForce")].T
        stance_frames = np.linalg.norm(vicon, axis=1) > 0
        ours = frames[plate][["force_x", "force_y", "force_z"]].to_numpy() / 85.0
        assert np.abs(ours - vicon)[stance_frames].max() < 1e-5          # N/kg (float32)
        moment = c3d["data"]["points"][:3, labels.index(f"{side}GroundReactionMoment")].T
        ours = frames[plate][["moment_x", "moment_y", "moment_z"]].to_numpy() / 85.0
        assert np.abs(ours - moment)[stance_frames].max() < 1e-3         # N mm/kg
        samples = analog[plate].to_numpy()[:n * r].reshape(n, r, 3) / 85.0
        rms = {name: np.sqrt(np.mean((guess - vicon)[stance_frames, 2] ** 2))
               for name, guess in (("frame's nine", samples.mean(axis=1)),
                                   ("sample at frame", samples[:, 0]))}
        assert rms["frame's nine"] > 0.15 and rms["sample at frame"] > 0.02, rms


@needs_shared("walks_with_plates/sample14.c3d")
def test_analog_blocks_out_of_order_are_refused():
    with pytest.raises(ValueError, match=r"sample14.c3d: force plate 1: its vertical load "
                                         r"jumps by 262 N \(96 % of its peak load\).*damaged"):
        read_force_plates(WALKS / "sample14.c3d")
    with pytest.raises(ValueError, match="blocks of samples written out of order"):
        force_plate_events(WALKS / "sample14.c3d", {"RHEEL": "RHEE", "RTOE": "RTOE"})


def test_a_spike_is_no_damage_but_a_step_of_the_whole_load_is():
    load = stance()
    spiky = load.copy()
    spiky[500] += 500.0                                  # one sample: electrical spike
    fp.check_load_continuity(spiky, RATE, "plate 1")
    fp.check_load_continuity(load, RATE, "plate 1")
    with pytest.raises(ValueError, match="plate 1: its vertical load jumps"):
        fp.check_load_continuity(np.r_[np.zeros(300), np.full(300, 600.0), np.zeros(400)],
                                 RATE, "plate 1")


# --- which foot stands on which plate -------------------------------------------------

def feet_file(tmp_path, right, left, loads, name="feet.c3d"):
    """Two adjacent 400 x 600 mm plates (x 0-400 and 400-800) loaded by `loads` (two
    vertical load curves) and feet markers standing still at `right` and `left` (x, y)."""
    frames = int(N / RATE * POINT_RATE)
    markers = {}
    for label, (x, y) in (("RHEE", right), ("RTOE", right), ("LHEE", left), ("LTOE", left)):
        markers[label] = np.tile([x, y + (60.0 if "TOE" in label else -60.0), 40.0],
                                 (frames, 1))
    plates = [dict(type=2, channels=type2_channels(load, np.zeros((N, 2)), np.zeros(N),
                                                   [0, 0, -40.0]),
                   corners=corners_at(x0, 0.0), origin=[0, 0, -40.0])
              for x0, load in zip((0.0, 400.0), loads)]
    return write_plates(tmp_path / name, plates, markers=markers)


ROLES = {"RHEEL": "RHEE", "RTOE": "RTOE", "LHEEL": "LHEE", "LTOE": "LTOE"}
FEET = {"right": ["RHEE", "RTOE"], "left": ["LHEE", "LTOE"]}


def test_one_foot_on_two_plates_is_assigned_to_neither_and_strikes_once_at_most(tmp_path):
    # the right foot straddles the two plates' common edge (x = 400) and loads both
    path = feet_file(tmp_path, (400.0, 300.0), (200.0, 3000.0),
                     [stance(0.2, 0.8, 300.0), stance(0.201, 0.8, 300.0)])
    with pytest.warns(RuntimeWarning, match=r"2 force-plate contact\(s\) left out: plate 1 "
                                            r".*\(the right foot also on plate 2\); plate 2 "
                                            r".*\(the right foot also on plate 1\)"):
        events = force_plate_events(path, ROLES)
    assert events["right"]["heel_strike"].size == 0     # not two strikes 1 ms apart
    with pytest.warns(RuntimeWarning, match="2 force-plate contact"):
        contacts = assign_plates(read_force_plates(path), read_c3d(path), FEET)
    assert contacts["side"].isna().all() and len(contacts) == 2


def test_two_feet_on_one_plate_are_not_assigned(tmp_path):
    path = feet_file(tmp_path, (100.0, 200.0), (300.0, 400.0),
                     [stance(0.2, 0.8), np.zeros(N)])
    with pytest.warns(RuntimeWarning, match=r"plate 1 at 0.2\d\d-0.7\d\d s \(both feet over it\)"):
        contacts = assign_plates(read_force_plates(path), read_c3d(path), FEET)
    assert contacts["side"].isna().all()


def test_a_foot_alone_on_its_plate_is_assigned_in_any_unit(tmp_path):
    path = feet_file(tmp_path, (200.0, 300.0), (600.0, 300.0),
                     [stance(0.1, 0.6), stance(0.4, 0.9)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        contacts = assign_plates(read_force_plates(path), read_c3d(path), FEET)
    assert contacts["side"].tolist() == ["right", "left"]
    np.testing.assert_allclose(contacts[["start", "stop"]].to_numpy(),
                               [[0.101, 0.599], [0.401, 0.899]], atol=0.006)
    trial = read_c3d(path)
    in_metres = trial / 1000.0
    in_metres.attrs = dict(trial.attrs, units="m")       # the same trial, in metres
    events = force_plate_events(path, ROLES, trial=in_metres)
    assert events["right"]["heel_strike"] == pytest.approx([0.101], abs=0.006)
    assert events["left"]["heel_strike"] == pytest.approx([0.401], abs=0.006)


@needs_shared("walks_with_plates/gait_with_emg.c3d")
def test_the_plate_events_of_a_trial_in_metres_find_their_feet():
    # positions in metres: a 50 "mm" margin in metres put both feet over every plate
    roles = {"RHEEL": "RCAL", "RTOE": "RTOE", "LHEEL": "LCAL", "LTOE": "LTOE"}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        events = force_plate_events(WALKS / "gait_with_emg.c3d", roles)
    assert [side for _, side, _, _ in events.contacts] == ["left", "right"]


def test_assign_plates_bad_input(synthetic):
    path, _ = synthetic      # its RHEE is (0, 0, 0): kept as such, not the point here
    plates = read_force_plates(path)
    with pytest.raises(ValueError, match=r"feet: right marker\(s\) \['RTOE'\] not in the trial"):
        assign_plates(plates, read_c3d(path, zeros_as_gaps=False), {"right": ["RHEE", "RTOE"]})
    with pytest.raises(TypeError, match="feet must map each side to a list"):
        assign_plates(plates, read_c3d(path, zeros_as_gaps=False), {"right": "RHEE"})
    trial = read_c3d(path, zeros_as_gaps=False)
    trial.attrs["rate"] = 50.0
    with pytest.raises(ValueError, match=r"trial: its rate \(50.0 Hz\) is not the plates'"):
        assign_plates(plates, trial, {"right": ["RHEE"]})


def test_a_table_without_a_plate_s_column_is_refused_naming_it(synthetic):
    path, _ = synthetic
    plates = read_force_plates(path)
    cut = plates.drop(columns=[(2, "force_y")])
    cut.attrs = plates.attrs
    named = r"plates: plate 2 of attrs\['plates'\] has no column \(2, 'force_y'\); expected"
    with pytest.raises(ValueError, match=named + r" the x, y and z columns of its force,"):
        resample_force_plates(cut)
    with pytest.raises(ValueError, match=named + r" the x, y and z columns of its force, as"):
        assign_plates(cut, read_c3d(path, zeros_as_gaps=False), {"right": ["RHEE"]})
    # the columns in another order are the same table: the same forces
    shuffled = plates[plates.columns[::-1]]
    shuffled.attrs = plates.attrs
    np.testing.assert_array_equal(np.stack(fp.plate_forces(shuffled)),
                                  np.stack(fp.plate_forces(plates)))


def test_a_plate_loaded_over_most_of_the_trial_keeps_its_zero(tmp_path):
    # the median of all samples is a load then: taken for the zero, it inverted the
    # contact (loaded read as unloaded and back)
    path = feet_file(tmp_path, (200.0, 300.0), (600.0, 3000.0),
                     [stance(0.05, 0.95) + 30.0, np.zeros(N)])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)    # plate 1 reads 30 N unloaded
        contacts = assign_plates(read_force_plates(path), read_c3d(path), FEET)
    assert contacts["side"].tolist() == ["right"]
    np.testing.assert_allclose(contacts[["start", "stop"]].to_numpy(), [[0.051, 0.949]],
                               atol=0.01)


@needs_shared("plug_in_gait/Movement_trial.c3d")
def test_a_trial_of_another_time_base_is_refused_naming_trial():
    plates = read_force_plates(PIG)
    trial = read_c3d(PIG)
    shifted = trial.copy()
    shifted.attrs = dict(trial.attrs)
    shifted.index = shifted.index + 100.0       # no overlap: frames matched by position
    with pytest.raises(ValueError, match=r"trial: its time \(100-102.683 s\) is not the "
                                         r"plates' \(0-2.69074 s\)"):
        assign_plates(plates, shifted, FEET)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assign_plates(plates, trial, FEET)      # same file: fine


def test_same_foot_on_two_plates_matches_the_pairwise_definition():
    # the vectorized search against its definition, pair by pair, on random contacts
    # (three plates, two feet and unassigned ones, overlapping and touching runs)
    from bmc_functions.files.force_plates import _same_foot_elsewhere
    rng = np.random.default_rng(7)
    for _ in range(50):
        n = int(rng.integers(0, 12))
        start = rng.integers(0, 40, n)
        found = [[int(rng.integers(1, 4)), [None, "left", "right"][rng.integers(0, 3)],
                  int(s), int(s + rng.integers(1, 15)), None] for s in start]
        expected = {}
        for i, one in enumerate(found):
            for j, other in enumerate(found):
                if (one[0] != other[0] and one[1] is not None and one[1] == other[1]
                        and one[2] < other[3] and other[2] < one[3]):
                    expected[i] = j                  # the last one listed
        assert dict(_same_foot_elsewhere(found)) == expected


# --- the plate's zero by lookup on the sorted samples: numpy's numbers ---------------------

def test_sorted_median_and_percentiles_are_numpy_s():
    """normal_load reads the medians and percentiles of its sorted samples by index
    (no partition of a copy): the same numbers as np.median and np.percentile, bit for
    bit, on odd and even sizes, ties, NaN and an empty slice."""
    rng = np.random.default_rng(29)
    for trial in range(2000):
        n = int(rng.integers(1, 500))
        x = rng.normal(size=n) * 10.0 ** rng.uniform(-3, 4)
        ordered = np.sort(np.round(x, 1) if trial % 3 == 0 else x)
        q = np.r_[1, 99, rng.uniform(0, 100, 3)]
        assert np.array_equal(fp.sorted_percentiles(ordered, q), np.percentile(ordered, q))
        start, stop = sorted(rng.integers(0, n + 1, 2))
        if stop > start:
            assert fp.sorted_median(ordered[start:stop]) == np.median(ordered[start:stop])
    with_nan = np.array([1.0, 2.0, np.nan])
    assert np.isnan(fp.sorted_median(with_nan))
    assert np.isnan(fp.sorted_percentiles(with_nan, [1, 99])).all()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        assert np.isnan(fp.sorted_median(np.zeros(0)))


def test_frame_means_of_some_frames_are_those_of_all_frames():
    """The kinetics average a plate only in the frames a foot uses it: the same numbers,
    bit for bit, as all frames averaged (odd and even ratios, runs of frames, the cut
    windows of the first and last frames)."""
    rng = np.random.default_rng(4)
    for _ in range(300):
        ratio, n = int(rng.integers(1, 12)), int(rng.integers(1, 300))
        values = rng.normal(size=(n, 3)) * 100.0
        every = fp.frame_means(values, ratio, [0, 2])
        frames = np.flatnonzero(rng.random(len(every)) < 0.5)
        assert np.array_equal(fp.frame_means(values, ratio, [0, 2], frames), every[frames])
    # by hand: ratio 3, samples 0..6 -> frames centred on 0, 3, 6 (windows cut at the ends)
    values = np.arange(7.0)[:, None]
    np.testing.assert_array_equal(fp.frame_means(values, 3, [0]).ravel(), [0.5, 3.0, 5.5])
    np.testing.assert_array_equal(fp.frame_means(values, 3, [0], [2]).ravel(), [5.5])


def test_foot_positions_by_column_position_are_those_by_label():
    """foot_positions takes the feet's x, y, z columns by position in one step: the same
    numbers, bit for bit, as each marker's columns by label (NaN frames, three markers, a
    float32 table, columns in any order); a label without its coordinates still raises
    pandas' KeyError, and a table with repeated columns is read by label."""
    rng = np.random.default_rng(11)
    labels = ["RHEE", "RTOE", "RANK", "LHEE", "LTOE"]
    columns = pd.MultiIndex.from_product([labels, ["x", "y", "z"]])
    values = rng.normal(size=(50, 15)) * 300.0
    values[rng.random(values.shape) < 0.2] = np.nan
    feet = {"right": ["RHEE", "RTOE", "RANK"], "left": ["LTOE", "LHEE"]}
    for dtype in (float, np.float32):
        order = rng.permutation(15)
        trial = pd.DataFrame(values[:, order].astype(dtype), columns=columns[order])
        trial.attrs = {"rate": 100.0, "units": "mm"}
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            found = fp.foot_positions(trial, feet, 100.0)
            for side, names in feet.items():
                expected = np.nanmean([trial[name][["x", "y", "z"]].to_numpy(float)
                                       for name in names], axis=0)
                assert np.array_equal(found[side], expected, equal_nan=True)
    cut = trial.drop(columns=[("RANK", "z")])
    with pytest.raises(KeyError):
        fp.foot_positions(cut, feet, 100.0)
    twice = pd.concat([trial, trial[["RHEE"]]], axis=1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        assert np.array_equal(fp.foot_positions(twice, {"left": ["LTOE"]}, 100.0)["left"],
                              trial["LTOE"][["x", "y", "z"]].to_numpy(float),
                              equal_nan=True)


def test_loaded_runs_match_the_padded_difference():
    """loaded_runs finds its edges without padding: the runs of the padded difference
    (loaded at the first or last sample, empty, all loaded, NaN), same indices and type."""
    rng = np.random.default_rng(12)
    for trial in range(500):
        vertical = rng.normal(size=int(rng.integers(0, 30))) * 30.0 + 20.0
        if trial % 4 == 0 and vertical.size:
            vertical[rng.integers(0, vertical.size, 2)] = np.nan
        if trial % 7 == 0:
            vertical[:] = 50.0
        above = np.concatenate(([False], vertical > 20.0, [False]))
        edges = np.flatnonzero(np.diff(above.astype(np.int8)))
        keep = (edges[1::2] - edges[0::2]) >= 0.02 * 100.0
        starts, stops = fp.loaded_runs(vertical, 100.0, 20.0, 0.02)
        assert starts.dtype == stops.dtype == np.intp
        assert np.array_equal(starts, edges[0::2][keep])
        assert np.array_equal(stops, edges[1::2][keep])


def test_normal_load_with_a_shared_scratch_is_the_same():
    """plate_contacts hands every plate the same scratch arrays (the product before the
    filter, the sorted samples): the same loads and normals, bit for bit, as fresh arrays
    per plate (tilted plates, a loaded half, NaN, a record too short to filter), and a
    plate's load is not overwritten by the next plate's."""
    rng = np.random.default_rng(13)
    for n in (4, 40, 3000):
        scratch = np.empty((2, n))
        kept = []
        for _ in range(3):
            corners = np.array([[300.0, 200, 0], [-300, 200, 0], [-300, -200, 0],
                                [300, -200, 0]]).T + rng.normal(size=(3, 4))
            force = rng.normal(size=(3, n)) * 5.0 + [[0.0], [0.0], [12.0]]
            force[2, : n // 2] -= 700.0
            if n > 40:
                force[:, rng.integers(0, n, 2)] = np.nan
            with warnings.catch_warnings():      # 4 samples: an empty median's warning
                warnings.simplefilter("ignore", RuntimeWarning)
                fresh = fp.normal_load(force, corners, 1000.0, 20.0)
                shared = fp.normal_load(force, corners, 1000.0, 20.0, scratch)
            assert np.array_equal(fresh[0], shared[0], equal_nan=True)
            assert np.array_equal(fresh[1], shared[1])
            kept.append((fresh[0], shared[0]))
        for fresh, shared in kept:
            assert np.array_equal(fresh, shared, equal_nan=True)


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_cumulative_finite_sums_as_the_concatenated_cumsum(dtype):
    """cumulative_finite writes its sums under a row of zeros: the numbers of
    ``concatenate([zeros, cumsum(where(finite, values, 0))])``, added in the values' own
    type (float32 feet are summed in float32, as before), NaN frames counted out."""
    rng = np.random.default_rng(5)
    values = (rng.normal(size=(500, 3)) * 300).astype(dtype)
    values[::7, 1] = np.nan
    finite = np.isfinite(values)
    expected = [np.concatenate([np.zeros((1, 3)), np.cumsum(c, axis=0)])
                for c in (np.where(finite, values, 0.0), finite)]
    for got, want in zip(fp.cumulative_finite(values), expected):
        assert got.dtype == want.dtype and got.tobytes() == want.tobytes()
