"""Tests of the gait figures of bmc_functions.plotting: plot_angles (one trial over time)
and what plot_gait_cycles says when there is nothing to draw."""

import gc
import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from bmc_functions.plotting import SIDE_COLORS, plot_angles, plot_gait_cycles  # noqa: E402


def trial(joints=("ankle", "hip", "knee", "pelvis"), n=200):
    """A DataFrame like LowerLimbModel.angles: known curves, columns out of clinical order."""
    planes = {"pelvis": ("rotation", "tilt", "obliquity"),
              "ankle": ("inversion", "dorsiflexion", "rotation")}
    columns = [(j, s, a) for j in joints for s in ("left", "right")
               for a in planes.get(j, ("rotation", "adduction", "flexion"))]
    time = pd.Index(np.arange(n) / 100, name="time")
    values = np.sin(np.outer(time, np.arange(1, len(columns) + 1)))
    df = pd.DataFrame(values, index=time, columns=pd.MultiIndex.from_tuples(columns))
    df.attrs["units"] = "deg"
    return df


EVENTS = {"right": {"heel_strike": np.array([0.1, 1.2]), "toe_off": np.array([0.75])},
          "left": {"heel_strike": np.array([0.65]), "toe_off": np.array([0.2, 1.3])}}


def test_plot_angles_panels_in_clinical_order_with_the_curves():
    angles = trial()
    fig, axes = plot_angles(angles)
    assert axes.shape == (4, 3)
    assert [ax.get_title() for ax in axes[:, 0]] == ["pelvis tilt", "hip flexion",
                                                    "knee flexion", "ankle dorsiflexion"]
    assert [ax.get_title() for ax in axes[1]] == ["hip flexion", "hip adduction",
                                                 "hip rotation"]
    ax = axes[2, 0]                                     # knee flexion: right, then left
    right, left = ax.lines[:2]
    assert right.get_color() == SIDE_COLORS["right"] and left.get_color() == SIDE_COLORS["left"]
    np.testing.assert_array_equal(right.get_ydata(), angles["knee", "right", "flexion"])
    np.testing.assert_array_equal(left.get_xdata(), angles.index.to_numpy())
    assert axes[3, 0].get_ylabel() == "Plan − / Dors + (deg)"
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["right", "left"]
    plt.close(fig)


def test_plot_angles_marks_every_event_in_every_panel():
    fig, axes = plot_angles(trial(("knee",)), EVENTS, title="walk 1")
    ax = axes[0, 0]
    vertical = [line for line in ax.lines if len(set(line.get_xdata())) == 1]
    assert len(vertical) == 6
    solid = sorted(line.get_xdata()[0] for line in vertical if line.get_linestyle() == "-")
    dotted = sorted(line.get_xdata()[0] for line in vertical if line.get_linestyle() == ":")
    assert solid == [0.1, 0.65, 1.2] and dotted == [0.2, 0.75, 1.3]
    colors = {line.get_xdata()[0]: line.get_color() for line in vertical}
    assert colors[0.65] == SIDE_COLORS["left"] and colors[0.75] == SIDE_COLORS["right"]
    assert fig._suptitle.get_text() == "walk 1"
    assert [t.get_text() for t in fig.legends[0].get_texts()] == [
        "right", "left", "heel strike", "toe-off"]
    plt.close(fig)


def test_plot_angles_a_side_without_data_is_left_out():
    angles = trial(("knee",))
    angles.loc[:, ("knee", "left")] = np.nan
    fig, axes = plot_angles(angles)
    assert len([line for line in axes[0, 0].lines if len(line.get_xdata()) > 2]) == 1
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["right"]
    plt.close(fig)


def test_plot_angles_labels_time_under_the_lowest_panel_of_each_column():
    # the knee has flexion only: below hip adduction and rotation there is no panel, so
    # their time axis is labelled there; below hip flexion, the knee's is
    angles = trial(("hip", "knee"))
    angles = angles[[c for c in angles.columns if c[0] == "hip" or c[2] == "flexion"]]
    fig, axes = plot_angles(angles)
    assert [ax.get_visible() for ax in axes[1]] == [True, False, False]
    assert [ax.get_xlabel() for ax in axes[0]] == ["", "time (s)", "time (s)"]
    assert axes[1, 0].get_xlabel() == "time (s)"
    plt.close(fig)


