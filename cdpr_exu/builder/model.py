"""Scene -> Exudyn system: builds the lumped-mass CDPR and returns a :class:`Model`.

Coordinates: the scene speaks the paper's x-z plane; Exudyn's planar items live in
its x-y plane. The builder maps paper (x, z) onto Exudyn (x, y) one to one, so
Exudyn's y *is* the paper's height z, and rotations about Exudyn's z axis are the
paper's platform rotation (positive counter-clockwise, eq. 17).

Only the items of the effects the scene switches on are added (see
:class:`~cdpr_exu.scenes.scene.Effects`); :meth:`Model.item_counts` says which are there.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np
from scipy.optimize import brentq

from cdpr_exu.builder.cable import CableForceItems, CableItems, RopeItems, add_cable, add_cable_forces, add_rope
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.statics import statics
from cdpr_exu.statics.kinematics import anchor_points, initial_cable_nodes, straight_cable_nodes
from cdpr_exu.statics.workspace import check_reference
from cdpr_exu.builder.platform import PlatformItems, add_platform, attach_cable
from cdpr_exu.builder.robot_3d import Model3D, build_model_3d
from cdpr_exu.scenes.scene import Scene
from cdpr_exu.physics.segment_contact import contact_segments
from cdpr_exu.builder.winch import ServoItems, WinchItems, add_servo_drum, add_winch
from cdpr_exu.space import PLANE, SPACE


@dataclass
class Model:
    """An assembled Exudyn system of a planar scene, with the indices of its items.

    Per cable: ``contact_nodes`` and ``contact_elements`` the cable-local nodes and elements that carry a
    rim contact (all contacts live in ``cable_forces``). ``initial_paid_out`` (m,) [m]: lambda_i(0),
    the unstrained cable between the pulley's hang point and the anchor. ``ropes``: the massless
    ropes (``effects.cable_mass`` off; ``cables`` is then empty); ``servos``: a servo winch's drums.
    """

    scene: Scene
    system_container: exu.SystemContainer
    mbs: exu.MainSystem
    cables: list[CableItems]
    platform: PlatformItems
    winches: list[WinchItems]
    cable_forces: CableForceItems | None
    contact_nodes: list[np.ndarray] = field(default_factory=list)
    initial_paid_out: np.ndarray | None = None
    ropes: list[RopeItems] = field(default_factory=list)
    servos: list[ServoItems] = field(default_factory=list)
    contact_elements: list[np.ndarray] = field(default_factory=list)

    def item_counts(self) -> dict[str, int]:
        """How many Exudyn items each effect added; the cable nodes' masses (``mass_points``) and weights
        (``gravity_loads``, with the platform's load) count the entries of the cables' generic object."""
        return {
            "mass_points": sum(len(c.nodes) for c in self.cables),
            "axial_spring_dampers": sum(len(c.springs) for c in self.cables),
            "gravity_loads": sum(np.count_nonzero(c.weights) for c in self.cables) + (self.platform.load is not None),
            "cable_force_objects": int(self.cable_forces is not None),
            "bending_joints": 0 if self.cable_forces is None else len(self.cable_forces.joints),
            "slack_elements": 0 if self.cable_forces is None else len(self.cable_forces.slack_elements),
            "pulley_contacts": sum(len(n) for n in self.contact_nodes),
            "contact_segments": sum(len(e) for e in self.contact_elements),
            "massless_ropes": len(self.ropes),
            "winch_constraints": sum((int(w.horizontal) >= 0) + (int(w.vertical) >= 0) for w in self.winches),
            "servo_drums": len(self.servos),
            "platform_joints": len(self.platform.joints),
        }

    def coordinate_indices(self) -> dict[str, np.ndarray]:
        """Positions of the model's nodes in Exudyn's ODE2 coordinate vector: ``"platform"`` (3,)
        (x, z, rotation) and ``"cable_i"`` (n + 1, 2)."""
        mbs = self.mbs
        out = {"platform": mbs.GetNodeODE2Index(self.platform.node) + np.arange(3)}
        for i, cable in enumerate(self.cables):
            out[f"cable_{i}"] = np.array([mbs.GetNodeODE2Index(n) + np.arange(2) for n in cable.nodes])
        return out


def initial_nodes(scene: Scene, cable_index: int, pose=None) -> np.ndarray:
    """Initial node positions (x, z) of a cable, winch end first, shape (n + 1, 2) [m], the platform at ``pose``
    (3,) [m, m, rad] (default its initial pose).

    Over a pulley: the paper's ideal configuration, straight from the anchor to the
    pulley, wrapped over it and hanging to the winch, every element at its unstrained
    length. With a point exit: straight from the pulley centre to the anchor.

    Segment contact wraps the nodes on the contact model's ``wrap_radius`` instead, so that no
    chord starts inside the disc (the polygon circumscribed about the pulley).
    """
    cable, pulley = scene.cables[cable_index], scene.exits[cable_index]
    pose = scene.platform.initial_pose if pose is None else pose
    anchor = anchor_points(np.asarray(pose), np.asarray(scene.platform.anchors))[cable_index]
    if not pulley.wraps:
        return straight_cable_nodes(np.asarray(pulley.point), anchor, cable.n_elements)
    return initial_cable_nodes(np.asarray(pulley.center), _wrap_radius(scene, cable_index), pulley.side, anchor,
                               cable.element_length, cable.n_elements)


def _wrap_radius(scene: Scene, cable_index: int) -> float:
    """The radius [m] the builder wraps a cable's nodes on: its pulley's, or the segment contact's larger one."""
    pulley, contact = scene.exits[cable_index], scene.contact_model
    return pulley.radius if contact is None else contact.wrap_radius(pulley.radius, scene.cables[cable_index].element_length)


def presag_nodes(scene: Scene, pose=None) -> tuple[list[np.ndarray], float]:
    """Each cable's nodes (n + 1, 2) [m], winch end first, near its static rest (``solver.start = "steady"``), and the
    platform's rotation there [rad].

    The elastic-catenary inverse statics at ``pose`` (3,) [m, m, rad] (default the initial pose; the
    tension-aware controller's statics, milliseconds) gives each cable's loaded shape: catenary, wrap, winch
    line. Walking from the anchor, each node lies on that shape at the chord l0 (1 + T / EA) from the last, T the
    static tension there: every element strained to it. The unstrained lengths and :attr:`Model.initial_paid_out`
    stay the paper start's; the winch node ends where the chain does. SceneError naming ``solver.start`` if the
    statics finds no rest at the initial pose (on two cables: at its rotation) or a cable is too short.
    """
    initial = np.asarray(scene.platform.initial_pose if pose is None else pose, dtype=float)
    try:  # on two cables the rotation is the equilibrium's: at the initial pose it must be the pose's
        rest = statics.solve_inverse_statics(statics.catenary_platform(scene), initial[:2] if len(scene.cables) < 3
                                             else initial)
        if pose is None and abs(rest.rotation - initial[2]) > 1e-9:
            raise SceneError(f"the cables hold it at rotation {rest.rotation:.6g} rad, not {initial[2]:.6g}")
    except (SceneError, UnreachableError) as error:
        raise SceneError(f"solver.start = 'steady' needs a static rest at platform.initial_pose: {error}") from None
    nodes = []
    for i, (equilibrium, cable, exit_) in enumerate(zip(rest.cables, scene.cables, scene.exits)):
        point, tension = _loaded_path(scene, i, equilibrium)
        placed, s, l0 = np.empty((cable.n_elements + 1, 2)), 0.0, cable.element_length
        placed[-1] = equilibrium.anchor_point
        for k in range(cable.n_elements - 1, -1, -1):
            chord = l0 * (1.0 + tension(s + 0.5 * l0) / equilibrium.cable.axial_stiffness)
            s = brentq(lambda t, p=placed[k + 1]: np.linalg.norm(point(t) - p) - chord, s, s + 2.0 * l0, xtol=1e-14)
            placed[k] = point(s)
        if placed[0, 1] > exit_.hang_point[1]:
            raise SceneError(f"solver.start = 'steady': cables[{i}].unstrained_length = {cable.unstrained_length} m "
                             "does not reach past its pulley on its static catenary")
        nodes.append(placed)
    return nodes, float(rest.rotation)


def _loaded_path(scene: Scene, cable_index: int, equilibrium):
    """``point(s)`` (2,) [m] and ``tension(s)`` [N] of a cable's static shape at unstrained arc length s [m] from its
    anchor: the catenary, the wrap stretched by the tension T there (on the builder's wrap radius), the winch line
    below the hang point stretched by T less the weight above."""
    exit_, state, cable = scene.exits[cable_index], equilibrium.catenary, equilibrium.cable
    radius = _wrap_radius(scene, cable_index)
    span, weight, stiffness, top = (equilibrium.suspended_length, cable.weight_per_length, cable.axial_stiffness,
                                    equilibrium.tension_at_exit)
    center, side = np.asarray(exit_.center), exit_.side
    tangent = np.arctan2(*(equilibrium.exit_point - center)[::-1])
    wrap_end = span + exit_.radius * equilibrium.wrap_angle / (1.0 + top / stiffness)

    def point(s):
        if s <= span:
            return equilibrium.points(s)[0]
        if s <= wrap_end:
            angle = tangent - side * (s - span) * (1.0 + top / stiffness) / exit_.radius
            return center + radius * np.array([np.cos(angle), np.sin(angle)])
        down = s - wrap_end
        return center + np.array([side * radius, -down * (1.0 + (top - 0.5 * weight * down) / stiffness)])

    def tension(s):
        if s <= span:
            return float(np.hypot(state.horizontal_tension, state.vertical_tension_a + weight * s))
        return top - weight * max(s - wrap_end, 0.0)

    return point, tension


def start_velocities(scene: Scene, nodes: list[np.ndarray], step: float = 1e-6) -> tuple[np.ndarray, list[np.ndarray]]:
    """The platform's (3,) [m/s, m/s, rad/s] and each cable's node velocities (n + 1, 2) [m/s] of the steady start
    from its ``nodes`` (:func:`presag_nodes`): the reference's velocity at t = 0 (on two cables the rotation
    the statics' along it), and the pre-sagged nodes (material points at their unstrained distance from the
    anchor) as they move with it, a forward difference over ``step`` [s]: the rope over the pulley, the span
    turning and sagging with its anchor, no element changing its length (to 5e-6 m/s), so no velocity step
    for the winches' first command to jolt the stiff, damped cables with. The winch node moves as the chain
    does (ideal IK's rate 5 % less on the paper circle, which its constraint takes up in the first step)."""
    velocity = np.array(scene.trajectory.velocity(0.0), dtype=float)
    later, rotation = presag_nodes(scene, np.asarray(scene.platform.initial_pose) + step * velocity)
    velocity[2] = (rotation - scene.platform.initial_pose[2]) / step
    return velocity, [(moved - placed) / step for moved, placed in zip(later, nodes)]


def contact_candidates(scene: Scene, cable_index: int, margin_elements: float = 2.0) -> np.ndarray:
    """Cable-local indices of the nodes that can reach their pulley during the run.

    A node at unstrained distance s = j l0i from the winch end lies on the pulley
    when s is between the hanging length l0 - lambda(t) and that plus the wrapped arc.
    This range is taken over the reference trajectory sampled at 200 times, widened
    by ``margin_elements`` elements and 5 % of the cable for sag, stretch and the
    difference between controllers.
    """
    cable, pulley = scene.cables[cable_index], scene.exits[cable_index]
    times = np.linspace(0.0, scene.solver.end_time, 200)
    anchors = anchor_points(scene.trajectory.pose(times), np.asarray(scene.platform.anchors))[:, cable_index]
    exits = pulley.exit(anchors)  # all times at once
    hang = cable.unstrained_length - exits.cable_length
    arc_end = hang + pulley.radius * exits.wrap_angle
    margin = margin_elements * cable.element_length + 0.05 * cable.unstrained_length
    s = np.arange(cable.n_elements + 1) * cable.element_length
    reach = (s >= hang.min() - margin) & (s <= arc_end.max() + margin)
    reach[0] = False  # the winch node's motion is prescribed
    return np.flatnonzero(reach)


def _check_elements_fit_the_pulley(scene: Scene, cable_index: int, nodes_xz: np.ndarray) -> None:
    """Refuse a cable whose straight elements cut deep into the pulley from the start.

    With node contact an element much longer than the pulley radius spans the wrap as a
    chord through the disc, and the cable then slips through the pulley; segment contact
    pushes the chords out, so nothing is refused then.
    """
    from cdpr_exu.core.geometry import segment_penetration

    if scene.contact_model is not None and not scene.contact_model.limits_element_length:
        return
    pulley, cable = scene.exits[cable_index], scene.cables[cable_index]
    depth = segment_penetration(pulley, nodes_xz).max()
    if depth > 0.5 * pulley.radius:
        raise SceneError(
            f"cables[{cable_index}].n_elements = {cable.n_elements} is too coarse: its {cable.element_length:.3f} m "
            f"elements cut {1000 * depth:.0f} mm into the {pulley.radius} m pulley as chords of the wrap; "
            f"use elements no longer than about 1.4 pulley radii, or effects.pulley_contact_model = 'segment'")


#: Above this many cable nodes (all cables) the cables' Jacobian is handed to Exudyn as
#: sparse triplets; below, the dense matrix is cheaper (measured: 0.45x at 2 x 16 nodes,
#: 1.06x at 2 x 31, 3.2x at 2 x 121, 5.5x at 2 x 241; see benchmarks/bench_sparse_jacobian.py).
SPARSE_JACOBIAN_MIN_NODES = 50


def build_model(scene: Scene, sparse_jacobian: bool | None = None) -> Model | Model3D:
    """Build and assemble the Exudyn system of ``scene``, planar or spatial: the scene's space picks the
    item family (:data:`BUILDERS`: :func:`build_planar_model`, :func:`cdpr_exu.builder.robot_3d.build_model_3d`).
    """
    return BUILDERS[scene.space](scene, sparse_jacobian)


def build_planar_model(scene: Scene, sparse_jacobian: bool | None = None) -> Model:
    """Build and assemble the Exudyn system of a planar ``scene``.

    ``sparse_jacobian`` hands Exudyn the Jacobian of the cables' Python-side forces
    (exact bending, tension-only elements) as sparse triplets, whose cost grows with the
    number of elements rather than its square; False keeps the dense (2N)^2 matrix (the
    same numbers to round-off); None (default) chooses sparse above
    :data:`SPARSE_JACOBIAN_MIN_NODES` nodes. UnreachableError if the reference leaves the workspace.
    """
    check_reference(scene)  # a reference the cables cannot reach or hold is refused before anything is built
    steady = scene.solver.start == "steady"
    placed = presag_nodes(scene)[0] if steady else None
    moving, velocities = start_velocities(scene, placed) if steady else (None, None)
    system_container = exu.SystemContainer()
    mbs = system_container.AddSystem()
    ground_node = mbs.AddNode(eii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
    ground_coordinate = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground_node, coordinate=0))

    effects = scene.effects
    platform = add_platform(mbs, scene.platform, effects, scene.gravity, moving)
    if not effects.cable_mass:
        return _build_massless(scene, system_container, mbs, platform, ground_coordinate)
    contact = scene.contact_model
    on_segments = contact is not None and contact.on_segments
    cables, winches, contact_nodes, paid_out, servos = [], [], [], [], []
    contact_elements = []
    for i, (cable, exit_) in enumerate(zip(scene.cables, scene.exits)):
        nodes_xz = initial_nodes(scene, i)  # the paper's start: its winch end sets lambda(0) for either start
        if exit_.wraps:
            _check_elements_fit_the_pulley(scene, i, nodes_xz)
        items = add_cable(mbs, cable, nodes_xz if placed is None else placed[i], effects, scene.gravity,
                          None if velocities is None else velocities[i])
        attach_cable(mbs, platform, i, items.markers[-1], cable, explicit=scene.solver.integrator != "generalized_alpha")
        servo = scene.winch.kind == "servo"
        winches.append(add_winch(mbs, ground_coordinate, items.nodes[0], drive_height=not servo))
        if servo:
            servos.append(add_servo_drum(mbs, items.nodes[0], scene.space.vertical, scene.winch))
            winches[-1].vertical = servos[-1].connector
        candidates = np.zeros(0, dtype=int) if contact is None else contact_candidates(scene, i)
        contact_elements.append(contact_segments(candidates, cable.n_elements) if on_segments
                                else np.zeros(0, dtype=np.int64))
        contact_nodes.append(np.zeros(0, dtype=int) if on_segments else candidates)
        paid_out.append(exit_.paid_out_length(cable.unstrained_length, nodes_xz[0]))
        cables.append(items)
    if sparse_jacobian is None:
        sparse_jacobian = sum(c.n_elements + 1 for c in scene.cables) > SPARSE_JACOBIAN_MIN_NODES
    on_nodes = contact is not None and not on_segments
    cable_forces = add_cable_forces(mbs, list(scene.cables), cables, effects, list(scene.exits),
                                    contact_elements if on_segments else None, sparse_jacobian=sparse_jacobian,
                                    contact_nodes=contact_nodes if on_nodes else None,
                                    frozen_contact=on_nodes and contact.frozen_nodes)
    mbs.Assemble()
    return Model(scene, system_container, mbs, cables, platform, winches, cable_forces, contact_nodes,
                 np.asarray(paid_out), servos=servos, contact_elements=contact_elements)


