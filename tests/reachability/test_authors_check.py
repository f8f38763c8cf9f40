"""The authors' ``dynamicscheck.m``, ported (``qc.AuthorsCheck``): with ``refine=1`` it reproduces
Octave 7.3's ode45 outputs and the Octave verdicts on the reference pairs (tests/data/authors_check,
copied from the shared reference data); ``refine=4`` follows MATLAB's ode45 (4 outputs a step, the
tail of the trajectory untested); it works in any dimension and refuses bad arguments by name."""

from __future__ import annotations

import csv
import gzip
import json
from pathlib import Path

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.reachability.predicate import check_predicate
from qrrt_circuits.registry import PREDICATES

DATA = Path(__file__).resolve().parents[1] / "data" / "authors_check"
BOUNDS = np.array([[0.0, 20.0], [0.0, 20.0]])
GROUPS = [(world, family) for world in (0, 1) for family in ("global", "local")]
RTOL = 1e-3  # ode45's default RelTol

# Octave's times are reproduced up to rounding, not bit for bit: the error estimate max|x5 - x4| /
# max(AbsTol, RelTol |x|) is a difference of nearly equal sums, and Octave's BLAS sums k * c' in
# its own order (and perhaps with FMA). Only error-limited steps carry that rounding forward (a step
# factor clamped at 0.8 / 1.5 or at MaxStep does not), i.e. steps with err in
# ((0.38^(1/6) / 1.5)^6, (0.38^(1/6) / 0.8)^6) = (0.033, 1.45): there |x5 - x4| >= 0.033 RelTol |x|,
# so a few ulps of |x| are a relative error of err of at most ~c eps / (0.033 RelTol) = c 6.7e-12, and
# dt ~ err^(-1/6) takes a sixth of it: c 1.1e-12 per step. dt_{k+1} = dt_k g(err_k) adds these up
# over <= 25 steps (c 3e-11) and the times, sums of steps over [0, 5], move by at most
# 5 * c 3e-11 ~ c 1.4e-10; with c (ulps lost in a 7-term sum) up to ~5:
TIME_TOL = 1e-9
# The states move with the times (|dx/dt| = |M e| <= 4 * 20 sqrt 2 ~ 113 here) plus the same rounding:
STATE_TOL = 113 * TIME_TOL
# A different number of outputs needs an accept/reject test (err <= 1) or the final clip
# dt = min(dt, T - t) to fall within that rounding of its threshold: ~25 decisions x ~1e-10 relative
# per pair, ~3e-6 for the 1 200 pairs tested. So every pair must give Octave's count: FRACTION = 1.
COUNT_FRACTION = 1.0
# The threshold for the verdicts (refine=1 against authors_octave on the 8 000 pairs).
AGREEMENT = 0.995


def boxes_of(world: int) -> np.ndarray:
    raw = np.loadtxt(DATA / f"boxes_world{world}.csv", delimiter=",", ndmin=2)  # xlo, xhi, ylo, yhi
    return np.stack([raw[:, [0, 2]], raw[:, [1, 3]]], axis=1)


@pytest.fixture(scope="module")
def envs():
    return {world: qc.Environment(BOUNDS, boxes_of(world)) for world in (0, 1)}


