"""Where a force acting on a few nodes puts its Jacobian in the sparse matrix, in either dimension.

Exudyn's ``ObjectGenericODE2`` takes a sparse Jacobian as triplets (row, column, value). An item
that acts on k nodes (a bending joint on 3, an axial element on 2, a node contact on 1) fills the
dense (k d) x (k d) block over its nodes' d coordinates each; :func:`block_pattern` gives the rows and
columns of every item's block, and the item's values kernel fills the values in the same order
(row-major over node-major coordinates: node 0's x, y(, z), node 1's ...). No Exudyn here.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["block_pattern"]


@njit(cache=True)
def block_pattern(items, dimension):
    """Rows and columns, shape (N (k d)^2,) each, of the dense block of each of the ``items`` (N, k) (the
    nodes each acts on) over its nodes' coordinates, d = ``dimension`` per node (node ``i``'s are
    ``d i .. d i + d - 1``): item ``j``'s block at ``[j (k d)^2, (j + 1) (k d)^2)``, row-major."""
    n, k = items.shape[0], items.shape[1]
    size = k * dimension
    rows = np.empty(n * size * size, dtype=np.int64)
    columns = np.empty(n * size * size, dtype=np.int64)
    for j in range(n):
        for i in range(size):
            row = dimension * items[j, i // dimension] + i % dimension
            for m in range(size):
                rows[size * size * j + size * i + m] = row
                columns[size * size * j + size * i + m] = dimension * items[j, m // dimension] + m % dimension
    return rows, columns
