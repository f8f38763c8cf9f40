"""Deprecated alias of ``qrrt_circuits.search.policies``."""

from .._support.deprecation import warn_deprecated
from .policies import *  # noqa: F403
from .policies import __all__  # noqa: F401

warn_deprecated("qrrt_circuits.search.schedules", "qrrt_circuits.search.policies")
