"""plug_in_gait on variations of the repository's real Plug-in Gait trial, as other labs'
files come: subject prefixes, SACR, zero-filled and partial gaps, metres, a mirrored lab,
swapped labels, other walking directions and sampling rates, incomplete subject files.

Each variation is a modified copy of data/real/plug_in_gait/Movement_trial.c3d (the
lower-body Plug-in Gait markers, written with ezc3d in a temporary folder); the oracle is
the curve Vicon Nexus stored in the original file (read_c3d_model_outputs), or the
original trial's own angles where the variation must not change them.
"""

import re
import xml.etree.ElementTree as ElementTree

import numpy as np
import pandas as pd
import pytest

from bmc_functions import plug_in_gait, read_c3d, read_c3d_model_outputs
from bmc_functions.files.c3d_parameters import subject_parameters
from bmc_functions.models.plug_in_gait import CGM_ANGLES, VICON_OUTPUTS, check_handedness

from helpers import ROOT, write_c3d_points as write_copy

ezc3d = pytest.importorskip("ezc3d")

FOLDER = ROOT / "data" / "real" / "plug_in_gait"
pytestmark = pytest.mark.skipif(not (FOLDER / "Movement_trial.c3d").exists(),
                                reason="the repository's Plug-in Gait trial is absent")
STATIC, VSK = FOLDER / "Static_trial.c3d", FOLDER / "Test.vsk"

#: The lower-body Plug-in Gait markers of the trial (LHEE is labelled late in the file).
LOWER = ["LASI", "RASI", "LPSI", "RPSI"] + [p + m for p in "LR" for m in (
    "THI", "KNE", "TIB", "ANK", "HEE", "TOE")]
RMS_LIMIT = 0.1   # degrees per curve, as tests/test_plug_in_gait.py


@pytest.fixture(scope="module")
def original():
    trial = read_c3d(FOLDER / "Movement_trial.c3d")
    xyz = np.stack([trial[label].to_numpy() for label in LOWER], axis=1)  # (frames, n, 3)
    model = plug_in_gait(STATIC, VSK)
    full = model.angles(FOLDER / "Movement_trial.c3d")
    # the lower body's curves: the copies below hold the lower-body markers only
    angles = full.loc[:, [column for column in full.columns if column[0] in CGM_ANGLES]]
    return {"xyz": xyz, "vicon": read_c3d_model_outputs(FOLDER / "Movement_trial.c3d"),
            "model": model, "angles": angles, "full": full}


def rms_against_vicon(angles, vicon, rows=slice(None)):
    """(joint, side, angle) -> RMS (degrees) against Vicon's stored curve, over `rows`
    (the NaN frames of `angles` left out)."""
    out = {}
    for joint, side, name in angles.columns:
        label, component = VICON_OUTPUTS[(joint, name)]
        reference = vicon[("L" if side == "left" else "R") + label].iloc[rows, component]
        difference = angles[joint, side, name].to_numpy()[rows] - reference.to_numpy()
        out[(joint, side, name)] = float(np.sqrt(np.nanmean(difference ** 2)))
    return out


def assert_matches_vicon(angles, vicon, rows=slice(None)):
    rms = rms_against_vicon(angles, vicon, rows)
    worst = max(rms, key=rms.get)
    assert rms[worst] < RMS_LIMIT, (worst, rms[worst])


# --- labels ---------------------------------------------------------------------------------

def test_subject_prefixed_labels(tmp_path, original):
    path = write_copy(tmp_path / "prefixed.c3d", original["xyz"],
                      ["Sub01:" + label for label in LOWER])
    model = plug_in_gait(STATIC, VSK)
    assert_matches_vicon(model.angles(path), original["vicon"])
    assert model.markers["LASI"] == "Sub01:LASI"
    assert model.event_markers()["RHEEL"] == "Sub01:RHEE"


