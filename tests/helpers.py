"""Paths and loaders shared by several test modules."""

import importlib.util
from pathlib import Path

#: The repository root.
ROOT = Path(__file__).resolve().parents[1]

#: Real recordings (validation data) kept beside the checkout, not in it; tests that use
#: them skip when the folder is absent.
SHARED_DATA = ROOT.parent / "shared" / "data"


def load_data_script(name):
    """Import a generator script of data/ (e.g. 'generate_marker_data') as a module."""
    spec = importlib.util.spec_from_file_location(name, ROOT / "data" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
