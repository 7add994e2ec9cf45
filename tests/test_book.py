"""The book (tools/build_book.py): built once per test session from the notebooks as they
are stored, with warnings as errors, into a temporary folder; then checked as files and,
when Chromium is installed, in a real headless browser opened on file:// URLs."""

import functools
import http.server
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from urllib.parse import unquote, urlsplit

import nbformat
import pytest

from helpers import ROOT

NOTEBOOKS = sorted(p for p in (ROOT / "notebooks").glob("*.ipynb")
                   if re.match(r"\d\d_", p.name))


def load_tool(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "tools" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


build_book = load_tool("build_book")


@pytest.fixture(scope="session")
def book(tmp_path_factory):
    """The built book's HTML folder (one build per test session)."""
    output = tmp_path_factory.mktemp("book")
    start = time.perf_counter()
    try:
        html = build_book.build(output, quiet=True)
    except subprocess.CalledProcessError as error:
        log = (error.output or "") + (error.stderr or "")
        warnings = [line for line in log.splitlines() if "WARNING" in line or "ERROR" in line]
        pytest.fail("the book did not build with warnings as errors:\n"
                    + "\n".join(warnings or log.splitlines()[-40:]), pytrace=False)
    size = sum(p.stat().st_size for p in html.rglob("*") if p.is_file())
    print(f"\nbook built in {time.perf_counter() - start:.1f} s, {size / 1e6:.1f} MB, "
          f"{len(list(html.rglob('*.html')))} HTML files")
    return html


def soup(path):
    from bs4 import BeautifulSoup
    return BeautifulSoup(path.read_text(encoding="utf-8"), "html.parser")


def page(book, notebook):
    return book / "notebooks" / (notebook.stem + ".html")


def pages(book):
    return sorted(book.rglob("*.html"))


# --------------------------------------------------------------------------- the files


def test_the_folder_can_be_published_on_github_pages(book):
    assert (book / ".nojekyll").is_file()  # else Jekyll drops _static and _images


def test_the_front_page_opens_from_index_html(book):
    index = (book / "index.html").read_text(encoding="utf-8")
    assert 'url=book/intro.html' in index
    intro = soup(book / "book" / "intro.html")
    text = intro.get_text()
    for part in ("Who it is for", "Prerequisites", "Learning path", "How to cite",
                 "Run the notebooks on your computer", "python -m pip install -e"):
        assert part in text, part


def test_every_notebook_has_a_page_linked_from_the_learning_path(book):
    intro = soup(book / "book" / "intro.html")
    table = intro.find("table")
    linked = {a["href"].split("#")[0] for a in table.find_all("a", href=True)}
    for notebook in NOTEBOOKS:
        assert page(book, notebook).is_file(), f"no page for {notebook.name}"
        assert f"../notebooks/{notebook.stem}.html" in linked, notebook.name


def test_every_notebook_is_downloadable_from_its_page_as_stored(book):
    for notebook in NOTEBOOKS:
        links = [a["href"] for a in soup(page(book, notebook)).find_all("a", href=True)
                 if a["href"].endswith(".ipynb")]
        assert links, f"{notebook.name}: no download link"
        target = (page(book, notebook).parent / links[0]).resolve()
        assert target.read_bytes() == notebook.read_bytes(), notebook.name


def test_previous_and_next_follow_the_teaching_order(book):
    order = ["book/intro"] + [f"notebooks/{p.stem}" for p in NOTEBOOKS]
    for k, name in enumerate(order):
        html = soup(book / f"{name}.html")
        nxt = html.select_one("a.right-next")
        prev = html.select_one("a.left-prev")
        folder = (book / name).parent
        if k + 1 < len(order):
            assert nxt is not None, name
            assert (folder / nxt["href"]).resolve() == (book / f"{order[k + 1]}.html").resolve()
        if k > 0:
            assert prev is not None, name
            assert (folder / prev["href"]).resolve() == (book / f"{order[k - 1]}.html").resolve()


NETWORK = re.compile(r"^\s*(https?:)?//", re.IGNORECASE)


def test_no_page_loads_a_script_style_sheet_or_font_from_the_network(book):
    found = []
    for path in pages(book):
        html = soup(path)
        for tag in html.find_all("script", src=True):
            if NETWORK.match(tag["src"]):
                found.append(f"{path.name}: script {tag['src']}")
        for tag in html.find_all("link", href=True):
            if NETWORK.match(tag["href"]) and set(tag.get("rel", [])) & {
                    "stylesheet", "preload", "modulepreload", "prefetch", "icon"}:
                found.append(f"{path.name}: {tag.get('rel')} {tag['href']}")
        for tag in html.find_all("script", src=False):
            if re.search(r"https?://[^\s\"']+\.(js|css|woff2?)\b", tag.get_text()):
                found.append(f"{path.name}: inline script names a web address")
        for tag in html.find_all("style"):
            found += [f"{path.name}: {u}" for u in css_network_urls(tag.get_text())]
    for css in book.rglob("*.css"):
        found += [f"{css.name}: {u}" for u in css_network_urls(css.read_text(errors="replace"))]
    assert found == []


def css_network_urls(text):
    urls = re.findall(r"url\(\s*['\"]?([^)'\"]+)", text) + re.findall(
        r"@import\s+['\"]([^'\"]+)", text)
    return [u for u in urls if NETWORK.match(u)]


def test_mathjax_is_served_from_the_book_with_its_extensions(book):
    mathjax = book / "_static" / "mathjax"
    assert (mathjax / "tex-svg.js").is_file()
    assert (mathjax / "input" / "tex" / "extensions" / "boldsymbol.js").is_file()
    for notebook in NOTEBOOKS:
        srcs = [s["src"] for s in soup(page(book, notebook)).find_all("script", src=True)]
        assert "../_static/mathjax/tex-svg.js" in srcs, notebook.name


def solutions_section(html):
    for section in html.find_all("section"):
        heading = section.find(["h2"], recursive=False)
        if heading and re.match(r"^\s*(\d+\.\s*)?(worked\s+)?solutions\b",
                                heading.get_text(" ").strip(), re.IGNORECASE):
            return section
    return None


def test_every_solution_is_inside_a_closed_block(book):
    for notebook in NOTEBOOKS:
        nb = nbformat.read(notebook, as_version=4)
        expected = sum(1 for c in nb.cells if c.cell_type == "markdown"
                       and re.match(r"\*\*Solution\s+\d+", c.source.lstrip())
                       and "solution" in c.metadata.get("tags", []))
        section = solutions_section(soup(page(book, notebook)))
        assert section is not None, notebook.name
        blocks = section.select("details.bmc-solution")
        assert len(blocks) == expected > 0, notebook.name
        assert not any(b.has_attr("open") for b in blocks), notebook.name
        for strong in section.find_all("strong"):
            if re.match(r"Solution\s+\d+", strong.get_text()):
                assert strong.find_parent("details", class_="bmc-solution"), notebook.name
        first = blocks[0]
        for cell in section.select("div.cell"):  # every code cell after the first solution
            if first in cell.find_all_previous("details"):
                assert cell.find_parent("details", class_="bmc-solution"), notebook.name


def ids_of(path, cache={}):
    if path not in cache:
        cache[path] = {tag["id"] for tag in soup(path).find_all(id=True)}
    return cache[path]


def test_every_link_in_the_book_resolves(book):
    broken = []
    for path in pages(book):
        for a in soup(path).find_all("a", href=True):
            parts = urlsplit(a["href"])
            if parts.scheme or a["href"].startswith("//"):
                continue
            target = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            if not target.exists():
                broken.append(f"{path.relative_to(book)}: {a['href']}")
            elif parts.fragment and target.suffix == ".html":
                if unquote(parts.fragment) not in ids_of(target):
                    broken.append(f"{path.relative_to(book)}: {a['href']} (no such id)")
    assert broken == []


def test_the_notebooks_jupyterlab_anchors_are_ids_in_the_book(book):
    nav = load_tool("notebook_navigation")
    for notebook in NOTEBOOKS:
        nb = nbformat.read(notebook, as_version=4)
        missing = nav.anchors(nb) - ids_of(page(book, notebook))
        assert missing == set(), notebook.name


def test_search_index_covers_every_notebook(book):
    index = (book / "searchindex.js").read_text(encoding="utf-8")
    for notebook in NOTEBOOKS:
        assert f'"notebooks/{notebook.stem}"' in index, notebook.name


def test_the_api_front_page_lists_every_name(book):
    front = book / "book" / "api" / "index.html"
    linked = {(front.parent / a["href"].split("#")[0]).resolve()
              for a in soup(front).select("article a[href]")}
    missing = [path.relative_to(book).as_posix() for path in api_pages(book)
               if path.resolve() not in linked]
    assert missing == []


def test_the_group_pages_show_their_roles_as_links_and_their_modules_docstrings(book):
    # the summaries' :func:`name` are links to the names' pages, not literal text
    pig = soup(book / "book" / "api" / "plug_in_gait.html").select_one("article")
    text = pig.get_text(" ")
    assert ":func:" not in text and ":meth:" not in text
    made_by = pig.find(string=re.compile("made by"))
    link = made_by.find_parent("td").select_one("a[href]")
    assert link["href"].split("#")[0] == "plug_in_gait/plug_in_gait.html"
    # the module's docstring (its steps and sources), which the function's page points to
    assert "The module bmc_functions.models.plug_in_gait" in text
    assert "Davis" in text and "Kadaba" in text
    page = soup(book / "book" / "api" / "plug_in_gait" / "plug_in_gait.html")
    assert any(a["href"].split("#")[0] == "../plug_in_gait.html"
               for a in page.select("article a[href]"))


@pytest.mark.parametrize("name, notebook", [("lowpass", "14"), ("svdt", "02"),
                                            ("gait_events", "10"),
                                            ("plug_in_gait", "13")])
def test_an_api_page_links_back_to_the_notebooks_that_use_it(book, name, notebook):
    path = next(p for p in api_pages(book) if p.stem == name)
    hrefs = [a["href"].split("#")[0] for a in soup(path).select("article a[href]")]
    targets = {(path.parent / h).resolve().relative_to(book).as_posix() for h in hrefs}
    assert any(t.startswith(f"notebooks/{notebook}_") for t in targets), targets


def test_most_api_pages_link_back_to_a_notebook(book):
    linking = [path for path in api_pages(book)
               if any("notebooks/" in a["href"] for a in soup(path).select("article a[href]"))]
    assert len(linking) >= 50, len(linking)


def test_the_book_leaves_the_notebooks_navigation_cell_to_the_theme(book):
    # one Previous/Next: the theme's buttons, not also the JupyterLab cell tagged
    # 'navigation' (tools/notebook_navigation.py), which the download keeps
    for notebook in NOTEBOOKS:
        html = soup(page(book, notebook))
        assert len(html.select(".prev-next-area")) == 1, notebook.name
        bold = [b for b in html.select("article strong")
                if b.get_text().strip() in ("Previous:", "Next:")]
        assert bold == [], notebook.name


def test_the_api_reference_helpers():
    api = load_tool("api_reference")
    assert api.markdown("made by :func:`plug_in_gait`, :meth:`~x.PlugInGait.track` and "
                        ":class:`Nothing`; :math:`10^5`, ``R``",
                        {"plug_in_gait": "g/plug_in_gait.rst", "PlugInGait": "g/P.rst"}) == (
        "made by [`plug_in_gait`](g/plug_in_gait.rst), [`track`](g/P.rst) and `Nothing`; "
        "$10^5$, `R`")
    assert api.rst_text("when $\\det M = -1$") == "when :math:`\\det M = -1`"


# --------------------------------------------------------------------------- in a browser

BROWSER_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--no-first-run",
                "--disable-dev-shm-usage", "--window-size=1280,2000"]


