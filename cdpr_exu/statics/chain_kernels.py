"""The per-dimension kernels of the chain statics (:mod:`cdpr_exu.statics.chain_statics`): the potential of
the lumped cables, its gradient (the nodal forces) and Hessian (the tangent stiffness), operation for
operation the simulator's own floating-point numbers, the nodes of all cables numbered cable after cable.

* the plane (x, z), :class:`PlanarChains`: numba kernels of the axial springs (tension-only when slack),
  the rim contact k_p (r_p - d) along the radius and the node weights, and the exact-angle bending of
  :mod:`cdpr_exu.physics.bending`;
* space (x, y, z), :class:`SpatialChains`: the chains, the platform's pose and the swivel angles, with the
  dynamic model's kernels at zero velocity (:mod:`cdpr_exu.physics.bending_3d`,
  :mod:`cdpr_exu.physics.axial_3d`, :mod:`cdpr_exu.physics.swivel_pulley`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sparse
from numba import njit

from cdpr_exu.physics.sparse_blocks import block_pattern
from cdpr_exu.core.errors import UnreachableError
from cdpr_exu.core.geometry import rotation_from_vector, skew
from cdpr_exu.physics import axial_3d, bending, bending_3d
from cdpr_exu.physics import swivel_pulley as sp

__all__ = ["ChainIndex", "PlanarChains", "planar_energy", "planar_forces", "SpatialChains"]


class ChainIndex:
    """The nodes of all cables numbered cable after cable: per cable its node count, first and last node; per
    element its nodes, cable, ``k`` [N/m], ``l0`` [m] and law (``slack``: tension-only); per node its mass
    [kg]; per interior joint its nodes and bending stiffness ``joint_k`` [N m/rad]."""

    def __init__(self, robot):
        self.counts = [c.n_elements + 1 for c in robot.cables]
        self.first = np.concatenate([[0], np.cumsum(self.counts)[:-1]]).astype(int)
        self.last = self.first + np.asarray(self.counts) - 1
        self.n_nodes = int(sum(self.counts))
        elements = [np.stack([np.arange(f, f + n - 1), np.arange(f + 1, f + n)], axis=1)
                    for f, n in zip(self.first, self.counts)]
        self.elements = np.ascontiguousarray(np.concatenate(elements).astype(np.int64))
        self.element_cable = np.concatenate([np.full(n - 1, i) for i, n in enumerate(self.counts)])
        self.k = np.array([robot.cables[c].axial_stiffness for c in self.element_cable])
        self.l0 = np.array([robot.cables[c].element_length for c in self.element_cable])
        self.slack = np.array([robot.cables[c].slack for c in self.element_cable])
        self.masses = np.concatenate([np.asarray(c.node_masses) for c in robot.cables])
        self.joint_k = np.concatenate([np.full(n - 2, c.bending_stiffness) for c, n in zip(robot.cables, self.counts)])
        self.joints = bending.cable_joints(self.counts)


class PlanarChains(ChainIndex):
    """The planar chains' index, contact and bending; the inner unknowns ``v`` are the interior node
    coordinates of every cable, cable after cable, then the rotation when it is free."""

    def __init__(self, robot, free_rotation: bool):
        super().__init__(robot)
        self.interior = np.concatenate([np.arange(f + 1, f + n - 1)
                                        for f, n in zip(self.first, self.counts)]).astype(int)
        self.winch = self.first.copy()
        self.anchor = self.last
        self.free_rotation = free_rotation
        self.n_interior = 2 * self.interior.size
        self.n_inner = self.n_interior + int(free_rotation)
        self.interior_rows = (2 * self.interior[:, None] + np.arange(2)).ravel()
        self.bending = (bending.BendingSpringDamper(self.n_nodes, self.joints, self.joint_k, np.zeros_like(self.joint_k))
                        if np.any(self.joint_k > 0) else None)
        self.zero_velocities = np.zeros(2 * self.n_nodes)
        # (2, 2N): sums the anchor nodes' coordinates; its transpose moves every anchor with the platform
        self.anchor_sum = np.zeros((2, 2 * self.n_nodes))
        for j in self.anchor:
            self.anchor_sum[:, 2 * j:2 * j + 2] = np.eye(2)
        # per node: the pulley it may touch (stiffness 0: none)
        self.node_center = np.concatenate([np.tile(np.asarray(c.pulley.point, float), (n, 1))
                                           for c, n in zip(robot.cables, self.counts)])
        self.node_radius = np.concatenate([np.full(n, c.pulley.radius) for c, n in zip(robot.cables, self.counts)])
        self.node_contact = np.concatenate([np.full(n, c.contact_stiffness if c.pulley.wraps else 0.0)
                                            for c, n in zip(robot.cables, self.counts)])


@njit(cache=True)
def _energy_kernel(p, elements, k, l0, slack, weights, center, radius, contact, joints, joint_k):
    """Potential of the chains [J]: axial springs, pulley penalty, weight, bending."""
    energy = 0.0
    for j in range(p.shape[0]):
        energy += weights[j] * p[j, 1]
        if contact[j] > 0.0:
            dx, dz = p[j, 0] - center[j, 0], p[j, 1] - center[j, 1]
            depth = radius[j] - np.sqrt(dx * dx + dz * dz)
            if depth > 0.0:
                energy += 0.5 * contact[j] * depth * depth
    for e in range(elements.shape[0]):
        a, b = elements[e, 0], elements[e, 1]
        dx, dz = p[b, 0] - p[a, 0], p[b, 1] - p[a, 1]
        stretch = np.sqrt(dx * dx + dz * dz) - l0[e]
        if stretch > 0.0 or not slack[e]:
            energy += 0.5 * k[e] * stretch * stretch
    for i in range(joints.shape[0]):
        a, b, c = joints[i, 0], joints[i, 1], joints[i, 2]
        e1x, e1z = p[b, 0] - p[a, 0], p[b, 1] - p[a, 1]
        e2x, e2z = p[c, 0] - p[b, 0], p[c, 1] - p[b, 1]
        angle = np.arctan2(e1x * e2z - e1z * e2x, e1x * e2x + e1z * e2z)
        energy += 0.5 * joint_k[i] * angle * angle
    return energy


@njit(cache=True)
def _force_kernel(p, elements, k, l0, slack, weights, center, radius, contact, with_stiffness, F, K, tension):
    """Axial, contact and weight forces on the nodes into F (N, 2), -dF/dX into K, tensions."""
    F[:, :] = 0.0
    if with_stiffness:
        K[:, :] = 0.0
    for j in range(p.shape[0]):
        F[j, 1] -= weights[j]
        if contact[j] > 0.0:
            dx, dz = p[j, 0] - center[j, 0], p[j, 1] - center[j, 1]
            dist = np.sqrt(dx * dx + dz * dz)
            depth = radius[j] - dist
            if depth > 0.0 and dist > 0.0:
                nx, nz = dx / dist, dz / dist
                F[j, 0] += contact[j] * depth * nx
                F[j, 1] += contact[j] * depth * nz
                if with_stiffness:
                    # k_p (n n^T - depth / d (I - n n^T))
                    ratio = depth / dist
                    K[2 * j, 2 * j] += contact[j] * (nx * nx - ratio * (1.0 - nx * nx))
                    K[2 * j + 1, 2 * j + 1] += contact[j] * (nz * nz - ratio * (1.0 - nz * nz))
                    K[2 * j, 2 * j + 1] += contact[j] * (nx * nz + ratio * nx * nz)
                    K[2 * j + 1, 2 * j] += contact[j] * (nx * nz + ratio * nx * nz)
    for e in range(elements.shape[0]):
        a, b = elements[e, 0], elements[e, 1]
        dx, dz = p[b, 0] - p[a, 0], p[b, 1] - p[a, 1]
        length = np.sqrt(dx * dx + dz * dz)
        tx, tz = dx / length, dz / length
        force = k[e] * (length - l0[e])
        if slack[e] and force < 0.0:
            tension[e] = 0.0
            continue
        tension[e] = force
        F[a, 0] += force * tx
        F[a, 1] += force * tz
        F[b, 0] -= force * tx
        F[b, 1] -= force * tz
        if with_stiffness:
            geometric = force / length
            kxx = k[e] * tx * tx + geometric * (1.0 - tx * tx)
            kzz = k[e] * tz * tz + geometric * (1.0 - tz * tz)
            kxz = (k[e] - geometric) * tx * tz
            for r, c, sign in ((a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)):
                K[2 * r, 2 * c] += sign * kxx
                K[2 * r + 1, 2 * c + 1] += sign * kzz
                K[2 * r, 2 * c + 1] += sign * kxz
                K[2 * r + 1, 2 * c] += sign * kxz


def planar_energy(robot, layout, p):
    """Potential energy of the chains at node positions p (n_nodes, 2) [J]."""
    return _energy_kernel(p, layout.elements, layout.k, layout.l0, layout.slack, layout.masses * robot.gravity,
                          layout.node_center, layout.node_radius, layout.node_contact, layout.joints,
                          layout.joint_k)


def planar_forces(robot, layout, p, with_stiffness=True):
    """Nodal forces (n_nodes, 2) [N] (springs, bending, contact, weight), the tangent stiffness ``-dF/dX``
    (2 n_nodes, 2 n_nodes) [N/m] (None without ``with_stiffness``), the element tensions [N] and the
    cables' potential energy [J] at node positions ``p`` (n_nodes, 2) [m]."""
    N = layout.n_nodes
    p = np.ascontiguousarray(p, dtype=float)
    if np.any(np.hypot(*(p[layout.elements[:, 1]] - p[layout.elements[:, 0]]).T) <= 0):
        raise UnreachableError("chain statics: two neighbouring cable nodes coincide")
    F = np.empty((N, 2))
    K = np.empty((2 * N, 2 * N)) if with_stiffness else np.empty((0, 0))
    tension = np.empty(len(layout.elements))
    _force_kernel(p, layout.elements, layout.k, layout.l0, layout.slack, layout.masses * robot.gravity,
                  layout.node_center, layout.node_radius, layout.node_contact, with_stiffness, F, K, tension)
    if layout.bending is not None:
        flat = p.ravel()
        if with_stiffness:
            force, Kb, _ = layout.bending.force_and_jacobian(flat, layout.zero_velocities)
            K += Kb
        else:
            force = layout.bending.force(flat, layout.zero_velocities)
        F += force.reshape(-1, 2)
    return F, (K if with_stiffness else None), tension, planar_energy(robot, layout, p)


