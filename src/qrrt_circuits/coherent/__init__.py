"""The reachability check as a reversible circuit: a coherent phase oracle for Grover search over
a structured (lattice) database, with its fixed-point semantics, classical reference, exhaustive
verification and costs (``docs/explanations/coherent_oracle.md``).

Entry points: ``coherent_phase_oracle(env, database, motion)`` (the circuit) and
``reachable_reference(env, database, motion)`` (its 2^n marks), with ``FixedPointFormat``,
``LatticeDatabase`` and ``SampledMotion`` describing the arithmetic, the index and the motion.
"""

from .costs import LookupCost, OracleCost, lookup_costs, oracle_costs
from .grover import coherent_grover_circuit, coherent_search_oracle
from .lattice import DatabaseEntries, LatticeDatabase
from .motion import SampledMotion
from .number_format import FixedPointFormat
from .oracle import CoherentOracle, build_coherent_oracle, coherent_phase_oracle
from .plan import OracleOptions, OraclePlan, oracle_plan
from .reference import RoundingComparison, compare_with_time_sampled, reachable_reference
from .simulate import PermutationResult, simulate
from .verify import VerificationResult, verify_oracle
from .walk import Layout

__all__ = [
    "CoherentOracle",
    "DatabaseEntries",
    "FixedPointFormat",
    "LatticeDatabase",
    "Layout",
    "LookupCost",
    "OracleCost",
    "OracleOptions",
    "OraclePlan",
    "PermutationResult",
    "RoundingComparison",
    "SampledMotion",
    "VerificationResult",
    "build_coherent_oracle",
    "coherent_grover_circuit",
    "coherent_phase_oracle",
    "coherent_search_oracle",
    "compare_with_time_sampled",
    "lookup_costs",
    "oracle_costs",
    "oracle_plan",
    "reachable_reference",
    "simulate",
    "verify_oracle",
]
