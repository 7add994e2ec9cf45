"""Every notebook is a regression test: check that each one is collected by nbval, was
stored after a top-to-bottom run, and has the parts a teaching notebook must have."""

import json
import pathlib
import re
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
IGNORE_MARKERS = re.compile(r"^#\s*NBVAL_(IGNORE_OUTPUT|SKIP|RAISES_EXCEPTION)\s*$", re.M)


def load(path):
    return json.loads(path.read_text(encoding="utf-8"))


def code_cells(nb):
    return [c for c in nb["cells"] if c["cell_type"] == "code" and "".join(c["source"]).strip()]


def markdown(nb):
    return "\n".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "markdown")


def test_notebook_names_are_numbered():
    for path in NOTEBOOKS:
        assert re.fullmatch(r"\d\d_[a-z0-9_]+\.ipynb", path.name), path.name


def test_every_notebook_is_collected_by_nbval():
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "--collect-only", "-q", "notebooks"],
        cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert result.returncode in (0, 5), result.stdout + result.stderr
    collected = {line.split("::")[0] for line in result.stdout.splitlines() if "::" in line}
    for path in NOTEBOOKS:
        assert f"notebooks/{path.name}" in collected, f"{path.name} is not collected by nbval"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_outputs_stored_from_a_top_to_bottom_run(path):
    cells = code_cells(load(path))
    counts = [c.get("execution_count") for c in cells]
    assert None not in counts, f"{path.name}: code cells without stored execution"
    assert counts == list(range(1, len(cells) + 1)), (
        f"{path.name}: execution counts {counts} are not 1..N: not one top-to-bottom run")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_no_errors_or_memory_addresses_in_stored_outputs(path):
    for cell in code_cells(load(path)):
        for output in cell.get("outputs", []):
            assert output["output_type"] != "error", f"{path.name}: stored error output"
            text = "".join(output.get("text", "")) + "".join(
                output.get("data", {}).get("text/plain", ""))
            assert not re.search(r"at 0x[0-9a-f]{6,}", text), f"{path.name}: memory address"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_teaching_structure(path):
    nb = load(path)
    first = nb["cells"][0]
    assert first["cell_type"] == "markdown" and "".join(first["source"]).lstrip().startswith("# ")
    text = markdown(nb).lower()
    for part in ("exercise", "solution", "reference"):
        assert part in text, f"{path.name}: no {part}s section"
    assert "$" in text, f"{path.name}: no LaTeX derivation"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_switched_off_output_checks_say_why(path):
    for cell in code_cells(load(path)):
        source = "".join(cell["source"])
        tags = set(cell.get("metadata", {}).get("tags", []))
        if IGNORE_MARKERS.search(source) or tags & {"nbval-ignore-output", "nbval-skip"}:
            comments = [ln for ln in source.splitlines()
                        if ln.startswith("#") and not IGNORE_MARKERS.match(ln)]
            assert comments, f"{path.name}: output check switched off without a reason"
