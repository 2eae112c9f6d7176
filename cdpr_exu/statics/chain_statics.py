"""Static equilibrium of the simulator's own lumped cables: chains of nodes, in the plane and in space.

Not the continuous catenary (:mod:`cdpr_exu.statics.statics`): n straight elements whose nodes carry the
mass, exact-angle bending springs at the interior nodes, an exit that holds or pushes the nodes (a
pulley's rim, a swivel pulley's groove). On the paper's robot (0.25 m elements on 0.25 m pulleys) the
coarse polygon on the pulley and its bending move the paid-out length of a pose by millimetres to
centimetres. This module solves that discrete model at rest, without Exudyn and without damping.

A :class:`ChainRobot` of :class:`ChainCable` (:func:`chain_robot`), one :class:`ChainEquilibrium`, and two
drivers: :func:`solve_inverse_chain_statics` (the pose given) and :func:`solve_chain_statics` (the lengths
given, in space; the plane's rest is Exudyn's). The kernels (:mod:`cdpr_exu.statics.chain_kernels`) stay
per dimension; all minimise the potential with :func:`descent_step` and one Armijo line search. Over
swivel pulleys the forward statics start the runs (:func:`cdpr_exu.run.settle.start_at_rest`).

Units SI (m, N, kg, rad); the vertical axis up, gravity along it downwards.
"""

from __future__ import annotations

import copy
import math
from collections import namedtuple
from dataclasses import dataclass, field, replace

import numpy as np
import scipy.sparse as sparse
import scipy.sparse.linalg as sparse_linalg

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.geometry import (all_at_centre, planar_cross, rotation_from_vector, rotation_matrix,
                                    rotation_vector)
from cdpr_exu.core.validation import finite, non_negative, positive, real_array, shown, vector
from cdpr_exu.exits import Exit
from cdpr_exu.physics import swivel_pulley as sp
from cdpr_exu.statics.statics import catenary_platform, chain_element_mass, node_masses_along, solve_statics
from cdpr_exu.space import PLANE, SPACE, space_of
from cdpr_exu.statics.chain_kernels import PlanarChains, SpatialChains, planar_energy, planar_forces
from cdpr_exu.statics.kinematics import initial_cable_nodes, straight_cable_nodes

__all__ = ["ChainCable", "ChainRobot", "ChainEquilibrium", "chain_robot", "solve_chain_statics", "chain_rest",
           "solve_inverse_chain_statics", "InverseChainStatics", "chain_forces", "catenary_start",
           "swivel_chain_start", "winch_line_elements", "cable_paid_out", "robot_paid_out", "HeldChain",
           "solve_held_chain", "descent_step", "rounding_floor"]

_E_Z = np.array([0.0, 0.0, 1.0])


@dataclass(frozen=True)
class ChainCable:
    """One lumped cable as the simulator builds it, for statics.

    Parameters
    ----------
    node_masses : tuple of float, length n + 1 [kg]
        Winch (or exit) node first; its weight is carried by the winch or the frame.
    element_length, axial_stiffness, bending_stiffness : float [m], [N/m], [N m/rad]
        l0 = L / n, k = EA / l0 (> 0), and k_theta = EJ / l0 of each interior joint (0: no bending).
    slack : bool
        Tension-only elements.
    anchor : (x, z) or (x, y, z) [m]
        In the platform frame (centre of mass at 0); its size is the Space's.
    pulley : Exit, SwivelPulley or None
        In the plane the exit (required): node 0 hangs on its winch line by the paid-out length, a
        pulley's rim (penalty ``contact_stiffness`` k_p [N/m], 0: none) pushes the nodes. In space the
        swivel pulley every node may touch (its own k_p), None at a point exit.
    exit_point, winch_elements, winch_travel : (x, y, z) [m], int, float [m]; in space
        Where node 0 is held (required): the exit point, or over a swivel pulley the winch end on its
        axis, ``winch_elements`` below the inlet, moved up the axis by ``winch_travel`` by the winch
        (:class:`cdpr_exu.run.run_3d._SpatialWinches` keeps the elements).
    """

    node_masses: tuple
    element_length: float
    axial_stiffness: float
    bending_stiffness: float
    slack: bool
    anchor: tuple
    pulley: object = None
    contact_stiffness: float = 0.0
    exit_point: tuple | None = None
    winch_elements: int = 0
    winch_travel: float = 0.0

    def __post_init__(self):
        anchor = real_array("anchor", self.anchor)
        if anchor.shape not in ((2,), (3,)):
            raise SceneError(f"anchor must be (x, z) or (x, y, z) [m], got {shown(self.anchor)}")
        object.__setattr__(self, "anchor", tuple(float(a) for a in anchor))
        if len(self.node_masses) < 2:
            raise SceneError(f"node_masses needs at least 2 nodes, got {len(self.node_masses)}")
        for name, check in (("element_length", positive), ("axial_stiffness", positive),
                            ("bending_stiffness", non_negative), ("contact_stiffness", non_negative)):
            check(name, getattr(self, name))
        if np.any(~np.isfinite(self.node_masses)) or min(self.node_masses) < 0:
            raise SceneError(f"node_masses must be finite and non-negative, got {shown(self.node_masses)}")
        finite("winch_travel", self.winch_travel)
        _CABLE_CHECKS[anchor.size](self)

    @property
    def space(self):
        """The cable's :class:`~cdpr_exu.space.Space` (from its anchor)."""
        return space_of(len(self.anchor))

    @property
    def n_elements(self) -> int:
        return len(self.node_masses) - 1

    @property
    def unstrained_length(self) -> float:
        """L = n l0 [m] (over a swivel pulley the winch line's elements included)."""
        return self.n_elements * self.element_length

    def winch_node(self, paid_out: float) -> np.ndarray:
        """In the plane: position of node 0 for a paid-out length lambda [m], shape (2,) [m]."""
        return self.pulley.winch_end(self.unstrained_length, paid_out)

    @property
    def held_point(self) -> np.ndarray:
        """In space: where node 0 is held [m], ``exit_point`` moved up the axis by ``winch_travel``."""
        return np.asarray(self.exit_point, dtype=float) + self.winch_travel * _E_Z

    @property
    def paid_out_length(self) -> float:
        """In space: the winch's paid-out length [m], n l0 at a point exit, over a swivel pulley
        (n - ``winch_elements``) l0 + ``winch_travel``. (In the plane it is the statics' unknown.)"""
        return (self.n_elements - self.winch_elements) * self.element_length + self.winch_travel


