"""Project-wide pytest set-up, found from the repository root wherever pytest is started.

- Points nbval at notebooks/sanitize.cfg by absolute path, so that the notebooks'
  regression tests work from any folder.
- Builds matplotlib's font cache in this process before any notebook kernel starts: on a
  fresh machine the first import would otherwise print "Matplotlib is building the font
  cache" into the first notebook's outputs, and nbval would report a difference.
"""

import os
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent

# Kernels started by nbval inherit these; they keep warnings about the debugger and
# about the Jupyter paths out of the outputs that nbval compares.
os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")
os.environ.setdefault("JUPYTER_PLATFORM_DIRS", "1")


def pytest_configure(config):
    # read by nbval when it sets up each notebook, after every plugin is configured
    if getattr(config.option, "nbval_sanitize_with", "absent") is None:
        config.option.nbval_sanitize_with = str(ROOT / "notebooks" / "sanitize.cfg")
    import matplotlib.font_manager  # noqa: F401  (builds the font cache once, here)
