"""Execute the tutorial notebooks in notebooks/ and check they run cleanly and draw figures.

Each notebook runs in a fresh kernel of the interpreter running the tests: the kernel spec
manager is given no kernel directories, so "python3" resolves to ipykernel's built-in spec
(``sys.executable -m ipykernel_launcher``) and never to a user- or system-level kernelspec that
may point at another Python. A cell appended to the in-memory copy checks that the kernel runs
in this environment (same ``sys.prefix``, e.g. the project's .venv).

The docs build (``python -m sphinx ... docs docs/_build/html``, myst-nb in cache mode) executes the
same tutorials and keeps each executed copy in ``docs/_build/.jupyter_cache``, keyed by a hash of
the notebook's code; jupyter-cache stores only executions that raised no error, and the build
refuses a kernel that is not its own interpreter. When that cache holds this exact code (CI builds
the docs just before the suite), the test checks the cached outputs instead of running the
notebook a second time; otherwise it executes the notebook itself.
"""

import difflib
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import nbclient
import nbformat
import pytest
from jupyter_client.kernelspec import KernelSpecManager
from jupyter_client.manager import AsyncKernelManager
from traitlets import default

NOTEBOOKS_DIR = Path(__file__).resolve().parents[2] / "notebooks"
DOCS_EXECUTION_CACHE = NOTEBOOKS_DIR.parent / "docs" / "_build" / ".jupyter_cache"
NOTEBOOKS = [
    "01_grover_search_on_aer.ipynb",
    "02_qrrt_planning.ipynb",
    "03_parallel_workers_and_lemmas.ipynb",
    "04_quantum_database_annealing.ipynb",
    "05_custom_predicate.ipynb",
    "06_would_it_pay_off.ipynb",
    "07_plan_your_ompl_problem.ipynb",
    "08_coherent_oracle.ipynb",
    "09_connect_and_star.ipynb",
]
INTERPRETER_MARK = "kernel interpreter: "


class ThisInterpreterKernelManager(AsyncKernelManager):
    """Resolves "python3" to ipykernel's built-in spec, i.e. ``sys.executable``: no kernel
    directories are searched. Passed as ``kernel_manager_class`` so that the NotebookClient owns
    the manager and shuts the kernel down after the run."""

    @default("kernel_spec_manager")
    def _kernel_spec_manager_default(self) -> KernelSpecManager:
        return KernelSpecManager(kernel_dirs=[])


def test_notebook_list_is_complete():
    assert sorted(p.name for p in NOTEBOOKS_DIR.glob("*.ipynb")) == sorted(NOTEBOOKS)


def _stream_text(cell) -> str:
    return "".join(out.get("text", "") for out in cell.get("outputs", []) if out.output_type == "stream")


def executed_by_docs_build(nb):
    """The docs build's executed copy of ``nb`` (same code), or None if it has none."""
    if not DOCS_EXECUTION_CACHE.is_dir():
        return None
    try:
        from jupyter_cache import get_cache
    except ImportError:  # the docs extra is not installed
        return None
    cache = get_cache(DOCS_EXECUTION_CACHE)
    try:
        record = cache.match_cache_notebook(nb)
    except KeyError:
        return None
    return cache.get_cache_bundle(record.pk).nb


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebook_executes(name):
    nb = nbformat.read(NOTEBOOKS_DIR / name, as_version=4)
    check_stored(name, nb)
    stored = nbformat.read(NOTEBOOKS_DIR / name, as_version=4)
    for cell in nb.cells:  # executed afresh below (or by the docs build), from the code alone
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
    cached = executed_by_docs_build(nb)
    if cached is not None:
        unexecuted = [c.source[:60] for c in cached.cells if c.cell_type == "code" and c.source.strip()
                      and not c.get("execution_count")]
        assert not unexecuted, f"the docs build's copy of {name} has unexecuted cells: {unexecuted}"
        check_outputs(name, cached)
        check_stored_outputs_match(name, stored, cached)
        return
    nb.cells.append(nbformat.v4.new_code_cell(f"import sys; print({INTERPRETER_MARK!r} + sys.prefix)"))

    client = nbclient.NotebookClient(
        nb,
        kernel_manager_class=ThisInterpreterKernelManager,
        timeout=120,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOKS_DIR)}},
    )
    client.execute()  # raises CellExecutionError on the first failing cell

    reported = _stream_text(nb.cells[-1]).strip()
    assert reported.startswith(INTERPRETER_MARK), reported
    assert Path(reported.removeprefix(INTERPRETER_MARK)) == Path(sys.prefix), "kernel runs another Python"
    nb.cells.pop()  # (the interpreter check, not part of the tutorial)
    check_outputs(name, nb)
    check_stored_outputs_match(name, stored, nb)


