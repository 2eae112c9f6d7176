"""Static equilibrium of the simulator's own lumped cables: chains of nodes over pulleys.

:mod:`cdpr_exu.statics.statics` treats each cable as a continuous elastic catenary. The
simulator does not: its cable is a chain of n straight elements whose nodes carry the
mass, with exact-angle bending springs at the interior nodes, and a pulley pushes the
*nodes* out of its disc (:mod:`cdpr_exu.builder.pulley`). On the paper's robot (0.25 m elements
on 0.25 m pulleys) the chain wraps the pulley as a coarse polygon, and its bending
springs lift it off the rim near the tangent point. Both change the paid-out length
that puts the platform on a given pose by millimetres to centimetres, by an amount that
depends on where the nodes happen to sit. This module solves the same discrete model
the simulator integrates, at rest:

* unknowns: the interior node positions of every cable, the platform rotation (when
  equilibrium chooses it) and the paid-out length of every winch;
* equations: force balance of every interior node (axial springs k_i (|d| - l0i),
  tension-only when the scene's elements are slack; bending moments k_theta dtheta;
  pulley penalty k_p (r_p - d) along the radius; node weight m_j g) and the force and
  moment balance of the platform, which also carries the last node of each cable
  (joined to it at the anchor) and an optional external wrench.

Newton's method with the analytic Jacobian (axial, contact and bending tangent
stiffness) and a backtracking line search on the residual norm. The equilibrium at
rest needs no damping, so damping constants do not enter.

The winch geometry is the simulator's (:mod:`cdpr_exu.builder.winch`): node 0 sits on the
winch line ``x = c_x + side r_p`` at height ``z = c_z - (L0 - lambda)``, with ``L0``
the cable's unstrained length and ``lambda`` the paid-out length (cable beyond the
hang point). A fixed exit point is the limit ``r_p = 0``.

Coordinates are the paper's x-z plane (z up, gravity along -z); units SI (m, N, kg,
rad). Plain NumPy plus the numba bending kernels; no Exudyn.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from numba import njit

from cdpr_exu.physics import bending
from cdpr_exu.scenes.contact_models import CONTACT_MODELS
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import rotation_matrix
from cdpr_exu.exits import Exit
from cdpr_exu.statics.kinematics import initial_cable_nodes, straight_cable_nodes
from cdpr_exu.core.validation import finite, shown, vector

__all__ = ["ChainCable", "ChainRobot", "ChainEquilibrium", "chain_robot", "solve_chain_statics",
           "chain_forces"]


@dataclass(frozen=True)
class ChainCable:
    """One lumped cable as the simulator builds it, for statics.

    Parameters
    ----------
    node_masses : tuple of float, length n + 1 [kg]
        Winch node first (its mass is carried by the winch).
    element_length : float [m]
        Unstrained element length l0i = L0 / n.
    axial_stiffness : float [N/m]
        k_i = EA / l0i; ``inf`` is not supported (inextensible chains have no statics here).
    bending_stiffness : float [N m/rad]
        k_theta of each interior joint (0: no bending).
    slack : bool
        Tension-only elements.
    pulley : Exit
        Where the cable leaves the frame (:mod:`cdpr_exu.exits`: a pulley, or a point exit).
    contact_stiffness : float [N/m]
        Pulley penalty k_p (0: no contact).
    anchor : (x, z) [m]
        Anchor in the platform frame.
    """

    node_masses: tuple
    element_length: float
    axial_stiffness: float
    bending_stiffness: float
    slack: bool
    pulley: Exit
    contact_stiffness: float
    anchor: tuple

    def __post_init__(self):
        if len(self.node_masses) < 2:
            raise SceneError(f"node_masses needs at least 2 nodes, got {len(self.node_masses)}")
        for name in ("element_length", "axial_stiffness"):
            value = finite(name, getattr(self, name))
            if value <= 0:
                raise SceneError(f"{name} must be positive and finite, got {shown(value)}")
        for name in ("bending_stiffness", "contact_stiffness"):
            if finite(name, getattr(self, name)) < 0:
                raise SceneError(f"{name} must be zero or positive, got {shown(getattr(self, name))}")
        if np.any(~np.isfinite(self.node_masses)) or min(self.node_masses) < 0:
            raise SceneError(f"node_masses must be finite and non-negative, got {shown(self.node_masses)}")
        if not isinstance(self.pulley, Exit):
            raise SceneError(f"pulley must be an exit (cdpr_exu.exits), got {shown(self.pulley)}")
        vector("anchor", self.anchor, 2)

    @property
    def n_elements(self) -> int:
        return len(self.node_masses) - 1

    @property
    def unstrained_length(self) -> float:
        """L0 = n l0i [m]."""
        return self.n_elements * self.element_length

    def winch_node(self, paid_out: float) -> np.ndarray:
        """Position of node 0 for a paid-out length lambda [m], shape (2,) [m]."""
        return self.pulley.winch_end(self.unstrained_length, paid_out)


@dataclass(frozen=True)
class ChainRobot:
    """The platform and its lumped cables.

    Parameters
    ----------
    cables : tuple of ChainCable
    mass : float [kg]
    gravity : float [m/s^2]
        Magnitude along -z (0: no gravity, also on the cables).
    """

    cables: tuple
    mass: float
    gravity: float

    @property
    def is_point_mass(self) -> bool:
        """True when every anchor sits at the centre of mass (no rotation to balance)."""
        return all(np.allclose(c.anchor, 0.0) for c in self.cables)


def chain_robot(scene) -> ChainRobot:
    """The chain-statics model of a scene, with the effects the scene's builder adds.

    Raises
    ------
    SceneError
        For massless or inextensible cables (no nodes, or no axial spring to solve for).
    """
    effects = scene.effects
    if not effects.cable_mass or not effects.axial_elasticity:
        raise SceneError("chain statics needs effects.cable_mass and effects.axial_elasticity "
                         f"(the scene's preset is {shown(effects.preset)}); use the catenary statics instead")
    if effects.bending and effects.bending_model != "exact":
        raise SceneError("chain statics models the exact-angle bending only, "
                         f"got effects.bending_model = {shown(effects.bending_model)}")
    if scene.contact_model not in (None, CONTACT_MODELS["node"]):
        raise SceneError("chain statics models the node contact on pulleys only, got "
                         f"effects.pulley_contact_model = {shown(effects.pulley_contact_model)}")
    gravity = scene.gravity if effects.gravity else 0.0
    cables = []
    for cable, exit_, anchor in zip(scene.cables, scene.exits, scene.platform.anchors):
        masses = cable.node_masses() if gravity > 0 else np.zeros(cable.n_elements + 1)
        contact = exit_.contact_stiffness if scene.pulley_contact else 0.0
        cables.append(ChainCable(
            node_masses=tuple(float(m) for m in masses), element_length=cable.element_length,
            axial_stiffness=cable.axial_stiffness,
            bending_stiffness=cable.bending_stiffness if effects.bending else 0.0,
            slack=effects.slack, pulley=exit_, contact_stiffness=contact, anchor=tuple(anchor)))
    return ChainRobot(tuple(cables), scene.platform.mass, gravity)


@dataclass(frozen=True, eq=False)
class ChainEquilibrium:
    """A static equilibrium of the chains and platform.

    Attributes
    ----------
    position : ndarray, shape (2,) [m]
    rotation : float [rad]
    paid_out : ndarray, shape (m,) [m]
        Paid-out length lambda of each winch.
    nodes : tuple of ndarray, each shape (n + 1, 2) [m]
        Node positions, winch node first, anchor last.
    tensions : tuple of ndarray, each shape (n,) [N]
        Axial force of each element (positive in tension).
    residual : float [N]
        Largest force imbalance left.
    iterations : int
    """

    position: np.ndarray
    rotation: float
    paid_out: np.ndarray
    nodes: tuple
    tensions: tuple
    residual: float
    iterations: int = field(default=0)

    @property
    def anchor_tensions(self) -> np.ndarray:
        """Tension of each cable's last element, at the platform, shape (m,) [N]."""
        return np.array([t[-1] for t in self.tensions])


