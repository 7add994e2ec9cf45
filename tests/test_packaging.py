"""The package as a user installs it: a wheel built with ``python -m build``, installed in a
fresh virtual environment, away from the repository, where ``import bmc_functions``, every
docstring example and the command line must work.

The fresh environment gets the wheel (``pip install --no-deps``) and sees this
environment's installed packages (numpy, pandas, pytest, ...) through a path file, so no
download is needed beyond what ``python -m build`` fetches to build; it does not see the
repository (no PYTHONPATH, no editable install, run from a temporary folder), and the test
checks that the imported package is the wheel's.
"""

import filecmp
import importlib.util
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from helpers import ROOT

from bmc_functions.examples import example_file


def test_the_example_trials_are_the_repository_trials():
    # bmc_functions/example_data ships data/markers' trials for the docstrings: the same
    # bytes, so the examples' numbers are those of the repository's data
    for name in ("markers/static.trc", "markers/walk.trc", "gait/walk.trc"):
        assert filecmp.cmp(example_file(name), ROOT / "data" / name, shallow=False), name
    for name in ("Static_trial.c3d", "Movement_trial.c3d", "Test.vsk", "LICENSE"):
        assert filecmp.cmp(example_file("plug_in_gait/" + name),
                           ROOT / "data" / "real" / "plug_in_gait" / name, shallow=False), name


def test_example_file_refuses_an_unknown_name():
    with pytest.raises(ValueError, match=r"name must be one of 'gait/walk.trc', "
                                         r"'markers/markers.toml', 'markers/static.trc', "
                                         r"'markers/walk.trc', 'plug_in_gait/LICENSE', .*"
                                         r"; got 'run.trc'"):
        example_file("run.trc")


def run(command, **kwargs):
    result = subprocess.run(command, capture_output=True, text=True, **kwargs)
    assert result.returncode == 0, (command, result.stdout[-3000:], result.stderr[-3000:])
    return result


@pytest.mark.skipif(importlib.util.find_spec("build") is None,
                    reason="python -m build is not installed (it is in the test extra)")
def test_the_wheel_works_in_a_fresh_environment_without_the_repository(tmp_path):
    # build from a copy of what the project declares (pyproject.toml names the package,
    # README.md and LICENSE): setuptools writes build/ and *.egg-info into its source
    # folder, and a stale build/lib could slip a deleted module into the wheel
    source = tmp_path / "source"
    shutil.copytree(ROOT / "bmc_functions", source / "bmc_functions",
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        shutil.copy(ROOT / name, source / name)
    dist = tmp_path / "dist"
    run([sys.executable, "-m", "build", "--wheel", "--outdir", str(dist), str(source)],
        timeout=300)
    wheel, = dist.glob("bmc_functions-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert "bmc_functions/example_data/gait/walk.trc" in names
    assert "bmc_functions/example_data/markers/markers.toml" in names
    assert not any(name.startswith(("tests/", "data/", "notebooks/")) for name in names)

    # a fresh environment: the wheel, and this environment's packages as dependencies
    venv = tmp_path / "venv"
    run([sys.executable, "-m", "venv", "--without-pip", str(venv)], timeout=120)
    python = venv / ("Scripts/python.exe" if os.name == "nt" else "bin/python")
    site = Path(run([str(python), "-c", "import sysconfig; "
                     "print(sysconfig.get_paths()['purelib'])"]).stdout.strip())
    dependencies = {sysconfig.get_paths()[key] for key in ("purelib", "platlib")}
    (site / "dependencies.pth").write_text("\n".join(sorted(dependencies)) + "\n")
    # --ignore-installed: this environment's own (editable) install of the package is
    # visible through the path file; it is neither used nor touched
    run([sys.executable, "-m", "pip", "--python", str(python), "install", "--no-deps",
         "--no-index", "--ignore-installed", "-q", str(wheel)], timeout=300)

    work = tmp_path / "elsewhere"
    work.mkdir()
    env = {key: value for key, value in os.environ.items()
           if key not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["MPLBACKEND"] = "Agg"
    where = run([str(python), "-c", "import bmc_functions; print(bmc_functions.__file__)"],
                cwd=work, env=env, timeout=120).stdout.strip()
    installed = site / "bmc_functions"
    assert Path(where).parent == installed, where

    # every docstring example, from the installed files only
    (work / "pytest.ini").write_text("[pytest]\ndoctest_optionflags = NORMALIZE_WHITESPACE "
                                     "NUMBER\n")
    doctests = run([str(python), "-m", "pytest", "-c", "pytest.ini", "-q", "-p",
                    "no:cacheprovider",
                    "--doctest-modules", str(installed)], cwd=work, env=env, timeout=600)
    assert " passed" in doctests.stdout and "failed" not in doctests.stdout

    # the command line, on the example trials the wheel ships
    script = venv / ("Scripts/bmc-kinematics.exe" if os.name == "nt" else
                     "bin/bmc-kinematics")
    data = installed / "example_data" / "markers"
    run([str(script), "angles", "--static", str(data / "static.trc"), "--markers",
         str(data / "markers.toml"), str(data / "walk.trc"), "-o", "out", "-q"],
        cwd=work, env=env, timeout=300)
    for name in ("walk_angles.mot", "walk_angles.csv", "walk_events.csv", "walk_angles.png",
                 "walk_angles.json"):
        assert (work / "out" / name).is_file(), name
    assert "bmc-kinematics" in run([str(python), "-m", "bmc_functions", "--help"], cwd=work,
                                   env=env, timeout=120).stdout