#: what may differ between two runs of the same code, replaced before stored and fresh outputs are
#: compared: durations and rates (a number with a unit of time), object addresses, and which
#: counter gave the fault-tolerant counts (Qualtran where the ``ft`` extra is installed, else the
#: library's formulas: the counts agree, ``tests/hardware/test_resources.py``)
VOLATILE = [
    (re.compile(r"\d[\d,.]*(?:e[-+]?\d+)?\s*(?:ms|µs|us|ns|s|sec|seconds?|minutes?|min|h)\b"), "<time>"),
    (re.compile(r"(?:ms|s|seconds?) (?:per|a) (?:node|call|oracle call|round|plan)[^\n]*"), "<time per>"),
    (re.compile(r"0x[0-9a-f]+"), "<address>"),
    (re.compile(r"\((?:qualtran [\w.]+|formula)\)"), "(<fault-tolerant counter>)"),
    (re.compile(r"[^\n]*\d+it/s[^\n]*|[^\n]*\|[#█▏▎▍▌▋▊▉ ]*\|[^\n]*"), "<progress>"),
]


def _texts(nb) -> list[str]:
    """The text each code cell printed or returned (streams and text/plain), volatile parts masked."""
    texts = []
    for cell in nb.cells:
        if cell.cell_type != "code":
            continue
        parts = [out.get("text", "") if out.output_type == "stream" else out.get("data", {}).get("text/plain", "")
                 for out in cell.get("outputs", []) if out.output_type in ("stream", "execute_result")]
        text = "".join(parts)
        for pattern, mask in VOLATILE:
            text = pattern.sub(mask, text)
        texts.append(text)
    return texts


#: notebooks whose outputs depend on an optional extra (stored with it installed): compared only
#: where it is installed
NEEDS_EXTRA = {"07_plan_your_ompl_problem.ipynb": "ompl"}


def check_stored_outputs_match(name, stored, fresh):
    """The outputs the repository stores are those a fresh run prints, up to ``VOLATILE`` parts:
    a stored tutorial whose code or library has changed since it was executed fails here."""
    import importlib.util

    if name in NEEDS_EXTRA and importlib.util.find_spec(NEEDS_EXTRA[name]) is None:
        return  # (its stored outputs are those with the extra; this run has none)
    for index, (kept, made) in enumerate(zip(_texts(stored), _texts(fresh), strict=True)):
        if kept != made:
            diff = "\n".join(difflib.unified_diff(kept.splitlines(), made.splitlines(), "stored", "fresh", lineterm="",
                                                  n=1))
            pytest.fail(f"{name}: code cell {index + 1}'s stored output differs from a fresh run (run python "
                        f"docs/execute_notebooks.py {name}):\n{diff[:3000]}")


def check_stored(name, nb):
    """The repository stores each notebook executed (``python docs/execute_notebooks.py``): every
    code cell run once, in order, with no error and at least one figure."""
    counts = [cell.get("execution_count") for cell in nb.cells if cell.cell_type == "code" and cell.source.strip()]
    assert counts == list(range(1, len(counts) + 1)), (
        f"{name} is not stored executed in order (execution counts {counts}): "
        f"run python docs/execute_notebooks.py {name}")
    check_outputs(name, nb)