def find_browser():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        binary = shutil.which(name)
        if binary:
            break
    else:
        return None, "no Chromium (apt-get install chromium chromium-driver)"
    driver = shutil.which("chromedriver") or (
        "/usr/lib/chromium/chromedriver" if os.path.exists("/usr/lib/chromium/chromedriver")
        else None)
    if driver is None:
        return None, "no chromedriver (apt-get install chromium-driver)"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return None, "selenium is not installed (it is in the test extra)"
    return (binary, driver), ""


@pytest.fixture(scope="session")
def browser():
    found, reason = find_browser()
    if found is None:
        pytest.skip(f"browser test skipped: {reason}")
    from selenium import webdriver
    from selenium.webdriver.chrome.options import Options
    from selenium.webdriver.chrome.service import Service

    options = Options()
    profile = tempfile.mkdtemp(prefix="chromium-profile-")
    for argument in BROWSER_ARGS + [f"--user-data-dir={profile}"]:
        options.add_argument(argument)
    options.binary_location = found[0]
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(found[1]), options=options)
    driver.set_script_timeout(60)
    driver.set_page_load_timeout(60)
    yield driver
    driver.quit()
    shutil.rmtree(profile, ignore_errors=True)


WAIT_FOR_MATHJAX = """
const done = arguments[arguments.length - 1];
const start = Date.now();
(function wait() {
  if (window.MathJax && MathJax.startup && MathJax.startup.promise) {
    MathJax.startup.promise.then(() => done('ok'), e => done('error: ' + e));
  } else if (Date.now() - start > 30000) {
    done('MathJax did not load');
  } else {
    setTimeout(wait, 50);
  }
})();
"""

