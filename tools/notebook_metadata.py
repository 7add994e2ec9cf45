"""Give every notebook the kernel metadata JupyterLab 4 writes, so opening one does not
mark it as modified.

    python tools/notebook_metadata.py            # rewrite notebooks/*.ipynb where needed
    python tools/notebook_metadata.py --check    # exit 1 and list the notebooks that differ

When JupyterLab opens a notebook and starts its kernel, it writes the kernel's spec into
``metadata.kernelspec`` (ipykernel's display name is "Python 3 (ipykernel)") and the
kernel's ``language_info``; any difference from the stored metadata marks the notebook as
modified before the reader has touched it. Only ``metadata.kernelspec`` is rewritten here,
and only its text: cells, outputs and every other byte of the file stay as they are
(``language_info.version`` follows the Python that last ran the notebook, as it must).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: what ipykernel's kernel spec says (jupyter kernelspec list; share/jupyter/kernels/python3)
KERNELSPEC = {"display_name": "Python 3 (ipykernel)", "language": "python", "name": "python3"}


def fixed_text(text: str) -> str:
    """The notebook's text with the kernelspec replaced; nothing else changes."""
    nb = json.loads(text)
    old = nb.get("metadata", {}).get("kernelspec")
    if old == KERNELSPEC:
        return text
    indent = " "
    old_block = json.dumps({"kernelspec": old}, indent=1, ensure_ascii=False)[2:-2]
    new_block = json.dumps({"kernelspec": KERNELSPEC}, indent=1, ensure_ascii=False)[2:-2]
    # the block as nbformat writes it (indent 1), one level deeper inside "metadata"
    old_block = "\n".join(indent + line for line in old_block.splitlines())
    new_block = "\n".join(indent + line for line in new_block.splitlines())
    if old is None or text.count(old_block) != 1:
        nb["metadata"]["kernelspec"] = KERNELSPEC     # unusual layout: rewrite the JSON
        return json.dumps(nb, indent=1, ensure_ascii=False) + "\n"
    new = text.replace(old_block, new_block)
    if json.loads(new)["metadata"]["kernelspec"] != KERNELSPEC:
        raise RuntimeError("the kernelspec was not replaced")
    return new


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="only report")
    parser.add_argument("notebooks", nargs="*", type=Path,
                        default=sorted((ROOT / "notebooks").glob("*.ipynb")))
    args = parser.parse_args(argv)
    differ = []
    for path in args.notebooks:
        text = path.read_text(encoding="utf-8")
        new = fixed_text(text)
        if new != text:
            differ.append(path)
            if not args.check:
                path.write_text(new, encoding="utf-8")
    for path in differ:
        print(f"{'differs' if args.check else 'fixed'}: {path}")
    return 1 if (args.check and differ) else 0


if __name__ == "__main__":
    sys.exit(main())
