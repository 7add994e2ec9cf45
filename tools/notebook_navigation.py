"""Navigation and hidden solutions for the teaching notebooks, written into the notebooks.

    python tools/notebook_navigation.py            # update every notebook in notebooks/
    python tools/notebook_navigation.py --check    # change nothing; exit 1 if out of date

For every numbered notebook ``NN_name.ipynb`` in notebooks/ it

1. regenerates the **Contents** list of the first cell from the notebook's ``## `` headings,
   with links in JupyterLab's anchor form (``[What a rotation matrix
   is](#2.-What-a-rotation-matrix-is)``); the book gives its sections the same ids
   (book/_ext/bmc_book.py), so one link works in both;
2. hides the worked solutions: in the ``## N. Solutions`` section every cell from the first
   ``**Solution k.**`` cell on gets JupyterLab's standard ``jupyter.source_hidden`` (and,
   for code, ``outputs_hidden``) metadata and the tag ``solution``; the heading and the
   intro above the first solution stay visible. A Markdown cell that holds both the intro
   and ``**Solution 1.**`` is split in two, so the intro stays visible. The book puts the
   same cells in closed dropdowns;
3. writes a last cell (tag ``navigation``) with Previous/Next links to the neighbouring
   notebooks in teaching order (the order of the file names: 00 first).

It changes only Markdown cells and metadata, never code or outputs, so nbval is not
affected; running it twice changes nothing the second time. ``--check`` also reports
notebooks whose layout the tool cannot fix (no Solutions section, a solution under a
``###`` heading, ...) and every link that does not resolve (to a section, to another
notebook or a section of it, to a file of the repository).
"""

from __future__ import annotations

import argparse
import copy
import html
import os
import re
import sys
import uuid
from dataclasses import dataclass
from pathlib import Path
from urllib.parse import quote, unquote, urlsplit

import nbformat

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
INTRO = ROOT / "book" / "intro.md"
LEARNING_PATH = re.compile(r"(<!-- learning-path:(?! end).*?-->\n)(.*?)(<!-- learning-path: end -->)",
                           re.DOTALL)
# Reading times, calibrated on what three first-time readers measured in round 4 of the
# reviews (../shared/reviews/teaching_round4.md, the table at its top): through the eleven
# notebooks that build on what came before (00-08, 11, 12) they kept a pace of 28 to 36
# words of Markdown a minute (median 32), counted as \w+ with the mathematics' TeX, and
# that pace already holds the time to read and run the code cells and compare their
# outputs (code-heavy 05 and text-heavy 02 came out alike; a separate cost per code cell
# or per code line made the fit worse). Notebooks that bring in many ideas no earlier one
# teaches took about half as long again (09: 1.4x the pace's time, 10: 1.4x, 13: 1.5x,
# 14: 1.8x). The front page (book/intro.md) states this rule.
WORDS_PER_MINUTE = 32
NEW_IDEAS_FACTOR = 1.5
# The notebooks that bring in many ideas of their own: a teaching judgement, as LEVELS.
NEW_IDEAS = {"09": "quaternion algebra", "10": "gait events, filtering for them, time normalisation",
             "13": "the clinical model's markers, conventions and offsets",
             "14": "sampling, spectra, digital filters and derivatives",
             "17": "rotation sequences of the pelvis, OpenSim, cross-talk, force-plate events"}
# The level of each notebook that is not second year (issue 25's reading of the collection);
# a teaching judgement, not something the file can tell. 14 (filtering) is second year
# because the primer (00) teaches what it needs beyond the second year's mathematics:
# sinusoids, complex exponentials, a spectrum and the Nyquist frequency (issue 35).
LEVELS = {"08": "upper second or third year", "09": "graduate (appendix)",
          "11": "graduate", "12": "graduate", "17": "third year"}
DEFAULT_LEVEL = "second year"
NAME = re.compile(r"^(\d\d)_[a-z0-9_]+\.ipynb$")