def _check_planar_cable(cable: ChainCable) -> None:
    if not isinstance(cable.pulley, Exit):
        raise SceneError(f"pulley must be an exit (cdpr_exu.exits), got {shown(cable.pulley)}")
    if cable.exit_point is not None or cable.winch_elements or cable.winch_travel:
        raise SceneError("exit_point, winch_elements and winch_travel are the spatial chain's: a planar cable "
                         f"hangs from its pulley, got {shown(cable.exit_point)}, {shown(cable.winch_elements)}, "
                         f"{shown(cable.winch_travel)}")


def _check_spatial_cable(cable: ChainCable) -> None:
    if cable.exit_point is None:
        raise SceneError("exit_point (x, y, z) [m] is needed for a spatial cable: where its node 0 is held")
    object.__setattr__(cable, "exit_point", tuple(vector("exit_point", cable.exit_point, 3)))
    if cable.pulley is not None and not isinstance(cable.pulley, sp.SwivelPulley):
        raise SceneError(f"pulley must be a SwivelPulley or None in space, got {shown(cable.pulley)}")
    if not 0 <= int(cable.winch_elements) <= len(cable.node_masses) - 3 or (cable.pulley is None) != (
            cable.winch_elements == 0):
        raise SceneError(f"winch_elements must be 0 for a point exit and leave 2 elements above the inlet "
                         f"over a swivel pulley, got {shown(cable.winch_elements)}")
    if cable.winch_travel != 0.0 and cable.pulley is None:
        raise SceneError(f"winch_travel must be 0 for a point exit, got {shown(cable.winch_travel)}")


#: Each dimension's own checks of a cable, by the size of its anchor.
_CABLE_CHECKS = {2: _check_planar_cable, 3: _check_spatial_cable}


@dataclass(frozen=True)
class ChainRobot:
    """The platform of ``mass`` [kg] and its lumped cables (all of one dimension), ``gravity`` [m/s^2]
    downwards. ``anchor_spring_factor``, in space: None, each cable's last node on its anchor (an exact
    spherical joint); f > 0, tied to it by a spring of stiffness f k (the builder's penalty joint,
    :class:`cdpr_exu.builder.robot_3d.ChainSpec3D`)."""

    cables: tuple
    mass: float
    gravity: float
    anchor_spring_factor: float | None = None

    def __post_init__(self):
        if not self.cables or not all(isinstance(c, ChainCable) for c in self.cables):
            raise SceneError(f"cables must be a non-empty tuple of ChainCable, got {shown(self.cables)}")
        object.__setattr__(self, "cables", tuple(self.cables))
        if len({len(c.anchor) for c in self.cables}) != 1:
            raise SceneError("cables must all be planar or all spatial (their anchors' sizes differ)")
        non_negative("mass", self.mass)
        non_negative("gravity", self.gravity)
        if self.anchor_spring_factor is not None and not finite("anchor_spring_factor", self.anchor_spring_factor) > 0:
            raise SceneError(f"anchor_spring_factor must be positive or None, got {shown(self.anchor_spring_factor)}")

    @property
    def space(self):
        """The robot's :class:`~cdpr_exu.space.Space`."""
        return self.cables[0].space

    @property
    def is_point_mass(self) -> bool:
        """True when every anchor sits at the centre of mass (no rotation to balance)."""
        return all_at_centre([c.anchor for c in self.cables])


def chain_robot(scene, anchor_spring_factor: float | None = None, tension_only: bool | None = None,
                catenary=None) -> ChainRobot:
    """The chain-statics model of a scene, with the effects its builder adds.

    ``anchor_spring_factor``: in space, see :class:`ChainRobot`. ``tension_only``: default the scene's
    ``effects.slack``. ``catenary``: in space, the scene's catenary statics, which hold a swivel cable at
    the winch end its start shape puts it (:func:`swivel_chain_start`); solved here when needed. Raises
    SceneError for a bending model other than the exact angle; in the plane also for massless or
    inextensible cables and contact models other than the node contact.
    """
    effects = scene.effects
    if effects.bending and effects.bending_model != "exact":
        raise SceneError("chain statics models the exact-angle bending only, "
                         f"got effects.bending_model = {shown(effects.bending_model)}")
    slack = bool(effects.slack if tension_only is None else tension_only)
    return _METHODS[scene.space].cables(scene, slack, anchor_spring_factor, catenary)


def _planar_robot(scene, slack, anchor_spring_factor, catenary) -> ChainRobot:
    """:func:`chain_robot` of a planar scene."""
    effects = scene.effects
    if not effects.cable_mass or not effects.axial_elasticity:
        raise SceneError("chain statics needs effects.cable_mass and effects.axial_elasticity "
                         f"(the scene's preset is {shown(effects.preset)}); use the catenary statics instead")
    if scene.contact_model is not None and not scene.contact_model.frozen_nodes:  # the node contact, Exudyn's law
        raise SceneError("chain statics models the node contact on pulleys only, got "
                         f"effects.pulley_contact_model = {shown(effects.pulley_contact_model)}")
    if anchor_spring_factor is not None:
        raise SceneError(f"anchor_spring_factor must be None in the plane (the chains end on their anchors), "
                         f"got {shown(anchor_spring_factor)}")
    gravity = scene.gravity if effects.gravity else 0.0
    cables = []
    for cable, exit_, anchor in zip(scene.cables, scene.exits, scene.platform.anchors):
        masses = cable.node_masses() if gravity > 0 else np.zeros(cable.n_elements + 1)
        contact = exit_.contact_stiffness if scene.pulley_contact else 0.0
        cables.append(ChainCable(
            node_masses=tuple(float(m) for m in masses), element_length=cable.element_length,
            axial_stiffness=cable.axial_stiffness,
            bending_stiffness=cable.bending_stiffness if effects.bending else 0.0,
            slack=slack, pulley=exit_, contact_stiffness=contact, anchor=tuple(anchor)))
    return ChainRobot(tuple(cables), scene.platform.mass, gravity)


