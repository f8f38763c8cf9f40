"""The coherent oracle's fixed-point semantics, database and motion: exact rounding, refusals of
bad input by name, and the integer reference against a slow restatement of its rules."""

from fractions import Fraction
from math import floor

import numpy as np
import pytest
from coherent_instances import random_instance, wall_instance

from qrrt_circuits import Environment, LinearTrackingDynamics, TimeSampledCheck
from qrrt_circuits.coherent import (
    FixedPointFormat,
    LatticeDatabase,
    SampledMotion,
    compare_with_time_sampled,
    reachable_reference,
)


def test_encode_floors_exactly_on_a_step_that_is_not_a_power_of_two():
    fmt = FixedPointFormat(3, 0.0, 10.0)  # step 1.25
    values = np.array([0.0, 1.25, 2.5, np.nextafter(2.5, 0.0), 9.99])
    assert fmt.encode(values).tolist() == [0, 1, 2, 1, 7]
    assert (fmt.ceil_index(3.75), fmt.floor_index(3.75)) == (3, 3)
    assert (fmt.ceil_index(3.76), fmt.floor_index(3.74)) == (4, 2)
    assert fmt.decode([2]).tolist() == [2.5]


def test_covering_puts_the_largest_coordinate_on_the_last_grid_point():
    env = Environment([[-1.0, 7.0], [0.5, 3.0]], [[[2.0, 1.0], [7.5, 2.0]]])  # TODO start/goal: start=[0.0, 1.0]
    fmt = FixedPointFormat.covering(env, 5)
    fmt.check_environment(env)
    assert fmt.lo == -1.0 and fmt.encode([7.5]).tolist() == [31]


@pytest.mark.parametrize("kwargs, match", [
    ({"bits": 0, "lo": 0.0, "hi": 1.0}, r"bits must be an integer in \[1, 24\]"),
    ({"bits": 25, "lo": 0.0, "hi": 1.0}, r"bits must be an integer in \[1, 24\]"),
    ({"bits": 4, "lo": 1.0, "hi": 1.0}, "hi must be > lo"),
    ({"bits": 4, "lo": 0.0, "hi": float("inf")}, "hi must be a finite number"),
])
def test_a_bad_format_is_refused_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        FixedPointFormat(**kwargs)


def test_coordinates_outside_the_format_are_refused_naming_the_argument_and_range():
    fmt = FixedPointFormat(4, 0.0, 16.0)
    with pytest.raises(ValueError, match=r"nodes\[1, 0\] = 16.0 is outside the fixed-point range \[0.0, 16.0\)"):
        LatticeDatabase(fmt, 2, np.array([[1.0, 1.0], [16.0, 2.0]]))
    env = Environment([[0, 15], [0, 15]], [[[1, 1], [2, 2]], [[3, 3], [17, 4]]])
    with pytest.raises(ValueError, match=r"env.boxes\[1\] has the coordinate 17.0, outside the fixed-point range"):
        fmt.check_environment(env)
    env = Environment([[-1, 15], [0, 15]], [])
    with pytest.raises(ValueError, match=r"env.bounds has the coordinate -1.0"):
        reachable_reference(env, LatticeDatabase(fmt, 2, np.array([[1.0, 1.0]])), SampledMotion.straight_line(2, 2, 0))


@pytest.mark.parametrize("kwargs, match", [
    ({"cell_bits": 5}, r"cell_bits must be an integer in \[1, 4\]"),
    ({"cell_bits": 2, "parent_bits": 0}, r"parent_bits must be an integer in \[1, 40\]"),
    ({"cell_bits": 2, "parent_bits": 41}, r"parent_bits must be an integer in \[1, 40\]"),
])
def test_a_bad_database_is_refused_by_name(kwargs, match):
    with pytest.raises(ValueError, match=match):
        LatticeDatabase(FixedPointFormat(4, 0.0, 16.0), nodes=np.array([[1.0, 1.0], [2.0, 2.0]]), **kwargs)


def test_a_bad_motion_is_refused_by_name():
    with pytest.raises(ValueError, match=r"time_samples must be an integer in \[2, 4096\]"):
        SampledMotion.straight_line(2, 1, 3)
    with pytest.raises(ValueError, match=r"fraction_bits must be an integer in \[0, 24\]"):
        SampledMotion.straight_line(2, 3, 25)
    with pytest.raises(ValueError, match=r"propagators must have shape \(K, d, d\)"):
        SampledMotion(np.zeros((3, 2, 3)), 2)
    env, database, _ = wall_instance()
    with pytest.raises(ValueError, match="motion has d = 3, the database d = 2"):
        reachable_reference(env, database, SampledMotion.straight_line(3, 3, 1))


