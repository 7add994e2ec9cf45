"""Write the book's API reference: a page per group of modules and a page per public name.

    python tools/api_reference.py          # -> book/api/ (tools/build_book.py runs it)

Every public name of the package (``bmc_functions.__all__``), of ``bmc_functions.plotting``
and of ``bmc_functions.examples`` gets a page generated from its docstring by Sphinx's
autodoc (numpydoc sections read by napoleon): its signature, parameters, returns, the
mathematics, references and examples, and an entry in the book's index. The pages are
grouped by the module that defines the name, in the order of the applied path (files ->
markers -> segments -> joints -> gait cycles); a module not listed in GROUPS (a new one)
gets a group of its own, titled by the first line of its docstring, so nothing is left
out. The pages are generated at every build (book/api/ is not kept in git), so they
cannot go stale.

The table of contents of these pages is returned by :func:`write` and appended by
tools/build_book.py to book/_toc.yml in a generated copy.
"""

from __future__ import annotations

import importlib
import inspect
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
API = ROOT / "book" / "api"

#: (slug, title, modules, what the group is for), in the order of the applied path and of
#: the package's layers (bmc_functions/files, markers, rigid_body, models, gait); a module
#: is named by its path below bmc_functions
GROUPS = [
    ("files", "Files", ["files.trc", "files.c3d", "files.c3d_parameters",
                        "files.force_plates", "files.c3d_writer", "files.opensim", "files.vsk",
                        "examples"],
     "Read and write TRC and C3D marker files, C3D parameters and model outputs, C3D "
     "force plates, a trial written back to C3D with the package's outputs, OpenSim "
     ".mot/.sto files and Vicon subject files; the example trials shipped with the package."),
    ("markers", "Markers", ["markers.roles", "markers.gap_filling", "markers.filtering",
                            "markers.tracking"],
     "Which marker is which (role mappings), gap filling, low-pass filtering and "
     "derivatives, cluster calibration and tracking."),
    ("rigid_body", "The rigid-body fit and marker clusters",
     ["rigid_body.svdt", "rigid_body.quaternion_fit", "rigid_body.clusters"],
     "The least-squares rigid-body transformation of marker sets (svdt) and cluster "
     "design."),
    ("rotations", "Rotations and Cardan angles",
     ["rigid_body.rotations", "rigid_body.cardan", "rigid_body.frames"],
     "Elemental rotations, the rotation between two vectors, Cardan/Euler angles, "
     "orthonormal frames from axes and points."),
    ("motion", "Angular velocity and helical axes", ["rigid_body.motion"],
     "Rigid-body motion beyond angles."),
    ("segments", "Segment frames and joint angles", ["models.segments", "models.joints"],
     "Segment frames from landmarks (ISB), the hip joint centre, joint angles by the "
     "joint coordinate system."),
    ("lower_limb", "The lower-limb pipeline", ["models.lower_limb"],
     "Pelvis, hip, knee and ankle angles of a lab's trials in one call."),
    ("plug_in_gait", "Plug-in Gait (the Conventional Gait Model)",
     ["models.plug_in_gait.model", "models.plug_in_gait.subject", "models.plug_in_gait.labels",
      "models.plug_in_gait.lower_body", "models.plug_in_gait.upper_body"],
     "Vicon's Plug-in Gait, lower and upper body, reproduced to Vicon's numbers."),
    ("functional_joints", "Functional joint centres and axes", ["models.functional_joints"],
     "Joints found by their motion: SCoRE, SARA and the sphere fit."),
    ("poses", "Joint angles from 3D body poses", ["models.skeleton"],
     "Keypoints of a markerless pose estimator to joint angles and back."),
    ("dynamics", "Inverse dynamics", ["dynamics.segment_parameters", "dynamics.newton_euler"],
     "Dempster's segment masses, centres of mass and radii of gyration; Newton-Euler joint "
     "forces, moments and powers of a chain of segments, from the foot up."),
    ("gait", "Gait events and cycles", ["gait.events", "gait.cycles",
                                         "gait.force_plates", "gait.event_files",
                                         "gait.gait_profile"],
     "Heel strikes and toe-offs from markers and from force plates, event files, time "
     "normalisation, ensembles, spatio-temporal parameters, normative data and the Gait "
     "Profile Score."),
    ("plotting", "Figures", ["plotting"],
     "Gait figures and the 3D helpers the notebooks use (bmc_functions.plotting)."),
]


def public_names():
    """{module name: [(public path, object)]} of every documented public name."""
    sys.path.insert(0, str(ROOT))
    package = importlib.import_module("bmc_functions")
    found = {}

    def add(path, obj):
        module = obj.__module__.removeprefix("bmc_functions.")
        found.setdefault(module, []).append((path, obj))

    for name in package.__all__:
        add(f"bmc_functions.{name}", getattr(package, name))
    for module_name in ("plotting", "examples"):
        module = importlib.import_module(f"bmc_functions.{module_name}")
        for name, obj in vars(module).items():
            if (not name.startswith("_") and (inspect.isfunction(obj) or inspect.isclass(obj))
                    and obj.__module__ == module.__name__
                    and name not in package.__all__):
                add(f"bmc_functions.{module_name}.{name}", obj)
    for entries in found.values():
        entries.sort(key=lambda entry: entry[0].rsplit(".", 1)[-1].lower())
    return found