class _Layout:
    """Index bookkeeping: global nodes of all cables and the inner unknowns.

    The inner unknowns ``v`` are the interior node coordinates of every cable, cable
    after cable, then the rotation when it is free.
    """

    def __init__(self, robot: ChainRobot, free_rotation: bool):
        self.counts = [c.n_elements + 1 for c in robot.cables]
        self.first = np.concatenate([[0], np.cumsum(self.counts)[:-1]]).astype(int)
        self.n_nodes = int(sum(self.counts))
        self.interior = np.concatenate([
            np.arange(f + 1, f + n - 1) for f, n in zip(self.first, self.counts)]).astype(int)
        self.winch = self.first.copy()
        self.anchor = (self.first + np.asarray(self.counts) - 1).astype(int)
        self.free_rotation = free_rotation
        self.n_interior = 2 * self.interior.size
        self.n_inner = self.n_interior + int(free_rotation)
        self.interior_rows = (2 * self.interior[:, None] + np.arange(2)).ravel()
        joints = bending.cable_joints(self.counts)
        joint_stiffness = np.concatenate([
            np.full(n - 2, c.bending_stiffness) for c, n in zip(robot.cables, self.counts)])
        self.bending = (bending.BendingSpringDamper(self.n_nodes, joints, joint_stiffness, np.zeros_like(joint_stiffness))
                        if np.any(joint_stiffness > 0) else None)
        self.zero_velocities = np.zeros(2 * self.n_nodes)
        # (2, 2N): sums the anchor nodes' coordinates; its transpose moves every anchor
        # with the platform position
        self.anchor_sum = np.zeros((2, 2 * self.n_nodes))
        for j in self.anchor:
            self.anchor_sum[:, 2 * j:2 * j + 2] = np.eye(2)
        self.joints, self.joint_stiffness = joints, joint_stiffness
        # per node: the pulley it may touch (stiffness 0: none)
        self.node_center = np.concatenate([np.tile(np.asarray(c.pulley.point, float), (n, 1))
                                           for c, n in zip(robot.cables, self.counts)])
        self.node_radius = np.concatenate([np.full(n, c.pulley.radius) for c, n in zip(robot.cables, self.counts)])
        self.node_contact = np.concatenate([
            np.full(n, c.contact_stiffness if c.pulley.wraps else 0.0)
            for c, n in zip(robot.cables, self.counts)])
        elements = [np.stack([np.arange(f, f + n - 1), np.arange(f + 1, f + n)], axis=1)
                    for f, n in zip(self.first, self.counts)]
        self.elements = np.concatenate(elements).astype(int)
        self.element_cable = np.concatenate([np.full(n - 1, i) for i, n in enumerate(self.counts)])
        self.k = np.array([robot.cables[c].axial_stiffness for c in self.element_cable])
        self.l0 = np.array([robot.cables[c].element_length for c in self.element_cable])
        self.slack = np.array([robot.cables[c].slack for c in self.element_cable])
        self.masses = np.concatenate([np.asarray(c.node_masses) for c in robot.cables])


