"""Sphinx extension for the book made from the bmc_functions notebooks.

What Jupyter Book 1 does not do by itself:

1. **MathJax without a network.** The pages load MathJax 3 from the book's own ``_static``
   folder. The files come from the ``sphinx-mathjax-offline`` package (installed by the
   ``book`` extra), of which only what the pages need is copied: the SVG output component
   (no web fonts, so it also works from ``file://``), the TeX extensions that ``autoload``
   fetches on demand (``\\boldsymbol`` lives in ``boldsymbol.js``) and the menu.
2. **JupyterLab's heading anchors.** JupyterLab gives every heading the id
   ``textContent.replace(/ /g, '-')`` (``## 2. What a rotation matrix is`` ->
   ``2.-What-a-rotation-matrix-is``), and the notebooks' links use that form. Each section
   of a page gets the same id, and MyST resolves ``#id`` and ``other.ipynb#id`` links to it,
   so one link works in JupyterLab and in the book.
3. **Solutions hidden until opened.** In the section whose heading is ``N. Solutions``,
   everything from the first ``**Solution k.**`` paragraph on is put, solution by
   solution, in a closed ``<details>`` block (no JavaScript needed). The heading and the
   intro above the first solution stay visible.
4. **Links to the API reference.** In each notebook page, the first inline literal that
   names a public function or class (``svdt``, ``svdt(A, B)``,
   ``bmc_functions.svdt``, ``plotting.set_lab_view``) links to its page in
   ``book/api/`` (written by ``tools/api_reference.py``).
5. **One Previous/Next.** The last cell of each notebook (tag ``navigation``, written by
   ``tools/notebook_navigation.py`` for JupyterLab) is left out of its page: the theme's
   Previous/Next buttons below the page do the same.
6. **MathJax on every page**, not only on pages with mathematics: the sidebar, the
   Previous/Next buttons and the search results show notebook titles with maths (03's
   ``$\\det(\\mathbf{U}\\mathbf{V}^T) = -1$``). ``static/bmc_book.js`` typesets the
   search results, fits wide display equations to the column and links figures shown
   smaller than drawn to their full-size image.
7. **API names first in search results** (``search_scorer.js``).

``tools/notebook_navigation.py`` computes the same anchors (``jupyterlab_anchor``) from the
Markdown source and writes the matching cell metadata for JupyterLab.
"""

from __future__ import annotations

import html
import importlib.util
import json
import re
import shutil
from pathlib import Path

from docutils import nodes
from sphinx.transforms import SphinxTransform
from sphinx.util import logging

LOGGER = logging.getLogger(__name__)

#: where the copied MathJax lives in the built book, relative to ``_static``
MATHJAX_DIR = "mathjax"
MATHJAX_ENTRY = "tex-svg.js"
#: what the pages need from the MathJax distribution: files and whole folders
MATHJAX_PARTS = (MATHJAX_ENTRY, "input/tex/extensions", "ui", "a11y")

SOLUTIONS_TITLE = re.compile(r"^\s*(\d+\.\s*)?(worked\s+)?solutions\s*$", re.IGNORECASE)
SOLUTION_START = re.compile(r"^\s*Solution\s+(\d+)\b")


def mathjax_source() -> Path:
    """The folder of MathJax 3 files shipped by ``sphinx-mathjax-offline``."""
    spec = importlib.util.find_spec("sphinx-mathjax-offline")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError(
            "the book needs MathJax from the package 'sphinx-mathjax-offline': "
            "install the book extra, python -m pip install -e '.[book]'")
    folder = Path(list(spec.submodule_search_locations)[0]) / "static" / "mathjax"
    if not (folder / MATHJAX_ENTRY).is_file():
        raise RuntimeError(f"no {MATHJAX_ENTRY} in {folder}")
    return folder


