"""Small example trials shipped with the package, so that the docstring examples and the
command line run wherever the package is installed (from a wheel, without the repository).

``example_file(name)`` is the path of one of them, named as in the repository's ``data/``
folder (the same bytes; made by its seeded scripts and described in ``data/README.md``):

- ``'markers/static.trc'``, ``'markers/walk.trc'``: a static and a walking trial of both
  legs of a synthetic subject (``data/generate_marker_data.py``), 100 Hz, mm;
- ``'markers/markers.toml'``: their marker mapping (role = label) for
  :func:`~bmc_functions.calibrate_lower_limb` and the command line's ``--markers`` (not in
  ``data/``);
- ``'gait/walk.trc'``: five strides of a synthetic walker's pelvis and feet
  (``data/generate_gait_data.py``), 100 Hz, mm.
"""

from pathlib import Path

_FOLDER = Path(__file__).resolve().parent / "example_data"


def example_file(name):
    """The path of an example file shipped with the package.

    Parameters
    ----------
    name : str
        ``'markers/static.trc'``, ``'markers/walk.trc'``, ``'markers/markers.toml'`` or
        ``'gait/walk.trc'``.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ValueError
        If there is no example file of that name (the message lists them).

    Examples
    --------
    >>> from bmc_functions import read_trc
    >>> from bmc_functions.examples import example_file
    >>> walk = read_trc(example_file("markers/walk.trc"))
    >>> print(walk.attrs["rate"], walk.attrs["units"], len(walk))
    100.0 mm 111
    """
    names = sorted(path.relative_to(_FOLDER).as_posix() for path in _FOLDER.rglob("*")
                   if path.is_file())
    if not isinstance(name, str) or name not in names:
        raise ValueError(f"name must be one of {', '.join(map(repr, names))}; got {name!r}")
    return _FOLDER / name
