"""The spatial robot's item family in Exudyn (the 3-D :class:`Model` of a scene, :func:`build_model_3d`).

Each cable is a chain of :mod:`cdpr_exu.builder.chain_3d`, its first node held at the cable's
exit point (or at its winch end on a swivel pulley's axis). Its last node is joined to the
platform's anchor by an ``ObjectJointSpherical`` (no moment, like a cable end on a swivel eye),
or, with ``ChainSpec3D.anchor_spring_factor``, by a stiff ``ObjectConnectorCartesianSpringDamper``
(a penalty spherical joint).

Why the penalty joint exists (measured): Exudyn's static solver does not converge when an
``ObjectJointSpherical`` holds a rigid body's ``MarkerBodyPosition`` and the body must turn
(from 3e-4 rad off the answer the first Newton step turned the platform by 1e-2 rad and
diverged, with analytic or numerical Jacobians, for every rotation parametrisation), as if the
joint's geometric stiffness were missing from the static Jacobian. The dynamic solver runs
with the exact joint; a point-mass platform solves statically with it.

The platform is a point mass (every anchor at the centre: ``NodePoint`` + ``ObjectMassPoint``)
or a rigid body with Euler parameters (``mbs.CreateRigidBody``): free of singularities and
fit for both the generalised-alpha integrator and ``SolveStatic``
(``NodeRigidBodyRotVecLG`` is meant for Exudyn's explicit Lie-group integrators; Tait-Bryan
angles are singular at a pitch of 90 degrees).

A cable over a swivel pulley (:class:`cdpr_exu.exits.swivel.Swivel`) is a fixed-length chain
from its winch end on the pulley's vertical axis, over the disc
(:func:`cdpr_exu.builder.swivel_chain.add_swivel_pulley`) to the anchor; the winch moves the
held end along the axis (``SpatialChainItems.holds``) so that cable flows over the pulley. It
starts on the catenary statics' shape, and :func:`cdpr_exu.run.settle.start_at_rest` brings it
to rest by the chain statics (Exudyn's static solver does not converge from there).

Units SI, z up, gravity along -z. The chains start on the catenary statics' solution (or any
:class:`PlatformEquilibrium`): their reference configuration is straight and unstrained
(element length ``L / n``), their initial displacements put the nodes on the catenary.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np
from exudyn.rigidBodyUtilities import RigidBodyInertia

from cdpr_exu.core.errors import SceneError
from cdpr_exu.core.validation import non_negative, positive, shown
from cdpr_exu.exits import PointExit

from cdpr_exu.physics import axial_3d
from cdpr_exu.builder.chain_3d import ChainForces, add_spatial_chain, chain_energy
from cdpr_exu.builder.winch import add_servo_drum
from cdpr_exu.builder.swivel_chain import add_swivel_pulley, swivel_energy  # the disc and its angle psi
from cdpr_exu.statics.statics import (PlatformEquilibrium, SuspendedPlatform, catenary_platform, chain_element_mass,
                                      checked_unstrained_lengths, node_masses_along, solve_statics)
from cdpr_exu.statics.chain_statics import chain_over


@dataclass(frozen=True)
class ChainSpec3D:
    """How the cables are discretised, damped and bent.

    Parameters
    ----------
    n_elements : int
        Elements per cable (at least 2), each of unstrained length ``L / n``.
    axial_damping_constant : float [N s]
        ``d_n A``: element damping ``c = d_n A / l_e`` (Kelvin-Voigt); 0 for none.
    flexural_rigidity : float [N m^2]
        ``E J``: joint bending stiffness ``k_theta = E J / l_e``; 0 for no bending
        (the catenary's cable).
    bending_damping_constant : float [N m^2 s]
        ``d_n J``: joint bending damping ``c_theta = d_n J / l_e`` (the planar model's), on
        the segments' relative angular velocity (:mod:`cdpr_exu.physics.bending_3d`); 0 for
        none. Needs ``flexural_rigidity > 0``.
    anchor_spring_factor : float or None
        None: the cable ends are held at the anchors by ``ObjectJointSpherical`` (exact). A
        number ``f > 0``: by a penalty spring of stiffness ``f EA / l_e`` in x, y, z, which adds
        ``1 / (f n)`` of the cable's compliance; needed for Exudyn's static solver on a rigid
        platform (see the module notes).
    tension_only : bool
        Tension-only axial elements (:mod:`cdpr_exu.physics.axial_3d`) instead of Exudyn's
        ``ObjectConnectorSpringDamper``.
    mass_lumping : {"consistent", "paper"}
        As the planar cable's (:class:`cdpr_exu.scenes.scene.CableSpec`).
    """

    n_elements: int = 20
    axial_damping_constant: float = 0.0
    flexural_rigidity: float = 0.0
    bending_damping_constant: float = 0.0
    anchor_spring_factor: float | None = None
    tension_only: bool = False
    mass_lumping: str = "consistent"

    def __post_init__(self):
        if self.mass_lumping not in ("consistent", "paper"):
            raise SceneError(f"mass_lumping must be 'consistent' or 'paper', got {shown(self.mass_lumping)}")
        if not isinstance(self.tension_only, (bool, np.bool_)):
            raise SceneError(f"tension_only must be True or False, got {shown(self.tension_only)}")
        object.__setattr__(self, "tension_only", bool(self.tension_only))
        if isinstance(self.n_elements, bool) or not isinstance(self.n_elements, (int, np.integer)):
            raise SceneError(f"n_elements must be a whole number, got {shown(self.n_elements)}")
        if self.n_elements < 2:
            raise SceneError(f"n_elements must be at least 2, got {shown(self.n_elements)}")
        object.__setattr__(self, "n_elements", int(self.n_elements))
        object.__setattr__(self, "axial_damping_constant",
                           non_negative("axial_damping_constant", self.axial_damping_constant))
        object.__setattr__(self, "flexural_rigidity", non_negative("flexural_rigidity", self.flexural_rigidity))
        object.__setattr__(self, "bending_damping_constant",
                           non_negative("bending_damping_constant", self.bending_damping_constant))
        if self.bending_damping_constant > 0.0 and self.flexural_rigidity == 0.0:
            raise SceneError("bending_damping_constant needs bending: flexural_rigidity must be positive, got 0")
        if self.anchor_spring_factor is not None:
            factor = positive("anchor_spring_factor", self.anchor_spring_factor)
            object.__setattr__(self, "anchor_spring_factor", factor)


def scene_chain_spec(scene, anchor_spring_factor: float | None = None,
                     tension_only: bool | None = None) -> ChainSpec3D:
    """The lumped cables of a spatial scene (:class:`~cdpr_exu.scenes.scene.Scene`), with its effects.

    ``tension_only`` defaults to ``effects.slack``; the static mode asks for False (Exudyn's
    static solver needs every element's stiffness, which a slack element has not).
    """
    effects, cable = scene.effects, scene.cables[0]  # the cables share one discretisation (the scene checks)
    return ChainSpec3D(
        tension_only=effects.slack if tension_only is None else bool(tension_only),
        n_elements=cable.n_elements,
        axial_damping_constant=cable.damping_constant * cable.area if effects.axial_damping else 0.0,
        flexural_rigidity=cable.youngs_modulus * cable.second_moment if effects.bending else 0.0,
        bending_damping_constant=(cable.damping_constant * cable.second_moment
                                  if effects.bending and effects.bending_damping else 0.0),
        anchor_spring_factor=anchor_spring_factor, mass_lumping=cable.mass_lumping)


@dataclass
class SpatialRobotItems:
    """Item indices and data of a spatial robot in an Exudyn ``MainSystem``.

    ``chains`` (one :class:`SpatialChainItems` per cable, node 0 held) and ``node_masses`` [kg];
    per cable, ``axial_stiffnesses`` and ``axial_dampings`` of each element [N/m, N s/m],
    ``bending_stiffnesses`` and ``bending_dampings`` of each joint [N m/rad, N m s/rad];
    ``platform_node`` and ``platform_body`` (point mass or rigid body), ``anchor_markers`` and
    ``joints`` (spherical or penalty), one per cable; ``initial`` the equilibrium it started on;
    ``swivels`` and ``swivel_pulleys`` each cable's swivel in Exudyn and its physics (None for
    a point exit); ``winch_elements`` the elements of each chain below the inlet (node
    ``winch_elements[i]`` started at the inlet; 0 where nothing wraps).
    """

    platform: SuspendedPlatform
    unstrained_lengths: np.ndarray
    chain: ChainSpec3D
    chains: list
    node_masses: list
    axial_stiffnesses: np.ndarray
    axial_dampings: np.ndarray
    bending_stiffnesses: np.ndarray
    platform_node: int
    platform_body: int
    anchor_markers: list
    joints: list
    initial: PlatformEquilibrium = field(repr=False)
    swivels: list = field(default_factory=list)
    swivel_pulleys: list = field(default_factory=list)
    winch_elements: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    bending_dampings: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def is_point_mass(self):
        return self.platform.is_point_mass


def build_spatial_robot(mbs, platform, unstrained_lengths, chain=None, initial=None, exits=None):
    """Add the robot to ``mbs``: chains, platform, spherical joints, gravity.

    ``unstrained_lengths`` (n_cables,) [m]; ``chain`` default ``ChainSpec3D()``; ``initial`` the start
    (platform pose and cable shapes), default the catenary statics of these lengths; ``exits`` each
    cable's exit (default: a point exit at its platform cable's exit point), matching the platform
    cable's ``pulley_radius`` and exit point. Bad input raises SceneError naming the field, before
    anything is added to ``mbs``.
    """
    if not isinstance(platform, SuspendedPlatform):
        raise SceneError(f"platform must be a SuspendedPlatform, got {shown(platform)}")
    lengths = checked_unstrained_lengths(platform, unstrained_lengths)
    chain = ChainSpec3D() if chain is None else chain
    if not isinstance(chain, ChainSpec3D):
        raise SceneError(f"chain must be a ChainSpec3D, got {shown(chain)}")
    gravity = positive("gravity", platform.gravity)  # the chains' mass is weight_per_length / gravity
    inertia = np.array(platform.inertia)
    if not platform.is_point_mass and np.any(inertia <= 0.0):
        raise SceneError(f"inertia must be positive for a rigid platform, got {shown(platform.inertia)}")
    if not platform.is_point_mass and platform.mass <= 0.0:
        raise SceneError(f"mass must be positive for a rigid platform, got {shown(platform.mass)}")
    if initial is None:
        initial = solve_statics(platform, lengths)
    elif not isinstance(initial, PlatformEquilibrium) or len(initial.cables) != len(platform.cables):
        raise SceneError(f"initial must be a PlatformEquilibrium of this platform's {len(platform.cables)} cables, "
                         f"got {shown(initial)}")

    exits = [PointExit(cable.point) for cable in platform.cables] if exits is None else list(exits)
    if len(exits) != len(platform.cables):
        raise SceneError(f"exits must give one exit per cable ({len(platform.cables)}), got {len(exits)}")
    for i, (cable, exit_) in enumerate(zip(platform.cables, exits)):
        if cable.pulley_radius != exit_.radius or tuple(exit_.point) != tuple(cable.point):
            raise SceneError(f"exits[{i}] does not match cables[{i}] of the platform (pulley_radius "
                             f"{shown(cable.pulley_radius)} m, exit point {cable.point})")

    n = chain.n_elements
    element_lengths = lengths / n
    axial_stiffnesses = np.array([c.axial_stiffness for c in platform.cables]) / element_lengths
    axial_dampings = chain.axial_damping_constant / element_lengths
    bending_stiffnesses = chain.flexural_rigidity / element_lengths
    bending_dampings = chain.bending_damping_constant / element_lengths

    chains, node_masses, swivel_items, swivel_pulleys, winch_elements = [], [], [], [], []
    for cable, length, equilibrium_cable, k, c, k_theta, c_theta, exit_ in zip(
            platform.cables, lengths, initial.cables, axial_stiffnesses, axial_dampings, bending_stiffnesses,
            bending_dampings, exits):
        element_mass = chain_element_mass(cable, length, n, gravity)
        below, reference, current, pulley = chain_over(exit_, equilibrium_cable, length, n)
        masses = node_masses_along(n + below, element_mass, chain.mass_lumping)
        items = add_spatial_chain(mbs, reference, masses, float(k), float(c), float(k_theta), gravity=gravity,
                                  hold_first=True, tension_only=chain.tension_only, bending_damping=float(c_theta),
                                  forces=False)
        for node, displacement in zip(items.nodes, current - reference):
            mbs.SetNodeParameter(node, "initialCoordinates", [float(x) for x in displacement])
        swivel_pulleys.append(pulley)
        anchor = equilibrium_cable.anchor_point - np.asarray(exit_.point)
        swivel_items.append(None if pulley is None else  # the disc the cable wraps over, at its anchor's azimuth
                            add_swivel_pulley(mbs, items, pulley, psi=float(np.arctan2(anchor[1], anchor[0]))))
        chains.append(items)
        node_masses.append(masses)
        winch_elements.append(below)
    # one generic object for every chain and swivel: one force call per iteration. Over swivel pulleys the elements at the inlet
    # are truly cut by their dampers (the wrap bends the cable) and the cut rule held them 15 Newton iterations
    # at an unchanged residual: without it 5.95 -> 5.35 iterations per step (spatial-four-cable-swivel)
    ChainForces(mbs, chains, gravity, cut_slopes=all(pulley is None for pulley in swivel_pulleys),
                swivels=[swivel for swivel in swivel_items if swivel is not None])

    position = [float(x) for x in initial.position]
    if platform.is_point_mass:
        platform_node = mbs.AddNode(eii.NodePoint(referenceCoordinates=position))
        platform_body = mbs.AddObject(eii.ObjectMassPoint(mass=platform.mass, nodeNumber=platform_node))
        centre = mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=platform_node))
        anchor_markers = [centre] * len(platform.cables)
        if platform.mass > 0.0:
            mbs.AddLoad(eii.LoadForceVector(markerNumber=centre, loadVector=[0.0, 0.0, -platform.mass * gravity]))
    else:
        body_inertia = RigidBodyInertia(mass=platform.mass, inertiaTensor=np.diag(inertia), inertiaTensorAtCOM=True)
        created = mbs.CreateRigidBody(referencePosition=position, referenceRotationMatrix=initial.rotation_matrix,
                                      inertia=body_inertia, gravity=[0.0, 0.0, -gravity],
                                      nodeType=exu.NodeType.RotationEulerParameters, returnDict=True, show=False)
        platform_node, platform_body = created["nodeNumber"], created["bodyNumber"]
        anchor_markers = [mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=platform_body,
                                                               localPosition=[float(x) for x in cable.anchor]))
                          for cable in platform.cables]
    joints = []
    for items, marker, k in zip(chains, anchor_markers, axial_stiffnesses):
        markers = [items.markers[-1], marker]
        if chain.anchor_spring_factor is None:
            joints.append(mbs.AddObject(eii.ObjectJointSpherical(markerNumbers=markers)))
        else:
            stiffness = float(chain.anchor_spring_factor * k)
            joints.append(mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(
                markerNumbers=markers, stiffness=[stiffness] * 3, damping=[0.0] * 3)))
    return SpatialRobotItems(platform, lengths, chain, chains, node_masses, axial_stiffnesses, axial_dampings,
                             bending_stiffnesses, platform_node, platform_body, anchor_markers, joints, initial,
                             swivel_items, swivel_pulleys, np.array(winch_elements, dtype=int), bending_dampings)


def _configuration(current):
    return exu.ConfigurationType.Current if current else exu.ConfigurationType.Initial


def _chain_state(mbs, chain, configuration, rate=False):
    """A chain's displacements (or, with ``rate``, velocities), flat (3N,) [m or m/s]."""
    variable = exu.OutputVariableType.Coordinates_t if rate else exu.OutputVariableType.Coordinates
    return np.concatenate([mbs.GetNodeOutput(node, variable, configuration=configuration)
                           for node in chain.nodes])


def platform_pose(mbs, items, current=True):
    """Platform position [m] shape (3,) and rotation matrix shape (3, 3) (identity for a point mass)."""
    configuration = _configuration(current)
    position = np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.Position,
                                          configuration=configuration))
    if items.is_point_mass:
        return position, np.eye(3)
    rotation = np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.RotationMatrix,
                                          configuration=configuration)).reshape(3, 3)
    return position, rotation


