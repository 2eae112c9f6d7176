"""Bending spring-damper of a lumped-mass cable, planar, with the exact relative angle.

A *joint* is a triplet ``(a, b, c)`` of global node indices; for a cable these are
consecutive nodes ``(b - 1, b, b + 1)``, but any triplets are accepted, so that all the
cables of a scene can share one call over one global node list. For a joint,

    e1 = p_b - p_a,    e2 = p_c - p_b,
    dtheta = atan2(e1 x e2, e1 . e2)  in (-pi, pi]      (exact, valid for large angles)

and the joint moment is ``M = k dtheta + c dtheta_dot`` with ``dtheta_dot = grad(dtheta) . v``.
The potential is ``V = k dtheta^2 / 2`` and the generalized force on the nodes is
``f = -M grad_p(dtheta)``. With ``g(e) = (-e_y, e_x) / |e|^2``, the gradient of
``atan2(e_y, e_x)``:

    d dtheta / d p_a = g(e1),   d dtheta / d p_b = -g(e1) - g(e2),   d dtheta / d p_c = g(e2).

The tangent matrices are ``K = -df/dq = G (k G + c H v)^T + M H`` and ``D = -df/dv = c G G^T``
per joint, with ``G`` the (6,) gradient and ``H`` the (6, 6) Hessian of ``dtheta`` in
``(p_a, p_b, p_c)``; the Hessian of ``atan2(e_y, e_x)`` is
``1/|e|^4 [[2 e_x e_y, e_y^2 - e_x^2], [e_y^2 - e_x^2, -2 e_x e_y]]``.
``K`` is not symmetric when ``c != 0`` (the velocity-dependent term).

Coordinates are flat, ``(2 n_nodes,)``, ordered ``x0, y0, x1, y1, ...`` as in an Exudyn
``ObjectGenericODE2`` over ``NodePoint2D`` nodes. Note that Exudyn passes the
*displacement* ``q`` to user functions: add the reference positions before calling.

Also here: the linear curvature-vector spring ``(k / l^2) |p_a - 2 p_b + p_c|^2 / 2``, a
cheaper small-angle alternative with constant matrices (see ``curvature_stiffness_matrix``).

``BendingSpringDamper`` validates joints and parameters once and owns its output buffers;
the numba kernels (``*_kernel``) do no checks. This module does not import Exudyn.
"""

import numpy as np
from numba import njit

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import flat_coordinates, per_item, whole_array

__all__ = ["BendingSpringDamper", "cable_joints", "bending_angles", "bending_energy",
           "curvature_stiffness_matrix", "bending_force_kernel", "bending_jacobian_kernel"]


# --------------------------------------------------------------------------- kernels

@njit(cache=True, fastmath=False)
def _joint_geometry(positions, velocities, a, b, c, grad, hess):
    """Angle, angular rate, gradient (6,) and Hessian (6, 6) of one joint (writes grad, hess).

    Returns ``(dtheta, dtheta_dot)``. ``hess`` is only filled when its size is 36.
    """
    e1x = positions[2 * b] - positions[2 * a]
    e1y = positions[2 * b + 1] - positions[2 * a + 1]
    e2x = positions[2 * c] - positions[2 * b]
    e2y = positions[2 * c + 1] - positions[2 * b + 1]
    dtheta = np.arctan2(e1x * e2y - e1y * e2x, e1x * e2x + e1y * e2y)
    r1 = 1.0 / (e1x * e1x + e1y * e1y)
    r2 = 1.0 / (e2x * e2x + e2y * e2y)
    g1x = -e1y * r1
    g1y = e1x * r1
    g2x = -e2y * r2
    g2y = e2x * r2
    grad[0] = g1x
    grad[1] = g1y
    grad[2] = -g1x - g2x
    grad[3] = -g1y - g2y
    grad[4] = g2x
    grad[5] = g2y
    dtheta_dot = (grad[0] * velocities[2 * a] + grad[1] * velocities[2 * a + 1]
                  + grad[2] * velocities[2 * b] + grad[3] * velocities[2 * b + 1]
                  + grad[4] * velocities[2 * c] + grad[5] * velocities[2 * c + 1])
    if hess.shape[0] == 6:
        # Hessian of atan2(e_y, e_x): 1/|e|^4 [[2 xy, y^2 - x^2], [y^2 - x^2, -2 xy]]
        h1xx = 2.0 * e1x * e1y * r1 * r1
        h1xy = (e1y * e1y - e1x * e1x) * r1 * r1
        h2xx = 2.0 * e2x * e2y * r2 * r2
        h2xy = (e2y * e2y - e2x * e2x) * r2 * r2
        # dtheta = theta(e2) - theta(e1); blocks in (p_a, p_b, p_c):
        # aa = -H1, ab = +H1, bb = -H1 + H2, bc = -H2, cc = +H2, ac = 0
        for i in range(6):
            for j in range(6):
                hess[i, j] = 0.0
        # the first four blocks carry H1 (segment 1), the last four H2 (segment 2)
        blocks = ((0, 0, -1.0), (0, 1, 1.0), (1, 0, 1.0), (1, 1, -1.0),
                  (1, 1, 1.0), (1, 2, -1.0), (2, 1, -1.0), (2, 2, 1.0))
        for k in range(8):
            blk = blocks[k]
            hxx, hxy = (h1xx, h1xy) if k < 4 else (h2xx, h2xy)
            i0 = 2 * blk[0]
            j0 = 2 * blk[1]
            s = blk[2]
            hess[i0, j0] += s * hxx
            hess[i0, j0 + 1] += s * hxy
            hess[i0 + 1, j0] += s * hxy
            hess[i0 + 1, j0 + 1] -= s * hxx
    return dtheta, dtheta_dot


