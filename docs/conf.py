"""Sphinx configuration of the qrrt_circuits documentation site.

Build (from the repository root, after ``pip install ".[docs]"``)::

    python -m sphinx -W -b html docs docs/_build/html

Four things are generated at build time, so nothing here has to be edited when the code,
the tutorials or the results change (under ``docs/``; all but the results tables git-ignored):

* ``docs/api/_generated/reference.rst`` -- the API reference, written from
  ``qrrt_circuits.__all__`` (and each public submodule's own public names) by ``write_api_pages``;
  ``sphinx.ext.autosummary`` then writes one page per name from its docstring. A name added to
  ``__all__`` appears in the reference on the next build.
* ``docs/tutorials/_notebooks/*.ipynb`` -- copies of ``notebooks/*.ipynb`` (Sphinx reads only
  files under ``docs/``), executed by ``myst-nb`` at build time.
* ``docs/results/_gallery.md`` -- every figure under ``docs/results`` (referenced in place, not
  copied).
* ``docs/results/_generated/EXPERIMENT.md`` -- each results page's table of numbers, from the
  committed ``summary.json`` files (``results_tables.py``). These are committed too, so that a
  repository browser shows them (each page links its own); ``tests/project/test_results_pages.py``
  fails where they differ from what the summaries give (``python docs/results_tables.py``).
* ``docs/_generated/performance.md`` -- the Performance page, written by ``performance_page.py``
  from ``benchmarks/results/run.json`` and ``baseline.json``: every figure on it is read from them.
"""

from __future__ import annotations

import importlib.util
import inspect
import os
import re
import shutil
import sys
import types
from importlib import metadata
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT / "src"))  # a source checkout builds without an install too
sys.path.insert(0, str(DOCS))  # the page generators beside this file

from api_names import public_names as _public_names  # noqa: E402
from performance_page import write_performance_page  # noqa: E402
from results_tables import write_tables as write_results_tables  # noqa: E402

import qrrt_circuits  # noqa: E402

# -- project -------------------------------------------------------------------------------------
project = "qrrt_circuits"
author = "the qrrt_circuits authors"
copyright = "2026, the qrrt_circuits authors"  # noqa: A001
try:
    release = metadata.version("qrrt-circuits")
except metadata.PackageNotFoundError:  # building from a checkout that was never installed
    release = qrrt_circuits.__version__
version = release

# -- extensions ----------------------------------------------------------------------------------
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax copied into the built site: formulas render without a network
    "sphinx.ext.viewcode",
    "myst_nb",  # Markdown pages (MyST) and executed notebooks
    "qiskit_sphinx_theme",  # registers the "qiskit-ecosystem" HTML theme
]

templates_path = ["_templates"]
exclude_patterns = [
    "_build",
    "**/.ipynb_checkpoints",
    "results/_generated",  # included by the results pages
]
include_patterns = ["**"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}

# Docstrings: Google style (Qiskit's convention: ``Args:``, ``Returns:``, ``Raises:``), read by
# napoleon; most docstrings are prose with ``literal`` spans, which napoleon leaves as they are.
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_rtype = False
autosummary_generate = True
autosummary_imported_members = True
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_class_signature = "mixed"
add_module_names = False

# MyST and myst-nb: tutorials are executed at build time; jupyter-cache (kept in the build folder)
# skips a notebook whose code has not changed since the last build.
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
nb_execution_mode = "cache"
nb_execution_timeout = 120  # seconds per cell; each tutorial runs in well under 60 s in all
nb_execution_raise_on_error = True  # a failing tutorial fails the build
nb_execution_show_tb = True
nb_merge_streams = True
#: pages that need an optional extra to run: (docname, the module it needs); where the module is not
#: installed the page is shown without running, and says so at its top (``note_unrun_pages``)
NEEDS_EXTRA = {"howto/ompl": "ompl"}
UNRUN = {page for page, module in NEEDS_EXTRA.items() if importlib.util.find_spec(module) is None}
nb_execution_excludepatterns = [f"{page}.md" for page in UNRUN]

suppress_warnings = [
    "myst.header",  # README/DESIGN fragments start below level 1
]