def chain_positions(mbs, items, cable, current=True):
    """Node positions of one cable, exit first, shape (n + 1, 3) [m]."""
    chain = items.chains[cable]
    configuration = _configuration(current)
    return (chain.reference + _chain_state(mbs, chain, configuration)).reshape(-1, 3)


def anchor_forces(mbs, items):
    """Force each cable exerts on the platform at its anchor, shape (n_cables, 3) [N]: the joint reactions.

    The last element's axial force, the bending shear of the last joints (0.2 N of 9 N on the paper's
    cable) and the anchor node's weight and inertia together. Exudyn reports the spherical joint's
    force as the force on the platform, and the penalty spring's with the opposite sign.
    """
    sign = 1.0 if items.chain.anchor_spring_factor is None else -1.0
    return np.array([sign * np.asarray(mbs.GetObjectOutput(joint, exu.OutputVariableType.Force))
                     for joint in items.joints])


def element_forces(mbs, items, cable, current=True, positions=None, velocities=None):
    """Axial force of each element of one cable [N], shape (n,), exit first (tension > 0).

    ``positions``, ``velocities`` (n + 1, 3) [m, m/s]: the cable's nodes when the caller has read them
    already, else read here. As the model computes it: Exudyn's spring-damper k (l - l0) + c (dl/dt -
    dl0/dt) with the parameters the connectors hold now (negative when compressed), or the
    tension-only law with the arrays the chain's force reads.
    """
    chain = items.chains[cable]
    configuration = _configuration(current)
    positions = (chain_positions(mbs, items, cable, current) if positions is None else np.asarray(positions)).ravel()
    v = (_chain_state(mbs, chain, configuration, rate=True) if velocities is None
         else np.asarray(velocities).ravel())
    if chain.tension_only:
        return axial_3d.tension_only_tensions(positions, v, chain.axial_elements, chain.axial_rest_length,
                                              chain.axial_stiffness, chain.axial_damping, chain.axial_rest_rate,
                                              np.zeros(len(chain.axial_elements)))
    points, velocities = positions.reshape(-1, 3), v.reshape(-1, 3)
    delta, delta_rate = np.diff(points, axis=0), np.diff(velocities, axis=0)
    length = np.linalg.norm(delta, axis=1)
    rate = np.einsum("ij,ij->i", delta, delta_rate) / length
    rest, stiffness, damping, offset = (np.array([mbs.GetObjectParameter(spring, name) for spring in chain.springs])
                                        for name in ("referenceLength", "stiffness", "damping", "velocityOffset"))
    return stiffness * (length - rest) + damping * (rate - offset)