#: Shortest rope segment kept between the fixed winch point and the pulley [m]; a
#: cable that starts fully paid out gets this much extra, unstrained rope there.
MIN_WINCH_SEGMENT = 0.25


def _build_massless(scene: Scene, system_container, mbs, platform: PlatformItems, ground_coordinate: int) -> Model:
    """Massless cables: one reeving-system rope per cable, winch point -> pulley -> anchor."""
    anchors = anchor_points(np.asarray(scene.platform.initial_pose), np.asarray(scene.platform.anchors))
    ropes, winches, paid_out = [], [], []
    for i, (cable, exit_) in enumerate(zip(scene.cables, scene.exits)):
        hang, length = exit_.hang_point, float(exit_.cable_length(np.asarray(anchors[i])))
        hanging = cable.unstrained_length - length
        segment = max(hanging, MIN_WINCH_SEGMENT)
        rope_cable = replace(cable, unstrained_length=cable.unstrained_length + segment - hanging)
        bx, bz = scene.platform.anchors[i]
        anchor_marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=platform.body,
                                                          localPosition=[bx, bz, 0.0]))
        rope = add_rope(mbs, rope_cable, exit_.point, exit_.radius, exit_.side, anchor_marker,
                        hang - np.array([0.0, segment]), ground_coordinate, scene.effects)
        drive = mbs.AddObject(eii.ObjectConnectorCoordinate(
            markerNumbers=[ground_coordinate, rope.drum_marker], offset=0.0))
        winches.append(WinchItems(-1, drive))
        ropes.append(rope)
        paid_out.append(length)
    mbs.Assemble()
    return Model(scene, system_container, mbs, [], platform, winches, None, [np.zeros(0, dtype=int) for _ in ropes],
                 np.asarray(paid_out), ropes)


#: The builder of each space's item family, by :class:`cdpr_exu.space.Space`.
BUILDERS = {PLANE: build_planar_model, SPACE: build_model_3d}