def _spatial_robot(scene, slack, anchor_spring_factor, catenary) -> ChainRobot:
    """:func:`chain_robot` of a spatial scene."""
    effects = scene.effects
    platform = catenary_platform(scene)  # what the builder builds from: weights, EA, gravity
    gravity = platform.gravity
    if catenary is None and any(exit_.wraps for exit_ in scene.exits):
        catenary = solve_statics(platform, scene.unstrained_lengths)
    cables = []
    for i, (spec, cable, exit_) in enumerate(zip(scene.cables, platform.cables, scene.exits)):
        n, length = spec.n_elements, spec.unstrained_length
        l0 = length / n
        below, held, pulley = 0, cable.exit_point, None  # held at the exit's point (no catenary needed)
        if exit_.wraps:  # held below it, on its winch line
            below, _, start, pulley = chain_over(exit_, catenary.cables[i], length, n)
            held = start[0]
        # the builder's lumping (:func:`cdpr_exu.builder.robot_3d.build_spatial_robot`), to the last bit
        masses = (node_masses_along(n + below, chain_element_mass(cable, length, n, gravity), spec.mass_lumping)
                  if gravity > 0 else np.zeros(n + below + 1))
        cables.append(ChainCable(
            exit_point=held, node_masses=tuple(float(m) for m in masses), element_length=l0,
            axial_stiffness=cable.axial_stiffness / l0,
            bending_stiffness=spec.youngs_modulus * spec.second_moment / l0 if effects.bending else 0.0,
            slack=slack, anchor=cable.anchor, pulley=pulley, winch_elements=below))
    return ChainRobot(tuple(cables), scene.platform.mass, gravity, anchor_spring_factor)


@dataclass(frozen=True, eq=False)
class ChainEquilibrium:
    """A static equilibrium of the chains and platform; d the Space's dimension, m cables.

    Attributes
    ----------
    position, rotation : ndarray (d,) [m]; float [rad] (plane) or ndarray (3, 3) (space)
        The platform's centre of mass and rotation (0 / identity for a point mass).
    nodes, tensions : tuple of ndarray, shape (n + 1, d) [m], (n,) [N] each
        Each cable's nodes and elements' axial forces, winch (exit) first.
    forces_on_platform : ndarray, shape (m, d) [N]
        Each cable's force at its anchor (the last element's pull, the bending shear, the anchor node's
        weight; a penalty joint's force if any).
    paid_out : ndarray, shape (m,) [m]
        In the plane beyond the hang point; in space :attr:`ChainCable.paid_out_length`.
    residual : float [N]
        Largest force (moment) imbalance left.
    swivel_angles, rotation_vector : ndarray (m,) [rad] or None; ndarray (1,) or (3,) [rad]
        In space each swivel pulley's psi (NaN at a point exit); the rotation's coordinates in the pose.
    """

    position: np.ndarray
    rotation: object
    nodes: tuple
    tensions: tuple
    forces_on_platform: np.ndarray
    paid_out: np.ndarray
    residual: float
    iterations: int = field(default=0)
    swivel_angles: np.ndarray | None = None
    rotation_vector: np.ndarray = None

    @property
    def pose(self) -> np.ndarray:
        """The platform's pose in its Space's coordinates: (x, z, rotation) or (x, y, z, rotation vector) [m, rad]."""
        return np.concatenate([self.position, self.rotation_vector])

    @property
    def anchor_tensions(self) -> np.ndarray:
        """Tension of each cable's last element, at the platform, shape (m,) [N]."""
        return np.array([t[-1] for t in self.tensions])

    @property
    def tensions_at_anchor(self) -> np.ndarray:
        """Norm of each cable's force on the platform, shape (m,) [N]."""
        return np.linalg.norm(self.forces_on_platform, axis=1)


def chain_over(exit_: Exit, equilibrium_cable, length: float, n_elements: int):
    """How a spatial chain of ``n_elements`` from ``exit_`` to its anchor starts, as the builder builds it and
    the chain statics hold it: the elements below the exit, the straight unstrained reference and the
    catenary's nodes (held winch end first, (k + n + 1, 3) [m] each), and the disc it wraps
    (:class:`~cdpr_exu.physics.swivel_pulley.SwivelPulley`; None at a point exit, held at its point)."""
    if exit_.wraps:
        below = winch_line_elements(exit_.winch_line, length / n_elements)
        return (below, *swivel_chain_start(equilibrium_cable, length, n_elements, below, exit_.contact_stiffness),
                exit_.pulley())
    exit_point = equilibrium_cable.exit_point
    towards = equilibrium_cable.anchor_point - exit_point
    direction = towards / max(float(np.linalg.norm(towards)), 1e-300)
    arc_from_exit = np.linspace(0.0, length, n_elements + 1)
    reference = exit_point + np.outer(arc_from_exit, direction)
    current = equilibrium_cable.points(length - arc_from_exit)
    current[0] = exit_point  # the catenary ends there to round-off; the held node must sit exactly on it
    return 0, reference, current, None


def winch_line_elements(winch_line: float, element_length: float) -> int:
    """Elements below a swivel pulley's inlet: its ``winch_line`` [m] in elements of ``element_length`` [m],
    at least 2 (the builder's)."""
    return max(2, int(round(winch_line / element_length)))