def check_outputs(name, nb):
    """No error output, and at least one figure."""
    errors = [out for cell in nb.cells for out in cell.get("outputs", []) if out.output_type == "error"]
    assert not errors, errors
    images = [
        out
        for cell in nb.cells
        if cell.cell_type == "code"
        for out in cell.get("outputs", [])
        if "image/png" in out.get("data", {})
    ]
    assert images, f"{name} produced no image/png output"


def _results_script() -> str:
    """Notebook 06's imports and its section 3 (which reads the committed results), as a script."""
    nb = nbformat.read(NOTEBOOKS_DIR / "06_would_it_pay_off.ipynb", as_version=4)
    start = next(i for i, cell in enumerate(nb.cells) if cell.cell_type == "markdown" and "## 3." in cell.source)
    end = next(i for i, cell in enumerate(nb.cells) if i > start and cell.cell_type == "markdown")
    imports = next(cell for cell in nb.cells if cell.cell_type == "code")
    cells = [imports, *(cell for cell in nb.cells[start:end] if cell.cell_type == "code")]
    return "\n".join(line for cell in cells for line in cell.source.splitlines() if not line.startswith("%"))


def _run_results_script(cwd, package_parent):
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(package_parent))
    return subprocess.run([sys.executable, "-c", _results_script()], capture_output=True, text=True, cwd=cwd,
                          env=env, timeout=300)


RESULTS_READ = ["break-even p2, ", "break-even: one call must cost at most", "with the wall-clock experiment's"]
RESULTS_USED = ["noise", "resources", "wallclock", "oracle-efficiency"]


def test_notebook_06_finds_the_results_from_outside_the_repository(tmp_path):
    """Run elsewhere (a copy of the notebook, say), it finds the repository's docs/results from the
    checkout the package is imported from."""
    import qrrt_circuits

    package_parent = Path(qrrt_circuits.__file__).resolve().parent.parent
    if not (package_parent.parent / "docs" / "results").is_dir():
        pytest.skip("the package is not imported from a checkout of the repository")
    run = _run_results_script(tmp_path, package_parent)
    assert run.returncode == 0, run.stderr
    assert all(text in run.stdout for text in RESULTS_READ), run.stdout


def test_notebook_06_without_the_results_says_how_to_make_them_and_reads_results_here(tmp_path):
    """Outside any checkout it prints, for each summary it lacks, one line naming the command that
    makes it, and runs on; with those commands' output in ./results it reads that."""
    import qrrt_circuits

    package = tmp_path / "site" / "qrrt_circuits"
    shutil.copytree(Path(qrrt_circuits.__file__).resolve().parent, package,
                    ignore=shutil.ignore_patterns("__pycache__"))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    run = _run_results_script(elsewhere, package.parent)
    assert run.returncode == 0, run.stderr
    for experiment in RESULTS_USED[:2]:  # (the other two are read only with the resources)
        assert f"`qrrt reproduce {experiment}` writes one to results/{experiment}; skipped" in run.stdout
    assert not any(text in run.stdout for text in RESULTS_READ), run.stdout
    for experiment in RESULTS_USED:
        shutil.copytree(NOTEBOOKS_DIR.parent / "docs" / "results" / experiment, elsewhere / "results" / experiment)
    run = _run_results_script(elsewhere, package.parent)
    assert run.returncode == 0, run.stderr
    assert all(text in run.stdout for text in RESULTS_READ) and "skipped" not in run.stdout, run.stdout


def test_a_stale_stored_output_is_caught_and_timings_are_not():
    """The comparison fails on a changed count and passes on changed timings and addresses."""
    def notebook(text):
        cell = nbformat.v4.new_code_cell("print(...)")
        cell.outputs = [nbformat.v4.new_output("stream", name="stdout", text=text)]
        return nbformat.v4.new_notebook(cells=[cell])

    stored = notebook("196 oracle calls in 1.52 s at 0x7f00aa (qualtran 0.7.0)\n")
    check_stored_outputs_match("x", stored, notebook("196 oracle calls in 0.9 s at 0x7f11bb (formula)\n"))
    with pytest.raises(pytest.fail.Exception, match="196 oracle calls"):
        check_stored_outputs_match("x", stored, notebook("60 oracle calls in 1.52 s at 0x7f00aa (formula)\n"))
