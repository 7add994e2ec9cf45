r"""Marker roles: which label of a lab's files plays which part in the lower-limb model.

A lab names its markers as it likes (``'R.ASIS'``, ``'RASI'``, ``'R_ASIS'`` ...); the
lower-limb pipeline (:func:`calibrate_lower_limb`) asks for *roles* and a mapping from
each role to the lab's label, or to a list of labels for a technical cluster. This module
holds the role table and turns a mapping into a checked one, with errors that name the
role, the label and the labels of the file that look close (:mod:`difflib`), so that a
typo is an error and never a wrong curve.

Roles (per side with the prefix ``R`` or ``L``): see :data:`PELVIS_ROLES` and
:data:`SIDE_ROLES`.
"""

import difflib
import json
from pathlib import Path

from .._checks import warn

#: Pelvis roles and what they mean. ``PELVIS`` is a technical cluster (3 or more labels).
PELVIS_ROLES = {
    "RASIS": "right anterior superior iliac spine",
    "LASIS": "left anterior superior iliac spine",
    "RPSIS": "right posterior superior iliac spine",
    "LPSIS": "left posterior superior iliac spine",
    "SACRUM": "sacral marker, midway between the posterior superior iliac spines",
    "PELVIS": "technical pelvis cluster (3 or more labels)",
}

#: Roles of one side, without the side prefix (``R`` or ``L``).
SIDE_ROLES = {
    "THIGH": "thigh cluster (3 or more labels)",
    "KNEE_LAT": "lateral femoral epicondyle",
    "KNEE_MED": "medial femoral epicondyle",
    "SHANK": "shank cluster (3 or more labels)",
    "ANKLE_LAT": "lateral malleolus",
    "ANKLE_MED": "medial malleolus",
    "HEEL": "heel (posterior calcaneus)",
    "TOE": "toe (forefoot, e.g. second metatarsal head)",
    "MT5": "fifth metatarsal head",
    "FOOT": "foot cluster (3 or more labels)",
    "HJC": "hip joint centre computed by the lab (hip_centre='marker')",
}

#: Roles that hold a technical cluster (a list of labels) rather than one label.
CLUSTER_ROLES = ("PELVIS", "THIGH", "SHANK", "FOOT")

#: Roles every computed side needs.
REQUIRED_SIDE_ROLES = ("KNEE_LAT", "KNEE_MED", "ANKLE_LAT", "ANKLE_MED")

#: Roles of the foot frame: a side without both has hip and knee angles only (its ankle
#: angles are NaN: many clinical walks have no heel marker).
FOOT_FRAME_ROLES = ("HEEL", "TOE")

SIDE_PREFIX = {"right": "R", "left": "L"}


def all_roles():
    """Every valid role name, pelvis roles first, then right and left side roles."""
    return list(PELVIS_ROLES) + [SIDE_PREFIX[side] + role for side in ("right", "left")
                                 for role in SIDE_ROLES]


def describe(role):
    """A role's meaning, e.g. 'right lateral femoral epicondyle'."""
    if role in PELVIS_ROLES:
        return PELVIS_ROLES[role]
    side = "right" if role[0] == "R" else "left"
    return f"{side} {SIDE_ROLES[role[1:]]}"


def is_cluster(role):
    """Whether `role` is a technical cluster role (PELVIS, RTHIGH, LSHANK, ...)."""
    return role == "PELVIS" or role[1:] in CLUSTER_ROLES[1:]


def _key(text):
    """A label as compared for suggestions: without spaces, case folded."""
    return "".join(str(text).split()).casefold()


def _same_but_case(word, candidates):
    """Candidates that differ from `word` only in case or spaces."""
    return [c for c in candidates if c != word and _key(c) == _key(word)]


def _close(word, candidates, cutoff=0.5):
    """Up to 3 candidates that look like `word` (difflib), ignoring case and spaces, those
    equal but for case and spaces first; as a string of reprs."""
    keys = {}
    for candidate in candidates:
        keys.setdefault(_key(candidate), []).append(candidate)
    matches = difflib.get_close_matches(_key(word), list(keys), n=3, cutoff=cutoff)
    found = _same_but_case(word, candidates) + [candidate for match in matches
                                                for candidate in keys[match]]
    found = [candidate for candidate in dict.fromkeys(found) if candidate != word][:3]
    return ", ".join(repr(candidate) for candidate in found)


