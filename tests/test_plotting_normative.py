"""plot_gait_cycles as a clinical report draws it (issue 30): the lab's normal band behind
each curve, fixed clinical y ranges, the cycles of each side in the title."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.colors as mcolors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from bmc_functions import normative_data  # noqa: E402
from bmc_functions.plotting import (CLINICAL_RANGES, MIN_RANGE, NORMAL_COLOR,  # noqa: E402
                                    SIDE_COLORS, plot_gait_cycles)

PERCENT = np.linspace(0, 100, 101)


def cycles_of(curves, columns):
    """{column: (cycles, 101) array} -> a normalize_by_side-like table."""
    n = max(len(c) for c in curves)
    index = pd.MultiIndex.from_product([range(n), PERCENT], names=["cycle", "percent"])
    data = np.full((n * 101, len(columns)), np.nan)
    for k, curve in enumerate(curves):
        data[:len(curve) * 101, k] = np.asarray(curve).ravel()
    return pd.DataFrame(data, index=index, columns=pd.MultiIndex.from_tuples(columns))


@pytest.fixture(autouse=True)
def close():
    yield
    plt.close("all")


def knee_cycles():
    wave = 30 + 30 * np.sin(np.pi * PERCENT / 100) ** 2
    return cycles_of([np.stack([wave, wave + 2]), wave[None] + 1.0],
                     [("knee", "right", "flexion"), ("knee", "left", "flexion")])


def test_the_normal_band_is_drawn_behind_both_sides_in_grey():
    cycles = knee_cycles()
    normative = normative_data(cycles)
    fig, axes = plot_gait_cycles(cycles, normative=normative)
    ax = axes[0, 0]
    grey = [c for c in ax.collections
            if np.allclose(c.get_facecolor()[0][:3], mcolors.to_rgb(NORMAL_COLOR))]
    assert len(grey) == 1 and grey[0].get_zorder() < min(line.get_zorder()
                                                         for line in ax.lines)
    band = grey[0].get_paths()[0].vertices
    expected = normative["mean"][("knee", "flexion")] + normative["sd"][("knee", "flexion")]
    assert np.isclose(band[:, 1].max(), expected.max())
    colours = {line.get_label(): mcolors.to_hex(line.get_color()) for line in ax.lines
               if line.get_label() in SIDE_COLORS}
    assert colours == {side: mcolors.to_hex(c) for side, c in SIDE_COLORS.items()}
    assert "normal" in [text.get_text() for text in fig.legends[0].get_texts()]


def test_the_title_counts_the_cycles_of_each_side():
    fig, _ = plot_gait_cycles(knee_cycles(), title="walk 3")
    assert fig._suptitle.get_text() == "walk 3: right 2 cycles, left 1 cycle"


def test_a_quarter_degree_is_drawn_on_the_clinical_range():
    """A hip rotation that wobbles 0.25 degree stays flat on the -30..30 degree scale; a
    knee flexion beyond the range widens it; an angle without a range gets MIN_RANGE."""
    wobble = 5 + 0.125 * np.sin(2 * np.pi * PERCENT / 100)
    cycles = cycles_of([wobble[None], 120 * np.sin(np.pi * PERCENT / 100)[None],
                        wobble[None]],
                       [("hip", "right", "rotation"), ("knee", "right", "flexion"),
                        ("trunk", "right", "lean")])
    _, axes = plot_gait_cycles(cycles)
    panels = {ax.get_title(): ax.get_ylim() for ax in axes.ravel() if ax.get_visible()}
    assert panels["hip rotation"] == pytest.approx(CLINICAL_RANGES["hip", "rotation"])
    low, high = panels["knee flexion"]
    assert low == CLINICAL_RANGES["knee", "flexion"][0] and high > 120
    low, high = panels["trunk lean"]
    assert high - low == pytest.approx(MIN_RANGE) and low < 5 < high
    _, axes = plot_gait_cycles(cycles, clinical_ranges=False)
    low, high = axes[0, 0].get_ylim()
    assert high - low < 6.0                    # matplotlib's own: the curve (5 deg) and 0


def test_a_bad_normative_is_named():
    with pytest.raises(ValueError, match="normative must be the table"):
        plot_gait_cycles(knee_cycles(), normative=pd.DataFrame({"a": [1.0]}))