def swivel_chain_start(equilibrium_cable, length, n_elements, winch_elements, contact_stiffness):
    """Straight unstrained reference (winch end first) and the catenary statics' nodes of a cable over a
    swivel pulley, shape (k + n + 1, 3) each [m], k = ``winch_elements``, n of unstrained ``length`` [m] from
    the inlet to the anchor.

    From the anchor: the catenary (``equilibrium_cable``, a
    :class:`~cdpr_exu.statics.statics.CableEquilibrium`) to the tangent point; the wrap as the chain lies on
    it, a polygon of stretched chords (chords on the arc are short by r_p theta^3 / 24 and pushed with up to 3
    kN: Newton diverged), each node inside the groove by the depth that carries its pressure, ``T l_e / (r_p
    k_p)`` (on the rim psi has no stiffness: Exudyn's static solver met a singular matrix); then down the axis
    to the held winch end. The tension is the catenary's at the tangent point (frictionless wrap, its weight
    left out).
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


def descent_step(hessian, gradient, relative_shift: float = 1e-8) -> np.ndarray:
    """Newton's step -H^-1 g (H dense or scipy sparse (N, N), g (N,)), H shifted by ``relative_shift`` times
    its largest diagonal entry, then ten times more each time, until the step descends (a node on a rim, a
    slack element, a swivel angle with no stiffness make H indefinite or singular)."""
    is_sparse = sparse.issparse(hessian)
    if is_sparse:
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


def _line_search(move, energy_of, improves, energy: float, slope: float):
    """Armijo's backtracking along a descent step: ``(trial, its energy)``, or None when no step is accepted.

    Tries ``move(alpha)``, alpha = 1, 1/2, ... (40 halvings), takes the first whose ``energy_of(trial)``
    falls by 1e-4 of what ``slope`` (g . step) promises. The penalty contact makes the Hessian jump but the
    energy stays C1, so every step descends (a force residual would not). Near the solution the decrease,
    ~ |g|^2 / k, falls below the energy's rounding (1e-13 |E|): there a step is taken if
    ``improves(trial)`` (the gradient shrinks), else refused (the gradient is as small as it gets).
    """
    roundoff = 1e-13 * (1.0 + abs(energy))
    alpha = 1.0
    for _ in range(40):
        trial = move(alpha)
        trial_energy = energy_of(trial)
        if trial_energy <= energy + 1e-4 * alpha * slope:
            return trial, trial_energy
        if abs(trial_energy - energy) <= roundoff:
            return (trial, trial_energy) if improves(trial) else None
        alpha *= 0.5
    return None


def rounding_floor(stiffness, points) -> float:
    """The force [N] below which a chain's node forces are rounding: an element's k (l - l0), its length from
    coordinates of size |p|, carries k |p| eps; 16 times that for the sums (``stiffness`` k [N/m], ``points``
    [m])."""
    return 16.0 * np.finfo(float).eps * float(np.max(stiffness)) * float(np.abs(points).max())


# --- the plane: nodes and paid-out lengths at a pose
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
        return planar_energy(self.robot, self.layout, p) - self.wrench[2] * rotation

    def _gradient(self, S, F):
        """dPi/dv from dX/dv (2N, n_inner) and the nodal forces (N, 2)."""
        gradient = -(S.T @ F.ravel())
        if self.layout.free_rotation:
            gradient[-1] -= self.wrench[2]
        return gradient

    def gradient(self, v):
        """dPi/dv without the Hessian."""
        p, _ = _positions(self.robot, self.layout, self.position, self.rotation, v, self.paid_out)
        F, _, _, _ = planar_forces(self.robot, self.layout, p, with_stiffness=False)
        S, _ = _selection(self.robot, self.layout, p, self.position)
        return self._gradient(S, F)

    def evaluate(self, v):
        """Energy, gradient, Hessian and the state they came from."""
        layout = self.layout
        p, rotation = _positions(self.robot, layout, self.position, self.rotation, v, self.paid_out)
        F, K, tension, energy = planar_forces(self.robot, layout, p)
        S, S_lambda = _selection(self.robot, layout, p, self.position)
        gradient = self._gradient(S, F)
        hessian = S.T @ K @ S
        if layout.free_rotation:
            arms = p[layout.anchor] - self.position
            hessian[-1, -1] += float(np.sum(arms * F[layout.anchor]))  # the arms turn with the platform
        return {"energy": energy - self.wrench[2] * rotation, "gradient": gradient, "hessian": hessian,
                "p": p, "rotation": rotation, "F": F, "K": K, "S": S, "S_lambda": S_lambda, "tension": tension}


def _minimise(inner: _Inner, v, tolerance, max_iterations):
    """Newton's method on the potential with the line search (:func:`_line_search`); returns (v, state, iterations).

    An indefinite Hessian is shifted towards the identity until the step descends (:func:`descent_step`).
    """
    state = inner.evaluate(v)
    for iteration in range(max_iterations):
        if np.max(np.abs(state["gradient"])) < tolerance:
            return v, state, iteration
        g, H = state["gradient"], state["hessian"]
        step = descent_step(H, g, relative_shift=1e-6)
        found = _line_search(lambda alpha: v + alpha * step, inner.energy,
                             lambda trial: np.linalg.norm(inner.gradient(trial)) < np.linalg.norm(g),
                             state["energy"], float(np.dot(step, g)))
        if found is None:
            break
        v = found[0]
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
    """Force imbalance of a planar configuration: ``robot``'s ``nodes`` (each (n + 1, 2) [m], winch first,
    the anchors where the pose puts them), the platform at ``position`` (x, z) [m] and ``rotation`` [rad]
    under ``external_wrench`` (fx, fz, moment) [N, N m].

    Returns the net force on each interior node, (n_interior, 2) [N] (all cables, in order), and the net
    force and moment on the platform about its centre of mass, (3,) [N, N m]."""
    layout = PlanarChains(robot, free_rotation=False)
    p = np.concatenate([np.asarray(n, dtype=float) for n in nodes])
    if p.shape != (layout.n_nodes, 2):
        raise SceneError(f"nodes must hold {layout.counts} nodes per cable, got shape {p.shape}")
    wrench = np.zeros(3) if external_wrench is None else vector("external_wrench", external_wrench, 3)
    position = vector("position", position, 2)
    F, _, _, _ = planar_forces(robot, layout, p, with_stiffness=False)
    arms = p[layout.anchor] - position
    force = _platform_force(robot, layout, F, wrench)
    moment = planar_cross(arms, F[layout.anchor]).sum() + wrench[2]
    return F[layout.interior], np.array([*force, moment])


def _straight_guess(robot, position, rotation, tensions):
    """Start of the iteration: straight chains stretched by ``tensions`` (m,) [N], laid from the anchor back
    over the pulley with elements of l0 (1 + T / k l0)
    (:func:`~cdpr_exu.statics.kinematics.initial_cable_nodes`); the paid-out length follows from where node 0
    lands. Returns the interior coordinates (flat) and the paid-out lengths."""
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
    """Tangent predictor from the solution ``guess`` to ``position``: the linearised equilibrium (nodes and
    platform force) moves the nodes, rotation and paid-out lengths (else a centimetre's anchor move stretches
    its element by kN, for the iteration to walk back). The guess itself if the system is singular."""
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


def _planar_inverse(robot: ChainRobot, position, rotation=0.0, *, free_rotation=None, external_wrench=None,
                    guess: ChainEquilibrium | None = None, tension_guess=None, tolerance: float = 1e-7,
                    max_iterations: int = 50) -> ChainEquilibrium:
    """:func:`solve_inverse_chain_statics` in the plane. Tension-only elements have no stiffness in
    compression, so Newton from compressed elements can stall: the equilibrium is first sought with springs
    that also push; where none of its elements is compressed it is the tension-only one as well, else it
    starts it."""
    kwargs = dict(free_rotation=free_rotation, external_wrench=external_wrench, tolerance=tolerance,
                  max_iterations=max_iterations)
    if not any(c.slack for c in robot.cables):
        return _planar_solve(robot, position, rotation, guess=guess, tension_guess=tension_guess, **kwargs)
    springs = ChainRobot(tuple(replace(c, slack=False) for c in robot.cables), robot.mass, robot.gravity)
    try:
        spring = _planar_solve(springs, position, rotation, guess=guess, tension_guess=tension_guess, **kwargs)
    except UnreachableError:
        return _planar_solve(robot, position, rotation, guess=guess, tension_guess=tension_guess, **kwargs)
    if all(np.all(t >= 0.0) for t in spring.tensions):
        return spring
    return _planar_solve(robot, position, rotation, guess=spring, **kwargs)


def _planar_solve(robot: ChainRobot, position, rotation=0.0, *, free_rotation=None, external_wrench=None,
                  guess: ChainEquilibrium | None = None, tension_guess=None, tolerance: float = 1e-7,
                  max_iterations: int = 50) -> ChainEquilibrium:
    """:func:`_planar_inverse` for the robot's own element law. Inner: the platform held at ``position`` and
    the paid-out lengths given, the nodes (and a free rotation) minimise the potential (:func:`_minimise`).
    Outer: Newton on the paid-out lengths until the held platform needs no force, its derivative from the
    inner tangent stiffness."""
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
    layout = PlanarChains(robot, bool(free_rotation))
    if guess is not None:
        rotation = float(guess.rotation) if free_rotation else rotation
        interior = np.concatenate([n[1:-1].ravel() for n in guess.nodes])
        paid_out = np.array(guess.paid_out, dtype=float)
        if interior.size != layout.n_interior or paid_out.shape != (m,):
            raise SceneError("guess does not belong to this robot (node or cable counts differ)")
        interior, rotation, paid_out = _predict(robot, layout, guess, interior, rotation, paid_out, position, wrench)
    else:
        if tension_guess is None:
            raise SceneError("the planar inverse chain statics need a guess or tension_guess")
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
    return ChainEquilibrium(position=position, rotation=rotation, nodes=nodes, tensions=tensions,
                            forces_on_platform=state["F"][layout.anchor].copy(), paid_out=paid_out,
                            residual=float(residual), iterations=outer + inner_iterations,
                            rotation_vector=np.array([rotation]))


# --- space: the potential of the 3-D chains (bending, tension-only law, swivel groove), pose and swivels free
def catenary_start(robot: ChainRobot, equilibrium):
    """The nodes on the catenary statics' cables (``equilibrium``, a
    :class:`~cdpr_exu.statics.statics.PlatformEquilibrium` of the same cables), as the builder starts its
    chains: each cable's nodes (n + 1, 3) [m] (over a swivel pulley :func:`swivel_chain_start`), the
    position (3,) [m], the rotation (3, 3), and each swivel pulley's angle at its anchor's azimuth (m,) [rad]
    (NaN at a point exit)."""
    if len(equilibrium.cables) != len(robot.cables):
        raise SceneError(f"equilibrium has {len(equilibrium.cables)} cables, the robot {len(robot.cables)}")
    nodes, angles = [], np.full(len(robot.cables), np.nan)
    for i, (cable, state) in enumerate(zip(robot.cables, equilibrium.cables)):
        length = cable.unstrained_length
        if cable.pulley is not None:
            n = cable.n_elements - cable.winch_elements
            points = swivel_chain_start(state, n * cable.element_length, n, cable.winch_elements,
                                        cable.pulley.contact_stiffness)[1]
            angles[i] = sp.exit_azimuth(state.anchor_point, state.inlet)  # where the builder starts psi
        else:
            points = state.points(length - np.linspace(0.0, length, cable.n_elements + 1))
            points[0] = cable.exit_point
        points[-1] = state.anchor_point
        nodes.append(points)
    return nodes, np.asarray(equilibrium.position, float), np.asarray(equilibrium.rotation_matrix, float), angles


def _spatial_forward(robot: ChainRobot, nodes, position, rotation=None, swivel_angles=None, *,
                     tolerance: float = 1e-9, max_iterations: int = 100, external_force=None) -> ChainEquilibrium:
    """:func:`solve_chain_statics` in space: Newton's method on the total potential from a start."""
    model = SpatialChains(robot)
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
        psi = np.array([sp.exit_azimuth(np.asarray(nodes[i], float)[-1], robot.cables[i].pulley.inlet_array)
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
        found = _line_search(lambda alpha: model.step(*state, alpha * step), lambda trial: model.energy(*trial),
                             lambda trial: np.max(np.abs(model.derivatives(*trial)[0])) < np.max(np.abs(gradient)),
                             energy, float(step @ gradient))
        if found is None:
            # stalled at rounding, close enough: a coordinate's last bit (eps |p|) on the stiffest spring
            # (a penalty joint, f k ~ 1e8 N/m) is a force of 1e-8 N, above the default tolerance
            rounding = rounding_floor(np.abs(hessian.diagonal()), max(1.0, float(np.abs(p).max())))
            if np.max(np.abs(gradient)) < max(10.0 * tolerance, rounding):
                break
            raise UnreachableError(f"spatial chain statics: the line search failed (force imbalance "
                                   f"{np.max(np.abs(gradient)):.3g} N after {iteration} iterations)")
        state, energy = found
    else:
        raise UnreachableError(f"spatial chain statics did not converge in {max_iterations} iterations "
                               f"(force imbalance {np.max(np.abs(gradient)):.3g} N)")
    _, x, R, psi = state
    chain_nodes = tuple(p[f:f + n].copy() for f, n in zip(model.first, model.counts))
    tensions = tuple(force[model.element_cable == i] for i in range(len(robot.cables)))
    forces = _forces_on_platform(model, p, G)
    angles = np.full(len(robot.cables), np.nan)
    angles[model.swivel_cables] = psi
    return ChainEquilibrium(position=x.copy(), rotation=R.copy(), nodes=chain_nodes, tensions=tensions,
                            forces_on_platform=forces, paid_out=np.array([c.paid_out_length for c in robot.cables]),
                            residual=float(np.max(np.abs(gradient))), iterations=iteration, swivel_angles=angles,
                            rotation_vector=rotation_vector(R) if model.rigid else np.zeros(3))


def _forces_on_platform(model: SpatialChains, p, G):
    """Force each cable exerts on its anchor, shape (m, 3) [N], from the point gradient ``G``."""
    forces = np.zeros((len(model.robot.cables), 3))
    for (j, i) in model.body:
        if model.penalty:
            forces[i] = model.penalty_k[i] * (p[model.last[i]] - p[j])
        else:
            # the chain's pull on the anchor node, its weight included: -dU_chain/dp
            forces[i] = -G[3 * j:3 * j + 3]
    return forces


def _spatial_rest(scene, anchor_spring_factor: float | None = None, tension_only: bool | None = None,
                  **kwargs) -> ChainEquilibrium:
    """:func:`chain_rest` in space: started on the catenary statics, as the builder starts Exudyn's."""
    catenary = solve_statics(catenary_platform(scene), scene.unstrained_lengths)
    robot = chain_robot(scene, anchor_spring_factor, tension_only, catenary)
    return _spatial_forward(robot, *catenary_start(robot, catenary), **kwargs)


# --- the inverse: lengths whose chains hold a pose
def cable_paid_out(cable: ChainCable, length: float) -> ChainCable:
    """``cable`` paid out to the unstrained ``length`` [m], as the run's variable-length winch changes it
    (:class:`cdpr_exu.run.run_3d._SpatialWinches`): at a point exit the same n elements of length
    L / n, their stiffness E A n / L, the node masses rho L / n and the bending stiffness E J n / L; over a
    swivel pulley the same elements, the held winch end moved up the axis by the change of the paid-out
    length (``winch_travel``, :attr:`ChainCable.paid_out_length`), the cable running over the disc."""
    length = positive("length", length, "m")
    if cable.pulley is not None:
        return replace(cable, winch_travel=cable.winch_travel + length - cable.paid_out_length)
    scale = length / cable.unstrained_length
    return replace(cable, element_length=cable.element_length * scale, axial_stiffness=cable.axial_stiffness / scale,
                   node_masses=tuple(m * scale for m in cable.node_masses),
                   bending_stiffness=cable.bending_stiffness / scale)


def robot_paid_out(robot: ChainRobot, lengths) -> ChainRobot:
    """``robot`` with each cable paid out to ``lengths`` (m,) [m] (:func:`cable_paid_out`)."""
    lengths = np.asarray(lengths, dtype=float).reshape(-1)
    if lengths.size != len(robot.cables):
        raise SceneError(f"lengths must give one length per cable ({len(robot.cables)}), got {lengths.size}")
    return replace(robot, cables=tuple(cable_paid_out(c, L) for c, L in zip(robot.cables, lengths)))


@dataclass(frozen=True, eq=False)
class HeldChain:
    """One lumped cable at rest between its exit point (over a swivel pulley its held winch end) and a fixed
    anchor point: ``nodes`` (n + 1, 3) [m] and ``tensions`` (n,) [N] exit first, its ``force`` on the anchor
    (3,) [N], ``force_rate`` (3,) [N/m] its derivative in the paid-out length with the anchor held and the
    chain re-settled (implicit function theorem; paid out as :func:`cable_paid_out`), and ``swivel_angle``
    psi [rad] (NaN at a point exit)."""

    nodes: np.ndarray
    tensions: np.ndarray
    force: np.ndarray
    force_rate: np.ndarray
    swivel_angle: float = float("nan")


def _held_model(cable: ChainCable, gravity: float) -> SpatialChains:
    """The model of one cable whose anchor is a fixed point: a one-cable robot of no mass with the anchor at
    its centre, whose position unknowns are kept fixed."""
    return SpatialChains(ChainRobot((replace(cable, anchor=(0.0, 0.0, 0.0)),), 0.0, gravity))


#: Halvings of a held chain's jump the continuation may make (:func:`solve_held_chain`): at most 32 sub-steps.
CONTINUATION_HALVINGS = 5


def solve_held_chain(cable: ChainCable, gravity: float, anchor_point, nodes, *, tolerance: float = 1e-9,
                     max_iterations: int = 50, swivel_angle: float | None = None, model=None) -> HeldChain:
    """The rest shape of one lumped cable (paid out as wanted, :func:`cable_paid_out`; its ``anchor`` unused)
    held at its exit point (or winch end) and at ``anchor_point`` (x, y, z) [m].

    Newton's method on its free nodes and, over a swivel pulley, psi (start ``swivel_angle``, default the
    anchor's azimuth), from ``nodes`` (n + 1, 3) [m] with its ends put on the held points; then the force
    on the anchor and its rate. ``tolerance`` [N]: the largest force left on a free node; below the rounding
    floor (:func:`rounding_floor`) Newton also stops once a step no longer halves it. ``model``: the held
    model, built once by a caller that changes the length (:func:`_paid_out_model`); default built here.

    Only if Newton fails, continuation: the anchor (and a swivel cable's winch end) moved from the start's
    in sub-steps, each from the last one's chain, a failing one halved, at most
    :data:`CONTINUATION_HALVINGS` times. On spatial-four-cable-swivel, from the rest's chains, Newton alone
    stopped at 2 cm up or 5 cm across; the sub-steps converge 30 cm across and 20 cm up (to 1e-10 relative
    of Newton given 2000 iterations). Raises :class:`UnreachableError` if neither finds a rest shape.
    """
    model = _held_model(cable, gravity) if model is None else model
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
    travel = float(np.dot(nodes[0] - held_point, _E_Z)) if cable.pulley is not None else 0.0

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


def _newton_held(model: SpatialChains, cable: ChainCable, anchor_point, nodes, tolerance: float,
                 max_iterations: int, swivel_angle: float | None = None) -> HeldChain:
    """Newton for :func:`solve_held_chain` from ``nodes`` (n + 1, 3) [m] (checked), its ends first moved onto
    the held and anchor points (over a swivel pulley by :func:`_swivel_start`)."""
    nodes = np.array(nodes, dtype=float)
    n = cable.n_elements
    share = np.linspace(0.0, 1.0, n + 1)[:, None]
    held_point = model.fixed_positions[0]
    if cable.pulley is None:
        nodes += (1.0 - share) * (held_point - nodes[0]) + share * (anchor_point - nodes[-1])
    else:
        nodes = _swivel_start(nodes, cable.pulley, held_point, anchor_point)
    if cable.pulley is None:
        psi = np.zeros(0)
    elif swivel_angle is None or not np.isfinite(swivel_angle):
        psi = np.array([sp.exit_azimuth(anchor_point, cable.pulley.inlet_array)])
    else:
        psi = np.array([float(swivel_angle)])
    R = np.eye(3)
    # the unknowns among the point coordinates (exit, free nodes, anchor, then psi): the free nodes and psi
    inner = np.concatenate([np.arange(3, 3 * n), np.arange(3 * (n + 1), model.size)])
    end = slice(3 * n, 3 * n + 3)
    n_free = 3 * (n - 1)
    free = nodes[1:-1].ravel().copy()
    energy = model.energy(free, anchor_point, R, psi)
    # Below the rounding floor Newton keeps gaining while it can (chains stopped at the floor stalled
    # CoGiRo's Gauss-Newton for 30 iterations at 1e-5 N): stop there once a step no longer halves it.
    floor = rounding_floor(model.k, nodes)
    last = np.inf
    # a point exit's chain is solved dense (57 unknowns at 20 elements); over a swivel pulley sparse (SuperLU:
    # 163 unknowns at 48 + 6 elements, whose dense solve took 0.14 s with OpenBLAS's threads on a busy machine)
    dense = cable.pulley is None
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

        def improves(trial):
            moved = nodes.copy()
            moved[1:-1] = trial[0].reshape(-1, 3)
            return np.max(np.abs(model.point_derivatives(moved, trial[1])[0][inner])) < np.max(np.abs(g))
        found = _line_search(lambda alpha: (free + alpha * step[:n_free], psi + alpha * step[n_free:]),
                             lambda trial: model.energy(trial[0], anchor_point, R, trial[1]), improves, energy,
                             float(step @ g))
        if found is None:
            if imbalance < max(10.0 * tolerance, floor):
                break
            raise UnreachableError(f"held chain statics: the line search failed (force imbalance "
                                   f"{np.max(np.abs(g)):.3g} N after {iteration} iterations)")
        (free, psi), energy = found
    else:
        raise UnreachableError(f"held chain statics did not converge in {max_iterations} iterations "
                               f"(force imbalance {np.max(np.abs(g)):.3g} N)")
    if cable.pulley is None:
        # d(gradient)/dL at fixed nodes: central differences of the chain paid out by +-dL (cable_paid_out)
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
        settle = -sparse_linalg.splu(H_inner.tocsc()).solve(rate[inner])
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


def _paid_out_model(model: SpatialChains, cable: ChainCable, length: float) -> SpatialChains:
    """A copy of the held ``model`` of ``cable`` (the model's own cable) paid out to ``length`` [m], as
    :func:`cable_paid_out`: at a point exit scaled (:func:`_scaled_model`), over a swivel pulley its held
    winch end moved up the axis."""
    if cable.pulley is None:
        return _scaled_model(model, length / cable.unstrained_length)
    moved = copy.copy(model)
    moved.fixed_positions = {0: cable_paid_out(cable, length).held_point}
    return moved


def _scaled_model(model: SpatialChains, scale: float) -> SpatialChains:
    """A copy of a one-cable ``model`` with its cable paid out ``scale`` times as long, as :func:`cable_paid_out`
    at a point exit: element lengths and weights times ``scale``, axial and bending stiffness over it."""
    scaled = copy.copy(model)
    scaled.l0, scaled.k = model.l0 * scale, model.k / scale
    scaled.weights, scaled.joint_k = model.weights * scale, model.joint_k / scale
    return scaled


def _solve_inverse(robot, models, pose, tension_guess, lengths, nodes, external_wrench, tolerance, max_iterations,
                   swivel_angles=None):
    """The Gauss-Newton of :func:`solve_inverse_chain_statics` in space, each cable's held model given."""

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
        chains = [solve_held_chain(cable_paid_out(c, L), robot.gravity, a, start, swivel_angle=psi,
                                   model=_paid_out_model(model, c, L))
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
            return ChainEquilibrium(position=pose[:3].copy(), rotation=rotation,
                                    nodes=tuple(chain.nodes for chain in chains),
                                    tensions=tuple(chain.tensions for chain in chains), forces_on_platform=forces,
                                    paid_out=lengths, residual=residual, iterations=iteration,
                                    swivel_angles=np.array([chain.swivel_angle for chain in chains]),
                                    rotation_vector=pose[3:6].copy() if rigid else np.zeros(3))
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


# --- the drivers: one interface, the kernel chosen by the robot's Space
def solve_chain_statics(robot: ChainRobot, nodes, position, rotation=None, swivel_angles=None,
                        **kwargs) -> ChainEquilibrium:
    """The rest of the chains and platform on the cables' unstrained lengths (the forward chain statics).

    In space, Newton's method on the total potential (unknowns: the free nodes, the platform's pose, the
    swivel angles). The plane has none: its rest is Exudyn's (:func:`cdpr_exu.run.rest.solve_rest`).

    Parameters
    ----------
    robot : ChainRobot
    nodes : sequence of array_like, each shape (n + 1, 3) [m]
        Start of each cable's nodes, exit first (eg :func:`catenary_start`).
    position, rotation, swivel_angles : (3,) [m], (3, 3) optional, (m,) [rad] optional
        Start of the platform's pose (rotation default identity, ignored for a point mass) and of each
        swivel pulley's psi (default turned towards its cable's last start node).
    tolerance : float [N]
        Largest gradient entry accepted (moments [N m]); at least the rounding floor
        (:func:`rounding_floor`: 1.6e-7 N on CoGiRo's steel ropes, where 1e-9 N is out of reach).
    external_force : (fx, fy, fz) [N], optional
        Constant extra force on the centre of mass (eg the d'Alembert force -M a).

    Raises UnreachableError if Newton finds no equilibrium, SceneError on malformed input or a planar robot.
    """
    return _METHODS[robot.space].forward(robot, nodes, position, rotation, swivel_angles, **kwargs)


def chain_rest(scene, anchor_spring_factor: float | None = None, tension_only: bool | None = None,
               **kwargs) -> ChainEquilibrium:
    """The lumped robot of a scene at rest on its unstrained lengths: :func:`solve_chain_statics` (``kwargs``)
    from :func:`chain_robot`, started on the catenary statics as the builder starts Exudyn's. UnreachableError
    if either finds no equilibrium; SceneError for a planar scene."""
    return _METHODS[scene.space].rest(scene, anchor_spring_factor, tension_only, **kwargs)


def _no_planar_forward(*args, **kwargs):
    raise SceneError("the planar chain statics hold the platform at a pose (solve_inverse_chain_statics); a planar "
                     "robot's rest on given lengths is Exudyn's (cdpr_exu.run.rest.solve_rest)")


class InverseChainStatics:
    """The inverse chain statics of one robot for many poses (:func:`solve_inverse_chain_statics`); in space
    each cable's held model is built once (:func:`_paid_out_model` changes its length)."""

    def __init__(self, robot: ChainRobot):
        if not isinstance(robot, ChainRobot):
            raise SceneError(f"robot must be a ChainRobot, got {shown(robot)}")
        self.robot = robot
        self._solve = _METHODS[robot.space].inverse(robot)

    def solve(self, pose, tension_guess=None, **kwargs) -> ChainEquilibrium:
        """As :func:`solve_inverse_chain_statics` (same parameters, robot aside)."""
        return self._solve(pose, tension_guess, **kwargs)


def solve_inverse_chain_statics(robot: ChainRobot, pose, tension_guess=None, **kwargs) -> ChainEquilibrium:
    """Paid-out lengths, nodes and tensions of the chains that hold ``robot``'s platform at ``pose``.

    Plane (:func:`_planar_inverse`): the nodes minimise the potential at fixed paid-out lengths, the lengths
    cancel the force the held platform needs; a rigid platform on two cables chooses its rotation, on three
    it is imposed. Space (:func:`_solve_inverse`): Gauss-Newton on the lengths over chains held at their
    anchors, tied only by the platform's balance (six equations; three for a point mass or fewer than six
    cables, whose rotation is left free); of the changes that cancel the imbalance to first order, the one
    whose tensions come nearest ``tension_guess``: continued along a trajectory, a redundant robot keeps
    its internal tension.

    Parameters
    ----------
    robot : ChainRobot
        In space its lengths are paid out to ``lengths`` (:func:`cable_paid_out`).
    pose : array_like [m, rad]
        Plane: (x, z) or (x, z, rotation) (imposed, or the start if free). Space: (x, y, z) for a point
        mass or (x, y, z, rotation vector).
    tension_guess : array_like, shape (m,) [N], optional
        Plane: tensions (>= 0) of the straight start chains, without ``guess``. Space: positive tensions
        to stay near (default the ``guess``'s).
    guess : ChainEquilibrium, optional
        A nearby solution, the start (in space its lengths, nodes and angles, unless given).
    lengths, nodes, swivel_angles : optional, in space
        Start of the paid-out lengths (m,) [m], each cable's nodes (n + 1, 3) [m] and each psi (m,) [rad]
        (NaN: the anchor's azimuth).
    free_rotation : bool, optional, in the plane
        Let equilibrium choose the rotation (default: a rigid platform on two cables).
    external_wrench : array_like, optional [N, N m]
        Extra load about the centre of mass: (fx, fz, moment) in the plane, (f, moment) in space.
    tolerance, max_iterations : float, int, optional
        Plane: the force imbalance accepted [N] (1e-7), each Newton's iterations (50). Space: the
        imbalance relative to the larger of the weight and the largest cable force (1e-9), Gauss-Newton
        iterations (30).

    Raises UnreachableError if no lengths with the cables in tension hold the platform there or the
    iteration fails; SceneError on malformed input or (plane) a problem that is not square.
    """
    return InverseChainStatics(robot).solve(pose, tension_guess, **kwargs)


def _planar_inverse_solver(robot: ChainRobot):
    """The plane's :meth:`InverseChainStatics.solve` for ``robot``."""
    def solve(pose, tension_guess, *, guess=None, lengths=None, nodes=None, swivel_angles=None,
              free_rotation=None, external_wrench=None, tolerance=1e-7, max_iterations=50):
        if lengths is not None or nodes is not None or swivel_angles is not None:
            raise SceneError("lengths, nodes and swivel_angles start the spatial inverse chain statics; the planar "
                             "one starts from guess or tension_guess")
        pose = real_array("pose", pose, require_finite=False)
        if pose.shape not in ((2,), (3,)):
            raise SceneError(f"pose must be (x, z) or (x, z, rotation), got {shown(pose.tolist())}")
        return _planar_inverse(robot, pose[:2], pose[2] if pose.size == 3 else 0.0, free_rotation=free_rotation,
                               external_wrench=external_wrench, guess=guess, tension_guess=tension_guess,
                               tolerance=tolerance, max_iterations=max_iterations)
    return solve


def _spatial_inverse_solver(robot: ChainRobot):
    """Space's :meth:`InverseChainStatics.solve` for ``robot``: each cable's held model built once."""
    models = [_held_model(c, robot.gravity) for c in robot.cables]

    def solve(pose, tension_guess, *, guess=None, lengths=None, nodes=None, swivel_angles=None,
              free_rotation=None, external_wrench=None, tolerance=1e-9, max_iterations=30):
        if free_rotation is not None:
            raise SceneError("free_rotation is the planar inverse's: in space a rigid platform on fewer than six "
                             f"cables keeps its rotation free, got {shown(free_rotation)}")
        if guess is not None:
            lengths = guess.paid_out if lengths is None else lengths
            nodes = guess.nodes if nodes is None else nodes
            swivel_angles = guess.swivel_angles if swivel_angles is None else swivel_angles
            tension_guess = guess.tensions_at_anchor if tension_guess is None else tension_guess
        if tension_guess is None or lengths is None or nodes is None:
            raise SceneError("the spatial inverse chain statics need tension_guess, lengths and nodes to start "
                             "from, or a guess")
        return _solve_inverse(robot, models, pose, tension_guess, lengths, nodes, external_wrench, tolerance,
                              max_iterations, swivel_angles)
    return solve


#: One dimension's chain statics: its cables from a scene, forward solve, rest and inverse solver.
_Methods = namedtuple("_Methods", "cables forward rest inverse")

#: Each dimension's chain statics, by the robot's (the scene's) Space: the one place they are chosen.
_METHODS = {PLANE: _Methods(_planar_robot, _no_planar_forward, _no_planar_forward, _planar_inverse_solver),
            SPACE: _Methods(_spatial_robot, _spatial_forward, _spatial_rest, _spatial_inverse_solver)}
