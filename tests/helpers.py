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


#: The one wording of the skip reason of every test that needs SHARED_DATA.
SKIP_SHARED = f"real recordings not found at {SHARED_DATA} (../shared/data beside the checkout)"


def shared_data_present(*names):
    """True when SHARED_DATA holds every one of `names` (or exists, without names)."""
    return SHARED_DATA.is_dir() and all((SHARED_DATA / name).exists() for name in names)


def needs_shared(*names):
    """A pytest mark: skip, with SKIP_SHARED, unless SHARED_DATA holds `names`."""
    import pytest

    return pytest.mark.skipif(not shared_data_present(*names), reason=SKIP_SHARED)


def skip_without_shared(*names):
    """Inside a test or fixture: skip, with SKIP_SHARED, unless SHARED_DATA holds `names`."""
    import pytest

    if not shared_data_present(*names):
        pytest.skip(SKIP_SHARED)