@njit(cache=True)
def bending_force_kernel(positions, velocities, joints, stiffness, damping, out):
    """Unchecked kernel of ``BendingSpringDamper.force``: overwrites ``out`` (2N,) with the force [N]."""
    out[:] = 0.0
    grad = np.empty(6)
    no_hess = np.empty((0, 0))
    for j in range(joints.shape[0]):
        a = joints[j, 0]
        b = joints[j, 1]
        c = joints[j, 2]
        dtheta, dtheta_dot = _joint_geometry(positions, velocities, a, b, c, grad, no_hess)
        moment = stiffness[j] * dtheta + damping[j] * dtheta_dot
        out[2 * a] -= moment * grad[0]
        out[2 * a + 1] -= moment * grad[1]
        out[2 * b] -= moment * grad[2]
        out[2 * b + 1] -= moment * grad[3]
        out[2 * c] -= moment * grad[4]
        out[2 * c + 1] -= moment * grad[5]
    return out


@njit(cache=True)
def _joint_terms(positions, velocities, joints, j, stiffness, damping, grad, hess, index, hess_v):
    """Geometry of joint j for the tangent matrices: fills grad (6,), hess (6, 6), the
    coordinate indices ``index`` (6,) and ``hess_v`` = H v (6,) = d(dtheta_dot)/dq; returns
    the moment k dtheta + d dtheta_dot [N m]."""
    dtheta, dtheta_dot = _joint_geometry(positions, velocities, joints[j, 0], joints[j, 1], joints[j, 2], grad, hess)
    for node in range(3):
        index[2 * node] = 2 * joints[j, node]
        index[2 * node + 1] = 2 * joints[j, node] + 1
    for i in range(6):
        s = 0.0
        for m in range(6):
            s += hess[i, m] * velocities[index[m]]
        hess_v[i] = s  # d(dtheta_dot)/dq_i (H symmetric)
    return stiffness[j] * dtheta + damping[j] * dtheta_dot


@njit(cache=True)
def bending_jacobian_kernel(positions, velocities, joints, stiffness, damping,
                            factor_position, factor_velocity, out_force, out_k, out_d):
    """Unchecked kernel of the force and tangent matrices.

    Overwrites ``out_force`` (2N,) with f; if ``out_d`` has size 0, overwrites ``out_k``
    (2N, 2N) with ``factor_position * K + factor_velocity * D``, else ``out_k`` with K and
    ``out_d`` with D (factors ignored). ``out_force`` may have size 0 to skip the force.
    """
    separate = out_d.shape[0] != 0
    want_force = out_force.shape[0] != 0
    if want_force:
        out_force[:] = 0.0
    out_k[:, :] = 0.0
    if separate:
        out_d[:, :] = 0.0
    grad = np.empty(6)
    hess = np.empty((6, 6))
    index = np.empty(6, dtype=np.int64)
    hess_v = np.empty(6)
    for j in range(joints.shape[0]):
        moment = _joint_terms(positions, velocities, joints, j, stiffness, damping, grad, hess, index, hess_v)
        k = stiffness[j]
        d = damping[j]
        if want_force:
            for i in range(6):
                out_force[index[i]] -= moment * grad[i]
        if separate:
            for i in range(6):
                gi = grad[i]
                for m in range(6):
                    out_k[index[i], index[m]] += gi * (k * grad[m] + d * hess_v[m]) + moment * hess[i, m]
                    out_d[index[i], index[m]] += d * gi * grad[m]
        else:
            for i in range(6):
                gi = grad[i]
                for m in range(6):
                    out_k[index[i], index[m]] += (
                        factor_position * (gi * (k * grad[m] + d * hess_v[m]) + moment * hess[i, m])
                        + factor_velocity * d * gi * grad[m])
    return out_force