@pytest.mark.parametrize("plot", ["angles", "cycles"])
def test_a_side_is_drawn_only_in_the_panels_of_its_angles(plot):
    # the left knee has flexion only: the adduction panel draws the right side alone
    angles = trial(("knee",))
    angles = angles.drop(columns=[("knee", "left", "adduction"), ("knee", "left", "rotation")])
    if plot == "angles":
        fig, axes = plot_angles(angles)
    else:
        cycles = angles.set_axis(pd.MultiIndex.from_product(
            [range(2), np.linspace(0, 100, 100)], names=["cycle", "percent"]))
        fig, axes = plot_gait_cycles(cycles, sd=False)
    colors = [[line.get_color() for line in ax.lines if len(line.get_xdata()) > 2]
              for ax in axes[0]]
    assert colors == [[SIDE_COLORS["right"], SIDE_COLORS["left"]], [SIDE_COLORS["right"]],
                      [SIDE_COLORS["right"]]]
    plt.close(fig)


def test_plot_angles_refuses_what_it_cannot_draw():
    angles = trial(("knee",))
    with pytest.raises(TypeError, match=r"angles must be a pandas DataFrame; got ndarray"):
        plot_angles(angles.to_numpy())
    many = pd.concat([angles, angles], keys=["walk1", "walk2"], names=["trial", "time"])
    with pytest.raises(ValueError, match=r"2 row index levels \['trial', 'time'\]; plot "
                                         r"one trial, e.g. angles.loc\['walk1'\]"):
        plot_angles(many)
    with pytest.raises(ValueError, match=r"three-level \(joint, side, angle\) columns"):
        plot_angles(pd.DataFrame({"a": [1.0]}))
    with pytest.raises(ValueError, match=r"no finite value \(200 rows\)"):
        plot_angles(angles * np.nan)
    with pytest.raises(TypeError, match=r"events must be the dict of gait_events"):
        plot_angles(angles, [0.1, 0.2])
    with pytest.raises(ValueError, match=r"events\['right'\]\['toe_off'\] must be finite"):
        plot_angles(angles, {"right": {"heel_strike": [0.1], "toe_off": [np.inf]}})
    plt.close("all")


def cycles_frame(n_cycles):
    index = pd.MultiIndex.from_product([range(n_cycles), np.linspace(0, 100, 11)],
                                       names=["cycle", "percent"])
    columns = pd.MultiIndex.from_product([["knee"], ["right", "left"], ["flexion"]])
    return pd.DataFrame(1.0, index=index, columns=columns)


@pytest.mark.parametrize("cycles", [cycles_frame(0), cycles_frame(2) * np.nan])
def test_plot_gait_cycles_says_there_is_no_cycle(cycles):
    # a trial with fewer than two heel strikes of each side: no empty panels without a word
    with pytest.raises(ValueError, match=r"cycles holds no complete gait cycle .* two heel "
                                         r"strikes of one side"):
        plot_gait_cycles(cycles)
    assert not plt.get_fignums()


def test_plot_gait_cycles_table_without_stance():
    table = pd.DataFrame({"cadence": [110.0, 111.0]}, index=["right", "left"])
    with pytest.raises(ValueError, match=r"toe_off: the table has no 'stance' column \(its "
                                         r"columns: cadence\)"):
        plot_gait_cycles(cycles_frame(2), table)
    assert not plt.get_fignums()


# --- the 3D view of a trial ------------------------------------------------------------------