def _positions(robot, layout, position, rotation, v, paid_out):
    """All node positions, shape (n_nodes, 2) [m], and the rotation [rad]."""
    if layout.free_rotation:
        rotation = v[layout.n_interior]
    p = np.empty((layout.n_nodes, 2))
    p[layout.interior] = v[:layout.n_interior].reshape(-1, 2)
    R = rotation_matrix(rotation)
    for i, cable in enumerate(robot.cables):
        p[layout.winch[i]] = cable.winch_node(paid_out[i])
        p[layout.anchor[i]] = position + R @ np.asarray(cable.anchor)
    return p, rotation


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


def _energy(robot, layout, p):
    """Potential energy of the chains at node positions p (n_nodes, 2) [J]."""
    return _energy_kernel(p, layout.elements, layout.k, layout.l0, layout.slack, layout.masses * robot.gravity,
                          layout.node_center, layout.node_radius, layout.node_contact, layout.joints,
                          layout.joint_stiffness)


def _forces(robot, layout, p, with_stiffness=True):
    """Nodal forces, tangent stiffness, element tensions and potential energy.

    Returns
    -------
    F : ndarray, shape (n_nodes, 2) [N]
        Net force on every node (springs, bending, contact, weight).
    K : ndarray, shape (2 n_nodes, 2 n_nodes) [N/m] or None
        ``-dF/dX``.
    tension : ndarray, shape (n_elements_total,) [N]
    energy : float [J]
        Elastic, contact and gravitational potential of the cables.
    """
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
    return F, (K if with_stiffness else None), tension, _energy(robot, layout, p)