def test_labels_in_another_case(tmp_path, original):
    path = write_copy(tmp_path / "lower.c3d", original["xyz"],
                      ["sub01:" + label.lower() for label in LOWER])
    model = plug_in_gait(STATIC, VSK)
    assert_matches_vicon(model.angles(path), original["vicon"])
    assert model.markers["RKNE"] == "sub01:rkne"
    # two labels for one marker in different cases: which one is meant is not known
    xyz = np.concatenate([original["xyz"], original["xyz"][:, :1]], axis=1)
    path = write_copy(tmp_path / "twice.c3d", xyz, [label.lower() for label in LOWER]
                      + ["Lasi"])
    with pytest.raises(ValueError, match=r"LASI matches several labels in other cases "
                                         r"\(lasi, Lasi\)"):
        model.angles(path)


def test_two_subjects_are_ambiguous_until_one_is_named(tmp_path, original):
    xyz = np.concatenate([original["xyz"], original["xyz"] + [2000.0, 0, 0]], axis=1)
    labels = ["Sub01:" + label for label in LOWER] + ["Sub02:" + label for label in LOWER]
    path = write_copy(tmp_path / "two.c3d", xyz, labels)
    with pytest.raises(ValueError, match=r"LASI appears with several subject prefixes "
                                         r"\(Sub01:LASI, Sub02:LASI\)"):
        plug_in_gait(STATIC, VSK).angles(path)
    # the offsets from the C3D's PROCESSING (the static trial has no prefixes)
    second = plug_in_gait(None, FOLDER / "Movement_trial.c3d",
                          markers={name: "Sub02:" + name for name in LOWER})
    # the second subject is the first moved 2 m along the walkway: Vicon's angles
    assert_matches_vicon(second.angles(path), original["vicon"])
    assert second.markers["RKNE"] == "Sub02:RKNE"


def test_sacrum_instead_of_the_psis_markers(tmp_path, original):
    xyz = original["xyz"].copy()
    xyz[:, LOWER.index("LPSI")] = (xyz[:, LOWER.index("LPSI")]
                                   + xyz[:, LOWER.index("RPSI")]) / 2.0
    labels = [{"LPSI": "SACR", "RPSI": "RBAK"}.get(label, label) for label in LOWER]
    path = write_copy(tmp_path / "sacr.c3d", xyz, labels)
    model = plug_in_gait(STATIC, VSK)
    assert_matches_vicon(model.angles(path), original["vicon"])
    assert model.event_markers()["SACRUM"] == "SACR"


def test_sacr_fills_the_gaps_of_a_psis_marker(tmp_path, original):
    """Both SACR and the PSIS markers: the midpoint of the PSISs where both are seen, SACR
    where one is missing (the pelvis is not NaN there), with one warning."""
    psis = original["xyz"][:, [LOWER.index("LPSI"), LOWER.index("RPSI")]]
    sacr = psis.mean(axis=1)
    xyz = np.concatenate([original["xyz"], sacr[:, None]], axis=1)
    xyz[100:106, LOWER.index("RPSI")] = np.nan
    path = write_copy(tmp_path / "both.c3d", xyz, LOWER + ["SACR"])
    with pytest.warns(RuntimeWarning, match=r"^6 of 323 frames .* lack LPSI or RPSI: the "
                                            r"pelvis uses SACR there"):
        angles = plug_in_gait(STATIC, VSK).angles(path)
    assert angles.notna().all().all()
    np.testing.assert_allclose(angles.to_numpy(), original["angles"].to_numpy(), atol=1e-4)


# --- gaps -----------------------------------------------------------------------------------

def test_zero_filled_gaps_are_nan_not_an_error(tmp_path, original):
    """Some systems write (0, 0, 0) for a marker not seen: all markers so in the first 50
    frames. They are gaps: NaN angles there, Vicon's angles elsewhere, no 'mirrored' or
    'swapped' verdict."""
    xyz = original["xyz"].copy()
    xyz[:50] = 0.0
    path = write_copy(tmp_path / "zeros.c3d", xyz, LOWER)
    with pytest.warns(Warning) as record:
        angles = plug_in_gait(STATIC, VSK).angles(path)
    messages = " ".join(str(w.message) for w in record)
    assert "were exactly (0, 0, 0)" in messages and "read as gaps (NaN)" in messages
    assert "50 of 323 frames have undefined segments" in messages
    assert "mirrored" not in messages and "swapped" not in messages
    assert angles.iloc[:50].isna().all().all()
    assert angles.iloc[50:].notna().all().all()
    assert_matches_vicon(angles, original["vicon"], slice(50, None))