@njit(cache=True)
def bending_triplet_values(positions, velocities, joints, stiffness, damping, factor_position, factor_velocity,
                           out_values):
    """Values of ``factor_position * K + factor_velocity * D`` at
    :func:`~cdpr_exu.physics.sparse_blocks.block_pattern`'s places (overwrites ``out_values``, shape (36 J,)): the same numbers the dense kernel adds, in
    36-entry blocks per joint, so the Jacobian costs O(J) instead of O(N^2)."""
    grad = np.empty(6)
    hess = np.empty((6, 6))
    index = np.empty(6, dtype=np.int64)
    hess_v = np.empty(6)
    for j in range(joints.shape[0]):
        moment = _joint_terms(positions, velocities, joints, j, stiffness, damping, grad, hess, index, hess_v)
        k = stiffness[j]
        d = damping[j]
        for i in range(6):
            gi = grad[i]
            for m in range(6):
                out_values[36 * j + 6 * i + m] = (
                    factor_position * (gi * (k * grad[m] + d * hess_v[m]) + moment * hess[i, m])
                    + factor_velocity * d * gi * grad[m])
    return out_values


# --------------------------------------------------------------------------- validation

def _as_joints(joints, n_nodes):
    array = np.ascontiguousarray(whole_array("joints", joints))
    if array.ndim != 2 or array.shape[1] != 3:
        raise SceneError(f"joints must be an integer array (n_joints, 3); got shape {array.shape}")
    if array.size:
        low, high = array.min(), array.max()
        if low < 0 or high >= n_nodes:
            raise SceneError(f"joints refer to nodes outside 0..{n_nodes - 1}: min {low}, max {high}")
        if ((array[:, 0] == array[:, 1]) | (array[:, 1] == array[:, 2])).any():
            raise SceneError("joints must not repeat a node in (a, b) or (b, c): the element would have zero length")
    return array


_EMPTY_VECTOR = np.empty(0)


# --------------------------------------------------------------------------- public API

def cable_joints(nodes_per_cable):
    """Joint triplets ``(b - 1, b, b + 1)``, shape (sum(n_i - 2), 3), of every interior node ``b`` of
    cables of ``nodes_per_cable`` nodes each, numbered consecutively, cable after cable."""
    rows = []
    first = 0
    for n in whole_array("nodes_per_cable", nodes_per_cable).reshape(-1):
        n = int(n)
        if n < 2:
            raise SceneError(f"nodes_per_cable entries must be >= 2; got {n}")
        middle = np.arange(first + 1, first + n - 1, dtype=np.int64)
        rows.append(np.stack([middle - 1, middle, middle + 1], axis=1))
        first += n
    if not rows:
        return np.empty((0, 3), dtype=np.int64)
    return np.concatenate(rows, axis=0)