def _cross(a, f):
    return a[..., 0] * f[..., 1] - a[..., 1] * f[..., 0]


def _selection(robot, layout, p, position):
    """dX/dv (2N, n_inner) and dX/dlambda (2N, m) at a configuration."""
    N, m = layout.n_nodes, len(robot.cables)
    S = np.zeros((2 * N, layout.n_inner))
    S[layout.interior_rows, np.arange(layout.n_interior)] = 1.0
    if layout.free_rotation:
        arms = p[layout.anchor] - position
        for i, j in enumerate(layout.anchor):
            S[2 * j:2 * j + 2, layout.n_interior] = [-arms[i, 1], arms[i, 0]]
    S_lambda = np.zeros((2 * N, m))
    for i, j in enumerate(layout.winch):
        S_lambda[2 * j + 1, i] = 1.0
    return S, S_lambda


class _Inner:
    """Potential, gradient and Hessian of the chains at fixed platform position and paid-out lengths.

    ``Pi(v) = cable potential - M_ext * rotation``; its minimum over ``v`` (interior
    nodes, free rotation) is the equilibrium of the nodes and of the platform's moment.
    """

    def __init__(self, robot, layout, position, rotation, paid_out, wrench):
        self.robot, self.layout, self.position = robot, layout, position
        self.rotation, self.paid_out, self.wrench = rotation, paid_out, wrench

    def energy(self, v):
        p, rotation = _positions(self.robot, self.layout, self.position, self.rotation, v, self.paid_out)
        return _energy(self.robot, self.layout, p) - self.wrench[2] * rotation

    def _gradient(self, S, F):
        """dPi/dv from dX/dv (2N, n_inner) and the nodal forces (N, 2)."""
        gradient = -(S.T @ F.ravel())
        if self.layout.free_rotation:
            gradient[-1] -= self.wrench[2]
        return gradient

    def gradient(self, v):
        """dPi/dv without the Hessian."""
        p, _ = _positions(self.robot, self.layout, self.position, self.rotation, v, self.paid_out)
        F, _, _, _ = _forces(self.robot, self.layout, p, with_stiffness=False)
        S, _ = _selection(self.robot, self.layout, p, self.position)
        return self._gradient(S, F)

    def evaluate(self, v):
        """Energy, gradient, Hessian and the state they came from."""
        layout = self.layout
        p, rotation = _positions(self.robot, layout, self.position, self.rotation, v, self.paid_out)
        F, K, tension, energy = _forces(self.robot, layout, p)
        S, S_lambda = _selection(self.robot, layout, p, self.position)
        gradient = self._gradient(S, F)
        hessian = S.T @ K @ S
        if layout.free_rotation:
            arms = p[layout.anchor] - self.position
            hessian[-1, -1] += float(np.sum(arms * F[layout.anchor]))  # the arms turn with the platform
        return {"energy": energy - self.wrench[2] * rotation, "gradient": gradient, "hessian": hessian,
                "p": p, "rotation": rotation, "F": F, "K": K, "S": S, "S_lambda": S_lambda, "tension": tension}


