"""Execute ``notebooks/*.ipynb`` in place, so the repository stores each tutorial with its outputs
(a repository browser then shows its figures): ``python docs/execute_notebooks.py [NAME ...]``.

Run it after editing a notebook; ``tests/project/test_notebooks.py`` fails on a stored notebook with a code
cell that was not executed in order, an error output, or no figure. The docs build executes the
notebooks again, so the site always shows the outputs of the current code.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"


def execute(path: Path) -> None:
    """Run every cell of ``path`` in a fresh kernel (working folder: ``notebooks/``) and store the
    outputs, without timing metadata, in a stable JSON layout."""
    import nbclient
    import nbformat

    notebook = nbformat.read(path, as_version=4)
    nbclient.NotebookClient(notebook, timeout=600, record_timing=False,
                            resources={"metadata": {"path": str(NOTEBOOKS)}}).execute()
    path.write_text(json.dumps(notebook, indent=1, ensure_ascii=True, sort_keys=True) + "\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", help="notebook file names (default: every notebook)")
    args = parser.parse_args(argv)
    paths = [NOTEBOOKS / name for name in args.names] or sorted(NOTEBOOKS.glob("*.ipynb"))
    for path in paths:
        execute(path)
        print(f"executed {path.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
