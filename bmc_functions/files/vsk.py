"""Vicon subject files (``.vsk``): the subject measurements a model needs.

A ``.vsk`` file is XML written by Vicon Nexus: ``<KinematicModel>`` holds
``<Parameters>`` with one ``<StaticParameter NAME=... VALUE=... PRIOR=.../>`` per subject
measurement (``LeftLegLength``, ``LeftKneeWidth``, ``InterAsisDistance``, the static
offsets ``LeftStaticPlantFlex``, ...) and ``<Parameter .../>`` entries for values the
skeleton calibration fitted. Lengths are in mm and angles in radians.
"""

import os
import xml.etree.ElementTree as ElementTree

from .._checks import check_regular_file

#: Largest .vsk file read (bytes): the subject files are tens of kB; a larger file is not one.
MAX_VSK_BYTES = 50_000_000


def read_vsk(path):
    """Read the subject measurements of a Vicon ``.vsk`` file.

    Parameters
    ----------
    path : str or path-like
        The ``.vsk`` file.

    Returns
    -------
    dict
        Parameter name -> float VALUE (lengths mm, angles radians) for every
        ``StaticParameter`` and ``Parameter`` that has a VALUE. A parameter with only a
        PRIOR (Nexus shows it empty; ``LeftTibialTorsion`` often is) is left out, so that
        the model's own default applies and is recorded as such. ``dict.attrs``-like
        metadata is not needed: the model name is in the key ``'__model__'`` (e.g.
        ``'PlugInGait FullBody Ai'``) when the file states it.

    Raises
    ------
    ValueError
        If the file is not XML, its root is not ``KinematicModel``, it has no
        ``Parameters``, a VALUE is not a number, or a name appears twice with different
        values; the message names the file.
    FileNotFoundError, TypeError
        If the file is missing, or `path` is not a file name.

    Examples
    --------
    >>> from bmc_functions import read_vsk
    >>> from bmc_functions.examples import example_file   # the Plug-in Gait subject, shipped
    >>> subject = read_vsk(example_file("plug_in_gait/Test.vsk"))
    >>> subject["LeftLegLength"], subject["RightKneeWidth"], subject["__model__"]
    (877.0, 139.0, 'PlugInGait FullBody Ai')
    """
    check_regular_file(path, "Vicon subject (.vsk)")
    size = os.path.getsize(path)
    if size > MAX_VSK_BYTES:
        raise ValueError(f"{path}: {size} bytes; a Vicon subject file holds tens of kB "
                         f"(more than {MAX_VSK_BYTES} bytes is not one)")
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as err:
        raise ValueError(f"{path}: not a readable .vsk file: the XML is broken ({err})") \
            from None
    if root.tag != "KinematicModel":
        raise ValueError(f"{path}: not a Vicon subject file: the XML root is <{root.tag}>, "
                         f"expected <KinematicModel>")
    parameters = root.find("Parameters")
    if parameters is None:
        raise ValueError(f"{path}: the .vsk file has no <Parameters> section (no subject "
                         f"measurements)")
    subject = {}
    for element in parameters:
        name, value = element.get("NAME"), element.get("VALUE")
        if name is None or value is None:
            continue
        try:
            number = float(value)
        except ValueError:
            raise ValueError(f"{path}: parameter {name}: VALUE {value!r} is not a number") \
                from None
        if name in subject and subject[name] != number:
            raise ValueError(f"{path}: parameter {name} appears twice with different values "
                             f"({subject[name]:g} and {number:g}); which one holds is "
                             f"ambiguous")
        subject[name] = number
    if root.get("MODEL"):
        subject["__model__"] = root.get("MODEL")
    return subject
