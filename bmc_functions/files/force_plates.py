r"""Force plates: the ground reaction force, centre of pressure and free moment of a C3D file.

A C3D file stores what a force plate measured as analog channels and says how to read
them in its FORCE_PLATFORM group: the plate's type (which channels), its corners in the
lab, the position of its sensors' origin below the top surface (ORIGIN) and, for type 4,
a calibration matrix [1]_. :func:`read_force_plates` turns them into the ground reaction
force, its centre of pressure on the plate's top surface, the free moment and the moment
about the plate's centre, in the lab frame, at the analog rate (damaged analog data are
refused: :func:`check_load_continuity`); :func:`resample_force_plates` averages them to
the marker rate as Vicon Nexus does; :func:`assign_plates` gives each loaded interval
and the foot that stood on the plate alone, the rule by which a force is assigned to a
foot (:func:`~bmc_functions.force_plate_events` times its contacts).

The loads are computed here from the channels, not taken from a library: the maths is
in :func:`plate_loads`, checked against ezc3d's force-plate module [2]_ on every shared
file and against hand derivations on synthetic plates.

References
----------
.. [1] Motion Lab Systems (2008). The C3D File Format User Guide, chapter "The
   FORCE_PLATFORM group" (types 1-4, CORNERS, ORIGIN, CAL_MATRIX, ZERO).
.. [2] Michaud B, Begon M (2021). ezc3d: An easy C3D file I/O cross-platform solution
   for C++, Python and MATLAB. Journal of Open Source Software 6(58), 2911.
"""

import functools
import warnings

import numpy as np
import pandas as pd
from scipy.signal import butter, sosfiltfilt

from .._checks import ArgumentTypeError, as_float_array, check_choice, check_number, warn
from ._c3d_binary import read_checked
from .trial import UNIT_ALIASES, UNIT_SCALE, mm_per_unit

#: The C3D plate types read here and their channels, in the order FORCE_PLATFORM:CHANNEL
#: lists them [1]: 1: Fx Fy Fz, the centre of pressure x y and the free moment Tz, in the
#: plate frame about the centre of its top surface; 2: Fx Fy Fz Mx My Mz about the
#: sensors' origin (AMTI, Bertec); 3: Kistler's eight piezoelectric channels fx12 fx34
#: fy14 fy23 fz1 fz2 fz3 fz4; 4: type 2's six channels through a 6 x 6 calibration matrix.
PLATE_TYPES = {1: 6, 2: 6, 3: 8, 4: 6}

#: Vertical force (N) below which the centre of pressure is NaN. The centre of pressure is
#: a moment divided by the vertical force (Notes of :func:`plate_loads`), so its error is
#: the moment's noise over that force: the unloaded plates of the shared files read
#: moments of 1,200-6,400 N·mm at most (standard deviation 40-3,100 N·mm), hence errors
#: up to 60-300 mm at 20 N, a foot's length, and 6-30 mm at 200 N (early stance). Below
#: 20 N no foot is on the plate (the threshold of
#: :func:`~bmc_functions.force_plate_events`' contacts; Vicon Nexus draws the force
#: vector above 25 N by default); between 20 N and a few hundred N the centre of
#: pressure is defined but uncertain, which is why kinetics use the force and the moment
#: about the plate's centre (linear in the channels) rather than the centre of pressure.
COP_THRESHOLD = 20.0

#: Vertical force (N) within which of the unloaded plate's level a sample counts as
#: unloaded, for the zero (the same 20 N: well above the unloaded plates' noise here,
#: 0.4-9 N, and far below a foot's load).
UNLOADED = 20.0

#: The shortest unloaded stretch (s) that gives a plate's zero; a plate loaded
#: throughout (someone standing on it) has none and keeps the file's zero.
MIN_UNLOADED = 0.1

#: Largest offset (N) of an unloaded plate's vertical force that is zeroed: the plates
#: here read 0.3-40 N unloaded, while a plate whose lowest load is larger has someone on
#: it throughout (a child's body weight is 150 N), whose load is no offset.
MAX_OFFSET = 100.0

#: Largest change of a plate's vertical load between two consecutive analog samples, as
#: a fraction of the plate's peak load. A foot's load rises over 10 ms or more, even at a
#: running heel strike's impact (its peak is reached in 10-30 ms), so at 200 Hz or more
#: one sample cannot carry half of it: the real trials here change by at most 11 % of
#: their peak per sample (Codamotion's 400 Hz plate; 3-9 % at 960-1080 Hz), while the
#: damaged sample14.c3d, whose blocks of analog samples were written out of order, jumps
#: by 89-97 % (the whole load appears and vanishes between two samples).
MAX_JUMP = 0.5

#: Samples on each side of a jump whose median must move too (a level, not a spike).
JUMP_SPAN = 5

#: Lowest analog rate (Hz) at which :data:`MAX_JUMP` is checked.
MIN_JUMP_RATE = 200.0

#: Quantities of each plate, in the columns of :func:`read_force_plates`.
QUANTITIES = ("force_x", "force_y", "force_z", "cop_x", "cop_y", "cop_z",
              "free_moment_x", "free_moment_y", "free_moment_z", "moment_x", "moment_y",
              "moment_z")


def _extract_raw(source):
    """The analog channels and the parameters the plates need, read with ezc3d (run in
    the child process of read_checked; plain NumPy objects only)."""
    import ezc3d

    c3d = ezc3d.c3d(str(source))
    params = c3d["parameters"]

    def group(name, keys):
        found = params.get(name, {})
        return {key: (list(found[key]["value"]) if isinstance(found[key]["value"], list)
                      else np.asarray(found[key]["value"]))
                for key in keys if key in found}

    return {"FORCE_PLATFORM": group("FORCE_PLATFORM", ("USED", "TYPE", "CHANNEL", "CORNERS",
                                                       "ORIGIN", "CAL_MATRIX", "ZERO")),
            "ANALOG": group("ANALOG", ("RATE", "LABELS", "UNITS")),
            "POINT": group("POINT", ("RATE", "UNITS")),
            "analogs": np.asarray(c3d["data"]["analogs"][0], dtype=float)}