def check_mapping(markers, sides=None, hip_centre="harrington"):
    """Validate a role -> label(s) mapping and choose the sides to compute.

    Parameters
    ----------
    markers : dict
        Role -> label (str), or role -> list of 3 or more labels for a cluster role.
    sides : None, str or sequence of {'right', 'left'}
        None: every side with at least one role in the mapping.
    hip_centre : str
        The hip-centre method; ``'marker'`` makes the ``RHJC``/``LHJC`` roles required.

    Returns
    -------
    mapping : dict
        Role -> label (str) or tuple of labels, for the roles in `markers`.
    sides : tuple of str

    Raises
    ------
    TypeError
        If `markers` is not a dict, a label is not a string, or `sides` is not a string
        or a list.
    ValueError
        For an unknown role (with the valid roles that look close), a cluster given as
        one label or with fewer than 3 labels, a landmark given as a list, one label
        mapped to two landmark roles, a required
        role missing (naming the role, what it is, and the roles in the mapping that
        look close), an unknown side, or no side at all.

    Warns
    -----
    UserWarning
        If the mapping has ``RHJC``/``LHJC`` but `hip_centre` is not ``'marker'``: the
        lab's hip centres would be silently ignored.

    Examples
    --------
    >>> from bmc_functions.markers.roles import check_mapping
    >>> mapping, sides = check_mapping({"RASIS": "RASI", "LASIS": "LASI", "SACRUM": "SACR",
    ...     "RTHIGH": ["T1", "T2", "T3"], "RKNEE_LAT": "RLFC", "RKNEE_MED": "RMFC",
    ...     "RANKLE_LAT": "RLMAL", "RANKLE_MED": "RMMAL", "RHEEL": "RCAL", "RTOE": "RTOE"})
    >>> sides
    ('right',)
    """
    if not isinstance(markers, dict):
        raise TypeError(f"markers must be a dict of role -> label; got "
                        f"{type(markers).__name__}")
    valid = all_roles()
    mapping = {role: _checked_value(role, value, valid) for role, value in markers.items()}
    check_shared_labels(mapping)
    sides = _checked_sides(sides, mapping)
    unused = [role for role in mapping if role[1:] == "HJC" and hip_centre != "marker"]
    if unused:
        warn(f"markers maps {' and '.join(unused)} (the lab's hip-centre markers), "
             f"but hip_centre={hip_centre!r}: they are not used, and the hip centres "
             f"come from that method instead; pass hip_centre='marker' to use them",
             UserWarning)
    _check_required(mapping, _required_roles(mapping, sides, hip_centre))
    return mapping, tuple(side for side in ("right", "left") if side in sides)


def check_known_roles(markers, valid=None):
    """Raise ValueError naming the first key of `markers` that is no role (a misspelt
    'RHEAL', a lower-case 'rtoe'), with the valid roles that look close."""
    valid = all_roles() if valid is None else valid
    for role in markers:
        if role not in valid:
            close = _close(str(role), valid)
            raise ValueError(f"markers: unknown role {role!r}"
                             + (f"; did you mean {close}?" if close else "")
                             + " Valid roles: RASIS, LASIS, RPSIS, LPSIS, SACRUM, PELVIS "
                             "and, with the prefix R or L, " + ", ".join(SIDE_ROLES))


def _checked_value(role, value, valid):
    """A known role's label (str), or its cluster's labels (tuple of 3 or more)."""
    check_known_roles({role: value}, valid)
    if is_cluster(role):
        if isinstance(value, str) or not hasattr(value, "__iter__"):
            raise ValueError(f"markers[{role!r}] must be a list of 3 or more labels "
                             f"(the {describe(role)}); got {value!r}")
        value = tuple(value)
        _check_label_types(role, value)
        if len(value) < 3:
            raise ValueError(f"markers[{role!r}] needs 3 or more labels (a rigid-body "
                             f"fit needs 3 non-collinear markers); got {len(value)}: "
                             f"{list(value)}")
        if len(set(value)) != len(value):
            raise ValueError(f"markers[{role!r}] lists a label twice: {list(value)}")
    elif not isinstance(value, str):
        if isinstance(value, (list, tuple)):
            raise ValueError(f"markers[{role!r}] must be one label (the "
                             f"{describe(role)}), not a list; got {value!r}")
        raise TypeError(f"markers[{role!r}] must be a label (str); got "
                        f"{type(value).__name__}")
    return value


def _check_label_types(role, labels):
    for label in labels:
        if not isinstance(label, str):
            raise TypeError(f"markers[{role!r}]: labels must be strings; got "
                            f"{label!r} ({type(label).__name__})")


