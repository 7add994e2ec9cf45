"""Tests of bmc_functions.markers.roles: the role table and the mapping and label checks."""

import warnings

import pytest

from bmc_functions.markers.roles import all_roles, check_labels, check_mapping, describe


def minimal(prefix="R", **extra):
    mapping = {"RASIS": "RASI", "LASIS": "LASI", "SACRUM": "SACR"}
    for role in ("KNEE_LAT", "KNEE_MED", "ANKLE_LAT", "ANKLE_MED", "HEEL", "TOE"):
        mapping[prefix + role] = prefix + role.lower()
    mapping.update(extra)
    return mapping


def test_sides_are_found_from_the_roles_and_can_be_chosen():
    assert check_mapping(minimal())[1] == ("right",)
    assert check_mapping(minimal("L"))[1] == ("left",)
    both = dict(minimal(), **minimal("L"))
    assert check_mapping(both)[1] == ("right", "left")
    assert check_mapping(both, sides="left")[1] == ("left",)
    assert check_mapping(both, sides=["left", "right"])[1] == ("right", "left")


def test_clusters_become_tuples_and_landmarks_stay_strings():
    mapping, _ = check_mapping(minimal(RTHIGH=["a", "b", "c"]))
    assert mapping["RTHIGH"] == ("a", "b", "c") and mapping["RASIS"] == "RASI"


def test_role_table():
    assert len(all_roles()) == 6 + 2 * 11
    assert describe("LKNEE_MED") == "left medial femoral epicondyle"
    assert describe("SACRUM").startswith("sacral marker")


def test_unknown_side_and_no_side():
    with pytest.raises(ValueError, match=r"sides must hold 'right' and/or 'left'; got 'r'"):
        check_mapping(minimal(), sides=["r"])
    with pytest.raises(ValueError, match="sides is empty"):
        check_mapping(minimal(), sides=[])
    with pytest.raises(ValueError, match="markers has no role of either side"):
        check_mapping({"RASIS": "a", "LASIS": "b", "SACRUM": "c"})


def test_a_chosen_side_needs_its_roles():
    with pytest.raises(ValueError, match=r"role 'LKNEE_LAT' \(left lateral femoral "
                                         r"epicondyle\) is missing from the mapping; the left "
                                         r"side needs it"):
        check_mapping(minimal(), sides="left")


def test_cluster_label_errors():
    with pytest.raises(ValueError, match=r"markers\['RTHIGH'\] lists a label twice"):
        check_mapping(minimal(RTHIGH=["a", "b", "a"]))
    with pytest.raises(TypeError, match=r"markers\['RTHIGH'\]: labels must be strings; got 1"):
        check_mapping(minimal(RTHIGH=["a", "b", 1]))
    with pytest.raises(ValueError, match=r"markers\['RHEEL'\] must be one label .*not a list"):
        check_mapping(minimal(RHEEL=["a", "b"]))
    with pytest.raises(TypeError, match=r"markers\['RHEEL'\] must be a label \(str\); got int"):
        check_mapping(minimal(RHEEL=3))


def test_check_labels_names_close_labels_or_lists_the_file():
    mapping = {"RKNEE_MED": "R.MKnee"}
    with pytest.raises(ValueError, match=r"markers\['RKNEE_MED'\] = 'R.MKnee' \(right medial "
                                         r"femoral epicondyle\): no marker with that label in "
                                         r"the static trial; labels in it that look close: "
                                         r"'R.Knee'"):
        check_labels(mapping, ["RKNEE_MED"], ["R.Knee", "R.Knee.Medial", "L.Knee"],
                     "the static trial")
    with pytest.raises(ValueError, match=r"no marker with that label in trial; it has 'A', "
                                         r"'B'"):
        check_labels({"RHEEL": "zzzz"}, ["RHEEL"], ["A", "B"], "trial")


