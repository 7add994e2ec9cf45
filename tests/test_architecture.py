"""The package's architecture, checked: layers that import only downwards, no import
cycles, no private names across modules, one warning mechanism, short functions.

These are the rules of issue 24 (README, "How the package is organised"); a change that
breaks one fails here with the file and line to look at.
"""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "bmc_functions"
MODULES = sorted(PACKAGE.rglob("*.py"))

#: The layers, lowest first: a module may import from its own layer and the ones below.
#: The shared utilities (input checks, BLAS threads, the batch runner, the example files)
#: are below everything; the command line and the figures above everything.
#: ``dynamics`` (segment parameters, Newton-Euler) sits below ``models``: arrays in, arrays
#: out, it needs segment frames and joint centres as arrays, not the models' code, and the
#: models' ``kinetics()`` methods call it (issue 29).
LAYERS = {"utilities": 0, "rigid_body": 1, "files": 2, "markers": 3, "dynamics": 4, "models": 5,
          "gait": 6, "applications": 7}
UTILITIES = {"_checks", "_threads", "batch", "examples"}

#: Function bodies (docstring aside) longer than this many lines are split into named
#: steps; the few listed below say why they are not.
MAX_BODY_LINES = 80
LONG_FUNCTIONS = {}

#: Modules whose imports inside functions are deliberate: the command line imports the
#: models, matplotlib and the file readers only for the subcommand that runs, so that
#: `bmc-kinematics --help` starts fast.
LAZY_IMPORTS = {"cli.py"}


def layer(module):
    """The layer of a module given as its path parts below the package."""
    if len(module) > 1:
        return LAYERS[module[0]]
    name = module[0].removesuffix(".py")
    if name in UTILITIES or name == "__init__":
        return LAYERS["utilities"] if name != "__init__" else LAYERS["applications"]
    return LAYERS["applications"]


def relative(path):
    return path.relative_to(PACKAGE).parts


def imported_modules(path, tree):
    """(line, module parts below the package, names) of every relative import."""
    here = relative(path)[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = here[:len(here) - (node.level - 1)] if node.level > 1 else here
            target = tuple(base) + tuple((node.module or "").split(".") if node.module else ())
            yield node, target, [alias.name for alias in node.names]


def module_file(target):
    """The file of a module given as parts below the package, or None for a package."""
    file = PACKAGE.joinpath(*target).with_suffix(".py")
    return file if file.exists() else None


@pytest.fixture(scope="module")
def trees():
    return {path: ast.parse(path.read_text(encoding="utf-8")) for path in MODULES}


def test_layers_import_only_downwards(trees):
    found = []
    for path, tree in trees.items():
        for node, target, names in imported_modules(path, tree):
            if not target:          # `from . import x` inside a package's __init__
                continue
            file = module_file(target)
            parts = relative(file) if file else tuple(target) + ("__init__.py",)
            if layer(parts) > layer(relative(path)):
                found.append(f"{path.relative_to(PACKAGE)}:{node.lineno} imports "
                             f"{'.'.join(target)}")
    assert not found, "\n".join(found)


def test_no_private_names_imported_across_modules(trees):
    found = [f"{path.relative_to(PACKAGE)}:{node.lineno} imports {name} from "
             f"{'.'.join(target)}"
             for path, tree in trees.items()
             for node, target, names in imported_modules(path, tree)
             for name in names if name.startswith("_") and not name.startswith("__")]
    assert not found, "\n".join(found)


def test_no_imports_inside_functions_to_dodge_cycles(trees):
    found = []
    for path, tree in trees.items():
        if path.name in LAZY_IMPORTS:
            continue
        for function in ast.walk(tree):
            if isinstance(function, (ast.FunctionDef, ast.AsyncFunctionDef)):
                found += [f"{path.relative_to(PACKAGE)}:{node.lineno}"
                          for node in ast.walk(function)
                          if isinstance(node, ast.ImportFrom) and node.level]
    assert not found, "\n".join(found)


def test_no_import_cycles(trees):
    graph = {}
    for path, tree in trees.items():
        edges = graph.setdefault(relative(path), set())
        for node in tree.body:                     # module-level imports only
            if isinstance(node, ast.ImportFrom) and node.level:
                for _, target, names in imported_modules(path, ast.Module([node], [])):
                    file = module_file(target)
                    if file is not None:
                        edges.add(relative(file))
    state = {}

    def visit(node, stack):
        state[node] = "open"
        for child in graph.get(node, ()):
            if state.get(child) == "open":
                raise AssertionError(" -> ".join("/".join(p) for p in stack + [child]))
            if child not in state:
                visit(child, stack + [child])
        state[node] = "done"

    for node in graph:
        if node not in state:
            visit(node, [node])


def test_every_warning_goes_through_checks_warn(trees):
    """One mechanism attributes warnings to the user's line (`_checks.warn`)."""
    found = []
    for path, tree in trees.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.Call):
                called = ast.unparse(node.func)
                uses_stacklevel = any(k.arg == "stacklevel" for k in node.keywords)
                if (called == "warnings.warn" or uses_stacklevel) and path.name != "_checks.py":
                    found.append(f"{path.relative_to(PACKAGE)}:{node.lineno}")
    assert not found, "\n".join(found)


def body_lines(function):
    body = function.body
    if (isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str) and len(body) > 1):
        body = body[1:]
    return function.end_lineno - body[0].lineno + 1


def test_function_bodies_are_short(trees):
    long = {f"{path.relative_to(PACKAGE).as_posix()}:{node.name}": body_lines(node)
            for path, tree in trees.items() for node in ast.walk(tree)
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
            and body_lines(node) > MAX_BODY_LINES}
    too_long = [f"{name}: {lines} lines" for name, lines in long.items()
                if name not in LONG_FUNCTIONS]
    assert not too_long, "\n".join(too_long)
    assert len(LONG_FUNCTIONS) <= 3


def test_the_rules_can_fail(tmp_path):
    """The checks above see a violation when there is one (they are not vacuous)."""
    tree = ast.parse("from ..models.lower_limb import _calibrate\n"
                     "def f():\n    from .x import y\n" + "    z = 1\n" * 90)
    function = tree.body[1]
    assert body_lines(function) == 91
    path = PACKAGE / "files" / "example.py"
    (_, target, names), = list(imported_modules(path, ast.Module([tree.body[0]], [])))
    assert target == ("models", "lower_limb") and names == ["_calibrate"]
    assert layer(("models", "lower_limb.py")) > layer(("files", "example.py"))
