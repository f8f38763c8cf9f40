"""Planning on the lattice database (``LatticeCandidates``), searched by lookup or by the coherent
circuit on Aer's matrix-product-state method: every plan reaches its goal within an oracle-call
budget and every edge is re-checked by the planner's own predicate."""

from __future__ import annotations

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.coherent import FixedPointFormat

BOXES = np.array([[[0.0, 0.0], [20.0, 7.0]], [[0.0, 13.0], [20.0, 20.0]], [[9.0, 9.0], [11.0, 11.0]]])
CORRIDOR = qc.Problem.build(qc.Environment(np.array([[0.0, 20.0], [0.0, 20.0]]), BOXES), [2.0, 10.0], [18.0, 10.0],
                            2.5)


def _on_lattice(points: np.ndarray, bits: int, cell_bits: int) -> bool:
    """Whether every point is a cell centre of the 2^a-per-axis lattice on the b-bit grid."""
    fmt = FixedPointFormat.covering(CORRIDOR.env, bits)
    grid = (points - fmt.lo) / fmt.step
    shift = 1 << (bits - cell_bits)
    return bool(np.allclose(grid, np.round(grid)) and np.all(np.round(grid) % shift == shift // 2))


@pytest.mark.parametrize("coherent", [False, True])
def test_lattice_plans_reach_the_goal_with_checked_edges(coherent):
    reached = 0
    for seed in range(4):
        backend = qc.AerBackend(seed=0, method="matrix_product_state") if coherent else qc.StatevectorBackend(seed=0)
        planner = qc.QRRT(backend=backend, num_qubits=7, seed=seed,
                          database=qc.LatticeCandidates(3, bits=6, coherent=coherent))
        result = planner.plan(CORRIDOR, max_oracle_calls=400)
        reached += result.reached
        assert CORRIDOR.predicate.reachable(result.nodes[result.parents[1:]], result.nodes[1:]).all()
        assert _on_lattice(result.nodes[1:], 6, 3)  # every node but the root is a cell centre
        assert result.settings["database"] == {"kind": "lattice", "cell_bits": 3, "bits": 6, "coherent": coherent,
                                               "time_samples": 4, "fraction_bits": 6}
        assert any("coherent oracle" in label for label in result.labels) == coherent
    assert reached == 4


@pytest.mark.parametrize(("options", "message"), [
    ({"num_qubits": 6}, "num_qubits must exceed d \\* cell_bits = 6"),
    ({"oracle_errors": "errors"}, "oracle_errors cannot corrupt a coherent oracle"),
    ({"annealing": qc.AnnealingSchedule.paper()}, "give annealing or database, not both"),
])
def test_bad_lattice_planners_are_refused_before_planning(options, message):
    if options.get("oracle_errors") == "errors":
        options = {"oracle_errors": qc.OracleErrorModel(false_positive=0.1)}
    with pytest.raises(ValueError, match=message):  # (the settings a world cannot serve: when planned)
        qc.QRRT(backend=qc.StatevectorBackend(seed=0), **({"num_qubits": 7} | options),
                database=qc.LatticeCandidates(3, bits=6, coherent=True)).plan(CORRIDOR, max_rounds=1)


@pytest.mark.parametrize(("arguments", "message"), [({"cell_bits": 0}, "cell_bits"), ({"cell_bits": 7}, "cell_bits"),
                                                    ({"cell_bits": 3, "bits": 30}, "bits"),
                                                    ({"cell_bits": 3, "time_samples": 1}, "time_samples")])
def test_bad_lattice_arguments_name_the_argument(arguments, message):
    with pytest.raises(ValueError, match=message):
        qc.LatticeCandidates(**({"bits": 6} | arguments))