def jupyterlab_id(title: nodes.Element) -> str:
    """JupyterLab's id for a heading: its text (inline maths with its ``$``), spaces -> '-'."""

    def text(node):
        if isinstance(node, nodes.math):
            return "$" + node.astext() + "$"
        if isinstance(node, nodes.Text):
            return str(node)
        return "".join(text(child) for child in node.children)

    return text(title).replace(" ", "-")


class JupyterLabAnchors(SphinxTransform):
    """Give every section JupyterLab's id and register it for MyST's link resolution."""

    # before Sphinx's smart quotes (750) change the title text, and before MyST resolves
    # ``[text](#id)`` links (879)
    default_priority = 700

    def apply(self, **kwargs) -> None:
        slugs = getattr(self.document, "myst_slugs", None)
        if slugs is None:
            slugs = {}
            self.document.myst_slugs = slugs
        for section in self.document.findall(nodes.section):
            if not section.children or not isinstance(section[0], nodes.title):
                continue
            anchor = jupyterlab_id(section[0])
            if not anchor or anchor in self.document.ids:
                continue  # the first of two equal headings wins, as in a browser
            section["ids"].append(anchor)
            self.document.ids[anchor] = section
            entry = (section.line, anchor, section[0].astext())
            # MyST leaves the reserved characters '$' and '#' percent-encoded in link
            # targets (markdown-it's normalizeLinkText): accept both spellings
            for key in {anchor, anchor.replace("#", "%23").replace("$", "%24")}:
                slugs.setdefault(key, entry)
        if self.env is not None:
            self.env.metadata[self.env.docname]["myst_slugs"] = dict(slugs)


class solution(nodes.General, nodes.Element):
    """A worked solution, closed until the reader opens it."""


def visit_solution_html(self, node):
    label = html.escape(node["label"])
    self.body.append(
        f'<details class="bmc-solution"><summary>{label} '
        '<span class="bmc-solution-hint">(click to open)</span></summary>\n'
        '<div class="bmc-solution-body">\n')


def depart_solution_html(self, node):
    self.body.append("</div>\n</details>\n")


def visit_solution_other(self, node):
    pass


def depart_solution_other(self, node):
    pass


def solution_number(node: nodes.Node) -> str | None:
    """'3' if ``node`` is a paragraph that starts with a bold 'Solution 3', else None."""
    if not isinstance(node, nodes.paragraph):
        return None
    # MyST may leave an empty text node before the first inline element
    children = [c for c in node.children if not (isinstance(c, nodes.Text) and not c.strip())]
    first = children[0] if children else None
    if not isinstance(first, nodes.strong):
        return None
    match = SOLUTION_START.match(first.astext())
    return match.group(1) if match else None


class HideSolutions(SphinxTransform):
    """Wrap each worked solution of the Solutions section in a closed ``<details>``."""

    default_priority = 710

    def apply(self, **kwargs) -> None:
        for section in list(self.document.findall(nodes.section)):
            if not section.children or not isinstance(section[0], nodes.title):
                continue
            if not SOLUTIONS_TITLE.match(section[0].astext()):
                continue
            children = list(section.children[1:])
            starts = [i for i, child in enumerate(children) if solution_number(child)]
            if not starts:
                LOGGER.warning("section %r has no '**Solution k.**' paragraph",
                               section[0].astext(), location=section)
                continue
            nested = [c for c in children[starts[0]:] if isinstance(c, nodes.section)]
            if nested:
                LOGGER.warning("a heading inside the solutions (%r) cannot be hidden: "
                               "start each solution with a '**Solution k.**' paragraph",
                               nested[0][0].astext(), location=nested[0])
            groups = []
            for k, start in enumerate(starts):
                stop = starts[k + 1] if k + 1 < len(starts) else len(children)
                groups.append(children[start:stop])
            for group in groups:
                for child in group:
                    section.remove(child)
                block = solution(label=f"Solution {solution_number(group[0])}")
                block.extend(group)
                section.append(block)


