"""Grover search on a noisy simulated device, for planning with noise (beyond the paper).

A ``NoisySamplerBackend`` is the ``SamplerBackend`` (one pass manager per backend object, each
transpiled circuit cached by its shape) around qiskit-aer's ``SamplerV2`` with a noise model:

- ``depolarizing_backend(p1, p2)``: basis [cx, rz, sx, x], all-to-all, depolarizing errors p1 on
  sx/x and p2 on cx (``qrrt_circuits.hardware.noise.depolarizing_noise_model``);
- ``fake_device_backend(name)``: a fake IBM device's coupling map, basis and calibrated errors
  (readout and relaxation included), from ``qiskit-ibm-runtime`` (optional extra ``noise``).

Each shot is an independent noisy run (method "statevector": one noise trajectory per shot; method
"density_matrix": shots sampled from the exact noisy distribution). Every result carries a label
naming the noise.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

import numpy as np

from ..._support.validation import check_choice, check_probability
from ...hardware.noise import depolarizing_noise_model, fake_device
from ..synthesis import OracleSynthesis
from .sampler import SamplerBackend

if TYPE_CHECKING:
    from qiskit.primitives import BaseSamplerV2
    from qiskit.providers import BackendV2

METHODS = ("statevector", "density_matrix")


class NoisySamplerBackend(SamplerBackend):
    """A ``SamplerBackend`` whose sampler simulates device noise (beyond the paper's ideal machine).

    Build one with ``depolarizing_backend`` or ``fake_device_backend``. Seeding and caching are
    the ``SamplerBackend``'s; every result additionally carries a ``noise: ...`` label.

    Args:
        sampler: A ``BaseSamplerV2`` with a noise model (qiskit-aer's ``SamplerV2``).
        noise: Human-readable description of the noise, copied into the labels.
        backend: A ``BackendV2`` to transpile to (a fake device), or None for [cx, rz, sx, x].
        seed: The backend's own stream (see ``SamplerBackend``).
        synthesis: The oracle's form: ``"auto"``, ``"diagonal"`` or ``"mcz"``.

    Attributes:
        noise: The noise description.

    Raises:
        ValueError: As ``SamplerBackend``.
    """

    name = "noisy-sampler"

    def __init__(self, sampler: BaseSamplerV2, noise: str, backend: BackendV2 | None = None,
                 seed: int | np.random.Generator | None = None, synthesis: str | OracleSynthesis = "auto") -> None:
        super().__init__(sampler, backend=backend, seed=seed, synthesis=synthesis)
        self.noise = noise

    def labels(self) -> tuple[str, ...]:
        """The ``SamplerBackend`` labels plus ``"noise: <noise> (simulated device noise, ...)"``."""
        return (*super().labels(), f"noise: {self.noise} (simulated device noise, not the paper's perfect machine)")

    def describe(self) -> str:
        """``"noisy-sampler (<noise>)"``."""
        return f"{self.name} ({self.noise})"


def depolarizing_backend(p1: float, p2: float, method: str = "statevector",
                         seed: int | np.random.Generator | None = None,
                         synthesis: str | OracleSynthesis = "auto") -> NoisySamplerBackend:
    """Aer's SamplerV2 with depolarizing errors p1 (sx, x) and p2 (cx) after transpiling to [cx, rz, sx, x].

    The noise model is ``qrrt_circuits.hardware.noise.depolarizing_noise_model(p1, p2)`` on an all-to-all
    device; Aer runs single-threaded.

    Args:
        p1: Depolarizing probability of each sx and x gate, in [0, 1].
        p2: Depolarizing probability of each cx gate, in [0, 1].
        method: ``"statevector"`` (one noise trajectory per shot) or ``"density_matrix"`` (shots
            from the exact noisy distribution).
        seed: The backend's own stream (see ``SamplerBackend``).
        synthesis: The oracle's form: ``"auto"``, ``"diagonal"`` or ``"mcz"``.

    Returns:
        A ``NoisySamplerBackend`` labelled with p1 and p2.

    Raises:
        TypeError: A non-numeric probability.
        ValueError: p1 or p2 outside [0, 1], or an unknown ``method``.

    Example:
        >>> from qrrt_circuits.search.backends.noisy import depolarizing_backend
        >>> backend = depolarizing_backend(0.001, 0.01, seed=0)
        >>> backend.describe()
        'noisy-sampler (depolarizing p1=0.001 (sx, x), p2=0.01 (cx))'
    """
    from qiskit_aer.primitives import SamplerV2

    p1 = check_probability(p1, "p1")
    p2 = check_probability(p2, "p2")
    method = check_choice(method, "method", METHODS)
    options = {"noise_model": depolarizing_noise_model(p1, p2), "method": method, "max_parallel_threads": 1}
    sampler = SamplerV2(options={"backend_options": options})
    return NoisySamplerBackend(sampler, f"depolarizing p1={p1:g} (sx, x), p2={p2:g} (cx)", seed=seed,
                               synthesis=synthesis)


@functools.lru_cache(maxsize=2)
def _device_sampler(name: str | None, method: str) -> tuple[BackendV2, BaseSamplerV2]:
    """Aer's SamplerV2 with a fake device's noise model (costly to build, so cached)."""
    from qiskit_aer.primitives import SamplerV2

    device = fake_device(name)
    return device, SamplerV2.from_backend(device, options={"backend_options": {"method": method,
                                                                               "max_parallel_threads": 1}})


def fake_device_backend(name: str | None = None, method: str = "statevector",
                        seed: int | np.random.Generator | None = None) -> NoisySamplerBackend:
    """The Grover circuit transpiled to a fake IBM device and run with its calibrated noise model.

    The device's coupling map, basis, readout and relaxation errors come from the fake provider of
    ``qiskit-ibm-runtime`` (optional extra ``noise``); the sampler is built once per (name,
    method) and cached.

    Args:
        name: One of ``qrrt_circuits.hardware.noise.FAKE_DEVICES``, or None for the first installed.
        method: ``"statevector"`` or ``"density_matrix"``.
        seed: The backend's own stream (see ``SamplerBackend``).

    Returns:
        A ``NoisySamplerBackend`` that transpiles to the device, labelled with its name.

    Raises:
        ValueError: An unknown ``method`` or device name.
        MissingExtraError: qiskit-ibm-runtime is not installed, or lacks the named device.
    """
    method = check_choice(method, "method", METHODS)
    device, sampler = _device_sampler(name, method)
    return NoisySamplerBackend(sampler, f"{device.name} calibration snapshot (qiskit-ibm-runtime fake "
                                        "provider)", backend=device, seed=seed)


def measured_indices_success(indices: np.ndarray, marks: np.ndarray) -> int:
    """How many measured indices are marked.

    Args:
        indices: Measured database indices (int array).
        marks: Boolean (or 0/1) marks of the database.

    Returns:
        The count of ``indices`` whose entry is marked.
    """
    return int(np.count_nonzero(np.asarray(marks, dtype=bool)[np.asarray(indices, dtype=np.int64)]))


__all__ = ["NoisySamplerBackend", "depolarizing_backend", "fake_device_backend"]