# -- HTML ----------------------------------------------------------------------------------------
html_theme = "qiskit-ecosystem"
html_title = f"qrrt_circuits {release}"
html_static_path = ["_static"]
html_css_files = ["wide-figures.css"]  # pages with figures or wide tables use the whole width
html_last_updated_fmt = None


# -- generated pages -----------------------------------------------------------------------------
GENERATED_API = DOCS / "api" / "_generated"
NOTEBOOK_COPIES = DOCS / "tutorials" / "_notebooks"
GALLERY = DOCS / "results" / "_gallery.md"
PERFORMANCE = DOCS / "_generated" / "performance.md"

#: modules documented beyond ``qrrt_circuits.__all__`` (public, used in the README's examples)
EXTRA_MODULES = ("qrrt_circuits.plotting", "qrrt_circuits.execution")


def _write_if_changed(path: Path, text: str) -> None:
    """Rewrite a generated file only when its text changes (keeps incremental builds cheap)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def _summary_line(module: types.ModuleType) -> str:
    doc = inspect.getdoc(module) or module.__name__
    return doc.split("\n\n")[0].replace("\n", " ").strip()


def _autosummary(current: str, names: list[str]) -> list[str]:
    lines = [f".. currentmodule:: {current}", "", ".. autosummary::", "   :toctree: .", ""]
    lines += [f"   {name}" for name in names]
    return lines + [""]


def _heading(text: str, mark: str) -> list[str]:
    return [text, mark * len(text), ""]


def api_reference() -> str:
    """The reference page's body: top-level names grouped by defining module, then submodules."""
    package = qrrt_circuits
    groups: dict[str, list[str]] = {}
    submodules: list[types.ModuleType] = []
    for name in package.__all__:
        obj = getattr(package, name)
        if isinstance(obj, types.ModuleType):
            submodules.append(obj)
        else:
            groups.setdefault(obj.__module__, []).append(name)
    for extra in EXTRA_MODULES:
        submodules.append(sys.modules.get(extra) or __import__(extra, fromlist=["_"]))

    lines = _heading("The ``qrrt_circuits`` namespace", "-")
    lines += ["Every name of ``qrrt_circuits.__all__``, grouped by the module that defines it.", ""]
    for module_name in sorted(groups):
        module = sys.modules[module_name]
        lines += _heading(f"``{module_name}``", "~")
        lines += [_summary_line(module), ""]
        lines += _autosummary("qrrt_circuits", groups[module_name])

    top_level = {id(getattr(package, n)) for n in package.__all__}
    lines += _heading("Modules", "-")
    for module in submodules:
        lines += _heading(f"``{module.__name__}``", "~")
        lines += [f".. automodule:: {module.__name__}", "   :no-members:", ""]
        names = _public_names(module)
        own = [n for n in names if id(getattr(module, n)) not in top_level]
        also = [n for n in names if id(getattr(module, n)) in top_level]
        if own:
            lines += _autosummary(module.__name__, own)
        if also:
            refs = ", ".join(f":obj:`qrrt_circuits.{getattr(module, n).__name__}`" for n in also)
            lines += [f"Also here (documented above): {refs}.", ""]
    return "\n".join(lines)


def write_api_pages() -> None:
    """The reference page; autosummary's pages of the last build are removed first, so a name
    that left the API leaves no page behind (autosummary writes the current ones again)."""
    title = "qrrt_circuits"
    text = "\n".join(_heading(title, "=")) + "\n" + api_reference()
    for stale in GENERATED_API.glob("qrrt_circuits.*.rst"):
        stale.unlink()
    _write_if_changed(GENERATED_API / "reference.rst", text)


def copy_notebooks() -> None:
    """Copy ``notebooks/*.ipynb`` under ``docs/`` (only when changed); drop copies of deleted ones."""
    NOTEBOOK_COPIES.mkdir(parents=True, exist_ok=True)
    sources = {p.name: p for p in sorted((ROOT / "notebooks").glob("*.ipynb"))}
    for stale in NOTEBOOK_COPIES.glob("*.ipynb"):
        if stale.name not in sources:
            stale.unlink()
    for name, source in sources.items():
        target = NOTEBOOK_COPIES / name
        if not target.exists() or target.read_bytes() != source.read_bytes():
            shutil.copyfile(source, target)