def walking_trial():
    import warnings

    from bmc_functions import calibrate_lower_limb, read_trc
    from bmc_functions import read_marker_mapping
    from bmc_functions.examples import example_file

    walk = read_trc(example_file("markers/walk.trc"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                       # the occlusion gaps
        model = calibrate_lower_limb(example_file("markers/static.trc"),
                                     read_marker_mapping(example_file("markers/markers.toml")))
        return walk, model.track(walk).frames


def test_plot_trial_3d_draws_the_lab_coordinates_unpermuted_with_y_up():
    from bmc_functions.plotting import plot_trial_3d

    walk, frames = walking_trial()
    ax = plot_trial_3d(walk, frames, time=0.504)              # nearest row: 0.50 s
    assert ax.get_title() == "t = 0.500 s"
    row = walk.loc[0.5].to_numpy().reshape(-1, 3)
    row = row[~np.isnan(row).any(axis=1)]
    dots = ax.lines[0]
    # x, y, z of the lab are matplotlib's X, Y, Z: right-handed, never (x, z, y)
    np.testing.assert_array_equal(np.array(dots.get_data_3d()).T, row)
    assert ax._vertical_axis == 1        # view_init(vertical_axis="y"): the lab's y is up
    # a segment frame: its x axis drawn from the origin along R[:, 0], 100 mm long
    R, origin = frames[("thigh", "right")]
    k = walk.index.get_loc(0.5)
    x_axis = np.array(ax.lines[1 + 3 * list(frames).index(("thigh", "right"))]
                      .get_data_3d()).T
    np.testing.assert_allclose(x_axis, [origin[k], origin[k] + 100 * R[k, :, 0]])
    # the box holds the body at that instant, one scale on all three axes
    limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()])
    assert np.allclose(np.diff(limits, axis=1), np.diff(limits, axis=1)[0])
    assert ((limits[:, 0] <= row.min(axis=0)) & (row.max(axis=0) <= limits[:, 1])).all()
    plt.close("all")


def test_animate_trial_plays_offline_and_follows_the_subject():
    from bmc_functions.plotting import animate_trial, animation_html

    walk, frames = walking_trial()
    animation = animate_trial(walk, frames, step=25, vertical_axis="y")
    html = animation_html(animation)
    assert html.count("data:image/png") == len(range(0, len(walk), 25))
    # offline: matplotlib's player links an icon font on a CDN; not this one
    assert "font-awesome" in animation.to_jshtml() and "http" not in html
    assert '<i class="fa' not in html and "&#9654;" in html       # the buttons: text
    assert animation_html(animation) == html                 # the same output every run
    ax = animation._fig.axes[0]
    animation._func(len(walk) - 1, *animation._args)          # the last frame
    assert ax.get_title() == f"t = {walk.index[-1]:.3f} s"
    x = walk.xs("x", axis=1, level=1).iloc[-1]
    assert ax.get_xlim3d()[0] <= x.min() and x.max() <= ax.get_xlim3d()[1]
    plt.close("all")


def test_the_3d_view_refuses_what_it_cannot_draw():
    from bmc_functions.plotting import animate_trial, plot_trial_3d

    walk, frames = walking_trial()
    with pytest.raises(ValueError, match=r"vertical_axis must be 'x' or 'y' or 'z'; got 'up'"):
        plot_trial_3d(walk, vertical_axis="up")
    with pytest.raises(ValueError, match=r"frames\['a'\] must be \(R, origin\) of shapes "
                                         r"\(111, 3, 3\) and \(111, 3\)"):
        plot_trial_3d(walk, {"a": (np.eye(3), np.zeros(3))})
    with pytest.raises(TypeError, match=r"frames must be a dict"):
        plot_trial_3d(walk, [1, 2])
    with pytest.raises(ValueError, match=r"markers must be a DataFrame with \(marker, "
                                         r"coord\) columns"):
        plot_trial_3d(walk.to_numpy())
    with pytest.raises(ValueError, match=r"step must be a positive whole number; got 0"):
        animate_trial(walk, step=0)
    with pytest.raises(ValueError, match=r"every coordinate is NaN"):
        plot_trial_3d(walk * np.nan)
    with pytest.raises(TypeError, match=r"time must be a numeric array"):
        plot_trial_3d(walk, time="a")
    with pytest.raises(ValueError, match=r"frames\['a'\] must be a pair \(R, origin\)"):
        plot_trial_3d(walk, {"a": np.eye(3)})
    plt.close("all")


# --- adversarial pass, round 2 (tools/adversarial_pass_round2.py) ----------------------------