@pytest.mark.parametrize("marker, nan_columns", [
    ("LTOE", [("ankle", "left"), ("foot", "left")]),
    ("RTHI", [("hip", "right"), ("knee", "right"), ("ankle", "right"), ("foot", "right")]),
    ("LASI", "all"),
])
def test_a_marker_missing_for_a_few_frames(tmp_path, original, marker, nan_columns):
    xyz = original["xyz"].copy()
    xyz[100:106, LOWER.index(marker)] = np.nan
    path = write_copy(tmp_path / "gap.c3d", xyz, LOWER)
    with pytest.warns(RuntimeWarning, match=rf"6 of 323 frames .*{marker} missing in 6"):
        angles = plug_in_gait(STATIC, VSK).angles(path)
    gap = angles.iloc[100:106]
    expected = list(angles.columns) if nan_columns == "all" else \
        [column for column in angles.columns if column[:2] in nan_columns]
    assert [c for c in angles.columns if gap[c].isna().all()] == expected
    assert gap.drop(columns=expected).notna().all().all()   # NaN only where needed
    assert angles.drop(index=angles.index[100:106]).notna().all().all()
    assert_matches_vicon(angles, original["vicon"])         # NaN frames left out


# --- units, directions, rates --------------------------------------------------------------

def test_a_trial_in_metres(tmp_path, original):
    path = write_copy(tmp_path / "metres.c3d", original["xyz"] / 1000.0, LOWER, units="m")
    assert_matches_vicon(plug_in_gait(STATIC, VSK).angles(path), original["vicon"])


@pytest.mark.parametrize("scale, units, width", [(0.001, "mm", "0.3107 mm"),
                                                  (1.0, "m", "3.107e+05 mm")])
def test_wrong_declared_units_are_refused(tmp_path, original, scale, units, width):
    """Metres labelled mm gave finite, plausible-looking angles (no NaN, no word) and a
    static trial so labelled foot offsets of -2.6 rad, before the units check."""
    path = write_copy(tmp_path / "units.c3d", original["xyz"] * scale, LOWER, units=units)
    message = (rf"declares its units as '{units}', but then the distance between RASIS "
               rf"\('RASI'\) and LASIS \('LASI'\) is {re.escape(width)}")
    with pytest.raises(ValueError, match=message):
        original["model"].angles(path)
    with pytest.raises(ValueError, match=r"the static trial \(units.c3d\) declares its units"):
        plug_in_gait(path, VSK)


@pytest.mark.parametrize("direction, turn", [("+x", 180), ("-y", 90), ("+y", -90),
                                             ("-x, y up", "y up"), ("+z, y up", "y up z")])
def test_walking_along_other_lab_axes(tmp_path, original, direction, turn):
    """The trial walks along -x with z up; turned about the vertical to walk along +x,
    +y, -y, or into a y-up lab (as many systems write), the static trial with it: the
    progression frame follows, the angles do not change (pelvis rotation and foot
    progression included)."""
    if turn == "y up":      # lab z -> y, y -> -z (a rotation about x)
        R = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])
    elif turn == "y up z":  # y up and walking along +z
        R = np.array([[0.0, -1, 0], [0, 0, 1], [-1, 0, 0]])
    else:
        c, s = np.cos(np.radians(turn)), np.sin(np.radians(turn))
        R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    assert np.linalg.det(R) == pytest.approx(1.0)
    path = write_copy(tmp_path / "turned.c3d", original["xyz"] @ R.T, LOWER)
    static = read_c3d(STATIC)
    static_xyz = np.stack([static[label].to_numpy() for label in LOWER], axis=1) @ R.T
    static_path = write_copy(tmp_path / "static.c3d", static_xyz, LOWER)
    model = plug_in_gait(static_path, VSK)
    angles = model.angles(path)
    np.testing.assert_allclose(angles.to_numpy(), original["angles"].to_numpy(), atol=1e-6)
    forward = model.track(path).progression[:, 0]
    axis = {"+x": [1, 0, 0], "+y": [0, 1, 0], "-y": [0, -1, 0], "-x, y up": [-1, 0, 0],
            "+z, y up": [0, 0, 1]}[direction]
    np.testing.assert_array_equal(forward, axis)