SOLUTION_TAG = "solution"
NAVIGATION_TAG = "navigation"
SOLUTIONS_HEADING = re.compile(r"^(\d+\.\s*)?(worked\s+)?solutions\s*$", re.IGNORECASE)
SOLUTION_START = re.compile(r"^\*\*Solution\s+\d+\b", re.MULTILINE)
CONTENTS_LINE = re.compile(r"^\*\*Contents\*\*[ \t]*$", re.MULTILINE)
LIST_ITEM = re.compile(r"^\s*(\d+\.|[-*+])\s+")
NUMBERED = re.compile(r"^(\d+)\.\s+(.*)$")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
FENCE = re.compile(r"^\s*(```|~~~)")
# The characters an anchor may have for a link to reach it in JupyterLab as well as in the
# book. JupyterLab compares the link's fragment, as the browser serializes it, with the
# heading's id: the browser percent-encodes spaces, '"<>`' and every non-ASCII character,
# so a heading with those cannot be reached (checked in JupyterLab 4.6); '$' would be
# taken for maths, '\\' is an escape in Markdown, '%' starts an escape.
LINKABLE = re.compile(r"^[!&'()*+,\-./0-9:;=?@A-Z\[\]^_a-z{|}~]+$")
SAFE = "!&'()*+,-./:;=?@[]^_{|}~"


# --------------------------------------------------------------------------- anchors


def _split_math(text: str):
    """Yield (is_math, piece) for a line of Markdown; maths keeps its ``$`` delimiters."""
    pattern = re.compile(r"(\$\$.+?\$\$|(?<!\\)\$[^$\n]+?(?<!\\)\$)")
    position = 0
    for match in pattern.finditer(text):
        if match.start() > position:
            yield False, text[position:match.start()]
        yield True, match.group(0)
        position = match.end()
    if position < len(text):
        yield False, text[position:]


def _plain(text: str) -> str:
    """The text a browser shows for inline Markdown (no maths in ``text``)."""
    text = re.sub(r"`+([^`]*?)`+", lambda m: "\0" + m.group(1) + "\0", text)  # code
    pieces = text.split("\0")
    out = []
    for k, piece in enumerate(pieces):
        if k % 2:  # inside a code span: literal
            out.append(piece)
            continue
        piece = re.sub(r"!\[[^\]]*\]\([^)]*\)", "", piece)             # images
        piece = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", piece)         # links
        piece = re.sub(r"<[^>]+>", "", piece)                           # HTML tags
        piece = re.sub(r"(\*\*|__)(.+?)\1", r"\2", piece)               # bold
        piece = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"\1", piece)
        piece = re.sub(r"(?<![\w_])_(?!\s)(.+?)(?<!\s)_(?![\w_])", r"\1", piece)
        piece = re.sub(r"\\([!-/:-@\[-`{-~])", r"\1", piece)            # escapes
        out.append(html.unescape(piece))
    return "".join(out)


def heading_text(markdown: str) -> str:
    """The text content of a rendered heading, with inline maths kept as written."""
    return "".join(piece if is_math else _plain(piece)
                   for is_math, piece in _split_math(markdown.strip()))


def jupyterlab_anchor(markdown: str) -> str:
    """JupyterLab's id for a heading: its text content with spaces replaced by '-'.

    >>> jupyterlab_anchor("2. What a rotation matrix is")
    '2.-What-a-rotation-matrix-is'
    >>> jupyterlab_anchor("4. Comparison with scipy's `align_vectors`")
    "4.-Comparison-with-scipy's-align_vectors"
    """
    return heading_text(markdown).replace(" ", "-")


def link_target(anchor: str) -> str:
    """``anchor`` as a Markdown link target (percent-encoded where Markdown needs it)."""
    return quote(anchor, safe=SAFE)


@dataclass
class Heading:
    cell: int
    level: int
    text: str

    @property
    def anchor(self) -> str:
        return jupyterlab_anchor(self.text)


def markdown_lines(source: str):
    """Yield the lines of a Markdown cell that are Markdown (not code blocks, not $$ maths)."""
    fence = None
    in_math = False
    for line in source.splitlines():
        match = FENCE.match(line)
        stripped = line.strip()
        if fence:
            if match and match.group(1) == fence:
                fence = None
            continue
        if in_math:
            if stripped.endswith("$$"):
                in_math = False
            continue
        if match:
            fence = match.group(1)
            continue
        if stripped.startswith("$$"):
            # a display block opens here unless it also closes on this line
            in_math = stripped == "$$" or not (len(stripped) > 4 and stripped.endswith("$$"))
            continue
        yield line


