"""Imported by the fork server of a local Dask cluster (after ``distributed``): the workers it
forks leave out the warnings Dask's worker state machine logs for tasks cancelled while the
cluster shuts down ("Async instruction ... ended with CancelledError"), which an interrupted run
causes and which say nothing about its results. Only the fork server imports it; the command's
own process and a remote cluster keep their logging.
"""

from __future__ import annotations

import logging

#: the worker loggers whose warnings a shutdown causes
QUIET_LOGGERS = ("distributed.worker.state_machine",)

for _name in QUIET_LOGGERS:
    logging.getLogger(_name).setLevel(logging.ERROR)
