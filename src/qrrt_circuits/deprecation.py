"""Deprecated location of ``qrrt_circuits._support.deprecation`` (importing it warns)."""

from qrrt_circuits._support.deprecation import moved_module

moved_module(__name__, "qrrt_circuits._support.deprecation")