def read_force_plates(path, *, zero="file", cop_threshold=COP_THRESHOLD):
    r"""The ground reaction force, centre of pressure and free moment of each force plate.

    Parameters
    ----------
    path : str or path-like
        A ``.c3d`` file with a FORCE_PLATFORM group (plate types 1-4) and its analog
        channels.
    zero : {'file', 'unloaded', 'none'}, optional
        How each plate is zeroed. ``'file'`` (default): as the file says, the mean over
        the frames FORCE_PLATFORM:ZERO names, none when it names none (0, 0; Vicon Nexus
        zeroes its plates when it records, and its stored forces are the channels
        unchanged); ``'unloaded'``: each channel's median over the samples where the
        plate is unloaded (vertical load within ``UNLOADED`` = 20 N of its lowest level),
        when they last ``MIN_UNLOADED`` (0.1 s) or more and that level is within
        ``MAX_OFFSET`` (100 N) of zero; ``'none'``: as stored.
    cop_threshold : float, optional
        Vertical force (N) below which the centre of pressure is NaN (default 20 N).

    Returns
    -------
    pandas.DataFrame
        Indexed by ``time`` (s, 0 at the first marker frame, as :func:`read_c3d`), at
        the analog rate; columns ``(plate, quantity)`` with plate 1, 2, ... and quantity
        ``force_x/y/z`` (N: the ground reaction force, the force of the ground on the
        body), ``cop_x/y/z`` (mm: the centre of pressure on the plate's top
        surface), ``free_moment_x/y/z`` (N·mm: the moment of the ground on the body
        about the centre of pressure, along the plate's normal) and ``moment_x/y/z``
        (N·mm: the moment of the ground on the body about the centre of the plate's top
        surface; Vicon's ``<S>GroundReactionMoment`` times the body mass), all in the
        lab frame and in millimetres whatever the file's unit. ``attrs``: ``'rate'``
        (analog, Hz), ``'point_rate'`` (Hz), ``'units'`` ({'force': 'N', 'position':
        'mm', 'moment': 'N·mm'}), ``'file_units'`` (the file's POINT:UNITS),
        ``'plates'`` (per plate a dict of ``type``, ``corners`` (4 x 3, mm, lab),
        ``origin`` (3, mm, plate frame, from the sensors' origin to the top surface's
        centre), ``normal`` (unit, lab, pointing into the plate), ``zero`` (the channel
        offsets removed)), ``'cop_threshold'``, ``'zero'`` and ``'source'``.

    Raises
    ------
    ValueError
        If the file has no force plate, a plate's type is not 1-4, its corners are all
        zero (the file does not say where it lies), its channels or parameters are
        missing, or its analog data jump as no force can (:func:`check_load_continuity`:
        blocks written out of order).

    Notes
    -----
    See :func:`plate_loads` for the maths. ezc3d [2]_ reads the channels, already
    scaled as the C3D format says [1]_: (stored - ANALOG:OFFSET) x ANALOG:SCALE x
    ANALOG:GEN_SCALE. Positions (corners, origin) are converted from POINT:UNITS to mm;
    moments to N·mm from the unit the moment channels' ANALOG:UNITS give (N·m, N·mm) or,
    when they give none, from N times POINT:UNITS (type 4: the calibration matrix's
    outputs). Damaged analog data are refused by :func:`check_load_continuity`; the
    plate's zero is discussed under `zero`.

    References
    ----------
    .. [1] C3D.ORG, The C3D file format user guide: "The FORCE_PLATFORM group" (types
       1-4, CORNERS, ORIGIN, CAL_MATRIX, ZERO) and the ANALOG group (c3d.org).
    .. [2] Michaud B, Begon M (2021). ezc3d: An easy C3D file I/O cross-platform
       solution for C++, Python and MATLAB. Journal of Open Source Software 6(58), 2911.

    Examples
    --------
    >>> from bmc_functions import read_force_plates
    >>> from bmc_functions.examples import example_file
    >>> plates = read_force_plates(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> print(plates.attrs["rate"], plates.attrs["point_rate"], plates.attrs["units"])
    1080.0 120.0 {'force': 'N', 'position': 'mm', 'moment': 'N·mm'}
    """
    zero = check_choice(zero, "zero", ("file", "unloaded", "none"))
    cop_threshold = check_number(cop_threshold, "cop_threshold", positive=True)
    raw = read_checked(path, _extract_raw, "read_force_plates")
    setups = plate_setups(raw, path)
    analogs = raw["analogs"]
    rate = float(np.ravel(raw["ANALOG"]["RATE"])[0])
    point_rate = float(np.ravel(raw["POINT"]["RATE"])[0])
    columns, described, notes = [], [], []
    for number, setup in enumerate(setups, start=1):    # a few plates, not frames
        channels = analogs[setup["channels"]].T * setup["moment_scale"]
        offsets, note = _plate_zero(channels, setup, zero, rate, point_rate,
                                    f"plate {number}")
        notes += [note] if note else []
        loads = plate_loads(channels - offsets, setup["type"], setup["corners"],
                            setup["origin"], setup["cal_matrix"], cop_threshold=cop_threshold)
        check_load_continuity(loads[0] @ _plate_axes(setup["corners"])[:, 2] * -1, rate,
                              f"{path}: force plate {number}")
        columns.append(np.concatenate(loads, axis=1))
        described.append({key: np.asarray(setup[key]).tolist() for key in
                          ("type", "corners", "origin")}
                         | {"normal": _plate_axes(setup["corners"])[:, 2].tolist(),
                            "zero": np.asarray(offsets).ravel().tolist()})
    if notes:
        warn(f"{path}: " + "; ".join(notes), RuntimeWarning)
    index = pd.Index(np.arange(analogs.shape[1]) / rate, name="time")
    table = pd.DataFrame(np.concatenate(columns, axis=1), index=index,
                         columns=pd.MultiIndex.from_product(
                             [range(1, len(setups) + 1), QUANTITIES],
                             names=["plate", "quantity"]))
    table.attrs = {"rate": rate, "point_rate": point_rate,
                   "units": {"force": "N", "position": "mm", "moment": "N·mm"},
                   "file_units": setups[0]["file_units"], "plates": described,
                   "cop_threshold": cop_threshold, "zero": zero, "source": str(path)}
    return table


def _text(values):
    """Stripped strings of a C3D string parameter."""
    return [str(v).strip() for v in np.ravel(np.asarray(values, dtype=object))]


def _moment_mm(unit, length_scale):
    """N·mm per unit of a moment channel whose ANALOG:UNITS is `unit` (the file's length
    unit's when the channel's says nothing)."""
    key = unit.replace(" ", "").replace(".", "").replace("*", "").replace("·", "").lower()
    known = {"nmm": 1.0, "nm": 1000.0, "ncm": 10.0}
    return known.get(key, length_scale)


def plate_setups(raw, path):
    """Each plate's type, channel rows, corners and origin (mm), calibration matrix and
    the factor taking its channels to N and N·mm, checked (ValueErrors name the plate
    and the parameter). `raw` is what the reader extracted from `path`."""
    plates = raw["FORCE_PLATFORM"]
    used = int(np.ravel(plates.get("USED", [0]))[0]) if np.size(plates.get("USED", 0)) else 0
    if used < 1:
        raise ValueError(f"{path}: no force plate in the file (FORCE_PLATFORM:USED is 0 or "
                         "missing)")
    units = _text(raw["POINT"].get("UNITS", ["mm"]))
    unit = UNIT_ALIASES.get(units[0].lower(), units[0].lower()) if units else "mm"
    if unit not in UNIT_SCALE:
        raise ValueError(f"{path}: POINT:UNITS is {units[0]!r}; expected one of "
                         f"{', '.join(UNIT_SCALE)} (the plates' corners are in it)")
    scale = UNIT_SCALE[unit]
    types = np.ravel(plates.get("TYPE", []))
    for key in ("TYPE", "CHANNEL", "CORNERS", "ORIGIN"):
        if key not in plates or np.size(plates[key]) == 0:
            raise ValueError(f"{path}: FORCE_PLATFORM:{key} is missing; it is needed to "
                             "read the force plates")
    setups = [_plate_setup(raw, path, plate, int(types[plate]) if plate < types.size else None,
                           scale) for plate in range(used)]
    for setup in setups:
        setup["file_units"] = unit
    return setups


def _plate_setup(raw, path, plate, kind, scale):
    """One plate's setup (see plate_setups)."""
    plates, name = raw["FORCE_PLATFORM"], f"{path}: force plate {plate + 1}"
    if kind not in PLATE_TYPES:
        raise ValueError(f"{name}: FORCE_PLATFORM:TYPE is {kind}; the supported plate "
                         f"types are {', '.join(map(str, PLATE_TYPES))} (C3D types 1-4)")
    n_channels = PLATE_TYPES[kind]
    channel = np.asarray(plates["CHANNEL"]).reshape(len(np.asarray(plates["CHANNEL"])), -1)
    corners = np.asarray(plates["CORNERS"], dtype=float).reshape(3, 4, -1)
    origin = np.asarray(plates["ORIGIN"], dtype=float).reshape(3, -1)
    if channel.shape[0] < n_channels or channel.shape[1] <= plate:
        raise ValueError(f"{name}: FORCE_PLATFORM:CHANNEL lists no {n_channels} channels "
                         f"for it (type {kind}); got shape {channel.shape}")
    rows = channel[:n_channels, plate].astype(int) - 1
    if rows.min() < 0 or rows.max() >= raw["analogs"].shape[0]:
        raise ValueError(f"{name}: FORCE_PLATFORM:CHANNEL names analog channels "
                         f"{(rows + 1).tolist()}, but the file has "
                         f"{raw['analogs'].shape[0]}")
    if corners.shape[2] <= plate or origin.shape[1] <= plate:
        raise ValueError(f"{name}: FORCE_PLATFORM:CORNERS or ORIGIN has no entry for it")
    corners = corners[:, :, plate].T * scale
    if not np.any(corners):
        raise ValueError(f"{name}: its corners (FORCE_PLATFORM:CORNERS) are all zero: the "
                         "file does not say where the plate lies in the lab (missing "
                         "corners), so its forces cannot be placed")
    edges = np.linalg.norm(np.diff(corners, axis=0, append=corners[:1]), axis=1)
    if not np.all(edges > 0) or np.linalg.norm(np.cross(corners[0] - corners[1],
                                                        corners[0] - corners[3])) == 0:
        raise ValueError(f"{name}: its corners (FORCE_PLATFORM:CORNERS) do not span a "
                         f"rectangle: {corners.round(1).tolist()}")
    factors = _channel_scales(raw, rows, kind, scale)
    cal_matrix = _cal_matrix(plates, plate, kind, name)
    if cal_matrix is not None:                  # type 4: the units are the outputs'
        cal_matrix, factors = factors[:, None] * cal_matrix, np.ones(6)
    return {"type": kind, "channels": rows, "corners": corners,
            "origin": _surface_origin(origin[:, plate], kind) * scale,
            "cal_matrix": cal_matrix, "moment_scale": factors,
            "zero_frames": np.ravel(plates.get("ZERO", [0, 0]))[:2].astype(int)}