def anchor_points(mbs, items):
    """World positions of the anchors on the platform, shape (n_cables, 3) [m] (current state)."""
    return np.array([mbs.GetMarkerOutput(marker, exu.OutputVariableType.Position) for marker in items.anchor_markers])


def robot_energy(mbs, items, current=True):
    """Mechanical energy [J] of cables and platform: kinetic, gravity (z up), axial and bending springs.

    Tension-only elements store the potential of their undamped law
    (:func:`cdpr_exu.physics.axial_3d.tension_only_energy`: 0 below the rest length)."""
    configuration = _configuration(current)
    gravity = items.platform.gravity
    energy = 0.0
    for chain, masses, k, k_theta in zip(items.chains, items.node_masses, items.axial_stiffnesses,
                                         items.bending_stiffnesses):
        q, v = _chain_state(mbs, chain, configuration), _chain_state(mbs, chain, configuration, rate=True)
        energy += chain_energy(chain, masses, q, v, float(k), float(k_theta), gravity)
    for swivel in items.swivels:
        if swivel is not None:
            energy += _swivel_energy(mbs, swivel, configuration)
    if items.chain.anchor_spring_factor is not None:  # the penalty joints' springs
        anchors = np.array([mbs.GetMarkerOutput(marker, exu.OutputVariableType.Position, configuration=configuration)
                            for marker in items.anchor_markers])
        for cable, (anchor, k) in enumerate(zip(anchors, items.axial_stiffnesses)):
            gap = chain_positions(mbs, items, cable, current)[-1] - anchor
            energy += 0.5 * items.chain.anchor_spring_factor * k * float(gap @ gap)
    position, rotation = platform_pose(mbs, items, current)
    velocity = np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.Velocity,
                                          configuration=configuration))
    energy += items.platform.mass * (0.5 * float(velocity @ velocity) + gravity * position[2])
    if not items.is_point_mass:
        omega = np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.AngularVelocityLocal,
                                           configuration=configuration))
        energy += 0.5 * float(omega @ (np.array(items.platform.inertia) * omega))
    return energy


