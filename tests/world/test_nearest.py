"""Nearest-neighbour structures answer what brute force answers under their metric, ties to the
lowest index: the compiled Euclidean grid (``GridNearest``) as it grows, and the scan under a
space's distance (``LinearNearest``, Euclidean and SE(2)), and its compiled SE(2) form
(``SE2Nearest``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.world.nearest import (
    BRUTE_FORCE_BELOW_SE2,
    GridNearest,
    LinearNearest,
    NearestNeighbors,
    SE2Nearest,
)


def _grid(first: np.ndarray, capacity: int = 256) -> GridNearest:
    """A ``GridNearest`` holding the one point ``first`` (d,), as a plan's holds its root."""
    grid = GridNearest(len(first), capacity)
    grid.add(np.atleast_2d(first))
    return grid


@pytest.mark.parametrize("dim", [1, 2, 3, 5])
def test_nearest_equals_brute_force_as_the_tree_grows(dim):
    rng = np.random.default_rng(dim)
    grid = _grid(rng.random(dim) * 20, capacity=4)
    for step in range(700):
        grid.add(np.atleast_2d(rng.random(dim) * 20))
        if step % 97 == 0 or step < 6:
            queries = rng.random((50, dim)) * 24 - 2  # some outside the nodes' span
            squared = ((queries[:, None, :] - grid.points[None]) ** 2).sum(-1)
            want = np.argmin(squared, axis=1)
            assert np.array_equal(grid.nearest(queries), want)  # brute force below BRUTE_FORCE_BELOW
            assert np.array_equal(grid.grid_nearest(queries), want)  # the grid at every size
    assert grid.size == 701 and grid.points.shape == (701, dim)


def test_ties_go_to_the_lowest_index_and_clustered_nodes_work():
    grid = _grid(np.array([1.0, 1.0]))
    for point in ([1.0, 3.0], [3.0, 1.0], [1.0, 1.0], [5.0, 5.0]):
        grid.add(np.array([point]))
    for nearest in (grid.nearest, grid.grid_nearest):
        assert nearest(np.array([[2.0, 2.0], [1.0, 1.0], [9.0, 9.0]])).tolist() == [0, 0, 4]
        assert nearest(np.array([1.0, 2.0])).tolist() == [0]


def test_degenerate_trees_line_and_repeated_points():
    rng = np.random.default_rng(5)
    line = _grid(np.array([0.0, 3.0]))
    same = _grid(np.array([2.0, 2.0, 2.0]))
    for _ in range(300):
        line.add(np.array([[rng.random() * 50, 3.0]]))
        same.add(np.array([[2.0, 2.0, 2.0]]))
    queries = rng.random((40, 2)) * 60 - 5
    squared = ((queries[:, None, :] - line.points[None]) ** 2).sum(-1)
    for tree_line, tree_same in ((line.nearest, same.nearest), (line.grid_nearest, same.grid_nearest)):
        assert np.array_equal(tree_line(queries), np.argmin(squared, axis=1))
        assert tree_same(rng.random((10, 3))).tolist() == [0] * 10  # all equally near: the lowest index


@pytest.mark.parametrize("width", [0.0, 0.7, 1.6])  # one, three and five columns of cells
@pytest.mark.parametrize("vertical", [True, False])
def test_strips_one_to_three_cells_wide_on_integer_points(width, vertical):
    """The first visit's three column runs at the grid's edges (a column outside the grid is an empty
    run): strips of integer points, so that many queries tie, searched along and across."""
    rng = np.random.default_rng(int(width * 10) + vertical)
    along = rng.integers(0, 60, size=500).astype(float)
    across = np.round(rng.random(500) * width)
    points = np.column_stack((across, along) if vertical else (along, across))
    grid = _grid(points[0])
    grid.add(points[1:])
    queries = np.round(rng.random((400, 2)) * np.array([8.0, 70.0] if vertical else [70.0, 8.0]) - 3.0) / 2.0
    want = np.argmin(((queries[:, None, :] - grid.points[None]) ** 2).sum(-1), axis=1)  # ties: lowest index
    assert np.array_equal(grid.grid_nearest(queries), want)
    assert np.array_equal(grid.nearest(queries), want)