def check_shared_labels(mapping):
    """A landmark is one place on the body: one label mapped to two landmark roles is an
    error (a copied line not edited)."""
    owners = {}
    for role, value in mapping.items():
        if isinstance(value, str):
            owners.setdefault(value, []).append(role)
    shared = {label: roles for label, roles in owners.items() if len(roles) > 1}
    if shared:
        label, roles = next(iter(shared.items()))
        raise ValueError(f"markers maps the label {label!r} to {len(roles)} roles: "
                         + ", ".join(f"{role} ({describe(role)})" for role in roles)
                         + "; each landmark role needs its own marker. Check the mapping "
                         "(a copied line not edited?)")


def _checked_sides(sides, mapping):
    """The sides asked for, as a tuple; None: every side with a role in the mapping."""
    if sides is None:
        sides = tuple(side for side, p in SIDE_PREFIX.items()
                      if any(role[0] == p and role[1:] in SIDE_ROLES for role in mapping))
        if not sides:
            raise ValueError("markers has no role of either side (RKNEE_LAT, LKNEE_LAT, "
                             "...): nothing to compute")
        return sides
    if not isinstance(sides, (str, list, tuple)):
        raise TypeError(f"sides must be 'right', 'left' or a list of them; got "
                        f"{type(sides).__name__} {sides!r}")
    sides = (sides,) if isinstance(sides, str) else tuple(sides)
    for side in sides:
        if not isinstance(side, str) or side not in SIDE_PREFIX:
            raise ValueError(f"sides must hold 'right' and/or 'left'; got {side!r}")
    if not sides:
        raise ValueError("sides is empty: give 'right', 'left' or both")
    return sides


def _required_roles(mapping, sides, hip_centre):
    """The roles the pelvis and the computed sides need, given what the mapping has."""
    required = ["RASIS", "LASIS"]
    if not ({"RPSIS", "LPSIS"} <= set(mapping) or "SACRUM" in mapping):
        required += ["RPSIS", "LPSIS"] if ("RPSIS" in mapping or "LPSIS" in mapping) \
            else ["SACRUM"]
    for side in sides:
        roles = list(REQUIRED_SIDE_ROLES) + (["HJC"] if hip_centre == "marker" else [])
        required += [SIDE_PREFIX[side] + role for role in roles]
    return required


def _check_required(mapping, required):
    """Raise for the first required role missing, with the close roles the mapping has."""
    for role in required:
        if role not in mapping:
            close = _close(role, mapping, cutoff=0.6)
            where = (f"the {role[0] == 'R' and 'right' or 'left'} side needs it"
                     if role not in PELVIS_ROLES else "the pelvis needs it")
            extra = ""
            if role == "SACRUM":
                extra = " (or both RPSIS and LPSIS)"
            if role.endswith("HJC"):
                where = "hip_centre='marker' needs it"
            raise ValueError(f"markers: role {role!r} ({describe(role)}){extra} is missing "
                             f"from the mapping; {where}"
                             + (f". The mapping has {close}: a typo?" if close else ""))


def check_labels(mapping, roles, available, trial, dropped=()):
    """Raise ValueError if a label of `roles` is not among the trial's `available` labels.

    The message names the role, the label, the trial and up to three labels of the trial
    that look close (difflib), or, if none does, some of the labels the trial has. A label
    in `dropped` (named by the file, but with empty columns, which :func:`read_trc`
    drops: ``df.attrs['dropped_labels']``) is said to be empty rather than absent.
    """
    available = list(available)
    for role in roles:
        value = mapping[role]
        for label in (value if isinstance(value, tuple) else (value,)):
            if label in available:
                continue
            if label in dropped:
                raise ValueError(f"markers[{role!r}] = {label!r} ({describe(role)}): {trial} "
                                 f"names this label but its columns are empty in every frame "
                                 f"(read_trc leaves such labels out: see "
                                 f"df.attrs['dropped_labels'])")
            close = _close(label, available, cutoff=0.4)
            same = _same_but_case(label, available)
            hint = (f"it has {same[0]!r}, which differs only in case or spaces (labels "
                    f"are matched exactly)" if same else
                    f"labels in it that look close: {close}" if close else
                    "it has " + ", ".join(repr(a) for a in available[:12])
                    + (" ..." if len(available) > 12 else ""))
            raise ValueError(f"markers[{role!r}] = {label!r} ({describe(role)}): no marker "
                             f"with that label in {trial}; {hint}")


