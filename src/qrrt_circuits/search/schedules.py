"""Alias of ``qrrt_circuits.search.policies`` (the iteration policies' former module name)."""

from .policies import *  # noqa: F403
from .policies import __all__  # noqa: F401
