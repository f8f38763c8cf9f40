"""Deprecated location of ``qrrt_circuits.reachability.predicate`` (importing it warns)."""

from qrrt_circuits._support.deprecation import moved_module

moved_module(__name__, "qrrt_circuits.reachability.predicate")