def _surface_origin(stored, kind):
    """The vector from the sensors' origin to the top surface's centre, plate frame.

    The C3D format defines ORIGIN (type 2) as the vector from the plate's origin "to
    the point at the geometric center of the physical force platform working surface",
    in the plate frame, whose z points down, so "the Z component of this vector will be
    negative" [4]_. Files that store a positive z (Vicon's: the shared stair descent
    and sample14.c3d; older AMTI calibrations gave the offset that way) store the
    opposite vector: it is negated whole, as Visual3D [5]_ and ezc3d do. In every shared
    file the corners' order makes the plate's z point down (against the lab's vertical).
    Type 1 has no origin (its channels are already at the surface); type 3's x and y are
    Kistler's sensor offsets a and b, its z the surface's height, negative [4]_.

    References
    ----------
    .. [4] C3D.ORG, The C3D file format user guide: FORCE_PLATFORM:ORIGIN, "TYPE-2" and
       "TYPE-3" (c3d.org/HTML/Documents/type24.htm, type31.htm).
    .. [5] HAS-Motion, Visual3D documentation: "FP ORIGIN" ("If the ORIGIN is stored with
       a positive value, Visual3D multiplies all 3 components of the ORIGIN by -1").
    """
    stored = np.asarray(stored, dtype=float)
    if kind == 1:
        return np.zeros(3)
    if kind == 3:
        return np.array([stored[0], stored[1], -abs(stored[2])])
    return -stored if stored[2] > 0 else stored


def _cal_matrix(plates, plate, kind, name):
    """Type 4's 6 x 6 calibration matrix (None for the other types)."""
    if kind != 4:
        return None
    cal = np.asarray(plates.get("CAL_MATRIX", []), dtype=float)
    if cal.size < 36 * (plate + 1):
        raise ValueError(f"{name}: type 4 needs FORCE_PLATFORM:CAL_MATRIX (6 x 6 per "
                         f"plate); the file holds {cal.size} values")
    return cal.reshape(6, 6, -1)[:, :, plate]


def _channel_scales(raw, rows, kind, length_scale):
    """The factor taking each of a plate's channels to N (forces) and N·mm (moments).

    Type 2's moment channels are in the unit ANALOG:UNITS gives them (else the file's
    length unit times N), and so are type 4's moments out of its calibration matrix
    (the factors then scale its outputs); type 1's centre of pressure is in the file's
    length unit.
    """
    units = _text(raw["ANALOG"].get("UNITS", []))
    factors = np.ones(PLATE_TYPES[kind])
    if kind == 1:
        factors[3:5] = length_scale
        factors[5] = _moment_mm(units[rows[5]] if rows[5] < len(units) else "",
                                length_scale)
    elif kind in (2, 4):
        factors[3:] = [_moment_mm(units[r] if r < len(units) else "", length_scale)
                       for r in rows[3:]]
    return factors


def _plate_axes(corners):
    """The plate frame's axes (columns x, y, z, in the lab) from its corners: corner 1 lies
    at +x +y, 2 at -x +y, 3 at -x -y, 4 at +x -y (the C3D user guide), so x = c1 - c2, y = c1 - c4
    (made orthogonal to x), z = x × y (into the plate when the corners are listed
    clockwise seen from above, as the format's example)."""
    x = corners[0] - corners[1]
    y = corners[0] - corners[3]
    z = np.cross(x, y)
    y = np.cross(z, x)
    return np.column_stack([v / np.linalg.norm(v) for v in (x, y, z)])


def plate_loads(channels, plate_type, corners, origin, cal_matrix=None, *,
                cop_threshold=COP_THRESHOLD):
    r"""Force, centre of pressure and free moment in the lab from one plate's channels.

    Parameters
    ----------
    channels : array_like, shape (n, 6) or (n, 8)
        The plate's channels in N and N·mm (type 1: Fx Fy Fz, COP x y (mm), Tz; types 2
        and 4: Fx Fy Fz Mx My Mz; type 3: fx12 fx34 fy14 fy23 fz1 fz2 fz3 fz4), in the
        plate frame, as C3D files store them: the load of the ground on the body (in
        every shared file a foot's load reads as a negative Fz, the plate's z pointing
        down; ezc3d reads them so too).
    plate_type : {1, 2, 3, 4}
    corners : array_like, shape (4, 3)
        The top surface's corners in the lab (mm), in the order of FORCE_PLATFORM:CORNERS.
    origin : array_like, shape (3,)
        Types 2 and 4: the vector from the sensors' origin to the centre of the top
        surface, plate frame (mm, z negative); type 3: Kistler's a, b and az0; type 1:
        unused.
    cal_matrix : array_like, shape (6, 6), optional
        Type 4's calibration matrix (outputs = cal_matrix @ channels).
    cop_threshold : float, optional
        Vertical force (N) below which the centre of pressure and the free moment are
        NaN (default 20 N).

    Returns
    -------
    force, cop, free_moment, moment : ndarray, shape (n, 3)
        In the lab frame: the force of the ground on the body (N), the centre of
        pressure on the top surface (mm), the free moment of the ground on the body
        about it (N·mm, along the plate's normal), and the moment of the ground on the
        body about the centre of the top surface, :math:`\mathbf M_C` (N·mm; defined
        under any load, unlike the centre of pressure).

    Notes
    -----
    In the plate frame (z into the plate, :func:`_plate_axes`) the plate measures the
    force :math:`\mathbf F` and the moment :math:`\mathbf M_O` about its sensors' origin
    :math:`O` (type 4: :math:`[\mathbf F; \mathbf M_O] = C\,\mathbf v`; type 3 from
    Kistler's formulae: :math:`F_x = f_{x12} + f_{x34}`, :math:`F_y = f_{y14} + f_{y23}`,
    :math:`F_z = \sum f_{zi}`, :math:`M_x = b(f_{z1} + f_{z2} - f_{z3} - f_{z4})`,
    :math:`M_y = a(-f_{z1} + f_{z2} + f_{z3} - f_{z4})`,
    :math:`M_z = b(f_{x34} - f_{x12}) + a(f_{y14} - f_{y23})`, about the plate's centre
    at the sensors' height :math:`a_{z0}` below the surface). With
    :math:`\mathbf r = (d_x, d_y, d_z)` from :math:`O` to the surface's centre :math:`C`
    (type 3: :math:`(0, 0, a_{z0})`), the moment about :math:`C` is

    .. math:: \mathbf M_C = \mathbf M_O + \mathbf F \times \mathbf r .

    The centre of pressure :math:`\mathbf p = (p_x, p_y, 0)` (from :math:`C`, on the
    surface) is the point about which the moment has no horizontal component:
    :math:`\mathbf M_C - \mathbf p \times \mathbf F = (0, 0, T_z)`, so

    .. math::
        p_x = -\frac{M_{C,y}}{F_z} = \frac{-M_{O,y} - F_z d_x + F_x d_z}{F_z}, \qquad
        p_y = \frac{M_{C,x}}{F_z} = \frac{M_{O,x} + F_y d_z - F_z d_y}{F_z},

    .. math:: T_z = M_{C,z} - p_x F_y + p_y F_x .

    With :math:`d_z = -h` (the surface :math:`h` above the sensors) and the centre at
    the origin's vertical, :math:`p_x = (-M_y - h F_x)/F_z`: the textbook formula of a
    plate whose z points down. The lab's values are :math:`R\mathbf F`,
    :math:`\mathbf c + R\mathbf p` and :math:`T_z R\hat{\mathbf z}` (:math:`R` the
    plate's axes, :math:`\mathbf c` the corners' mean). Whether the channels give the
    load on the plate or on the body, :math:`\mathbf p` is the same (a ratio of the
    two); :math:`\mathbf p` and :math:`T_z` are NaN where the vertical load
    :math:`-F_z` is below `cop_threshold`: a moment divided by a small force is noise.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.files.force_plates import plate_loads
    >>> # a 600 x 400 mm plate centred at the lab's origin: its x along the lab's y, its
    >>> # y along the lab's x, its z down (the corners' order says so)
    >>> corners = [[300, 200, 0], [300, -200, 0], [-300, -200, 0], [-300, 200, 0]]
    >>> # 600 N straight up on the body at plate x = 50 mm, y = 20 mm: Fz = -600 N,
    >>> # Mx = p_y Fz and My = -p_x Fz about the surface's centre (40 mm above O)
    >>> channels = [[0.0, 0.0, -600.0, 20 * -600.0, -50 * -600.0, 0.0]]
    >>> force, cop, free, moment = plate_loads(channels, 2, corners, [0, 0, -40])
    >>> print(force.round(6) + 0.0, cop.round(6) + 0.0)
    [[  0.   0. 600.]] [[20. 50.  0.]]
    """
    channels = as_float_array(channels, "channels")
    axes = _plate_axes(np.asarray(corners, dtype=float))
    if plate_type not in PLATE_TYPES:
        raise ValueError(f"plate_type must be one of {', '.join(map(str, PLATE_TYPES))}; "
                         f"got {plate_type!r}")
    if channels.ndim != 2 or channels.shape[1] != PLATE_TYPES[plate_type]:
        raise ValueError(f"channels must have shape (n, {PLATE_TYPES[plate_type]}) for a type "
                         f"{plate_type} plate; got {channels.shape}")
    if plate_type == 1:
        force = channels[:, :3]
        cop = np.column_stack([channels[:, 3:5], np.zeros(len(channels))])
        torque = channels[:, 5]
        moment = np.cross(cop, force) + torque[:, None] * [0.0, 0.0, 1.0]
    else:
        force, moment, r = _force_and_moment(channels, plate_type, np.asarray(origin, float),
                                             cal_matrix)
        moment = moment + np.cross(force, r)
        with np.errstate(divide="ignore", invalid="ignore"):
            cop = np.column_stack([-moment[:, 1] / force[:, 2], moment[:, 0] / force[:, 2],
                                   np.zeros(len(force))])
            torque = moment[:, 2] - cop[:, 0] * force[:, 1] + cop[:, 1] * force[:, 0]
    small = ~(-force[:, 2] >= cop_threshold)      # the load presses along -z
    cop[small] = np.nan
    torque = np.where(small, np.nan, torque)
    centre = np.asarray(corners, dtype=float).mean(axis=0)
    return (force @ axes.T, centre + cop @ axes.T, torque[:, None] * axes[:, 2],
            moment @ axes.T)


