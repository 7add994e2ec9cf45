r"""Segment inertial parameters: Dempster's masses, centres of mass and radii of gyration.

The numbers are Dempster's (1955) cadaver measurements as Winter (2009, Table 4.1)
tabulates them, the table that Plug-in Gait also cites for its lower body (Vicon,
Plug-in Gait reference guide, "Kinetic modelling"): a segment's mass as a fraction of the
body mass, its centre of mass as a fraction of the segment length from the proximal end,
and its radius of gyration about the centre of mass as a fraction of the segment length.

The radius of gyration is given about the segment frame's axes of this package (ISB:
x anterior, y superior, z to the right; the foot's x runs from heel to toe): Dempster
measured the moment of inertia about a transverse axis only, so the two transverse axes
take Winter's number and the long axis (y for the thigh and the shank, x for the foot)
takes none, as Plug-in Gait does (its segments have no moment of inertia about their
long axis). Override any number with ``parameters=``.
"""

from typing import NamedTuple

import numpy as np

from .._checks import check_choice, check_scalar, check_vectors, warn, warn_frames
from ..rigid_body.rotations import vector_dot


class SegmentParameters(NamedTuple):
    """One segment's inertial parameters, as fractions (dimensionless)."""

    mass: float
    """Segment mass / body mass."""
    com: float
    """Distance from the proximal joint centre to the centre of mass / segment length,
    along the line from the proximal to the distal end."""
    gyration: tuple
    """Radii of gyration about the centre of mass, about the segment frame's x, y and z
    axes, / segment length (3 floats)."""


#: Dempster (1955) via Winter (2009), Biomechanics and Motor Control of Human Movement,
#: 4th ed., Table 4.1: segment mass / body mass, centre of mass / segment length from the
#: proximal end, radius of gyration about the centre of mass / segment length.
#: Segments (Winter's definitions): foot = lateral malleolus to the head of metatarsal II
#: (here: the ankle centre to the toe marker); shank ("leg") = femoral condyles to medial
#: malleolus (here: knee centre to ankle centre); thigh = greater trochanter to femoral
#: condyles (here: hip centre to knee centre).
DEMPSTER = {
    # foot: mass 0.0145, centre of mass 0.50, radius of gyration 0.475 (Table 4.1);
    # long axis x (heel to toe): no radius (see the module's docstring)
    "foot": SegmentParameters(0.0145, 0.50, (0.0, 0.475, 0.475)),
    # leg (shank): mass 0.0465, centre of mass 0.433, radius of gyration 0.302
    "shank": SegmentParameters(0.0465, 0.433, (0.302, 0.0, 0.302)),
    # thigh: mass 0.100, centre of mass 0.433, radius of gyration 0.323
    "thigh": SegmentParameters(0.100, 0.433, (0.323, 0.0, 0.323)),
}

#: Winter (2009) Table 4.1's radii of gyration about the *proximal end* (/ segment
#: length): foot 0.690, leg 0.528, thigh 0.540. pyCGM2's re-implementation of Plug-in
#: Gait (bodySegmentParameters.py) puts these where the radii about the centre of mass
#: belong; which of the two Vicon's Plug-in Gait uses is to be checked against its stored
#: moments. Not used by default here.
GYRATION_ABOUT_PROXIMAL = {"foot": 0.690, "shank": 0.528, "thigh": 0.540}


def _check_fraction(value, name):
    return check_scalar(value, name, "a fraction from 0 to 1", minimum=0, maximum=1)


def segment_parameters(parameters=None):
    """Dempster's table (:data:`DEMPSTER`) with a user's overrides.

    Parameters
    ----------
    parameters : dict, optional
        Segment name -> :class:`SegmentParameters`, or a dict of some of its fields
        (``{'thigh': {'mass': 0.105}}``): those fields replace Dempster's. A new segment
        name must give all three fields.

    Returns
    -------
    dict
        Segment name -> :class:`SegmentParameters`.

    Raises
    ------
    ValueError
        If `parameters` is not a dict of dicts, names an unknown field, misses a field
        for a new segment, or gives a fraction outside [0, 1] or a gyration that is not
        three fractions.

    Examples
    --------
    >>> from bmc_functions import segment_parameters
    >>> table = segment_parameters({"thigh": {"mass": 0.105}})
    >>> print(table["thigh"].mass, table["thigh"].com, table["shank"].mass)
    0.105 0.433 0.0465
    """
    table = dict(DEMPSTER)
    if parameters is None:
        return table
    if not isinstance(parameters, dict):
        raise ValueError(f"parameters must be a dict of segment name -> parameters; got "
                         f"{type(parameters).__name__}")
    for segment, given in parameters.items():
        if given is DEMPSTER.get(segment):     # the table's own entry (a table made here
            continue                           # and passed on): valid, kept as it is
        fields = given._asdict() if isinstance(given, SegmentParameters) else given
        if not isinstance(fields, dict):
            raise ValueError(f"parameters[{segment!r}] must be a dict of mass, com, "
                             f"gyration (or a SegmentParameters); got "
                             f"{type(given).__name__}")
        unknown = sorted(set(fields) - set(SegmentParameters._fields))
        if unknown:
            raise ValueError(f"parameters[{segment!r}] has unknown fields {unknown}; "
                             f"expected some of {list(SegmentParameters._fields)}")
        base = table.get(segment)
        if base is None and len(fields) < 3:
            raise ValueError(f"parameters[{segment!r}]: {segment!r} is not in Dempster's "
                             f"table ({', '.join(DEMPSTER)}): give mass, com and gyration")
        merged = {**(base._asdict() if base else {}), **fields}
        gyration = np.asarray(merged["gyration"], dtype=float)
        if gyration.shape != (3,) or not ((gyration >= 0) & (gyration <= 1)).all():
            raise ValueError(f"parameters[{segment!r}]['gyration'] must be three fractions "
                             f"from 0 to 1 (about x, y, z); got {merged['gyration']!r}")
        table[segment] = SegmentParameters(
            _check_fraction(merged["mass"], f"parameters[{segment!r}]['mass']"),
            _check_fraction(merged["com"], f"parameters[{segment!r}]['com']"),
            tuple(float(g) for g in gyration))
    return table