def test_plot_angles_warns_of_events_outside_the_curves():
    """Another trial's events, or events in ms, were silently not drawn."""
    in_ms = {side: {event: 1000 * times for event, times in found.items()}
             for side, found in EVENTS.items()}
    with pytest.warns(RuntimeWarning, match=r"events: 6 of 6 event times lie outside the "
                                            r"curves' time \(0 to 1.99 s\).*in ms"):
        plot_angles(trial(), in_ms)
    plt.close("all")


def test_plot_trial_3d_refuses_a_time_outside_the_trial_and_a_bad_axis_length():
    from bmc_functions.plotting import animate_trial, plot_trial_3d

    walk, frames = walking_trial()
    with pytest.raises(ValueError, match=r"time must lie within the trial \(0 to .* s\); "
                                         r"got 100"):
        plot_trial_3d(walk, frames, time=100.0)        # was: the last frame, silently
    for call in (plot_trial_3d, animate_trial):
        with pytest.raises(ValueError, match="axis_length must be a positive number"):
            call(walk, frames, axis_length=-1)
    hidden = walk.copy()
    hidden.iloc[0] = np.nan
    with pytest.warns(RuntimeWarning, match=r"no marker is visible at t = 0 s"):
        plot_trial_3d(hidden, time=0.0)
    plt.close("all")


# the refused animation is never drawn: matplotlib says so when it is collected (here)
@pytest.mark.filterwarnings("ignore:Animation was deleted without rendering")
def test_animation_html_refuses_more_frames_than_the_page_can_hold():
    """1000 frames at step=1 took minutes and were cut at matplotlib's 20 MB embed limit
    (a player that stops part-way)."""
    from bmc_functions.plotting import MAX_HTML_FRAMES, animate_trial, animation_html

    walk, frames = walking_trial()
    long = pd.concat([walk] * (MAX_HTML_FRAMES // len(walk) + 1), ignore_index=True)
    long.index = np.arange(len(long)) / 100
    animation = animate_trial(long)
    with pytest.raises(ValueError, match=rf"animation: {len(long)} frames to embed, more "
                                         rf"than {MAX_HTML_FRAMES}.*step="):
        animation_html(animation)
    plt.close("all")
    del animation
    gc.collect()


def test_plot_gait_cycles_draws_kinetics_with_their_units_and_signs():
    """Kinetics columns (joint, side, quantity) are drawn as angles are: sagittal moment
    first, y labels in N·m/kg, W/kg, N/kg with the clinical sign of each quantity, and a
    range fitted to the curves (at least 1 unit wide), not the 20 degrees of an angle, or
    the clinical range of a moment or power."""
    index = pd.MultiIndex.from_product([range(2), np.linspace(0, 100, 101)],
                                       names=["cycle", "percent"])
    columns = pd.MultiIndex.from_product([["hip", "ankle"], ["right", "left"],
                                          ["power", "force_z", "moment_y", "moment_x"]])
    curve = np.sin(np.linspace(0, 2 * np.pi, 101))
    values = np.tile(np.r_[curve, curve] [:, None], (1, len(columns))) * 0.2
    values[:, [c[2] == "moment_x" for c in columns]] *= 10.0           # +-2 N m/kg
    fig, axes = plot_gait_cycles(pd.DataFrame(values, index=index, columns=columns))
    assert axes.shape == (2, 4)
    labels = [[ax.get_ylabel() for ax in row] for row in axes]
    assert labels[0] == ["Flex − / Ext + (N·m/kg)", "Add − / Abd + (N·m/kg)",
                         "Abs − / Gen + (W/kg)", "Dist − / Prox + (N/kg)"]
    assert labels[1][:2] == ["Dors − / Plan + (N·m/kg)", "Inv − / Ev + (N·m/kg)"]
    low, high = axes[0, 0].get_ylim()
    assert -2.3 < low < -2.0 and 2.0 < high < 2.3                    # the curve, 5 % margin
    low, high = axes[0, 3].get_ylim()
    assert high - low == pytest.approx(1.0)                           # +-0.2: the least range
    # moments and powers have clinical ranges (CLINICAL_RANGES), as the angles
    assert axes[0, 2].get_ylim() == (-2.0, 3.0)                      # hip power, W/kg
    plt.close(fig)
