"""Where a force acting on a few nodes puts its Jacobian in the sparse matrix, in either dimension.

Exudyn's ``ObjectGenericODE2`` takes a sparse Jacobian as triplets (row, column, value). An item
that acts on k nodes (a bending joint on 3, an axial element on 2, a node contact on 1) fills the
dense (k d) x (k d) block over its nodes' d coordinates each; :func:`block_pattern` gives the rows and
columns of every item's block, and the item's values kernel fills the values in the same order
(row-major over node-major coordinates: node 0's x, y(, z), node 1's ...). Neighbouring items' blocks
overlap (a node's block holds every joint and element it belongs to): :func:`distinct_places` and
:func:`sum_into_places` hand Exudyn each place off the diagonal once, its values summed in the items'
order (half the triplets for a cable with bending, 2.0x fewer in space and 1.8x in the plane, which
Exudyn copies, sorts and sums at every Jacobian: x1.05-1.13 of a run's CPU time). No Exudyn here.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["block_pattern", "distinct_places", "sum_into_places"]


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


def distinct_places(rows, columns):
    """The places of a triplet pattern whose entries repeat: their rows and columns (P,) each, and ``slot`` (T,),
    each of the T entries' place (``rows``, ``columns`` (T,) int). Off the diagonal each place once; on it every
    entry stays a place of its own, because Exudyn adds its mass term there and sums what it is handed in its own
    order: so the sums are Exudyn's to the last bit (measured: planar and point-exit spatial runs bit for bit;
    summed on the diagonal too, 1e-13 m apart)."""
    rows, columns = np.asarray(rows, dtype=np.int64), np.asarray(columns, dtype=np.int64)
    size = int(max(rows.max(initial=0), columns.max(initial=0))) + 1
    keys = np.where(rows == columns, size * size + np.arange(rows.size), rows * size + columns)
    _, first, slot = np.unique(keys, return_index=True, return_inverse=True)
    return rows[first], columns[first], slot.astype(np.int64).reshape(-1)


@njit(cache=True)
def sum_into_places(values, slot, triplets):
    """Overwrite the values column ``triplets[:, 2]`` (P, 3) with the sums of ``values`` (T,) by place
    ``slot`` (T,) (:func:`distinct_places`), each sum taken in the entries' order; returns ``triplets``."""
    triplets[:, 2] = 0.0
    for k in range(values.size):
        triplets[slot[k], 2] += values[k]
    return triplets
