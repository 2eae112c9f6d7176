"""Pulley rim contact on cable *segments* (the elements between nodes): numba kernels.

Node contact (:mod:`cdpr_exu.physics.node_contact`) lets a straight element span the wrap as a
chord through the disc. Here the contact acts on the element itself: for a segment
from node a to node b and a pulley of centre c and radius r,

    s  = ((c - p_a) . (p_b - p_a)) / |p_b - p_a|^2,     t = clamp(s, 0, 1),
    P  = p_a + t (p_b - p_a)          (the point of the segment closest to c),
    d  = |P - c|,   n = (P - c) / d   (outward normal),
    v_n = n . v_P,  v_P = (1 - t) v_a + t v_b   (normal velocity of that material point),

and if d < r the normal force is

    F = max(0, k_p (r - d) - c_p v_n)

pushing P outward along n; the nodes share it by the lever rule, f_a = (1 - t) F n and
f_b = t F n. The clamp of F at zero is the one of Exudyn's sphere contact (which this
replaces): damping may resist a node that leaves the rim but never pull the cable into
the pulley; a contact that separates faster than k_p (r - d) / c_p simply lets go.

**Endpoints.** Each listed segment counts its own closest point with full weight. When
the closest points of both segments next to a node clamp to that node (t = 1 on one, t = 0
on the other: a corner pointing into the disc), the node is pushed by both, i.e. with
2 k_p. This is deliberate: the spring part is then the gradient of the potential
V = sum_s k_p (r - d_s)_+^2 / 2 (envelope theorem: dd/dp_a = (1 - t) n, dd/dp_b = t n),
continuous with a symmetric stiffness, and no rule that counts such a node once can be
continuous (just outside that configuration both feet lie inside their segments and each
must count fully). The doubled corner only arises for a cable kinked into the pulley; on
the paper's circle no active contact ever sat at a segment end.

Coordinates are flat arrays ``x0, y0, x1, y1, ...`` [m, m/s] over a global node list (as
in an Exudyn ``ObjectGenericODE2`` over ``NodePoint2D`` nodes); each segment carries its
own pulley (centre, radius, k_p, c_p), so the segments of all cables share one call.

:class:`SegmentPulleyContact` validates once; the kernels ``*_kernel`` do no checks. This
module does not import Exudyn.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import per_item, points_per_item, whole_array

__all__ = ["SegmentPulleyContact", "contact_segments", "segment_contact_force_kernel",
           "segment_contact_jacobian_kernel"]

#: Below this distance from the centre [m] the normal is undefined: the segment passes
#: through the pulley centre, far beyond any penetration a run may survive.
_MIN_DISTANCE = 1.0e-12


# --------------------------------------------------------------------------- kernels

@njit(cache=True)
def _closest_point(positions, velocities, a, b, cx, cy):
    """Closest point of segment (a, b) to (cx, cy).

    Returns ``(t, interior, px, py, ex, ey, d, nx, ny, vn, s)``: the clamped parameter,
    whether it is strictly inside (0, 1), the point, the segment vector, the distance,
    the outward normal, the normal velocity of the material point at t, and the
    unclamped parameter s.
    """
    ax = positions[2 * a]
    ay = positions[2 * a + 1]
    ex = positions[2 * b] - ax
    ey = positions[2 * b + 1] - ay
    wx = cx - ax
    wy = cy - ay
    length2 = ex * ex + ey * ey
    s = (wx * ex + wy * ey) / length2 if length2 > 0.0 else 0.0
    interior = 0.0 < s < 1.0
    t = s if interior else (0.0 if s <= 0.0 else 1.0)
    px = ax + t * ex
    py = ay + t * ey
    rx = px - cx
    ry = py - cy
    d = np.sqrt(rx * rx + ry * ry)
    nx = rx / d if d > _MIN_DISTANCE else 0.0
    ny = ry / d if d > _MIN_DISTANCE else 0.0
    vx = (1.0 - t) * velocities[2 * a] + t * velocities[2 * b]
    vy = (1.0 - t) * velocities[2 * a + 1] + t * velocities[2 * b + 1]
    return t, interior, px, py, ex, ey, d, nx, ny, nx * vx + ny * vy, s


@njit(cache=True)
def segment_contact_force_kernel(positions, velocities, segments, centers, radii, stiffness, damping, out):
    """Add the segment contact forces to ``out`` (2N,) [N] and return it (unchecked).

    ``positions``, ``velocities`` (2N,) [m, m/s]; ``segments`` (S, 2), ``centers`` (S, 2) [m], ``radii``,
    ``stiffness``, ``damping`` (S,) [m, N/m, N s/m] as :class:`SegmentPulleyContact`'s.
    """
    for k in range(segments.shape[0]):
        a = segments[k, 0]
        b = segments[k, 1]
        t, interior, px, py, ex, ey, d, nx, ny, vn, s = _closest_point(
            positions, velocities, a, b, centers[k, 0], centers[k, 1])
        if d >= radii[k] or d <= _MIN_DISTANCE:
            continue
        force = stiffness[k] * (radii[k] - d) - damping[k] * vn
        if force <= 0.0:
            continue
        out[2 * a] += (1.0 - t) * force * nx
        out[2 * a + 1] += (1.0 - t) * force * ny
        out[2 * b] += t * force * nx
        out[2 * b + 1] += t * force * ny
    return out


@njit(cache=True)
def segment_contact_jacobian_kernel(positions, velocities, segments, centers, radii, stiffness, damping,
                                    factor_position, factor_velocity, out):
    """Add ``factor_position * K + factor_velocity * D`` of the segment contacts to ``out`` (unchecked).

    K = -df/dq [N/m] and D = -df/dv [N s/m], shape (2N, 2N), the left-hand-side Jacobians
    Exudyn expects; zero for a segment out of contact or whose clamped force is zero.
    With g = dd/dq = ((1 - t) n, t n) (4,) the force of a segment is f = F g, and

        K = g (k_p g + c_p dv_n/dq)^T - F dg/dq,      D = c_p g g^T,

    where, with J = dP/dq = ((1 - t) I, t I) + e (dt/dq)^T (dt/dq = 0 when clamped),
    dn/dq = (I - n n^T) J / d, dv_n/dq = v_P^T dn/dq + (n . (v_b - v_a)) dt/dq and
    dg/dq = ((1 - t) dn/dq - n dt/dq^T ; t dn/dq + n dt/dq^T).
    """
    grad_t = np.empty(4)
    jac_p = np.empty((2, 4))
    dn = np.empty((2, 4))
    dvn = np.empty(4)
    g = np.empty(4)
    dg = np.empty((4, 4))
    index = np.empty(4, dtype=np.int64)
    for k in range(segments.shape[0]):
        a = segments[k, 0]
        b = segments[k, 1]
        cx = centers[k, 0]
        cy = centers[k, 1]
        t, interior, px, py, ex, ey, d, nx, ny, vn, s = _closest_point(positions, velocities, a, b, cx, cy)
        if d >= radii[k] or d <= _MIN_DISTANCE:
            continue
        kp = stiffness[k]
        cp = damping[k]
        force = kp * (radii[k] - d) - cp * vn
        if force <= 0.0:
            continue
        # dt/dq: ds/dp_a = ((2 s - 1) e - w) / |e|^2, ds/dp_b = (w - 2 s e) / |e|^2
        if interior:
            length2 = ex * ex + ey * ey
            wx = cx - positions[2 * a]
            wy = cy - positions[2 * a + 1]
            grad_t[0] = ((2.0 * s - 1.0) * ex - wx) / length2
            grad_t[1] = ((2.0 * s - 1.0) * ey - wy) / length2
            grad_t[2] = (wx - 2.0 * s * ex) / length2
            grad_t[3] = (wy - 2.0 * s * ey) / length2
        else:
            for i in range(4):
                grad_t[i] = 0.0
        # J = dP/dq
        for i in range(2):
            for j in range(4):
                jac_p[i, j] = 0.0
        jac_p[0, 0] = 1.0 - t
        jac_p[1, 1] = 1.0 - t
        jac_p[0, 2] = t
        jac_p[1, 3] = t
        for j in range(4):
            jac_p[0, j] += ex * grad_t[j]
            jac_p[1, j] += ey * grad_t[j]
        # dn/dq = (I - n n^T) J / d
        p00 = (1.0 - nx * nx) / d
        p01 = -nx * ny / d
        p11 = (1.0 - ny * ny) / d
        for j in range(4):
            dn[0, j] = p00 * jac_p[0, j] + p01 * jac_p[1, j]
            dn[1, j] = p01 * jac_p[0, j] + p11 * jac_p[1, j]
        vx = (1.0 - t) * velocities[2 * a] + t * velocities[2 * b]
        vy = (1.0 - t) * velocities[2 * a + 1] + t * velocities[2 * b + 1]
        relative_n = nx * (velocities[2 * b] - velocities[2 * a]) + ny * (velocities[2 * b + 1] - velocities[2 * a + 1])
        for j in range(4):
            dvn[j] = vx * dn[0, j] + vy * dn[1, j] + relative_n * grad_t[j]
        g[0] = (1.0 - t) * nx
        g[1] = (1.0 - t) * ny
        g[2] = t * nx
        g[3] = t * ny
        for j in range(4):
            dg[0, j] = (1.0 - t) * dn[0, j] - nx * grad_t[j]
            dg[1, j] = (1.0 - t) * dn[1, j] - ny * grad_t[j]
            dg[2, j] = t * dn[0, j] + nx * grad_t[j]
            dg[3, j] = t * dn[1, j] + ny * grad_t[j]
        index[0] = 2 * a
        index[1] = 2 * a + 1
        index[2] = 2 * b
        index[3] = 2 * b + 1
        for i in range(4):
            for j in range(4):
                stiff = g[i] * (kp * g[j] + cp * dvn[j]) - force * dg[i, j]
                out[index[i], index[j]] += factor_position * stiff + factor_velocity * cp * g[i] * g[j]
    return out


# --------------------------------------------------------------------------- validation

def _segments(segments, n_nodes):
    array = np.ascontiguousarray(whole_array("segments", segments), dtype=np.int64)
    if array.ndim != 2 or array.shape[1] != 2:
        raise SceneError(f"segments must be an integer array (n_segments, 2); got shape {array.shape}")
    if array.size:
        if array.min() < 0 or array.max() >= n_nodes:
            raise SceneError(f"segments refer to nodes outside 0..{n_nodes - 1}: min {array.min()}, max {array.max()}")
        if (array[:, 0] == array[:, 1]).any():
            raise SceneError("segments must join two different nodes")
    return array


# --------------------------------------------------------------------------- public API

def contact_segments(candidate_nodes, n_elements: int) -> np.ndarray:
    """Elements of one cable that touch a candidate node (cable-local, sorted, unique int64).

    Element j joins nodes j and j + 1; a node that can reach the pulley brings both its
    elements, so the segments of the wrap and the ones leaving it are all listed.
    """
    nodes = np.asarray(whole_array("candidate_nodes", candidate_nodes), dtype=np.int64).reshape(-1)
    elements = np.concatenate([nodes - 1, nodes])
    return np.unique(elements[(elements >= 0) & (elements < int(n_elements))])


class SegmentPulleyContact:
    """Rim contacts of a set of segments with their pulleys, validated once, for the hot path.

    ``n_nodes`` of all cables (coordinates (2 n_nodes,)); ``segments`` (S, 2) global node pairs;
    ``centers`` (2,) or (S, 2) [m]; ``radii``, ``stiffness`` k_p and ``damping`` c_p per segment or
    scalars [m, N/m, N s/m].

    ``add_force`` and ``add_jacobian`` accumulate into arrays the caller owns (the cables'
    generic object adds bending, slack and contact into one buffer).
    """

    def __init__(self, n_nodes, segments, centers, radii, stiffness, damping):
        n_nodes = int(n_nodes)
        if n_nodes < 2:
            raise SceneError(f"n_nodes must be >= 2; got {n_nodes}")
        self.n_coordinates = 2 * n_nodes
        self.segments = _segments(segments, n_nodes)
        n = self.segments.shape[0]
        self.centers = points_per_item("centers", centers, n)
        self.radii = per_item("radii", radii, n, positive=True)
        self.stiffness = per_item("stiffness", stiffness, n)
        self.damping = per_item("damping", damping, n)

    def _check(self, name, values):
        if not (type(values) is np.ndarray and values.dtype == np.float64 and values.flags.c_contiguous):
            values = np.ascontiguousarray(values, dtype=np.float64)
        if values.shape != (self.n_coordinates,):
            raise SceneError(f"{name} must have shape ({self.n_coordinates},); got {values.shape}")
        return values

    def add_force(self, positions, velocities, out):
        """Add the contact forces (2 n_nodes,) [N] to ``out`` and return it."""
        return segment_contact_force_kernel(self._check("positions", positions), self._check("velocities", velocities),
                                            self.segments, self.centers, self.radii, self.stiffness, self.damping, out)

    def add_jacobian(self, positions, velocities, factor_position, factor_velocity, out):
        """Add ``factor_position * K + factor_velocity * D`` (2 n_nodes, 2 n_nodes) to ``out``."""
        return segment_contact_jacobian_kernel(
            self._check("positions", positions), self._check("velocities", velocities), self.segments, self.centers,
            self.radii, self.stiffness, self.damping, float(factor_position), float(factor_velocity), out)