def _force_and_moment(channels, plate_type, origin, cal_matrix):
    """Force, moment about the sensors' origin and the vector to the surface's centre
    (plate frame) of a type 2, 3 or 4 plate (see plate_loads)."""
    if plate_type == 3:
        f = channels.T
        a, b, az0 = origin
        force = np.column_stack([f[0] + f[1], f[2] + f[3], f[4] + f[5] + f[6] + f[7]])
        moment = np.column_stack([b * (f[4] + f[5] - f[6] - f[7]),
                                  a * (f[5] + f[6] - f[4] - f[7]),
                                  b * (f[1] - f[0]) + a * (f[2] - f[3])])
        return force, moment, np.array([0.0, 0.0, az0])
    if plate_type == 4:
        channels = channels @ np.asarray(cal_matrix, dtype=float).T
    return channels[:, :3], channels[:, 3:6], origin


def _vertical_load(channels, setup):
    """A plate's vertical load (N, along -z of the plate: positive under a foot)."""
    force = plate_loads(channels, setup["type"], setup["corners"], setup["origin"],
                        setup["cal_matrix"], cop_threshold=np.inf)[0]
    return force @ -_plate_axes(setup["corners"])[:, 2]


def _plate_zero(channels, setup, zero, rate, point_rate, name):
    """The offsets (one per channel) to subtract from a plate's channels (read_force_plates'
    `zero`), and a note when the plate left unzeroed reads more than UNLOADED unloaded;
    type 1's centre-of-pressure channels are never offset."""
    offsets = np.zeros(channels.shape[1])
    first, last = setup["zero_frames"]
    if zero == "file" and 1 <= first <= last:
        per_frame = int(round(rate / point_rate))
        offsets = channels[(first - 1) * per_frame:last * per_frame].mean(axis=0)
    vertical = _vertical_load(channels - offsets, setup)
    lowest = np.nanpercentile(vertical, 1)
    unloaded = vertical < lowest + UNLOADED
    level = np.median(vertical[unloaded])
    if zero == "unloaded":
        if unloaded.sum() < MIN_UNLOADED * rate or abs(lowest) > MAX_OFFSET:
            return offsets, (f"{name} not zeroed: its vertical load never stays within "
                             f"{UNLOADED:g} N of its lowest level ({lowest:.0f} N) for "
                             f"{MIN_UNLOADED:g} s, or that level exceeds {MAX_OFFSET:g} N "
                             "(someone on it throughout?)")
        offsets = np.median(channels[unloaded], axis=0)
        level = 0.0
    if setup["type"] == 1:
        offsets[3:5] = 0.0
    note = (f"{name} reads {level:.0f} N unloaded (not zeroed: zero={zero!r}; "
            "zero='unloaded' removes it)" if abs(level) > UNLOADED else None)
    return offsets, note


def check_load_continuity(load, rate, name):
    """Raise when a plate's vertical load jumps between two analog samples as no foot's
    load can (:data:`MAX_JUMP`): the analog data are damaged.

    Parameters
    ----------
    load : array_like, shape (n,)
        The plate's vertical load (N), zeroed, at the analog rate.
    rate : float
        The analog rate (Hz); below :data:`MIN_JUMP_RATE` nothing is checked.
    name : str
        The plate, for the message.

    Raises
    ------
    ValueError
        Naming the largest jump, its time and how many samples jump so.

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.files.force_plates import check_load_continuity
    >>> load = np.r_[np.zeros(100), np.linspace(0, 600, 30), np.full(100, 600.0)]
    >>> check_load_continuity(load, 1000.0, "plate 1")       # 20 N per ms: a foot
    >>> check_load_continuity(np.r_[np.zeros(100), np.full(100, 600.0)], 1000.0, "plate 1")
    Traceback (most recent call last):
    ...
    ValueError: plate 1: its vertical load jumps by 600 N (100 % of its peak load) between two analog samples 1 ms apart, at 0.099 s (1 such jump): no foot loads a plate that fast; the analog data are damaged (e.g. blocks of samples written out of order), so no force is read from them
    """
    load = np.asarray(load, dtype=float)
    if rate < MIN_JUMP_RATE or load.size < 2 * JUMP_SPAN + 1:
        return
    # the median of each JUMP_SPAN samples: an electrical spike of a sample or two
    # leaves it (Static_trial.c3d's unloaded plates spike by 80 N), a level does not
    level = np.median(np.lib.stride_tricks.sliding_window_view(load, JUMP_SPAN), axis=1)
    peak = np.nanmax(np.abs(level))
    if not peak > UNLOADED:
        return
    jumps = np.abs(np.diff(load))
    shift = np.zeros_like(jumps)        # level after sample i minus level up to it
    shift[JUMP_SPAN - 1:len(level) - 1] = np.abs(level[JUMP_SPAN:] - level[:-JUMP_SPAN])
    bad = np.flatnonzero((jumps > MAX_JUMP * peak) & (shift > MAX_JUMP * peak))
    if bad.size:
        worst = bad[np.argmax(jumps[bad])]
        raise ValueError(f"{name}: its vertical load jumps by {jumps[worst]:.0f} N "
                         f"({100 * jumps[worst] / peak:.0f} % of its peak load) between two "
                         f"analog samples {1000 / rate:.3g} ms apart, at {worst / rate:.3f} s "
                         f"({bad.size} such jump{'s' if bad.size > 1 else ''}): no foot loads "
                         "a plate that fast; the analog data are damaged (e.g. blocks of "
                         "samples written out of order), so no force is read from them")