PAGE_FACTS = """
const article = document.querySelector('article') || document.body;
const without = (element, selector) => {
  const clone = element.cloneNode(true);
  clone.querySelectorAll(selector).forEach(e => e.remove());
  return clone.innerText;
};
return {
  typeset: article.querySelectorAll('mjx-container').length,
  errors: Array.from(article.querySelectorAll('mjx-merror, [data-mjx-error]'))
               .map(e => e.getAttribute('data-mjx-error') || e.textContent),
  // the article's prose: no code, no typeset maths
  text: without(article, 'pre, code, mjx-container, script, style'),
  // the article as read, inline code literals included
  reading: without(article, 'pre, mjx-container, script, style'),
  // everything on the page outside code: the sidebar, Previous/Next, search results
  page: without(document.body, 'pre, code, mjx-container, script, style'),
  images: Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, i.naturalWidth]),
};
"""

#: What a reader should never see in a page's text (issue 35, the book's round-4 review):
#: TeX that was not typeset, a docstring's rST role shown as text, a path of the project's
#: own layout, a notebook's own Previous/Next line (the theme has the buttons).
READER_TEXT = {
    "untypeset maths": (re.compile(r"[\w)}]\^[\w{(]|[α-ωΑ-Ω]_[\w{]|\\(?:mathbf|frac|det)\b"),
                        "text"),
    "rST role": (re.compile(r":(?:func|meth|class|mod|attr|data|math|ref|doc|py:\w+):`?\w"),
                 "reading"),
    "repository path": (re.compile(r"\.\./shared|shared/data"), "reading"),
    "own Previous/Next": (re.compile(r"\bPrevious:"), "text"),
}

