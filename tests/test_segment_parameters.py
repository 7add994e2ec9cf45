"""Segment inertial parameters (bmc_functions.dynamics.segment_parameters)."""

import warnings

import numpy as np
import pytest

from bmc_functions import SegmentParameters, segment_inertia, segment_parameters
from bmc_functions.dynamics.segment_parameters import (DEMPSTER, GYRATION_ABOUT_PROXIMAL,
                                                       principal_moments)


def test_dempsters_numbers_as_winter_tabulates_them():
    """Winter (2009) Table 4.1: mass fraction, centre of mass from the proximal end,
    radius of gyration about the centre of mass (two transverse axes; none about the long
    axis: y for thigh and shank, x for the foot)."""
    assert DEMPSTER["foot"] == (0.0145, 0.50, (0.0, 0.475, 0.475))
    assert DEMPSTER["shank"] == (0.0465, 0.433, (0.302, 0.0, 0.302))
    assert DEMPSTER["thigh"] == (0.100, 0.433, (0.323, 0.0, 0.323))
    # the radius about the proximal end follows from the one about the centre of mass
    # (parallel axes, k_p^2 = k^2 + com^2) within the table's rounding
    for name, k_proximal in GYRATION_ABOUT_PROXIMAL.items():
        mass, com, gyration = DEMPSTER[name]
        assert np.hypot(max(gyration), com) == pytest.approx(k_proximal, abs=0.01), name


def test_centre_of_mass_and_inertia_per_frame():
    proximal = np.array([[0.0, 0.9, 0.0], [0.1, 0.9, 0.0]])
    distal = np.array([[0.0, 0.5, 0.0], [0.1, 0.4, 0.0]])      # 0.40 m then 0.50 m
    mass, com, inertia = segment_inertia(proximal, distal, 80.0, "thigh")
    assert mass == pytest.approx(8.0)
    assert com == pytest.approx(proximal + 0.433 * (distal - proximal))
    for frame, length in enumerate((0.4, 0.5)):
        expected = 8.0 * (0.323 * length) ** 2
        assert np.diag(inertia[frame]) == pytest.approx([expected, 0.0, expected])
        assert inertia[frame][~np.eye(3, dtype=bool)] == pytest.approx(np.zeros(6))


def test_overrides_replace_some_fields_or_add_a_segment():
    table = segment_parameters({"thigh": {"com": 0.5},
                                "pelvis": SegmentParameters(0.142, 0.105, (0.3, 0.3, 0.3))})
    assert table["thigh"] == (0.100, 0.5, (0.323, 0.0, 0.323))
    assert table["pelvis"].mass == 0.142
    assert segment_parameters() == DEMPSTER
    mass, com, _ = segment_inertia([[0, 1.0, 0]], [[0, 0, 0]], 50, "pelvis",
                                   parameters={"pelvis": {"mass": 0.1, "com": 0.2,
                                                          "gyration": (0, 0, 0)}})
    assert mass == pytest.approx(5.0) and com[0] == pytest.approx([0, 0.8, 0])


def test_a_nan_end_gives_nan_in_that_frame():
    _, com, inertia = segment_inertia([[0, 1.0, 0], [np.nan] * 3], [[0, 0, 0]] * 2, 70, "shank")
    assert np.isnan(com[1]).all() and np.isnan(inertia[1]).all() and not np.isnan(com[0]).any()


def test_principal_moments_are_the_tensors_diagonal_bit_for_bit():
    """principal_moments (the kinetics' path) gives segment_inertia's mass, centre of mass
    and diagonal exactly, NaN in every moment of a frame of zero or unknown length, and
    the same warnings."""
    rng = np.random.default_rng(3)
    proximal = rng.normal(size=(50, 3)) * 0.1 + [0, 0.9, 0]
    distal = rng.normal(size=(50, 3)) * 0.1 + [0, 0.5, 0]
    proximal[7], distal[9], distal[11] = np.nan, np.nan, proximal[11]     # 11: length 0
    for segment in ("foot", "shank", "thigh"):
        with pytest.warns(RuntimeWarning, match="length of 0") as tensor_warnings:
            mass, com, inertia = segment_inertia(proximal, distal, 70.0, segment)
        with pytest.warns(RuntimeWarning, match="length of 0") as moment_warnings:
            mass2, com2, moments = principal_moments(proximal, distal, 70.0, segment)
        assert [str(w.message) for w in tensor_warnings] == [str(w.message)
                                                            for w in moment_warnings]
        assert mass2 == mass and np.array_equal(com2, com, equal_nan=True)
        assert np.array_equal(moments, np.diagonal(inertia, axis1=1, axis2=2).T,
                              equal_nan=True)
        assert np.isnan(moments[:, [7, 9, 11]]).all()
        assert not np.isnan(np.delete(moments, [7, 9, 11], axis=1)).any()
        # the tensor is m L^2 diag(k^2), NaN as a whole in those frames
        length2 = np.sum((distal - proximal) ** 2, axis=1)
        expected = mass * length2[0] * np.square(DEMPSTER[segment].gyration)
        assert moments[:, 0] == pytest.approx(expected, rel=1e-15)
        assert np.isnan(inertia[[7, 9, 11]]).all()