class LinksToRepositoryFiles(SphinxTransform):
    """A link to a Markdown file that is not a page of the book is a download.

    MyST takes a link to any ``.md`` (or ``.ipynb``) file for a link to a page; a
    notebook's link to, say, ``../data/README.md`` would then fail the build. The file is
    copied into the book instead (``_downloads/``), as MyST does for other files.
    """

    default_priority = 500

    def apply(self, **kwargs) -> None:
        from sphinx import addnodes

        srcdir = Path(self.env.srcdir)
        for node in list(self.document.findall(addnodes.pending_xref)):
            if node.get("refdomain") != "doc" or node.get("reftype") != "myst":
                continue
            docname = node["reftarget"]
            if docname in self.env.found_docs:
                continue
            suffixes = list(self.config.source_suffix)
            found = [srcdir / (docname + s) for s in suffixes if (srcdir / (docname + s)).is_file()]
            if not found:
                continue
            download = addnodes.download_reference(
                refdomain=None, reftype="myst", refdoc=node.get("refdoc"),
                refexplicit=node.get("refexplicit", False),
                reftarget="/" + found[0].relative_to(srcdir).as_posix())
            download.extend(child.deepcopy() for child in node.children)
            for child in download.findall(nodes.inline):
                child["classes"] = [c for c in child["classes"] if c != "xref"] + ["download"]
            node.replace_self(download)


#: an inline literal that names one thing: ``name``, ``module.name``, ``name(args)`` or
#: ``result = name(args)``; group 1 is the (dotted) name
NAMED_LITERAL = re.compile(
    r"^\s*(?:[A-Za-z_][\w, ]*=(?!=)\s*)?([A-Za-z_][\w.]*)\s*(?:\(.*\))?\s*$", re.S)
API_PREFIX = "book/api/"


def api_pages(docnames) -> dict[str, str]:
    """{name as a notebook may write it: docname of its API page}.

    tools/api_reference.py names each page after its name: ``book/api/<group>/svdt`` for
    ``bmc_functions.svdt``, ``book/api/plotting/plotting.set_lab_view`` for
    ``bmc_functions.plotting.set_lab_view`` (also written ``set_lab_view`` once imported,
    unless a name of the package has that spelling).
    """
    pages, bare = {}, {}
    for docname in docnames:
        parts = docname[len(API_PREFIX):].split("/") if docname.startswith(API_PREFIX) else ()
        if len(parts) != 2:
            continue
        stem = parts[1]
        pages[stem] = pages[f"bmc_functions.{stem}"] = docname
        if "." in stem:
            bare[stem.rsplit(".", 1)[1]] = docname
    return {**bare, **pages}


def link_api_names(app, doctree, docname) -> None:
    """In a notebook page, link the first inline literal naming a public name to its page.

    Done when the book is built, not in the notebooks: a notebook's Markdown links must
    work in JupyterLab too, where book/api/ does not exist (it is generated at every build
    and not kept in git; tools/notebook_navigation.py --check refuses links to missing
    files). Code cells, headings and literals already inside a link are left as they are.
    """
    if not docname.startswith("notebooks/") or app.builder.format != "html":
        return
    pages = api_pages(app.env.found_docs)
    seen = set()
    for literal in list(doctree.findall(nodes.literal)):
        match = NAMED_LITERAL.match(literal.astext())
        target = pages.get(match.group(1)) if match else None
        if target is None or target in seen:
            continue
        if any(isinstance(parent, nodes.title)
               or (isinstance(parent, nodes.container) and "cell" in parent["classes"])
               for parent in ancestors(literal)):
            continue
        seen.add(target)
        if any(isinstance(parent, nodes.reference) for parent in ancestors(literal)):
            continue  # the notebook links it already
        uri = app.builder.get_relative_uri(docname, target)
        reference = nodes.reference("", "", internal=True, refuri=uri,
                                    reftitle=f"bmc_functions.{target.rsplit('/', 1)[1]}")
        literal.replace_self(reference)
        reference.append(literal)