def test_nearest_agrees_with_the_grid_on_both_sides_of_the_brute_force_switch():
    from qrrt_circuits.world import nearest as nearest_module

    rng = np.random.default_rng(8)
    grid = _grid(rng.random(2) * 20)
    while grid.size < nearest_module.BRUTE_FORCE_BELOW + 50:
        grid.add(np.atleast_2d(rng.random(2) * 20))
        if grid.size in (nearest_module.BRUTE_FORCE_BELOW - 1, nearest_module.BRUTE_FORCE_BELOW):
            queries = rng.random((256, 2)) * 20
            want = np.argmin(((queries[:, None, :] - grid.points[None]) ** 2).sum(-1), axis=1)
            assert np.array_equal(grid.nearest(queries), want)  # brute force, then the grid
            assert np.array_equal(grid.grid_nearest(queries), want)


def test_the_grid_built_when_the_tree_reaches_the_switch_answers_as_one_kept_from_the_start():
    """Small trees keep no grid (built at BRUTE_FORCE_BELOW nodes, or by a first grid query), and a
    grid is rebuilt once the nodes added since its build reach ``_pending_limit``: both histories
    answer every query as the brute force does, at every size, rebuilds on both sides."""
    from qrrt_circuits.world import nearest as nearest_module

    switch = nearest_module.BRUTE_FORCE_BELOW
    rebuilds = [switch]  # the sizes at which the lazy grid (re)builds its grid
    while rebuilds[-1] < 1200:
        rebuilds.append(rebuilds[-1] + nearest_module._pending_limit(rebuilds[-1]))
    rng = np.random.default_rng(11)
    points = rng.random((1200, 2)) * 20
    lazy, early = _grid(points[0]), _grid(points[0])
    early.grid_nearest(points[:1])  # the grid from the first node on
    assert lazy._grid_built_at == 0 and early._grid_built_at == 1
    checked = {switch - 1, 1200} | {size + offset for size in rebuilds[:4] for offset in (-1, 0, 1)}
    for point in points[1:]:
        lazy.add(np.atleast_2d(point))
        early.add(np.atleast_2d(point))
        assert lazy.size - lazy._grid_built_at < nearest_module._pending_limit(lazy._grid_built_at) or \
            lazy._grid_built_at == 0
        if lazy.size in checked:
            queries = rng.random((128, 2)) * 24 - 2
            want = np.argmin(((queries[:, None, :] - lazy.points[None]) ** 2).sum(-1), axis=1)
            assert np.array_equal(lazy.nearest(queries), want)
            assert np.array_equal(early.nearest(queries), want)
            assert np.array_equal(early.grid_nearest(queries), want)
            if lazy.size >= switch:  # (below, a grid query would build the grid)
                assert np.array_equal(lazy.grid_nearest(queries), want)
    assert lazy._grid_built_at == max(size for size in rebuilds if size <= 1200)


def test_nodes_added_since_the_grid_was_built_are_found_and_win_no_false_ties():
    """The nodes the grid does not hold yet are scanned first: the nearest may be one of them, and
    a grid node exactly as near (a lower index) still wins the tie."""
    from qrrt_circuits.world import nearest as nearest_module

    rng = np.random.default_rng(4)
    grid = _grid(np.array([10.0, 10.0]))
    while grid.size < nearest_module.BRUTE_FORCE_BELOW:
        grid.add(np.atleast_2d(rng.random(2) * 20))
    assert grid._grid_built_at == grid.size
    query = np.array([[3.25, 17.5]])
    grid.add(np.atleast_2d(query[0] + [0.0, 1e-9]))  # added after the build: the nearest
    assert grid.nearest(query).tolist() == [grid.size - 1]
    grid.add(np.atleast_2d(grid.points[1].copy()))  # a twin of node 1, added after the build
    assert grid.nearest(grid.points[1][None]).tolist() == [1]  # node 1 and its later twin: the lower index
    assert grid.size - grid._grid_built_at == 2


@pytest.mark.parametrize("xs, query", [
    # a node a rounding error below a cell edge is filed in the cell above it: the search must
    # still find it (it is nearer by 2.5e-14) ...
    ([3.1327023920027237, 49.03221452405565, 20.115521880862303, 40.311307218965595, 37.55733649104241,
      30.67240967123448], 34.11487308113845),
    # ... and a tie across such an edge goes to the lower index
    ([-4.590264760638053, -0.8134658907971861, -3.1928491787969326, -1.5310576760669505, -1.7576656082574031,
      -1.8520855800034244], -1.8048755941304138),
])
def test_the_grid_finds_nodes_filed_across_a_cell_edge_by_rounding(xs, query):
    grid = _grid(np.array(xs[:1]))
    for value in xs[1:]:
        grid.add(np.array([[value]]))
    squared = (query - np.array(xs)) ** 2
    assert grid.grid_nearest(np.array([[query]])).tolist() == [int(np.argmin(squared))]
    assert grid.nearest(np.array([[query]])).tolist() == [int(np.argmin(squared))]