def test_a_diagonal_walkway_warns_once(tmp_path, original):
    """Turned 30 degrees about the vertical: Plug-in Gait reports the pelvis and foot
    progression against the nearest lab axis (Vicon too), so pelvis rotation reads about
    30 degrees off; the trial says so, once; hip and knee are unchanged."""
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    path = write_copy(tmp_path / "diagonal.c3d", original["xyz"] @ R.T, LOWER)
    with pytest.warns(RuntimeWarning) as record:
        angles = original["model"].angles(path)
    messages = [str(w.message) for w in record]
    assert len(messages) == 1
    assert re.match(r"the pelvis in the dynamic trial \(diagonal.c3d\) travels (29|30|31) "
                    r"degrees from the lab axis", messages[0])
    offset = angles["pelvis", "right", "rotation"] - original["angles"]["pelvis", "right",
                                                                        "rotation"]
    assert abs(offset.mean()) == pytest.approx(30.0, abs=3.0)   # 28: tilt comes first
    for joint in ("hip", "knee"):
        np.testing.assert_allclose(angles[joint].to_numpy(),
                                   original["angles"][joint].to_numpy(), atol=1e-4)


@pytest.mark.parametrize("rate", [50.0, 250.0])
def test_other_sampling_rates(tmp_path, original, rate):
    """The model is frame by frame: the same markers at 50 or 250 Hz give the same angles
    per frame, indexed by the new times; attrs carry the rate."""
    path = write_copy(tmp_path / f"rate{rate:g}.c3d", original["xyz"], LOWER, rate=rate)
    angles = plug_in_gait(STATIC, VSK).angles(path)
    np.testing.assert_allclose(angles.index, np.arange(323) / rate)
    assert angles.attrs["rate"] == rate
    np.testing.assert_allclose(angles.to_numpy(), original["angles"].to_numpy(), atol=1e-6)


# --- mirrored and swapped -----------------------------------------------------------------

def _swap_sides(labels):
    return [{"L": "R", "R": "L"}[label[0]] + label[1:] for label in labels]


@pytest.mark.parametrize("how", ["mirrored lab", "left-right labels swapped"])
def test_a_mirrored_or_swapped_trial_is_refused(tmp_path, original, how):
    """Before the handedness check both gave plausible-looking curves (162° and 179° RMS
    from Vicon's, with no word)."""
    xyz, labels = original["xyz"].copy(), list(LOWER)
    if how == "mirrored lab":
        xyz[..., 1] *= -1.0                # the lab's y axis reversed: a left-handed frame
    else:
        labels = _swap_sides(labels)
    path = write_copy(tmp_path / "flipped.c3d", xyz, labels)
    with pytest.raises(ValueError, match=r"in every frame of the dynamic trial "
                                         r"\(flipped.c3d\) \(323\), the body is mirrored"):
        plug_in_gait(STATIC, VSK).angles(path)
    with pytest.raises(ValueError, match="the body is mirrored"):
        plug_in_gait(path, VSK)            # as a static trial too


def test_labels_swapped_in_some_frames_are_nan_with_one_warning(tmp_path, original):
    """A labelling error over 40 frames (the tracker swapped every side): those frames
    NaN, one warning, the rest Vicon's."""
    xyz = original["xyz"].copy()
    swapped = [LOWER.index(label) for label in _swap_sides(LOWER)]
    xyz[150:190] = xyz[150:190][:, swapped]
    path = write_copy(tmp_path / "partly.c3d", xyz, LOWER)
    with pytest.warns(RuntimeWarning) as record:
        angles = plug_in_gait(STATIC, VSK).angles(path)
    messages = [str(w.message) for w in record]
    assert len(messages) == 1 and messages[0].startswith("40 of 323 frames")
    assert "the body is mirrored" in messages[0]
    assert angles.iloc[150:190].isna().all().all()
    assert_matches_vicon(angles, original["vicon"])


