"""The notebooks' kernel metadata is what JupyterLab 4 writes when it opens them with
ipykernel's kernel, so that opening a notebook does not mark it as modified (a reader who
closes it is not asked to save changes they never made). Checked by hand in JupyterLab
4.6 with a headless browser: a notebook with the old display name "Python 3" shows the
unsaved-changes dot as soon as its kernel is idle; with "Python 3 (ipykernel)" it does not.
The fix is tools/notebook_metadata.py (run it after adding a notebook)."""

import importlib.util
import json
import sys

from helpers import ROOT

spec = importlib.util.spec_from_file_location("notebook_metadata",
                                              ROOT / "tools" / "notebook_metadata.py")
notebook_metadata = importlib.util.module_from_spec(spec)
sys.modules["notebook_metadata"] = notebook_metadata
spec.loader.exec_module(notebook_metadata)

NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))


def test_the_kernelspec_is_ipykernels():
    from jupyter_client.kernelspec import KernelSpecManager

    spec = KernelSpecManager().get_kernel_spec("python3")
    assert notebook_metadata.KERNELSPEC == {"display_name": spec.display_name,
                                            "language": spec.language, "name": "python3"}


def test_every_notebook_has_it():
    differ = [path.name for path in NOTEBOOKS
              if json.loads(path.read_text(encoding="utf-8"))["metadata"].get("kernelspec")
              != notebook_metadata.KERNELSPEC]
    assert differ == [], "run: python tools/notebook_metadata.py"


def test_the_tool_changes_the_kernelspec_and_nothing_else():
    nb = {"cells": [{"cell_type": "markdown", "id": "a", "metadata": {}, "source": ["x"]}],
          "metadata": {"kernelspec": {"display_name": "Python 3", "language": "python",
                                      "name": "python3"},
                       "language_info": {"name": "python", "version": "3.11.7"}},
          "nbformat": 4, "nbformat_minor": 5}
    text = json.dumps(nb, indent=1) + "\n"
    fixed = notebook_metadata.fixed_text(text)
    changed = [(a, b) for a, b in zip(text.splitlines(), fixed.splitlines()) if a != b]
    assert changed == [('   "display_name": "Python 3",',
                        '   "display_name": "Python 3 (ipykernel)",')]
    assert notebook_metadata.fixed_text(fixed) == fixed
