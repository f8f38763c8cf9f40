"""Executors for sweeps and parallel planners: ``get_executor(kind, jobs, scheduler)`` gives a
``concurrent.futures.Executor`` for ``"serial"``, ``"process"`` or ``"dask"``, and ``WorkerPool``
keeps one for several sweeps (warm local workers forked from one preloaded server; a broken local
pool renewed). Their contract is documented in ``qrrt_circuits._support.execution``, which
implements them; this module is their public home.
"""

from qrrt_circuits._support.execution import EXECUTORS, WorkerPool, check_executor_args, get_executor

__all__ = ["EXECUTORS", "WorkerPool", "check_executor_args", "get_executor"]
