"""Time per motion check of the occupancy-grid check (``qc.GridCheck``) on a 512 x 512 maze
image, beside the exact check (``qc.ExactCheck``) on box worlds of similar clutter.

    python benchmarks/bench_grid_check.py [--quick] [--out FILE]

Worlds, all 20 x 20 length units:

- ``maze512``: a perfect maze (``qrrt_circuits.world.maze``, seed 0) of 64 x 64 rooms, corridors
  7 pixels wide and walls 1 pixel thick, cropped to 512 x 512 pixels of 20 / 512, written as a PNG
  and read with ``qc.image_problem``; checked by ``GridCheck`` (straight segments, every cell
  touched);
- ``maze512-boxes``: the same walls as boxes (each run of occupied pixels in a row, merged with the
  identical runs of the rows below), checked by ``ExactCheck`` at its default resolution 0.01
  (closed-loop trajectories under the paper's dynamics, DESIGN §2);
- ``paper_clutter``: the paper's world (525 boxes, seed 0), checked by ``ExactCheck``.

The two checks answer different questions (a straight segment; a closed-loop trajectory), so the
figures compare the cost of a check a planner would make in each world, not the same motion. Pairs:
parents uniform among valid points of the world, children ``local`` (uniform in the disc of
radius 1 around the parent, clipped to the workspace) or ``global`` (uniform valid points); M
pairs per batch, one core, the median of the repeats. Prints a table and writes JSON with a flat
``figures`` object (``<world>.<family>.m<M>.us_per_pair``).
"""

from __future__ import annotations

import argparse
import os
import tempfile
from pathlib import Path

os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from _common import machine, median_time, write_json  # noqa: E402

import qrrt_circuits as qc  # noqa: E402
from qrrt_circuits.world.maze import maze_free  # noqa: E402

SIDE = 512
EXTENT = 20.0


def as_boxes(free: np.ndarray, pixel_size: float) -> np.ndarray:
    """The occupied pixels as boxes (k, 2, 2): each run of occupied pixels in a row, extended down
    over the rows that have the identical run (image row 0 is the top)."""
    rows = free.shape[0]
    open_runs: dict[tuple[int, int], int] = {}  # (first col, end col) -> first row
    boxes = []

    def close(run: tuple[int, int], first: int, end: int) -> None:
        boxes.append([[run[0] * pixel_size, (rows - end) * pixel_size],
                      [run[1] * pixel_size, (rows - first) * pixel_size]])

    for row in range(rows + 1):
        runs = set()
        if row < rows:
            occupied = np.concatenate([[False], ~free[row], [False]])
            edges = np.flatnonzero(occupied[1:] != occupied[:-1])
            runs = {(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)}
        for run in list(open_runs):
            if run not in runs:
                close(run, open_runs.pop(run), row)
        for run in runs:
            open_runs.setdefault(run, row)
    return np.array(boxes, dtype=float)


def pairs(valid, env: qc.Environment, count: int, family: str, rng: np.random.Generator):
    """``count`` (parents, children): parents valid, children local or global (see the docstring)."""
    def draw(number: int) -> np.ndarray:
        found = np.zeros((0, 2))
        while len(found) < number:
            batch = env.sample_uniform(4 * number + 16, rng)
            found = np.concatenate([found, batch[valid(batch)]])
        return found[:number]

    parents = draw(count)
    if family == "global":
        return parents, draw(count)
    angle = rng.uniform(0, 2 * np.pi, count)
    radius = np.sqrt(rng.random(count))
    children = parents + radius[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    return parents, np.clip(children, env.bounds[:, 0], env.bounds[:, 1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    sizes = (1, 100, 1000) if args.quick else (1, 100, 10_000)
    repeats = 3 if args.quick else 9
    free = maze_free(64, seed=0, corridor=7)[:SIDE, :SIDE]
    pixel = EXTENT / SIDE
    with tempfile.TemporaryDirectory(prefix="qrrt-bench-grid-") as scratch:
        path = Path(scratch) / "maze512.png"
        plt.imsave(path, free.astype(float), cmap="gray", vmin=0.0, vmax=1.0)
        maze = qc.image_problem(path, pixel, start=[0.5 * pixel + 0.1] * 2, goal=[19.8, 0.2], goal_radius=0.1)
    maze_env, grid_check = maze.env, maze.predicate
    assert np.array_equal(grid_check.grid.free, free)
    box_env = qc.Environment([[0.0, EXTENT], [0.0, EXTENT]], as_boxes(free, pixel), name="maze512-boxes")
    clutter = qc.paper_clutter(seed=0).env
    worlds = {
        "maze512": (maze_env, grid_check, grid_check.is_valid),
        "maze512-boxes": (box_env, qc.ExactCheck(box_env), box_env.is_free),
        "paper_clutter": (clutter, qc.ExactCheck(clutter), clutter.is_free),
    }
    rows, figures = [], {}
    print(f"{'world':14s} {'check':6s} {'family':7s} {'M':>6s} {'us/pair':>10s} {'accepts':>8s}")
    for world, (env, check, valid) in worlds.items():
        occupied = 1.0 - env.free_fraction() if world != "maze512" else 1.0 - grid_check.grid.free_fraction
        for family in ("local", "global"):
            for size in sizes:
                rng = np.random.default_rng([0x6D1D, size, family == "global"])
                parents, children = pairs(valid, env, size, family, rng)
                check.reachable(parents[:1], children[:1])  # compile / load the cache
                med, lo, hi = median_time(lambda c=check, p=parents, q=children: c.reachable(p, q), repeats)
                accepts = float(check.reachable(parents, children).mean())
                us = 1e6 * med / size
                rows.append({"world": world, "check": check.name, "family": family, "pairs": size,
                             "us_per_pair": us, "median_s": med, "min_s": lo, "max_s": hi, "repeats": repeats,
                             "accept_fraction": accepts, "occupied_fraction": occupied,
                             "boxes": env.num_boxes, "describe": check.describe()})
                figures[f"{world}.{family}.m{size}.us_per_pair"] = us
                print(f"{world:14s} {check.name:6s} {family:7s} {size:6d} {us:10.2f} {accepts:8.3f}")
    path = write_json("bench_grid_check" + ("_quick" if args.quick else ""),
                      {"machine": machine(), "quick": args.quick, "rows": rows, "figures": figures,
                       "note": "one core; GridCheck checks straight segments on the 512 x 512 maze image, "
                               "ExactCheck closed-loop trajectories (resolution 0.01) on box worlds: the cost "
                               "of one planner check in each world, not of the same motion"}, args.out)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
