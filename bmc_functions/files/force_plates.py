r"""Force plates: the ground reaction force, centre of pressure and free moment of a C3D file.

A C3D file stores what a force plate measured as analog channels and says how to read
them in its FORCE_PLATFORM group: the plate's type (which channels), its corners in the
lab, the position of its sensors' origin below the top surface (ORIGIN) and, for type 4,
a calibration matrix [1]_. :func:`read_force_plates` turns them into the ground reaction
force, its centre of pressure on the plate's top surface and the free moment, in the lab
frame, at the analog rate; :func:`resample_force_plates` averages them to the marker
rate as Vicon Nexus does; :func:`find_plate_contacts` gives each loaded interval and the
foot that stood on the plate alone, the rule by which a force is assigned to a foot.

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

import warnings

import numpy as np
import pandas as pd

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
#: the moment's noise over that force: with the unloaded plates' moment noise here (up to
#: about 2,000 N mm peak), 20 N leaves errors up to 100 mm, the size of a foot, and 200 N
#: (a foot's load early in stance) 10 mm. Below 20 N no foot is on the plate (the same
#: threshold as :func:`~bmc_functions.force_plate_events`'s contacts; Vicon Nexus draws
#: the force vector above 25 N by default).
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

#: Largest jump between consecutive analog samples of a force channel, in units of that
#: channel's typical step (the median absolute step): a foot loads a plate over 10-30 ms,
#: so at 400-2,000 Hz a real step is at most a few percent of the body weight, while a
#: block of samples written out of order jumps by the load itself between two samples.
#: The real trials here reach 160 typical steps (the heel strike's impact); see
#: :func:`check_analog_continuity`.
MAX_STEP = 1000.0

#: Quantities of each plate, in the columns of :func:`read_force_plates`.
QUANTITIES = ("force_x", "force_y", "force_z", "cop_x", "cop_y", "cop_z",
              "free_moment_x", "free_moment_y", "free_moment_z")


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


def read_force_plates(path, *, zero="unloaded", cop_threshold=COP_THRESHOLD):
    r"""The ground reaction force, centre of pressure and free moment of each force plate.

    Parameters
    ----------
    path : str or path-like
        A ``.c3d`` file with a FORCE_PLATFORM group (plate types 1-4) and its analog
        channels.
    zero : {'unloaded', 'file', 'none'}, optional
        How each plate is zeroed. ``'unloaded'`` (default): each channel's median over
        the samples where the plate is unloaded (vertical force within ``UNLOADED`` = 20
        N of its lowest level) is subtracted, when they last ``MIN_UNLOADED`` (0.1 s) or
        more; ``'file'``: the mean over the frames FORCE_PLATFORM:ZERO names (none when
        it is 0, 0); ``'none'``: the channels as stored.
    cop_threshold : float, optional
        Vertical force (N) below which the centre of pressure is NaN (default 20 N).

    Returns
    -------
    pandas.DataFrame
        Indexed by ``time`` (s, 0 at the first marker frame, as :func:`read_c3d`), at
        the analog rate; columns ``(plate, quantity)`` with plate 1, 2, ... and quantity
        ``force_x/y/z`` (N: the ground reaction force, the force of the ground on the
        body), ``cop_x/y/z`` (mm: the centre of pressure on the plate's top
        surface) and ``free_moment_x/y/z`` (N·mm: the moment of the ground on the body
        about the centre of pressure, along the plate's normal), all in the lab frame
        and in millimetres whatever the file's unit. ``attrs``: ``'rate'`` (analog, Hz),
        ``'point_rate'`` (Hz), ``'units'`` ({'force': 'N', 'position': 'mm', 'moment':
        'N·mm'}), ``'file_units'`` (the file's POINT:UNITS), ``'plates'`` (per plate a dict
        of ``type``, ``corners`` (4 x 3, mm, lab), ``origin`` (3, mm, plate frame, the
        sensors' origin to the top surface's centre), ``normal`` (unit, lab, pointing
        into the plate), ``zero`` (the offsets removed)), ``'cop_threshold'``, ``'zero'``
        and ``'source'``.

    Raises
    ------
    ValueError
        If the file has no force plate, a plate's type is not 1-4, its corners are all
        zero (the file does not say where it lies), its channels or parameters are
        missing, or its analog data jump as no force can (:func:`check_analog_continuity`:
        blocks written out of order).

    Notes
    -----
    See :func:`plate_loads` for the maths. ezc3d [2]_ reads the channels, already
    scaled as the C3D format says: (stored - ANALOG:OFFSET) x ANALOG:SCALE x
    ANALOG:GEN_SCALE. Moments are read in N·mm when the channel's unit (ANALOG:UNITS) or
    else the file's length unit (POINT:UNITS) says metres (N·m), converted otherwise.

    Examples
    --------
    >>> from bmc_functions import read_force_plates
    >>> from bmc_functions.examples import example_file
    >>> plates = read_force_plates(example_file("plug_in_gait/Movement_trial.c3d"))
    >>> print(plates.attrs["rate"], plates.attrs["point_rate"], plates.attrs["units"])
    1080.0 120.0 {'force': 'N', 'position': 'mm', 'moment': 'N·mm'}
    """
    zero = check_choice(zero, "zero", ("unloaded", "file", "none"))
    cop_threshold = check_number(cop_threshold, "cop_threshold", positive=True)
    raw = read_checked(path, _extract_raw, "read_force_plates")
    setups = plate_setups(raw, path)
    analogs = raw["analogs"]
    rate = float(np.ravel(raw["ANALOG"]["RATE"])[0])
    point_rate = float(np.ravel(raw["POINT"]["RATE"])[0])
    columns, described = [], []
    for number, setup in enumerate(setups, start=1):    # a few plates, not frames
        channels = analogs[setup["channels"]].T * setup["moment_scale"]
        check_analog_continuity(channels, f"{path}: plate {number}")
        offsets = _plate_zero(channels, setup, zero, rate, point_rate)
        loads = plate_loads(channels - offsets, setup["type"], setup["corners"],
                            setup["origin"], setup["cal_matrix"], cop_threshold=cop_threshold)
        columns.append(np.concatenate(loads, axis=1))
        described.append({key: np.asarray(setup[key]).tolist() for key in
                          ("type", "corners", "origin")}
                         | {"normal": _plate_axes(setup["corners"])[:, 2].tolist(),
                            "zero": np.asarray(offsets).ravel().tolist()})
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

    The plate frame's z points into the plate (down; :func:`_plate_axes`), and the top
    surface lies above the sensors, so the vector's z is negative. Files that store it
    with a positive z (Vicon's) store the opposite vector (the surface's centre to the
    origin): it is negated whole, as ezc3d does. Type 1 has no origin (its channels are
    already at the surface); type 3's x and y are Kistler's sensor offsets a and b.
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
    at +x +y, 2 at -x +y, 3 at -x -y, 4 at +x -y [1]_, so x = c1 - c2, y = c1 - c4
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
    force, cop, free_moment : ndarray, shape (n, 3)
        In the lab frame: the force of the ground on the body (N), the centre of
        pressure on the top surface (mm), and the free moment of the ground on the body
        about it (N·mm, along the plate's normal).

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
    >>> corners = [[200, 300, 0], [-200, 300, 0], [-200, -300, 0], [200, -300, 0]]
    >>> # 600 N straight up on the body at plate x = 50 mm, y = 20 mm (plate z down):
    >>> # Fz = -600 N, Mx = p_y Fz, My = -p_x Fz
    >>> channels = [[0.0, 0.0, -600.0, 20 * -600.0, -50 * -600.0, 0.0]]
    >>> force, cop, free = plate_loads(channels, 2, corners, [0, 0, -40])
    >>> print(force.round(6) + 0.0, cop.round(6) + 0.0)
    [[  0.   0. 600.]] [[-50.  20.   0.]]
    """
    channels = as_float_array(channels, "channels")
    axes = _plate_axes(np.asarray(corners, dtype=float))
    if plate_type == 1:
        force = channels[:, :3]
        cop = np.column_stack([channels[:, 3:5], np.zeros(len(channels))])
        torque = channels[:, 5]
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
    return force @ axes.T, centre + cop @ axes.T, torque[:, None] * axes[:, 2]


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


def _plate_zero(channels, setup, zero, rate, point_rate):
    """The offsets (one per channel) to subtract from a plate's channels (read_force_plates'
    `zero`); type 1's centre-of-pressure channels are never offset."""
    offsets = np.zeros(channels.shape[1])
    if zero == "none":
        return offsets
    if zero == "file":
        first, last = setup["zero_frames"]
        per_frame = int(round(rate / point_rate))
        if first < 1 or last < first:
            return offsets
        unloaded = slice((first - 1) * per_frame, last * per_frame)
        offsets = channels[unloaded].mean(axis=0)
    else:
        vertical = plate_loads(channels, setup["type"], setup["corners"], setup["origin"],
                               setup["cal_matrix"], cop_threshold=np.inf)[0] \
            @ -_plate_axes(setup["corners"])[:, 2]     # the load, along -z of the plate
        lowest = np.nanpercentile(vertical, 1)
        unloaded = vertical < lowest + UNLOADED
        if unloaded.sum() < MIN_UNLOADED * rate or abs(lowest) > MAX_OFFSET:
            return offsets
        offsets = np.median(channels[unloaded], axis=0)
    if setup["type"] == 1:
        offsets[3:5] = 0.0
    return offsets


def check_analog_continuity(channels, name):
    """Placeholder."""
    return None
