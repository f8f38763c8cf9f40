"""Occupancy-image worlds (``qc.OccupancyGrid``, ``qc.GridCheck``, ``qc.image_world``).

The grid check is compared with two references that share none of its code:

- ``exact_touched``: the cells whose closed square meets the segment, decided cell by cell with
  exact rational arithmetic (Liang-Barsky clipping in ``fractions.Fraction``) on the same float
  cell coordinates u = (x - ox) / s, v = (y - oy) / s the check computes;
- ``sampled_free``: the segment sampled at N + 1 evenly spaced points, each point's cells (both
  cells where it lies on an edge) looked up. Sampling can only miss a cell: an occupied cell the
  segment crosses for a parameter length under 1 / N (a corner clipped) has no sample in it. So
  the check may reject where sampling accepts only there (asserted from the exact clip lengths),
  and must never accept where sampling rejects.
"""

from __future__ import annotations

import math
import pickle
import zlib
from fractions import Fraction

import matplotlib
import numpy as np
import pytest
from planner_checks import posed

import qrrt_circuits as qc
from qrrt_circuits.plotting import plan_dynamics
from qrrt_circuits.reachability.grid_check import EPSILON
from qrrt_circuits.world.image import MAX_CELLS
from qrrt_circuits.world.maze import maze_free

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


# ----------------------------------------------------------------------------- references
def cell_coordinates(grid: qc.OccupancyGrid, point: np.ndarray) -> tuple[float, float]:
    """The check's float cell coordinates of a world point (the same operations)."""
    return (float((point[0] - grid.origin[0]) / grid.pixel_size), float((point[1] - grid.origin[1]) / grid.pixel_size))


def clip(u0, v0, u1, v1, i: int, j: int) -> tuple[Fraction, Fraction] | None:
    """The exact parameter interval [t0, t1] of the segment inside the closed cell [i, i+1] x [j, j+1]
    (Liang-Barsky in rationals), or None where they do not meet."""
    low, high = Fraction(0), Fraction(1)
    for start, end, lo in ((u0, u1, i), (v0, v1, j)):
        s, d = Fraction(start), Fraction(end) - Fraction(start)
        if d == 0:
            if not lo <= s <= lo + 1:
                return None
            continue
        a, b = (lo - s) / d, (lo + 1 - s) / d
        low, high = max(low, min(a, b)), min(high, max(a, b))
        if low > high:
            return None
    return low, high


def exact_touched(u0: float, v0: float, u1: float, v1: float, rows: int, cols: int) -> dict:
    """{(j, i): (t0, t1)} for every cell (j from the bottom, i from the left) whose closed square
    meets the segment; a float prefilter skips cells whose centre is farther than 0.75 cells from
    the segment (a cell's points are within sqrt(2) / 2 of its centre)."""
    out = {}
    d = np.array([u1 - u0, v1 - v0])
    length2 = float(d @ d)
    for i in range(max(0, math.floor(min(u0, u1)) - 1), min(cols, math.floor(max(u0, u1)) + 2)):
        for j in range(max(0, math.floor(min(v0, v1)) - 1), min(rows, math.floor(max(v0, v1)) + 2)):
            centre = np.array([i + 0.5 - u0, j + 0.5 - v0])
            t = 0.0 if length2 == 0 else min(max(float(centre @ d) / length2, 0.0), 1.0)
            if np.linalg.norm(centre - t * d) > 0.75:
                continue
            interval = clip(u0, v0, u1, v1, i, j)
            if interval is not None:
                out[(j, i)] = interval
    return out


def in_bounds(grid: qc.OccupancyGrid, point: np.ndarray) -> bool:
    bounds = grid.bounds()
    return bool(np.all((point >= bounds[:, 0]) & (point <= bounds[:, 1])))


def occupied_bottom_up(grid: qc.OccupancyGrid) -> np.ndarray:
    return ~grid.free[::-1]


def exact_free(grid: qc.OccupancyGrid, parent: np.ndarray, child: np.ndarray) -> bool:
    """The exact verdict: both ends in bounds and no occupied cell touched."""
    if not (in_bounds(grid, parent) and in_bounds(grid, child)):
        return False
    occupied = occupied_bottom_up(grid)
    touched = exact_touched(*cell_coordinates(grid, parent), *cell_coordinates(grid, child), grid.rows, grid.cols)
    return not any(occupied[cell] for cell in touched)