def headings(nb) -> list[Heading]:
    found = []
    for index, cell in enumerate(nb.cells):
        if cell.cell_type != "markdown":
            continue
        for line in markdown_lines(cell.source):
            match = HEADING.match(line)
            if match:
                found.append(Heading(index, len(match.group(1)), match.group(2)))
    return found


def anchors(nb) -> set[str]:
    return {h.anchor for h in headings(nb)}


# --------------------------------------------------------------------------- contents


def contents_list(nb) -> str:
    lines = []
    for heading in headings(nb):
        if heading.level != 2:
            continue
        match = NUMBERED.match(heading.text)
        target = link_target(heading.anchor)
        if match:
            lines.append(f"{match.group(1)}. [{match.group(2)}](#{target})")
        else:
            lines.append(f"- [{heading.text}](#{target})")
    return "\n".join(lines)


def replace_contents(source: str, listing: str) -> str:
    """Replace the list that follows ``**Contents**`` in ``source`` (or add one at its end)."""
    match = CONTENTS_LINE.search(source)
    if not match:
        return source.rstrip("\n") + "\n\n**Contents**\n\n" + listing
    before = source[:match.end()]
    rest = source[match.end():].split("\n")
    # rest[0] is what follows **Contents** on its line (nothing); skip blank lines, then the
    # list: items, their indented continuation lines, blank lines inside the list
    k = 1
    while k < len(rest) and not rest[k].strip():
        k += 1
    end = k
    while end < len(rest):
        line = rest[end]
        if LIST_ITEM.match(line) or (line.startswith((" ", "\t")) and line.strip()):
            end += 1
            continue
        if not line.strip():
            nxt = end + 1
            while nxt < len(rest) and not rest[nxt].strip():
                nxt += 1
            if nxt < len(rest) and LIST_ITEM.match(rest[nxt]):
                end = nxt
                continue
        break
    after = "\n".join(rest[end:])
    after = ("\n\n" + after.lstrip("\n")) if after.strip() else ""
    return before + "\n\n" + listing + after


def update_contents(nb) -> None:
    listing = contents_list(nb)
    first_heading = next((h.cell for h in headings(nb) if h.level == 2), len(nb.cells))
    for index in range(min(first_heading + 1, len(nb.cells))):
        cell = nb.cells[index]
        if cell.cell_type == "markdown" and CONTENTS_LINE.search(cell.source):
            cell.source = replace_contents(cell.source, listing)
            return
    for cell in nb.cells:  # no Contents yet: add it to the title cell
        if cell.cell_type == "markdown":
            cell.source = replace_contents(cell.source, listing)
            return


# --------------------------------------------------------------------------- solutions


def solutions_range(nb) -> tuple[int, int] | None:
    """(index of the cell with the Solutions heading, index of the cell of the next ##)."""
    found = headings(nb)
    for k, heading in enumerate(found):
        if heading.level == 2 and SOLUTIONS_HEADING.match(heading_text(heading.text)):
            stop = next((h.cell for h in found[k + 1:] if h.level <= 2), len(nb.cells))
            return heading.cell, stop
    return None


def new_markdown_cell(source: str, like):
    cell = nbformat.v4.new_markdown_cell(source)
    cell.id = uuid.uuid5(uuid.NAMESPACE_URL, (like.get("id") or "") + source).hex[:8]
    return cell


def split_solution_cells(nb) -> None:
    """Split a Markdown cell of the Solutions section before each ``**Solution k.**``."""
    section = solutions_range(nb)
    if section is None:
        return
    start, stop = section
    index = start
    while index < min(stop, len(nb.cells)):
        cell = nb.cells[index]
        if cell.cell_type == "markdown":
            starts = [m.start() for m in SOLUTION_START.finditer(cell.source)]
            cuts = [s for s in starts if s > 0 and cell.source[:s].strip()]
            if cuts:
                pieces = [cell.source[a:b].strip("\n")
                          for a, b in zip([0] + cuts, cuts + [len(cell.source)])]
                cell.source = pieces[0]
                new = [new_markdown_cell(piece, cell) for piece in pieces[1:]]
                nb.cells[index + 1:index + 1] = new
                stop += len(new)
                index += len(new)
        index += 1