class SpatialChains(ChainIndex):
    """Points, unknowns and the potential with its gradient and Hessian.

    Points (rows of ``P``, (n_points, 3)): every cable's nodes, then (penalty joints) one anchor point per
    cable; each fixed (the held first nodes), free, or on the platform (``x + R b``). The point coordinates
    are their 3 n_points coordinates, then the swivel angles psi. Unknowns ``v``: the free points'
    coordinates, the platform position, (rigid) the rotation increment ``d`` (``R <- exp([d]x) R``), the
    swivel angles. A state is ``(free, x, R, psi)``.
    """

    def __init__(self, robot):
        super().__init__(robot)
        self.robot = robot
        m = len(robot.cables)
        n_chain = self.n_nodes
        self.penalty = robot.anchor_spring_factor is not None
        self.n_points = n_chain + (m if self.penalty else 0)
        self.rigid = not robot.is_point_mass
        # body points: (point index, cable)
        self.body = [(n_chain + i if self.penalty else int(self.last[i]), i) for i in range(m)]
        body_points = {p for p, _ in self.body}
        fixed = set(int(f) for f in self.first)
        self.free = np.array([j for j in range(self.n_points) if j not in fixed and j not in body_points], dtype=int)
        self.n_free = 3 * self.free.size
        self.swivel_cables = [i for i, c in enumerate(robot.cables) if isinstance(c.pulley, sp.SwivelPulley)]
        self.n_psi = len(self.swivel_cables)
        self.psi0 = self.n_free + 3 + (3 if self.rigid else 0)  # first psi unknown
        self.n_unknowns = self.psi0 + self.n_psi
        self.size = 3 * self.n_points + self.n_psi  # point coordinates and the swivel angles
        self.fixed_positions = {int(f): c.held_point for f, c in zip(self.first, robot.cables)}
        self.local = np.array([c.anchor for c in robot.cables], dtype=float)
        self.weights = np.zeros(self.n_points)
        self.weights[:n_chain] = self.masses * robot.gravity
        self.axial_pattern = block_pattern(self.elements, 3)
        if not np.any(self.joint_k > 0):
            self.joints, self.joint_k = self.joints[:0], self.joint_k[:0]
        self.pattern = block_pattern(self.joints, 3)
        self.penalty_k = (np.array([robot.anchor_spring_factor * c.axial_stiffness for c in robot.cables])
                          if self.penalty else np.zeros(0))
        # each swivel pulley: its cable's nodes (all may touch it), the contact's sparse pattern in
        # the cable's own coordinates (x, y, z per node, psi last) mapped to the point coordinates
        self.contacts = []
        for s, i in enumerate(self.swivel_cables):
            count, first = self.counts[i], int(self.first[i])
            nodes = np.arange(count, dtype=np.int64)
            rows, columns = sp.swivel_contact_pattern(nodes, 3 * count + 1)
            index = np.concatenate([3 * first + np.arange(3 * count), [3 * self.n_points + s]])
            self.contacts.append((i, robot.cables[i].pulley, first, count, nodes, index[rows], index[columns], index))
        self.external_force = np.zeros(3)  # a constant force on the platform's centre of mass [N]

    def points(self, free, x, R):
        """All points, shape (n_points, 3) [m]."""
        p = np.empty((self.n_points, 3))
        for j, position in self.fixed_positions.items():
            p[j] = position
        p[self.free] = free.reshape(-1, 3)
        for j, i in self.body:
            p[j] = x + R @ self.local[i]
        return p

    def _axial(self, p):
        """Element lengths, unit vectors and axial forces (tension-only elements: the dynamic model's law)."""
        a, b = self.elements[:, 0], self.elements[:, 1]
        d = p[b] - p[a]
        length = np.linalg.norm(d, axis=1)
        t = d / length[:, None]
        force = self.k * (length - self.l0)
        if np.any(self.slack):
            taut = np.zeros(len(self.elements))
            axial_3d.tension_only_tensions(p.ravel(), np.zeros(p.size), self.elements, self.l0, self.k,
                                           np.zeros(len(self.elements)), np.zeros(len(self.elements)), taut)
            force = np.where(self.slack, taut, force)
        return length, t, force

    def _contact_args(self, pulley):
        return (pulley.inlet_array, pulley.radius, pulley.groove_radius, pulley.flange_height)

    def energy(self, free, x, R, psi):
        """Total potential [J]."""
        p = self.points(free, x, R)
        flat = p.ravel()
        length, _, _ = self._axial(p)
        stretch = length - self.l0
        spring = ~self.slack
        energy = 0.5 * float(np.sum(self.k[spring] * stretch[spring] ** 2))
        if np.any(self.slack):
            energy += axial_3d.tension_only_energy(flat, self.elements[self.slack], self.l0[self.slack],
                                                   self.k[self.slack])
        energy += float(self.weights @ p[:, 2]) + self.robot.mass * self.robot.gravity * x[2]
        energy -= float(self.external_force @ x)
        if self.joints.size:
            energy += bending_3d.spatial_bending_energy(flat, self.joints, self.joint_k)
        if self.penalty:
            for (j, i), k in zip(self.body, self.penalty_k):
                energy += 0.5 * k * float(np.sum((p[self.last[i]] - p[j]) ** 2))
        for s, (_, pulley, first, count, nodes, _, _, _) in enumerate(self.contacts):
            energy += sp.swivel_contact_energy(flat[3 * first:3 * (first + count)].copy(), float(psi[s]), nodes,
                                               *self._contact_args(pulley), pulley.contact_stiffness,
                                               pulley.onset_band)
        return energy

    def point_derivatives(self, p, psi):
        """Gradient (size,) and sparse Hessian (size, size) of the potential in the point coordinates
        (and the swivel angles), and the element forces (n_elements,) [N]."""
        size = self.size
        G = np.zeros(size)
        G[2:3 * self.n_points:3] += self.weights
        flat = p.ravel().copy()
        length, t, force = self._axial(p)
        # axial: the force along each element, and its 6 x 6 block [[B, -B], [-B, B]] in the
        # order of sparse_blocks.block_pattern; a tension-only element's slope is its law's
        np.subtract.at(G, 3 * self.elements[:, 0][:, None] + np.arange(3), force[:, None] * t)
        np.add.at(G, 3 * self.elements[:, 1][:, None] + np.arange(3), force[:, None] * t)
        tt = t[:, :, None] * t[:, None, :]
        block = self.k[:, None, None] * tt + (force / length)[:, None, None] * (np.eye(3) - tt)
        axial_values = np.block([[block, -block], [-block, block]]).reshape(-1)
        if np.any(self.slack):
            slack_values = np.zeros(36 * len(self.elements))
            axial_3d.tension_only_triplet_values(flat, np.zeros(flat.size), self.elements, self.l0, self.k,
                                                 np.zeros(len(self.elements)), np.zeros(len(self.elements)),
                                                 1.0, 0.0, slack_values)
            axial_values = np.where(np.repeat(self.slack, 36), slack_values, axial_values)
        rows, columns, values_list = [self.axial_pattern[0]], [self.axial_pattern[1]], [axial_values]
        if self.joints.size:
            bend = np.zeros(3 * self.n_points)
            bending_3d.spatial_bending_force(flat, self.joints, self.joint_k, bend)
            G[:3 * self.n_points] -= bend
            values = np.zeros(self.pattern[0].size)
            bending_3d.spatial_bending_stiffness(flat, self.joints, self.joint_k, 1.0, values)
            rows.append(self.pattern[0])
            columns.append(self.pattern[1])
            values_list.append(values)
        if self.penalty:
            for (j, i), k in zip(self.body, self.penalty_k):
                last = self.last[i]
                f = k * (p[last] - p[j])
                G[3 * last:3 * last + 3] += f
                G[3 * j:3 * j + 3] -= f
                for r, s, sign in ((last, last, 1.0), (j, j, 1.0), (last, j, -1.0), (j, last, -1.0)):
                    rows.append(np.repeat(3 * r + np.arange(3), 3).astype(np.int64))
                    columns.append(np.tile(3 * s + np.arange(3), 3).astype(np.int64))
                    values_list.append(sign * k * np.eye(3).ravel())
        for s, (_, pulley, first, count, nodes, contact_rows, contact_columns, index) in enumerate(self.contacts):
            positions = flat[3 * first:3 * (first + count)].copy()
            zero = np.zeros(3 * count)
            contact_force = np.zeros(3 * count + 1)
            # the dynamic model's kernels at rest: the force -dU/dq and K = -df/dq = d^2 U / dq^2
            sp.swivel_contact_force(positions, zero, float(psi[s]), 0.0, nodes, *self._contact_args(pulley),
                                    pulley.contact_stiffness, 0.0, pulley.onset_band, contact_force)
            G[index] -= contact_force
            values = np.zeros(contact_rows.size)
            sp.swivel_contact_values(positions, zero, float(psi[s]), 0.0, nodes, *self._contact_args(pulley),
                                     pulley.contact_stiffness, 0.0, pulley.onset_band, 1.0, 0.0, values)
            rows.append(contact_rows)
            columns.append(contact_columns)
            values_list.append(values)
        H = sparse.coo_matrix((np.concatenate(values_list), (np.concatenate(rows), np.concatenate(columns))),
                              shape=(size, size)).tocsr()
        return G, H, force

    def _map(self, R):
        """Sparse T = d(point coordinates)/d(unknowns), shape (size, n_unknowns)."""
        rows, columns, values = [], [], []
        for c, j in enumerate(self.free):
            rows.extend(3 * j + np.arange(3))
            columns.extend(3 * c + np.arange(3))
            values.extend([1.0, 1.0, 1.0])
        x0 = self.n_free
        for j, i in self.body:
            rows.extend(3 * j + np.arange(3))
            columns.extend(x0 + np.arange(3))
            values.extend([1.0, 1.0, 1.0])
            if self.rigid:
                block = -skew(R @ self.local[i])  # d(exp([d]x) b) = d x b
                for r in range(3):
                    for s in range(3):
                        rows.append(3 * j + r)
                        columns.append(x0 + 3 + s)
                        values.append(block[r, s])
        for s in range(self.n_psi):
            rows.append(3 * self.n_points + s)
            columns.append(self.psi0 + s)
            values.append(1.0)
        return sparse.csr_matrix((values, (rows, columns)), shape=(self.size, self.n_unknowns))

    def derivatives(self, free, x, R, psi):
        """Gradient, sparse Hessian in the unknowns, the points, their gradient and the element forces."""
        p = self.points(free, x, R)
        G, H, force = self.point_derivatives(p, psi)
        T = self._map(R)
        x0 = self.n_free
        gradient = T.T @ G
        gradient[x0 + 2] += self.robot.mass * self.robot.gravity
        gradient[x0:x0 + 3] -= self.external_force
        hessian = (T.T @ H @ T).tolil()
        if self.rigid:
            rotation_second = np.zeros((3, 3))
            for j, i in self.body:
                arm = R @ self.local[i]
                g = G[3 * j:3 * j + 3]
                rotation_second += 0.5 * (np.outer(g, arm) + np.outer(arm, g)) - float(g @ arm) * np.eye(3)
            hessian[x0 + 3:x0 + 6, x0 + 3:x0 + 6] = hessian[x0 + 3:x0 + 6, x0 + 3:x0 + 6].toarray() + rotation_second
        return gradient, hessian.tocsc(), p, G, force

    def step(self, free, x, R, psi, delta):
        """The state moved by ``delta`` (unknowns)."""
        x0 = self.n_free
        free = free + delta[:x0]
        x = x + delta[x0:x0 + 3]
        if self.rigid:
            R = rotation_from_vector(delta[x0 + 3:x0 + 6]) @ R
        return free, x, R, psi + delta[self.psi0:]