def bending_angles(positions, joints):
    """Relative angle (n_joints,) [rad] in (-pi, pi] of each joint (a, b, c), ``atan2(e1 x e2, e1 . e2)``,
    at node positions (2 n_nodes,) [m]: positive when the cable turns counter-clockwise from a-b to b-c."""
    positions = flat_coordinates("positions", positions)
    joints = _as_joints(joints, positions.shape[0] // 2)
    p = positions.reshape(-1, 2)
    e1 = p[joints[:, 1]] - p[joints[:, 0]]
    e2 = p[joints[:, 2]] - p[joints[:, 1]]
    cross = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    dot = np.einsum("ij,ij->i", e1, e2)
    return np.arctan2(cross, dot)


def bending_energy(positions, joints, stiffness):
    """Elastic bending energy ``sum_j k_j dtheta_j^2 / 2`` [J], k (n_joints,) or scalar [N m/rad]."""
    dtheta = bending_angles(positions, joints)
    stiffness = per_item("stiffness", stiffness, dtheta.shape[0])
    return 0.5 * float(np.dot(stiffness, dtheta * dtheta))


def curvature_stiffness_matrix(n_nodes, joints, stiffness, element_length):
    """Constant matrix of the linear curvature-vector spring ``(k / l^2) |p_a - 2 p_b + p_c|^2 / 2``.

    For equal element lengths ``l`` and small angles ``|p_a - 2 p_b + p_c| ~ l dtheta``, so
    the energy tends to ``k dtheta^2 / 2``; at large angles (wrapped joints) it differs.
    The force is ``-K q``: zero for any straight, evenly spaced cable.

    ``stiffness`` k [N m/rad] and ``element_length`` l [m] per joint (or scalars); ``n_nodes`` of all
    cables. Returns K (2 n_nodes, 2 n_nodes) [N/m], symmetric positive semi-definite; with the damping
    c_theta in place of ``stiffness``, the constant damping matrix D [N s/m].
    """
    n_nodes = int(n_nodes)
    if n_nodes < 0:
        raise SceneError(f"n_nodes must be >= 0; got {n_nodes}")
    joints = _as_joints(joints, n_nodes)
    stiffness = per_item("stiffness", stiffness, joints.shape[0])
    element_length = per_item("element_length", element_length, joints.shape[0], positive=True)
    coefficient = stiffness / element_length**2
    matrix = np.zeros((2 * n_nodes, 2 * n_nodes))
    weights = np.array([1.0, -2.0, 1.0])
    outer = np.outer(weights, weights)  # B^T B per coordinate direction
    for j in range(joints.shape[0]):
        for r in range(3):
            for s in range(3):
                value = coefficient[j] * outer[r, s]
                for axis in range(2):
                    matrix[2 * joints[j, r] + axis, 2 * joints[j, s] + axis] += value
    return matrix


class BendingSpringDamper:
    """Exact-angle bending spring-dampers of a set of joints, validated once, for the hot path.

    Joints, stiffness and damping are checked and stored when made; each call only checks
    the coordinate arrays and runs the numba kernel into buffers owned by the object.

    ``n_nodes`` of all cables (coordinates (2 n_nodes,)); ``joints`` (n_joints, 3) node triplets (a, b, c);
    ``stiffness`` and ``damping`` per joint or scalars [N m/rad, N m s/rad]. The returned arrays are the
    object's buffers, overwritten by the next call of the same method.
    """

    def __init__(self, n_nodes, joints, stiffness, damping):
        n_nodes = int(n_nodes)
        if n_nodes < 1:
            raise SceneError(f"n_nodes must be >= 1; got {n_nodes}")
        self.n_nodes = n_nodes
        self.n_coordinates = 2 * n_nodes
        self.joints = _as_joints(joints, n_nodes)
        self.stiffness = per_item("stiffness", stiffness, self.joints.shape[0])
        self.damping = per_item("damping", damping, self.joints.shape[0])
        n = self.n_coordinates
        self._force = np.empty(n)
        self._force_with_jacobian = np.empty(n)
        self._stiffness_matrix = np.empty((n, n))
        self._damping_matrix = np.empty((n, n))

    def _coordinates(self, name, values):
        if not (type(values) is np.ndarray and values.dtype == np.float64 and values.flags.c_contiguous):
            values = np.ascontiguousarray(values, dtype=np.float64)
        if values.shape != (self.n_coordinates,):
            raise SceneError(f"{name} must have shape ({self.n_coordinates},); got {values.shape}")
        return values

    def force(self, positions, velocities):
        """Generalized bending force (2 n_nodes,) [N], ``-sum_j (k_j dtheta_j + c_j dtheta_dot_j)
        grad_q(dtheta_j)``, at positions (not Exudyn displacements) and velocities (2 n_nodes,)."""
        return bending_force_kernel(self._coordinates("positions", positions),
                                    self._coordinates("velocities", velocities),
                                    self.joints, self.stiffness, self.damping, self._force)

    def jacobian(self, positions, velocities):
        """``(K, D)``, each (2 n_nodes, 2 n_nodes): K = -df/dq [N/m] (not symmetric if c != 0),
        D = -df/dv [N s/m]."""
        bending_jacobian_kernel(self._coordinates("positions", positions),
                                self._coordinates("velocities", velocities),
                                self.joints, self.stiffness, self.damping, 1.0, 0.0,
                                _EMPTY_VECTOR, self._stiffness_matrix, self._damping_matrix)
        return self._stiffness_matrix, self._damping_matrix

    def force_and_jacobian(self, positions, velocities):
        """``(f, K, D)`` of :meth:`force` and :meth:`jacobian` in one pass."""
        bending_jacobian_kernel(self._coordinates("positions", positions),
                                self._coordinates("velocities", velocities),
                                self.joints, self.stiffness, self.damping, 1.0, 0.0,
                                self._force_with_jacobian, self._stiffness_matrix, self._damping_matrix)
        return self._force_with_jacobian, self._stiffness_matrix, self._damping_matrix

    def energy(self, positions):
        """Elastic bending energy [J]; see ``bending_energy``."""
        return bending_energy(positions, self.joints, self.stiffness)