def _swivel_energy(mbs, swivel, configuration):
    """Contact potential and J_s psi_dot^2 / 2 of one swivel pulley [J]."""
    q = _chain_state(mbs, swivel.chain, configuration)
    psi = mbs.GetNodeOutput(swivel.node, exu.OutputVariableType.Coordinates, configuration=configuration)
    rate = mbs.GetNodeOutput(swivel.node, exu.OutputVariableType.Coordinates_t, configuration=configuration)
    return swivel_energy(swivel, q, float(np.ravel(psi)[0]), float(np.ravel(rate)[0]))


def swivel_angles(mbs, items, current=True):
    """Swivel angle psi [rad] of each cable's pulley, shape (n_cables,) (NaN for a point exit)."""
    configuration = _configuration(current)
    return np.array([np.nan if swivel is None else swivel.psi_reference + float(np.ravel(
        mbs.GetNodeOutput(swivel.node, exu.OutputVariableType.Coordinates, configuration=configuration))[0])
        for swivel in (items.swivels or [None] * len(items.chains))])


@dataclass
class Model3D:
    """A spatial scene's assembled Exudyn system (the planar :class:`cdpr_exu.builder.model.Model`'s role):
    ``items`` (:class:`SpatialRobotItems`), ``initial_paid_out`` (m,) [m] the unstrained lengths it starts with;
    ``servos`` a servo winch's drums, each moving its chain's held end along the swivel axis (the z hold, which
    keeps the drum still while the robot settles, is released for the run)."""

    scene: object
    system_container: object
    mbs: object
    items: SpatialRobotItems
    initial_paid_out: np.ndarray
    servos: list = field(default_factory=list)

    def item_counts(self) -> dict[str, int]:
        """How many Exudyn items each part added."""
        items = self.items
        return {"mass_points": sum(len(c.nodes) for c in items.chains),
                "axial_spring_dampers": sum(len(c.springs) for c in items.chains),
                "swivel_pulleys": sum(s is not None for s in items.swivels),
                "platform_joints": len(items.joints)}


def build_model_3d(scene, sparse_jacobian: bool | None = None) -> Model3D:  # noqa: ARG001 - the planar builder's
    """The scene's lumped robot in a new Exudyn system, assembled in its catenary equilibrium
    (UnreachableError if there is none). ``sparse_jacobian`` is the planar builder's choice."""
    platform = catenary_platform(scene)
    lengths = scene.unstrained_lengths
    start = solve_statics(platform, lengths)
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    items = build_spatial_robot(mbs, platform, lengths, scene_chain_spec(scene), initial=start, exits=scene.exits)
    servos = [add_servo_drum(mbs, chain.nodes[0], scene.space.vertical, scene.winch)
              for chain in items.chains] if scene.winch.kind == "servo" else []
    mbs.Assemble()
    return Model3D(scene, container, mbs, items, lengths, servos)
