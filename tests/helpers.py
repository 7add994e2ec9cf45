"""Paths and loaders shared by several test modules."""

import importlib.util
import warnings
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


def write_c3d_points(path, xyz, labels, *, rate=120.0, units="mm", processing=None):
    """A C3D file (needs ezc3d) of the points `xyz` (frames, n, 3; NaN = not seen,
    written with a residual of -1 as Nexus does), with POINT:RATE and UNITS and,
    optionally, a PROCESSING group (name -> number): a modified copy of a real trial."""
    import ezc3d
    import numpy as np

    c3d = ezc3d.c3d()
    c3d["parameters"]["POINT"]["RATE"]["value"] = [float(rate)]
    c3d["parameters"]["POINT"]["LABELS"]["value"] = tuple(labels)
    c3d["parameters"]["POINT"]["UNITS"]["value"] = [units]
    points = np.ones((4, len(labels), len(xyz)))
    points[:3] = np.nan_to_num(xyz).transpose(2, 1, 0)
    c3d["data"]["points"] = points
    c3d["data"]["meta_points"]["residuals"] = np.where(
        np.isnan(xyz).any(axis=2), -1.0, 0.0).T[None]
    for name, value in (processing or {}).items():
        c3d.add_parameter("PROCESSING", name, [float(value)])
    c3d.write(str(path))
    return path


def synthetic_markers():
    """Role -> label of the synthetic trials of data/generate_marker_data.py (right leg,
    pelvis landmarks and cluster); a new dict at each call, for tests that change it."""
    return load_data_script("generate_marker_data").marker_roles(("right",))


def two_leg_markers():
    """Role -> label of the two-leg trials of data/generate_marker_data.py (both legs,
    pelvis landmarks and cluster); a new dict at each call."""
    return load_data_script("generate_marker_data").marker_roles()

def subject_without_static(df, asis="{}ASI", ankle="{}ANK", **more):
    """A Plug-in Gait subject (dict) for a real trial without its static or .vsk: each leg's
    length the median distance of its ASIS and ankle markers (labels `asis` and `ankle`,
    '{}' the side's L or R), knees 100 mm and ankles 70 mm wide, no static offsets, an
    inter-ASIS distance of 146 mm; `more` adds or replaces entries."""
    import numpy as np

    leg = {s: float(np.nanmedian(np.linalg.norm(df[asis.format(s)].to_numpy()
                                                - df[ankle.format(s)].to_numpy(), axis=1)))
           for s in "LR"}
    return {"LeftLegLength": leg["L"], "RightLegLength": leg["R"], "LeftKneeWidth": 100.0,
            "RightKneeWidth": 100.0, "LeftAnkleWidth": 70.0, "RightAnkleWidth": 70.0,
            "LeftStaticPlantFlex": 0.0, "RightStaticPlantFlex": 0.0, "LeftStaticRotOff": 0.0,
            "RightStaticRotOff": 0.0, "InterAsisDistance": 146.0, **more}


#: Role -> label of the functional trials of data/functional (data/generate_functional_data.py).
FUNCTIONAL_MARKERS = {"RASIS": "RASI", "LASIS": "LASI", "RPSIS": "RPSI", "LPSIS": "LPSI",
                      "RTHIGH": ["RTH1", "RTH2", "RTH3", "RTH4"], "RKNEE_LAT": "RLFC",
                      "RKNEE_MED": "RMFC", "RSHANK": ["RTB1", "RTB2", "RTB3", "RTB4"],
                      "RANKLE_LAT": "RLMAL", "RANKLE_MED": "RMMAL", "RHEEL": "RHEEL",
                      "RTOE": "RTOE", "RMT5": "RMT5"}


def warning_messages(function, *args, **kwargs):
    """The messages of every warning `function(*args, **kwargs)` issues."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        function(*args, **kwargs)
    return [str(w.message) for w in caught]


def swapped(df, a, b, rows=slice(None)):
    """A copy of the marker table `df` with markers `a` and `b` swapped in `rows`."""
    out = df.copy()
    index = out.index[rows]
    first = out.loc[index, a].to_numpy()
    out.loc[index, a] = out.loc[index, b].to_numpy()
    out.loc[index, b] = first
    return out