def read_marker_mapping(path):
    r"""A marker mapping (role -> label or list of labels) from a TOML, JSON or YAML file.

    The mapping that :func:`~bmc_functions.calibrate_lower_limb` and
    :func:`~bmc_functions.gait_events` take, kept in a file beside a lab's trials (the
    command line's ``--markers``). One line per role, e.g. in TOML::

        RASIS = "R.ASIS"
        RTHIGH = ["R.TH1", "R.TH2", "R.TH3"]

    The table may also sit under a key ``markers`` (room for other settings in the same
    file). The roles themselves are checked later, by the function that uses them.

    Parameters
    ----------
    path : str or path-like
        A ``.toml``, ``.json``, ``.yaml`` or ``.yml`` file.

    Returns
    -------
    dict
        Role -> label (str) or labels (list of str), in file order.

    Raises
    ------
    ValueError
        Naming the file: it does not exist, its suffix is none of those, it does not
        parse (the parser's message), it is not a table of roles, a value is neither a
        label nor a list of labels; TOML on Python 3.10 without the package ``tomli``, or
        YAML without PyYAML (the message says what to install).

    Examples
    --------
    >>> from bmc_functions import read_marker_mapping
    >>> from bmc_functions.examples import example_file
    >>> markers = read_marker_mapping(example_file("markers/markers.toml"))
    >>> markers["RASIS"], markers["RTHIGH"]
    ('RASI', ['RTH1', 'RTH2', 'RTH3', 'RTH4'])
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: the marker mapping file does not exist")
    suffix = path.suffix.lower()
    if suffix == ".toml":
        try:
            import tomllib
        except ModuleNotFoundError:  # Python 3.10
            try:
                import tomli as tomllib
            except ModuleNotFoundError:
                raise ValueError(f"{path}: reading TOML on Python < 3.11 needs the package "
                                 "tomli (pip install tomli); or write the mapping as "
                                 "JSON") from None
        load = tomllib.loads
    elif suffix == ".json":
        load = json.loads
    elif suffix in (".yaml", ".yml"):
        try:
            import yaml
        except ModuleNotFoundError:
            raise ValueError(f"{path}: reading YAML needs the package PyYAML (pip install "
                             "pyyaml); or write the mapping as TOML or JSON") from None
        load = yaml.safe_load
    else:
        raise ValueError(f"{path}: a marker mapping is a .toml, .json, .yaml or .yml file; "
                         f"got {suffix or 'no suffix'!r}")
    try:
        data = load(path.read_bytes().decode("utf-8"))
    except Exception as err:     # the parser's own error (a syntax error, bad UTF-8)
        raise ValueError(f"{path}: could not be read as {suffix[1:].upper()}: {err}") \
            from None
    if isinstance(data, dict) and isinstance(data.get("markers"), dict):
        data = data["markers"]
    if not isinstance(data, dict) or not data:
        raise ValueError(f"{path}: expected a table role = label (e.g. RASIS = \"R.ASIS\"); "
                         f"got {type(data).__name__}")
    mapping = {}
    for role, value in data.items():
        if isinstance(value, str):
            mapping[str(role)] = value
        elif isinstance(value, list) and value and all(isinstance(v, str) for v in value):
            mapping[str(role)] = list(value)
        else:
            raise ValueError(f"{path}: {role} must be a label or a list of labels; got "
                             f"{value!r}")
    return mapping


def pelvis_roles(markers):
    """The pelvis landmark roles a mapping uses: the two ASIS and the posterior landmarks.

    Both PSIS when the mapping has both (the pelvis frame of Wu et al. 2002 is defined
    from them), else the sacrum marker (their midpoint on a marker set with one posterior
    marker, as Plug-in Gait's SACR). The one rule of the package: the lower-limb pipeline,
    its checks and the gait events use the same pelvis.

    Parameters
    ----------
    markers : mapping
        Roles to labels, as :func:`read_marker_mapping` returns.

    Returns
    -------
    list of str

    Examples
    --------
    >>> from bmc_functions.markers.roles import pelvis_roles
    >>> pelvis_roles({'RPSIS': 'RPSI', 'LPSIS': 'LPSI', 'SACRUM': 'SACR'})
    ['RASIS', 'LASIS', 'RPSIS', 'LPSIS']
    >>> pelvis_roles({'SACRUM': 'SACR'})
    ['RASIS', 'LASIS', 'SACRUM']
    """
    posterior = ["RPSIS", "LPSIS"] if {"RPSIS", "LPSIS"} <= set(markers) else ["SACRUM"]
    return ["RASIS", "LASIS"] + posterior