#: Those of them that are in a notebook's own text or a docstring, waiting for its edit by
#: issue 35's notebook work (or a change to the module that another branch is making).
#: Each must still be there: a fixed one fails the test until it is struck off this list,
#: so that the list cannot go stale. (page's file stem, defect)
TEXT_PENDING = set()


def reader_text_problems(facts, stem=None, seen=None):
    """The READER_TEXT defects of a page; those pending for notebook ``stem`` go to
    ``seen`` instead."""
    problems = []
    for kind, (pattern, key) in READER_TEXT.items():
        match = pattern.search(facts[key])
        if match is None:
            continue
        if (stem, kind) in TEXT_PENDING and seen is not None:
            seen.add((stem, kind))
            continue
        text = facts[key]
        problems.append(f"{kind}: ...{text[max(0, match.start() - 60):match.end() + 40]!r}")
    return problems


def equations_in(notebook):
    """How many formulas a notebook's Markdown and rendered outputs hold (for MathJax)."""
    nb = nbformat.read(notebook, as_version=4)
    count = 0
    for cell in nb.cells:
        if "navigation" in cell.metadata.get("tags", []):
            continue   # left out of the page (the theme's Previous/Next buttons do it)
        if cell.cell_type == "markdown":
            text = re.sub(r"^\s*(```|~~~).*?^\s*\1\s*$", "", cell.source, flags=re.M | re.S)
            text = re.sub(r"`[^`\n]*`", "", text)
            text = re.sub(r"\\\$", "", text)
            display = re.findall(r"\$\$.+?\$\$", text, flags=re.S)
            text = re.sub(r"\$\$.+?\$\$", "", text, flags=re.S)
            inline = re.findall(r"\$[^$]+?\$", text, flags=re.S)
            text = re.sub(r"\$[^$]+?\$", "", text, flags=re.S)
            envs = re.findall(r"^\s*\\begin\{([a-z]+\*?)\}", text, flags=re.M)
            count += len(display) + len(inline) + len(envs)
        for output in cell.get("outputs", []):
            data = output.get("data", {})
            richer = {"text/html", "image/svg+xml", "image/png", "image/jpeg", "text/markdown"}
            if "text/latex" in data and not richer & set(data):
                count += 1
    return count


def console_errors(driver):
    return [entry["message"] for entry in driver.get_log("browser")
            if entry["level"] == "SEVERE"]


def check_page(driver, url, expected=None, mathjax=True):
    driver.get(url)
    if mathjax:   # (Sphinx loads MathJax only on pages with mathematics)
        status = driver.execute_async_script(WAIT_FOR_MATHJAX)
        assert status == "ok", f"{url}: {status}"
    facts = driver.execute_script(PAGE_FACTS)
    problems = []
    if facts["errors"]:
        problems.append(f"MathJax errors: {facts['errors'][:5]}")
    for raw in ("\\(", "\\[", "$$"):
        # in the article, and anywhere else on the page (the sidebar lists notebook titles
        # with maths, also on pages without any of their own)
        for where in ("text", "page"):
            if raw in facts[where]:
                k = facts[where].index(raw)
                problems.append(f"raw TeX {raw!r} left: "
                                f"...{facts[where][max(0, k - 60):k + 60]!r}")
                break
    if expected is not None and facts["typeset"] != expected:
        problems.append(f"{facts['typeset']} typeset equations, the notebook has {expected}")
    for src, complete, width in facts["images"]:
        if not complete or width == 0:
            problems.append(f"figure not loaded: {src}")
    problems += [f"console: {message}" for message in console_errors(driver)]
    return facts, problems


