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

Each group's page lists its names with their one-line summaries (the docstring's rST
roles made links, ``:func:`decompose``` -> a link to ``decompose``'s page) and shows the
docstring of each of its modules, where a module describes its method as a whole; each
name's page ends with the notebooks that use the name in their text (the notebooks link
the other way, book/_ext/bmc_book.py). The reference's front page lists every name, by
group.

The table of contents of these pages is returned by :func:`write` and appended by
tools/build_book.py to book/_toc.yml in a generated copy.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import json
import re
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
API = ROOT / "book" / "api"
NOTEBOOKS = ROOT / "notebooks"

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


#: an rST role in a docstring: :func:`name`, :meth:`~Class.method`, :math:`x^2`
ROLE = re.compile(r":(?:py:)?(\w+):`([^`]+)`")


def markdown(text, links):
    """A docstring's rST inline markup as MyST Markdown, for the group and index pages.

    ``links``: {name: relative path of its page}. ``:func:`name``` (also ``:meth:``,
    ``:class:``, ``~`` and dotted forms) becomes a link to the name's page, or a literal
    when the name has none; ``:math:`x``` becomes ``$x$``; ````x```` becomes ```x```.

    >>> markdown("Made by :func:`plug_in_gait`; see :meth:`~bmc.PlugInGait.track`, "
    ...          ":math:`10^5` and ``R``.", {"plug_in_gait": "pig/plug_in_gait.rst"})
    'Made by [`plug_in_gait`](pig/plug_in_gait.rst); see `track`, $10^5$ and `R`.'
    """
    def role(match):
        kind, target = match.groups()
        if kind == "math":
            return f"${target}$"
        shown = target.lstrip("~")
        if target.startswith("~"):
            shown = shown.rsplit(".", 1)[-1]
        parts = target.lstrip("~").removeprefix("bmc_functions.").split(".")
        page = next((links[p] for p in reversed(parts) if p in links), None)
        return f"[`{shown}`]({page})" if page else f"`{shown}`"

    text = re.sub(r"``([^`]+)``", r"`\1`", text)
    return ROLE.sub(role, text)


#: a call in a code cell: ``svdt(``, ``plotting.set_lab_view(``, ``bmc_functions.svdt(``
CALL = re.compile(r"(?<![\w.])((?:bmc_functions\.)?(?:plotting\.|examples\.)?[A-Za-z_]\w*)\s*\(")


def notebook_mentions(notebooks=None):
    """{name as the notebooks write it: [(notebook path, its title)]}: the inline literals
    of the notebooks' Markdown cells that name one thing (``svdt``, ``svdt(A, B)``,
    ``bmc_functions.svdt``; the rule by which the book links a notebook to a name's page,
    book/_ext/bmc_book.py's NAMED_LITERAL) and the names their code cells call."""
    spec = importlib.util.spec_from_file_location(
        "bmc_book", ROOT / "book" / "_ext" / "bmc_book.py")
    bmc_book = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bmc_book)
    if notebooks is None:
        notebooks = sorted(p for p in NOTEBOOKS.glob("*.ipynb") if re.match(r"\d\d_", p.name))
    found = {}
    for path in notebooks:
        cells = json.loads(path.read_text(encoding="utf-8"))["cells"]
        text = "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "markdown")
        text = re.sub(r"^\s*(```|~~~).*?^\s*\1\s*$", "", text, flags=re.M | re.S)
        title = next((line[2:].strip() for line in text.splitlines()
                      if line.startswith("# ")), path.stem)
        code = "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")
        named = [match.group(1) for literal in re.findall(r"(?<!`)`([^`\n]+)`(?!`)", text)
                 if (match := bmc_book.NAMED_LITERAL.match(literal))]
        for name in named + CALL.findall(code):
            entries = found.setdefault(name.removeprefix("bmc_functions."), [])
            if not entries or entries[-1][0] != path:
                entries.append((path, title))
    return found


def rst_text(markdown_text):
    """Inline maths of a notebook title (``$...$``) as rST's ``:math:`` role."""
    return re.sub(r"\$([^$]+)\$", r":math:`\1`", markdown_text)


def used_in(path, mentions):
    """The notebooks whose text names ``path`` (``bmc_functions.plotting.x`` is also
    written ``plotting.x`` and, once imported, ``x``)."""
    parts = path.split(".")
    spellings = [path, ".".join(parts[1:]), parts[-1]]
    seen, found = set(), []
    for spelling in spellings:
        for notebook, title in mentions.get(spelling, []):
            if notebook not in seen:
                seen.add(notebook)
                found.append((notebook, title))
    return sorted(found)


def name_page(path, obj, group=None, notebooks=()):
    """The page of one name, in reStructuredText: autodoc's footnotes ([1]_ and the
    References section) stay with the rST parser (MyST would claim them).

    ``group``: (slug, title) of its group, whose page shows the docstring of the module
    (or of its package), or None;
    ``notebooks``: [(notebook path, title)] of the notebooks that use the name."""
    module, name = path.rsplit(".", 1)
    if inspect.isclass(obj):
        directive = f".. autoclass:: {name}\n   :members:"
    else:
        directive = f".. autofunction:: {name}"
    text = (f"{name}\n{'=' * len(name)}\n\n.. currentmodule:: {module}\n\n{directive}\n\n"
            f"Defined in ``{obj.__module__}``")
    if group is not None:
        text += f" (the module is described on :doc:`{group[1]} <../{group[0]}>`)"
    text += f"; imported as ``{path}``.\n"
    if notebooks:
        text += "\n.. rubric:: In the notebooks\n\n"
        for notebook, title in notebooks:
            number = notebook.name[:2]
            bare = re.sub(r"^\d\d\s*[·.:-]\s*", "", title)
            text += (f"- :doc:`Notebook {number} </notebooks/{notebook.stem}>`: "
                     f"{rst_text(bare)}\n")
    return text


