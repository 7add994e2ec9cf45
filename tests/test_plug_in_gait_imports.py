"""Issue 24, finding 6: plug_in_gait's imports at module level (no import inside a
function); the optional parsers of subject tables still say what to install."""

import ast
from pathlib import Path

import pytest

import bmc_functions.models.plug_in_gait as pig
import bmc_functions.models.plug_in_gait.subject as subject_module
from bmc_functions.models.plug_in_gait import load_subject

SOURCES = sorted(Path(pig.__file__).parent.glob("*.py"))


@pytest.mark.parametrize("source", SOURCES, ids=lambda path: path.name)
def test_no_import_inside_a_function(source):
    tree = ast.parse(source.read_text())
    inside = [f"{node.name}:{inner.lineno}"
              for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef,
                                                                ast.AsyncFunctionDef))
              for inner in ast.walk(node) if isinstance(inner, (ast.Import, ast.ImportFrom))]
    assert inside == []


@pytest.mark.parametrize("source", SOURCES, ids=lambda path: path.name)
def test_no_private_import_from_another_module(source):
    tree = ast.parse(source.read_text())
    private = [alias.name for node in tree.body if isinstance(node, ast.ImportFrom)
               for alias in node.names if alias.name.startswith("_")]
    assert private == []


def test_subject_table_in_toml_and_json(tmp_path):
    toml = tmp_path / "subject.toml"
    toml.write_text("[subject]\nLLEGLENGTH = 877.0\n")
    json = tmp_path / "subject.json"
    json.write_text('{"rightKneeWidth": 139.0}')
    assert load_subject(toml)[0] == {"LeftLegLength": 877.0}
    assert load_subject(json)[0] == {"RightKneeWidth": 139.0}


@pytest.mark.parametrize("suffix, attribute, package", [(".yaml", "yaml", "pyyaml"),
                                                        (".toml", "tomllib", "tomli")])
def test_subject_table_without_its_parser_says_what_to_install(tmp_path, monkeypatch,
                                                               suffix, attribute, package):
    monkeypatch.setattr(subject_module, attribute, None)     # as if the parser were not installed
    path = tmp_path / f"subject{suffix}"
    path.write_text("LLEGLENGTH: 877.0\n")
    with pytest.raises(ValueError, match=rf"subject: reading subject{suffix} needs the "
                                         rf"package .* \(pip install {package}\)"):
        load_subject(path)