def test_every_page_in_a_browser_from_file_urls(book, browser):
    from selenium.webdriver.common.by import By

    report = []
    total = 0
    intro_url = (book / "index.html").as_uri()
    browser.get(intro_url)  # the redirect of index.html to the front page
    assert browser.current_url.endswith("book/intro.html")
    _, problems = check_page(browser, (book / "book" / "intro.html").as_uri())
    report += [f"intro: {p}" for p in problems]
    seen = set()
    for notebook in NOTEBOOKS:
        expected = equations_in(notebook)
        facts, problems = check_page(browser, page(book, notebook).as_uri(), expected)
        problems += reader_text_problems(facts, notebook.stem, seen)
        total += facts["typeset"]
        # worked solutions: closed, and open when their summary is clicked
        blocks = browser.find_elements(By.CSS_SELECTOR, "details.bmc-solution")
        if not blocks:
            problems.append("no solution blocks")
        for block in blocks:
            body = block.find_element(By.CSS_SELECTOR, ".bmc-solution-body")
            if block.get_attribute("open") is not None or body.is_displayed():
                problems.append("a solution is open before it is clicked")
            summary = block.find_element(By.TAG_NAME, "summary")
            browser.execute_script("arguments[0].scrollIntoView({block: 'center'});", summary)
            summary.click()
            if block.get_attribute("open") is None or not body.is_displayed():
                problems.append("a solution does not open when clicked")
        if notebook.name.startswith("08"):
            browser.execute_script("window.scrollTo(0, 0);")
            browser.save_screenshot(str(book.parent / "screenshot_08.png"))
        problems += [f"console: {message}" for message in console_errors(browser)]
        report += [f"{notebook.name}: {p}" for p in problems]
    stems = {notebook.stem for notebook in NOTEBOOKS}
    report += [f"{stem}: no {kind} any more: strike it off TEXT_PENDING"
               for stem, kind in sorted(TEXT_PENDING - seen) if stem in stems]
    for path in (book / "genindex.html", book / "search.html"):
        _, problems = check_page(browser, path.as_uri())
        report += [f"{path.name}: {p}" for p in problems]
    assert report == []
    print(f"\nbook: {len(NOTEBOOKS)} notebook pages, {total} equations typeset by MathJax")
    target = os.environ.get("BMC_BOOK_SCREENSHOT")
    if target:
        shutil.copy(book.parent / "screenshot_08.png", target)


def test_search_works_from_a_file_url(book, browser):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    browser.get((book / "search.html").as_uri() + "?q=quaternion")
    WebDriverWait(browser, 30).until(
        lambda d: d.find_elements(By.CSS_SELECTOR, "#search-results li"))
    hrefs = [a.get_attribute("href")
             for a in browser.find_elements(By.CSS_SELECTOR, "#search-results li a")]
    assert any("09_quaternion_method.html" in h for h in hrefs), hrefs
    assert console_errors(browser) == []


