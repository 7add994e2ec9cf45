"""Build the book: a static HTML site made from notebooks/ with their stored outputs.

    python tools/build_book.py                 # -> _build/html/index.html
    python tools/build_book.py --output DIR    # -> DIR/html/index.html

Jupyter Book 1 (Sphinx + MyST-NB) with the configuration in book/; the notebooks are not
executed (their stored outputs are the ones nbval tests), every warning is an error (a
broken link, a formula MathJax cannot read, a notebook missing from the table of
contents), and nothing is fetched from the network: MathJax is copied into the book from
an installed package (book/_ext/bmc_book.py). The result opens from the file system
(file://.../index.html) and from any static web server.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BOOK = ROOT / "book"


def build(output: Path | None = None, *, fresh: bool = True, quiet: bool = False) -> Path:
    """Build the book into ``output`` (default: ``_build`` in the repository root).

    Returns the folder of the HTML site (``output/html``). Raises
    ``subprocess.CalledProcessError`` when the build fails or warns.
    """
    output = ROOT if output is None else Path(output).resolve()
    build_dir = output / "_build" if output == ROOT else output
    if fresh and build_dir.exists():
        shutil.rmtree(build_dir)
    command = [
        sys.executable, "-c", "from jupyter_book.cli.main import main; main()",
        "build", str(ROOT),
        "--config", str(BOOK / "_config.yml"),
        "--toc", str(BOOK / "_toc.yml"),
        "--warningiserror", "--keep-going",
    ]
    if output != ROOT:
        # Jupyter Book writes to <path-output>/_build/html: build in a staging folder
        staging = output / "_staging"
        command += ["--path-output", str(staging)]
    kwargs = {"capture_output": True, "text": True} if quiet else {}
    result = subprocess.run(command, cwd=ROOT, **kwargs)
    if result.returncode != 0:
        raise subprocess.CalledProcessError(
            result.returncode, command,
            output=getattr(result, "stdout", None), stderr=getattr(result, "stderr", None))
    if output == ROOT:
        html = ROOT / "_build" / "html"
    else:
        html = output / "html"
        if html.exists():
            shutil.rmtree(html)
        shutil.move(str(staging / "_build" / "html"), str(html))
        shutil.rmtree(staging)
    # GitHub Pages runs Jekyll unless told not to, and Jekyll drops _static and _images
    (html / ".nojekyll").touch()
    return html


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, default=None,
                        help="folder to build into (default: _build in the repository)")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    try:
        html = build(args.output)
    except subprocess.CalledProcessError as error:
        print(f"The book did not build (exit code {error.returncode}); see the messages above.",
              file=sys.stderr)
        return 1
    size = sum(p.stat().st_size for p in html.rglob("*") if p.is_file())
    print(f"\nBuilt in {time.perf_counter() - start:.0f} s: {html} ({size / 1e6:.1f} MB)")
    print(f"Open {(html / 'index.html').as_uri()} in a browser, or publish the folder "
          "on any static web host.")
    return 0


if __name__ == "__main__":
    sys.exit(main())
