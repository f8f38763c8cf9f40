"""The structured database: an index that names a lattice cell and a tree node.

The paper's database (Alg. 1, lines 4-8; ``planners.database.build_database``) is a list of 2^n
pairs [t; P]: t a random sample, P its nearest tree node. Its oracle can only look the pair of
index i up, so a coherent oracle over it must load 2^n coordinates (a lookup of 2^n entries, the
cost the lookup oracle pays for its marks). The lattice database is structured so that the entry is
computed from the index instead:

- the index register of n = d a + m qubits splits into fields (little-endian, qubit 0 the least
  significant): bits [j a, (j + 1) a) are the sample's cell k_j on axis j, bits [d a, d a + m) the
  parent's position in the list of tree nodes;
- cell k of 2^a per axis covers 2^(b - a) grid points of the fixed-point format; the sample is its
  centre, grid point u_c = k 2^(b - a) + floor(2^(b - a) / 2) (the cell's only point when a = b),
  so the sample's coordinate is the field itself shifted, with constant low bits: no gates;
- the parent's coordinates u_p = floor((p - lo) / s) (``FixedPointFormat.encode``) are loaded by
  a lookup over the N <= 2^m nodes only; a parent index >= N is not a tree node, and its entries
  are never marked (the lookup loads a ``valid`` bit).

Every entry is a (sample, parent) pair as in the paper, but the database holds every pairing of
the 2^(d a) cell centres with the N nodes rather than 2^n random samples, each with its nearest
node: a sample is on the lattice, not uniform, and its parent is any node, not the nearest. A
planner that wants the paper's nearest-parent pairs would have to mark only the entries whose parent
is the sample's nearest node (a coherent nearest-neighbour test, not built here).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._support.validation import check_int, check_optional_int, check_real_array
from .number_format import FixedPointFormat

#: the widest index register a database accepts (the costs scale to it; only small ones are enumerated)
MAX_INDEX_BITS = 64
#: the widest parent field (a lookup over up to 2^m nodes)
MAX_PARENT_BITS = 40
#: the widest index register ``entries`` enumerates (2^n rows)
MAX_ENUMERATED_BITS = 26


@dataclass(frozen=True)
class DatabaseEntries:
    """Database entries decoded from their indices.

    Args:
        indices: Int64 (M,): the entries' indices.
        cells: Int64 (M, d): the sample's cell per axis.
        sample_grid: Int64 (M, d): the sample's grid point u_c.
        parent_index: Int64 (M,): the parent field (a node's position when < N).
        parent_grid: Int64 (M, d): the parent's grid point u_p (0 where not valid).
        valid: Bool (M,): parent index < N.
        samples: Float (M, d): the sample's coordinates (grid points, exact).
        parents: Float (M, d): the parent's coordinates as given (NaN where not valid).
    """

    indices: np.ndarray
    cells: np.ndarray
    sample_grid: np.ndarray
    parent_index: np.ndarray
    parent_grid: np.ndarray
    valid: np.ndarray
    samples: np.ndarray
    parents: np.ndarray


@dataclass(frozen=True, eq=False)
class LatticeDatabase:
    """The index register's fields: a lattice cell per axis and a tree node (module text).

    Args:
        fmt: The ``FixedPointFormat`` of the coordinates.
        cell_bits: a, 1 .. ``fmt.bits``: 2^a cells per axis.
        nodes: Float (N, d), N >= 1, d >= 1: the tree's nodes (the candidate parents), inside the
            format's range [lo, hi).
        parent_bits: m, with 2^m >= N, at most ``MAX_PARENT_BITS`` (default: the smallest,
            ceil(log2 N)); m = 0 (one node) loads nothing, the parent being a constant.

    Raises:
        TypeError: A non-integer ``cell_bits`` / ``parent_bits`` or a format of the wrong type.
        ValueError: ``cell_bits`` or ``parent_bits`` out of range, 2^m < N, nodes of a wrong shape,
            a node outside the format's range (named ``nodes[i, axis]``), or n = d a + m above
            ``MAX_INDEX_BITS``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits.coherent import FixedPointFormat, LatticeDatabase
        >>> db = LatticeDatabase(FixedPointFormat(4, 0.0, 16.0), 2, np.array([[1.0, 1.0], [9.5, 3.0]]))
        >>> db.num_index_bits, db.parent_bits, db.cell_grid(np.arange(4)).tolist()  # centres 2, 6, 10, 14
        (5, 1, [2, 6, 10, 14])
        >>> entry = db.entries(np.array([db.index_of([3, 0], 1)]))
        >>> entry.samples.tolist(), entry.parents.tolist(), entry.parent_grid.tolist()
        ([[14.0, 2.0]], [[9.5, 3.0]], [[9, 3]])
    """

    fmt: FixedPointFormat
    cell_bits: int
    nodes: np.ndarray
    parent_bits: int | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.fmt, FixedPointFormat):
            raise TypeError(f"fmt must be a FixedPointFormat, got {type(self.fmt).__name__}")
        cell_bits = check_int(self.cell_bits, "cell_bits", 1, self.fmt.bits)
        nodes = check_real_array(self.nodes, "nodes")
        if nodes.ndim != 2 or nodes.shape[0] < 1 or nodes.shape[1] < 1:
            raise ValueError(f"nodes must have shape (N, d) with N >= 1, got {nodes.shape}")
        count = nodes.shape[0]
        smallest = max(count - 1, 0).bit_length()
        parent_bits = check_optional_int(self.parent_bits, "parent_bits", smallest, MAX_PARENT_BITS)
        parent_bits = smallest if parent_bits is None else parent_bits
        total = nodes.shape[1] * cell_bits + parent_bits
        if total > MAX_INDEX_BITS:
            raise ValueError(f"the index register would have n = d a + m = {total} qubits, more than "
                             f"{MAX_INDEX_BITS}: lower cell_bits (got {cell_bits}) or parent_bits (got {parent_bits})")
        grid = self.fmt.encode(nodes, "nodes")
        for array in (nodes, grid):
            array.setflags(write=False)
        object.__setattr__(self, "cell_bits", cell_bits)
        object.__setattr__(self, "nodes", nodes)
        object.__setattr__(self, "parent_bits", parent_bits)
        object.__setattr__(self, "_node_grid", grid)

    @property
    def dim(self) -> int:
        """d."""
        return int(self.nodes.shape[1])

    @property
    def num_nodes(self) -> int:
        """N, the tree nodes."""
        return int(self.nodes.shape[0])

    @property
    def num_index_bits(self) -> int:
        """n = d a + m."""
        return self.dim * self.cell_bits + int(self.parent_bits or 0)

    @property
    def num_entries(self) -> int:
        """2^n."""
        return 1 << self.num_index_bits

    @property
    def node_grid(self) -> np.ndarray:
        """The nodes' grid points u_p: int64 (N, d), read-only."""
        grid: np.ndarray = self.__dict__["_node_grid"]
        return grid

    @property
    def cell_shift(self) -> int:
        """b - a: a cell spans 2^(b - a) grid points."""
        return self.fmt.bits - self.cell_bits

    @property
    def cell_offset(self) -> int:
        """floor(2^(b - a) / 2): the centre's offset from the cell's first grid point."""
        return (1 << self.cell_shift) >> 1

    def cell_grid(self, cells: np.ndarray) -> np.ndarray:
        """The sample's grid point u_c = k 2^(b - a) + ``cell_offset`` of cells k (int64)."""
        return (np.asarray(cells, dtype=np.int64) << self.cell_shift) + self.cell_offset

    def index_of(self, cells: np.ndarray, parent: int) -> int:
        """The index of the entry (cell per axis, parent position).

        Args:
            cells: d cell numbers, each in [0, 2^a).
            parent: The parent field, in [0, 2^m).

        Returns:
            The index sum_j k_j 2^(j a) + parent 2^(d a).

        Raises:
            ValueError: A cell or parent out of range, or not d cells.
        """
        checked = [check_int(k, f"cells[{j}]", 0, (1 << self.cell_bits) - 1) for j, k in enumerate(cells)]
        if len(checked) != self.dim:
            raise ValueError(f"cells must have d = {self.dim} entries, got {len(checked)}")
        parent = check_int(parent, "parent", 0, (1 << int(self.parent_bits or 0)) - 1)
        index = parent << (self.dim * self.cell_bits)
        for j, k in enumerate(checked):
            index |= k << (j * self.cell_bits)
        return index

    def entries(self, indices: np.ndarray | None = None) -> DatabaseEntries:
        """Decode entries (default: all 2^n, for n <= ``MAX_ENUMERATED_BITS``).

        Args:
            indices: Int array of indices in [0, 2^n), or None for all.

        Returns:
            The ``DatabaseEntries``.

        Raises:
            ValueError: ``indices`` None with n > ``MAX_ENUMERATED_BITS``, or an index out of range.
        """
        n = self.num_index_bits
        if indices is None:
            if n > MAX_ENUMERATED_BITS:
                raise ValueError(f"entries() enumerates 2^n rows: n must be <= {MAX_ENUMERATED_BITS}, got {n}")
            indices = np.arange(1 << n, dtype=np.int64)
        indices = np.asarray(indices, dtype=np.int64).reshape(-1)
        if indices.size and (indices.min() < 0 or indices.max() >= (1 << n)):
            raise ValueError(f"indices must lie in [0, 2^{n})")
        a, d = self.cell_bits, self.dim
        mask = (1 << a) - 1
        cells = np.stack([(indices >> (j * a)) & mask for j in range(d)], axis=1)
        parent_index = indices >> (d * a)
        valid = parent_index < self.num_nodes
        safe = np.where(valid, parent_index, 0)
        parent_grid = np.where(valid[:, None], self.node_grid[safe], 0)
        parents = np.where(valid[:, None], self.nodes[safe], np.nan)
        sample_grid = self.cell_grid(cells)
        return DatabaseEntries(indices, cells, sample_grid, parent_index, parent_grid, valid,
                               self.fmt.decode(sample_grid), parents)
