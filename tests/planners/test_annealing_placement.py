"""The readings of Alg. 4, line 7 (``AnnealingSchedule.placement``): where each puts a database's
candidates relative to their parents."""

from __future__ import annotations

import math

import numpy as np
import pytest
from tolerances import z_bound

import qrrt_circuits as qc
from qrrt_circuits.planners.database import build_database
from qrrt_circuits.planners.placement import PLACEMENTS
from qrrt_circuits.planners.tree import Tree

BAND = (2.7, 4.2)
SIZE = 4096


def _tree(env, count=5, seed=3):
    points = env.sample_uniform(count, np.random.default_rng(seed))
    tree = Tree(points[0])
    for index, point in enumerate(points[1:]):
        tree.add(point, index)
    return tree


def _database(env, tree, placement, seed=1, size=SIZE):
    schedule = None if placement is None else qc.AnnealingSchedule(bands=(BAND,), placement=placement)
    return build_database(tree, size, env, np.random.default_rng(seed), annealing=schedule)


def _distances(tree, database):
    return np.linalg.norm(database.children - tree.nodes[database.parents], axis=1)


def test_default_placement_is_the_band():
    assert qc.AnnealingSchedule(bands=(BAND,)).placement == "band"
    assert qc.AnnealingSchedule(bands=(BAND,)).describe()["placement"] == "band"
    assert tuple(PLACEMENTS) == ("band", "clamp", "annulus", "admit")


def test_clamp_projects_each_sample_onto_the_band(clutter):
    """The same samples and parents as without annealing; each moved along parent -> sample to
    min(max(r, r_min), r_max)."""
    tree = _tree(clutter.env)
    raw, clamped = _database(clutter.env, tree, None), _database(clutter.env, tree, "clamp")
    assert np.array_equal(raw.parents, clamped.parents)
    r = _distances(tree, raw)
    assert np.allclose(_distances(tree, clamped), np.clip(r, *BAND))
    origin = tree.nodes[raw.parents]
    cosine = np.sum((raw.children - origin) * (clamped.children - origin), axis=1) / (
        r * _distances(tree, clamped))
    assert np.allclose(cosine, 1.0)


def test_annulus_distance_is_uniform_over_the_annulus_area(clutter):
    """r = sqrt(U(a^2, b^2)): mean 2/3 (b^3 - a^3) / (b^2 - a^2), E[r^2] = (a^2 + b^2) / 2."""
    tree = _tree(clutter.env)
    r = _distances(tree, _database(clutter.env, tree, "annulus"))
    a, b = BAND
    assert np.all((r >= a - 1e-9) & (r <= b + 1e-9))
    mean = 2 / 3 * (b**3 - a**3) / (b**2 - a**2)
    sd = math.sqrt((a**2 + b**2) / 2 - mean**2)
    assert abs(r.mean() - mean) <= z_bound() * sd / math.sqrt(SIZE)


def test_admit_keeps_samples_in_the_band_with_their_nearest_parent(clutter):
    tree = _tree(clutter.env)
    database = _database(clutter.env, tree, "admit", size=256)
    r = _distances(tree, database)
    assert database.children.shape == (256, 2) and np.all((r >= BAND[0]) & (r <= BAND[1]))
    brute = np.argmin(((database.children[:, None, :] - tree.nodes[None]) ** 2).sum(-1), axis=1)
    assert np.array_equal(database.parents, brute)


def test_admit_refuses_a_band_no_sample_reaches(clutter):
    tree = _tree(clutter.env)
    schedule = qc.AnnealingSchedule(bands=((100.0, 200.0),), placement="admit")
    with pytest.raises(RuntimeError, match="admitted to the band"):
        build_database(tree, 2, clutter.env, np.random.default_rng(0), annealing=schedule)


@pytest.mark.parametrize("placement", PLACEMENTS)
def test_every_placement_plans_edges_in_the_hot_band(placement, clutter):
    schedule = qc.AnnealingSchedule(bands=(BAND,), placement=placement)
    planner = qc.QRRT(backend=qc.StatevectorBackend(0), search_policy=qc.FixedIterations(2),
                      annealing=schedule, seed=0)
    result = planner.plan(clutter, max_nodes=6)
    distances = np.linalg.norm(result.nodes[1:] - result.nodes[result.parents[1:]], axis=1)
    assert result.metrics.nodes == 6 and np.all((distances >= BAND[0] - 1e-9) & (distances <= BAND[1] + 1e-9))
