"""Adapters that let planners use reachability checks from other libraries.

Each adapter lives in its own submodule and needs its own optional extra; importing the package
imports none of them. ``qrrt_circuits.adapters.ompl`` wraps an OMPL ``SpaceInformation``
(``pip install "qrrt-circuits[ompl]"``).
"""