def test_the_motion_samples_the_same_times_as_the_time_sampled_check():
    dynamics = LinearTrackingDynamics.paper()
    motion = SampledMotion.from_dynamics(dynamics, 7, 10)
    env = Environment([[0, 20], [0, 20]], [])
    check = TimeSampledCheck(env, dynamics, time_samples=7)
    assert np.allclose(motion.propagators, check._phis)
    assert np.array_equal(motion.coefficients, np.floor(check._phis * 1024 + 0.5))
    assert motion.tested[0].tolist() == [[1024, 0], [0, 1024]] and not motion.tested[-1].any()


def test_database_fields_round_trip():
    fmt = FixedPointFormat(5, 0.0, 16.0)
    database = LatticeDatabase(fmt, 3, np.array([[1.0, 2.0], [3.0, 4.0], [5.0, 6.0]]))
    assert (database.num_index_bits, database.parent_bits, database.cell_shift, database.cell_offset) == (8, 2, 2, 2)
    index = database.index_of([5, 2], 2)
    entry = database.entries(np.array([index]))
    assert entry.cells.tolist() == [[5, 2]] and entry.parent_index.tolist() == [2] and entry.valid.tolist() == [True]
    assert entry.sample_grid.tolist() == [[22, 10]] and entry.parent_grid.tolist() == [[10, 12]]
    missing = database.entries(np.array([database.index_of([0, 0], 3)]))
    assert missing.valid.tolist() == [False] and np.isnan(missing.parents).all()


def _slow_reference(env, database, motion) -> list[bool]:
    """The predicate restated entry by entry with Python integers and exact rationals."""
    fmt, f = database.fmt, motion.fraction_bits
    scale = Fraction(fmt.levels) / (Fraction(fmt.hi) - Fraction(fmt.lo))

    def grid(v):
        return (Fraction(float(v)) - Fraction(fmt.lo)) * scale

    marks = []
    a, d = database.cell_bits, database.dim
    for index in range(database.num_entries):
        parent = index >> (d * a)
        if parent >= database.num_nodes:
            marks.append(False)
            continue
        cells = [(index >> (j * a)) & ((1 << a) - 1) for j in range(d)]
        u_c = [(k << (fmt.bits - a)) + ((1 << (fmt.bits - a)) >> 1) for k in cells]
        u_p = [floor(grid(v)) for v in database.nodes[parent]]
        ok = True
        for e in motion.tested:
            x = [floor(Fraction(u_c[i] * 2**f + sum(int(e[i, j]) * (u_p[j] - u_c[j]) for j in range(d))
                                + (2**f >> 1), 2**f)) for i in range(d)]
            in_bounds = all(grid(low) <= x[i] <= grid(high) for i, (low, high) in enumerate(env.bounds))
            hit = any(all(grid(box[0, i]) <= x[i] <= grid(box[1, i]) for i in range(d)) for box in env.boxes)
            ok &= in_bounds and not hit
        marks.append(ok)
    return marks


@pytest.mark.parametrize("seed", range(6))
def test_the_reference_is_its_rules_restated(seed):
    env, database, motion = random_instance(seed, max_bits=4, max_cell_bits=2)
    assert reachable_reference(env, database, motion).tolist() == _slow_reference(env, database, motion)


def test_fine_fixed_point_mostly_agrees_with_the_floating_point_check():
    """Rounding changes few answers on a fine grid (14-bit coordinates and coefficients, 8 x 8
    cells, 4 nodes, 12 boxes): at most 5 % of the valid entries may differ (measured: none of 256
    here; with 6-bit coordinates 13 of 256)."""
    rng = np.random.default_rng(3)
    low = rng.uniform(0, 17, (12, 2))
    env = Environment([[0, 20], [0, 20]], np.stack([low, low + rng.uniform(0.5, 2.5, (12, 2))], axis=1))
    fmt = FixedPointFormat.covering(env, 14)
    database = LatticeDatabase(fmt, 3, env.sample_free(4, rng))
    motion = SampledMotion.from_dynamics(LinearTrackingDynamics.paper(), 20, 14)
    comparison = compare_with_time_sampled(env, database, motion)
    assert comparison.entries == 256 and 0 < comparison.reachable_float < 256
    assert comparison.fraction_differing <= 0.05
    with pytest.raises(ValueError, match="motion has no dynamics"):
        compare_with_time_sampled(env, database, SampledMotion.straight_line(2, 3, 1))
