"""Imported by the fork server of a local Dask cluster (after ``distributed``): the workers it
forks leave out what Dask logs while an interrupted run shuts the cluster down
(``dask_noise.quiet_workers``). Only the fork server imports it; the command's own process and a
remote cluster keep their logging.
"""

from __future__ import annotations

from .dask_noise import quiet_workers

quiet_workers()