def test_label_that_differs_only_in_case_or_spaces_is_named():
    # difflib compared case-sensitively: 'rasi' was offered 'RFAradius', not 'RASI'.
    available = ["RFAradius", "LFAradius", "RASI", "RTH1", "RTH2"]
    for label in ("rasi", "RASI ", " r asi"):
        with pytest.raises(ValueError, match=r"markers\['RASIS'\] = '.*' \(right anterior "
                                             r"superior iliac spine\): no marker with that "
                                             r"label in the static trial; it has 'RASI', "
                                             r"which differs only in case or spaces"):
            check_labels({"RASIS": label}, ["RASIS"], available, "the static trial")
    with pytest.raises(ValueError, match=r"labels in it that look close: 'RTH1'"):
        check_labels({"RASIS": "rth 11"}, ["RASIS"], available, "the static trial")


def test_unknown_role_in_lower_case_is_offered_the_role():
    with pytest.raises(ValueError, match=r"unknown role 'rasis'; did you mean 'RASIS'"):
        check_mapping(dict(minimal(), rasis="RASI"))


def test_sides_of_a_wrong_type():
    with pytest.raises(TypeError, match=r"sides must be 'right', 'left' or a list of them; "
                                        r"got int 1"):
        check_mapping(minimal(), sides=1)


def test_hip_centre_markers_mapped_but_not_used_warn():
    mapping = minimal(RHJC="RHJC")
    with pytest.warns(UserWarning, match=r"markers maps RHJC \(the lab's hip-centre "
                                         r"markers\), but hip_centre='harrington': they are "
                                         r"not used.*pass hip_centre='marker'"):
        check_mapping(mapping)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_mapping(mapping, hip_centre="marker")


def test_label_named_by_the_file_but_empty_is_said_to_be_empty():
    # It was reported as absent, with unrelated close labels ('V_R.Hip_JC' -> 'R.HF').
    with pytest.raises(ValueError, match=r"markers\['RHJC'\] = 'V_R.Hip_JC' \(right hip joint "
                                         r"centre computed by the lab .*\): walk.trc names this "
                                         r"label but its columns are empty in every frame"):
        check_labels({"RHJC": "V_R.Hip_JC"}, ["RHJC"], ["R.HF", "R.ASIS"], "walk.trc",
                     dropped=("V_Mid_ASIS", "V_R.Hip_JC"))


# --- issue 21: a label mapped to two roles, nested lists ------------------------------------

def _mapping(**changes):
    mapping = {"RASIS": "RASI", "LASIS": "LASI", "SACRUM": "SACR", "RKNEE_LAT": "RLFC",
               "RKNEE_MED": "RMFC", "RANKLE_LAT": "RLMAL", "RANKLE_MED": "RMMAL",
               "RHEEL": "RCAL", "RTOE": "RTOE"}
    mapping.update(changes)
    return mapping


def test_one_label_mapped_to_two_roles_is_named_as_such():
    with pytest.raises(ValueError, match=r"maps the label 'RLFC' to 2 roles: RKNEE_LAT "
                                         r"\(right lateral femoral epicondyle\), RKNEE_MED"):
        check_mapping(_mapping(RKNEE_MED="RLFC"))


def test_a_cluster_may_share_labels_with_landmarks():
    mapping, _ = check_mapping(_mapping(RSHANK=["RLFC", "RTB1", "RTB2"]))
    assert mapping["RSHANK"] == ("RLFC", "RTB1", "RTB2")


def test_nested_lists_are_named_not_unhashable():
    with pytest.raises(TypeError, match=r"markers\['RTHIGH'\]: labels must be strings; got "
                                        r"\['T1'\] \(list\)"):
        check_mapping(_mapping(RTHIGH=[["T1"], "T2", "T3"]))
    with pytest.raises(ValueError, match=r"sides must hold 'right' and/or 'left'; got "
                                         r"\['right'\]"):
        check_mapping(_mapping(), sides=[["right"]])
