"""Our exact check against the dense truth of the authors' 8 000 reference pairs
(tests/data/authors_check, copied from the shared reference data): it never accepts a pair whose
trajectory enters a box, and it rejects a free pair only within its documented false-rejection
bound ((1 + sqrt 2) x resolution from a box, 2 x resolution from the workspace edge)."""

import csv
from pathlib import Path

import numpy as np
import pytest

import qrrt_circuits as qc

DATA = Path(__file__).resolve().parents[1] / "data" / "authors_check"


def reference_world(world: int) -> qc.Environment:
    rows = np.loadtxt(DATA / f"boxes_world{world}.csv", delimiter=",", ndmin=2)  # xlo, xhi, ylo, yhi
    boxes = np.stack([rows[:, [0, 2]], rows[:, [1, 3]]], axis=1)
    return qc.Environment(np.array([[0.0, 20.0], [0.0, 20.0]]), boxes, name=f"reference_world{world}")


def reference_pairs(world: int) -> dict[str, np.ndarray]:
    with (DATA / "verdicts.csv").open() as handle:
        rows = [row for row in csv.DictReader(handle) if int(row["world"]) == world]
    columns = ("parent_x", "parent_y", "child_x", "child_y", "dense_depth", "dense_clearance",
               "dense_edge_clearance")
    out = {key: np.array([float(row[key]) for row in rows]) for key in columns}
    out["family"] = np.array([row["family"] for row in rows])
    return out


@pytest.mark.parametrize("world", [0, 1])
def test_exact_check_is_sound_and_within_its_false_rejection_bound(world):
    env = reference_world(world)
    pairs = reference_pairs(world)
    oracle = qc.ExactCheck(env)
    parents = np.stack([pairs["parent_x"], pairs["parent_y"]], axis=1)
    children = np.stack([pairs["child_x"], pairs["child_y"]], axis=1)
    accepted = oracle.reachable(parents, children)
    colliding = pairs["dense_depth"] > 0
    # sound: no accepted pair enters a box (dense truth, 200 000 time samples)
    assert not np.any(accepted & colliding), np.flatnonzero(accepted & colliding)
    # conservative only near obstacles or the edge: every free pair we reject passes close to one
    bound = oracle.false_rejection_bound
    rejected_free = ~accepted & ~colliding
    near_box = pairs["dense_clearance"] <= bound["obstacle"]
    near_edge = pairs["dense_edge_clearance"] <= bound["boundary"]
    assert np.all(near_box[rejected_free] | near_edge[rejected_free]), np.flatnonzero(
        rejected_free & ~near_box & ~near_edge)
    # and the bound is not vacuous: most free pairs are accepted
    assert accepted[~colliding].mean() > 0.9
