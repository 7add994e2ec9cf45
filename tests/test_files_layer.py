"""Issue 24, the file formats: one module per concept, no private imports across
modules, no function-level imports to dodge a cycle, no import of the body models, one
C3D loading path, no function body longer than about 80 lines; and the TRC scan's
explicit checks (no exception for control flow) at their boundaries."""

import ast
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import bmc_functions
from bmc_functions import opensim_coordinates, read_trc
from bmc_functions.files import c3d, trc, trc_rows
from bmc_functions.files.trc_rows import TrcError, needs_normalizing, scan_rows

from helpers import ROOT

PACKAGE = ROOT / "bmc_functions"
MODULES = sorted((PACKAGE / "files").glob("*.py")) + [PACKAGE / "markers" / "gap_filling.py"]
MODULES = [path for path in MODULES if path.name != "events.py"]   # not this helper's
# An optional dependency imported where it is needed (the only function-level import).
OPTIONAL = {"ezc3d"}


def tree(path):
    return ast.parse(path.read_text(encoding="utf-8"))


def imports(path):
    """(node, module, names, inside a function) of every import of the module."""
    found = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            inner = in_function or isinstance(child, (ast.FunctionDef,
                                                      ast.AsyncFunctionDef))
            if isinstance(child, ast.ImportFrom):
                found.append((child, child.module or "", [a.name for a in child.names],
                              in_function))
            elif isinstance(child, ast.Import):
                found.append((child, child.names[0].name, [], in_function))
            visit(child, inner)

    visit(tree(path), False)
    return found


@pytest.mark.parametrize("path", MODULES, ids=lambda path: path.name)
def test_no_private_name_imported_from_another_module(path):
    for node, module, names, _ in imports(path):
        if isinstance(node, ast.ImportFrom) and node.level:   # inside the package
            private = [name for name in names if name.startswith("_")]
            assert not private, f"{path.name}:{node.lineno} imports {private} from {module}"


@pytest.mark.parametrize("path", MODULES, ids=lambda path: path.name)
def test_no_function_level_import_but_the_optional_c3d_library(path):
    for node, module, _, in_function in imports(path):
        if in_function:
            assert module in OPTIONAL, f"{path.name}:{node.lineno} imports {module} " \
                                       "inside a function"


@pytest.mark.parametrize("path", [p for p in MODULES if p.parent.name == "files"],
                         ids=lambda path: path.name)
def test_the_file_formats_do_not_import_the_body_models(path):
    for node, module, _, _ in imports(path):
        assert "models" not in module.split("."), f"{path.name}:{node.lineno} imports " \
                                                  f"{module} (a layer above the files)"