def descent_step(hessian, gradient, relative_shift: float = 1e-8) -> np.ndarray:
    """Newton's step -H^-1 g, with H shifted by a multiple of the identity until it is a descent direction.

    An indefinite or singular Hessian (a node on a rim, a slack element, a swivel angle
    with no stiffness) is shifted by ``relative_shift`` times its largest diagonal entry,
    then ten times more each time. ``hessian``: dense (N, N) or a scipy sparse matrix;
    ``gradient``: (N,). Returns the step, shape (N,).
    """
    import scipy.sparse as sparse

    is_sparse = sparse.issparse(hessian)
    if is_sparse:
        import scipy.sparse.linalg as sparse_linalg

        identity = sparse.identity(hessian.shape[0], format="csc")
    scale = float(np.abs(hessian.diagonal()).max())
    shift = 0.0
    while True:
        try:
            if is_sparse:
                step = sparse_linalg.splu((hessian + shift * identity).tocsc()).solve(-gradient)
            else:
                step = np.linalg.solve(hessian + shift * np.eye(len(gradient)), -gradient)
        except (np.linalg.LinAlgError, RuntimeError):  # exactly singular
            step = None
        if step is not None and np.all(np.isfinite(step)) and float(step @ gradient) < 0.0:
            return step
        shift = max(10.0 * shift, relative_shift * scale)


def _minimise(inner: _Inner, v, tolerance, max_iterations):
    """Newton's method on the potential with an Armijo line search; returns (v, state, iterations).

    The penalty contact makes the Hessian jump where a node lands on or leaves a rim;
    the energy stays continuously differentiable, so the line search on it keeps every
    step a descent step (a force residual would not). An indefinite Hessian is shifted
    towards the identity until the step descends.
    """
    state = inner.evaluate(v)
    for iteration in range(max_iterations):
        if np.max(np.abs(state["gradient"])) < tolerance:
            return v, state, iteration
        g, H = state["gradient"], state["hessian"]
        step = descent_step(H, g, relative_shift=1e-6)
        slope = float(np.dot(step, g))
        # Near the solution the energy's decrease, ~ |g|^2 / k_p, falls below its rounding
        # (~1e-16 |E|): there the full step is taken if it shrinks the gradient, and the
        # iteration stops if it does not (the gradient is then as small as it gets).
        roundoff = 1e-13 * (1.0 + abs(state["energy"]))
        alpha, accepted = 1.0, False
        for _ in range(40):
            trial = v + alpha * step
            energy = inner.energy(trial)
            if energy <= state["energy"] + 1e-4 * alpha * slope:
                accepted = True
                break
            if abs(energy - state["energy"]) <= roundoff:
                accepted = np.linalg.norm(inner.gradient(trial)) < np.linalg.norm(g)
                break
            alpha *= 0.5
        if not accepted:
            break
        v = trial
        state = inner.evaluate(v)
    if np.max(np.abs(state["gradient"])) < 10.0 * tolerance:  # stalled at rounding, close enough
        return v, state, max_iterations
    raise UnreachableError(f"chain statics: the nodes found no equilibrium (force imbalance "
                           f"{np.max(np.abs(state['gradient'])):.3g} N after {max_iterations} iterations)")


def _platform_force(robot, layout, F, wrench):
    """Net force on the held platform [N], shape (2,): anchors' pull (from the nodal forces
    F, shape (N, 2)), weight, external force."""
    return F[layout.anchor].sum(axis=0) + np.array([0.0, -robot.mass * robot.gravity]) + wrench[:2]


def _platform_force_gradient(layout, state):
    """d(platform force)/d(paid-out lengths) with the nodes kept in equilibrium, shape (2, m),
    and how the inner unknowns follow the paid-out lengths, dv/dlambda, shape (n_inner, m)."""
    K, S, S_lambda = state["K"], state["S"], state["S_lambda"]
    dv = -np.linalg.solve(state["hessian"], S.T @ K @ S_lambda)  # nodes follow the winches
    dF = -K @ (S @ dv + S_lambda)  # (2N, m)
    return layout.anchor_sum @ dF, dv


