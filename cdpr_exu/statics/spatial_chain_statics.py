"""Static equilibrium of the simulator's own lumped spatial cables: chains of 3-D nodes.

:mod:`cdpr_exu.physics.spatial_statics` treats each cable as a continuous elastic
catenary in its vertical plane, without bending. The spatial simulator does not
(:mod:`cdpr_exu.builder.spatial_robot`): its cable is a chain of n straight elements whose
nodes carry the mass (the scene's lumping, :meth:`CableSpec.node_masses`), with
exact-angle bending springs at the interior nodes (:mod:`cdpr_exu.physics.bending_3d`).
This module solves that discrete model at rest, without Exudyn, as the spatial analogue
of :mod:`cdpr_exu.statics.chain_statics` (forward problem: the unstrained lengths given,
the pose found; the inverse, the pose given and the lengths found, is at the end):

* each cable's first node is held at its exit point (point exits only; swivel pulleys
  are refused), its last node sits at the platform anchor (an exact spherical joint) or
  is tied to it by a stiff isotropic penalty spring (``anchor_spring_factor``, what the
  static mode of :mod:`cdpr_exu.run.spatial_rest` uses on a rigid platform);
* unknowns: the free node positions, the platform position and, for a rigid platform,
  its rotation (updated multiplicatively, ``R <- exp([d]x) R``);
* the total potential: axial springs ``k (|d| - l0)^2 / 2`` (zero in compression when
  the elements are tension-only), bending ``k_theta theta^2 / 2``, node and platform
  weights along -z, and the penalty springs, is minimised by Newton's method with its
  analytic Hessian and a backtracking line search on the energy.

The equilibrium at rest needs no damping. Units SI (m, N, kg, rad); z up, gravity -z.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import rotation_from_vector, rotation_vector, skew
from cdpr_exu.core.validation import finite, vector
from cdpr_exu.physics import bending_3d
from cdpr_exu.physics.spatial_statics import chain_element_mass, node_masses_along, solve_spatial_statics

__all__ = ["SpatialChainCable", "SpatialChainRobot", "SpatialChainEquilibrium", "spatial_chain_robot",
           "solve_spatial_chain_statics", "catenary_start", "spatial_chain_statics", "cable_paid_out",
           "robot_paid_out", "HeldChain", "solve_held_chain", "SpatialChainInverse",
           "solve_inverse_spatial_chain_statics", "InverseChainStatics", "rounding_floor"]


@dataclass(frozen=True)
class SpatialChainCable:
    """One lumped spatial cable as the simulator builds it, for statics.

    Parameters
    ----------
    exit_point : (x, y, z) [m]
        Where node 0 is held (a point exit), world frame.
    node_masses : tuple of float, length n + 1 [kg]
        Exit node first (its weight is carried by the frame).
    element_length : float [m]
        Unstrained element length l0 = L / n.
    axial_stiffness : float [N/m]
        k = EA / l0.
    bending_stiffness : float [N m/rad]
        k_theta = EJ / l0 of each interior joint (0: no bending).
    slack : bool
        Tension-only elements.
    anchor : (x, y, z) [m]
        Anchor in the platform frame (centre of mass at 0).
    """

    exit_point: tuple
    node_masses: tuple
    element_length: float
    axial_stiffness: float
    bending_stiffness: float
    slack: bool
    anchor: tuple

    def __post_init__(self):
        object.__setattr__(self, "exit_point", tuple(vector("exit_point", self.exit_point, 3)))
        object.__setattr__(self, "anchor", tuple(vector("anchor", self.anchor, 3)))
        if len(self.node_masses) < 3:
            raise SceneError(f"node_masses needs at least 3 nodes (2 elements), got {len(self.node_masses)}")
        for name in ("element_length", "axial_stiffness"):
            value = finite(name, getattr(self, name))
            if value <= 0:
                raise SceneError(f"{name} must be positive and finite, got {value!r}")
        if finite("bending_stiffness", self.bending_stiffness) < 0:
            raise SceneError(f"bending_stiffness must be zero or positive, got {self.bending_stiffness!r}")
        if np.any(~np.isfinite(self.node_masses)) or min(self.node_masses) < 0:
            raise SceneError(f"node_masses must be finite and non-negative, got {self.node_masses!r}")

    @property
    def n_elements(self) -> int:
        return len(self.node_masses) - 1

    @property
    def unstrained_length(self) -> float:
        """L = n l0 [m]."""
        return self.n_elements * self.element_length


@dataclass(frozen=True)
class SpatialChainRobot:
    """The platform and its lumped spatial cables.

    Parameters
    ----------
    cables : tuple of SpatialChainCable
    mass : float [kg]
    gravity : float [m/s^2]
        Along -z (0: no gravity, also on the cables).
    anchor_spring_factor : float or None
        None: each cable's last node sits on its anchor (an exact spherical joint). A
        number f > 0: it is tied to the anchor by an isotropic spring of stiffness f k
        (the builder's penalty joint, :class:`cdpr_exu.builder.spatial_robot.SpatialChainSpec`).
    """

    cables: tuple
    mass: float
    gravity: float
    anchor_spring_factor: float | None = None

    def __post_init__(self):
        if not self.cables or not all(isinstance(c, SpatialChainCable) for c in self.cables):
            raise SceneError(f"cables must be a non-empty tuple of SpatialChainCable, got {self.cables!r}")
        object.__setattr__(self, "cables", tuple(self.cables))
        if finite("mass", self.mass) < 0 or finite("gravity", self.gravity) < 0:
            raise SceneError(f"mass and gravity must be zero or positive, got {self.mass!r}, {self.gravity!r}")
        if self.anchor_spring_factor is not None and not finite("anchor_spring_factor", self.anchor_spring_factor) > 0:
            raise SceneError(f"anchor_spring_factor must be positive or None, got {self.anchor_spring_factor!r}")

    @property
    def is_point_mass(self) -> bool:
        """True when every anchor sits at the centre of mass (no rotation to balance)."""
        return all(np.allclose(c.anchor, 0.0) for c in self.cables)


def spatial_chain_robot(scene, anchor_spring_factor: float | None = None) -> SpatialChainRobot:
    """The chain-statics model of a spatial scene, with the effects its builder adds.

    Raises
    ------
    SceneError
        For swivel exits (not modelled here) or a bending model other than the exact angle.
    """
    if any(s is not None for s in scene.swivel_exits):
        raise SceneError("spatial chain statics models point exits only: the scene's exits "
                         f"{[i for i, s in enumerate(scene.swivel_exits) if s is not None]} are swivel pulleys "
                         "(use cdpr static, Exudyn's static solve, for them)")
    effects = scene.effects
    if effects.bending and effects.bending_model != "exact":
        raise SceneError("spatial chain statics models the exact-angle bending only, "
                         f"got effects.bending_model = {effects.bending_model!r}")
    platform = scene.catenary_platform()  # what the builder builds from: weights, EA, gravity
    gravity = platform.gravity
    cables = []
    for spec, cable in zip(scene.cables, platform.cables):
        n, length = spec.n_elements, spec.unstrained_length
        l0 = length / n
        # the builder's lumping (:func:`cdpr_exu.builder.spatial_robot.build_spatial_robot`), to the last bit
        masses = (node_masses_along(n, chain_element_mass(cable, length, n, gravity), spec.mass_lumping)
                  if gravity > 0 else np.zeros(n + 1))
        cables.append(SpatialChainCable(
            exit_point=cable.exit_point, node_masses=tuple(float(m) for m in masses), element_length=l0,
            axial_stiffness=cable.axial_stiffness / l0,
            bending_stiffness=spec.youngs_modulus * spec.second_moment / l0 if effects.bending else 0.0,
            slack=bool(effects.slack), anchor=cable.anchor))
    return SpatialChainRobot(tuple(cables), scene.platform.mass, gravity, anchor_spring_factor)


@dataclass(frozen=True, eq=False)
class SpatialChainEquilibrium:
    """A static equilibrium of the spatial chains and platform.

    Attributes
    ----------
    position : ndarray, shape (3,) [m]
        Platform centre of mass.
    rotation : ndarray, shape (3, 3)
        Platform frame to world frame (identity for a point mass).
    rotation_vector : ndarray, shape (3,) [rad]
    nodes : tuple of ndarray, each shape (n + 1, 3) [m]
        Node positions of each cable, exit first.
    tensions : tuple of ndarray, each shape (n,) [N]
        Axial force of each element, exit first (positive in tension).
    forces_on_platform : ndarray, shape (m, 3) [N]
        Force each cable exerts on the platform at its anchor (the last element's pull, the
        bending shear and the anchor node's weight; the penalty spring's force if any).
    residual : float [N]
        Largest entry of the potential's gradient left (forces [N], moments [N m]).
    iterations : int
    """

    position: np.ndarray
    rotation: np.ndarray
    rotation_vector: np.ndarray
    nodes: tuple
    tensions: tuple
    forces_on_platform: np.ndarray
    residual: float
    iterations: int

    @property
    def tensions_at_anchor(self) -> np.ndarray:
        """Norm of each cable's force on the platform, shape (m,) [N]."""
        return np.linalg.norm(self.forces_on_platform, axis=1)


class _Model:
    """Points, unknowns and the potential with its gradient and Hessian.

    Points (rows of ``P``, shape (n_points, 3)): the chain nodes of every cable, cable after
    cable, then (with penalty joints) one anchor point per cable. Each point is fixed
    (the exit nodes), free (its own three unknowns) or on the platform (``x + R b``).
    Unknowns ``v``: the free points' coordinates, then the platform position, then (rigid)
    the rotation increment ``d`` (``R <- exp([d]x) R``).
    """

    def __init__(self, robot: SpatialChainRobot):
        self.robot = robot
        m = len(robot.cables)
        self.counts = [c.n_elements + 1 for c in robot.cables]
        self.first = np.concatenate([[0], np.cumsum(self.counts)[:-1]]).astype(int)
        n_chain = int(sum(self.counts))
        self.penalty = robot.anchor_spring_factor is not None
        self.n_points = n_chain + (m if self.penalty else 0)
        self.rigid = not robot.is_point_mass
        self.last = self.first + np.asarray(self.counts) - 1
        # body points: (point index, cable)
        self.body = [(n_chain + i if self.penalty else int(self.last[i]), i) for i in range(m)]
        body_points = {p for p, _ in self.body}
        fixed = set(int(f) for f in self.first)
        self.free = np.array([j for j in range(self.n_points) if j not in fixed and j not in body_points], dtype=int)
        self.n_free = 3 * self.free.size
        self.n_unknowns = self.n_free + 3 + (3 if self.rigid else 0)
        self.fixed_positions = {int(f): np.asarray(c.exit_point, float) for f, c in zip(self.first, robot.cables)}
        self.local = np.array([c.anchor for c in robot.cables], dtype=float)
        self.weights = np.zeros(self.n_points)
        self.weights[:n_chain] = np.concatenate([np.asarray(c.node_masses) for c in robot.cables]) * robot.gravity
        elements = [np.stack([np.arange(f, f + n - 1), np.arange(f + 1, f + n)], axis=1)
                    for f, n in zip(self.first, self.counts)]
        self.elements = np.concatenate(elements).astype(int)
        self.element_cable = np.concatenate([np.full(n - 1, i) for i, n in enumerate(self.counts)])
        self.k = np.array([robot.cables[c].axial_stiffness for c in self.element_cable])
        self.l0 = np.array([robot.cables[c].element_length for c in self.element_cable])
        self.slack = np.array([robot.cables[c].slack for c in self.element_cable])
        self.joints = bending_3d.chain_joints(self.counts)
        self.joint_k = np.concatenate([np.full(n - 2, c.bending_stiffness) for c, n in zip(robot.cables, self.counts)])
        if not np.any(self.joint_k > 0):
            self.joints, self.joint_k = self.joints[:0], self.joint_k[:0]
        self.pattern = bending_3d.spatial_bending_pattern(self.joints)
        self.penalty_k = (np.array([robot.anchor_spring_factor * c.axial_stiffness for c in robot.cables])
                          if self.penalty else np.zeros(0))
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
        """Element lengths, unit vectors and axial forces (0 for slack compressed elements)."""
        a, b = self.elements[:, 0], self.elements[:, 1]
        d = p[b] - p[a]
        length = np.linalg.norm(d, axis=1)
        t = d / length[:, None]
        force = self.k * (length - self.l0)
        active = ~(self.slack & (force < 0.0))
        return length, t, np.where(active, force, 0.0), active

    def energy(self, free, x, R):
        """Total potential [J]."""
        p = self.points(free, x, R)
        length, _, _, active = self._axial(p)
        stretch = length - self.l0
        energy = 0.5 * float(np.sum(self.k[active] * stretch[active] ** 2))
        energy += float(self.weights @ p[:, 2]) + self.robot.mass * self.robot.gravity * x[2]
        energy -= float(self.external_force @ x)
        if self.joints.size:
            energy += bending_3d.spatial_bending_energy(p.ravel(), self.joints, self.joint_k)
        if self.penalty:
            for (j, i), k in zip(self.body, self.penalty_k):
                energy += 0.5 * k * float(np.sum((p[self.last[i]] - p[j]) ** 2))
        return energy

    def point_derivatives(self, p):
        """Gradient (3N,) and Hessian (3N, 3N) of the potential in the point coordinates, and the
        element forces (n_elements,) [N]."""
        size = 3 * self.n_points
        G = np.zeros(size)
        H = np.zeros((size, size))
        G[2::3] += self.weights
        length, t, force, active = self._axial(p)
        a, b = self.elements[active, 0], self.elements[active, 1]
        if a.size:
            t, force, length, k = t[active], force[active], length[active], self.k[active]
            # In a chain every node is the first node of one element at most, and the second of one at
            # most: within each of the sums below the indices are distinct, and fancy-indexed += is exact.
            f = force[:, None] * t
            points = G.reshape(-1, 3)  # a view
            points[a] -= f
            points[b] += f
            tt = t[:, :, None] * t[:, None, :]
            blocks = k[:, None, None] * tt + (force / length)[:, None, None] * (np.eye(3) - tt)
            # each element's 3 x 3 block on (a, a) and (b, b), its negative on (a, b) and (b, a)
            offsets = np.arange(3)
            for r, s, sign in ((a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)):
                rows = (3 * r)[:, None, None] + offsets[None, :, None]
                cols = (3 * s)[:, None, None] + offsets[None, None, :]
                H[rows, cols] += sign * blocks
        if self.joints.size:
            flat = p.ravel().copy()
            bend = np.zeros(size)
            bending_3d.spatial_bending_force(flat, self.joints, self.joint_k, bend)
            G -= bend
            values = np.zeros(self.pattern[0].size)
            bending_3d.spatial_bending_stiffness(flat, self.joints, self.joint_k, 1.0, values)
            np.add.at(H, self.pattern, values)
        if self.penalty:
            for (j, i), k in zip(self.body, self.penalty_k):
                last = self.last[i]
                f = k * (p[last] - p[j])
                G[3 * last:3 * last + 3] += f
                G[3 * j:3 * j + 3] -= f
                for r, s, sign in ((last, last, 1.0), (j, j, 1.0), (last, j, -1.0), (j, last, -1.0)):
                    H[3 * r:3 * r + 3, 3 * s:3 * s + 3] += sign * k * np.eye(3)
        return G, H, force

    def derivatives(self, free, x, R):
        """Gradient and Hessian in the unknowns, the points, their gradient and the element forces."""
        p = self.points(free, x, R)
        G, H, force = self.point_derivatives(p)
        T = np.zeros((3 * self.n_points, self.n_unknowns))
        for c, j in enumerate(self.free):
            T[3 * j:3 * j + 3, 3 * c:3 * c + 3] = np.eye(3)
        x0 = self.n_free
        rotation_second = np.zeros((3, 3))
        for j, i in self.body:
            T[3 * j:3 * j + 3, x0:x0 + 3] = np.eye(3)
            if self.rigid:
                arm = R @ self.local[i]
                T[3 * j:3 * j + 3, x0 + 3:x0 + 6] = -skew(arm)  # d(exp([d]x) b) = d x b
                g = G[3 * j:3 * j + 3]
                rotation_second += 0.5 * (np.outer(g, arm) + np.outer(arm, g)) - float(g @ arm) * np.eye(3)
        gradient = T.T @ G
        gradient[x0 + 2] += self.robot.mass * self.robot.gravity
        gradient[x0:x0 + 3] -= self.external_force
        hessian = T.T @ H @ T
        if self.rigid:
            hessian[x0 + 3:, x0 + 3:] += rotation_second
        return gradient, hessian, p, G, force

    def step(self, free, x, R, delta):
        """The state moved by ``delta`` (unknowns)."""
        x0 = self.n_free
        free = free + delta[:x0]
        x = x + delta[x0:x0 + 3]
        if self.rigid:
            R = rotation_from_vector(delta[x0 + 3:]) @ R
        return free, x, R


def catenary_start(robot: SpatialChainRobot, equilibrium):
    """Start of the iteration: the nodes on the catenary statics' cables, as the builder starts its chains.

    Parameters
    ----------
    robot : SpatialChainRobot
    equilibrium : SpatialEquilibrium
        Of the same cables (:func:`cdpr_exu.physics.spatial_statics.solve_spatial_statics`).

    Returns
    -------
    nodes : list of ndarray, each shape (n + 1, 3) [m]
    position : ndarray, shape (3,) [m]
    rotation : ndarray, shape (3, 3)
    """
    if len(equilibrium.cables) != len(robot.cables):
        raise SceneError(f"equilibrium has {len(equilibrium.cables)} cables, the robot {len(robot.cables)}")
    nodes = []
    for cable, state in zip(robot.cables, equilibrium.cables):
        length = cable.unstrained_length
        points = state.points(length - np.linspace(0.0, length, cable.n_elements + 1))
        points[0] = cable.exit_point
        points[-1] = state.anchor_point
        nodes.append(points)
    return nodes, np.asarray(equilibrium.position, float), np.asarray(equilibrium.rotation, float)


def solve_spatial_chain_statics(robot: SpatialChainRobot, nodes, position, rotation=None, *,
                                tolerance: float = 1e-9, max_iterations: int = 100,
                                external_force=None) -> SpatialChainEquilibrium:
    """The rest configuration of the chains and platform for the cables' unstrained lengths.

    Parameters
    ----------
    robot : SpatialChainRobot
    nodes : sequence of array_like, each shape (n + 1, 3) [m]
        Start positions of each cable's nodes, exit first (eg :func:`catenary_start`);
        the exit node is put on the exit point and (with exact joints) the last on the anchor.
    position : (x, y, z) [m]
        Start of the platform's centre of mass.
    rotation : ndarray, shape (3, 3), optional
        Start of the platform's rotation (default identity; ignored for a point mass).
    tolerance : float [N]
        Largest entry of the potential's gradient accepted (node forces, platform force, moment);
        at least the rounding of the element forces (:func:`rounding_floor`: 4e-9 N on the
        four-cable robot, 1.6e-7 N on CoGiRo's steel ropes, where 1e-9 N cannot be reached).
    max_iterations : int
    external_force : (fx, fy, fz) [N], optional
        A constant extra force on the platform's centre of mass (eg the d'Alembert force
        -M a of an acceleration); its potential is -F . x.

    Returns
    -------
    SpatialChainEquilibrium

    Raises
    ------
    UnreachableError
        If Newton finds no equilibrium.
    SceneError
        On malformed input.
    """
    model = _Model(robot)
    if external_force is not None:
        model.external_force = vector("external_force", external_force, 3, " (fx, fy, fz) [N]")
    x = vector("position", position, 3)
    R = np.eye(3) if rotation is None or not model.rigid else np.asarray(rotation, float)
    if R.shape != (3, 3) or not np.allclose(R.T @ R, np.eye(3), atol=1e-9):
        raise SceneError(f"rotation must be a 3 x 3 rotation matrix, got {rotation!r}")
    if len(nodes) != len(robot.cables):
        raise SceneError(f"nodes must give one array per cable ({len(robot.cables)}), got {len(nodes)}")
    start = np.zeros((model.n_points, 3))
    for i, (cable, n) in enumerate(zip(robot.cables, nodes)):
        n = np.asarray(n, dtype=float)
        if n.shape != (cable.n_elements + 1, 3) or not np.all(np.isfinite(n)):
            raise SceneError(f"nodes[{i}] must be finite, shape {(cable.n_elements + 1, 3)}, got {n.shape}")
        start[model.first[i]:model.first[i] + cable.n_elements + 1] = n
    if model.penalty:
        for j, i in model.body:
            start[j] = x + R @ model.local[i]
    free = start[model.free].ravel()
    energy = model.energy(free, x, R)
    tolerance = max(tolerance, rounding_floor(model.k, start))
    for iteration in range(max_iterations):
        gradient, hessian, p, G, force = model.derivatives(free, x, R)
        if np.max(np.abs(gradient)) < tolerance:
            break
        shift = 0.0
        while True:
            try:
                step = np.linalg.solve(hessian + shift * np.eye(len(gradient)), -gradient)
            except np.linalg.LinAlgError:
                step = None
            if step is not None and np.all(np.isfinite(step)) and float(step @ gradient) < 0.0:
                break
            shift = max(10.0 * shift, 1e-8 * np.abs(np.diag(hessian)).max())
        slope = float(step @ gradient)
        # near the solution the energy's decrease ~ |g|^2 / k falls below its rounding: then the
        # full step is taken if it shrinks the gradient, and the iteration stops if it does not
        roundoff = 1e-13 * (1.0 + abs(energy))
        alpha, accepted = 1.0, False
        for _ in range(40):
            trial = model.step(free, x, R, alpha * step)
            trial_energy = model.energy(*trial)
            if trial_energy <= energy + 1e-4 * alpha * slope:
                accepted = True
                break
            if abs(trial_energy - energy) <= roundoff:
                accepted = np.max(np.abs(model.derivatives(*trial)[0])) < np.max(np.abs(gradient))
                break
            alpha *= 0.5
        if not accepted:
            if np.max(np.abs(gradient)) < 10.0 * tolerance:  # stalled at rounding, close enough
                break
            raise UnreachableError(f"spatial chain statics: the line search failed (force imbalance "
                                   f"{np.max(np.abs(gradient)):.3g} N after {iteration} iterations)")
        free, x, R = trial
        energy = trial_energy
    else:
        raise UnreachableError(f"spatial chain statics did not converge in {max_iterations} iterations "
                               f"(force imbalance {np.max(np.abs(gradient)):.3g} N)")
    chain_nodes = tuple(p[f:f + n].copy() for f, n in zip(model.first, model.counts))
    tensions = tuple(force[model.element_cable == i] for i in range(len(robot.cables)))
    forces = _forces_on_platform(model, p, G)
    return SpatialChainEquilibrium(x.copy(), R.copy(), rotation_vector(R) if model.rigid else np.zeros(3),
                                   chain_nodes, tensions, forces, float(np.max(np.abs(gradient))), iteration)


def rounding_floor(stiffness, points) -> float:
    """The force [N] below which a chain's node forces are rounding: an element's k (l - l0), its length
    computed from coordinates of size |p|, carries k |p| eps; 16 times that for the sums. ``stiffness``:
    the elements' k [N/m]; ``points``: the coordinates [m]."""
    return 16.0 * np.finfo(float).eps * float(np.max(stiffness)) * float(np.abs(points).max())


def _forces_on_platform(model: _Model, p, G):
    """Force each cable exerts on its anchor, shape (m, 3) [N], from the point gradient ``G``."""
    forces = np.zeros((len(model.robot.cables), 3))
    for (j, i) in model.body:
        if model.penalty:
            forces[i] = model.penalty_k[i] * (p[model.last[i]] - p[j])
        else:
            # the chain's pull on the anchor node, its weight included: -dU_chain/dp
            forces[i] = -G[3 * j:3 * j + 3]
    return forces


def spatial_chain_statics(scene, anchor_spring_factor: float | None = None, **kwargs) -> SpatialChainEquilibrium:
    """The lumped robot of a spatial scene at rest, started on its catenary statics (as the static mode starts
    Exudyn's); ``kwargs`` go to :func:`solve_spatial_chain_statics`.

    Raises
    ------
    SceneError
        For swivel exits (:func:`spatial_chain_robot`).
    UnreachableError
        If the catenary statics or the chains find no equilibrium.
    """
    robot = spatial_chain_robot(scene, anchor_spring_factor)
    catenary = solve_spatial_statics(scene.catenary_platform(), scene.unstrained_lengths)
    return solve_spatial_chain_statics(robot, *catenary_start(robot, catenary), **kwargs)


# ---------------------------------------------------------------------------
# the inverse: lengths whose chains hold a pose
# ---------------------------------------------------------------------------
def cable_paid_out(cable: SpatialChainCable, length: float) -> SpatialChainCable:
    """``cable`` paid out to the unstrained ``length`` [m], as the run's variable-length winch changes it
    (:class:`cdpr_exu.run.spatial_run._SpatialWinches`): the same n elements of length L / n, their
    stiffness E A n / L, the node masses rho L / n and the bending stiffness E J n / L."""
    length = finite("length", length)
    if length <= 0:
        raise SceneError(f"length must be positive [m], got {length!r}")
    scale = length / cable.unstrained_length
    return replace(cable, element_length=cable.element_length * scale, axial_stiffness=cable.axial_stiffness / scale,
                   node_masses=tuple(m * scale for m in cable.node_masses),
                   bending_stiffness=cable.bending_stiffness / scale)


def robot_paid_out(robot: SpatialChainRobot, lengths) -> SpatialChainRobot:
    """``robot`` with each cable paid out to ``lengths`` (m,) [m] (:func:`cable_paid_out`)."""
    lengths = np.asarray(lengths, dtype=float).reshape(-1)
    if lengths.size != len(robot.cables):
        raise SceneError(f"lengths must give one length per cable ({len(robot.cables)}), got {lengths.size}")
    return replace(robot, cables=tuple(cable_paid_out(c, L) for c, L in zip(robot.cables, lengths)))


@dataclass(frozen=True, eq=False)
class HeldChain:
    """One lumped cable at rest between its exit point and a fixed anchor point.

    Attributes
    ----------
    nodes : ndarray, shape (n + 1, 3) [m]
        Exit first, the anchor point last.
    tensions : ndarray, shape (n,) [N]
        Axial force of each element, exit first.
    force : ndarray, shape (3,) [N]
        Force the cable exerts on the anchor (the last element's pull, the bending shear and
        the anchor node's weight: what it exerts on the platform).
    force_rate : ndarray, shape (3,) [N/m]
        d(force)/d(unstrained length) with both ends held: the chain re-settles (implicit
        function theorem on the nodes' balance).
    """

    nodes: np.ndarray
    tensions: np.ndarray
    force: np.ndarray
    force_rate: np.ndarray


def _held_model(cable: SpatialChainCable, gravity: float) -> _Model:
    """The model of one cable whose anchor is a fixed point: a one-cable robot of no mass with the anchor at
    its centre, whose position unknowns are kept fixed."""
    return _Model(SpatialChainRobot((replace(cable, anchor=(0.0, 0.0, 0.0)),), 0.0, gravity))


def solve_held_chain(cable: SpatialChainCable, gravity: float, anchor_point, nodes, *, tolerance: float = 1e-9,
                     max_iterations: int = 50) -> HeldChain:
    """The rest shape of one lumped cable held at its exit point and at ``anchor_point``.

    Newton's method on its free nodes (the potential of :func:`solve_spatial_chain_statics`, with
    the same line search), then the force on the anchor and its rate with the unstrained length.

    Parameters
    ----------
    cable : SpatialChainCable
        At the unstrained length wanted (:func:`cable_paid_out`); its ``anchor`` is not used.
    gravity : float [m/s^2]
    anchor_point : (x, y, z) [m]
        World position of the anchor.
    nodes : array_like, shape (n + 1, 3) [m]
        Start of the nodes, exit first; the ends are put on the exit and anchor points, the nodes
        between moved along by the same share of the ends' displacement as of the cable.
    tolerance : float [N]
        Largest force left on a free node; below the rounding of the element forces
        (:func:`rounding_floor`: 4e-8 N on IPAnema's stiff cables, 2e-14 m of stretch), the
        iteration also stops once a Newton step no longer halves it.

    Raises
    ------
    UnreachableError
        If Newton finds no rest shape.
    """
    return _solve_held(_held_model(cable, gravity), cable, anchor_point, nodes, tolerance, max_iterations)


def _solve_held(model: _Model, cable: SpatialChainCable, anchor_point, nodes, tolerance: float,
                max_iterations: int) -> HeldChain:
    """:func:`solve_held_chain` with the cable's model given (built once, :func:`_paid_out_model` for other lengths)."""
    anchor_point = vector("anchor_point", anchor_point, 3)
    nodes = np.array(nodes, dtype=float)
    n = cable.n_elements
    if nodes.shape != (n + 1, 3) or not np.all(np.isfinite(nodes)):
        raise SceneError(f"nodes must be finite, shape {(n + 1, 3)}, got {nodes.shape}")
    share = np.linspace(0.0, 1.0, n + 1)[:, None]
    exit_point = np.asarray(cable.exit_point)
    nodes += (1.0 - share) * (exit_point - nodes[0]) + share * (anchor_point - nodes[-1])
    R = np.eye(3)
    inner = slice(3, 3 * n)  # the free nodes' rows among the points (exit, free nodes, anchor)
    end = slice(3 * n, 3 * n + 3)
    free = nodes[1:-1].ravel().copy()
    energy = model.energy(free, anchor_point, R)
    # Below the rounding floor Newton keeps gaining while it can: the anchor force of a chain stopped
    # at the floor is off by about the floor, and m of them stall the platform's balance (CoGiRo's
    # Gauss-Newton crawled for 30 iterations at 1e-5 N). So stop at the tolerance, or below the floor
    # once a step no longer halves the imbalance.
    floor = rounding_floor(model.k, nodes)
    last = np.inf
    for iteration in range(max_iterations):
        nodes[1:-1] = free.reshape(-1, 3)
        G, H, force = model.point_derivatives(nodes)
        g = G[inner]
        imbalance = float(np.max(np.abs(g)))
        if imbalance < tolerance or (imbalance < floor and imbalance > 0.5 * last):
            break
        last = imbalance
        step = _descent(H[inner, inner], g)
        slope = float(step @ g)
        roundoff = 1e-13 * (1.0 + abs(energy))
        alpha, accepted = 1.0, False
        for _ in range(40):
            trial = free + alpha * step
            trial_energy = model.energy(trial, anchor_point, R)
            if trial_energy <= energy + 1e-4 * alpha * slope:
                accepted = True
                break
            if abs(trial_energy - energy) <= roundoff:
                moved = nodes.copy()
                moved[1:-1] = trial.reshape(-1, 3)
                accepted = np.max(np.abs(model.point_derivatives(moved)[0][inner])) < np.max(np.abs(g))
                break
            alpha *= 0.5
        if not accepted:
            if imbalance < max(10.0 * tolerance, floor):
                break
            raise UnreachableError(f"held chain statics: the line search failed (force imbalance "
                                   f"{np.max(np.abs(g)):.3g} N after {iteration} iterations)")
        free, energy = trial, trial_energy
    else:
        raise UnreachableError(f"held chain statics did not converge in {max_iterations} iterations "
                               f"(force imbalance {np.max(np.abs(g)):.3g} N)")
    # d(gradient)/dL at fixed nodes by central differences of the chain paid out by +-dL (the run's
    # scaling, :func:`cable_paid_out`), then the free nodes re-settle: d(free)/dL = -H^-1 dg_free/dL;
    # the anchor's force is -(its gradient)
    step = 1e-6
    rate = (_paid_out_model(model, 1.0 + step).point_derivatives(nodes)[0]
            - _paid_out_model(model, 1.0 - step).point_derivatives(nodes)[0]) / (2.0 * step * cable.unstrained_length)
    settle = -np.linalg.solve(H[inner, inner], rate[inner])
    force_rate = -(rate[end] + H[end, inner] @ settle)
    return HeldChain(nodes, np.asarray(force, dtype=float).copy(), -G[end].copy(), force_rate)


def _paid_out_model(model: _Model, scale: float) -> _Model:
    """A copy of a one-cable ``model`` with its cable paid out ``scale`` times as long, as :func:`cable_paid_out`:
    element lengths and weights times ``scale``, axial and bending stiffness over it."""
    import copy

    scaled = copy.copy(model)
    scaled.l0, scaled.k = model.l0 * scale, model.k / scale
    scaled.weights, scaled.joint_k = model.weights * scale, model.joint_k / scale
    return scaled


def _descent(hessian, gradient):
    """Newton's step, shifted towards steepest descent until it descends."""
    shift = 0.0
    while True:
        try:
            step = np.linalg.solve(hessian + shift * np.eye(len(gradient)), -gradient)
        except np.linalg.LinAlgError:
            step = None
        if step is not None and np.all(np.isfinite(step)) and float(step @ gradient) < 0.0:
            return step
        shift = max(10.0 * shift, 1e-8 * np.abs(np.diag(hessian)).max())


@dataclass(frozen=True, eq=False)
class SpatialChainInverse:
    """Unstrained lengths whose lumped chains hold the platform at a pose.

    Attributes
    ----------
    unstrained_lengths : ndarray, shape (m,) [m]
    tensions : ndarray, shape (m,) [N]
        Norm of each cable's force on the platform.
    forces_on_platform : ndarray, shape (m, 3) [N]
    nodes : tuple of ndarray, each shape (n + 1, 3) [m]
        Each cable's nodes, exit first (a start for the next pose or the forward statics).
    residual : float [N]
        Largest force (and moment / arm) imbalance of the platform left.
    iterations : int
    """

    unstrained_lengths: np.ndarray
    tensions: np.ndarray
    forces_on_platform: np.ndarray
    nodes: tuple
    residual: float
    iterations: int


def solve_inverse_spatial_chain_statics(robot: SpatialChainRobot, pose, tension_guess, lengths, nodes,
                                        external_wrench=None, *, tolerance: float = 1e-9,
                                        max_iterations: int = 30) -> SpatialChainInverse:
    """Unstrained lengths whose lumped chains hold ``robot``'s platform at ``pose``, tensions nearest a guess.

    With the pose given, every anchor is a fixed point, and each cable is a chain between two
    held ends (:func:`solve_held_chain`): the cables decouple, and only the platform's balance
    ties them, six equations (three for a point mass, or a rigid platform on fewer than six
    cables, whose rotation is left free as in
    :func:`cdpr_exu.physics.spatial_statics.solve_inverse_spatial_statics`) in the m lengths.
    Gauss-Newton on the lengths, each cable's force derivative from its own chain: among the
    length changes that cancel the imbalance to first order, the one whose tensions (the norm
    of each cable's force on the platform) come nearest ``tension_guess``. Continuing from the
    previous pose's tensions along a trajectory, a redundant robot keeps its internal tension.

    Parameters
    ----------
    robot : SpatialChainRobot
        The cables (any lengths: they are paid out to ``lengths``), anchors, platform mass.
    pose : array_like, shape (3,) or (6,) [m, rad]
        Centre of mass and (rigid) rotation vector.
    tension_guess : array_like, shape (m,) [N]
        Positive tensions to stay near (eg the previous pose's).
    lengths : array_like, shape (m,) [m]
        Start of the unstrained lengths (eg the catenaries' inverse, or the previous pose's).
    nodes : sequence of array_like, each shape (n + 1, 3) [m]
        Start of each cable's nodes, exit first (moved onto the anchors as :func:`solve_held_chain` does).
    external_wrench : array_like, shape (6,) [N, N m], optional
        Extra load on the platform about its centre of mass (eg the d'Alembert force).
    tolerance : float
        Imbalance accepted, relative to the larger of the weight and the largest cable force.

    Returns
    -------
    SpatialChainInverse

    Raises
    ------
    UnreachableError
        If no lengths with positive tensions balance the platform there (a cable would have to
        push or go slack), or the iteration does not converge.
    """
    return InverseChainStatics(robot).solve(pose, tension_guess, lengths, nodes, external_wrench,
                                            tolerance=tolerance, max_iterations=max_iterations)


class InverseChainStatics:
    """:func:`solve_inverse_spatial_chain_statics` for many poses of one robot: each cable's model is
    built once (the lengths change by scaling it, :func:`_paid_out_model`).

    Parameters
    ----------
    robot : SpatialChainRobot
    """

    def __init__(self, robot: SpatialChainRobot):
        self.robot = robot
        self.models = [_held_model(c, robot.gravity) for c in robot.cables]

    def solve(self, pose, tension_guess, lengths, nodes, external_wrench=None, *, tolerance: float = 1e-9,
              max_iterations: int = 30) -> SpatialChainInverse:
        """As :func:`solve_inverse_spatial_chain_statics` (same parameters, robot aside)."""
        return _solve_inverse(self.robot, self.models, pose, tension_guess, lengths, nodes, external_wrench,
                              tolerance, max_iterations)


def _solve_inverse(robot, models, pose, tension_guess, lengths, nodes, external_wrench, tolerance, max_iterations):
    """The Gauss-Newton of :func:`solve_inverse_spatial_chain_statics`, each cable's held model given."""
    from cdpr_exu.core.validation import real_array

    m = len(robot.cables)
    pose = real_array("pose", pose)
    rigid = not robot.is_point_mass
    if pose.shape != (6,) and not (not rigid and pose.shape == (3,)):
        raise SceneError(f"pose must have 6 entries (3 for a point mass), got {pose.tolist()!r}")
    guess = real_array("tension_guess", tension_guess)
    if guess.shape != (m,) or np.any(guess <= 0.0):
        raise SceneError(f"tension_guess must be one positive tension per cable, got {tension_guess!r}")
    lengths = real_array("lengths", lengths)
    if lengths.shape != (m,) or np.any(lengths <= 0.0):
        raise SceneError(f"lengths must be one positive length per cable, got {lengths!r}")
    if len(nodes) != m:
        raise SceneError(f"nodes must give one array per cable ({m}), got {len(nodes)}")
    wrench = np.zeros(6) if external_wrench is None else vector("external_wrench", external_wrench, 6)
    rotation = rotation_from_vector(pose[3:6]) if rigid else np.eye(3)
    arms = np.array([c.anchor for c in robot.cables]) @ rotation.T
    anchor_points = pose[:3] + arms
    rows = 6 if (rigid and m >= 6) else 3
    weight = robot.mass * robot.gravity
    arm_scale = max(float(np.linalg.norm(arms, axis=1).max()), 1e-3)
    scale = np.array([1.0, 1.0, 1.0, 1.0 / arm_scale, 1.0 / arm_scale, 1.0 / arm_scale])[:rows]

    def held(trial_lengths, trial_nodes):
        chains = [_solve_held(_paid_out_model(model, L / c.unstrained_length), cable_paid_out(c, L), a, start,
                              1e-9, 50)
                  for model, c, L, a, start in zip(models, robot.cables, trial_lengths, anchor_points, trial_nodes)]
        forces = np.array([chain.force for chain in chains])
        total = np.concatenate([forces.sum(axis=0) + wrench[:3] - [0.0, 0.0, weight],
                                np.cross(arms, forces).sum(axis=0) + wrench[3:]])[:rows] * scale
        return chains, forces, total

    chains, forces, total = held(lengths, nodes)
    residual = float(np.abs(total).max())
    for iteration in range(max_iterations + 1):
        if residual <= tolerance * max(weight, float(np.abs(forces).max()), 1e-12):
            return SpatialChainInverse(lengths, np.linalg.norm(forces, axis=1), forces,
                                       tuple(chain.nodes for chain in chains), residual, iteration)
        if iteration == max_iterations:
            break
        tensions = np.linalg.norm(forces, axis=1)
        rates = np.array([chain.force_rate for chain in chains])
        slope = np.einsum("ij,ij->i", forces, rates) / tensions  # d(tension)/d(length): negative if taut
        if np.any(tensions <= 0.0) or np.any(slope >= 0.0):
            raise UnreachableError(f"pose {np.round(pose, 6).tolist()}: cable(s) "
                                   f"{(np.flatnonzero((tensions <= 0.0) | (slope >= 0.0)) + 1).tolist()} hang slack "
                                   "at these lengths: the chains hold the platform only if a cable pushes")
        jacobian = np.concatenate([rates.T, np.cross(arms, rates).T])[:rows] * scale[:, None]  # d(total)/d(lengths)
        # in the tensions' variables y = slope * dL: the change nearest the guess that cancels the imbalance
        in_tensions = jacobian / slope[None, :]
        offset = tensions - guess
        change = (-offset + np.linalg.pinv(in_tensions) @ (in_tensions @ offset - total)) / slope
        for _ in range(20):  # halve the step until the imbalance falls
            trial = lengths + change
            if np.all(trial > 0.0):
                try:
                    trial_chains, trial_forces, trial_total = held(trial, [c.nodes for c in chains])
                except UnreachableError:
                    trial_total = None
                if trial_total is not None and float(np.abs(trial_total).max()) < residual:
                    break
            change = 0.5 * change
        else:
            break
        lengths, chains, forces, total = trial, trial_chains, trial_forces, trial_total
        residual = float(np.abs(total).max())
    raise UnreachableError(f"pose {np.round(pose, 6).tolist()}: the chains' balance did not converge "
                           f"(imbalance {residual:.3g} N after {iteration} iterations)")