def module_docstring(module):
    """The module's docstring, shown on its group's page (where a module explains its
    method as a whole, its steps and sources), in rST; empty for a one-line docstring."""
    doc = inspect.getdoc(importlib.import_module(f"bmc_functions.{module}")) or ""
    if "\n\n" not in doc.strip():
        return ""
    heading = f"The module bmc_functions.{module}"
    return (f"{heading}\n{'-' * len(heading)}\n\n"
            f".. automodule:: bmc_functions.{module}\n   :no-index:\n")


def described(modules):
    """The modules whose docstrings a group's page shows: its modules' common package
    first when that is a package of its own below a layer (``models.plug_in_gait`` for
    ``models.plug_in_gait.model`` and ``models.plug_in_gait.lower_body``: the package's
    docstring is where a model split into modules is explained), then each module with a
    docstring of more than one paragraph."""
    common = modules[0].split(".")
    for module in modules[1:]:
        parts = module.split(".")
        while common != parts[:len(common)]:
            common.pop()
    package = ".".join(common)
    found = [package] if len(common) >= 2 and package not in modules else []
    return [module for module in found + list(modules) if module_docstring(module)]


def shown(obj, modules):
    """Whether the group page of ``modules`` shows the docstring of ``obj``'s module or of
    a package it is in."""
    module = obj.__module__.removeprefix("bmc_functions.")
    return any(module == m or module.startswith(m + ".") for m in described(modules))


def group_page(title, about, modules, entries):
    """A group's page, in reStructuredText: what the group is for, a table of its names
    with the first line of their docstrings, and its modules' docstrings.

    rST, so that the docstrings' roles (``:func:`decompose```) are links to the names'
    pages and their footnotes ([1]_) resolve; ``entries``: [(page, path, object)]."""
    lines = [title, "=" * len(title), "", about, "",
             f"Modules: {', '.join(f'``bmc_functions.{m}``' for m in modules)}.", "",
             ".. currentmodule:: bmc_functions", "",
             ".. list-table::", "   :header-rows: 1", "   :widths: 30 70", "",
             "   * - name", "     - what it does"]
    for _, path, obj in entries:
        role = "class" if inspect.isclass(obj) else "func"
        lines += [f"   * - :{role}:`~{path}`", f"     - {summary(obj)}"]
    lines += [""] + [module_docstring(module) for module in described(modules)]
    return "\n".join(lines).rstrip("\n") + "\n"


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
    relative = folder.relative_to(ROOT).as_posix()
    filled = []   # (slug, title, modules, about, [(page, path, obj)])
    for slug, title, modules, about in groups:
        entries = []
        for module in modules:
            for path, obj in names.get(module, []):
                page = path.rsplit(".", 1)[-1]
                if path.startswith(("bmc_functions.plotting.", "bmc_functions.examples.")):
                    page = f"{path.split('.')[1]}.{page}"
                entries.append((page, path, obj))
        if entries:
            filled.append((slug, title, modules, about, entries))
    # {name: its page relative to the reference's folder}, for the links of the front page
    links = {path.rsplit(".", 1)[-1]: f"{slug}/{page}.rst"
             for slug, _, _, _, entries in filled for page, path, _ in entries}
    mentions = notebook_mentions()
    toc, overview = [], []
    for slug, title, modules, about, entries in filled:
        (folder / slug).mkdir()
        for page, path, obj in entries:
            (folder / slug / f"{page}.rst").write_text(
                name_page(path, obj, (slug, title) if shown(obj, modules) else None,
                          used_in(path, mentions)),
                encoding="utf-8")
        (folder / f"{slug}.rst").write_text(group_page(title, about, modules, entries),
                                            encoding="utf-8")
        toc.append({"file": f"{relative}/{slug}",
                    "sections": [{"file": f"{relative}/{slug}/{page}"}
                                 for page, _, _ in entries]})
        listing = ", ".join(f"[`{path.rsplit('.', 1)[-1]}`]({slug}/{page}.rst)"
                            for page, path, _ in entries)
        about = about or markdown(summary(entries[0][2]), links)
        overview.append(f"- [{title}]({slug}.rst): {about}\\\n"
                        f"  {listing}")
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
        "`bmc_functions.plotting`. The {ref}`index <genindex>` lists them all, "
        "alphabetically; here they are by group, in the order of the applied path.\n\n"
        + "\n".join(overview) + "\n", encoding="utf-8")
    return toc


if __name__ == "__main__":
    entries = write()
    print(f"{sum(len(e.get('sections', ())) for e in entries)} API pages in "
          f"{sum('sections' in e for e in entries)} groups and the command line page "
          f"written to {API}")