def test_legs_swapped_in_some_frames(tmp_path, original):
    """Only the legs' labels swapped (the pelvis right): the thighs cross by a hip width;
    hip, knee, ankle and foot NaN there, the pelvis kept, one warning."""
    xyz = original["xyz"].copy()
    legs = [label for label in LOWER if label[1:] not in ("ASI", "PSI")]
    order = [LOWER.index(label) for label in LOWER]
    for label in legs:
        order[LOWER.index(label)] = LOWER.index(_swap_sides([label])[0])
    xyz[150:190] = xyz[150:190][:, order]
    path = write_copy(tmp_path / "legs.c3d", xyz, LOWER)
    with pytest.warns(RuntimeWarning, match=r"^40 of 323 frames .*right thigh's markers "
                                            r"\(RTHI, RKNE\) lie to the subject's left"):
        angles = plug_in_gait(STATIC, VSK).angles(path)
    assert angles.drop(columns="pelvis", level=0).iloc[150:190].isna().all().all()
    assert angles["pelvis"].iloc[150:190].notna().all().all()
    assert_matches_vicon(angles, original["vicon"])


def test_handedness_of_the_real_trials_is_never_flagged(original):
    """No false alarm on the real static and stair-descent trials (every frame judged)."""
    for trial in (FOLDER / "Movement_trial.c3d", STATIC):
        df = read_c3d(trial)
        points = {label: df[label].to_numpy() for label in LOWER}
        points["SACRUM"] = (points["LPSI"] + points["RPSI"]) / 2.0
        mirrored, crossed = check_handedness(points)
        assert not mirrored.any() and not crossed.any()


# --- subject files --------------------------------------------------------------------------

def _vsk_copy(tmp_path, edit):
    tree = ElementTree.parse(VSK)
    parameters = tree.getroot().find("Parameters")
    for element in list(parameters):
        edit(parameters, element)
    path = tmp_path / "Test.vsk"     # Nexus names a .vsk after its subject
    tree.write(path)
    return path


def test_vsk_without_required_measurements_names_each(tmp_path):
    def drop(parameters, element):
        if element.get("NAME") in ("LeftKneeWidth", "RightAnkleWidth"):
            parameters.remove(element)
    path = _vsk_copy(tmp_path, drop)
    with pytest.raises(ValueError, match=r"subject \(Test.vsk\): missing subject "
                                         r"measurement\(s\) LeftKneeWidth, RightAnkleWidth"):
        plug_in_gait(STATIC, path)


def test_vsk_with_an_optional_measurement_absent_derives_it(tmp_path, original):
    def drop(parameters, element):
        if element.get("NAME") in ("LeftAsisTrocanterDistance", "MarkerDiameter"):
            parameters.remove(element)
    model = plug_in_gait(STATIC, _vsk_copy(tmp_path, drop))
    assert model.derived["LeftAsisTrocanterDistance"] == pytest.approx(0.1288 * 877 - 48.56)
    assert model.attrs["marker_diameter_mm"] == 14.0
    assert_matches_vicon(model.angles(FOLDER / "Movement_trial.c3d"), original["vicon"])


def test_vsk_names_in_another_case(tmp_path, original):
    def shout(parameters, element):
        if element.get("NAME"):
            element.set("NAME", element.get("NAME").upper())
    model = plug_in_gait(None, _vsk_copy(tmp_path, shout))
    assert model.subject["LeftLegLength"] == 877.0
    np.testing.assert_allclose(model.angles(FOLDER / "Movement_trial.c3d").to_numpy(),
                               original["full"].to_numpy(), atol=1e-4)   # upper body too


def test_c3d_without_the_static_offsets_and_no_static_says_what_to_give(tmp_path, original):
    processing = {name: value for name, value in
                  subject_parameters(FOLDER / "Movement_trial.c3d").items()
                  if "Static" not in name and not name.isupper()}
    path = write_copy(tmp_path / "walk.c3d", original["xyz"], LOWER, processing=processing)
    message = ("missing subject measurement(s) LeftStaticPlantFlex, RightStaticPlantFlex, "
               "LeftStaticRotOff, RightStaticRotOff; without a static trial")
    with pytest.raises(ValueError, match=re.escape(message) + ".*give the static trial"):
        plug_in_gait(None, path)
    # with the static trial the same file is enough
    assert_matches_vicon(plug_in_gait(STATIC, path).angles(path), original["vicon"])


