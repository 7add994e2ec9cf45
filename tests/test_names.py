"""Issue 24, finding 8: no misleading names in the rigid-body and model modules."""

import ast
from pathlib import Path

import pytest

import bmc_functions

PACKAGE = Path(bmc_functions.__file__).parent
MODULES = sorted(str(path.relative_to(PACKAGE))
                 for path in (PACKAGE / "rigid_body").glob("*.py")) + [
    "_threads.py", "models/joints.py", "models/segments.py", "models/functional_joints.py",
    "models/skeleton.py", "models/keypoints.py", "models/keypoint_checks.py",
    "models/keypoint_sets.py"] + sorted(
    str(path.relative_to(PACKAGE)) for path in (PACKAGE / "models" / "plug_in_gait").glob("*.py"))
VAGUE = {"few", "flat", "dead", "th", "sh", "ft", "df"}


def assigned_names(tree):
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            yield node.id, node.lineno


@pytest.mark.parametrize("module", MODULES)
def test_no_vague_names(module):
    tree = ast.parse((PACKAGE / module).read_text())
    found = [f"{name}:{line}" for name, line in assigned_names(tree) if name in VAGUE]
    if module.startswith("models/plug_in_gait/"):   # df: the marker DataFrames of a trial
        found = [item for item in found if not item.startswith("df:")]
    assert found == []