def body_lengths(path):
    for node in ast.walk(tree(path)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if (body and isinstance(body[0], ast.Expr)
                    and isinstance(getattr(body[0], "value", None), ast.Constant)
                    and isinstance(body[0].value.value, str)):
                body = body[1:]   # the docstring does not count
            if body:
                yield node.name, body[-1].end_lineno - body[0].lineno + 1


@pytest.mark.parametrize("path", MODULES, ids=lambda path: path.name)
def test_no_function_body_longer_than_80_lines(path):
    long = {name: length for name, length in body_lengths(path) if length > 80}
    assert not long, f"{path.name}: {long}"


def test_the_marker_readers_live_in_their_format_modules():
    assert bmc_functions.read_trc is trc.read_trc
    assert bmc_functions.write_trc is trc.write_trc
    assert bmc_functions.read_c3d is c3d.read_c3d
    from bmc_functions.files import trial
    assert trial.read_trc is trc.read_trc and trial.read_c3d is c3d.read_c3d
    assert not (PACKAGE / "files" / "markers.py").exists()


def test_one_c3d_loading_path():
    """read_c3d and read_c3d_model_outputs both load through load_c3d_points; no other
    module of the files calls read_isolated or complete_frames_copy."""
    callers = {}
    for path in MODULES:
        for node in ast.walk(tree(path)):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
                callers.setdefault(node.func.id, set()).add(path.name)
    assert callers["load_c3d_points"] == {"c3d.py", "c3d_parameters.py"}
    assert callers["read_isolated"] == {"c3d.py", "_c3d_binary.py"}
    assert callers["complete_frames_copy"] == {"c3d.py"}


# --- the TRC scan: explicit checks at their boundaries ------------------------------------

@pytest.mark.parametrize("data, expected", [
    (b"1\t0.0\t1\t2\t3\n", False),
    (b"1\t0.0\t1\t2\t3\r\n", False),            # Windows line end: read as it is
    (b"1\t0.0\t1\t2\t3\r", True),               # old Mac line end (a CR alone)
    (b"1\t0.0\t1\r\t2\t3\n", True),             # a CR inside a row
    (b"1\t0.0\t 1\t2\t3\n", True),              # a space padding a field
    (b"", False),
])
def test_needs_normalizing(data, expected):
    assert needs_normalizing(data, len(data)) is expected


def test_needs_normalizing_looks_only_up_to_end():
    data = b"1\t0.0\n \r"
    assert not needs_normalizing(data, 6)
    assert needs_normalizing(data, 7)


def scan(text):
    import io
    source = io.BytesIO(text)
    return scan_rows(source, 0, 1 << 20, TrcError("test.trc"))


def test_scan_counts_trailing_tabs_at_every_length():
    # 0, 1, 2, 64, 65 (the walk's step limit) and 1,000 trailing tabs; blank lines and a
    # tab-only line are left out, a CR before the LF is no field
    trailing = [0, 1, 2, 64, 65, 1000]
    lines = [b"1\t0.0\t1.5" + b"\t" * k for k in trailing]
    text = (b"\n".join(lines[:3]) + b"\r\n\n\t\t\t\n" + b"\n".join(lines[3:]) + b"\n")
    result = scan(text)
    np.testing.assert_array_equal(result["trailing"], trailing)
    np.testing.assert_array_equal(result["tabs"], [2 + k for k in trailing])
    np.testing.assert_array_equal(result["numbers"], [0, 1, 2, 5, 6, 7])
    assert result["n_lines"] == 8 and result["terminated"]


def test_scan_of_a_first_line_without_text():
    result = scan(b"\t\t\n1\t0.0\t\n")
    np.testing.assert_array_equal(result["numbers"], [1])
    np.testing.assert_array_equal(result["trailing"], [1])


def test_scan_asks_for_a_normalized_copy_instead_of_raising():
    assert scan(b"1\t0.0\t 1.5\n") is None
    assert scan(b"1\t0.0\t1.5\r2\t0.1\t1.5\n") is None
    assert scan(b"1\t0.0\t1.5") is not None           # a last line cut: scanned


ROWS = ["1\t0.00\t10.0\t20.0\t30.0", "2\t0.01\t11.0\t21.0\t31.0"]


def trc_text(rows, end="\n"):
    head = ["PathFileType\t4\t(X/Y/Z)\tdemo.trc",
            "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t"
            "OrigDataStartFrame\tOrigNumFrames",
            "100\t100\t2\t1\tmm\t100\t1\t2", "Frame#\tTime\tA\t\t\t", "\t\tX1\tY1\tZ1\t", ""]
    return end.join(head + rows) + end


@pytest.mark.parametrize("rows, end", [
    ([row.replace("\t", " \t") for row in ROWS], "\n"),   # spaces in the rows
    (ROWS, "\r"),                                         # old Mac line ends
    (ROWS, "\r\n"),
], ids=["spaces", "cr", "crlf"])
def test_rows_needing_a_normalized_copy_read_as_the_plain_file(tmp_path, rows, end):
    plain = tmp_path / "plain.trc"
    plain.write_bytes(trc_text(ROWS).encode())
    other = tmp_path / "other.trc"
    other.write_bytes(trc_text(rows, end).encode())
    pd.testing.assert_frame_equal(read_trc(other), read_trc(plain))


# --- opensim_coordinates: Plug-in Gait's pelvis renamed without importing the model ----

def pig_angles(side, values):
    columns = pd.MultiIndex.from_tuples(
        [("pelvis", side, angle) for angle in ("tilt", "obliquity", "rotation")]
        + [("knee", side, "flexion")])
    angles = pd.DataFrame([values], columns=columns, index=pd.Index([0.0], name="time"))
    angles.attrs = {"units": "deg", "model": "Plug-in Gait lower body"}
    return angles


@pytest.mark.parametrize("side, expected", [
    ("right", [-12.0, -3.0, 5.0]),      # pelvis_list = -obliquity_R, rotation = rotation_R
    ("left", [-12.0, 3.0, -5.0]),       # pelvis_list = obliquity_L, rotation = -rotation_L
])
def test_plug_in_gait_pelvis_is_renamed_with_opensim_signs(side, expected):
    coordinates = opensim_coordinates(pig_angles(side, [12.0, 3.0, 5.0, 20.0]))
    np.testing.assert_array_equal(
        coordinates[["pelvis_tilt", "pelvis_list", "pelvis_rotation"]].iloc[0], expected)
    assert coordinates[f"knee_angle_{side[0]}"].iloc[0] == 20.0
    assert coordinates.attrs["source_columns"]["pelvis_list"] == ("pelvis", side,
                                                                  "obliquity")


def test_plug_in_gait_pelvis_nan_stays_in_its_column():
    coordinates = opensim_coordinates(pig_angles("right", [12.0, np.nan, 5.0, 20.0]))
    assert np.isnan(coordinates["pelvis_list"].iloc[0])
    assert coordinates["pelvis_tilt"].iloc[0] == -12.0


def test_plug_in_gait_pelvis_without_a_whole_side_is_refused():
    angles = pig_angles("right", [12.0, 3.0, 5.0, 20.0]).drop(
        columns=[("pelvis", "right", "rotation")])
    with pytest.raises(ValueError, match=r"the pelvis needs its tilt, obliquity and "
                                         r"rotation of one side"):
        opensim_coordinates(angles)


def test_the_trc_scan_raises_no_exception_for_control_flow():
    source = Path(trc_rows.__file__).read_text() + Path(trc.__file__).read_text()
    assert "class _Normalize" not in source and "except _Normalize" not in source
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert scan(b"1\t0.0\t1.5\n")["numbers"].tolist() == [0]


# --- one C3D loading path: both readers treat a cut file the same way ----------------------

def test_a_cut_c3d_file_is_read_alike_by_both_readers(tmp_path):
    pytest.importorskip("ezc3d")
    from bmc_functions import read_c3d, read_c3d_model_outputs
    from bmc_functions.examples import example_file
    from bmc_functions.files._c3d_binary import check_c3d

    original = Path(example_file("plug_in_gait/Movement_trial.c3d"))
    info = check_c3d(original)
    keep = 10   # whole frames left, then half a frame
    cut = tmp_path / "cut.c3d"
    cut.write_bytes(original.read_bytes()[:info["data_offset"] + keep * info["frame_bytes"]
                                          + info["frame_bytes"] // 2])
    message = (rf"the header announces {info['frames']} frames but the file holds {keep} "
               rf"whole frames \(is it cut\?\); the first {keep} were read")
    with pytest.warns(UserWarning, match=message):
        markers = read_c3d(cut)
    with pytest.warns(UserWarning, match=message):
        outputs = read_c3d_model_outputs(cut)
    assert len(markers) == len(outputs) == keep
    assert markers.attrs["frames"] == outputs.attrs["frames"]
    full = read_c3d_model_outputs(original)
    pd.testing.assert_frame_equal(outputs, full.iloc[:keep], check_freq=False)