#: The largest body mass accepted (kg): above the heaviest person recorded (about 635 kg),
#: so that a mass in grams is refused.
MAX_BODY_MASS = 650.0

#: The smallest body mass accepted (kg): below the lightest newborn known to have survived
#: (212 g, Kwek Yu Xuan, Singapore 2020; Guinness World Records, "Lightest birth", from the
#: University of Iowa's Tiniest Babies Registry), so that a mass in tonnes (0.085 for
#: 85 kg) is refused.
MIN_BODY_MASS = 0.2


def check_body_mass(value, name="body_mass"):
    """`value` as a body mass in kg within [:data:`MIN_BODY_MASS`, :data:`MAX_BODY_MASS`];
    else a ValueError naming `name`, the value and the range (a mass in g, lb or tonnes).

    >>> from bmc_functions.dynamics.segment_parameters import check_body_mass
    >>> check_body_mass(85)
    85.0
    >>> check_body_mass(0.085)
    Traceback (most recent call last):
    ...
    ValueError: body_mass must be a body mass in kg, from 0.2 to 650 (a mass in g, lb or tonnes?); got 0.085
    """
    return check_scalar(value, name, f"a body mass in kg, from {MIN_BODY_MASS:g} to "
                        f"{MAX_BODY_MASS:g} (a mass in g, lb or tonnes?)",
                        minimum=MIN_BODY_MASS, maximum=MAX_BODY_MASS)


def segment_inertia(proximal, distal, body_mass, segment, *, parameters=None):
    r"""Mass, centre of mass and inertia tensor of a segment in every frame.

    Parameters
    ----------
    proximal, distal : array_like, shape (frames, 3)
        The segment's proximal and distal ends (joint centres; for the foot the toe), in
        the lab, in metres for SI results. The centre of mass lies on the line between
        them, so the segment frame is not needed; the inertia tensor is about the axes of
        the segment frame the table's radii refer to.
    body_mass : float
        Body mass (kg), from :data:`MIN_BODY_MASS` to :data:`MAX_BODY_MASS`.
    segment : str
        A segment of the table: 'foot', 'shank', 'thigh' (or one added by `parameters`).
    parameters : dict, optional
        Overrides, as :func:`segment_parameters`.

    Returns
    -------
    mass : float
        kg.
    com : ndarray, shape (frames, 3)
        Centre of mass in the lab, on the line from `proximal` to `distal`.
    inertia : ndarray, shape (frames, 3, 3)
        Inertia tensor about the centre of mass, in the segment frame (kg m² for
        positions in m): :math:`m L^2 \operatorname{diag}(k_x^2, k_y^2, k_z^2)` with the
        segment length :math:`L` of each frame.

    Raises
    ------
    ValueError
        If `proximal` and `distal` are not both of shape (frames, 3) or are the same
        point in every frame, `body_mass` is outside [:data:`MIN_BODY_MASS`,
        :data:`MAX_BODY_MASS`] (a mass in g, lb or tonnes), `segment` is unknown, or a
        parameter is out of range.

    Warns
    -----
    UserWarning
        If the median length exceeds :data:`MAX_SEGMENT_LENGTH` (2.72 m: coordinates in
        mm), or some frames have length 0 (their inertia is NaN).

    Examples
    --------
    A 0.40 m shank of a 70 kg subject, vertical:

    >>> import numpy as np
    >>> from bmc_functions import segment_inertia
    >>> mass, com, inertia = segment_inertia([[0, 0.5, 0]], [[0, 0.1, 0]], 70, "shank")
    >>> print(round(mass, 4), com.round(4) + 0.0)
    3.255 [[0.     0.3268 0.    ]]
    >>> print(np.diag(inertia[0]).round(5))
    [0.04751 0.      0.04751]
    """
    mass, com, moments = principal_moments(proximal, distal, body_mass, segment,
                                           parameters=parameters)
    # m L^2 diag(k^2): the three diagonal terms written into zeros (the same products as
    # broadcasting the diagonal matrix, without the nine-term pass over every frame)
    inertia = np.zeros((moments.shape[1], 3, 3))
    for axis in range(3):
        inertia[:, axis, axis] = moments[axis]
    inertia[np.isnan(moments[0])] = np.nan               # as NaN * 0 made them
    return mass, com, inertia


