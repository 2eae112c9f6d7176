"""Static equilibrium of the simulator's own lumped spatial cables: chains of 3-D nodes.

:mod:`cdpr_exu.statics.statics` treats each cable as a continuous elastic
catenary in its vertical plane, without bending. The spatial simulator does not
(:mod:`cdpr_exu.builder.spatial_robot`): its cable is a chain of n straight elements whose
nodes carry the mass (the scene's lumping, :meth:`CableSpec.node_masses`), with
exact-angle bending springs at the interior nodes (:mod:`cdpr_exu.physics.bending_3d`).
This module solves that discrete model at rest, without Exudyn, as the spatial analogue
of :mod:`cdpr_exu.statics.chain_statics` (forward problem: the unstrained lengths given,
the pose found; the inverse, the pose given and the lengths found, is at the end):

* each cable's first node is held at its exit point, or, over a swivel pulley, at its
  winch end on the pulley's vertical axis below the inlet (the cable then runs up the
  axis, over the disc and down to the anchor, as the builder makes it); its last node
  sits at the platform anchor (an exact spherical joint) or is tied to it by a stiff
  isotropic penalty spring (``anchor_spring_factor``, what the static mode of
  :mod:`cdpr_exu.run.spatial_rest` uses on a rigid platform);
* unknowns: the free node positions, the platform position and, for a rigid platform,
  its rotation (updated multiplicatively, ``R <- exp([d]x) R``), and each swivel
  pulley's angle psi (its turn about the vertical axis);
* the total potential: axial springs ``k (|d| - l0)^2 / 2`` (tension-only elements: the
  dynamic model's law, :func:`cdpr_exu.physics.axial_3d.tension_only_energy`, zero below
  the rest length and a C1 smoothstep over a strain of 1e-5), bending
  ``k_theta theta^2 / 2``, node and platform weights along -z, the penalty springs, and
  the swivel pulleys' contact potential (:func:`cdpr_exu.physics.swivel_pulley.swivel_contact_energy`,
  every node of a swivel cable may touch its disc, as in the builder), is minimised by
  Newton's method with its analytic (sparse) Hessian and a backtracking line search on
  the energy. The contact's and the tension-only elements' gradients and Hessians are the
  dynamic model's own kernels at zero velocity (their force and ``-df/dq``), not copies.

Why it exists for swivel pulleys: Exudyn's static solver does not converge from the
catenary start over a swivel pulley (:func:`cdpr_exu.builder.spatial_robot.settle`);
Newton on the energy with a line search does, and its answer is the start of runs and of
the static mode on swivel scenes (:func:`cdpr_exu.builder.spatial_robot.start_at_rest_on`).

The equilibrium at rest needs no damping. Units SI (m, N, kg, rad); z up, gravity -z.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sparse

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import rotation_from_vector, rotation_vector, skew
from cdpr_exu.core.validation import finite, shown, vector
from cdpr_exu.physics import axial_3d, bending_3d
from cdpr_exu.physics import swivel_pulley as sp
from cdpr_exu.statics.chain_statics import descent_step
from cdpr_exu.statics.statics import catenary_platform, chain_element_mass, node_masses_along, solve_statics

__all__ = ["SpatialChainCable", "SpatialChainRobot", "SpatialChainEquilibrium", "spatial_chain_robot",
           "solve_spatial_chain_statics", "catenary_start", "spatial_chain_statics", "swivel_chain_start",
           "winch_line_elements", "cable_paid_out", "robot_paid_out", "HeldChain", "solve_held_chain",
           "SpatialChainInverse", "solve_inverse_spatial_chain_statics", "InverseChainStatics", "rounding_floor"]

_E_Z = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class SpatialChainCable:
    """One lumped spatial cable as the simulator builds it, for statics.

    Parameters
    ----------
    exit_point : (x, y, z) [m]
        Where node 0 is held, world frame: the exit point, or over a swivel pulley the
        winch end on the pulley's vertical axis below its inlet, where the builder holds it
        (``winch_travel`` moves it).
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
    swivel : SwivelPulley or None
        The swivel pulley the cable runs over (:class:`cdpr_exu.physics.swivel_pulley.SwivelPulley`);
        None for a point exit. Every node may touch it.
    winch_elements : int
        Over a swivel pulley: the elements of the winch line, below the inlet (0 for a point exit).
    winch_travel : float [m]
        Over a swivel pulley: how far the winch has moved the held winch end up the axis from
        ``exit_point`` (paying out; 0 for a point exit). The run's swivel winch keeps the chain's
        elements and moves only this end (:class:`cdpr_exu.run.spatial_run._SpatialWinches`).
    """

    exit_point: tuple
    node_masses: tuple
    element_length: float
    axial_stiffness: float
    bending_stiffness: float
    slack: bool
    anchor: tuple
    swivel: sp.SwivelPulley | None = None
    winch_elements: int = 0
    winch_travel: float = 0.0

    def __post_init__(self):
        object.__setattr__(self, "exit_point", tuple(vector("exit_point", self.exit_point, 3)))
        object.__setattr__(self, "anchor", tuple(vector("anchor", self.anchor, 3)))
        if len(self.node_masses) < 3:
            raise SceneError(f"node_masses needs at least 3 nodes (2 elements), got {len(self.node_masses)}")
        for name in ("element_length", "axial_stiffness"):
            value = finite(name, getattr(self, name))
            if value <= 0:
                raise SceneError(f"{name} must be positive and finite, got {shown(value)}")
        if finite("bending_stiffness", self.bending_stiffness) < 0:
            raise SceneError(f"bending_stiffness must be zero or positive, got {shown(self.bending_stiffness)}")
        if np.any(~np.isfinite(self.node_masses)) or min(self.node_masses) < 0:
            raise SceneError(f"node_masses must be finite and non-negative, got {shown(self.node_masses)}")
        if self.swivel is not None and not isinstance(self.swivel, sp.SwivelPulley):
            raise SceneError(f"swivel must be a SwivelPulley or None, got {shown(self.swivel)}")
        if not 0 <= int(self.winch_elements) <= len(self.node_masses) - 3 or (self.swivel is None) != (
                self.winch_elements == 0):
            raise SceneError(f"winch_elements must be 0 for a point exit and leave 2 elements above the inlet "
                             f"over a swivel pulley, got {shown(self.winch_elements)}")
        if finite("winch_travel", self.winch_travel) != 0.0 and self.swivel is None:
            raise SceneError(f"winch_travel must be 0 for a point exit, got {shown(self.winch_travel)}")

    @property
    def n_elements(self) -> int:
        return len(self.node_masses) - 1

    @property
    def unstrained_length(self) -> float:
        """L = n l0 [m] (over a swivel pulley the winch line's elements included)."""
        return self.n_elements * self.element_length

    @property
    def held_point(self) -> np.ndarray:
        """Where node 0 is held [m]: ``exit_point``, over a swivel pulley moved up the axis by ``winch_travel``."""
        return np.asarray(self.exit_point, dtype=float) + self.winch_travel * _E_Z

    @property
    def paid_out_length(self) -> float:
        """The winch's paid-out length [m]: L = n l0 at a point exit; over a swivel pulley the length from the
        inlet the cable was built with, (n - k) l0 (k = ``winch_elements``), plus ``winch_travel``."""
        return (self.n_elements - self.winch_elements) * self.element_length + self.winch_travel


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
            raise SceneError(f"cables must be a non-empty tuple of SpatialChainCable, got {shown(self.cables)}")
        object.__setattr__(self, "cables", tuple(self.cables))
        if finite("mass", self.mass) < 0 or finite("gravity", self.gravity) < 0:
            raise SceneError(f"mass and gravity must be zero or positive, got {shown(self.mass)}, {shown(self.gravity)}")
        if self.anchor_spring_factor is not None and not finite("anchor_spring_factor", self.anchor_spring_factor) > 0:
            raise SceneError(f"anchor_spring_factor must be positive or None, got {shown(self.anchor_spring_factor)}")

    @property
    def is_point_mass(self) -> bool:
        """True when every anchor sits at the centre of mass (no rotation to balance)."""
        return all(np.allclose(c.anchor, 0.0) for c in self.cables)

    @property
    def swivel_cables(self) -> list:
        """Indices of the cables that run over a swivel pulley."""
        return [i for i, c in enumerate(self.cables) if c.swivel is not None]


def winch_line_elements(winch_line: float, element_length: float) -> int:
    """Elements of a cable below a swivel pulley's inlet (its winch line along the axis): the
    winch line ``winch_line`` [m] in elements of ``element_length`` [m], at least 2 (the builder's)."""
    return max(2, int(round(winch_line / element_length)))


def swivel_chain_start(equilibrium_cable, length, n_elements, winch_elements, contact_stiffness):
    """Straight unstrained reference (winch end first) and the catenary statics' node positions of a
    cable over a swivel pulley, shape (k + n + 1, 3) each [m], k = ``winch_elements``.

    From the anchor: the catenary up to the tangent point; then the wrap as the lumped
    cable lies on it, a polygon of chords of the stretched element length (on the arc
    instead, each chord is short by r_p theta^3 / 24 and pushes with up to 3 kN at
    l_e = r_p: Newton then diverged), each node inside the groove by the depth that carries
    its share of the pressure, ``T l_e / (r_p k_p)`` (on the rim itself psi has no stiffness:
    Exudyn's static solver met a singular matrix); then down the axis to the winch end.
    The tension is the catenary's at the tangent point (frictionless wrap, its weight
    left out, as in the statics). The winch end (the first row of both) is where the
    cable is held: the builder holds it there, and so do the chain statics.

    Parameters
    ----------
    equilibrium_cable : SpatialCableState
        The cable in the catenary statics (:func:`cdpr_exu.statics.statics.solve_statics`).
    length : float [m]
        Unstrained length from the inlet to the anchor (the catenary's).
    n_elements, winch_elements : int
        Elements from the inlet to the anchor, and below the inlet.
    contact_stiffness : float [N/m]
        The pulley's penalty stiffness k_p.
    """
    element = length / n_elements
    inlet = equilibrium_cable.inlet
    axial = equilibrium_cable.cable.axial_stiffness
    tension = equilibrium_cable.tension_at_exit
    radius = equilibrium_cable.pulley_radius
    direction = equilibrium_cable.horizontal_direction
    suspended = equilibrium_cable.suspended_length
    arcs = length - element * np.arange(-winch_elements, n_elements + 1)  # unstrained, from the anchor
    hanging = arcs <= suspended
    current = np.empty((len(arcs), 3))
    current[hanging] = equilibrium_cable.points(arcs[hanging])
    stretched = element * (1.0 + tension / axial)
    chord_angle = 2.0 * math.asin(min(1.0, stretched / (2.0 * radius)))  # rim angle per element
    angle = math.pi - equilibrium_cable.wrap_angle + (arcs[~hanging] - suspended) / element * chord_angle
    depth = tension * stretched / (radius * contact_stiffness)
    centre = inlet + radius * direction
    rim = centre + np.outer((radius - depth) * np.cos(angle), direction) + np.outer((radius - depth) * np.sin(angle), _E_Z)
    axis = inlet - np.outer((angle - math.pi) / chord_angle * stretched, _E_Z)
    current[~hanging] = np.where((angle <= math.pi)[:, None], rim, axis)
    # the winch end on the axis, below the inlet by the winch line stretched under the tension at
    # the inlet less its own weight: where the paid-out length puts it, whatever the polygon
    weight = equilibrium_cable.cable.weight_per_length
    below = element * winch_elements
    current[0] = inlet - (below * (1.0 + tension / axial) - weight * below**2 / (2.0 * axial)) * _E_Z
    reference = current[0] + np.outer(element * np.arange(len(current)), _E_Z)
    return reference, current


def _anchor_azimuth(equilibrium_cable) -> float:
    """Azimuth [rad] of the cable's anchor seen from its swivel axis: where the builder starts psi."""
    return sp.exit_azimuth(equilibrium_cable.anchor_point, equilibrium_cable.inlet)


def spatial_chain_robot(scene, anchor_spring_factor: float | None = None, tension_only: bool | None = None,
                        catenary=None) -> SpatialChainRobot:
    """The chain-statics model of a spatial scene, with the effects its builder adds.

    Parameters
    ----------
    scene : Scene
    anchor_spring_factor : float or None
        See :class:`SpatialChainRobot`.
    tension_only : bool, optional
        Default the scene's ``effects.slack`` (the static mode builds spring elements: False).
    catenary : PlatformEquilibrium, optional
        The scene's catenary statics: a cable over a swivel pulley is held at the winch end
        its start shape puts it (:func:`swivel_chain_start`), as the builder holds it; solved
        here when not given and needed.

    Raises
    ------
    SceneError
        For a bending model other than the exact angle.
    """
    effects = scene.effects
    if effects.bending and effects.bending_model != "exact":
        raise SceneError("spatial chain statics models the exact-angle bending only, "
                         f"got effects.bending_model = {shown(effects.bending_model)}")
    platform = catenary_platform(scene)  # what the builder builds from: weights, EA, gravity
    gravity = platform.gravity
    swivels = scene.swivel_exits
    if catenary is None and any(s is not None for s in swivels):
        catenary = solve_statics(platform, scene.unstrained_lengths)
    slack = bool(effects.slack if tension_only is None else tension_only)
    cables = []
    for i, (spec, cable, swivel) in enumerate(zip(scene.cables, platform.cables, swivels)):
        n, length = spec.n_elements, spec.unstrained_length
        l0 = length / n
        below, held, pulley = 0, cable.exit_point, None
        if swivel is not None:
            below = winch_line_elements(swivel.winch_line, l0)
            held = swivel_chain_start(catenary.cables[i], length, n, below, swivel.contact_stiffness)[1][0]
            pulley = swivel.pulley()
        # the builder's lumping (:func:`cdpr_exu.builder.spatial_robot.build_spatial_robot`), to the last bit
        masses = (node_masses_along(n + below, chain_element_mass(cable, length, n, gravity), spec.mass_lumping)
                  if gravity > 0 else np.zeros(n + below + 1))
        cables.append(SpatialChainCable(
            exit_point=held, node_masses=tuple(float(m) for m in masses), element_length=l0,
            axial_stiffness=cable.axial_stiffness / l0,
            bending_stiffness=spec.youngs_modulus * spec.second_moment / l0 if effects.bending else 0.0,
            slack=slack, anchor=cable.anchor, swivel=pulley, winch_elements=below))
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
        Node positions of each cable, exit (or winch end) first.
    tensions : tuple of ndarray, each shape (n,) [N]
        Axial force of each element, exit first (positive in tension).
    forces_on_platform : ndarray, shape (m, 3) [N]
        Force each cable exerts on the platform at its anchor (the last element's pull, the
        bending shear and the anchor node's weight; the penalty spring's force if any).
    residual : float [N]
        Largest entry of the potential's gradient left (forces [N], moments [N m]).
    iterations : int
    swivel_angles : ndarray, shape (m,) [rad]
        Each swivel pulley's angle psi (NaN for a point exit).
    """

    position: np.ndarray
    rotation: np.ndarray
    rotation_vector: np.ndarray
    nodes: tuple
    tensions: tuple
    forces_on_platform: np.ndarray
    residual: float
    iterations: int
    swivel_angles: np.ndarray | None = None

    @property
    def tensions_at_anchor(self) -> np.ndarray:
        """Norm of each cable's force on the platform, shape (m,) [N]."""
        return np.linalg.norm(self.forces_on_platform, axis=1)


class _Model:
    """Points, unknowns and the potential with its gradient and Hessian.

    Points (rows of ``P``, shape (n_points, 3)): the chain nodes of every cable, cable after
    cable, then (with penalty joints) one anchor point per cable. Each point is fixed
    (the held first nodes), free (its own three unknowns) or on the platform (``x + R b``).
    The "point coordinates" are the points' 3 n_points coordinates followed by the swivel
    angles psi (one per swivel cable). Unknowns ``v``: the free points' coordinates, then the
    platform position, then (rigid) the rotation increment ``d`` (``R <- exp([d]x) R``), then
    the swivel angles. A state is the tuple ``(free, x, R, psi)``.
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
        self.swivel_cables = robot.swivel_cables
        self.n_psi = len(self.swivel_cables)
        self.psi0 = self.n_free + 3 + (3 if self.rigid else 0)  # first psi unknown
        self.n_unknowns = self.psi0 + self.n_psi
        self.size = 3 * self.n_points + self.n_psi  # point coordinates and the swivel angles
        self.fixed_positions = {int(f): c.held_point for f, c in zip(self.first, robot.cables)}
        self.local = np.array([c.anchor for c in robot.cables], dtype=float)
        self.weights = np.zeros(self.n_points)
        self.weights[:n_chain] = np.concatenate([np.asarray(c.node_masses) for c in robot.cables]) * robot.gravity
        elements = [np.stack([np.arange(f, f + n - 1), np.arange(f + 1, f + n)], axis=1)
                    for f, n in zip(self.first, self.counts)]
        self.elements = np.ascontiguousarray(np.concatenate(elements).astype(np.int64))
        self.element_cable = np.concatenate([np.full(n - 1, i) for i, n in enumerate(self.counts)])
        self.k = np.array([robot.cables[c].axial_stiffness for c in self.element_cable])
        self.l0 = np.array([robot.cables[c].element_length for c in self.element_cable])
        self.slack = np.array([robot.cables[c].slack for c in self.element_cable])
        self.axial_pattern = axial_3d.tension_only_pattern(self.elements)
        self.joints = bending_3d.chain_joints(self.counts)
        self.joint_k = np.concatenate([np.full(n - 2, c.bending_stiffness) for c, n in zip(robot.cables, self.counts)])
        if not np.any(self.joint_k > 0):
            self.joints, self.joint_k = self.joints[:0], self.joint_k[:0]
        self.pattern = bending_3d.spatial_bending_pattern(self.joints)
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
            self.contacts.append((i, robot.cables[i].swivel, first, count, nodes, index[rows], index[columns], index))
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
        # order of axial_3d.tension_only_pattern; a tension-only element's slope is its law's
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


def catenary_start(robot: SpatialChainRobot, equilibrium):
    """Start of the iteration: the nodes on the catenary statics' cables, as the builder starts its chains.

    Parameters
    ----------
    robot : SpatialChainRobot
    equilibrium : PlatformEquilibrium
        Of the same cables (:func:`cdpr_exu.statics.statics.solve_statics`).

    Returns
    -------
    nodes : list of ndarray, each shape (n + 1, 3) [m]
        Over a swivel pulley the builder's start (:func:`swivel_chain_start`).
    position : ndarray, shape (3,) [m]
    rotation : ndarray, shape (3, 3)
    swivel_angles : ndarray, shape (m,) [rad]
        Each swivel pulley at its anchor's azimuth, as the builder starts it (NaN for a point exit).
    """
    if len(equilibrium.cables) != len(robot.cables):
        raise SceneError(f"equilibrium has {len(equilibrium.cables)} cables, the robot {len(robot.cables)}")
    nodes, angles = [], np.full(len(robot.cables), np.nan)
    for i, (cable, state) in enumerate(zip(robot.cables, equilibrium.cables)):
        length = cable.unstrained_length
        if cable.swivel is not None:
            n = cable.n_elements - cable.winch_elements
            points = swivel_chain_start(state, n * cable.element_length, n, cable.winch_elements,
                                        cable.swivel.contact_stiffness)[1]
            angles[i] = _anchor_azimuth(state)
        else:
            points = state.points(length - np.linspace(0.0, length, cable.n_elements + 1))
            points[0] = cable.exit_point
        points[-1] = state.anchor_point
        nodes.append(points)
    return nodes, np.asarray(equilibrium.position, float), np.asarray(equilibrium.rotation_matrix, float), angles


def solve_spatial_chain_statics(robot: SpatialChainRobot, nodes, position, rotation=None, swivel_angles=None, *,
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
    swivel_angles : array_like, shape (m,) [rad], optional
        Start of each swivel pulley's psi (entries of point exits ignored); default each
        pulley turned towards its cable's last start node.
    tolerance : float [N]
        Largest entry of the potential's gradient accepted (node forces, platform force, moment,
        torques on the swivels [N m]); at least the rounding of the element forces
        (:func:`rounding_floor`: 4e-9 N on the four-cable robot, 1.6e-7 N on CoGiRo's steel
        ropes, where 1e-9 N cannot be reached).
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
        raise SceneError(f"rotation must be a 3 x 3 rotation matrix, got {shown(rotation)}")
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
    if swivel_angles is None:
        psi = np.array([sp.exit_azimuth(np.asarray(nodes[i], float)[-1], robot.cables[i].swivel.inlet_array)
                        for i in model.swivel_cables])
    else:
        angles = np.asarray(swivel_angles, dtype=float)
        if angles.shape != (len(robot.cables),) or not np.all(np.isfinite(angles[model.swivel_cables])):
            raise SceneError(f"swivel_angles must give one finite angle per cable ({len(robot.cables)}, NaN "
                             f"allowed at point exits), got {shown(swivel_angles)}")
        psi = angles[model.swivel_cables].copy()
    state = (start[model.free].ravel(), x, R, psi)
    energy = model.energy(*state)
    tolerance = max(tolerance, rounding_floor(model.k, start))
    for iteration in range(max_iterations):
        gradient, hessian, p, G, force = model.derivatives(*state)
        if np.max(np.abs(gradient)) < tolerance:
            break
        step = descent_step(hessian, gradient)
        slope = float(step @ gradient)
        # near the solution the energy's decrease ~ |g|^2 / k falls below its rounding: then the
        # full step is taken if it shrinks the gradient, and the iteration stops if it does not
        roundoff = 1e-13 * (1.0 + abs(energy))
        alpha, accepted = 1.0, False
        for _ in range(40):
            trial = model.step(*state, alpha * step)
            trial_energy = model.energy(*trial)
            if trial_energy <= energy + 1e-4 * alpha * slope:
                accepted = True
                break
            if abs(trial_energy - energy) <= roundoff:
                accepted = np.max(np.abs(model.derivatives(*trial)[0])) < np.max(np.abs(gradient))
                break
            alpha *= 0.5
        if not accepted:
            # stalled at rounding, close enough: a coordinate's last bit (eps |p|) on the stiffest spring
            # (a penalty joint, f k ~ 1e8 N/m) is a force of 1e-8 N, above the default tolerance
            rounding = rounding_floor(np.abs(hessian.diagonal()), max(1.0, float(np.abs(p).max())))
            if np.max(np.abs(gradient)) < max(10.0 * tolerance, rounding):
                break
            raise UnreachableError(f"spatial chain statics: the line search failed (force imbalance "
                                   f"{np.max(np.abs(gradient)):.3g} N after {iteration} iterations)")
        state = trial
        energy = trial_energy
    else:
        raise UnreachableError(f"spatial chain statics did not converge in {max_iterations} iterations "
                               f"(force imbalance {np.max(np.abs(gradient)):.3g} N)")
    _, x, R, psi = state
    chain_nodes = tuple(p[f:f + n].copy() for f, n in zip(model.first, model.counts))
    tensions = tuple(force[model.element_cable == i] for i in range(len(robot.cables)))
    forces = _forces_on_platform(model, p, G)
    angles = np.full(len(robot.cables), np.nan)
    angles[model.swivel_cables] = psi
    return SpatialChainEquilibrium(x.copy(), R.copy(), rotation_vector(R) if model.rigid else np.zeros(3),
                                   chain_nodes, tensions, forces, float(np.max(np.abs(gradient))), iteration,
                                   angles)


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


def spatial_chain_statics(scene, anchor_spring_factor: float | None = None, tension_only: bool | None = None,
                          **kwargs) -> SpatialChainEquilibrium:
    """The lumped robot of a spatial scene at rest, started on its catenary statics (as the builder starts
    Exudyn's); ``kwargs`` go to :func:`solve_spatial_chain_statics`.

    Raises
    ------
    UnreachableError
        If the catenary statics or the chains find no equilibrium.
    """
    catenary = solve_statics(catenary_platform(scene), scene.unstrained_lengths)
    robot = spatial_chain_robot(scene, anchor_spring_factor, tension_only, catenary)
    return solve_spatial_chain_statics(robot, *catenary_start(robot, catenary), **kwargs)


def rounding_floor(stiffness, points) -> float:
    """The force [N] below which a chain's node forces are rounding: an element's k (l - l0), its length
    computed from coordinates of size |p|, carries k |p| eps; 16 times that for the sums. ``stiffness``:
    the elements' k [N/m]; ``points``: the coordinates [m]."""
    return 16.0 * np.finfo(float).eps * float(np.max(stiffness)) * float(np.abs(points).max())


#: The swivel angles of a chain without swivel pulleys.
_NO_SWIVEL = np.zeros(0)


# ---------------------------------------------------------------------------
# the inverse: lengths whose chains hold a pose
# ---------------------------------------------------------------------------
def cable_paid_out(cable: SpatialChainCable, length: float) -> SpatialChainCable:
    """``cable`` paid out to the unstrained ``length`` [m], as the run's variable-length winch changes it
    (:class:`cdpr_exu.run.spatial_run._SpatialWinches`): at a point exit the same n elements of length
    L / n, their stiffness E A n / L, the node masses rho L / n and the bending stiffness E J n / L; over a
    swivel pulley the same elements, the held winch end moved up the axis by the change of the paid-out
    length (``winch_travel``, :attr:`SpatialChainCable.paid_out_length`), the cable running over the disc."""
    length = finite("length", length)
    if length <= 0:
        raise SceneError(f"length must be positive [m], got {shown(length)}")
    if cable.swivel is not None:
        return replace(cable, winch_travel=cable.winch_travel + length - cable.paid_out_length)
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
        Exit (over a swivel pulley the held winch end) first, the anchor point last.
    tensions : ndarray, shape (n,) [N]
        Axial force of each element, exit first.
    force : ndarray, shape (3,) [N]
        Force the cable exerts on the anchor (the last element's pull, the bending shear and
        the anchor node's weight: what it exerts on the platform).
    force_rate : ndarray, shape (3,) [N/m]
        d(force)/d(paid-out length) with the anchor held: the chain re-settles (implicit
        function theorem on the nodes' and the swivel's balance). Paid out as the run's winch
        pays out (:func:`cable_paid_out`): longer elements at a point exit, the winch end moved
        up the axis over a swivel pulley.
    swivel_angle : float [rad]
        The swivel pulley's angle psi (NaN at a point exit).
    """

    nodes: np.ndarray
    tensions: np.ndarray
    force: np.ndarray
    force_rate: np.ndarray
    swivel_angle: float = float("nan")


def _held_model(cable: SpatialChainCable, gravity: float) -> _Model:
    """The model of one cable whose anchor is a fixed point: a one-cable robot of no mass with the anchor at
    its centre, whose position unknowns are kept fixed."""
    return _Model(SpatialChainRobot((replace(cable, anchor=(0.0, 0.0, 0.0)),), 0.0, gravity))


def solve_held_chain(cable: SpatialChainCable, gravity: float, anchor_point, nodes, *, tolerance: float = 1e-9,
                     max_iterations: int = 50, swivel_angle: float | None = None) -> HeldChain:
    """The rest shape of one lumped cable held at its exit point (or winch end) and at ``anchor_point``.

    Newton's method on its free nodes and, over a swivel pulley, the pulley's angle psi (the
    potential of :func:`solve_spatial_chain_statics`, with the same line search), then the force
    on the anchor and its rate with the paid-out length. If Newton fails from ``nodes``, the
    anchor (and a swivel cable's winch end) is moved there from the start's in sub-steps, each
    solved from the last (:func:`_solve_held`). Over the swivel pulleys of
    spatial-four-cable-swivel, started from the rest's chains with the length changed as the
    straight distance from the inlet: Newton alone crawled (line search) and stopped at 50
    iterations from 2 cm up or 5 cm across; with the sub-steps, 30 cm across and 20 cm up
    converge (0.5 to 4 s, to within 1e-10 relative of Newton alone given 2000 iterations),
    30 cm up does not.

    Parameters
    ----------
    cable : SpatialChainCable
        At the paid-out length wanted (:func:`cable_paid_out`); its ``anchor`` is not used.
    gravity : float [m/s^2]
    anchor_point : (x, y, z) [m]
        World position of the anchor.
    nodes : array_like, shape (n + 1, 3) [m]
        Start of the nodes, exit first; the ends are put on the held and anchor points, the nodes
        between moved along by the same share of the ends' displacement as of the cable.
    tolerance : float [N]
        Largest force left on a free node; below the rounding of the element forces
        (:func:`rounding_floor`: 4e-8 N on IPAnema's stiff cables, 2e-14 m of stretch), the
        iteration also stops once a Newton step no longer halves it.
    swivel_angle : float [rad], optional
        Start of psi over a swivel pulley (default the anchor's azimuth about the axis).

    Raises
    ------
    UnreachableError
        If Newton finds no rest shape, neither from ``nodes`` nor in sub-steps.
    """
    return _solve_held(_held_model(cable, gravity), cable, anchor_point, nodes, tolerance, max_iterations,
                       swivel_angle)


#: Halvings of a held chain's jump the continuation may make (:func:`_solve_held`): at most 2^5 = 32 sub-steps.
CONTINUATION_HALVINGS = 5


def _solve_held(model: _Model, cable: SpatialChainCable, anchor_point, nodes, tolerance: float,
                max_iterations: int, swivel_angle: float | None = None) -> HeldChain:
    """:func:`solve_held_chain` with the cable's model given (built once, :func:`_paid_out_model` for other lengths).

    Newton from ``nodes`` first; only if it fails, by continuation: the anchor moved from the start's last
    node to ``anchor_point`` (and over a swivel pulley the held winch end from the start's height on the axis
    to the model's) in sub-steps, each solved from the previous one's chain, a sub-step that fails halved
    again, at most :data:`CONTINUATION_HALVINGS` times. A start that converges keeps its answer bit for bit.
    """
    anchor_point = vector("anchor_point", anchor_point, 3)
    nodes = np.array(nodes, dtype=float)
    n = cable.n_elements
    if nodes.shape != (n + 1, 3) or not np.all(np.isfinite(nodes)):
        raise SceneError(f"nodes must be finite, shape {(n + 1, 3)}, got {nodes.shape}")
    try:
        return _newton_held(model, cable, anchor_point, nodes, tolerance, max_iterations, swivel_angle)
    except UnreachableError as failure:
        direct = failure
    held_point = model.fixed_positions[0]
    start_anchor = nodes[-1].copy()
    # over a swivel pulley the start's winch end is its height on the axis (the start is slid along itself to it)
    travel = float(np.dot(nodes[0] - held_point, _E_Z)) if cable.swivel is not None else 0.0

    def at(share):
        """The model and anchor point [m] a ``share`` (0 to 1) of the way from the start's to the target's."""
        if share == 1.0:
            return model, anchor_point
        moved = copy.copy(model)
        moved.fixed_positions = {0: held_point + (1.0 - share) * travel * _E_Z}
        return moved, start_anchor + share * (anchor_point - start_anchor)

    def continued(chain_nodes, psi, begin, finish, halvings, failed=False):
        """The chain at share ``finish`` from ``chain_nodes`` (n + 1, 3) [m] and ``psi`` [rad] at share ``begin``
        (``failed``: Newton from there is known to fail)."""
        if not failed:
            sub_model, sub_anchor = at(finish)
            try:
                return _newton_held(sub_model, cable, sub_anchor, chain_nodes, tolerance, max_iterations, psi)
            except UnreachableError:
                if halvings == 0:
                    raise
        middle = 0.5 * (begin + finish)
        half = continued(chain_nodes, psi, begin, middle, halvings - 1)
        return continued(half.nodes, half.swivel_angle, middle, finish, halvings - 1)

    if CONTINUATION_HALVINGS == 0:
        raise direct
    try:
        return continued(nodes, swivel_angle, 0.0, 1.0, CONTINUATION_HALVINGS, failed=True)
    except UnreachableError as failure:
        raise UnreachableError(f"{direct}; and by continuation in up to {2 ** CONTINUATION_HALVINGS} sub-steps: "
                               f"{failure}") from None


def _newton_held(model: _Model, cable: SpatialChainCable, anchor_point, nodes, tolerance: float,
                 max_iterations: int, swivel_angle: float | None = None) -> HeldChain:
    """Newton for :func:`_solve_held` from ``nodes`` (n + 1, 3) [m] (checked), its ends first moved onto the held
    and anchor points (over a swivel pulley by :func:`_swivel_start`)."""
    nodes = np.array(nodes, dtype=float)
    n = cable.n_elements
    share = np.linspace(0.0, 1.0, n + 1)[:, None]
    held_point = model.fixed_positions[0]
    if cable.swivel is None:
        nodes += (1.0 - share) * (held_point - nodes[0]) + share * (anchor_point - nodes[-1])
    else:
        nodes = _swivel_start(nodes, cable.swivel, held_point, anchor_point)
    if cable.swivel is None:
        psi = _NO_SWIVEL
    elif swivel_angle is None or not np.isfinite(swivel_angle):
        psi = np.array([sp.exit_azimuth(anchor_point, cable.swivel.inlet_array)])
    else:
        psi = np.array([float(swivel_angle)])
    R = np.eye(3)
    # the unknowns among the point coordinates (exit, free nodes, anchor, then psi): the free nodes and psi
    inner = np.concatenate([np.arange(3, 3 * n), np.arange(3 * (n + 1), model.size)])
    end = slice(3 * n, 3 * n + 3)
    n_free = 3 * (n - 1)
    free = nodes[1:-1].ravel().copy()
    energy = model.energy(free, anchor_point, R, psi)
    # Below the rounding floor Newton keeps gaining while it can: the anchor force of a chain stopped
    # at the floor is off by about the floor, and m of them stall the platform's balance (CoGiRo's
    # Gauss-Newton crawled for 30 iterations at 1e-5 N). So stop at the tolerance, or below the floor
    # once a step no longer halves the imbalance.
    floor = rounding_floor(model.k, nodes)
    last = np.inf
    # a point exit's chain is solved dense (57 unknowns at 20 elements); over a swivel pulley sparse (SuperLU:
    # 163 unknowns at 48 + 6 elements, whose dense solve took 0.14 s with OpenBLAS's threads on a busy machine)
    dense = cable.swivel is None
    for iteration in range(max_iterations):
        nodes[1:-1] = free.reshape(-1, 3)
        G, H, force = model.point_derivatives(nodes, psi)
        H = H.toarray() if dense else H.tocsc()
        H_inner = H[np.ix_(inner, inner)] if dense else H[inner][:, inner]
        g = G[inner]
        imbalance = float(np.max(np.abs(g)))
        if imbalance < tolerance or (imbalance < floor and imbalance > 0.5 * last):
            break
        last = imbalance
        step = descent_step(H_inner, g)
        slope = float(step @ g)
        roundoff = 1e-13 * (1.0 + abs(energy))
        alpha, accepted = 1.0, False
        for _ in range(40):
            trial, trial_psi = free + alpha * step[:n_free], psi + alpha * step[n_free:]
            trial_energy = model.energy(trial, anchor_point, R, trial_psi)
            if trial_energy <= energy + 1e-4 * alpha * slope:
                accepted = True
                break
            if abs(trial_energy - energy) <= roundoff:
                moved = nodes.copy()
                moved[1:-1] = trial.reshape(-1, 3)
                accepted = np.max(np.abs(model.point_derivatives(moved, trial_psi)[0][inner])) < np.max(np.abs(g))
                break
            alpha *= 0.5
        if not accepted:
            if imbalance < max(10.0 * tolerance, floor):
                break
            raise UnreachableError(f"held chain statics: the line search failed (force imbalance "
                                   f"{np.max(np.abs(g)):.3g} N after {iteration} iterations)")
        free, psi, energy = trial, trial_psi, trial_energy
    else:
        raise UnreachableError(f"held chain statics did not converge in {max_iterations} iterations "
                               f"(force imbalance {np.max(np.abs(g)):.3g} N)")
    if cable.swivel is None:
        # d(gradient)/dL at fixed nodes by central differences of the chain paid out by +-dL (the run's
        # scaling, :func:`cable_paid_out`)
        step = 1e-6
        rate = (_scaled_model(model, 1.0 + step).point_derivatives(nodes, psi)[0]
                - _scaled_model(model, 1.0 - step).point_derivatives(nodes, psi)[0]) / (2.0 * step * cable.unstrained_length)
    else:
        # paying out moves the held winch end up the axis by dL, the elements kept: d(gradient)/dL at
        # fixed free nodes is the Hessian's column of the held node's z
        rate = H[:, 2].toarray().ravel()
    # then the free nodes (and psi) re-settle: d(unknowns)/dL = -H^-1 dg/dL; the anchor's force is -(its gradient)
    if dense:
        settle = -np.linalg.solve(H_inner, rate[inner])
    else:
        from scipy.sparse.linalg import splu

        settle = -splu(H_inner.tocsc()).solve(rate[inner])
    force_rate = -(rate[end] + H[end][:, inner] @ settle)
    return HeldChain(nodes, np.asarray(force, dtype=float).copy(), -G[end].copy(), force_rate,
                     float(psi[0]) if psi.size else float("nan"))


def _swivel_start(nodes, pulley, held_point, anchor_point):
    """Start nodes (n + 1, 3) [m] of a chain over a swivel pulley from ``nodes`` held elsewhere: turned about the
    axis to the new anchor's azimuth (the wrap stays in the groove: shifted across, it cuts into the disc or its
    flange at 1e6 N/m), all slid along themselves by the winch end's travel (the cable flows over the disc, its
    elements keep their lengths: slid by a share of the travel, a 5 cm element's length changes by 0.15 mm per
    8 mm of travel, 235 N of tension), and the hanging part beyond the wrap moved onto the anchor by the share
    of its length (about across the cable when the travel follows the anchor's distance)."""
    inlet = pulley.inlet_array
    azimuth = sp.exit_azimuth(anchor_point, inlet)
    turn = azimuth - sp.exit_azimuth(nodes[-1], inlet)
    c, s = math.cos(turn), math.sin(turn)
    turned = nodes - inlet
    turned[:, :2] = turned[:, :2] @ np.array([[c, s], [-s, c]])
    nodes = inlet + turned
    centre = inlet + pulley.radius * np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
    radii = np.linalg.norm(nodes - centre, axis=1)
    slid, element, fraction = _slid(nodes, np.full(len(nodes), float(np.dot(held_point - nodes[0], _E_Z))))
    # on the wrap, along the arc: a node slid along a chord sits inside the groove by up to the chord's
    # sagitta (3 mm for 5 cm elements on a 0.1 m disc: 3 kN at 1e6 N/m, which Newton could not undo)
    wrap = (radii[element] < 1.02 * pulley.radius) & (radii[element + 1] < 1.02 * pulley.radius)
    radius = (1.0 - fraction) * radii[element] + fraction * radii[element + 1]
    offset = slid - centre
    slid[wrap] = centre + offset[wrap] * (radius[wrap] / np.linalg.norm(offset[wrap], axis=1))[:, None]
    nodes = slid
    touching = np.flatnonzero(np.linalg.norm(nodes - centre, axis=1) < 1.05 * pulley.radius)
    tangent = int(touching.max()) if touching.size else 0
    weight = np.clip((np.arange(len(nodes)) - tangent) / (len(nodes) - 1 - tangent), 0.0, 1.0)
    nodes += weight[:, None] * (anchor_point - nodes[-1])
    nodes[0] = held_point
    return nodes


def _slid(nodes, shift):
    """``nodes`` (n + 1, 3) [m] each moved along their own polyline by ``shift`` (n + 1,) [m] of arc length
    (positive: towards the last node; beyond the ends along the end elements); with the element each
    lands on and the fraction along it, shape (n + 1,) each."""
    lengths = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(lengths)])
    target = arc + shift
    element = np.clip(np.searchsorted(arc, target, side="right") - 1, 0, len(lengths) - 1)
    fraction = (target - arc[element]) / lengths[element]
    return nodes[element] + fraction[:, None] * (nodes[element + 1] - nodes[element]), element, fraction


def _paid_out_model(model: _Model, cable: SpatialChainCable, length: float) -> _Model:
    """A copy of the held ``model`` of ``cable`` (the model's own cable) paid out to ``length`` [m], as
    :func:`cable_paid_out`: at a point exit scaled (:func:`_scaled_model`), over a swivel pulley its held
    winch end moved up the axis."""
    if cable.swivel is None:
        return _scaled_model(model, length / cable.unstrained_length)
    import copy

    moved = copy.copy(model)
    moved.fixed_positions = {0: cable_paid_out(cable, length).held_point}
    return moved


def _scaled_model(model: _Model, scale: float) -> _Model:
    """A copy of a one-cable ``model`` with its cable paid out ``scale`` times as long, as :func:`cable_paid_out`
    at a point exit: element lengths and weights times ``scale``, axial and bending stiffness over it."""
    import copy

    scaled = copy.copy(model)
    scaled.l0, scaled.k = model.l0 * scale, model.k / scale
    scaled.weights, scaled.joint_k = model.weights * scale, model.joint_k / scale
    return scaled


@dataclass(frozen=True, eq=False)
class SpatialChainInverse:
    """Unstrained lengths whose lumped chains hold the platform at a pose.

    Attributes
    ----------
    unstrained_lengths : ndarray, shape (m,) [m]
        The paid-out lengths (:attr:`SpatialChainCable.paid_out_length`: over a swivel pulley from the inlet).
    tensions : ndarray, shape (m,) [N]
        Norm of each cable's force on the platform.
    forces_on_platform : ndarray, shape (m, 3) [N]
    nodes : tuple of ndarray, each shape (n + 1, 3) [m]
        Each cable's nodes, exit first (a start for the next pose or the forward statics).
    residual : float [N]
        Largest force (and moment / arm) imbalance of the platform left.
    iterations : int
    swivel_angles : ndarray, shape (m,) [rad]
        Each swivel pulley's angle psi (NaN at a point exit).
    """

    unstrained_lengths: np.ndarray
    tensions: np.ndarray
    forces_on_platform: np.ndarray
    nodes: tuple
    residual: float
    iterations: int
    swivel_angles: np.ndarray | None = None


def solve_inverse_spatial_chain_statics(robot: SpatialChainRobot, pose, tension_guess, lengths, nodes,
                                        external_wrench=None, *, tolerance: float = 1e-9,
                                        max_iterations: int = 30, swivel_angles=None) -> SpatialChainInverse:
    """Unstrained lengths whose lumped chains hold ``robot``'s platform at ``pose``, tensions nearest a guess.

    With the pose given, every anchor is a fixed point, and each cable is a chain between two
    held ends (:func:`solve_held_chain`): the cables decouple, and only the platform's balance
    ties them, six equations (three for a point mass, or a rigid platform on fewer than six
    cables, whose rotation is left free as in
    :func:`cdpr_exu.statics.statics.solve_inverse_statics`) in the m lengths.
    Gauss-Newton on the lengths, each cable's force derivative from its own chain: among the
    length changes that cancel the imbalance to first order, the one whose tensions (the norm
    of each cable's force on the platform) come nearest ``tension_guess``. Continuing from the
    previous pose's tensions along a trajectory, a redundant robot keeps its internal tension.

    Parameters
    ----------
    robot : SpatialChainRobot
        The cables (any lengths: they are paid out to ``lengths`` as the run's winches pay out,
        :func:`cable_paid_out`; over a swivel pulley the winch end moves up the axis and psi is
        solved with the chain), anchors, platform mass.
    pose : array_like, shape (3,) or (6,) [m, rad]
        Centre of mass and (rigid) rotation vector.
    tension_guess : array_like, shape (m,) [N]
        Positive tensions to stay near (eg the previous pose's).
    lengths : array_like, shape (m,) [m]
        Start of the paid-out lengths (eg the catenaries' inverse, or the previous pose's).
    nodes : sequence of array_like, each shape (n + 1, 3) [m]
        Start of each cable's nodes, exit first (moved onto the anchors as :func:`solve_held_chain` does).
    external_wrench : array_like, shape (6,) [N, N m], optional
        Extra load on the platform about its centre of mass (eg the d'Alembert force).
    tolerance : float
        Imbalance accepted, relative to the larger of the weight and the largest cable force.
    swivel_angles : array_like, shape (m,) [rad], optional
        Start of each swivel pulley's psi (NaN or default: the anchor's azimuth about its axis).

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
                                            tolerance=tolerance, max_iterations=max_iterations,
                                            swivel_angles=swivel_angles)


class InverseChainStatics:
    """:func:`solve_inverse_spatial_chain_statics` for many poses of one robot: each cable's model is
    built once (the lengths change by scaling it, or by moving a swivel cable's winch end: :func:`_paid_out_model`).

    Parameters
    ----------
    robot : SpatialChainRobot
    """

    def __init__(self, robot: SpatialChainRobot):
        self.robot = robot
        self.models = [_held_model(c, robot.gravity) for c in robot.cables]

    def solve(self, pose, tension_guess, lengths, nodes, external_wrench=None, *, tolerance: float = 1e-9,
              max_iterations: int = 30, swivel_angles=None) -> SpatialChainInverse:
        """As :func:`solve_inverse_spatial_chain_statics` (same parameters, robot aside)."""
        return _solve_inverse(self.robot, self.models, pose, tension_guess, lengths, nodes, external_wrench,
                              tolerance, max_iterations, swivel_angles)


def _solve_inverse(robot, models, pose, tension_guess, lengths, nodes, external_wrench, tolerance, max_iterations,
                   swivel_angles=None):
    """The Gauss-Newton of :func:`solve_inverse_spatial_chain_statics`, each cable's held model given."""
    from cdpr_exu.core.validation import real_array

    m = len(robot.cables)
    pose = real_array("pose", pose)
    rigid = not robot.is_point_mass
    if pose.shape != (6,) and not (not rigid and pose.shape == (3,)):
        raise SceneError(f"pose must have 6 entries (3 for a point mass), got {shown(pose.tolist())}")
    guess = real_array("tension_guess", tension_guess)
    if guess.shape != (m,) or np.any(guess <= 0.0):
        raise SceneError(f"tension_guess must be one positive tension per cable, got {shown(tension_guess)}")
    lengths = real_array("lengths", lengths)
    if lengths.shape != (m,) or np.any(lengths <= 0.0):
        raise SceneError(f"lengths must be one positive length per cable, got {shown(lengths)}")
    if len(nodes) != m:
        raise SceneError(f"nodes must give one array per cable ({m}), got {len(nodes)}")
    angles = np.full(m, np.nan) if swivel_angles is None else real_array("swivel_angles", swivel_angles, require_finite=False)
    if angles.shape != (m,):
        raise SceneError(f"swivel_angles must give one angle per cable ({m}, NaN: the anchor's azimuth), "
                         f"got {shown(swivel_angles)}")
    wrench = np.zeros(6) if external_wrench is None else vector("external_wrench", external_wrench, 6)
    rotation = rotation_from_vector(pose[3:6]) if rigid else np.eye(3)
    arms = np.array([c.anchor for c in robot.cables]) @ rotation.T
    anchor_points = pose[:3] + arms
    rows = 6 if (rigid and m >= 6) else 3
    weight = robot.mass * robot.gravity
    arm_scale = max(float(np.linalg.norm(arms, axis=1).max()), 1e-3)
    scale = np.array([1.0, 1.0, 1.0, 1.0 / arm_scale, 1.0 / arm_scale, 1.0 / arm_scale])[:rows]

    def held(trial_lengths, trial_nodes, trial_angles):
        chains = [_solve_held(_paid_out_model(model, c, L), cable_paid_out(c, L), a, start, 1e-9, 50, psi)
                  for model, c, L, a, start, psi in zip(models, robot.cables, trial_lengths, anchor_points,
                                                        trial_nodes, trial_angles)]
        forces = np.array([chain.force for chain in chains])
        total = np.concatenate([forces.sum(axis=0) + wrench[:3] - [0.0, 0.0, weight],
                                np.cross(arms, forces).sum(axis=0) + wrench[3:]])[:rows] * scale
        return chains, forces, total

    chains, forces, total = held(lengths, nodes, angles)
    residual = float(np.abs(total).max())
    for iteration in range(max_iterations + 1):
        if residual <= tolerance * max(weight, float(np.abs(forces).max()), 1e-12):
            return SpatialChainInverse(lengths, np.linalg.norm(forces, axis=1), forces,
                                       tuple(chain.nodes for chain in chains), residual, iteration,
                                       np.array([chain.swivel_angle for chain in chains]))
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
                    trial_chains, trial_forces, trial_total = held(trial, [c.nodes for c in chains],
                                                                   [c.swivel_angle for c in chains])
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