@pytest.mark.parametrize("parameters, match", [
    ([1], r"parameters must be a dict of segment name -> parameters; got list"),
    ({"thigh": 0.1}, r"parameters\['thigh'\] must be a dict of mass, com, gyration"),
    ({"thigh": {"weight": 0.1}}, r"parameters\['thigh'\] has unknown fields \['weight'\]"),
    ({"arm": {"mass": 0.03}}, r"parameters\['arm'\]: 'arm' is not in Dempster's table"),
    ({"thigh": {"mass": 1.5}}, r"parameters\['thigh'\]\['mass'\] must be a fraction"),
    ({"thigh": {"gyration": (0.3, 0.3)}}, r"parameters\['thigh'\]\['gyration'\] must be "
                                          r"three fractions"),
])
def test_bad_overrides_are_refused(parameters, match):
    with pytest.raises(ValueError, match=match):
        segment_parameters(parameters)


@pytest.mark.parametrize("arguments, match", [
    (([[0, 1, 0]], [[0, 0, 0]], 0, "thigh"), r"body_mass must be a body mass in kg"),
    (([[0, 1, 0]], [[0, 0, 0]], 70, "arm"),
     r"segment must be .foot. or .shank. or .thigh.; got .arm."),
    (([[0, 1, 0]], [[0, 0, 0], [0, 0, 0]], 70, "thigh"),
     r"proximal and distal must have the same shape \(frames, 3\)"),
])
def test_bad_segment_inertia_arguments(arguments, match):
    with pytest.raises(ValueError, match=match):
        segment_inertia(*arguments)


def test_body_mass_in_grams_is_refused_naming_body_mass():
    with pytest.raises(ValueError, match=r"body_mass must be a body mass in kg, from 0.2 to 650"):
        segment_inertia([[0, 0.5, 0]], [[0, 0.1, 0]], 70000, "shank")
    mass = segment_inertia([[0, 0.5, 0]], [[0, 0.1, 0]], 650, "shank")[0]   # the bound
    assert mass == pytest.approx(0.0465 * 650)


def test_the_mm_warning_follows_the_median_not_the_longest_frame():
    """check_segment_length sorts for the median only when the longest length exceeds
    2.72 m: a few long frames (a swapped label) do not warn, a trial in mm does, NaN
    frames left out of both."""
    import warnings
    distal = np.zeros((9, 3))
    proximal = np.array([[0, 0.4, 0]] * 6 + [[0, 5.0, 0]] * 2 + [[np.nan] * 3])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        segment_inertia(proximal, distal, 70, "shank")
    with pytest.warns(UserWarning, match=r"the shank is 400 long \(median"):
        segment_inertia(proximal * 1000, distal, 70, "shank")


def test_a_table_made_here_passes_again_and_a_copied_bad_entry_is_still_refused():
    """segment_parameters keeps Dempster's own entries of a table it made (the kinetics
    passes its table to every segment) without checking them again; any other entry,
    a SegmentParameters with Dempster's name and impossible values too, is checked."""
    from bmc_functions.dynamics.segment_parameters import (DEMPSTER, SegmentParameters,
                                                           segment_parameters)
    table = segment_parameters()
    assert segment_parameters(table) == DEMPSTER
    assert all(segment_parameters(table)[name] is DEMPSTER[name] for name in DEMPSTER)
    bad = SegmentParameters(1.5, *DEMPSTER["foot"][1:])         # a mass fraction > 1
    with pytest.raises(ValueError, match=r"parameters\['foot'\]\['mass'\]"):
        segment_parameters({**table, "foot": bad})
