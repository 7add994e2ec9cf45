"""The project's promises: the README's test command is what CI runs, the README lists
every notebook, the public API imports, and the versions agree."""

import pathlib
import re

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

import bmc_functions

ROOT = pathlib.Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def readme_command(marker):
    """The first line of the README's shell block that contains `marker`."""
    blocks = re.findall(r"```(?:bash|sh)\n(.*?)```", README, re.S)
    lines = [ln.strip() for block in blocks for ln in block.splitlines() if marker in ln]
    assert lines, f"no command with {marker!r} in README.md"
    return lines[0]


def test_ci_runs_the_readme_test_command():
    command = readme_command("python -m pytest")
    ci_lines = [ln.strip() for ln in (ROOT / ".ci" / "run").read_text().splitlines()]
    assert command in ci_lines


def test_readme_lab_command_installs_and_opens_jupyterlab():
    command = readme_command("jupyter lab")
    assert 'pip install -e ".[lab]"' in command and "-m venv" in command


def test_readme_lists_every_notebook():
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        assert path.name in README, f"README.md does not list {path.name}"


def test_public_api_imports():
    from bmc_functions import compose, decompose, get_R, svdt  # noqa: F401
    for name in bmc_functions.__all__:
        assert callable(getattr(bmc_functions, name)), name


def test_versions_agree():
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())
    version = pyproject["project"]["version"]
    assert bmc_functions.__version__ == version
    citation = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert re.search(rf"^version: {re.escape(version)}$", citation, re.M)
    assert f"## [{version}]" in (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")


def test_pytest_runs_tests_doctests_and_every_notebook_under_strict_nbval():
    options = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["pytest"][
        "ini_options"]
    assert set(options["testpaths"]) == {"tests", "bmc_functions", "notebooks"}
    addopts = options["addopts"].split()
    assert {"--doctest-modules", "--nbval", "--nbval-current-env"} <= set(addopts)
    assert "--nbval-lax" not in addopts


def test_readme_usage_example_runs_and_says_what_it_computes():
    block = re.findall(r"```python\n(.*?)```", README, re.S)[0]
    namespace = {}
    exec(compile(block, "README.md", "exec"), namespace)
    import numpy as np
    np.testing.assert_allclose(namespace["angles"], [90, 0, 0], atol=1e-12)
    np.testing.assert_allclose(namespace["R_back"], namespace["R"], atol=1e-15)


def test_readme_book_command_installs_and_builds_the_book():
    command = readme_command("tools/build_book.py")
    assert 'pip install -e ".[book]"' in command and "-m venv" in command
