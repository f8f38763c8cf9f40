"""Imported first by the fork server (``execution.WORKER_PRELOAD``): SIGINT ignored from here on.

A Ctrl-C from a terminal reaches the whole process group, the fork server and every worker
included. The fork server is started with SIGINT blocked (``execution._interrupts_blocked``), but a
library it preloads may unblock it; ignoring it here, before any of them is imported, keeps the
server quiet, and the workers it forks inherit the disposition (the server restores, in each
child, the dispositions it found after its preload). The command's own process is never affected:
this module is imported only by the fork server.
"""

from __future__ import annotations

import signal

signal.signal(signal.SIGINT, signal.SIG_IGN)