def principal_moments(proximal, distal, body_mass, segment, *, parameters=None):
    r"""Mass, centre of mass and principal moments of inertia of a segment in every frame.

    :func:`segment_inertia` with its diagonal inertia tensor given by the diagonal only,
    for a caller that needs no (frames, 3, 3) tensor (Newton-Euler on component rows).

    Parameters
    ----------
    proximal, distal, body_mass, segment, parameters
        As :func:`segment_inertia`.

    Returns
    -------
    mass : float
        kg.
    com : ndarray, shape (frames, 3)
        Centre of mass in the lab, as :func:`segment_inertia`'s.
    moments : ndarray, shape (3, frames)
        The principal moments about the centre of mass, along the x, y and z axes of the
        segment frame (kg m² for positions in m): row i is :math:`m L^2 k_i^2`, the
        diagonal of :func:`segment_inertia`'s tensor, the same values; all three NaN in a
        frame of zero or unknown length.

    Raises
    ------
    ValueError
        As :func:`segment_inertia`.

    Warns
    -----
    UserWarning
        As :func:`segment_inertia` (its messages name it).

    Examples
    --------
    >>> from bmc_functions.dynamics.segment_parameters import principal_moments
    >>> mass, com, moments = principal_moments([[0, 0.5, 0]], [[0, 0.1, 0]], 70, "shank")
    >>> print(moments[:, 0].round(5))
    [0.04751 0.      0.04751]
    """
    table = segment_parameters(parameters)
    check_choice(segment, "segment", tuple(table))
    body_mass = check_body_mass(body_mass)
    proximal, distal = check_vectors(proximal, "proximal"), check_vectors(distal, "distal")
    if proximal.ndim != 2 or proximal.shape != distal.shape:
        raise ValueError(f"proximal and distal must have the same shape (frames, 3); got "
                         f"{proximal.shape} and {distal.shape}")
    p = table[segment]
    mass = p.mass * body_mass
    along = distal - proximal
    com = np.multiply(along, p.com)         # proximal + com along: the sum in place
    com += proximal
    length2 = vector_dot(along, along)
    zero = check_segment_length(np.sqrt(length2), segment)
    moments, mass_length2 = np.empty((3, len(length2))), mass * length2
    for axis, k2 in enumerate(np.square(p.gyration)):
        np.multiply(mass_length2, k2, out=moments[axis])       # (m L^2) k^2, per axis
    moments[:, zero | np.isnan(length2)] = np.nan          # as NaN * 0 made them
    return mass, com, moments


#: The longest segment accepted without a warning (m): the height of the tallest person
#: recorded (2.72 m, Robert Wadlow; Guinness World Records, "Tallest man ever"), which no
#: segment of a body exceeds; Winter's (2009, Fig. 4.1) longest lower-limb segment, the
#: thigh, is 0.245 of the height. A longer one is a segment in mm.
MAX_SEGMENT_LENGTH = 2.72


def check_segment_length(length, segment):
    """Frames of zero length (bool, (frames,)) of a segment's per-frame `length`.

    A ValueError if every frame with a length has length 0 (`proximal` equals `distal`: the
    same point given twice); one warning naming the frames if some have; one warning if
    the median length exceeds :data:`MAX_SEGMENT_LENGTH` (coordinates in mm).
    """
    known = np.isfinite(length)
    zero = known & (length == 0)
    if known.any() and zero[known].all():
        raise ValueError(f"proximal and distal must be the two ends of the {segment} (a "
                         f"length > 0); got the same point in all {int(known.sum())} "
                         f"frames")
    if zero.any():
        warn_frames(int(zero.sum()), len(length), f"give the {segment} a length of 0 "
                    f"(proximal equals distal): its inertia is NaN there")
    # the median (a sort, the slow part) only if it could exceed the limit: the longest
    # known length does not, as in any trial in metres
    longest = np.fmax.reduce(length) if known.any() else np.nan      # NaN ignored
    median = float(np.median(length[known])) if longest > MAX_SEGMENT_LENGTH else np.nan
    if median > MAX_SEGMENT_LENGTH:
        warn(f"segment_inertia: the {segment} is {median:.4g} long (median over frames), "
             f"longer than any body's segment in metres (the tallest person was "
             f"{MAX_SEGMENT_LENGTH:g} m): proximal and distal in mm? The centre of mass and "
             f"inertia are then in mm and kg mm²; give metres for SI results", UserWarning)
    return zero