@pytest.fixture(scope="module")
def verdicts():
    with open(DATA / "verdicts.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    groups = {}
    for world, family in GROUPS:
        sub = [r for r in rows if int(r["world"]) == world and r["family"] == family]
        assert [int(r["pair"]) for r in sub] == list(range(len(sub)))
        groups[world, family] = {
            "parents": np.array([[float(r["parent_x"]), float(r["parent_y"])] for r in sub]),
            "children": np.array([[float(r["child_x"]), float(r["child_y"])] for r in sub]),
            "octave": np.array([r["authors_octave"] == "1" for r in sub]),
            "outputs": np.array([int(r["ode45_outputs"]) for r in sub]),
            "depth": np.array([float(r["dense_depth"]) for r in sub]),  # -1 when the trajectory is free
            "clearance": np.array([float(r["dense_clearance"]) for r in sub]),
        }
    assert sum(len(g["octave"]) for g in groups.values()) == 8000
    return groups


def octave_outputs(world: int, family: str) -> list[tuple[np.ndarray, np.ndarray]]:
    """Octave's (times, points) per pair, for the pairs in the subset file."""
    out = []
    with gzip.open(DATA / f"ode45_world{world}_{family}.txt.gz", "rt") as handle:
        for line in handle:
            values = np.array(line.split(","), dtype=float)
            n = int(values[0])
            out.append((values[1:1 + n], np.stack([values[1 + n:1 + 2 * n], values[1 + 2 * n:1 + 3 * n]], axis=1)))
    return out


# ----------------------------------------------------------------------------------- (a) ode45 outputs
@pytest.mark.parametrize(("world", "family"), GROUPS)
def test_refine_1_reproduces_octaves_ode45_outputs(world, family, envs, verdicts):
    check = qc.AuthorsCheck(envs[world], refine=1)
    group = verdicts[world, family]
    reference = octave_outputs(world, family)
    assert len(reference) == 300
    same_count = 0
    worst_time = worst_state = 0.0
    for i, (times_ref, points_ref) in enumerate(reference):
        assert len(times_ref) == group["outputs"][i]
        times, points = check.ode45_outputs(group["parents"][i], group["children"][i])
        if len(times) != len(times_ref):
            continue
        same_count += 1
        worst_time = max(worst_time, float(np.max(np.abs(times - times_ref))))
        worst_state = max(worst_state, float(np.max(np.abs(points - points_ref))))
        assert times[0] == 0.0 and times[-1] == 5.0
    print(f"world {world} {family}: {same_count}/{len(reference)} same number of outputs; largest time "
          f"difference {worst_time:.2e}, state difference {worst_state:.2e}")
    assert same_count >= COUNT_FRACTION * len(reference)
    assert worst_time <= TIME_TOL and worst_state <= STATE_TOL


def test_octave_and_matlab_start_and_step_by_their_own_documented_rules(envs, verdicts):
    """The first step of each, from the documented formulas (Octave's starting_stepsize.m and
    MATLAB's ode45.m), computed here independently; MATLAB's Refine points split each step evenly."""
    group = verdicts[0, "global"]
    parent, child = group["parents"][0], group["children"][0]
    closed = qc.LinearTrackingDynamics.paper().closed_loop
    e0 = parent - child
    f0 = closed @ e0

    def norm(x):
        return np.max(np.abs(x) / np.maximum(1e-6, RTOL * np.abs(x)))

    d0, d1 = norm(e0), norm(f0)
    h0 = 0.01 * d0 / d1
    d2 = norm(closed @ (e0 + h0 * f0) - f0) / h0
    octave_first = min(100 * h0, (0.01 / max(d1, d2)) ** (1 / 6), 0.5)
    times_ref, _ = octave_outputs(0, "global")[0]
    assert times_ref[1] == pytest.approx(octave_first, rel=1e-12)
    ours = qc.AuthorsCheck(envs[0], refine=1).ode45_outputs(parent, child)[0]
    assert ours[1] == pytest.approx(octave_first, rel=1e-12)

    rh = np.max(np.abs(f0) / np.maximum(np.abs(e0), 1e-6 / RTOL)) / (0.8 * RTOL ** 0.2)
    matlab_first = min(0.5, 1 / rh)
    times, _ = qc.AuthorsCheck(envs[0], refine=4).ode45_outputs(parent, child)
    assert times[4] == pytest.approx(matlab_first, rel=1e-14)
    assert abs(matlab_first - octave_first) > 0.01  # the two really differ (0.050 vs 0.068)
    steps = times[::4]
    assert steps[-1] == 5.0 and (len(times) - 1) % 4 == 0
    for r in range(1, 4):
        np.testing.assert_allclose(times[r::4], steps[:-1] + r / 4 * np.diff(steps), rtol=0, atol=1e-14)


@pytest.mark.parametrize("refine", [1, 2, 4, 7])
def test_outputs_follow_the_true_trajectory(refine, envs):
    """Every output (step ends and MATLAB's interpolated points alike) is within 2 RelTol |e0| of
    x(t) = c + expm(Mt) e0: the local error is held at RelTol |y| and the contracting closed loop
    keeps the global one at that order (measured: 3e-5 |e0| for Octave, 3e-4 |e0| for refine=4's
    order-4 interpolant); a wrong interpolation coefficient would be off by ~h |M e0| ~ 0.1 |e0|."""
    check = qc.AuthorsCheck(envs[0], refine=refine)
    dynamics = qc.LinearTrackingDynamics.paper()
    rng = np.random.default_rng(7)
    for _ in range(40):
        parent, child = rng.uniform(0, 20, 2), rng.uniform(0, 20, 2)
        times, points = check.ode45_outputs(parent, child)
        assert np.all(np.diff(times) > 0) and times[0] == 0 and times[-1] == 5.0
        assert (len(times) - 1) % refine == 0
        np.testing.assert_array_equal(points[0], (parent - child) + child)
        exact = dynamics.positions(parent, child, times)
        assert np.max(np.abs(points - exact)) <= 2 * RTOL * np.max(np.abs(parent - child))


# ----------------------------------------------------------------------------------- (b) verdicts
def test_refine_1_verdicts_agree_with_octave(envs, verdicts):
    agree_total = 0
    disagreements = []
    print()
    for world, family in GROUPS:
        group = verdicts[world, family]
        check = qc.AuthorsCheck(envs[world], refine=1)
        ours = check.reachable(group["parents"], group["children"])
        assert check.evaluations == len(ours)
        same = ours == group["octave"]
        agree_total += int(same.sum())
        truth = group["depth"] < 0
        print(f"world {world} {family:6s}: agreement {same.mean():.4f}, accepts ours {ours.mean():.4f} / Octave "
              f"{group['octave'].mean():.4f} / dense truth {truth.mean():.4f}; wrong against the truth: "
              f"ours {(ours != truth).sum()}, Octave {(group['octave'] != truth).sum()}")
        for i in np.flatnonzero(~same):
            disagreements.append({"world": world, "family": family, "pair": int(i), "ours": bool(ours[i]),
                                  "octave": bool(group["octave"][i]), "dense_depth": float(group["depth"][i]),
                                  "dense_clearance": float(group["clearance"][i])})
    for row in disagreements:
        print("disagreement:", json.dumps(row))
    agreement = agree_total / 8000
    print(f"overall agreement {agreement:.5f} ({8000 - agree_total} disagreements)")
    assert agreement >= AGREEMENT, disagreements
    # what may differ is a near-tie: a trajectory within a hair of a box edge either way
    for row in disagreements:
        assert (0 <= row["dense_depth"] < 0.01) or (row["dense_depth"] < 0 and row["dense_clearance"] < 0.01), row


# ----------------------------------------------------------------------------------- (c) refine = 4
def test_refine_4_gives_four_outputs_a_step_and_nearly_the_same_verdicts(envs, verdicts):
    print()
    for world, family in GROUPS:
        group = verdicts[world, family]
        octave, matlab = qc.AuthorsCheck(envs[world], refine=1), qc.AuthorsCheck(envs[world], refine=4)
        pairs = list(zip(group["parents"][:200], group["children"][:200], strict=True))
        n1 = np.mean([len(octave.ode45_outputs(p, c)[0]) for p, c in pairs])
        n4 = np.mean([len(matlab.ode45_outputs(p, c)[0]) for p, c in pairs])
        t25 = np.median([matlab.ode45_outputs(p, c)[0][24] for p, c in pairs])
        t50 = np.median([matlab.ode45_outputs(p, c)[0][49] for p, c in pairs])
        v1 = octave.reachable(group["parents"], group["children"])
        v4 = matlab.reachable(group["parents"], group["children"])
        truth = group["depth"] < 0
        print(f"world {world} {family:6s}: outputs {n1:.1f} (Octave) vs {n4:.1f} (refine 4), ratio {n4 / n1:.2f}; "
              f"refine 4 rasterizes to t = {t25:.2f}, points to t = {t50:.2f}; accepts refine 1 {v1.mean():.4f}, "
              f"refine 4 {v4.mean():.4f}, truth {truth.mean():.4f}; refine 4 wrong {(v4 != truth).sum()} "
              f"(accepts entering a box: {(v4 & ~truth).sum()})")
        for i in np.flatnonzero(v4 != v1):
            print(f"   refine 4 differs from Octave on pair {i}: refine 4 {v4[i]}, dense_depth {group['depth'][i]}, "
                  f"dense_clearance {group['clearance'][i]}")
        # MATLAB takes about as many steps as Octave (slightly fewer here), each giving 4 outputs
        assert 3.5 <= n4 / n1 <= 4.1
        assert np.mean(v4 == v1) >= AGREEMENT
        assert abs(v4.mean() - v1.mean()) <= 0.01


def test_refine_4_leaves_the_tail_untested():
    """A small box the trajectory enters at t ~ 3 (past output 50 under MATLAB's Refine = 4)."""
    env = qc.Environment(BOUNDS, np.array([[[14.995, 14.999], [14.997, 15.0]]]))
    parent, child = np.array([1.0, 1.0]), np.array([15.0, 15.0])
    matlab = qc.AuthorsCheck(env, refine=4)
    times, _ = matlab.ode45_outputs(parent, child)
    assert len(times) > 50 and times[49] < 2.5
    assert not qc.ExactCheck(env).reachable(parent, child)[0]
    assert not qc.AuthorsCheck(env, refine=1).reachable(parent, child)[0]
    assert matlab.reachable(parent, child)[0]


# ----------------------------------------------------------------------------------- any dimension
def reference_verdict(check, boxes, parent, child) -> bool:
    """dynamicscheck's test, written plainly over the solver's outputs and all boxes."""
    _, y = check.ode45_outputs(parent, child)
    n = len(y)
    fractions = (np.arange(1, check.rast_num + 1) / check.rast_num)[:, None]
    segments = [y[i] + fractions * (y[i - 1] - y[i]) for i in range(1, min(n, 25))]
    points = np.concatenate([y[:1], *segments, y[25:min(n, 50)]])
    inside = np.all((points[:, None, :] >= boxes[None, :, 0]) & (points[:, None, :] <= boxes[None, :, 1]), axis=2)
    return not inside.any()


@pytest.mark.parametrize("dim", [2, 3, 4])
@pytest.mark.parametrize(("refine", "rast_num"), [(1, 37), (4, 37), (3, 5)])
def test_any_dimension_matches_a_plain_reference(dim, refine, rast_num):
    rng = np.random.default_rng([dim, refine, rast_num])
    bounds = np.array([[0.0, 10.0]] * dim)
    lower = rng.uniform(0, 9.5, (40 * dim, dim))
    boxes = np.stack([lower, lower + rng.uniform(0.1, 1.5, lower.shape)], axis=1)
    env = qc.Environment(bounds, boxes)
    A = -np.eye(dim) + 0.3 * np.triu(rng.normal(size=(dim, dim)), 1)
    dynamics = qc.LinearTrackingDynamics(A, np.eye(dim), np.diag(rng.uniform(0.5, 3.0, dim)))
    check = qc.AuthorsCheck(env, dynamics, rast_num=rast_num, refine=refine)
    parents = rng.uniform(0, 10, (150, dim))
    children = rng.uniform(0, 10, (150, dim))
    ours = check.reachable(parents, children)
    expected = [reference_verdict(check, boxes, p, c) for p, c in zip(parents, children, strict=True)]
    np.testing.assert_array_equal(ours, expected)
    assert 0 < ours.sum() < len(ours)


# ----------------------------------------------------------------------------------- protocol
def test_protocol_description_and_registry(envs):
    env = envs[0]
    for name, refine, integrator in (("authors", 4, "matlab"), ("authors-octave", 1, "octave")):
        check = PREDICATES.create(name, env=env)
        assert isinstance(check, qc.AuthorsCheck) and check.refine == refine and check.name == name
        assert check_predicate(check, 2) is check
        description = json.loads(json.dumps(check.describe()))
        assert description == {"name": name, "rast_num": 37, "refine": refine, "rel_tol": 1e-3, "abs_tol": 1e-6,
                               "integrator": integrator, "sound": False,
                               "dynamics": qc.LinearTrackingDynamics.paper().describe()}
    check = qc.AuthorsCheck(env, refine=2)
    assert check.name == "authors" and check.describe()["refine"] == 2
    children = np.array([[10.0, 10.0], [19.0, 1.0], [3.0, 17.0]])
    batch = check.reachable(np.array([5.0, 5.0]), children)  # one parent broadcast over the children
    assert batch.shape == (3,) and check.evaluations == 3
    single = [check.reachable(np.array([5.0, 5.0]), c)[0] for c in children]
    np.testing.assert_array_equal(batch, single)


# ----------------------------------------------------------------------------------- (d) arguments
def test_bad_arguments_are_refused_by_name(envs):
    env = envs[0]
    with pytest.raises(ValueError, match="rast_num"):
        qc.AuthorsCheck(env, rast_num=0)
    with pytest.raises(ValueError, match="refine"):
        qc.AuthorsCheck(env, refine=0)
    with pytest.raises(TypeError, match="rast_num"):
        qc.AuthorsCheck(env, rast_num=2.5)
    with pytest.raises(TypeError, match="refine"):
        qc.AuthorsCheck(env, refine=4.0)
    with pytest.raises(TypeError, match="refine"):
        qc.AuthorsCheck(env, refine=True)
    three = qc.LinearTrackingDynamics(-np.eye(3), np.eye(3), np.eye(3))
    with pytest.raises(ValueError, match="dynamics dimension 3"):
        qc.AuthorsCheck(env, three)
    with pytest.raises(TypeError, match="dynamics"):
        qc.AuthorsCheck(env, dynamics="paper")
    with pytest.raises(TypeError, match="env"):
        qc.AuthorsCheck(np.zeros((2, 2)))
    check = qc.AuthorsCheck(env)
    with pytest.raises(ValueError, match="shape"):
        check.reachable(np.zeros((4, 3)), np.zeros((4, 3)))
    with pytest.raises(ValueError, match="finite"):
        check.reachable(np.array([np.nan, 1.0]), np.array([1.0, 1.0]))
    with pytest.raises(ValueError, match="one pair"):
        check.ode45_outputs(np.zeros((2, 2)), np.ones((2, 2)))