def chain_forces(robot: ChainRobot, nodes, position, rotation=0.0, external_wrench=None):
    """Force imbalance of a configuration: interior nodes and platform.

    Parameters
    ----------
    robot : ChainRobot
    nodes : sequence of ndarray, each shape (n + 1, 2) [m]
        Node positions per cable, winch node first; the anchors must sit where the pose
        puts them.
    position : (x, z) [m]
    rotation : float [rad]
    external_wrench : (fx, fz, moment), optional [N, N, N m]

    Returns
    -------
    node_forces : ndarray, shape (n_interior, 2) [N]
        Net force on each interior node (all cables, in order).
    platform_wrench : ndarray, shape (3,) [N, N, N m]
        Net force and moment on the platform about its centre of mass.
    """
    layout = _Layout(robot, free_rotation=False)
    p = np.concatenate([np.asarray(n, dtype=float) for n in nodes])
    if p.shape != (layout.n_nodes, 2):
        raise SceneError(f"nodes must hold {layout.counts} nodes per cable, got shape {p.shape}")
    wrench = np.zeros(3) if external_wrench is None else vector("external_wrench", external_wrench, 3)
    position = vector("position", position, 2)
    F, _, _, _ = _forces(robot, layout, p, with_stiffness=False)
    arms = p[layout.anchor] - position
    force = _platform_force(robot, layout, F, wrench)
    moment = _cross(arms, F[layout.anchor]).sum() + wrench[2]
    return F[layout.interior], np.array([*force, moment])


def _straight_guess(robot, position, rotation, tensions):
    """Start of the iteration: straight chains stretched by ``tensions`` [N], shape (m,).

    Each chain is laid from its anchor back over its pulley with elements of length
    l0i (1 + T / k_i l0i) (:func:`~cdpr_exu.statics.kinematics.initial_cable_nodes`), so that
    every element carries the tension T; the paid-out length follows from where node
    0 lands. Returns the interior node coordinates (flat) and the paid-out lengths.
    """
    R = rotation_matrix(rotation)
    interior, paid_out = [], []
    for cable, tension in zip(robot.cables, tensions):
        anchor = np.asarray(position) + R @ np.asarray(cable.anchor)
        stretched = cable.element_length * (1.0 + tension / (cable.axial_stiffness * cable.element_length))
        pulley = cable.pulley
        if pulley.wraps:
            nodes = initial_cable_nodes(pulley.center, pulley.radius, pulley.side, anchor, stretched, cable.n_elements)
        else:
            direction = anchor - np.asarray(pulley.point)
            start = anchor - direction / np.linalg.norm(direction) * stretched * cable.n_elements
            nodes = straight_cable_nodes(start, anchor, cable.n_elements)
        interior.append(nodes[1:-1].ravel())
        paid_out.append(pulley.paid_out_length(cable.unstrained_length, nodes[0]))
    return np.concatenate(interior), np.array(paid_out)


def _predict(robot, layout, guess, interior, rotation, paid_out, position, wrench):
    """Tangent predictor from a solution at ``guess.position`` to ``position``.

    Linearises the equilibrium (nodes and platform force) at the guess and moves the
    nodes, rotation and paid-out lengths along it; an anchor that moved by a centimetre
    would otherwise stretch its element by that much (kN of force) and the iteration
    would have to walk it back. Falls back to the guess if the linear system is singular.
    """
    v = np.concatenate([interior, [rotation] if layout.free_rotation else []])
    dp = position - np.asarray(guess.position)
    if not np.any(dp):
        return interior, rotation, paid_out
    state = _Inner(robot, layout, np.asarray(guess.position), rotation, paid_out, wrench).evaluate(v)
    K, S, S_lambda = state["K"], state["S"], state["S_lambda"]
    anchor_sum, S_position = layout.anchor_sum, layout.anchor_sum.T  # the anchors move with the position
    n, m = layout.n_inner, len(robot.cables)
    # d(gradient) = H dv + S^T K S_lambda dlambda + S^T K S_p dp = 0
    # d(platform force) = -A K (S dv + S_lambda dlambda + S_p dp) = 0
    system = np.zeros((n + m, n + m))
    system[:n, :n] = state["hessian"]
    system[:n, n:] = S.T @ K @ S_lambda
    system[n:, :n] = anchor_sum @ K @ S
    system[n:, n:] = anchor_sum @ K @ S_lambda
    rhs = -np.concatenate([S.T @ K @ S_position @ dp, anchor_sum @ K @ S_position @ dp])
    try:
        delta = np.linalg.solve(system, rhs)
    except np.linalg.LinAlgError:
        return interior, rotation, paid_out
    v = v + delta[:n]
    if layout.free_rotation:
        rotation = float(v[-1])
    return v[:layout.n_interior], rotation, paid_out + delta[n:]


