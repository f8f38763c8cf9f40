import numpy as np
import pytest
from qiskit_aer.primitives import SamplerV2

import qrrt_circuits as qc


@pytest.fixture(scope="session")
def clutter():
    return qc.scenarios.paper_clutter(seed=0)


def make_backend(name: str, seed: int):
    if name == "aer":
        return qc.AerBackend(seed=seed)
    if name == "statevector":
        return qc.StatevectorBackend(seed=seed)
    if name == "statevector-iterated":
        return qc.StatevectorBackend(seed=seed, closed_form=False)
    if name == "sampler":
        return qc.SamplerBackend(SamplerV2(seed=seed))
    raise ValueError(name)


BACKENDS = ["aer", "statevector"]
ALL_BACKENDS = ["aer", "statevector", "statevector-iterated", "sampler"]


def random_marks(rng: np.random.Generator, num_qubits: int, num_marked: int) -> np.ndarray:
    marks = np.zeros(1 << num_qubits, dtype=bool)
    marks[rng.choice(1 << num_qubits, num_marked, replace=False)] = True
    return marks