def write_gallery() -> None:
    """A page showing every figure under ``docs/results`` where it lies (nothing copied)."""
    lines = ["# All result figures", "",
             "Every PNG under `docs/results/`, with the command that regenerates it. The numbers "
             "and their discussion are on the [results page](../results.md).", ""]
    for png in sorted((DOCS / "results").rglob("*.png")):
        rel = png.relative_to(DOCS / "results")
        if not (png.parent / "summary.json").exists():  # drawn from several folders' summaries
            text = ("the paper's numbers beside both checks: `qrrt compare-checks docs/results "
                    "docs/results/authors`")
        else:
            experiment = rel.parts[0] if len(rel.parts) == 2 else f"{rel.parts[1]} (authors' check)"
            name = rel.parts[-2]
            predicate = " --predicate authors" if rel.parts[0] == "authors" else ""
            text = (f"{experiment}: `qrrt reproduce {name}{predicate} --out docs/results"
                    f"{'/authors' if predicate else ''}`")
        lines += [f"## `{rel.as_posix()}`", "", text, "", f"![{rel.as_posix()}]({rel.as_posix()})", ""]
    _write_if_changed(GALLERY, "\n".join(lines))


def drop_builtin_docstrings(app, what, name, obj, options, lines) -> None:
    """Module constants (``registry.PLANNERS``, ``scenarios.SCENARIOS``) have no docstring of their
    own; autodoc would show their type's (``dict``'s), so show none instead."""
    if what in ("data", "attribute") and lines and type(obj).__module__ == "builtins":
        doc = inspect.getdoc(type(obj)) or ""
        if "\n".join(lines).strip() == doc.strip():
            lines.clear()


def check_notebook_kernel() -> None:
    """The tutorials must run in this interpreter (the one with qrrt_circuits installed). Kernel
    "python3" resolves to the environment's own kernelspec first (JUPYTER_PREFER_ENV_PATH), whose
    "python" jupyter_client replaces by ``sys.executable``; refuse a spec that names another one."""
    os.environ.setdefault("JUPYTER_PREFER_ENV_PATH", "1")
    from jupyter_client.kernelspec import KernelSpecManager

    spec = KernelSpecManager().get_kernel_spec("python3")
    program = spec.argv[0]
    if program not in ("python", "python3", f"python{sys.version_info[0]}.{sys.version_info[1]}") and \
            Path(program).resolve() != Path(sys.executable).resolve():
        raise RuntimeError(f"the 'python3' Jupyter kernel ({spec.resource_dir}) runs {program}, not this "
                           f"interpreter ({sys.executable}); the tutorials would run without qrrt_circuits")


def note_unrun_pages(app, docname: str, source: list[str]) -> None:
    """Under the title of a page of ``UNRUN``, a note that its code is shown without running."""
    if docname not in UNRUN:
        return
    lines = source[0].splitlines(keepends=True)
    title = next(index for index, line in enumerate(lines) if line.startswith("# "))
    note = (f"\n:::{{note}}\nThe `{NEEDS_EXTRA[docname]}` extra is not installed where this site was built, so the "
            "code on this page is shown without its output.\n:::\n")
    source[0] = "".join([*lines[:title + 1], note, *lines[title + 1:]])


#: a results page's link to its committed table, for a repository browser; the site shows the table
#: itself (``{include}``), so the build drops the link
BROWSER_LINK = re.compile(r" \(\[as a file\]\(_generated/[\w-]+\.md\), for a repository browser\)")


def drop_browser_links(app, docname: str, source: list[str]) -> None:
    """Drop the results pages' links to their committed tables (``BROWSER_LINK``)."""
    if docname.startswith("results/"):
        source[0] = BROWSER_LINK.sub("", source[0])


def setup(app) -> None:
    app.connect("autodoc-process-docstring", drop_builtin_docstrings)
    app.connect("source-read", note_unrun_pages)
    app.connect("source-read", drop_browser_links)


check_notebook_kernel()
write_api_pages()
copy_notebooks()
write_gallery()
write_results_tables(DOCS / "results", DOCS / "results" / "_generated")
write_performance_page(ROOT, PERFORMANCE)