def point_cells(u: float, v: float, rows: int, cols: int) -> list[tuple[int, int]]:
    """The cells whose closed square contains (u, v) (two on an edge, four at a corner)."""
    us = [math.floor(u)] + ([int(u) - 1] if u == int(u) else [])
    vs = [math.floor(v)] + ([int(v) - 1] if v == int(v) else [])
    return [(j, i) for i in us for j in vs if 0 <= i < cols and 0 <= j < rows]


def sampled_free(grid: qc.OccupancyGrid, parent: np.ndarray, child: np.ndarray, samples: int) -> bool:
    if not (in_bounds(grid, parent) and in_bounds(grid, child)):
        return False
    occupied = occupied_bottom_up(grid)
    (u0, v0), (u1, v1) = cell_coordinates(grid, parent), cell_coordinates(grid, child)
    for k in range(samples + 1):
        t = k / samples
        if any(occupied[cell] for cell in point_cells(u0 + t * (u1 - u0), v0 + t * (v1 - v0), grid.rows, grid.cols)):
            return False
    return True


def maze(cells: int, corridor: int, seed: int) -> np.ndarray:
    """A perfect maze as a bool image, True = free (``qrrt_circuits.world.maze``)."""
    return maze_free(cells, seed, corridor)


def write_pnm(path, magic: str, samples: np.ndarray, maxval: int = 255, comment: bool = False) -> None:
    """A PGM / PPM file written by hand: ``samples`` (H, W) or (H, W, 3) integers."""
    height, width = samples.shape[:2]
    header = f"{magic}\n" + ("# written by the test\n" if comment else "") + f"{width} {height}\n{maxval}\n"
    if magic in ("P5", "P6"):
        raster = samples.astype(">u2" if maxval > 255 else np.uint8).tobytes()
    else:
        raster = "\n".join(" ".join(str(int(x)) for x in row.reshape(-1)) for row in samples).encode() + b"\n"
    path.write_bytes(header.encode() + raster)


# ----------------------------------------------------------------------------- reading
@pytest.fixture(scope="module")
def picture() -> np.ndarray:
    """A 5 x 7 RGB picture of random 8-bit samples."""
    return np.random.default_rng(7).integers(0, 256, (5, 7, 3)).astype(np.uint8)


def expected_free(samples: np.ndarray, maxval: int, threshold: float = 0.5, negate: bool = False) -> np.ndarray:
    grey = samples.reshape(samples.shape[0], samples.shape[1], -1).sum(axis=2) / (
        samples.reshape(samples.shape[0], samples.shape[1], -1).shape[2] * maxval)
    return (1.0 - grey if negate else grey) >= threshold


def test_every_format_reads_the_same_free_cells(tmp_path, picture):
    grey = picture[:, :, 0]
    plt.imsave(tmp_path / "rgb.png", picture)
    rgba = np.concatenate([picture, np.full(picture.shape[:2] + (1,), 9, np.uint8)], axis=2)
    plt.imsave(tmp_path / "rgba.png", rgba)  # alpha ignored
    write_pnm(tmp_path / "binary.ppm", "P6", picture)
    write_pnm(tmp_path / "ascii.ppm", "P3", picture, comment=True)
    write_pnm(tmp_path / "binary.pgm", "P5", grey)
    write_pnm(tmp_path / "ascii.pgm", "P2", grey, comment=True)
    write_pnm(tmp_path / "deep.pgm", "P5", grey.astype(np.int64) * 257, maxval=65535)
    colour, grey_free = expected_free(picture, 255), expected_free(grey, 255)
    for name in ("rgb.png", "rgba.png", "binary.ppm", "ascii.ppm"):
        assert np.array_equal(qc.OccupancyGrid.from_image(tmp_path / name, 1.0).free, colour), name
    for name in ("binary.pgm", "ascii.pgm", "deep.pgm"):
        assert np.array_equal(qc.OccupancyGrid.from_image(tmp_path / name, 1.0).free, grey_free), name
    grid = qc.OccupancyGrid.from_image(tmp_path / "binary.ppm", 0.25, free_threshold=0.3, negate=True)
    assert np.array_equal(grid.free, expected_free(picture, 255, 0.3, negate=True))
    assert grid.metadata == {"path": str(tmp_path / "binary.ppm"), "format": "P6", "free_threshold": 0.3,
                             "negate": True}