def solution_cells(nb) -> list[int]:
    """Indices of the cells to hide: from the first ``**Solution k.**`` cell to the next ##."""
    section = solutions_range(nb)
    if section is None:
        return []
    start, stop = section
    first = next((i for i in range(start, stop) if nb.cells[i].cell_type == "markdown"
                  and SOLUTION_START.match(nb.cells[i].source.lstrip())), None)
    if first is None:
        return []
    return [i for i in range(first, stop)
            if NAVIGATION_TAG not in nb.cells[i].metadata.get("tags", [])]


def set_hidden(cell, hidden: bool) -> None:
    tags = list(cell.metadata.get("tags", []))
    jupyter = dict(cell.metadata.get("jupyter", {}))
    keys = ["source_hidden"] + (["outputs_hidden"] if cell.cell_type == "code" else [])
    if hidden:
        for key in keys:
            jupyter[key] = True
        if SOLUTION_TAG not in tags:
            tags.append(SOLUTION_TAG)
    elif SOLUTION_TAG in tags:  # hidden by this tool before, no longer a solution
        tags.remove(SOLUTION_TAG)
        for key in ("source_hidden", "outputs_hidden"):
            jupyter.pop(key, None)
    for key, value in (("jupyter", jupyter), ("tags", tags)):
        if value:
            cell.metadata[key] = value
        else:
            cell.metadata.pop(key, None)


SOLUTION_LABEL = re.compile(r"^(\*\*Solution\s+\d+[^*\n]*\*\*)[ \t]+(?=\S)")


def hide_solutions(nb) -> None:
    split_solution_cells(nb)
    hidden = set(solution_cells(nb))
    for index, cell in enumerate(nb.cells):
        set_hidden(cell, index in hidden)
        if index in hidden and cell.cell_type == "markdown":
            # a collapsed cell shows its first line in JupyterLab: let it be only the
            # label (a line break inside a paragraph renders as a space)
            cell.source = SOLUTION_LABEL.sub(r"\1\n", cell.source)


# --------------------------------------------------------------------------- previous / next


def bare_title(nb, path: Path) -> str:
    """The notebook's ``# `` title without a leading number ('02 · ')."""
    for heading in headings(nb):
        if heading.level == 1:
            return re.sub(r"^\d\d\s*[·.:-]\s*", "", heading.text.strip())
    return path.stem


def title(path: Path) -> str:
    return f"{path.name[:2]} · {bare_title(nbformat.read(path, as_version=4), path)}"


def navigation_source(previous: Path | None, following: Path | None) -> str:
    parts = []
    if previous is not None:
        parts.append(f"**Previous:** [{title(previous)}]({quote(previous.name)})")
    if following is not None:
        parts.append(f"**Next:** [{title(following)}]({quote(following.name)})")
    return " &nbsp;|&nbsp; ".join(parts) if parts else "This is the only notebook."


def update_navigation(nb, previous: Path | None, following: Path | None) -> None:
    source = navigation_source(previous, following)
    cells = [c for c in nb.cells if NAVIGATION_TAG in c.metadata.get("tags", [])]
    for cell in cells:
        nb.cells.remove(cell)
    cell = cells[0] if cells else new_markdown_cell(source, {"id": "navigation"})
    cell.source = source
    cell.metadata["tags"] = [NAVIGATION_TAG]
    nb.cells.append(cell)


# --------------------------------------------------------------------------- whole collection


def teaching_order(folder: Path = NOTEBOOKS) -> list[Path]:
    """The numbered notebooks of ``folder``, in teaching order (by file name: 00 first)."""
    return sorted(p for p in Path(folder).glob("*.ipynb") if NAME.match(p.name))


def updated(path: Path, order: list[Path]):
    """The notebook at ``path`` with contents, hidden solutions and navigation updated."""
    nb = nbformat.read(path, as_version=4)
    new = copy.deepcopy(nb)
    hide_solutions(new)
    update_contents(new)
    k = order.index(path)
    update_navigation(new, order[k - 1] if k > 0 else None,
                      order[k + 1] if k + 1 < len(order) else None)
    return new


