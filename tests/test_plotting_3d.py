"""3D figures must be right-handed: a right knee drawn as a right knee.

The test measures what a reader sees. Each lab axis is pushed through the figure's own
projection (``ax.get_proj()``) at the centre of the plot; on the screen, x points right, y
up, and the third direction out of the screen towards the reader. A right-handed lab frame
must map onto that right-handed screen frame with a positive determinant. Matplotlib's
3D axes are right-handed (checked first, so that the measure itself is tested); a figure
that plots the lab's (x, z, y) on them is a mirror image (det < 0), whatever the camera.
"""

import json
import pathlib
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from mpl_toolkits.mplot3d import proj3d  # noqa: E402

from bmc_functions.plotting import set_lab_view  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]
VIEWS = [(1, 0.3, 0.4), (0.5, 0.3, 1), (-1, 0.5, 0.2), (0.2, -0.4, -1), (1, 1, 1)]


def screen_frame(ax, to_axes=lambda p: p):
    """(3, 3): columns are the lab's x, y, z on the screen (right, up, out of the screen).

    `to_axes` is the linear map from lab coordinates to the coordinates plotted on the
    axes: the identity when the lab is plotted as it is, a permutation for the old
    (x, z, y) recipe. The derivative is taken at the centre of the plot.
    """
    M = ax.get_proj()
    lo, hi = np.array(ax.get_w_lims()).reshape(3, 2).T
    centre, h = (lo + hi) / 2, 1e-4 * np.max(hi - lo)

    def screen(q):
        xs, ys, depth = proj3d.proj_transform(*q, M)
        return np.array([xs, ys, -depth])      # matplotlib's depth grows away from the reader

    step = [np.asarray(to_axes(h * e), dtype=float) for e in np.eye(3)]
    return np.column_stack([(screen(centre + d) - screen(centre - d)) / (2 * h) for d in step])


def new_axes(limits=((-1, 1), (-0.5, 1.5), (0, 2))):
    ax = plt.figure().add_subplot(projection="3d")
    ax.set_xlim(*limits[0])
    ax.set_ylim(*limits[1])
    ax.set_zlim(*limits[2])
    return ax


def teardown_function():
    plt.close("all")


def test_depth_sign_of_the_measure():
    # seen from above (z up, elevation 90 deg), the top of the box is nearer the reader
    ax = new_axes()
    ax.view_init(elev=90, azim=-90)
    assert screen_frame(ax)[2, 2] > 0


@pytest.mark.parametrize("elev, azim", [(20, -60), (15, 35), (-30, 120), (80, 10)])
def test_matplotlib_axes_are_right_handed(elev, azim):
    ax = new_axes()
    ax.view_init(elev=elev, azim=azim)
    assert np.linalg.det(screen_frame(ax)) > 0


@pytest.mark.parametrize("view_from", VIEWS)
@pytest.mark.parametrize("vertical", ["x", "y", "z"])
def test_set_lab_view_is_right_handed_and_upright(view_from, vertical):
    ax = set_lab_view(new_axes(), view_from=view_from, vertical=vertical)
    S = screen_frame(ax)
    assert np.linalg.det(S) > 0
    up = S[:, "xyz".index(vertical)]
    assert up[1] > 0 and abs(up[0]) < 1e-6 * np.linalg.norm(up)    # vertical and upwards
    # the camera stands where it was asked to: view_from points out of the screen
    towards_reader = np.linalg.solve(S, [0, 0, 1])                  # lab direction of w
    cos = towards_reader @ view_from / np.linalg.norm(towards_reader) / np.linalg.norm(view_from)
    assert cos > 0.9     # perspective: the centre's line of sight is the view direction


def test_front_view_puts_the_subjects_right_on_the_readers_left():
    # lab x forwards, y up, z right, seen from the front: the subject's right (+z) is on
    # the reader's left, as when facing a person
    ax = set_lab_view(new_axes(), view_from=(1, 0, 0))
    S = screen_frame(ax)
    assert S[0, 2] < 0 and S[1, 1] > 0


@pytest.mark.parametrize("elev, azim", [(15, 35), (10, -35), (15, -60), (12, -55)])
def test_the_old_xzy_recipe_is_caught_as_a_mirror_image(elev, azim):
    # plot the lab's (x, z, y) on matplotlib's (X, Y, Z), with its vertical Z: the lab's y
    # stands upright but the figure is reflected, at every camera angle
    ax = new_axes()
    ax.view_init(elev=elev, azim=azim)
    S = screen_frame(ax, to_axes=lambda p: np.asarray(p)[[0, 2, 1]])
    assert S[1, 1] > 0                        # upright ...
    assert np.linalg.det(S) < 0               # ... and mirrored


# The notebooks: no 3D figure may swap two lab axes to stand a y-up lab upright.
SWAPS = [re.compile(p) for p in (
    r"\[\s*0\s*,\s*2\s*,\s*1\s*\]",                                       # [..., [0, 2, 1]]
    r"\[\[\s*1\s*,\s*0\s*,\s*0\s*\]\s*,\s*\[\s*0\s*,\s*0\s*,\s*1\s*\]\s*,\s*\[\s*0\s*,\s*1\s*,\s*0\s*\]\]",
    r"\[:\s*,\s*0\]\s*,\s*\w+\[:\s*,\s*2\]\s*,\s*\w+\[:\s*,\s*1\]",     # a[:, 0], a[:, 2], a[:, 1]
)]


@pytest.mark.parametrize("path", sorted((ROOT / "notebooks").glob("*.ipynb")),
                         ids=lambda p: p.name)
def test_no_notebook_plots_swapped_axes_in_3d(path):
    cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
    for cell in cells:
        source = "".join(cell["source"])
        if cell["cell_type"] != "code" or not re.search(r"projection\s*=\s*['\"]3d", source):
            continue
        for pattern in SWAPS:
            match = pattern.search(source)
            assert match is None, (
                f"{path.name}: a 3D figure swaps two lab axes ({match.group(0)!r}): a mirror "
                "image. Plot the lab's coordinates as they are and call "
                "bmc_functions.plotting.set_lab_view(ax, vertical='y')")


@pytest.mark.parametrize("kwargs, message", [
    (dict(view_from=(0, 0, 0)), "view_from must be one nonzero 3-vector"),
    (dict(view_from=(1, 2)), "view_from must have shape"),
    (dict(view_from=(1, np.nan, 0)), "view_from"),
    (dict(vertical="up"), "vertical must be 'x' or 'y' or 'z'"),
    (dict(labels=("x", "y")), "labels must be three strings"),
    (dict(labels="xyz"), "labels must be three strings"),
])
def test_set_lab_view_refuses_bad_input(kwargs, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        set_lab_view(new_axes(), **kwargs)