def ancestors(node: nodes.Node):
    while node.parent is not None:
        node = node.parent
        yield node


NAVIGATION_TAG = "navigation"


def drop_navigation_cells(app, docname, source) -> None:
    """Leave a notebook's Previous/Next cell out of its page (the theme has its own).

    The notebook is edited as it is read (MyST-NB's ``remove-cell`` tag), not on disk: the
    page's download button still gives the notebook as stored.
    """
    if not docname.startswith("notebooks/") or not source or '"navigation"' not in source[0]:
        return
    notebook = json.loads(source[0])
    for cell in notebook.get("cells", []):
        tags = cell.get("metadata", {}).get("tags", [])
        if NAVIGATION_TAG in tags:
            cell["metadata"]["tags"] = [*tags, "remove-cell"]
    source[0] = json.dumps(notebook)


#: A numbered footnote of a docstring, cited (``[1]_``) or defined (``.. [1]``).
FOOTNOTE = re.compile(r"(?<![\w\]])\[(\d+)\](_|(?=\s))")


def unique_module_footnotes(app, what, name, obj, options, lines) -> None:
    """Give a module docstring's numbered footnotes labels of its own.

    A group's API page shows the docstrings of several modules (Plug-in Gait's package,
    lower body and upper body), each numbering its sources from ``[1]``: on one page two
    ``.. [1]`` are a duplicate target. As auto-numbered footnotes labelled by module
    (``[#lower_body-1]``) they are numbered on the page in order and stay distinct. Only
    module docstrings: a function's page holds its own docstring alone.
    """
    if what != "module":
        return
    prefix = name.rsplit(".", 1)[-1]
    for k, line in enumerate(lines):
        lines[k] = FOOTNOTE.sub(lambda m: f"[#{prefix}-{m.group(1)}]{m.group(2)}", line)


def use_offline_mathjax(app, config) -> None:
    mathjax_source()  # fail early, with the install command, when the package is missing
    config.mathjax_path = f"{MATHJAX_DIR}/{MATHJAX_ENTRY}"
    if not config.html_search_scorer:   # API names first in the search results
        config.html_search_scorer = str(Path(__file__).parent / "search_scorer.js")


def add_static_path(app) -> None:
    static = str(Path(__file__).parent / "static")
    if static not in app.config.html_static_path:
        app.config.html_static_path.append(static)


def copy_mathjax(app, exception) -> None:
    if exception is not None or app.builder.format != "html":
        return
    source = mathjax_source()
    target = Path(app.outdir) / "_static" / MATHJAX_DIR
    for part in MATHJAX_PARTS:
        src, dst = source / part, target / part
        dst.parent.mkdir(parents=True, exist_ok=True)
        if src.is_dir():
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            shutil.copy2(src, dst)


def setup(app):
    app.add_node(
        solution,
        html=(visit_solution_html, depart_solution_html),
        latex=(visit_solution_other, depart_solution_other),
        text=(visit_solution_other, depart_solution_other),
        man=(visit_solution_other, depart_solution_other),
        texinfo=(visit_solution_other, depart_solution_other),
    )
    app.add_transform(JupyterLabAnchors)
    app.add_transform(HideSolutions)
    app.add_transform(LinksToRepositoryFiles)
    app.connect("config-inited", use_offline_mathjax)
    app.connect("builder-inited", add_static_path)
    app.connect("build-finished", copy_mathjax)
    app.connect("doctree-resolved", link_api_names)
    app.connect("source-read", drop_navigation_cells)
    app.setup_extension("sphinx.ext.autodoc")   # its event, whatever the extensions' order
    app.connect("autodoc-process-docstring", unique_module_footnotes)
    app.add_css_file("bmc_book.css")
    app.add_js_file("bmc_book.js")
    # every page loads MathJax (Sphinx's default: only pages with an equation of their own)
    app.set_html_assets_policy("always")
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