def solve_chain_statics(robot: ChainRobot, position, rotation=0.0, *, free_rotation=None,
                        external_wrench=None, guess: ChainEquilibrium | None = None,
                        tension_guess=None, tolerance: float = 1e-7, max_iterations: int = 50) -> ChainEquilibrium:
    """Paid-out lengths, node positions and rotation that hold the platform at ``position``.

    Tension-only (slack) elements have no stiffness in compression, so Newton started
    from a guess with compressed elements can stall on them. Their equilibrium is first
    sought with springs that also push: where no element of that equilibrium is
    compressed it is the tension-only one as well (the two potentials agree wherever
    every element is stretched); otherwise it is the start of the tension-only solve.

    Two nested Newton iterations. Inner: with the platform held at ``position`` and the
    paid-out lengths given, the nodes (and the free rotation) minimise the potential
    (:func:`_minimise`). Outer: the paid-out lengths are corrected until the cables
    carry the platform, i.e. the force the held platform needs vanishes; its
    derivative follows from the inner tangent stiffness (the nodes stay in equilibrium).

    Parameters
    ----------
    robot : ChainRobot
    position : (x, z) [m]
        Where the platform's centre of mass must be.
    rotation : float [rad]
        The platform's rotation when it is imposed, else the start of the iteration.
    free_rotation : bool, optional
        Let equilibrium choose the rotation (default: for a rigid platform on two
        cables). The problem must be square: a point mass or a rigid platform with a
        free rotation on two cables, or a rigid platform with its rotation imposed on
        three.
    external_wrench : (fx, fz, moment), optional [N, N, N m]
        Extra load on the platform, eg the inertial load -M a.
    guess : ChainEquilibrium, optional
        A nearby solution (the previous pose of a trajectory) to start from.
    tension_guess : array_like, shape (m,) [N], optional
        Cable tensions to start from when there is no ``guess`` (eg the catenary
        statics'): the iteration starts from straight chains that carry them.
    tolerance : float [N]
        Largest force imbalance accepted, on nodes and platform.
    max_iterations : int
        Of each Newton iteration.

    Returns
    -------
    ChainEquilibrium

    Raises
    ------
    UnreachableError
        If there is no equilibrium with the cables in tension, or Newton fails.
    SceneError
        On malformed input or a problem that is not square.
    """
    kwargs = dict(free_rotation=free_rotation, external_wrench=external_wrench, tolerance=tolerance,
                  max_iterations=max_iterations)
    if not any(c.slack for c in robot.cables):
        return _solve_chain_statics(robot, position, rotation, guess=guess, tension_guess=tension_guess, **kwargs)
    springs = ChainRobot(tuple(replace(c, slack=False) for c in robot.cables), robot.mass, robot.gravity)
    try:
        spring = _solve_chain_statics(springs, position, rotation, guess=guess, tension_guess=tension_guess, **kwargs)
    except UnreachableError:
        return _solve_chain_statics(robot, position, rotation, guess=guess, tension_guess=tension_guess, **kwargs)
    if all(np.all(t >= 0.0) for t in spring.tensions):
        return spring
    return _solve_chain_statics(robot, position, rotation, guess=spring, **kwargs)