# --- OpenSim names ---------------------------------------------------------------------------

def test_opensim_pelvis_is_plug_in_gaits_renamed(original):
    """Plug-in Gait's pelvis sequence (tilt, obliquity, rotation) is OpenSim's (Z, X, Y):
    the coordinates are the angles with the axes' signs; the ISB pipeline's conversion,
    made for the reverse sequence, would be off by degrees here."""
    from bmc_functions import opensim_coordinates

    angles = original["angles"]
    coordinates = opensim_coordinates(angles)
    np.testing.assert_array_equal(coordinates["pelvis_tilt"], -angles["pelvis", "right",
                                                                      "tilt"])
    np.testing.assert_array_equal(coordinates["pelvis_list"],
                                  angles["pelvis", "left", "obliquity"])
    np.testing.assert_array_equal(coordinates["pelvis_rotation"],
                                  angles["pelvis", "right", "rotation"])
    assert coordinates.columns[-1] == "foot_progression_l"
    # oracle: the pelvis against the progression frame, written in OpenSim's ground axes
    # (X forward, Y up, Z right = x, z, -y of Plug-in Gait's) and decomposed Z-X-Y
    from bmc_functions.rigid_body.cardan import decompose

    track = original["model"].track(FOLDER / "Movement_trial.c3d")
    relative = track.progression.T @ track.frames[("pelvis", None)][0]
    T = np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]])   # columns: X, Y, Z in x, y, z
    zxy = decompose(T.T @ relative @ T, "ZXY", degrees=True)
    np.testing.assert_allclose(coordinates.iloc[:, :3], zxy, atol=1e-9)
    # opensim_coordinates (and so write_mot) knows Plug-in Gait's angles by their attrs
    pd.testing.assert_frame_equal(opensim_coordinates(angles), coordinates)
    # attrs lost (pd.concat): Plug-in Gait's still, known by its foot progression angle
    unlabelled = angles.copy()
    unlabelled.attrs = {"units": "deg"}
    pd.testing.assert_frame_equal(opensim_coordinates(unlabelled), coordinates)
    # the ISB conversion, applied to the same numbers as if the ISB pipeline's, is off
    unlabelled.attrs = {"units": "deg", "pelvis_sequence": "YXZ"}
    isb_way = opensim_coordinates(unlabelled)
    assert np.abs(isb_way["pelvis_list"] - coordinates["pelvis_list"]).max() > 1.0
    np.testing.assert_array_equal(isb_way.drop(columns=["pelvis_tilt", "pelvis_list",
                                                        "pelvis_rotation"]),
                                  coordinates.iloc[:, 3:])


def test_a_walk_given_as_the_static_trial_warns(original):
    """The static offsets are means over the static trial's frames: a trial that moves
    is named (it gave offsets 0.08 rad off the real ones without a word)."""
    with pytest.warns(RuntimeWarning, match=r"the static trial \(Movement_trial.c3d\) is "
                                            r"not static: marker '\w+' moves up to \d+ mm"), \
            pytest.warns(RuntimeWarning, match=r"86 of 323 frames of the static trial .*LANK "
                                               r"is farther from LKNE than LTOE"), \
            pytest.warns(RuntimeWarning, match=r"53 of 323 frames of the static trial .*RANK "
                                               r"is farther from RKNE than RTOE"):
        model = plug_in_gait(FOLDER / "Movement_trial.c3d", VSK)
    assert model.static_offsets["LeftStaticPlantFlex"] != pytest.approx(
        original["model"].static_offsets["LeftStaticPlantFlex"], abs=0.01)


def test_a_trc_export_of_the_trial(tmp_path, original):
    """Labs often export TRC (OpenSim's format): the same trial as .trc gives Vicon's
    angles, static from the C3D."""
    from bmc_functions import write_trc

    trial = read_c3d(FOLDER / "Movement_trial.c3d")
    path = tmp_path / "walk.trc"
    write_trc(trial[LOWER], path)
    assert_matches_vicon(plug_in_gait(STATIC, VSK).angles(path), original["vicon"])