def minutes(nb, number: str | None = None) -> int:
    """Estimated time to read a notebook and run its cells, in minutes (multiple of 15).

    The words of its Markdown cells (with their mathematics) at ``WORDS_PER_MINUTE``, a
    pace that includes reading and running the code cells; times ``NEW_IDEAS_FACTOR`` when
    the notebook (``number``, its two digits) is one of ``NEW_IDEAS``. The Exercises and
    Solutions sections are not included (the learning path adds time for them).
    """
    exercises = next((h.cell for h in headings(nb) if h.level == 2
                      and re.match(r"\d+\.\s+Exercises", heading_text(h.text))), len(nb.cells))
    words = sum(len(re.findall(r"\w+", cell.source)) for cell in nb.cells[:exercises]
                if cell.cell_type == "markdown")
    return reading_minutes(words, number)


def reading_minutes(words: int, number: str | None = None) -> int:
    """The rule of :func:`minutes` for a text of ``words`` words (multiple of 15)."""
    total = words / WORDS_PER_MINUTE
    if number in NEW_IDEAS:
        total *= NEW_IDEAS_FACTOR
    return max(15, 15 * round(total / 15))


def duration(total: int) -> str:
    hours, rest = divmod(total, 60)
    return " ".join(part for part in (f"{hours} h" if hours else "",
                                      f"{rest} min" if rest else "") if part)


def learning_path(order: list[Path], intro: Path) -> str:
    """The Markdown table of the notebooks in teaching order, with links, levels and times."""
    rows = ["| | Notebook | Level | Time (about) |", "|---|---|---|---|"]
    for path in order:
        nb = nbformat.read(path, as_version=4)
        name = bare_title(nb, path).replace("|", "\\|")
        optional = re.search(r"appendix|optional", name, re.IGNORECASE)
        link = quote(Path(os.path.relpath(path, intro.parent)).as_posix())
        number = path.name[:2]
        level = LEVELS.get(number, DEFAULT_LEVEL)
        rows.append(f"| {number} | [{name}]({link}){' *(optional)*' if optional else ''} "
                    f"| {level} | {duration(minutes(nb, number))} |")
    dense = [path.name[:2] for path in order if path.name[:2] in NEW_IDEAS]
    if dense:
        names = ", ".join(dense[:-1]) + (" and " if len(dense) > 1 else "") + dense[-1]
        rows += ["", f"The times of {names} are multiplied by {NEW_IDEAS_FACTOR:g}: each "
                 "brings in many ideas that no earlier notebook teaches."]
    return "\n".join(rows) + "\n"


def update_intro(order: list[Path], intro: Path) -> tuple[str, str] | None:
    """(old text, new text) of the book's front page with its learning path regenerated."""
    if not intro.exists():
        return None
    old = intro.read_text(encoding="utf-8")
    if not LEARNING_PATH.search(old):
        return None
    new = LEARNING_PATH.sub(lambda m: m.group(1) + learning_path(order, intro) + m.group(3),
                            old)
    return old, new


def problems(path: Path, nb=None) -> list[str]:
    """What the tool cannot fix in one notebook: layout of the end sections, broken links."""
    nb = nbformat.read(path, as_version=4) if nb is None else nb
    found = []
    section = solutions_range(nb)
    if section is None:
        found.append("no '## N. Solutions' section")
    else:
        start, stop = section
        if not solution_cells(nb):
            found.append("the Solutions section has no cell starting with '**Solution k.**'")
        inner = [h for h in headings(nb) if start <= h.cell < stop and h.level > 2]
        for heading in inner:
            found.append(f"heading {'#' * heading.level} {heading.text!r} inside the "
                         "Solutions section: start each solution with '**Solution k.**'")
    last = [heading_text(h.text) for h in headings(nb) if h.level == 2][-3:]
    numbers = [NUMBERED.match(text) for text in last]
    if (len(last) < 3 or not all(numbers)
            or [m.group(2).strip().lower() for m in numbers] != ["exercises", "solutions",
                                                                "references"]
            or [int(m.group(1)) for m in numbers] != list(range(int(numbers[0].group(1)),
                                                                int(numbers[0].group(1)) + 3))):
        found.append(f"the last ## sections are {last}, not 'N. Exercises', "
                     "'N+1. Solutions', 'N+2. References'")
    for heading in headings(nb):
        if heading.level != 2 or LINKABLE.match(heading.anchor):
            continue
        if any(is_math for is_math, _ in _split_math(heading.text)):
            why = ("has maths: JupyterLab gives a heading its id only after MathJax has "
                   "typeset it, so no link can reach it; write the heading in words")
        else:
            odd = sorted({c for c in heading.anchor if not LINKABLE.match(c)})
            why = (f"has {' '.join(odd)}: JupyterLab cannot follow a link to a heading with "
                   "characters a browser percent-encodes (non-ASCII, quotes, <, >); "
                   "use plain ASCII")
        found.append(f"heading ## {heading.text!r} {why}")
    found.extend(broken_links(path, nb))
    return found


