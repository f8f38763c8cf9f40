"""What every planner that runs quantum searches shares: its backend, its qubits and its search
policy, with their defaults (a new ``AerBackend()``, the planner's ``default_search_policy()``)."""

from __future__ import annotations

from typing import Any

from ..search.backends.base import QuantumSearchBackend
from ..search.policies.base import IterationPolicy
from .base import Planner


class SearchingPlanner(Planner):
    """A planner with ``QuantumOptions``' ``backend``, ``num_qubits`` and ``search_policy``
    (``PQRRT``, ``QRRT``, q-RRT-Connect, q-RRT*); each subclass names its ``default_search_policy``."""

    @staticmethod
    def default_search_policy() -> IterationPolicy:
        """The policy used where none is given (each planner names its own)."""
        raise NotImplementedError

    def _complete(self, options: Any) -> Any:
        """The options with a new ``AerBackend()`` and ``default_search_policy()`` where none is given."""
        changes: dict[str, Any] = {}
        if options.backend is None:
            from ..search.backends.aer import AerBackend  # qiskit and Aer are imported only when used

            changes["backend"] = AerBackend()
        if options.search_policy is None:
            changes["search_policy"] = self.default_search_policy()
        return options.replace(**changes) if changes else options

    @property
    def backend(self) -> QuantumSearchBackend:
        """The search backend."""
        backend: QuantumSearchBackend = self.options.backend
        return backend

    @property
    def num_qubits(self) -> int:
        """n, the qubits of each database."""
        return int(self.options.num_qubits)

    @property
    def search_policy(self) -> IterationPolicy:
        """The search policy (the planner's default where none was given)."""
        policy: IterationPolicy = self.options.search_policy
        return policy
