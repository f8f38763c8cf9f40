import os
import tempfile

import numpy as np
import psutil
import pytest
from qiskit_aer.primitives import SamplerV2

import qrrt_circuits as qc


@pytest.fixture(scope="session")
def clutter():
    """The paper's clutter problem (world seed 0)."""
    return qc.paper_clutter(seed=0)


@pytest.fixture(scope="session")
def clutter_world(clutter):
    """Its world: the 20 x 20 environment with 525 boxes."""
    return clutter.env


def make_backend(name: str, seed: int):
    if name == "aer":
        return qc.AerBackend(seed=seed)
    if name == "aer-mps":
        return qc.AerBackend(seed=seed, method="matrix_product_state")
    if name == "statevector":
        return qc.StatevectorBackend(seed=seed)
    if name == "statevector-iterated":
        return qc.StatevectorBackend(seed=seed, closed_form=False)
    if name == "sampler":
        return qc.SamplerBackend(SamplerV2(), seed=seed)  # seeded per call through seed_simulator
    raise ValueError(name)


BACKENDS = ["aer", "statevector"]
ALL_BACKENDS = ["aer", "aer-mps", "statevector", "statevector-iterated", "sampler"]


def random_marks(rng: np.random.Generator, num_qubits: int, num_marked: int) -> np.ndarray:
    marks = np.zeros(1 << num_qubits, dtype=bool)
    marks[rng.choice(1 << num_qubits, num_marked, replace=False)] = True
    return marks


@pytest.fixture(scope="session", autouse=True)
def private_temp(tmp_path_factory):
    """Every temporary file of this test session (and of the processes it starts) goes to a folder
    of its own, so the checks below see only what this session created, whatever other runs on the
    machine leave in the shared temporary folder."""
    folder = str(tmp_path_factory.mktemp("tmp"))
    saved_env, saved = os.environ.get("TMPDIR"), tempfile.tempdir
    os.environ["TMPDIR"], tempfile.tempdir = folder, folder
    yield folder
    tempfile.tempdir = saved
    if saved_env is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = saved_env


@pytest.fixture(scope="session", autouse=True)
def no_leftovers(private_temp):
    """After the whole run: no child processes and no Dask scratch files left behind."""
    prefixes = ("dask-scratch", "qrrt-dask-")
    scratch = {name for name in os.listdir(tempfile.gettempdir()) if name.startswith(prefixes)}
    yield
    children = []
    for process in psutil.Process().children(recursive=True):
        try:
            if not any("resource_tracker" in part for part in process.cmdline()):  # stdlib, exits with us
                children.append(process)
        except psutil.NoSuchProcess:
            pass
    gone, alive = psutil.wait_procs(children, timeout=30)
    assert not alive, f"processes left running: {[p.pid for p in alive]}"
    left = {name for name in os.listdir(tempfile.gettempdir()) if name.startswith(prefixes)}
    assert left <= scratch, f"Dask scratch files left in {tempfile.gettempdir()}: {left - scratch}"
