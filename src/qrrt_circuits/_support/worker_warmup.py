"""What a worker process needs before its first trial, loaded once by the fork server.

Pool and Dask workers are forked from one *fork server* (``multiprocessing``'s ``forkserver``
start method) that imports this module first: every experiment (and with them Qiskit, Aer, numba,
scipy), the default world ``paper_clutter`` (seed 0), whose construction loads the compiled
numba kernels of the collision checks from their on-disk cache and is then cached per process
(``experiments.worlds.world``), and its exact predicate, whose chord grid for the paper's dynamics
is then cached per process too (``oracle.chord_grid``); then the problems experiment's
``load_kernels`` loads the kernels of its families' plans (a kernel loads once per process and
argument types, in tens of milliseconds that a worker's first trial on a family would otherwise
count in its wall time). A worker forked from the
server starts with all of it in memory instead of importing and loading it again; the fork server
itself is a fresh, single-threaded interpreter (it never runs Aer, whose threads a fork would not
carry), so forking it is safe.

Importing this module performs the warm-up (that is how a fork server's ``preload`` works).
"""

from __future__ import annotations

from ..experiments import EXPERIMENTS  # noqa: F401  (every experiment, planner and backend)
from ..experiments.problems import load_kernels
from ..experiments.worlds import world

#: the world built (and so cached) in every warm worker
WARM_WORLD = ("paper_clutter", 0)


def warm_up() -> None:
    """Import everything a trial needs, build the default world (loading numba's kernels) and its
    exact predicate (caching the paper dynamics' chord grid), and load the kernels of the problem
    families' plans (``experiments.problems.load_kernels``).

    A warm-up that fails (numba's on-disk cache unreadable, say) is left to the trials: it raises
    nothing, so the fork server that runs it stays up and prints no traceback; each worker then
    loads what it needs itself and meets the same error in its first trial, which the worker's
    client reports.
    """
    try:
        import qiskit_aer  # noqa: F401  (the Aer backend's import, named: it is the heavy one)

        world(*WARM_WORLD)  # (its problem builds the exact check)
        load_kernels()
    except Exception:  # (see the docstring: the trials report it)
        pass


warm_up()
