"""Perfect mazes as occupancy grids, drawn by the library itself (no image file needed).

``maze_grid(cells, seed)`` carves a maze of ``cells`` x ``cells`` rooms by a randomized depth-first
search (the "recursive backtracker": from the current room, move to a random unvisited neighbour
and remove the wall between; when none is left, step back), which makes a *perfect* maze: exactly
one path without loops between any two rooms. The grid has (2 c + 1) x (2 c + 1) pixels: room
(i, j) is pixel (2 i + 1, 2 j + 1), the pixels between two rooms are walls unless carved, and the
border is wall. Room (0, 0) is the bottom-left one, room (c - 1, c - 1) the top-right one (image
row 0 is the top of the map, as in ``OccupancyGrid``). Corridors and walls are one pixel wide, so
the straight segments the planners draw must turn at every bend of the solution path.
"""

from __future__ import annotations

import numpy as np

from .._support.validation import check_int, check_positive_float
from .image import OccupancyGrid

__all__ = ["MAX_MAZE_CELLS", "maze_grid", "room_center"]

#: the most rooms along a side (a (2 c + 1)^2 grid well inside ``image.MAX_SIDE``)
MAX_MAZE_CELLS = 256


def maze_grid(cells: int, seed: int, pixel_size: float = 1.0) -> OccupancyGrid:
    """A perfect maze of ``cells`` x ``cells`` rooms (module docstring).

    Args:
        cells: Rooms along a side, in [2, ``MAX_MAZE_CELLS``].
        seed: The seed of the carving order (same seed, same maze).
        pixel_size: A pixel's side in world units (> 0); the map is ``(2 cells + 1) pixel_size``
            wide, its bottom-left corner at the origin.

    Returns:
        The grid; its metadata names the generator, ``cells`` and ``seed``.

    Raises:
        ValueError: ``cells`` outside [2, ``MAX_MAZE_CELLS``], a negative ``seed`` or a ``pixel_size`` that is not > 0.

    Example:
        >>> from qrrt_circuits.world.maze import maze_grid
        >>> grid = maze_grid(2, seed=0)
        >>> grid.rows, int(grid.free.sum())  # 4 rooms and the 3 openings that join them
        (5, 7)
    """
    cells = check_int(cells, "cells", 2, MAX_MAZE_CELLS)
    seed = check_int(seed, "seed", 0)
    pixel_size = check_positive_float(pixel_size, "pixel_size")
    rng = np.random.default_rng(seed)
    side = 2 * cells + 1
    free = np.zeros((side, side), dtype=bool)  # rows upward here; flipped to image rows at the end
    visited = np.zeros((cells, cells), dtype=bool)
    stack = [(0, 0)]
    visited[0, 0] = True
    free[1, 1] = True
    steps = ((0, 1), (1, 0), (0, -1), (-1, 0))
    while stack:
        i, j = stack[-1]
        options = [(i + di, j + dj) for di, dj in steps
                   if 0 <= i + di < cells and 0 <= j + dj < cells and not visited[i + di, j + dj]]
        if not options:
            stack.pop()
            continue
        ni, nj = options[int(rng.integers(len(options)))]
        visited[ni, nj] = True
        free[2 * ni + 1, 2 * nj + 1] = True
        free[i + ni + 1, j + nj + 1] = True  # the wall between the two rooms
        stack.append((ni, nj))
    return OccupancyGrid(free[::-1].copy(), pixel_size,
                         metadata={"generator": "maze", "cells": cells, "seed": seed})


def room_center(grid: OccupancyGrid, i: int, j: int) -> np.ndarray:
    """The world position of room (``i``, ``j``) of a ``maze_grid`` (``i`` the row counted upward
    from the bottom, ``j`` the column).

    Args:
        grid: A grid from ``maze_grid``.
        i: The room's row, bottom first.
        j: The room's column.

    Returns:
        (x, y).
    """
    x, y = grid.pixel_center(grid.rows - 1 - (2 * i + 1), 2 * j + 1)
    return np.array([x, y])