def test_the_book_works_from_a_static_web_server(book, browser):
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(book))

    class Quiet(handler.func):
        def log_message(self, *args):
            pass

    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0),
                                             functools.partial(Quiet, directory=str(book)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        notebook = NOTEBOOKS[0]
        url = f"http://127.0.0.1:{server.server_port}/notebooks/{notebook.stem}.html"
        _, problems = check_page(browser, url, equations_in(notebook))
        assert problems == []
    finally:
        server.shutdown()
        server.server_close()


WIDTHS = {"laptop": 1400, "phone": 400}

WAIT_FOR_LAYOUT = """
const done = arguments[arguments.length - 1];
const start = Date.now();
(function wait() {
  const images = Array.from(document.images).every(i => i.complete);
  if (images && document.body.dataset.bmcEquationsFitted === 'true') {
    setTimeout(() => done('ok'), 100);
  } else if (Date.now() - start > 30000) {
    done('the book\\'s script did not fit the equations (bmc_book.js)');
  } else {
    setTimeout(wait, 50);
  }
})();
"""

LAYOUT_FACTS = """
const article = document.querySelector('article');
const box = e => e.getBoundingClientRect();
const column = box(article);
const clipped = e => {   // inside a box of the column that scrolls or clips it
  for (let p = e.parentElement; p && p !== article; p = p.parentElement) {
    if (getComputedStyle(p).overflowX !== 'visible' && box(p).right <= column.right + 1)
      return true;
  }
  return false;
};
const wider = Array.from(article.querySelectorAll('*'))
  .filter(e => box(e).width > 0 && box(e).right > column.right + 1 && !clipped(e))
  .map(e => `${e.tagName.toLowerCase()}.${String(e.className).split(' ')[0]}: ` +
            `${Math.round(box(e).right - column.right)} px (${e.textContent.slice(0, 50)})`);
const h1 = article.querySelector('h1');
return {
  page: document.documentElement.scrollWidth - document.documentElement.clientWidth,
  wider: wider.slice(0, 5),
  code: Array.from(article.querySelectorAll('pre'))
    .filter(p => p.scrollWidth > p.clientWidth + 1).map(p => p.textContent.slice(0, 60)),
  equations: Array.from(article.querySelectorAll('mjx-container[display="true"]')).map(e => [
    e.scrollWidth <= e.clientWidth + 1, e.classList.contains('bmc-scrolls'),
    box(e).right <= column.right + 1, e.textContent.slice(0, 40)]),
  images: Array.from(article.querySelectorAll('img')).map(i => [
    i.getAttribute('src'), box(i).width / i.naturalWidth,
    Boolean(i.closest('a') && i.closest('a').href === i.src)]),
  titleLines: h1 ? box(h1).height / parseFloat(getComputedStyle(h1).lineHeight) : 0,
};
"""


def layout_problems(driver, url, width):
    driver.get(url)
    assert driver.execute_async_script(WAIT_FOR_LAYOUT) == "ok", url
    facts = driver.execute_script(LAYOUT_FACTS)
    problems = []
    if facts["page"] > 0:
        problems.append(f"the page scrolls sideways by {facts['page']} px: {facts['wider']}")
    problems += [f"wider than the column: {w}" for w in facts["wider"]]
    problems += [f"code scrolls sideways: {c!r}" for c in facts["code"]]
    for fits, scrolls, inside, text in facts["equations"]:
        if not inside:
            problems.append(f"equation cut off at the column's edge: {text!r}")
        elif not fits and (width >= 1000 or not scrolls):
            problems.append(f"equation scrolls at {width} px: {text!r}")
    for src, scale, linked in facts["images"]:
        if scale < 0.9 and not linked:
            problems.append(f"figure shown at {scale:.0%} with no link to its full size: {src}")
    if width < 600 and facts["titleLines"] > 4.2:
        problems.append(f"the title takes {facts['titleLines']:.0f} lines")
    return problems


@pytest.fixture
def at_width(browser):
    """The browser at a given width (set_window_size), put back at the session's size."""
    before = browser.get_window_size()

    def resize(width):
        browser.set_window_size(width, 1000)
        assert browser.execute_script("return window.innerWidth") == width
        return browser

    yield resize
    browser.set_window_size(before["width"], before["height"])


@pytest.mark.parametrize("device", list(WIDTHS))
def test_nothing_is_wider_than_the_column(book, at_width, device):
    """Every notebook page at a laptop's and a phone's width: the page never scrolls
    sideways, code and its output wrap, display equations fit the column (scaled down to
    70 % at the least; on a phone a longer one scrolls inside its own box), a figure shown
    smaller than drawn opens at its full size, and a phone shows the title in 4 lines."""
    width = WIDTHS[device]
    browser = at_width(width)
    report = []
    for notebook in NOTEBOOKS:
        report += [f"{notebook.name}: {p}" for p in
                   layout_problems(browser, page(book, notebook).as_uri(), width)]
    for path in [book / "book" / "intro.html", book / "book" / "api" / "index.html",
                 *(p for p in api_pages(book) if p.stem in ("svdt", "gait_events",
                                                           "plug_in_gait", "lowpass"))]:
        report += [f"{path.relative_to(book)}: {p}" for p in
                   layout_problems(browser, path.as_uri(), width)]
    assert report == []


def visible(browser, selector):
    from selenium.webdriver.common.by import By
    return [e for e in browser.find_elements(By.CSS_SELECTOR, selector) if e.is_displayed()]


def test_the_menus_open_the_chapter_list_and_the_contents_on_a_phone(book, at_width):
    """pydata-sphinx-theme 0.17 adds a hidden second pair of sidebar buttons and wires only
    the first of each (its issue #2451): the visible buttons did nothing. The book has one
    of each (book/_config.yml, navbar_persistent) and both open their list."""
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import WebDriverWait

    browser = at_width(WIDTHS["phone"])
    notebook = next(p for p in NOTEBOOKS if p.name.startswith("10_"))
    browser.get(page(book, notebook).as_uri())
    assert len(browser.find_elements(By.CSS_SELECTOR, ".primary-toggle")) == 1
    assert len(browser.find_elements(By.CSS_SELECTOR, ".secondary-toggle")) == 1
    chapters = browser.find_element(By.ID, "pst-primary-sidebar-modal")
    assert chapters.get_attribute("open") is None
    (button,) = visible(browser, ".primary-toggle")
    button.click()
    WebDriverWait(browser, 5).until(lambda d: chapters.get_attribute("open") is not None)
    listed = {a.get_attribute("href").split("#")[0].rsplit("/", 1)[-1]
              for a in chapters.find_elements(By.CSS_SELECTOR, "a.reference")
              if a.is_displayed()}
    assert {f"{p.stem}.html" for p in NOTEBOOKS} <= listed
    chapters.send_keys(Keys.ESCAPE)
    WebDriverWait(browser, 5).until(lambda d: chapters.get_attribute("open") is None)
    contents = browser.find_element(By.ID, "pst-secondary-sidebar-modal")
    (button,) = visible(browser, ".secondary-toggle")
    button.click()
    WebDriverWait(browser, 5).until(lambda d: contents.get_attribute("open") is not None)
    sections = [a for a in contents.find_elements(By.CSS_SELECTOR, "a.nav-link")
                if a.is_displayed()]
    assert len(sections) >= 10
    assert console_errors(browser) == []


def test_the_chapter_list_folds_away_on_a_laptop(book, at_width):
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    browser = at_width(WIDTHS["laptop"])
    browser.get(page(book, NOTEBOOKS[2]).as_uri())
    sidebar = browser.find_element(By.ID, "pst-primary-sidebar")
    assert sidebar.is_displayed()
    assert len(visible(browser, ".search-button-field")) == 1   # one search field
    assert visible(browser, "#pst-secondary-sidebar nav.page-toc a.nav-link")
    (button,) = visible(browser, ".primary-toggle")
    button.click()
    WebDriverWait(browser, 5).until(lambda d: not sidebar.is_displayed())
    button.click()
    WebDriverWait(browser, 5).until(lambda d: sidebar.is_displayed())
    assert console_errors(browser) == []


def test_search_results_typeset_their_maths_and_put_api_names_first(book, browser):
    from selenium.webdriver.support.ui import WebDriverWait

    browser.get((book / "search.html").as_uri() + "?q=reflection")
    WebDriverWait(browser, 30).until(lambda d: visible(d, "#search-results li"))
    WebDriverWait(browser, 30).until(
        lambda d: visible(d, "#search-results li a mjx-container"))
    text = browser.execute_script(
        "return document.getElementById('search-results').innerText")
    assert "\\(" not in text and "\\det" not in text
    browser.get((book / "search.html").as_uri() + "?q=knee")
    WebDriverWait(browser, 30).until(lambda d: visible(d, "#search-results li"))
    first = visible(browser, "#search-results li a")[0]
    assert first.get_attribute("href").endswith("knee_angles.html#bmc_functions.knee_angles")
    assert console_errors(browser) == []


# --------------------------------------------------------------------------- the extension


def test_the_book_extension_on_a_small_project(tmp_path):
    """book/_ext/bmc_book.py alone, on a two-page project built by Sphinx with -W."""
    src = tmp_path / "src"
    (src / "pages").mkdir(parents=True)
    (src / "data").mkdir()
    (src / "data" / "README.md").write_text("# Not a page\n")
    (src / "index.md").write_text("# Home\n\n```{toctree}\npages/01_t\n```\n")
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3",
                                 "language": "python"}
    nb.metadata["language_info"] = {"name": "python"}
    for k, source in enumerate([
            "# T\n\n[first](#1.-Why-(this)-works) [data](../data/README.md) "
            "[home](../index.md)",
            "## 1. Why (this) works\n\nMaths $x^2$ and $\\boldsymbol{v}$.",
            "## 2. Solutions\n\nTry first.",
            "**Solution 1.**\nIt does.",
            ("code", "print(1)"),
            "**Solution 2.** Also.",
            "## 3. References"]):
        cell = (nbformat.v4.new_code_cell(source[1], execution_count=1, outputs=[
            nbformat.v4.new_output("stream", text="1\n")]) if isinstance(source, tuple)
            else nbformat.v4.new_markdown_cell(source))
        cell.id = f"c{k}"
        nb.cells.append(cell)
    (src / "pages" / "01_t.ipynb").write_text(nbformat.writes(nb))
    (src / "conf.py").write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(ROOT / 'book' / '_ext')!r})\n"
        "extensions = ['myst_nb', 'bmc_book']\n"
        "include_patterns = ['index.md', 'pages/*.ipynb']\n"
        "nb_execution_mode = 'off'\n"
        "myst_enable_extensions = ['dollarmath']\n")
    out = tmp_path / "out"
    result = subprocess.run([sys.executable, "-m", "sphinx", "-W", "-q", "-b", "html",
                             str(src), str(out)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    html = soup(out / "pages" / "01_t.html")
    assert html.find(id="1.-Why-(this)-works") is not None  # JupyterLab's id
    hrefs = [a["href"] for a in html.find_all("a", href=True)]
    assert "#1.-Why-(this)-works" in hrefs
    assert any("_downloads" in h and h.endswith("README.md") for h in hrefs)  # not a page
    blocks = html.select("details.bmc-solution")
    assert [b.summary.get_text(" ", strip=True) for b in blocks] == [
        "Solution 1 (click to open)", "Solution 2 (click to open)"]
    assert blocks[0].select_one("div.cell") is not None  # the code went in with its text
    assert html.find(string=re.compile("Try first")).find_parent("details") is None
    assert (out / "_static" / "mathjax" / "tex-svg.js").is_file()
    assert (out / "_static" / "mathjax" / "input" / "tex" / "extensions" /
            "boldsymbol.js").is_file()


# --------------------------------------------------------------------------- the API reference

def public_api():
    """Every documented public name: (page stem, name) for the package and its plotting and
    examples modules (tools/api_reference.py decides the pages; this is the list to cover)."""
    import inspect

    import bmc_functions
    from bmc_functions import examples, plotting

    names = [(name, name) for name in bmc_functions.__all__]
    for module in (plotting, examples):
        short = module.__name__.rsplit(".", 1)[-1]
        names += [(f"{short}.{name}", name) for name, obj in vars(module).items()
                  if not name.startswith("_") and (inspect.isfunction(obj) or
                                                   inspect.isclass(obj))
                  and obj.__module__ == module.__name__ and name not in bmc_functions.__all__]
    return names


def api_pages(book):
    return sorted((book / "book" / "api").glob("*/*.html"))


def test_every_public_name_has_an_api_page_and_an_index_entry(book):
    pages_by_stem = {path.stem: path for path in api_pages(book)}
    expected = public_api()
    assert sorted(pages_by_stem) == sorted(stem for stem, _ in expected)
    index = soup(book / "genindex.html").get_text(" ")
    for stem, name in expected:
        html = soup(pages_by_stem[stem])
        assert html.select_one("dl.py dt.sig") is not None, f"{stem}: no autodoc signature"
        assert html.find("h1").get_text().strip().rstrip("#").strip() == name
        assert f"{name}()" in index or f"{name} (class" in index, f"{name}: not in the index"
    # the reference's front page links to every group, each group to each of its names
    front = soup(book / "book" / "api" / "index.html")
    groups = {a["href"].split("#")[0] for a in front.select("article a[href]")
              if a["href"].split("#")[0].endswith(".html") and "/" not in a["href"]}
    assert len(groups) >= 10
    linked = set()
    for group in groups:
        group_page = book / "book" / "api" / group
        assert group_page.is_file(), group
        linked |= {(group_page.parent / a["href"].split("#")[0]).resolve()
                   for a in soup(group_page).select("article a[href]")
                   if a["href"].split("#")[0].endswith(".html") and "/" in a["href"]}
    assert {path.resolve() for path in pages_by_stem.values()} <= linked


def test_the_api_reference_is_in_the_navigation_after_the_notebooks(book):
    last = soup(page(book, NOTEBOOKS[-1])).select_one("a.right-next")
    assert (page(book, NOTEBOOKS[-1]).parent / last["href"]).resolve() == \
        (book / "book" / "api" / "index.html").resolve()


def test_every_api_page_in_a_browser(book, browser):
    # counted: one page per public name, one per group and the reference's front page;
    # every one typesets its mathematics and every link on it resolves
    from selenium.webdriver.common.by import By

    pages_ = api_pages(book)
    groups = sorted((book / "book" / "api").glob("*.html"))
    assert len(pages_) == len(public_api()) and len(groups) >= 10
    report, seen = [], set()
    for path in pages_ + groups:
        mathjax = bool(soup(path).select('script[src*="mathjax"]'))
        assert mathjax, f"{path.name}: no MathJax (the sidebar has notebook titles with maths)"
        facts, problems = check_page(browser, path.as_uri(), mathjax=mathjax)
        problems += reader_text_problems(facts, path.stem, seen)
        for link in browser.find_elements(By.CSS_SELECTOR, "article a[href]"):
            href = link.get_attribute("href")
            parts = urlsplit(href)
            if parts.scheme != "file":
                continue
            target = unquote(parts.path)
            if not os.path.exists(target):
                problems.append(f"broken link {href}")
            elif parts.fragment and target.endswith(".html"):
                if unquote(parts.fragment) not in ids_of(type(book)(target)):
                    problems.append(f"no id for {href}")
        report += [f"{path.relative_to(book)}: {p}" for p in problems]
    stems = {path.stem for path in pages_ + groups}
    report += [f"{stem}: no {kind} any more: strike it off TEXT_PENDING"
               for stem, kind in sorted(TEXT_PENDING - seen) if stem in stems]
    assert report == []
    print(f"\nAPI reference: {len(pages_)} name pages and {len(groups) - 1} group pages")


def book_extension():
    spec = importlib.util.spec_from_file_location("bmc_book", ROOT / "book" / "_ext" /
                                                  "bmc_book.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


HEADINGS = ["h1", "h2", "h3", "h4", "h5", "h6"]


@pytest.mark.parametrize("prefix, name", [("02", "svdt"), ("10", "gait_events"),
                                          ("13", "plug_in_gait")])
def test_a_notebook_links_the_first_literal_of_a_name_to_its_api_page(book, prefix, name):
    named = book_extension().NAMED_LITERAL
    notebook = next(p for p in NOTEBOOKS if p.name.startswith(prefix + "_"))
    path = page(book, notebook)
    article = soup(path).select_one("article")
    literals = []
    for code in article.select("code.literal"):
        match = named.match(code.get_text())
        if (match and match.group(1).removeprefix("bmc_functions.") == name
                and not code.find_parent(HEADINGS)):
            literals.append(code)
    assert len(literals) >= 2, f"{notebook.name}: fewer than two literals naming {name}"
    first = literals[0].find_parent("a")
    assert first is not None, f"{notebook.name}: the first `{name}` is not a link"
    target = (path.parent / first["href"].split("#")[0]).resolve()
    assert target.name == f"{name}.html" and target.parent.parent == book / "book" / "api"
    assert target.is_file()
    assert soup(target).find("h1").get_text().strip().rstrip("#").strip() == name
    assert first.get_text() == literals[0].get_text()  # the literal kept, in its <code>
    assert [code for code in literals[1:] if code.find_parent("a")] == []
    # the code cells are left as they are: highlighted code, no link; the name is used there
    cells = article.select("div.cell")
    assert any(f"{name}(" in cell.get_text() for cell in cells)
    assert [cell for cell in cells if cell.select("a[href*='api/']")] == []


def test_each_notebook_links_an_api_page_at_most_once(book):
    for notebook in NOTEBOOKS:
        article = soup(page(book, notebook)).select_one("article")
        hrefs = [a["href"] for a in article.select("a[href*='api/']")]
        assert len(hrefs) == len(set(hrefs)), notebook.name
        assert article.select(", ".join(f"{h} a[href*='api/']" for h in HEADINGS)) == []
