"""Perfect mazes as occupancy grids, drawn by the library itself (no image file needed).

``maze_grid(cells, seed, corridor=1)`` carves a maze of ``cells`` x ``cells`` rooms by a randomized
depth-first search (the "recursive backtracker": from the current room, move to a random unvisited
neighbour and open the wall between; when none is left, step back), which makes a *perfect* maze:
exactly one path without loops between any two rooms. Rooms are ``corridor`` x ``corridor`` pixels,
walls one pixel thick, so the grid has ``cells (corridor + 1) + 1`` pixels a side. Room (i, j) is in
image row band i (row 0 the top of the map, as in ``OccupancyGrid``) and column band j; the border
is wall. With one-pixel corridors the straight segments the planners draw must turn at every bend.
"""

from __future__ import annotations

import numpy as np

from .._support.validation import check_int, check_positive_float
from .image import MAX_SIDE, OccupancyGrid

__all__ = ["maze_free", "maze_grid", "room_center"]


def maze_free(cells: int, seed: int, corridor: int = 1) -> np.ndarray:
    """The free pixels of a perfect maze (module docstring), in image orientation.

    Args:
        cells: Rooms along a side (>= 2).
        seed: The seed of the carving order (>= 0; same seed, same maze).
        corridor: A room's side in pixels (>= 1).

    Returns:
        Bool (side, side), True where free, side = cells (corridor + 1) + 1.

    Raises:
        ValueError: ``cells`` < 2, ``seed`` < 0, ``corridor`` < 1, or a side above
            ``image.MAX_SIDE``.
    """
    cells = check_int(cells, "cells", 2)
    seed = check_int(seed, "seed", 0)
    corridor = check_int(corridor, "corridor", 1)
    step = corridor + 1
    if cells * step + 1 > MAX_SIDE:
        raise ValueError(f"cells * (corridor + 1) + 1 must be at most {MAX_SIDE} pixels, got {cells * step + 1}")
    rng = np.random.default_rng(seed)
    free = np.zeros((cells * step + 1, cells * step + 1), dtype=bool)
    seen = np.zeros((cells, cells), dtype=bool)
    stack = [(0, 0)]
    seen[0, 0] = True
    free[1:1 + corridor, 1:1 + corridor] = True
    while stack:
        r, c = stack[-1]
        options = [(r + dr, c + dc) for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1))
                   if 0 <= r + dr < cells and 0 <= c + dc < cells and not seen[r + dr, c + dc]]
        if not options:
            stack.pop()
            continue
        nr, nc = options[int(rng.integers(len(options)))]
        seen[nr, nc] = True
        top, left = 1 + min(r, nr) * step, 1 + min(c, nc) * step  # both rooms and the wall between
        free[top:1 + max(r, nr) * step + corridor, left:1 + max(c, nc) * step + corridor] = True
        stack.append((nr, nc))
    return free


def maze_grid(cells: int, seed: int, pixel_size: float = 1.0, corridor: int = 1) -> OccupancyGrid:
    """A perfect maze (``maze_free``) as an ``OccupancyGrid`` with its bottom-left corner at the origin.

    Args:
        cells: Rooms along a side (>= 2).
        seed: The seed of the carving order (>= 0).
        pixel_size: A pixel's side in world units (> 0).
        corridor: A room's side in pixels (>= 1).

    Returns:
        The grid; its metadata names the generator, ``cells``, ``seed`` and ``corridor``.

    Raises:
        ValueError: As ``maze_free``, or a ``pixel_size`` that is not > 0.

    Example:
        >>> from qrrt_circuits.world.maze import maze_grid
        >>> grid = maze_grid(2, seed=0)
        >>> grid.rows, int(grid.free.sum())  # 4 rooms and the 3 openings that join them
        (5, 7)
    """
    pixel_size = check_positive_float(pixel_size, "pixel_size")
    free = maze_free(cells, seed, corridor)
    return OccupancyGrid(free, pixel_size,
                         metadata={"generator": "maze", "cells": cells, "seed": seed, "corridor": corridor})


def room_center(grid: OccupancyGrid, i: int, j: int, corridor: int = 1) -> np.ndarray:
    """The world position of the centre of room (``i``, ``j``) of a maze grid (``i`` counted from
    the top row of rooms, ``j`` from the left).

    Args:
        grid: A grid from ``maze_grid``.
        i: The room's row band, top first.
        j: The room's column band, left first.
        corridor: The grid's room side in pixels.

    Returns:
        (x, y).
    """
    step = corridor + 1
    ox, oy = grid.origin
    s = grid.pixel_size
    x = ox + (1 + j * step + corridor / 2) * s
    y = oy + (grid.rows - (1 + i * step + corridor / 2)) * s
    return np.array([x, y])