def resample_force_plates(plates):
    r"""The plates' loads at the marker rate, averaged over each frame as Vicon Nexus does.

    Parameters
    ----------
    plates : pandas.DataFrame
        As :func:`read_force_plates` returns (its ``attrs`` give both rates).

    Returns
    -------
    pandas.DataFrame
        The same columns, one row per marker frame (``time`` = frame / marker rate, as
        :func:`read_c3d`'s index): the force and the moment about the plate's centre,
        each the mean of the analog samples within half a frame of the frame's instant
        (the :math:`r` samples centred on it for an odd ratio :math:`r` of the rates,
        :math:`r + 1` with the two end ones weighted one half for an even ratio; at
        the first and last frames the window is cut to the samples there are); the
        centre of pressure and free moment from them (:func:`cop_from_moment`), NaN
        under `cop_threshold`. (Columns of a table without the reader's ``attrs``
        are all averaged.)

    Raises
    ------
    ValueError
        If `plates` has no analog and marker rate in its ``attrs``, the analog rate is
        not a whole multiple of the marker rate, or a plate of ``attrs['plates']`` lacks
        a column the reader writes (named).

    Notes
    -----
    Vicon Nexus 2.6 stores the ground reaction force and its moment about the plate's
    centre at the marker rate (``LGroundReactionForce``, N/kg;
    ``LGroundReactionMoment``, N·mm/kg) in the shared stair descent (plates at 1080
    Hz, markers at 120 Hz, nine samples a frame). Against it, the mean of the nine
    samples centred on each frame's instant (samples :math:`9k - 4` to :math:`9k + 4`)
    differs by 5e-7 N/kg and 1e-4 N·mm/kg at most (the file's float32), the mean of the
    frame's own nine samples (:math:`9k` to :math:`9k + 8`) by 0.21-0.22 N/kg RMS
    (vertical), and the sample at the frame's instant by 0.03-0.11 N/kg
    (``tests/test_force_plate_reader.py``).

    Examples
    --------
    >>> from bmc_functions import read_force_plates, resample_force_plates
    >>> from bmc_functions.examples import example_file
    >>> plates = read_force_plates(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> frames = resample_force_plates(plates)
    >>> print(len(plates), len(frames), frames.attrs["rate"])
    2907 323 120.0
    """
    ratio = resampling_ratio(plates)
    rate, point_rate = plates.attrs["rate"], plates.attrs["point_rate"]
    values = plates.to_numpy(dtype=float)
    n_frames = -(-len(values) // ratio)
    centres = np.arange(n_frames) * ratio
    columns = {number: plate_columns(plates, number)
               for number in range(1, len(plates.attrs.get("plates", [])) + 1)}
    # the centre of pressure and free moment follow from the averaged force and moment
    derived = {k for column in columns.values() for kind in ("cop", "free_moment")
               for k in column[kind]}
    averaged = np.empty((n_frames, values.shape[1]))
    kept = [k for k in range(values.shape[1]) if k not in derived]
    averaged[:, kept] = frame_means(values, ratio, kept)
    for number, plate in enumerate(plates.attrs.get("plates", []), start=1):
        column = columns[number]      # on the array, by position (no DataFrame per step)
        averaged[:, column["cop"]], averaged[:, column["free_moment"]] = cop_from_moment(
            averaged[:, column["force"]], averaged[:, column["moment"]],
            np.mean(plate["corners"], axis=0), plate["normal"],
            plates.attrs.get("cop_threshold", COP_THRESHOLD))
    table = pd.DataFrame(averaged, index=pd.Index(centres / rate, name="time"),
                         columns=plates.columns)
    table.attrs = dict(plates.attrs) | {"rate": point_rate, "analog_rate": rate}
    return table


def resampling_ratio(plates):
    """The analog samples per marker frame of `plates` (:func:`read_force_plates`' table),
    a whole number; the errors of :func:`resample_force_plates`."""
    if not isinstance(plates, pd.DataFrame):
        raise ArgumentTypeError(f"plates must be the DataFrame read_force_plates returns; "
                                f"got {type(plates).__name__}")
    rate, point_rate = plates.attrs.get("rate"), plates.attrs.get("point_rate")
    if rate is None or point_rate is None:
        raise ValueError("plates: attrs 'rate' and 'point_rate' are missing; give the "
                         "DataFrame read_force_plates returns")
    ratio = rate / point_rate
    if abs(ratio - round(ratio)) > 1e-6 or round(ratio) < 1:
        raise ValueError(f"plates: the analog rate ({rate:g} Hz) is not a whole multiple of "
                         f"the marker rate ({point_rate:g} Hz)")
    return int(round(ratio))


def plate_columns(plates, number, kinds=("force", "moment", "cop", "free_moment")):
    """Positions of plate `number`'s columns in `plates`: kind (of `kinds`) -> the x, y, z
    columns; a ValueError naming the columns missing (a table cut down by its user)."""
    position = {key: k for k, key in enumerate(plates.columns)}
    missing = [(number, f"{kind}_{a}") for kind in kinds for a in "xyz"
               if (number, f"{kind}_{a}") not in position]
    if missing:
        raise ValueError(f"plates: plate {number} of attrs['plates'] has no column "
                         f"{', '.join(map(str, missing))}; expected the x, y and z columns "
                         f"of its {', '.join(kinds)}, as read_force_plates writes them")
    return {kind: np.array([position[(number, f"{kind}_{a}")] for a in "xyz"])
            for kind in kinds}


def frame_means(values, ratio, columns, frames=None):
    """The mean of each marker frame's analog samples (:func:`resample_force_plates`'
    windows, `ratio` samples a frame) of the `columns` of `values` (samples, columns):
    an array (frames, len(columns)); only the ascending `frames` when given. A column at
    a time: each column of a table is contiguous (no copy of the others), and the sums
    are those of all columns at once."""
    windows = _frame_windows(len(values), ratio, frames)
    means = np.empty((len(windows[0]), len(columns)))
    for k, column in enumerate(columns):
        means[:, k] = _frame_sums(values[:, column], ratio, windows) / windows[3]
    return means


def plate_loads_at_marker_rate(plates, ratio, numbers, frames=None):
    """The force (N) and the moment about the plate's centre (N·mm) of the plates `numbers`
    of `plates` (:func:`read_force_plates`' table), lab frame, at the marker rate: each
    frame the mean of its `ratio` analog samples, as :func:`resample_force_plates` gives
    them (`ratio` 1: the table's own rows). A dict number -> (force, moment), each
    (frames, 3); only the plates asked for are averaged, and with `frames` (number -> the
    ascending marker frames wanted) only those frames (NaN in the others; at a ratio
    of 1 every frame, as it is)."""
    values = plates.to_numpy(dtype=float)
    n_frames = -(-len(values) // ratio)
    loads = {}
    for number in numbers:
        column = plate_columns(plates, number, ("force", "moment"))
        wanted = np.r_[column["force"], column["moment"]]
        if ratio == 1:
            means = values[:, wanted]
        elif frames is None:
            means = frame_means(values, ratio, wanted)
        else:
            means = np.full((n_frames, len(wanted)), np.nan)
            means[frames[number]] = frame_means(values, ratio, wanted, frames[number])
        loads[number] = (means[:, :3], means[:, 3:])
    return loads


def _frame_windows(n_samples, ratio, frames=None):
    """The windows of :func:`_frame_sums` over `n_samples` analog samples, found once for
    all the columns of a table: the frames (every frame, or the ascending `frames`), the
    bounds handed to ``np.add.reduceat``, the places of the frames' sums among its
    results, and each window's weight, its samples counted (an even ratio's two ends one
    half each) by arithmetic: whole or half numbers, the same as summing ones."""
    half = ratio // 2                  # (ratio - 1) / 2 samples either side when odd
    frames = np.arange(-(-n_samples // ratio)) if frames is None else np.asarray(frames)
    if frames.size == 0:
        return frames, None, None, np.zeros(0)
    starts = np.maximum(frames * ratio - half, 0)
    stops = np.minimum(frames * ratio - half + ratio, n_samples)
    last = np.r_[frames[1:] != frames[:-1] + 1, True]      # the last frame of each run
    at = np.arange(len(frames)) + np.r_[0, np.cumsum(last)[:-1]]    # the starts' places
    bounds = np.empty(len(frames) + int(last.sum()), dtype=np.intp)
    bounds[at], bounds[at[last] + 1] = starts, stops[last]
    if bounds[-1] >= n_samples:        # the recording's last window: reduceat runs to its end
        bounds = bounds[:-1]
    counts = (stops - starts).astype(float)
    if ratio % 2 == 0:                 # the window's two ends, each weighted one half
        counts[frames * ratio + half < n_samples] += 0.5
        counts[frames > 0] -= 0.5
    return frames, bounds, at, counts


def _frame_sums(values, ratio, windows=None):
    """Each marker frame's weighted sum of the analog samples (samples, ...) within
    half a frame of its instant (sample k * `ratio`): `ratio` samples for an odd ratio,
    `ratio` + 1 with the two end ones weighted 1/2 for an even one; samples beyond the
    ends count zero. Every frame, or those of `windows` (:func:`_frame_windows`). The
    windows of consecutive frames abut: one pass of ``np.add.reduceat`` over their starts
    and, after each run of consecutive frames, its last stop (the sums between runs are
    dropped)."""
    frames, bounds, at, _ = _frame_windows(len(values), ratio) if windows is None else windows
    if frames.size == 0:
        return np.zeros((0,) + np.shape(values)[1:])
    half = ratio // 2
    sums = np.add.reduceat(values, bounds, axis=0)[at]
    if ratio % 2 == 0:                 # the window's two ends, each weighted one half
        ends = frames * ratio + half
        sums[ends < len(values)] += 0.5 * values[ends[ends < len(values)]]
        sums[frames > 0] -= 0.5 * values[frames[frames > 0] * ratio - half]
    return sums


def cop_from_moment(force, moment, centre, normal, cop_threshold=COP_THRESHOLD):
    r"""The centre of pressure and free moment from a force and its moment about the
    centre of a plate's top surface (all in the lab frame).

    Parameters
    ----------
    force, moment : array_like, shape (n, 3)
        The force (N) and its moment about `centre` (N·mm) of the ground on the body.
    centre : array_like, shape (3,)
        The centre of the plate's top surface (mm).
    normal : array_like, shape (3,)
        The plate's unit normal, pointing into the plate.
    cop_threshold : float, optional
        Load (N, along ``-normal``) below which both are NaN (default 20 N).

    Returns
    -------
    cop, free_moment : ndarray, shape (n, 3)

    Notes
    -----
    With :math:`\mathbf M_C = \mathbf p \times \mathbf F + T\hat{\mathbf n}` and
    :math:`\mathbf p \perp \hat{\mathbf n}`,
    :math:`\hat{\mathbf n} \times \mathbf M_C = \mathbf p\,(\hat{\mathbf n}\cdot
    \mathbf F)`, so :math:`\mathbf p = \hat{\mathbf n} \times \mathbf M_C /
    (\hat{\mathbf n} \cdot \mathbf F)` and :math:`T = \hat{\mathbf n} \cdot
    (\mathbf M_C - \mathbf p \times \mathbf F)`: :func:`plate_loads`' formulae in
    any frame.

    Examples
    --------
    >>> from bmc_functions.files.force_plates import cop_from_moment
    >>> # 600 N up at 20 mm along x from the centre, no free moment: M_C = p x F
    >>> cop, free = cop_from_moment([[0, 0, 600.0]], [[0, -12000.0, 0]], [0, 0, 0],
    ...                             [0, 0, -1.0])
    >>> print(cop + 0.0, free + 0.0)
    [[20.  0.  0.]] [[0. 0. 0.]]
    """
    force, moment = np.asarray(force, float), np.asarray(moment, float)
    normal = np.asarray(normal, float)
    along = force @ normal
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.cross(normal, moment) / along[:, None]
    torque = (moment - np.cross(p, force)) @ normal
    small = ~(-along >= cop_threshold)
    p[small] = np.nan
    torque[small] = np.nan
    return np.asarray(centre, float) + p, torque[:, None] * normal


# --- which foot stands on which plate ----------------------------------------------------

#: Vertical force (N) above which a foot is on a plate. Laboratories use 10-50 N; 20 N
#: lies six standard deviations above the noise of the unloaded plates here after the
#: low-pass filter (0.5-3.5 N; 0.4-9 N unfiltered) and far below a foot's load.
CONTACT_THRESHOLD = 20.0

#: Shortest loaded interval (s) taken as a foot contact: a walking stance lasts 0.5 s or
#: more, a sprinter's about 0.1 s; a shorter crossing is noise, a bump or a swing-foot tap.
MIN_CONTACT = 0.08

#: Low-pass cut-off (Hz) of the plate forces before the threshold: the mains hum (50-60
#: Hz) and plate noise lie at or above it, while the load of a foot strike rises over
#: 10-30 ms (zero-lag: the crossings stay within 15 ms of the raw channel's, tested).
FORCE_CUTOFF = 50.0

#: A foot is on a plate when its markers lie over the plate's top within this margin (mm).
PLATE_MARGIN = 50.0

#: A foot that stands on a plate moves less than this (mm, horizontally) over the middle
#: half of the contact; the swing foot passing beside it moves half a stride or more.
MAX_TRAVEL = 150.0


def loaded_runs(vertical, rate, threshold, min_contact):
    """Start and stop sample indices ([start, stop)) of the runs of `vertical` above
    `threshold` lasting `min_contact` (s) or more at `rate` (Hz).

    Examples
    --------
    >>> import numpy as np
    >>> from bmc_functions.files.force_plates import loaded_runs
    >>> vertical = np.r_[np.zeros(10), np.full(100, 500.0), np.zeros(10)]
    >>> print(loaded_runs(vertical, 1000.0, 20.0, 0.08))
    (array([10]), array([110]))
    """
    above = np.asarray(vertical) > threshold
    # the samples where `above` changes, and its ends when loaded there (the edges of
    # `above` padded with False either side, without the padded copy and its difference)
    change = np.flatnonzero(above[1:] != above[:-1]) + 1
    first = [0] if above.size and above[0] else []
    edges = np.concatenate((np.array(first, dtype=np.intp), change,
                            np.array([above.size] if above.size and above[-1] else [],
                                     dtype=np.intp)))
    starts, stops = edges[0::2], edges[1::2]
    keep = (stops - starts) >= min_contact * rate
    return starts[keep], stops[keep]


def normal_load(force, corners, analog_rate, threshold, scratch=None):
    """The magnitude of a plate's force (3, samples) along its normal, low-pass filtered
    (FORCE_CUTOFF, zero lag) and with the unloaded plate's offset removed; and the unit
    normal (corners (3, 4), lab). `scratch`, an array (2, samples) a caller with several
    plates hands to each, holds the force along the normal before the filter and the
    sorted samples: one pair of arrays for all the plates rather than two fresh ones per
    plate (fresh arrays cost the kernel's zeroing of their pages); the same numbers."""
    corners = np.asarray(corners, dtype=float)
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normal /= np.linalg.norm(normal)
    design = _force_filter(float(analog_rate))
    force = np.asarray(force, dtype=float)
    filtered = force[0].size > default_padlen(design)      # the product's size
    # the filter copies the product, so its buffer can serve the next plate; unfiltered,
    # the product is the result and has an array of its own
    product, ordered = (scratch if scratch is not None and filtered and force.ndim == 2
                        and scratch.shape == (2, force.shape[1]) else (None, None))
    along = np.matmul(normal, force, out=product)
    if filtered:
        along = sosfiltfilt(design, along)
    # the plate's zero: a load lies on one side of it, so it is the level of the lowest
    # or of the highest samples (within `threshold` of the 1st or 99th percentile),
    # whichever is nearer zero (an offset is tens of N, a foot's load hundreds), then
    # the median of the samples within `threshold` of it, twice. Not the median of all
    # samples: a load when the plate is loaded over half the trial
    # (on the sorted samples: each set below is a slice of them, its median a lookup)
    if ordered is None:
        ordered = np.sort(along)
    else:                          # np.sort's copy and sort, into the scratch row
        ordered[...] = along
        ordered.sort()
    low, high = sorted_percentiles(ordered, [1, 99])
    ends = [sorted_median(ordered[:np.searchsorted(ordered, low + threshold, side="right")]),
            sorted_median(ordered[np.searchsorted(ordered, high - threshold, side="left"):])]
    offset = min(ends, key=abs)
    for _ in range(2):             # the samples within `threshold` of it, ends excluded
        offset = sorted_median(
            ordered[np.searchsorted(ordered, offset - threshold, side="right"):
                    np.searchsorted(ordered, offset + threshold, side="left")])
    # in place: `along` is this function's own array (the filter's or the product's)
    return np.abs(np.subtract(along, offset, out=along), out=along), normal


def _force_filter(analog_rate):
    """The low-pass filter of :func:`normal_load` at `analog_rate` (Hz), second-order
    sections: designed once per rate, not once per plate (a copy of the design kept:
    scipy's filter needs a writable array)."""
    return _force_design(analog_rate).copy()


@functools.lru_cache(maxsize=8)
def _force_design(analog_rate):
    """:func:`_force_filter`'s design, kept per rate (private: only copies leave)."""
    return butter(2, min(FORCE_CUTOFF, 0.4 * analog_rate), fs=analog_rate, output="sos")


def sorted_median(ordered):
    """``np.median`` of the sorted 1-D `ordered`, by lookup: its middle sample, or the mean
    of its two middle ones (numpy's arithmetic, the same number) without the partition of
    a copy; numpy itself when it is empty or holds NaN."""
    size = len(ordered)
    if size == 0 or np.isnan(ordered[-1]):
        return np.median(ordered)
    half = size // 2
    return ordered[half] if size % 2 else (ordered[half - 1] + ordered[half]) / 2.0


def sorted_percentiles(ordered, q):
    """``np.percentile(ordered, q)`` of the sorted 1-D `ordered` by lookup: numpy's default
    ('linear', Hyndman and Fan's 7th) interpolation between the two samples around the
    rank :math:`(n - 1) q / 100`, with its arithmetic (the same numbers); numpy itself
    when `ordered` is empty or holds NaN."""
    if len(ordered) == 0 or np.isnan(ordered[-1]):
        return np.percentile(ordered, q)
    rank = (len(ordered) - 1) * np.true_divide(q, 100)
    below = np.floor(rank).astype(np.intp)
    above = np.minimum(below + 1, len(ordered) - 1)
    gamma = rank - below
    a, b = ordered[below], ordered[above]
    step = b - a
    # numpy's lerp: from the nearer end, so that a weight of 1 gives b exactly
    return np.where(gamma >= 0.5, b - step * (1 - gamma), a + step * gamma)


def default_padlen(sos):
    """scipy's default padding of sosfiltfilt for `sos` (samples)."""
    zeros = min(int((sos[:, 2] == 0).sum()), int((sos[:, 5] == 0).sum()))
    return 3 * (2 * len(sos) + 1 - zeros)


def feet_on_plate(feet, corners, normal, starts, stops, rates, n_frames, cumulative=None):
    """For each contact of a plate (analog samples [start, stop)), the side whose foot
    stands over the plate (None unless exactly one) and the sides found over it.

    `feet` maps a side to its foot's position (frames, 3, mm), `corners` (3, 4, mm),
    `normal` the plate's unit normal, `rates` the analog and the marker rates (Hz). A
    foot stands over the plate when its mean position over the middle half of the
    contact (NaN frames left out) lies over the plate (:func:`over_plate`) and it moves
    less than ``MAX_TRAVEL`` in the plate's plane meanwhile. All contacts at once;
    `cumulative` (side -> :func:`cumulative_finite` of its foot) saves recomputing them
    for every plate.
    """
    analog_rate, point_rate = rates
    starts, stops = np.asarray(starts, float), np.asarray(stops, float)
    # the middle half of each contact, in marker frames
    first, last = np.clip(np.round(np.array([0.75 * starts + 0.25 * stops,
                                             0.25 * starts + 0.75 * stops])
                                   / analog_rate * point_rate).astype(int), 0, n_frames - 1)
    centre = corners.mean(axis=1)
    over = {}
    for side, foot in feet.items():                 # a side at a time (two), not frames
        sums = cumulative_finite(foot) if cumulative is None else cumulative[side]
        where = _window_nanmean(sums, first, last) - centre
        travel = foot[last] - foot[first]
        travel = np.linalg.norm(travel - (travel @ normal)[:, None] * normal, axis=-1)
        horizontal = where - (where @ normal)[:, None] * normal
        over[side] = (np.isfinite(horizontal).all(axis=-1) & ~(travel > MAX_TRAVEL)
                      & over_plate(horizontal, corners, centre, normal))
    found = [[side for side in feet if over[side][k]] for k in range(len(starts))]
    return [(sides[0] if len(sides) == 1 else None, sides) for sides in found]


def cumulative_finite(values):
    """The cumulative sums of the finite `values` (frames, 3) and their cumulative counts,
    each from a first row of zeros (frames + 1, 3): any window's sum is a difference."""
    finite = np.isfinite(values)
    sums, counts = np.zeros((2, len(finite) + 1, 3))    # each sum written below its zeros
    kept = np.where(finite, values, 0.0)
    np.cumsum(kept, axis=0, dtype=kept.dtype, out=sums[1:])    # added in values' type
    np.cumsum(finite, axis=0, out=counts[1:])
    return sums, counts


def _window_nanmean(cumulative, first, last):
    """The mean of the finite values in frames [first, last] (both included) of each
    window, per coordinate (NaN when none), from their :func:`cumulative_finite`: all
    windows at once."""
    sums, counts = cumulative
    total, count = sums[last + 1] - sums[first], counts[last + 1] - counts[first]
    return np.divide(total, count, out=np.full(total.shape, np.nan), where=count > 0)


def over_plate(horizontal, corners, centre, normal):
    """Whether a point (..., 3; relative to the plate centre, in the plate's plane) lies
    over the plate's rectangle (corners (3, 4)), within PLATE_MARGIN."""
    edge_u = corners[:, 0] - corners[:, 1]
    edge_v = corners[:, 1] - corners[:, 2]
    half_u, half_v = 0.5 * np.linalg.norm(edge_u), 0.5 * np.linalg.norm(edge_v)
    return ((np.abs(horizontal @ (edge_u / (2 * half_u))) <= half_u + PLATE_MARGIN)
            & (np.abs(horizontal @ (edge_v / (2 * half_v))) <= half_v + PLATE_MARGIN))


def plate_contacts(forces, corners, rates, feet, *, threshold=CONTACT_THRESHOLD,
                   min_contact=MIN_CONTACT):
    """Every contact of every plate and the foot it is assigned to (arrays in).

    Parameters
    ----------
    forces : array_like, shape (plates, 3, samples)
        Each plate's force in the lab (N): an array or a list of (3, samples) arrays.
    corners : array_like, shape (plates, 3, 4)
        Each plate's corners in the lab (mm).
    rates : tuple of float
        The analog and the marker rates (Hz).
    feet : dict
        Side -> the foot's position (frames, 3; mm, lab): the mean of its markers.
    threshold, min_contact : float, optional
        As :func:`assign_plates`.

    Returns
    -------
    list of tuple
        ``(plate, side, start, stop, reason)``: plate from 1, side None when not
        assigned, analog samples [start, stop), and why not (None when assigned).
    """
    n_frames = len(next(iter(feet.values())))
    cumulative = {side: cumulative_finite(foot) for side, foot in feet.items()}  # once
    scratch = np.empty((2, np.shape(forces[0])[-1])) if len(forces) else None
    found = []
    for plate in range(len(forces)):                # loop over plates (a few), not frames
        vertical, normal = normal_load(forces[plate], corners[plate], rates[0], threshold,
                                       scratch)
        starts, stops = loaded_runs(vertical, rates[0], threshold, min_contact)
        on_plate = feet_on_plate(feet, corners[plate], normal, starts, stops, rates, n_frames,
                                 cumulative)
        for start, stop, (side, over) in zip(starts, stops, on_plate):
            reason = None if side else f"{'both feet' if over else 'no foot'} over it"
            found.append([plate + 1, side, int(start), int(stop), reason])
    for one, other in _same_foot_elsewhere(found):  # one foot on two plates at once
        found[one][4] = f"the {found[one][1]} foot also on plate {found[other][0]}"
    return [(plate, side if reason is None else None, start, stop, reason)
            for plate, side, start, stop, reason in found]


def _same_foot_elsewhere(found):
    """Pairs (i, j) of contacts of `found` (``[plate, side, start, stop, reason]``) in
    which the foot of contact i stands on another plate during it: j, the last such
    contact listed; ascending i. All pairs of a foot's contacts at once (contacts x
    contacts booleans), a foot at a time: the pairs of two feet's contacts never count,
    and leaving them out builds a quarter of the booleans."""
    if not found:
        return []
    plate, start, stop = (np.array([one[k] for one in found]) for k in (0, 2, 3))
    pairs = {}
    for side in {one[1] for one in found if one[1] is not None}:    # two feet, not frames
        mine = np.flatnonzero([one[1] == side for one in found])
        p, a, b = plate[mine], start[mine], stop[mine]
        both = ((p[:, None] != p[None, :])
                & (a[:, None] < b[None, :]) & (a[None, :] < b[:, None]))
        last = mine[len(mine) - 1 - np.argmax(both[:, ::-1], axis=1)]
        pairs.update((int(mine[i]), int(last[i])) for i in np.flatnonzero(both.any(axis=1)))
    return sorted(pairs.items())


def assign_plates(plates, trial, feet, *, threshold=CONTACT_THRESHOLD,
                  min_contact=MIN_CONTACT):
    r"""Each contact of each force plate, and the foot that stood on the plate alone.

    Parameters
    ----------
    plates : pandas.DataFrame
        As :func:`read_force_plates` returns.
    trial : pandas.DataFrame
        The trial's markers (:func:`read_c3d` of the same file: same marker rate, time
        0 at its first frame), with ``attrs['units']``.
    feet : dict
        Side -> list of the labels of that foot's markers, e.g. ``{'right': ['RHEE',
        'RTOE'], 'left': ['LHEE', 'LTOE']}``: their mean locates the foot.
    threshold : float, optional
        Vertical force (N) above which a plate is loaded (default 20 N).
    min_contact : float, optional
        Shortest contact (s) kept (default 0.08 s).

    Returns
    -------
    pandas.DataFrame
        One row per contact, in the order of the plates: ``plate`` (from 1), ``side``
        (None when not assigned), ``start`` and ``stop`` (s, first and last loaded
        sample on :func:`read_c3d`'s time axis), ``reason`` (why it is not assigned).

    Raises
    ------
    ValueError
        If a label of `feet` is not in `trial`, `trial` has no units or another rate, or
        a plate of `plates` lacks its force columns (named).
    TypeError
        If `feet` is not a dict of lists of labels.

    Warns
    -----
    RuntimeWarning
        Once, naming the contacts left unassigned and why.

    Notes
    -----
    Vicon Nexus assigns a plate to a foot from the foot's markers ("auto-detect ...
    based upon foot segment kinematics") and requires that a single foot be in contact
    with a plate [3]_; a foot on two plates is only taken with Plug-in Gait's advanced
    cross-plate option [3]_. The rule here: a contact is a run of the vertical force
    (low-pass filtered at ``FORCE_CUTOFF`` = 50 Hz, offset removed: the level of the lowest
    or the highest samples, whichever is nearer zero, refined twice) above `threshold` for
    `min_contact` or more; a foot stands on the plate when the mean of its markers, over
    the middle half of the contact, lies over the plate within ``PLATE_MARGIN`` (50 mm)
    and moves less than ``MAX_TRAVEL`` (150 mm) meanwhile (the swing foot passes over).
    The contact is assigned to that foot when it is the only one on the plate and it
    is on no other loaded plate at the same time; otherwise to none.

    References
    ----------
    .. [3] Vicon Nexus 2 user guide: "Force plate nodes" (Foot Contact: Auto-detect) and
       "Cross-plate foot strikes" ("the existing restriction that there must be only a
       single foot in contact with any given force plate still applies"), docs.vicon.com.

    Examples
    --------
    >>> from bmc_functions import read_c3d, read_force_plates, assign_plates
    >>> from bmc_functions.examples import example_file
    >>> path = example_file("plug_in_gait/Movement_trial.c3d")
    >>> feet = {"right": ["RHEE", "RTOE"], "left": ["LHEE", "LTOE"]}
    >>> contacts = assign_plates(read_force_plates(path), read_c3d(path), feet)
    >>> print(contacts[["plate", "side", "start", "stop"]].round(3).to_string(index=False))
     plate  side  start  stop
         1  left  1.914 2.691
         2 right  1.382 2.091
         3  left  0.875 1.553
         4 right  0.344 1.041
    """
    if not isinstance(plates, pd.DataFrame) or "plates" not in plates.attrs:
        raise ArgumentTypeError(f"plates must be the DataFrame read_force_plates returns; "
                                f"got {type(plates).__name__}")
    threshold = check_number(threshold, "threshold", positive=True)
    min_contact = check_number(min_contact, "min_contact", positive=True)
    positions = foot_positions(trial, feet, plates.attrs["point_rate"])
    check_same_time(trial, plates)
    forces = plate_forces(plates)
    corners = np.stack([np.asarray(p["corners"]).T for p in plates.attrs["plates"]])
    rate = plates.attrs["rate"]
    found = plate_contacts(forces, corners, (rate, plates.attrs["point_rate"]), positions,
                           threshold=threshold, min_contact=min_contact)
    table = pd.DataFrame([(plate, side, start / rate, (stop - 1) / rate, reason)
                          for plate, side, start, stop, reason in found],
                         columns=["plate", "side", "start", "stop", "reason"])
    left_out = table[table["side"].isna()]
    if len(left_out):
        warn(f"{len(left_out)} force-plate contact(s) not assigned to a foot: "
             + "; ".join(f"plate {row.plate} at {row.start:.3f}-{row.stop:.3f} s "
                         f"({row.reason})" for row in left_out.itertuples())
             + _units_hint(positions, corners), RuntimeWarning)
    table.attrs = {"threshold": threshold, "min_contact": min_contact, "feet": dict(feet)}
    return table


def plate_forces(plates):
    """Each plate's force (3, samples; N, lab) from :func:`read_force_plates`' table, a
    list: the table's own rows (its columns are contiguous), no copy, where the plate's
    force_x, force_y, force_z columns are adjacent as the reader writes them. A
    ValueError names a force column the table lacks (:func:`plate_columns`)."""
    rows = plates.to_numpy(dtype=float).T
    forces = []
    for number in range(1, len(plates.attrs["plates"]) + 1):
        wanted = plate_columns(plates, number, ("force",))["force"]
        first = wanted[0]
        forces.append(rows[first:first + 3] if (np.diff(wanted) == 1).all()
                      else rows[wanted])
    return forces


#: Ratio of the plates' distance from the lab's origin to the feet's below which the
#: trial's coordinates are in another unit than it declares (metres read as mm: 1/1000).
UNIT_HINT_RATIO = 0.02


def _units_hint(positions, corners):
    """A clause for the unassigned-contacts warning when the feet lie much nearer the lab's
    origin than the plates do (median distances; a trial in metres declared in mm), else
    an empty string."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        feet = np.nanmedian(np.concatenate([np.linalg.norm(p, axis=-1)
                                            for p in positions.values()]))
    plates = float(np.median(np.linalg.norm(corners, axis=1)))
    if np.isfinite(feet) and feet < UNIT_HINT_RATIO * plates:
        return (f". The feet's markers lie {feet:.3g} mm from the lab's origin (median), "
                f"the plates' corners {plates:.0f} mm: the trial's units are not what its "
                f"attrs['units'] says (metres read as mm?)")
    return ""


def check_same_time(trial, plates):
    """Raise unless `trial`'s time index starts with the plates' and ends within them (the
    frames are matched to the samples by position: another trial's or a shifted time base
    would be matched silently)."""
    step = 1.0 / plates.attrs["point_rate"]
    if len(trial) == 0 or len(plates) == 0:
        raise ValueError(f"trial and plates must hold frames; got {len(trial)} and "
                         f"{len(plates)}")
    t, p = np.asarray(trial.index, float), np.asarray(plates.index, float)
    if abs(t[0] - p[0]) > 0.5 * step or t[-1] > p[-1] + step:
        raise ValueError(f"trial: its time ({t[0]:g}-{t[-1]:g} s) is not the plates' "
                         f"({p[0]:g}-{p[-1]:g} s); give read_c3d and read_force_plates of "
                         f"the same file")


def foot_positions(trial, feet, point_rate):
    """Side -> the mean (frames, 3; mm) of the foot's markers in `trial` (see
    assign_plates), the trial checked against the plates' marker rate."""
    if not isinstance(trial, pd.DataFrame) or not isinstance(trial.columns, pd.MultiIndex):
        raise ArgumentTypeError(f"trial must be a marker DataFrame as read_c3d returns; "
                                f"got {type(trial).__name__}")
    rate = trial.attrs.get("rate")
    if rate is None or not np.isclose(float(rate), point_rate, rtol=1e-6):
        raise ValueError(f"trial: its rate ({rate} Hz) is not the plates' marker rate "
                         f"({point_rate:g} Hz); give read_c3d of the same file")
    scale = mm_per_unit(trial, "trial")[0]
    if not isinstance(feet, dict) or not all(isinstance(v, (list, tuple)) and v
                                             for v in feet.values()):
        raise ArgumentTypeError(f"feet must map each side to a list of marker labels; got "
                                f"{feet!r}")
    positions = {}
    for side, names in feet.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            positions[side] = scale * np.nanmean(_marker_stack(trial, side, names), axis=0)
    return positions


def _marker_stack(trial, side, names):
    """The markers `names` of `trial` stacked (markers, frames, 3), a ValueError naming those
    not in it. Their x, y, z columns are found by position and taken in one step (a
    DataFrame per marker and coordinate set copied the trial's attrs each time): the same
    values in the same C-ordered array as the list of each marker's columns gave."""
    wanted = [(name, a) for name in names for a in "xyz"]
    where = (trial.columns.get_indexer(wanted) if trial.columns.is_unique
             and trial.columns.nlevels == 2 else np.full(len(wanted), -1))
    if (where < 0).any():              # a label missing (or an unusual table): by label
        labels = set(trial.columns.get_level_values(0))
        missing = [name for name in names if name not in labels]
        if missing:
            raise ValueError(f"feet: {side} marker(s) {missing} not in the trial")
        return np.array([trial[name][["x", "y", "z"]].to_numpy(float) for name in names])
    columns = trial.iloc[:, where].to_numpy(float)          # (frames, 3 * markers)
    stack = np.empty((len(names), len(trial), 3))
    stack.transpose(1, 0, 2)[...] = columns.reshape(len(trial), len(names), 3)
    return stack