def test_pillow_greyscale_pngs_8_and_16_bit(tmp_path, picture):
    image = pytest.importorskip("PIL.Image")
    grey = picture[:, :, 1]
    image.fromarray(grey, "L").save(tmp_path / "l.png")
    image.fromarray(grey.astype(np.uint16) * 257).save(tmp_path / "i16.png")
    for name in ("l.png", "i16.png"):
        assert np.array_equal(qc.OccupancyGrid.from_image(tmp_path / name, 1.0).free, expected_free(grey, 255))


def write_png(path, samples: np.ndarray, depth: int) -> None:
    """A PNG written by hand (zlib, filter 0 on every row): ``samples`` (H, W) grey or (H, W, 3) RGB."""
    height, width = samples.shape[:2]
    colour = 2 if samples.ndim == 3 else 0
    dtype = ">u2" if depth == 16 else np.uint8
    raw = b"".join(b"\x00" + samples[row].astype(dtype).tobytes() for row in range(height))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return len(data).to_bytes(4, "big") + kind + data + (zlib.crc32(kind + data) & 0xFFFFFFFF).to_bytes(4, "big")

    header = width.to_bytes(4, "big") + height.to_bytes(4, "big") + bytes([depth, colour, 0, 0, 0])
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw))
                     + chunk(b"IEND", b""))


def test_sixteen_bit_pngs(tmp_path):
    """A 16-bit greyscale PNG keeps its 16 bits (a threshold between two adjacent samples splits
    them); a 16-bit colour PNG is read at 8 bits per channel (Pillow's reading), so its grey is
    within 1 / 255 of the file's."""
    write_png(tmp_path / "edge.png", np.array([[32767, 32768]]), 16)
    grid = qc.OccupancyGrid.from_image(tmp_path / "edge.png", 1.0, free_threshold=32767.5 / 65535)
    assert grid.free.tolist() == [[False, True]]
    samples = np.random.default_rng(11).integers(0, 65536, (6, 8, 3))
    write_png(tmp_path / "rgb16.png", samples, 16)
    grey = samples.sum(axis=2) / (3 * 65535)
    for threshold in np.linspace(0.05, 0.95, 19):
        free = qc.OccupancyGrid.from_image(tmp_path / "rgb16.png", 1.0, free_threshold=threshold).free
        assert np.all(free[grey >= threshold + 1 / 255]) and not np.any(free[grey < threshold - 1 / 255])
    write_png(tmp_path / "grey8.png", samples[:, :, 0] >> 8, 8)
    assert np.array_equal(qc.OccupancyGrid.from_image(tmp_path / "grey8.png", 1.0).free,
                          expected_free(samples[:, :, 0] >> 8, 255))


def test_threshold_is_inclusive_and_colour_is_the_mean_of_channels(tmp_path):
    write_pnm(tmp_path / "red.ppm", "P6", np.array([[[255, 0, 0], [128, 128, 128]]]))  # grey 1/3, 128/255
    assert qc.OccupancyGrid.from_image(tmp_path / "red.ppm", 1.0).free.tolist() == [[False, True]]
    assert qc.OccupancyGrid.from_image(tmp_path / "red.ppm", 1.0, free_threshold=1 / 3).free.tolist() == [[True, True]]
    assert qc.OccupancyGrid.from_image(tmp_path / "red.ppm", 1.0, free_threshold=0.0).free.all()


def test_image_row_zero_is_the_top_of_the_map(tmp_path):
    """One black pixel at image (row 1, col 3) of a 4 x 5 image, s = 0.5, origin (-1, 2): its
    world cell is x in [0.5, 1.0], y in [3.0, 3.5]."""
    samples = np.full((4, 5), 255)
    samples[1, 3] = 0
    write_pnm(tmp_path / "dot.pgm", "P5", samples)
    rgb = np.repeat(samples[:, :, None], 3, axis=2).astype(np.uint8)
    plt.imsave(tmp_path / "dot.png", rgb)
    for name in ("dot.pgm", "dot.png"):
        grid = qc.OccupancyGrid.from_image(tmp_path / name, 0.5, origin=(-1.0, 2.0))
        assert grid.bounds().tolist() == [[-1.0, 1.5], [2.0, 4.0]]
        assert grid.pixel_center(1, 3) == (0.75, 3.25)
        check = qc.GridCheck(grid)
        inside = np.array([[0.75, 3.25], [0.51, 3.01], [0.99, 3.49]])
        beside = np.array([[0.25, 3.25], [1.25, 3.25], [0.75, 2.75], [0.75, 3.75], [0.75, 2.25]])
        assert not check.is_valid(inside).any() and check.is_valid(beside).all()
        assert check.is_valid(np.array([[0.5, 3.25], [1.0, 3.5]])).tolist() == [False, False]  # its closed edges