def test_cell_edge_near_ties_in_two_dimensions():
    """A node a rounding error below a cell edge filed in the cell above, with a rival a hair
    farther on the query's side: the grid must visit the node's cell before stopping."""
    rng = np.random.default_rng(3)
    checked = 0
    for _ in range(60):
        base = rng.uniform(0, 20, (128, 2))
        probe = _grid(base[0])  # the grid of 130 nodes in base's box: base and two nodes inside its box
        for point in (*base[1:], base[1], base[2]):
            probe.add(np.atleast_2d(point))
        probe.grid_nearest(base[:1])  # a small grid builds its grid on the first grid query
        origin, cell = probe._origin, probe._cell
        y = float(rng.uniform(2, 18))
        for k in range(1, int(probe._shape[0])):
            edge = origin[0] + k * cell
            x = np.nextafter(edge, -np.inf)
            if int((x - origin[0]) / cell) < k:
                continue  # filed below the edge: not the case under test
            query = edge - 0.001 * cell
            angle = rng.uniform(np.pi / 2, 3 * np.pi / 2)  # a rival a hair farther, on the query's side
            radius = (x - query) * (1 + 1e-13)
            grid = _grid(base[0])
            for point in (*base[1:], [x, y], [query + radius * np.cos(angle), y + radius * np.sin(angle)]):
                grid.add(np.atleast_2d(np.asarray(point)))
            grid.grid_nearest(base[:1])  # the grid of these 130 nodes
            if not (np.array_equal(grid._origin, origin) and grid._cell == cell):
                continue  # the two nodes moved the box: another grid
            assert int((x - origin[0]) / cell) == k  # the node is filed above the edge
            queries = np.array([[query, y]])
            want = int(np.argmin(((queries[:, None] - grid.points[None]) ** 2).sum(-1)[0]))
            assert grid.grid_nearest(queries).tolist() == [want]
            assert grid.nearest(queries).tolist() == [want]
            checked += 1
    assert checked >= 20  # the construction produced cell-edge cases


def test_queries_of_the_wrong_shape_or_not_finite_are_refused():
    grid = _grid(np.array([1.0, 2.0]))
    grid.add(np.array([[3.0, 4.0]]))
    for bad in (np.array([[1.0, 2.0, 3.0]]), np.array([[1.0]]), np.array([[np.nan, 1.0]]), np.array([np.inf, 0.0])):
        for nearest in (grid.nearest, grid.grid_nearest):
            with pytest.raises(ValueError, match="points"):
                nearest(bad)


def test_queries_whose_squared_distances_overflow_still_end():
    """Every squared distance inf: the lowest index, from the brute force, from the grid, and from
    the grid with nodes added since its build (whose inf ties the grid's lower indices must win)."""
    from qrrt_circuits.world import nearest as nearest_module

    rng = np.random.default_rng(1)
    grid = _grid(rng.random(2))
    far = np.array([[1e200, 1.0], [-1e300, -1e300]])
    while grid.size < nearest_module.BRUTE_FORCE_BELOW + 10:
        grid.add(np.atleast_2d(rng.random(2)))
        if grid.size in (300, nearest_module.BRUTE_FORCE_BELOW + 10):
            assert grid.nearest(far).tolist() == [0, 0] and grid.grid_nearest(far).tolist() == [0, 0]
    assert grid.size > grid._grid_built_at > 0  # the last check had nodes the grid does not hold


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_a_tree_growing_outward_past_its_grid_box(dim):
    """Planner trees grow outward: the nodes added since the grid's build lie outside the box of
    the nodes it holds, and queries near them, beyond the box and on exact nodes agree with the
    brute force."""
    rng = np.random.default_rng(20 + dim)
    grid = _grid(np.zeros(dim))
    for step in range(1, 1500):
        radius = 0.02 * step  # each node a little farther out than the last
        direction = rng.normal(size=dim)
        grid.add(np.atleast_2d(direction / np.linalg.norm(direction) * radius * rng.uniform(0.9, 1.0)))
        if step % 61 == 0 or step in (399, 400, 401):
            newest = grid.points[-5:]
            queries = np.concatenate([newest, newest * 1.05, rng.normal(size=(30, dim)) * radius * 1.5])
            want = np.argmin(((queries[:, None, :] - grid.points[None]) ** 2).sum(-1), axis=1)
            assert np.array_equal(grid.nearest(queries), want)
            assert np.array_equal(grid.grid_nearest(queries), want)


