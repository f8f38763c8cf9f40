"""Grover search on a noisy simulated device, for planning with noise (beyond the paper).

A ``NoisySamplerBackend`` is the ``SamplerBackend`` (one pass manager per backend object, each
transpiled circuit cached by its shape) around qiskit-aer's ``SamplerV2`` with a noise model:

- ``depolarizing_backend(p1, p2)``: basis [cx, rz, sx, x], all-to-all, depolarizing errors p1 on
  sx/x and p2 on cx (``qrrt_circuits.noise.depolarizing_noise_model``);
- ``fake_device_backend(name)``: a fake IBM device's coupling map, basis and calibrated errors
  (readout and relaxation included), from ``qiskit-ibm-runtime`` (optional extra ``noise``).

Each shot is an independent noisy run (method "statevector": one noise trajectory per shot; method
"density_matrix": shots sampled from the exact noisy distribution). Every result carries a label
naming the noise.
"""

from __future__ import annotations

import functools

import numpy as np

from ..noise import depolarizing_noise_model, fake_device
from ..validation import check_choice, check_probability
from .sampler import SamplerBackend

METHODS = ("statevector", "density_matrix")


class NoisySamplerBackend(SamplerBackend):
    """A ``SamplerBackend`` whose sampler simulates device noise; ``noise`` describes it."""

    name = "noisy-sampler"

    def __init__(self, sampler, noise: str, backend=None, seed=None, synthesis: str = "auto"):
        super().__init__(sampler, backend=backend, seed=seed, synthesis=synthesis)
        self.noise = noise

    def labels(self) -> tuple[str, ...]:
        return (*super().labels(), f"noise: {self.noise} (simulated device noise, not the paper's perfect machine)")

    def describe(self) -> str:
        return f"{self.name} ({self.noise})"


def depolarizing_backend(p1: float, p2: float, method: str = "statevector", seed=None,
                         synthesis: str = "auto") -> NoisySamplerBackend:
    """Aer's SamplerV2 with depolarizing errors p1 (sx, x) and p2 (cx) after transpiling to [cx, rz, sx, x]."""
    from qiskit_aer.primitives import SamplerV2

    p1 = check_probability(p1, "p1")
    p2 = check_probability(p2, "p2")
    method = check_choice(method, "method", METHODS)
    options = {"noise_model": depolarizing_noise_model(p1, p2), "method": method, "max_parallel_threads": 1}
    sampler = SamplerV2(options={"backend_options": options})
    return NoisySamplerBackend(sampler, f"depolarizing p1={p1:g} (sx, x), p2={p2:g} (cx)", seed=seed,
                               synthesis=synthesis)


@functools.lru_cache(maxsize=2)
def _device_sampler(name: str | None, method: str):
    """Aer's SamplerV2 with a fake device's noise model (building it takes seconds: cached)."""
    from qiskit_aer.primitives import SamplerV2

    device = fake_device(name)
    return device, SamplerV2.from_backend(device, options={"backend_options": {"method": method,
                                                                               "max_parallel_threads": 1}})


def fake_device_backend(name: str | None = None, method: str = "statevector", seed=None) -> NoisySamplerBackend:
    """The Grover circuit transpiled to a fake IBM device (its coupling map and basis) and run with
    its calibrated noise model. Raises ``MissingExtraError`` if qiskit-ibm-runtime is missing."""
    method = check_choice(method, "method", METHODS)
    device, sampler = _device_sampler(name, method)
    return NoisySamplerBackend(sampler, f"{device.name} calibration snapshot (qiskit-ibm-runtime fake "
                                        "provider)", backend=device, seed=seed)


def measured_indices_success(indices: np.ndarray, marks: np.ndarray) -> int:
    """How many measured indices are marked."""
    return int(np.count_nonzero(np.asarray(marks, dtype=bool)[np.asarray(indices, dtype=np.int64)]))


__all__ = ["NoisySamplerBackend", "depolarizing_backend", "fake_device_backend"]
