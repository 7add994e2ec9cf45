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
  (``data/generate_gait_data.py``), 100 Hz, mm;
- ``'plug_in_gait/Static_trial.c3d'``, ``'plug_in_gait/Movement_trial.c3d'``,
  ``'plug_in_gait/Test.vsk'``: a real Plug-in Gait subject processed by Vicon Nexus 2.6 (a
  static trial and a stair descent, 120 Hz, with Vicon's own angles and joint centres; the
  subject's .vsk), the files of ``data/real/plug_in_gait/`` with their MIT licence
  (``'plug_in_gait/LICENSE'``; from the pyCGM repository, copyright (c) 2015 cadop).
"""

from pathlib import Path

_FOLDER = Path(__file__).resolve().parent / "example_data"


def example_file(name):
    """The path of an example file shipped with the package.

    Parameters
    ----------
    name : str
        ``'markers/static.trc'``, ``'markers/walk.trc'``, ``'markers/markers.toml'``,
        ``'gait/walk.trc'`` or one of ``'plug_in_gait/...'`` (see the module's list).

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