# ----------------------------------------------------------------------------- the check
@pytest.fixture(scope="module")
def random_grid() -> qc.OccupancyGrid:
    free = np.random.default_rng(3).random((16, 24)) > 0.3
    return qc.OccupancyGrid(free, pixel_size=0.37, origin=(-1.3, 2.1))


def random_segments(grid: qc.OccupancyGrid, count: int, reach_cells: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    bounds = grid.bounds()
    extent = bounds[:, 1] - bounds[:, 0]
    parents = bounds[:, 0] - 0.02 * extent + 1.04 * extent * rng.random((count, 2))  # a few outside
    children = parents + reach_cells * grid.pixel_size * rng.uniform(-1, 1, (count, 2))
    return parents, children


def test_grid_check_equals_the_exact_reference_on_random_segments(random_grid):
    """Zero disagreements with the exact rational reference on 1 500 short random segments on the
    30 %-occupied grid and 300 long ones on a 3 %-occupied grid of other cells and origin (a random
    segment passes within EPSILON = 1e-9 cells of a cell it does not touch with probability of order
    1e-9 per cell, so the check's widening changes nothing here)."""
    sparse = qc.OccupancyGrid(np.random.default_rng(4).random((21, 13)) > 0.03, pixel_size=1.3, origin=(5.0, -7.7))
    for grid, count, reach, seed in ((random_grid, 1500, 3.0, 0), (sparse, 300, 12.0, 1)):
        check = qc.GridCheck(grid)
        parents, children = random_segments(grid, count, reach, seed)
        answers = check.reachable(parents, children)
        reference = [exact_free(grid, p, c) for p, c in zip(parents, children, strict=True)]
        disagreements = np.flatnonzero(answers != np.array(reference))
        assert disagreements.size == 0, [(parents[i].tolist(), children[i].tolist()) for i in disagreements]
        assert 0.2 < answers.mean() < 0.8, answers.mean()  # both verdicts exercised
        assert check.evaluations == count


def test_grid_check_equals_the_exact_reference_on_lattice_segments():
    """Endpoints on the half-integer lattice of unit cells: segments along cell edges, through cell
    corners and ending on them, most of them ties; zero disagreements with the exact reference."""
    rng = np.random.default_rng(8)
    grid = qc.OccupancyGrid(rng.random((12, 15)) > 0.15, pixel_size=1.0)
    parents = np.minimum(rng.integers(0, 31, (2000, 2)) / 2.0, [15.0, 12.0])
    children = parents + rng.integers(-8, 9, (2000, 2)) / 2.0
    answers = qc.GridCheck(grid).reachable(parents, children)
    reference = np.array([exact_free(grid, p, c) for p, c in zip(parents, children, strict=True)])
    assert np.array_equal(answers, reference), np.flatnonzero(answers != reference)
    assert 0.15 < answers.mean() < 0.5, answers.mean()


def test_grid_check_against_dense_sampling(random_grid):
    """Never accepts what sampling rejects; rejects what sampling accepts only where every occupied
    cell touched is crossed for a parameter length under 1 / N (no sample can land in it)."""
    check = qc.GridCheck(random_grid)
    parents, children = random_segments(random_grid, 600, 4.0, 2)
    samples = 2000
    answers = check.reachable(parents, children)
    missed = 0
    for p, c, answer in zip(parents, children, answers, strict=True):
        sampled = sampled_free(random_grid, p, c, samples)
        assert not (answer and not sampled), (p.tolist(), c.tolist())
        if sampled and not answer:
            missed += 1
            occupied = occupied_bottom_up(random_grid)
            touched = exact_touched(*cell_coordinates(random_grid, p), *cell_coordinates(random_grid, c),
                                    random_grid.rows, random_grid.cols)
            clipped = [t1 - t0 for cell, (t0, t1) in touched.items() if occupied[cell]]
            assert clipped and max(clipped) < Fraction(1, samples), (p.tolist(), c.tolist(), clipped)
    assert missed <= 6  # corner clips shorter than 1 / 2000 of a segment a few cells long are rare


@pytest.fixture(scope="module")
def corner_grid() -> qc.OccupancyGrid:
    """6 x 6 cells of 0.5 at the origin (cell coordinates exact); occupied, bottom-up (j, i): (2, 2),
    and (0, 4) on the bottom row."""
    free = np.ones((6, 6), dtype=bool)
    free[6 - 1 - 2, 2] = False
    free[6 - 1 - 0, 4] = False
    return qc.OccupancyGrid(free, pixel_size=0.5)


CORNER_CASES = [
    # (parent, child) in cell coordinates, expected verdict, why
    ((0.5, 2.0), (5.5, 2.0), False, "along the bottom edge of the occupied cell"),
    ((0.5, 4.0), (5.5, 4.0), True, "along an edge between free cells"),
    ((2.0, 0.5), (2.0, 5.5), False, "along the left edge of the occupied cell"),
    ((1.0, 0.0), (5.0, 4.0), False, "a diagonal through the occupied cell's corner (3, 2) only"),
    ((1.5, 0.0), (5.5, 4.0), True, "the same diagonal half a cell to the right"),
    ((0.0, 4.0), (4.0, 0.0), False, "an anti-diagonal through corner (2, 2) and (4, 0)"),
    ((0.0, 0.0), (6.0, 0.0), False, "along the map's bottom edge, which the occupied (0, 4) touches"),
    ((0.0, 6.0), (6.0, 6.0), True, "along the map's top edge"),
    ((6.0, 0.0), (6.0, 6.0), True, "along the map's right edge"),
    ((3.0, 3.0), (3.0, 3.0), False, "a point at the occupied cell's corner"),
    ((3.0, 2.5), (3.0, 2.5), False, "a point on the occupied cell's edge"),
    ((3.5, 2.5), (3.5, 2.5), True, "a point in the free cell beside it"),
    ((0.0, 0.0), (2.0, 2.0), False, "ending at the occupied cell's corner"),
    ((0.0, 0.0), (1.9, 1.9), True, "stopping short of it"),
    ((0.0, 0.0), (6.0, 6.0), False, "the main diagonal, through the occupied cell"),
    ((1.0, 5.0), (5.0, 3.0), True, "a shallow segment above it (v = 3 reached at u = 5 only)"),
    ((-0.1, 1.0), (1.0, 1.0), False, "starting outside the bounds"),
]


@pytest.mark.parametrize(("parent", "child", "expected", "why"), CORNER_CASES)
def test_corner_cases(corner_grid, parent, child, expected, why):
    s = corner_grid.pixel_size
    p, c = np.array(parent) * s, np.array(child) * s
    check = qc.GridCheck(corner_grid)
    assert bool(check.reachable(p, c)[0]) is expected, why
    assert bool(check.reachable(c, p)[0]) is expected, why  # either direction
    assert exact_free(corner_grid, p, c) is expected, why  # the reference agrees


def test_a_corner_clip_between_samples_is_what_sampling_misses(corner_grid):
    """The disagreement the sampled reference is known to make, built on purpose: a diagonal that
    cuts 1e-4 cells into the occupied cell's corner (3, 2), for a parameter length of 2.5e-5, between
    two of the 2 001 samples. Sampling accepts it; the check and the exact reference reject it."""
    s = corner_grid.pixel_size
    p, c = np.array([1.9996, 0.9997]) * s, np.array([5.9996, 4.9997]) * s
    touched = exact_touched(*cell_coordinates(corner_grid, p), *cell_coordinates(corner_grid, c), 6, 6)
    t0, t1 = touched[(2, 2)]
    assert 0 < t1 - t0 < Fraction(1, 2000) and math.floor(t0 * 2000) == math.floor(t1 * 2000)
    assert sampled_free(corner_grid, p, c, 2000)
    assert not exact_free(corner_grid, p, c) and not qc.GridCheck(corner_grid).reachable(p, c)[0]


def test_epsilon_is_the_only_conservatism(corner_grid):
    """The diagonal through corner (3, 2), moved off it: by 1e-6 cells it is accepted, by 1e-12 (within
    EPSILON) it is still rejected, the check's documented widening."""
    check = qc.GridCheck(corner_grid)
    s = corner_grid.pixel_size
    for shift, expected in ((1e-6, True), (EPSILON / 1000, False)):
        p, c = np.array([1.0 + shift, 0.0]) * s, np.array([5.0 + shift, 4.0]) * s
        assert bool(check.reachable(p, c)[0]) is expected, shift


def test_is_valid_is_the_zero_length_segment_and_can_leave_follows_it(random_grid):
    check = qc.GridCheck(random_grid)
    points, _ = random_segments(random_grid, 500, 0.0, 5)
    assert np.array_equal(check.is_valid(points), check.reachable(points, points))
    assert check.is_valid(np.array([[np.nan, 3.0], [np.inf, 3.0]])).tolist() == [False, False]
    for point in points[:50]:
        assert check.can_leave(point) is bool(check.is_valid(point)[0])


def test_describe_names_straight_segments_and_no_dynamics(random_grid):
    check = qc.GridCheck(random_grid)
    description = check.describe()
    assert "dynamics" not in description and description["motion"] == "straight-segment"
    assert description["grid"]["rows"] == 16 and description["grid"]["cols"] == 24
    again = pickle.loads(pickle.dumps(check))
    parents, children = random_segments(random_grid, 200, 5.0, 6)
    assert np.array_equal(again.reachable(parents, children), check.reachable(parents, children))
    assert isinstance(check, qc.ReachabilityPredicate)
    assert check.bounds().tolist() == random_grid.bounds().tolist()


# ----------------------------------------------------------------------------- planning
@pytest.fixture(scope="module")
def maze_world(tmp_path_factory):
    """A 4 x 4 maze of 3-pixel corridors (17 x 17 pixels) as a PNG, pixel 0.5: start in the top-left
    room, goal in the bottom-right one."""
    path = tmp_path_factory.mktemp("maze") / "maze.png"
    plt.imsave(path, maze(4, 3, seed=1).astype(float), cmap="gray", vmin=0.0, vmax=1.0)
    return qc.image_problem(path, 0.5, start=[1.25, 7.25], goal=[7.25, 1.25], goal_radius=0.5)


def test_image_world_builds_the_environment(maze_world):
    env, check = maze_world.env, maze_world.predicate
    assert env.bounds.tolist() == [[0.0, 8.5], [0.0, 8.5]] and env.num_boxes == 0
    assert env.name == "image:maze" and env.metadata["occupancy"]["free_cells"] == int(check.grid.free.sum())
    assert np.array_equal(check.grid.free, maze(4, 3, seed=1))


def _recheck_edges(result, check) -> None:
    parents, children = result.nodes[result.parents[1:]], result.nodes[1:]
    assert len(children) > 0
    for p, c in zip(parents, children, strict=True):
        assert exact_free(check.grid, p, c), (p.tolist(), c.tolist())


def test_rrt_and_q_rrt_plan_through_the_maze_and_every_edge_rechecks(maze_world):
    check = maze_world.predicate
    rrt = qc.RRT(max_extension=1.0, goal_bias=0.05, seed=0).plan(maze_world, max_oracle_calls=20_000)
    qrrt = qc.QRRT(backend=qc.StatevectorBackend(seed=0), num_qubits=5, max_extension=1.0,
                   goal_bias=0.05, search_policy=qc.Adaptive(), seed=0).plan(maze_world, max_oracle_calls=20_000)
    for result in (rrt, qrrt):
        assert result.reached, result.status_text
        _recheck_edges(result, check)
        assert result.settings["dynamics"] is None and plan_dynamics(result) is None  # drawn straight
        assert result.settings["predicate"]["motion"] == "straight-segment"


def test_ompl_plans_the_same_maze_on_the_grid_check(maze_world):
    """OMPL's RRT through ``setup_from_problem``: the check is its motion validator and ``is_valid``
    its validity checker; every segment of its path rechecks with the exact reference."""
    pytest.importorskip("ompl.base")
    og = pytest.importorskip("ompl.geometric")
    from ompl import util as ou

    from qrrt_circuits.adapters.ompl_planning import setup_from_problem

    check = maze_world.predicate
    ou.RNG.setSeed(0)
    ou.setLogLevel(ou.LOG_NONE)
    setup = setup_from_problem(maze_world)
    planner = og.RRT(setup.getSpaceInformation())
    planner.setRange(1.0)
    setup.setPlanner(planner)
    assert str(setup.solve(30.0)) == "Exact solution"
    path = setup.getSolutionPath()
    points = np.array([[path.getState(i)[0], path.getState(i)[1]] for i in range(path.getStateCount())])
    assert np.linalg.norm(points[0] - maze_world.start) == 0.0
    assert np.linalg.norm(points[-1] - maze_world.goal.centre) <= 0.5
    for p, c in zip(points[:-1], points[1:], strict=True):
        assert exact_free(check.grid, p, c), (p.tolist(), c.tolist())


def test_image_world_refuses_a_start_or_goal_off_the_free_cells(maze_world, tmp_path):
    """The maze's top-left pixel (row 0, col 0) is wall: a start there, on its edge, or outside the
    map is refused naming the start, the pixel and what is accepted; so is such a goal."""
    path = tmp_path / "maze.pgm"
    write_pnm(path, "P5", maze(4, 3, seed=1).astype(int) * 255)
    accepted = r"accepted: a point inside a free cell, within the bounds \[\[0.0, 8.5\], \[0.0, 8.5\]\]"
    cases = [
        ("start", [0.25, 8.25], r"it lies in or on the boundary of the occupied image pixel \(row 0, col 0\)"),
        ("start", [0.5, 7.25], r"it lies in or on the boundary of the occupied image pixel \(row 2, col 0\)"),
        ("goal", [9.0, 1.0], "it lies outside the bounds"),
        ("goal", [8.3, 1.25], r"it lies in or on the boundary of the occupied image pixel \(row 14, col 16\)"),
    ]
    for key, point, why in cases:
        arguments = {"start": [1.25, 7.25], "goal": [7.25, 1.25]} | {key: point}
        with pytest.raises(ValueError, match=rf"{key} \[.*\] is not a free point of the map: {why}; {accepted}"):
            qc.image_problem(path, 0.5, goal_radius=0.5, **arguments)
    beside = qc.image_problem(path, 0.5, start=[0.75, 7.25], goal=[7.25, 1.25], goal_radius=0.5)  # beside the wall
    assert beside.start.tolist() == [0.75, 7.25]


def test_planners_refuse_a_start_in_an_occupied_cell(maze_world):
    with pytest.raises(ValueError, match=r"start \[0.25, 0.25\] is not a valid state: the grid check"):
        posed(maze_world, start=[0.25, 0.25])


# ----------------------------------------------------------------------------- bad input
def png_header(width: int, height: int) -> bytes:
    """A PNG signature and IHDR chunk (8-bit RGB) with no image data after them."""
    size = width.to_bytes(4, "big") + height.to_bytes(4, "big")
    return b"\x89PNG\r\n\x1a\n" + (13).to_bytes(4, "big") + b"IHDR" + size + bytes([8, 2, 0, 0, 0])


def test_bad_files_are_refused_naming_the_path_and_the_formats(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    write_pnm(tmp_path / "ok.pgm", "P5", np.full((3, 3), 255))
    (tmp_path / "short.pgm").write_bytes((tmp_path / "ok.pgm").read_bytes()[:-2])
    (tmp_path / "maxval.pgm").write_bytes(b"P5 2 2 0\n\x00\x00\x00\x00")
    (tmp_path / "above.pgm").write_bytes(b"P2 2 1 15\n3 16\n")
    (tmp_path / "word.pgm").write_bytes(b"P2 2 1 15\n3 x\n")
    (tmp_path / "noheader.pgm").write_bytes(b"P5 2\n")
    (tmp_path / "bitmap.pbm").write_bytes(b"P1 2 1\n0 1\n")
    (tmp_path / "broken.png").write_bytes(png_header(4, 4) + b"garbage")
    formats = r"accepted: a PNG file, or a PGM / PPM file \(binary P5 / P6 or ASCII P2 / P3\)"
    cases = {
        "missing.png": "does not exist",
        ".": "is not a file",
        "notes.txt": r"is not a readable image \(unknown format: neither a PNG signature nor",
        "short.pgm": r"is not a readable image \(truncated: 7 of 9 raster bytes\)",
        "maxval.pgm": r"maxval 0 outside \[1, 65535\]",
        "above.pgm": "a sample above maxval 15",
        "word.pgm": "not a non-negative integer",
        "noheader.pgm": "without its width, height and maxval",
        "bitmap.pbm": "unknown format",
        "broken.png": "is not a readable image",
    }
    for name, message in cases.items():
        with pytest.raises(ValueError, match=f"path '.*{name if name != '.' else ''}' .*(?:{message}).*{formats}"):
            qc.OccupancyGrid.from_image(tmp_path / name, 1.0)
    with pytest.raises(ValueError, match="path must be a file path"):
        qc.OccupancyGrid.from_image(3, 1.0)
    with pytest.raises(ValueError) as error:
        qc.OccupancyGrid.from_image(tmp_path / "notes.txt", 1.0)
    assert "hello" not in str(error.value)  # a file's content is never echoed


def test_a_pnm_reads_only_its_declared_raster_and_refuses_a_far_larger_file(tmp_path):
    """A 40 x 40 map with a 2 GiB tail (sparse): refused from its size before its raster is read,
    with little memory; a small tail is read and ignored; a 5 000-digit width is refused by name."""
    import tracemalloc

    raster = b"P5 40 40 255\n" + bytes([255]) * 1600
    tail = tmp_path / "tail.pgm"
    with open(tail, "wb") as handle:
        handle.write(raster)
        handle.truncate(2 << 30)
    tracemalloc.start()
    with pytest.raises(ValueError, match=r"2147483648 bytes, far more than the 1613 its header declares"):
        qc.OccupancyGrid.from_image(tail, 1.0)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 8 << 20
    (tmp_path / "small_tail.pgm").write_bytes(raster + b"\0" * 1000)
    assert qc.OccupancyGrid.from_image(tmp_path / "small_tail.pgm", 1.0).free.all()
    (tmp_path / "wide.pgm").write_bytes(b"P5 " + b"4" * 5000 + b" 4 255\n" + bytes(16))
    with pytest.raises(ValueError, match="a PGM / PPM header width of 5000 digits, more than 9"):
        qc.OccupancyGrid.from_image(tmp_path / "wide.pgm", 1.0)


def test_images_beyond_the_cell_limit_are_refused_from_their_header(tmp_path):
    """Headers only (no pixels follow): refused for their size, not as truncated."""
    (tmp_path / "huge.pgm").write_bytes(b"P5 5000 5000 255\n")
    (tmp_path / "wide.png").write_bytes(png_header(70000, 1))
    for name, size in (("huge.pgm", "5000 x 5000"), ("wide.png", "70000 x 1")):
        with pytest.raises(ValueError, match=f"path: the image has {size} pixels; accepted are at most {MAX_CELLS}"):
            qc.OccupancyGrid.from_image(tmp_path / name, 1.0)


@pytest.mark.parametrize(("kwargs", "message"), [
    ({"pixel_size": 0.0}, "pixel_size must be a finite number > 0.0, got 0.0"),
    ({"pixel_size": -1.0}, "pixel_size must be a finite number > 0.0"),
    ({"pixel_size": math.inf}, "pixel_size must be a finite number > 0.0, got inf"),
    ({"pixel_size": math.nan}, "pixel_size must be a finite number > 0.0, got nan"),
    ({"free_threshold": -0.1}, r"free_threshold must be a finite number in \[0.0, 1.0\], got -0.1"),
    ({"free_threshold": 1.5}, r"free_threshold must be a finite number in \[0.0, 1.0\], got 1.5"),
    ({"origin": (0.0, math.nan)}, "origin must be two finite numbers"),
    ({"origin": (1.0, 2.0, 3.0)}, "origin must be two finite numbers"),
    ({"origin": "here"}, "origin must be two finite numbers"),
])
def test_bad_arguments_are_refused_before_the_file_is_read(tmp_path, kwargs, message):
    arguments = {"path": tmp_path / "map.pgm", "pixel_size": 1.0} | kwargs  # no such file
    with pytest.raises(ValueError, match=message):
        qc.OccupancyGrid.from_image(**arguments)


def test_bounds_beyond_the_largest_extent_are_refused_from_the_header(tmp_path):
    (tmp_path / "wide.pgm").write_bytes(b"P5 4000 1 255\n")  # header only: refused before the pixels
    with pytest.raises(ValueError, match=r"the map's bounds must lie within \[-1e\+12, 1e\+12\]"):
        qc.OccupancyGrid.from_image(tmp_path / "wide.pgm", 1e9)


def test_bad_grids_and_checks_are_refused():
    with pytest.raises(ValueError, match="free must be a 2-D array of booleans"):
        qc.OccupancyGrid(np.ones((3, 3)), 1.0)
    with pytest.raises(ValueError, match="free must be a 2-D array of booleans"):
        qc.OccupancyGrid(np.ones(3, dtype=bool), 1.0)
    with pytest.raises(ValueError, match="free must be a 2-D array of booleans"):
        qc.OccupancyGrid(np.ones((0, 3), dtype=bool), 1.0)
    with pytest.raises(TypeError, match="negate must be True or False"):
        qc.OccupancyGrid.from_image("x.png", 1.0, negate=1)
    with pytest.raises(TypeError, match="grid must be an OccupancyGrid"):
        qc.GridCheck(np.ones((3, 3), dtype=bool))
    with pytest.raises(ValueError, match=r"\(row, col\) must lie in"):
        qc.OccupancyGrid(np.ones((2, 2), dtype=bool), 1.0).pixel_center(2, 0)