def summary(obj):
    doc = inspect.getdoc(obj) or ""
    return doc.strip().split("\n\n")[0].replace("\n", " ")


def name_page(path, obj):
    """The page of one name, in reStructuredText: autodoc's footnotes ([1]_ and the
    References section) stay with the rST parser (MyST would claim them)."""
    module, name = path.rsplit(".", 1)
    if inspect.isclass(obj):
        directive = f".. autoclass:: {name}\n   :members:"
    else:
        directive = f".. autofunction:: {name}"
    return (f"{name}\n{'=' * len(name)}\n\n.. currentmodule:: {module}\n\n{directive}\n\n"
            f"Defined in ``{obj.__module__}``; imported as ``{path}``.\n")


def group_page(title, about, modules, entries):
    lines = [f"# {title}", "", about, ""]
    lines += [f"Modules: {', '.join(f'`bmc_functions.{m}`' for m in modules)}.", ""]
    lines += ["| name | what it does |", "|---|---|"]
    for page, path, obj in entries:
        text = summary(obj).replace("|", "\\|")
        lines.append(f"| [`{path.rsplit('.', 1)[-1]}`]({page}.rst) | {text} |")
    return "\n".join(lines) + "\n"


def command_line_page():
    """The help of ``bmc-kinematics`` and of each subcommand, as the terminal shows it."""
    import argparse
    import os

    from bmc_functions.cli import build_parser

    columns = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = "90"     # argparse wraps to the terminal's width: a fixed one
    parser = build_parser()
    parts = ["# The command line", "",
             "`bmc-kinematics` (or `python -m bmc_functions`) runs the lower-limb pipeline, "
             "the gait events and the gait cycles over a folder of trials, one command per "
             "folder, and converts files. Its code is `bmc_functions/cli.py`; a body model "
             "is one entry of `bmc_functions.cli.MODELS`.", "",
             "```text", "$ bmc-kinematics --help", parser.format_help().rstrip(), "```"]
    commands = next(action for action in parser._actions
                    if isinstance(action, argparse._SubParsersAction))
    for name, sub in commands.choices.items():
        parts += ["", f"## {name}", "", "```text", f"$ bmc-kinematics {name} --help",
                  sub.format_help().rstrip(), "```"]
    if columns is None:
        del os.environ["COLUMNS"]
    else:
        os.environ["COLUMNS"] = columns
    return "\n".join(parts) + "\n"


def write(folder: Path = API) -> list[dict]:
    """Write the pages into `folder` (emptied first); return the toc entries (a list of
    sections for book/api/index)."""
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    names = public_names()
    groups = [(slug, title, modules, about) for slug, title, modules, about in GROUPS]
    listed = {m for _, _, modules, _ in GROUPS for m in modules}
    for module in sorted(m for m in names if m not in listed):   # a new module
        doc = inspect.getdoc(importlib.import_module(f"bmc_functions.{module}")) or module
        groups.append((module, doc.split("\n")[0].rstrip("."), [module], ""))
    toc, overview = [], []
    relative = folder.relative_to(ROOT).as_posix()
    for slug, title, modules, about in groups:
        entries = []
        for module in modules:
            for path, obj in names.get(module, []):
                page = path.rsplit(".", 1)[-1]
                if path.startswith(("bmc_functions.plotting.", "bmc_functions.examples.")):
                    page = f"{path.split('.')[1]}.{page}"
                entries.append((page, path, obj))
        if not entries:
            continue
        (folder / slug).mkdir()
        for page, path, obj in entries:
            (folder / slug / f"{page}.rst").write_text(name_page(path, obj), encoding="utf-8")
        (folder / f"{slug}.md").write_text(
            group_page(title, about, modules, [(f"{slug}/{p}", path, obj)
                                               for p, path, obj in entries]),
            encoding="utf-8")
        toc.append({"file": f"{relative}/{slug}",
                    "sections": [{"file": f"{relative}/{slug}/{page}"}
                                 for page, _, _ in entries]})
        overview.append(f"- [{title}]({slug}.md): {about or summary(obj)} "
                        f"({len(entries)} names)")
    (folder / "command_line.md").write_text(command_line_page(), encoding="utf-8")
    toc.append({"file": f"{relative}/command_line"})
    overview.append("- [The command line](command_line.md): `bmc-kinematics` and its "
                    "subcommands, as `--help` shows them")
    count = sum(len(entry.get("sections", ())) for entry in toc)
    (folder / "index.md").write_text(
        "# API reference\n\n"
        f"Every public function and class of `bmc_functions` ({count} names), one page "
        "each, generated from its docstring: what it computes, its parameters and what it "
        "returns, the mathematics, the references and examples that run (they are tested "
        "as doctests). The same text is at hand in Python with `help(name)`. Names are "
        "imported from the package, `from bmc_functions import svdt`; the figures from "
        "`bmc_functions.plotting`. The {ref}`index <genindex>` lists them all.\n\n"
        + "\n".join(overview) + "\n", encoding="utf-8")
    return toc


if __name__ == "__main__":
    entries = write()
    print(f"{sum(len(e.get('sections', ())) for e in entries)} API pages in "
          f"{sum('sections' in e for e in entries)} groups and the command line page "
          f"written to {API}")