# [text](target "title"), the target possibly with balanced parentheses
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?((?:[^()\s<>]|\([^()\s]*\))+)>?"
                  r"(?:\s+\"[^\"]*\")?\s*\)")
HTML_LINK = re.compile(r"<(?:a|img)\s[^>]*?(?:href|src)=[\"']([^\"']+)[\"']", re.IGNORECASE)


def links(nb):
    """(cell index, target) of every Markdown link and image of the notebook."""
    for index, cell in enumerate(nb.cells):
        if cell.cell_type != "markdown":
            continue
        text = "\n".join(markdown_lines(cell.source))
        # inline maths may hold brackets: drop it before looking for links
        text = "".join("" if is_math else piece for is_math, piece in _split_math(text))
        for pattern in (LINK, HTML_LINK):
            for match in pattern.finditer(text):
                yield index, match.group(1)


def broken_links(path: Path, nb=None) -> list[str]:
    """Every link of the notebook that does not resolve, as 'cell k: target (why)'."""
    nb = nbformat.read(path, as_version=4) if nb is None else nb
    own = anchors(nb)
    broken = []
    path = Path(path).resolve()
    # links may go anywhere in the repository (or, for a folder outside it, in the folder)
    root = ROOT if path.is_relative_to(ROOT) else path.parent
    for index, target in links(nb):
        parts = urlsplit(target)
        if parts.scheme or target.startswith("//"):
            continue  # a web address: not checked here (no network)
        fragment = unquote(parts.fragment)
        if not parts.path:
            if fragment not in own:
                broken.append(f"cell {index}: {target} (no heading with this anchor)")
            continue
        file = (path.parent / unquote(parts.path)).resolve()
        try:
            file.relative_to(root)
        except ValueError:
            broken.append(f"cell {index}: {target} (outside the repository)")
            continue
        if not file.exists():
            broken.append(f"cell {index}: {target} (no such file)")
        elif fragment and file.suffix == ".ipynb":
            if fragment not in anchors(nbformat.read(file, as_version=4)):
                broken.append(f"cell {index}: {target} (no heading with this anchor "
                              f"in {file.name})")
    return broken


def run(folder: Path = NOTEBOOKS, check: bool = False, out=sys.stdout,
        intro: Path | None = INTRO) -> int:
    """Update (or with ``check``, only compare) every notebook; return the exit code.

    ``intro``: the book's front page, whose learning path is regenerated too (None: skip).
    """
    order = teaching_order(folder)
    status = 0
    texts = update_intro(order, intro) if intro is not None else None
    if texts is not None and texts[0] != texts[1]:
        if check:
            print(f"{intro.name}: learning path out of date; run "
                  "python tools/notebook_navigation.py", file=out)
            status = 1
        else:
            intro.write_text(texts[1], encoding="utf-8")
            print(f"{intro.name}: learning path updated", file=out)
    for path in order:
        old = path.read_text(encoding="utf-8")
        nb = updated(path, order)
        new = nbformat.writes(nb) + "\n"
        if new != old:
            if check:
                print(f"{path.name}: out of date; run python tools/notebook_navigation.py",
                      file=out)
                status = 1
            else:
                path.write_text(new, encoding="utf-8")
                print(f"{path.name}: updated", file=out)
        for problem in problems(path, nb):
            print(f"{path.name}: {problem}", file=out)
            status = 1
    return status


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", nargs="?", type=Path, default=NOTEBOOKS,
                        help="folder of the notebooks (default: notebooks/)")
    parser.add_argument("--check", action="store_true",
                        help="change nothing; exit 1 if a notebook is out of date or has "
                             "a problem the tool cannot fix")
    args = parser.parse_args(argv)
    same = args.folder.resolve() == NOTEBOOKS.resolve()
    return run(args.folder, check=args.check, intro=INTRO if same else None)


if __name__ == "__main__":
    sys.exit(main())