def test_first_grid_queries_from_several_threads_agree_with_the_brute_force():
    """A small grid builds its grid on the first grid query: threads asking at once must not read a
    half-built grid (before the lock, about 1.5 % of such trials answered wrongly)."""
    import threading

    rng = np.random.default_rng(1)
    queries = rng.random((400, 2)) * 20
    for _ in range(150):
        points = rng.random((159, 2)) * 20
        grid = _grid(points[0])
        for point in points[1:]:
            grid.add(np.atleast_2d(point))
        want = np.argmin(((queries[:, None, :] - grid.points[None]) ** 2).sum(-1), axis=1)
        results = [None] * 4
        barrier = threading.Barrier(4)

        def work(i, grid=grid, barrier=barrier, results=results):
            barrier.wait()
            results[i] = grid.grid_nearest(queries)

        threads = [threading.Thread(target=work, args=(i,)) for i in range(4)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        assert all(np.array_equal(result, want) for result in results)


def test_points_added_in_batches_answer_as_points_added_one_at_a_time():
    """``add`` of m rows appends as m ``add`` calls of one row do (indices, positions, buffers
    grown), with the grid rebuilt once at most, and queries answer as the brute force does on both."""
    from qrrt_circuits.world import nearest as nearest_module

    rng = np.random.default_rng(9)
    points = rng.random((1500, 2)) * 20
    one, many = _grid(points[0], capacity=4), _grid(points[0], capacity=4)
    for index in range(1, 1500):
        one.add(points[index:index + 1])
    position = 1
    for count in (0, 1, 3, 250, 7, 1, 500):  # batches across the switch, rebuilds and buffer growth
        many.add(points[position:position + count])
        position += count
        built = many._grid_built_at
        assert many.size == position
        assert (built == 0 and position < nearest_module.BRUTE_FORCE_BELOW) or \
            position - built < nearest_module._pending_limit(built)  # a batch that reaches the limit rebuilds
    many.add(points[position:])
    assert np.array_equal(one.points, many.points) and np.array_equal(one.points, points)
    queries = rng.random((300, 2)) * 24 - 2
    want = np.argmin(((queries[:, None, :] - one.points[None]) ** 2).sum(-1), axis=1)
    assert np.array_equal(one.nearest(queries), want) and np.array_equal(many.nearest(queries), want)


@pytest.mark.parametrize("make", [lambda: GridNearest(2), lambda: LinearNearest(qc.RealVectorSpace(2))])
def test_points_of_the_wrong_shape_and_an_empty_structure_are_refused(make):
    near = make()
    with pytest.raises(ValueError, match="holds no points yet"):
        near.nearest(np.zeros(2))
    for bad in (np.zeros(2), np.zeros((3, 3)), np.zeros((1, 2, 1))):
        with pytest.raises(ValueError, match=r"points must have shape \(m, 2\)"):
            near.add(bad)
    assert near.size == 0 and isinstance(near, NearestNeighbors)


@pytest.mark.parametrize("dim", [20, 63, 64, 100])
def test_high_dimensional_trees_past_the_switch(dim):
    """In high d every axis of the grid got 2 cells: 2^64 cells wrapped to 0 in int64 and the grid was
    filed out of bounds (a segmentation fault at d >= 64, a numpy error at d = 63), and at d = 20 a
    query visited all 2^20 cells. Where a query's first block (3^d cells) would exceed the node
    count the grid is one cell: answers as brute force, in bounded work."""
    rng = np.random.default_rng(dim)
    grid = _grid(rng.uniform(0, 20, dim))
    for point in rng.uniform(0, 20, (450, dim)):
        grid.add(np.atleast_2d(point))
    assert grid.size == 451 and grid._grid_built_at >= 400 and grid._shape.tolist() == [1] * dim
    assert not grid._several_cells  # one cell: searched by the (vectorized) brute-force block
    queries = rng.uniform(0, 20, (64, dim))
    brute = np.argmin(((queries[:, None, :] - grid.points[None, :, :]) ** 2).sum(axis=2), axis=1)
    assert np.array_equal(grid.nearest(queries), brute)
    assert np.array_equal(grid.grid_nearest(queries), brute)


def test_a_six_dimensional_grid_has_cells_once_the_nodes_outnumber_a_query_block():
    """3^6 = 729: one cell below 729 nodes, a real grid above (the same answers either way)."""
    rng = np.random.default_rng(6)
    grid = _grid(rng.uniform(0, 20, 6))
    grid.add(rng.uniform(0, 20, (500, 6)))
    assert grid._shape.tolist() == [1] * 6
    grid.add(rng.uniform(0, 20, (1500, 6)))
    assert int(np.prod(grid._shape)) > 1
    queries = rng.uniform(0, 20, (64, 6))
    brute = np.argmin(((queries[:, None, :] - grid.points[None, :, :]) ** 2).sum(axis=2), axis=1)
    assert np.array_equal(grid.nearest(queries), brute)


def test_a_planar_tree_past_the_switch_is_searched_through_its_grid():
    """The grid is used wherever it has several cells:
    a planner's 2-D grid past BRUTE_FORCE_BELOW is not scanned by brute force."""
    rng = np.random.default_rng(2)
    grid = _grid(rng.uniform(0, 20, 2))
    grid.add(rng.uniform(0, 20, (999, 2)))
    assert grid._several_cells and grid._grid_built_at >= 400 and int(np.prod(grid._shape)) > 1


PI = math.pi


def _se2_points(rng: np.random.Generator, count: int) -> np.ndarray:
    return np.column_stack([rng.uniform(0, 10, count), rng.uniform(0, 10, count), rng.uniform(-PI, PI, count)])


@pytest.mark.parametrize("space", [qc.SE2Space(), qc.SE2Space(angle_weight=2.0), qc.RealVectorSpace(3)],
                         ids=["se2", "se2-heavy-turns", "euclidean"])
@pytest.mark.parametrize("chunk", [1 << 20, 1000])  # (1000 pairs: queries scanned a few at a time)
def test_the_linear_scan_is_the_brute_force_under_the_space_metric(space, chunk, monkeypatch):
    """Against ``argmin`` of the space's own distance, query by query, as points are added in
    batches."""
    from qrrt_circuits.world import nearest as nearest_module

    monkeypatch.setattr(nearest_module, "_CHUNK", chunk)
    rng = np.random.default_rng(0)
    near = LinearNearest(space)
    points = _se2_points(rng, 700)
    for first, stop in ((0, 1), (1, 40), (40, 700)):
        near.add(points[first:stop])
        queries = _se2_points(rng, 300)
        want = [int(np.argmin(space.distance(points[:stop], query))) for query in queries]
        assert near.nearest(queries).tolist() == want
    assert near.nearest(points[5]).tolist() == [5]  # a (d,) query


def test_the_linear_scan_breaks_ties_to_the_lowest_index_and_wraps_the_angle():
    near = LinearNearest(qc.SE2Space())
    near.add(np.array([[5.0, 5.0, 0.0], [5.0, 5.3, PI - 0.05], [5.0, 5.0, 0.0], [5.0, 5.3, PI - 0.05]]))
    query = np.array([[5.0, 5.3, -PI + 0.05], [5.0, 5.0, 0.0]])
    assert near.nearest(query).tolist() == [1, 0]  # theta wraps: node 1 is 0.1 rad away; twins: the lower
    euclidean = _grid(np.array([5.0, 5.0, 0.0]))
    euclidean.add(np.array([[5.0, 5.3, PI - 0.05]]))
    assert euclidean.nearest(query[:1]).tolist() == [0]  # (the Euclidean search does not wrap)


def test_each_space_chooses_its_structure_once_empty():
    grid, scan = qc.RealVectorSpace(2).nearest_neighbors(), qc.SE2Space().nearest_neighbors()
    assert isinstance(grid, GridNearest) and grid.dim == 2 and grid.size == 0
    assert isinstance(scan, SE2Nearest) and scan.angle_weight == 0.5 and scan.size == 0
    assert qc.RealVectorSpace(2).nearest_neighbors() is not grid  # a new structure per call (per plan)


@pytest.mark.parametrize(("make", "space"), [(lambda: GridNearest(3), qc.RealVectorSpace(3)),
                                             (lambda: LinearNearest(qc.SE2Space()), qc.SE2Space()),
                                             (lambda: SE2Nearest(0.5), qc.SE2Space()),
                                             (lambda: LinearNearest(qc.RealVectorSpace(3)), qc.RealVectorSpace(3))],
                         ids=["grid", "se2-scan", "se2-compiled", "euclidean"])
@pytest.mark.parametrize("count", [5, 700])  # (700: past the grid's brute-force switch)
def test_the_distance_to_the_points_added_since_an_index_is_the_brute_force(make, space, count):
    """``nearest_distance_from(queries, first)``: the smallest distance, under the structure's
    metric, to the points of index ``first`` on; ``inf`` where there are none."""
    rng = np.random.default_rng(count)
    near = make()
    points = _se2_points(rng, count)
    near.add(points)
    queries = _se2_points(rng, 9)
    for first in (0, 1, count // 2, count - 1, count):
        want = [min((float(space.distance(points[index], query)[0]) for index in range(first, count)),
                    default=math.inf) for query in queries]
        np.testing.assert_allclose(near.nearest_distance_from(queries, first), want, rtol=1e-12)


@pytest.mark.parametrize("weight", [0.5, 2.0, 0.0])
def test_the_compiled_se2_scan_is_the_space_metric_scan_bit_for_bit(weight):
    """``SE2Nearest`` answers ``LinearNearest(SE2Space(w))``'s indices and distances exactly, ties
    (positions on a 0.1 grid) and wrapped angles included."""
    rng = np.random.default_rng(int(weight * 10))
    for trial in range(30):
        scan, compiled = LinearNearest(qc.SE2Space(weight)), SE2Nearest(weight)
        count = int(rng.integers(1, 300))
        points, queries = _se2_points(rng, count), _se2_points(rng, 40)
        if trial % 3 == 0:
            points[:, :2], queries[:, :2] = np.round(points[:, :2], 1), np.round(queries[:, :2], 1)
        scan.add(points)
        compiled.add(points)
        assert np.array_equal(scan.nearest(queries), compiled.nearest(queries))
        first = int(rng.integers(0, count + 1))
        assert np.array_equal(scan.nearest_distance_from(queries, first),
                              compiled.nearest_distance_from(queries, first))


@pytest.mark.parametrize("weight", [0.5, 2.0, 0.0])
def test_the_se2_grid_answers_the_scan_bit_for_bit(weight):
    """From ``BRUTE_FORCE_BELOW_SE2`` points on, ``SE2Nearest`` searches an (x, y) grid: it answers
    ``LinearNearest(SE2Space(w))``'s indices exactly, grown point by point across rebuilds, with
    ties (positions on a coarse grid, repeated points with angles that wrap to the same turn),
    clusters, points on one line, and queries far outside the points' box."""
    rng = np.random.default_rng(7 + int(weight * 10))
    for trial in range(6):
        scan, compiled = LinearNearest(qc.SE2Space(weight)), SE2Nearest(weight)
        count = BRUTE_FORCE_BELOW_SE2 + int(rng.integers(0, 1500))
        points = _se2_points(rng, count)
        if trial % 3 == 0:  # ties: a coarse lattice of positions, angles a multiple of pi / 2
            points[:, :2] = np.round(points[:, :2] * 4) / 4
            points[:, 2] = rng.integers(-2, 2, count) * (math.pi / 2)
        elif trial % 3 == 1:  # a cluster and a few far points (most cells empty)
            points[: count // 2, :2] = 0.01 * points[: count // 2, :2]
        if trial == 5:  # every point on one line, a third of them at one position
            points[:, 0] = 3.0
            points[: count // 3, 1] = 5.0
        queries = _se2_points(rng, 60)
        queries[:10, :2] *= 25.0  # outside the box
        if trial % 3 == 0:
            queries[10:, :2] = np.round(queries[10:, :2] * 4) / 4
            queries[10:, 2] = rng.integers(-2, 3, 50) * (math.pi / 2)
        for chunk in np.array_split(np.arange(count), 7):  # through several grid rebuilds
            scan.add(points[chunk])
            compiled.add(points[chunk])
            assert np.array_equal(scan.nearest(queries), compiled.nearest(queries)), (trial, chunk[-1])
        assert compiled._grid_built_at > 0


def test_the_se2_grid_refuses_queries_that_are_not_finite():
    near = SE2Nearest(0.5)
    near.add(_se2_points(np.random.default_rng(0), BRUTE_FORCE_BELOW_SE2))
    with pytest.raises(ValueError, match="finite"):
        near.nearest(np.array([[0.0, np.nan, 0.0]]))