def _solve_chain_statics(robot: ChainRobot, position, rotation=0.0, *, free_rotation=None,
                         external_wrench=None, guess: ChainEquilibrium | None = None,
                         tension_guess=None, tolerance: float = 1e-7, max_iterations: int = 50) -> ChainEquilibrium:
    """:func:`solve_chain_statics` for one element law (the robot's own)."""
    position = vector("position", position, 2)
    rotation = finite("rotation", rotation)
    m = len(robot.cables)
    rigid = not robot.is_point_mass
    if free_rotation is None:
        free_rotation = rigid and m == 2
    if free_rotation and not rigid:
        raise SceneError("a point-mass platform has no rotation to set free")
    equations = 2 + int(rigid and not free_rotation)
    if m != equations:
        raise SceneError(f"chain statics needs as many cables as platform equations: {m} cables "
                         f"for {equations} ({'rotation free' if free_rotation else 'rotation imposed'})")
    wrench = np.zeros(3) if external_wrench is None else vector("external_wrench", external_wrench, 3)
    layout = _Layout(robot, bool(free_rotation))
    if guess is not None:
        rotation = float(guess.rotation) if free_rotation else rotation
        interior = np.concatenate([n[1:-1].ravel() for n in guess.nodes])
        paid_out = np.array(guess.paid_out, dtype=float)
        if interior.size != layout.n_interior or paid_out.shape != (m,):
            raise SceneError("guess does not belong to this robot (node or cable counts differ)")
        interior, rotation, paid_out = _predict(robot, layout, guess, interior, rotation, paid_out, position, wrench)
    else:
        if tension_guess is None:
            raise SceneError("solve_chain_statics needs a guess or tension_guess")
        tension_guess = np.asarray(tension_guess, dtype=float)
        if tension_guess.shape != (m,) or not np.all(np.isfinite(tension_guess)) or np.any(tension_guess < 0):
            raise SceneError(f"tension_guess must be {m} finite tensions >= 0 [N], got {shown(tension_guess)}")
        interior, paid_out = _straight_guess(robot, position, rotation, tension_guess)
    v = np.concatenate([interior, [rotation] if free_rotation else []])
    inner_iterations = 0
    inner_tolerance = tolerance
    for outer in range(max_iterations):
        inner = _Inner(robot, layout, position, rotation, paid_out, wrench)
        v, state, count = _minimise(inner, v, inner_tolerance, max_iterations)
        inner_iterations += count
        force = _platform_force(robot, layout, state["F"], wrench)
        if np.max(np.abs(force)) < tolerance and inner_tolerance <= tolerance:
            break
        # inexact Newton: the nodes need not balance better than the platform does
        inner_tolerance = max(tolerance, 1e-3 * float(np.max(np.abs(force))))
        gradient, node_motion = _platform_force_gradient(layout, state)
        step = -np.linalg.solve(gradient, force)
        # a paid-out step moves the nodes along the chain: cap it at a tenth of an element
        limit = 0.1 * min(c.element_length for c in robot.cables)
        step *= min(1.0, limit / np.abs(step).max())
        paid_out = paid_out + step
        v = v + node_motion @ step  # predictor: the nodes follow the winches on the tangent
    else:
        raise UnreachableError(f"chain statics did not converge in {max_iterations} iterations at position "
                               f"{np.round(position, 4).tolist()} m (platform force imbalance "
                               f"{np.max(np.abs(force)):.3g} N)")
    p, rotation = state["p"], float(state["rotation"])
    nodes = tuple(p[f:f + n].copy() for f, n in zip(layout.first, layout.counts))
    tensions = tuple(state["tension"][layout.element_cable == i] for i in range(m))
    if any(t[-1] <= 0 for t in tensions):
        raise UnreachableError(f"at position {np.round(position, 4).tolist()} m a cable would have to push "
                               f"(anchor tensions {[round(float(t[-1]), 3) for t in tensions]} N)")
    residual = max(np.max(np.abs(state["gradient"])), np.max(np.abs(force)))
    return ChainEquilibrium(position, rotation, paid_out, nodes, tensions, float(residual), outer + inner_iterations)
