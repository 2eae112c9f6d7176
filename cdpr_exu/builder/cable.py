"""Adds one lumped-mass cable to an Exudyn system, effect by effect (paper sec. 2.1).

A cable of n elements has n + 1 mass points, node 0 at the winch end and node n at the
platform anchor. Each element is an axial spring-damper (Exudyn's); each interior node a
rotational spring-damper on the relative angle of its two elements. The bending of all cables
is one ``ObjectGenericODE2`` with numba force and Jacobian (:mod:`cdpr_exu.physics.bending`),
one Python call per Newton iteration for the whole robot; it also carries the tension-only
elements (:mod:`cdpr_exu.physics.axial`), the smooth node or segment pulley contacts, and the nodes'
masses (its constant diagonal mass matrix) and weights (its force vector): no mass point or load item
per node (measured x1.2 of the 60-element paper circle's CPU time, paths moved by round-off).

Exudyn items live in its x-y plane: the paper's (x, z) maps to Exudyn's (x, y).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.builder.chain_3d import generic_state
from cdpr_exu.physics.sparse_blocks import block_pattern, distinct_places, sum_into_places
from cdpr_exu.physics import axial
from cdpr_exu.physics import bending
from cdpr_exu.physics import cable_forces
from cdpr_exu.exits import Pulley
from cdpr_exu.scenes.scene import CableSpec, Effects
from cdpr_exu.physics import node_contact as node_contact_module
from cdpr_exu.physics.node_contact import FrozenNodeContact, NodePulleyContact
from cdpr_exu.physics.segment_contact import SegmentPulleyContact


@dataclass
class CableItems:
    """Exudyn indices of one cable's items: ``nodes`` (``NodePoint2D``, winch end first, n + 1)
    and their ``markers``, axial ``springs`` (n, or distance constraints; empty with slack);
    ``reference`` (n + 1, 2) [m] the initial node positions, ``masses`` (n + 1,) [kg] and ``weights``
    (n + 1,) [N] (zero without gravity), which the cables' generic object carries (:func:`add_cable_forces`)."""

    nodes: list[int]
    markers: list[int]
    reference: np.ndarray
    masses: np.ndarray
    weights: np.ndarray
    springs: list[int] = field(default_factory=list)


def add_cable(mbs: exu.MainSystem, cable: CableSpec, nodes_xz: np.ndarray, effects: Effects,
              gravity: float, velocities: np.ndarray | None = None) -> CableItems:
    """Add the nodes and axial spring-dampers of one cable; its masses and weights go into the cables'
    generic object (:func:`add_cable_forces`).

    ``nodes_xz`` (n + 1, 2) [m]: initial node positions (x, z), winch end first, each element at
    its unstrained length or strained to its static tension (:func:`cdpr_exu.builder.model.presag_nodes`);
    ``velocities`` (n + 1, 2) [m/s] their initial velocities (default at rest); ``gravity`` [m/s^2] along -z.
    """
    nodes_xz = np.asarray(nodes_xz, dtype=float)
    masses = cable.node_masses()
    weights = masses * gravity if effects.gravity and gravity > 0.0 else np.zeros_like(masses)
    items = CableItems(nodes=[], markers=[], reference=nodes_xz.copy(), masses=masses, weights=weights)
    velocities = np.zeros_like(nodes_xz) if velocities is None else velocities
    for (x, z), velocity in zip(nodes_xz, velocities):
        node = mbs.AddNode(eii.NodePoint2D(referenceCoordinates=[x, z], initialVelocities=velocity.tolist()))
        items.nodes.append(node)
        items.markers.append(mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node)))
    damping = cable.axial_damping if effects.axial_damping else 0.0
    if effects.slack:
        return items  # axial forces: see add_cable_forces
    if not effects.axial_elasticity:  # inextensible elements: distance constraints
        for a, b in zip(items.markers[:-1], items.markers[1:]):
            items.springs.append(mbs.AddObject(eii.ObjectConnectorDistance(
                markerNumbers=[a, b], distance=cable.element_length)))
        return items
    for a, b in zip(items.markers[:-1], items.markers[1:]):
        items.springs.append(mbs.AddObject(eii.ObjectConnectorSpringDamper(
            markerNumbers=[a, b], referenceLength=cable.element_length,
            stiffness=cable.axial_stiffness, damping=damping)))
    return items


@dataclass
class CableForceItems:
    """The one ``ObjectGenericODE2`` that carries the cables' numba-computed forces: bending
    ``joints``, ``slack_elements``, the segment contacts ``contact_segments`` (S, 2) (global node
    pairs; ``contact`` their :class:`SegmentPulleyContact`) and the smooth ``node_contact``.
    ``user_functions`` keeps the Python callables alive as long as the model.
    """

    object: int
    joints: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    slack_elements: np.ndarray
    user_functions: tuple = ()
    contact_segments: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.int64))
    contact: SegmentPulleyContact | None = None
    #: The tension-only elements' rest lengths, stiffnesses and dampings [m, N/m, N s/m], shape (E,):
    #: the arrays the force kernels read (a winch's rope reservoir changes its first element's).
    slack_arrays: tuple = ()
    node_contact: NodePulleyContact | None = None
    #: One entry: the kink strain of :func:`cdpr_exu.physics.axial._element_block`, set for a
    #: run's first step only (:func:`arm_first_step_kink`).
    first_step_kink: np.ndarray = field(default_factory=lambda: np.zeros(1))


def arm_first_step_kink(forces: CableForceItems | None) -> np.ndarray:
    """Arm the round-off kink rule of the tension-only elements for a run's first step.

    Returns the one-entry array the run's first post-step function sets to 0 (an empty
    stand-in when the model has no cable forces). See :func:`cdpr_exu.physics.axial._element_block`.
    """
    if forces is None:
        return np.zeros(1)
    forces.first_step_kink[0] = axial.ROUNDOFF_STRAIN if len(forces.slack_elements) else 0.0
    return forces.first_step_kink


def add_cable_forces(mbs: exu.MainSystem, cables: list[CableSpec], items: list[CableItems],
                     effects: Effects, pulleys: list[Pulley] | None = None,
                     contact_elements: list[np.ndarray] | None = None,
                     sparse_jacobian: bool = True,
                     contact_nodes: list[np.ndarray] | None = None, frozen_contact: bool = False) -> CableForceItems:
    """Add the masses, weights, bending, tension-only and smooth contact forces of all cables as one object.

    Parameters
    ----------
    items : list of CableItems
        The cables' nodes, in the order of ``cables``.
    pulleys : list of Pulley, optional
        Pulley of each cable; needed with contacts.
    contact_elements, contact_nodes : list of ndarray of int, optional
        Per cable, the cable-local elements (element j joins nodes j and j + 1) that get a segment
        rim contact ("segment") and the nodes that get a node contact (:mod:`cdpr_exu.physics.node_contact`);
        None or all empty: none, and no cost for it.
    frozen_contact : bool
        The node contact is Exudyn's law frozen within Newton's iteration ("node"), not the smooth one
        ("node_smooth"): its gaps are data coordinates of one ``NodeGenericData`` (restored with a rejected
        step), switched by the system's PostNewton function (this object's; measured x1.2 against Exudyn's
        contact items on the 60-element paper circle, the path within 1e-5 mm).
    sparse_jacobian : bool
        Return the Jacobian as sparse triplets (cost linear in the number of nodes) instead of a
        dense (2N, 2N) matrix; with segment contact the dense form is kept.

    The masses form the object's constant diagonal mass matrix, the weights its force vector; without
    bending, tension-only elements or smooth contact it has no user function (nothing in Python). The
    Jacobian is analytic, ``fODE2 * K + fODE2_t * D`` with K = -df/dq, D = -df/dq_t.
    """
    counts = [len(it.nodes) for it in items]
    contact = _segment_contact(counts, pulleys, contact_elements)
    node_contact = _node_contact(counts, pulleys, contact_nodes, frozen_contact)
    reference = np.concatenate([it.reference for it in items]).ravel()
    size = reference.size
    if effects.bending:
        joints = bending.cable_joints(counts)
        stiffness = _per_item(cables, counts, 2, lambda c: c.bending_stiffness)
        damping = _per_item(cables, counts, 2,
                            lambda c: c.bending_damping if effects.bending_damping else 0.0)
    else:
        joints, stiffness, damping = np.zeros((0, 3), np.int64), np.zeros(0), np.zeros(0)
    linear = effects.bending and effects.bending_model == "linear"
    matrices = _linear_bending_matrices(cables, counts, joints, stiffness, damping, reference) if linear else {}
    if linear:  # K and D live in the object's constant matrices; no exact-angle joints
        spring = bending.BendingSpringDamper(size // 2, np.zeros((0, 3), np.int64), np.zeros(0), np.zeros(0))
    else:
        spring = bending.BendingSpringDamper(size // 2, joints, stiffness, damping)
    if effects.slack:
        elements = axial.cable_elements(counts)
        rest = _per_item(cables, counts, 1, lambda c: c.element_length)
        axial_k = _per_item(cables, counts, 1, lambda c: c.axial_stiffness)
        axial_c = _per_item(cables, counts, 1, lambda c: c.axial_damping if effects.axial_damping else 0.0)
    else:
        elements = np.zeros((0, 2), np.int64)
        rest, axial_k, axial_c = np.zeros(0), np.zeros(0), np.zeros(0)
    positions = np.zeros(size)
    force_buffer = np.zeros(size)
    jacobian_buffer = np.zeros((size, size))
    no_force, no_matrix = np.zeros(0), np.zeros((0, 0))
    # The tension-only elements' kink rule of a run's first step (axial._element_block): off
    # until a run arms it, which clears it after its first accepted step (CableForceItems.first_step_kink).
    kink = np.zeros(1)
    cut = axial.CutSlopes()  # damper-cut elements keep their taut slopes in a step's first iterations
    joint_args = (spring.joints, spring.stiffness, spring.damping, elements, rest, axial_k, axial_c)

    where = []  # the object's coordinates in the system's state vectors (generic_state)
    frozen = node_contact is not None and frozen_contact
    if frozen:
        read_gaps = _frozen_contact(mbs, node_contact, reference, positions, where)
    else:
        def read_gaps(mbs):  # noqa: ARG001
            return None

    def force_function(mbs, t, item, q, q_t):  # noqa: ARG001 - Exudyn's signature
        # bending and tension-only elements in one compiled call (cable_forces), then any rim contact
        displacements, velocities = generic_state(mbs, item, where)
        read_gaps(mbs)
        cut.force_evaluated(t)
        force = cable_forces.cable_force(reference, displacements, velocities, positions, *joint_args, force_buffer)
        if contact is not None:
            contact.add_force(positions, velocities, force)
        if node_contact is not None:
            node_contact.add_force(positions, velocities, force)
        return force.tolist()  # a list crosses into Exudyn faster than an array

    def jacobian_function(mbs, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
        displacements, velocities = generic_state(mbs, item, where)
        read_gaps(mbs)
        jacobian = cable_forces.cable_jacobian(reference, displacements, velocities, positions, *joint_args,
                                               float(f_q), float(f_q_t), no_force, no_matrix, jacobian_buffer,
                                               kink[0], cut.active)
        if contact is not None:
            contact.add_jacobian(positions, velocities, f_q, f_q_t, jacobian)
        if node_contact is not None:
            node_contact.add_jacobian(positions, velocities, f_q, f_q_t, jacobian)
        return jacobian

    nodes = [n for it in items for n in it.nodes]
    functions = (force_function, jacobian_function)
    mass = np.diag(np.repeat(np.concatenate([it.masses for it in items]), 2))
    weights = np.zeros(size)
    weights[1::2] = -np.concatenate([it.weights for it in items])  # Exudyn's y is the paper's z
    matrices["forceVector"] = matrices.get("forceVector", 0.0) + weights
    if sparse_jacobian and contact is None and not linear:
        blocks = [_bending_blocks(spring)]
        if effects.slack and len(elements):
            blocks.append(_slack_blocks(elements, rest, axial_k, axial_c, kink, cut))
        if node_contact is not None:
            blocks.append((*node_contact.triplet_pattern(), node_contact.triplet_values))
        functions = (functions[0], _sparse_jacobian_function(blocks, reference, positions, where, read_gaps))
        mass = _sparse(mass)
    if not (effects.bending or effects.slack or contact is not None or node_contact is not None):
        functions = (0, 0)  # masses and weights only
    elif linear and not effects.slack and contact is None and node_contact is None:
        # Nothing left for Python per Newton iteration: no force function, and a Jacobian
        # function that returns an empty matrix, so that Exudyn adds the constant K and D
        # itself (without any Jacobian function it would differentiate them numerically).
        # Sparse triplets: dense (2N, 2N) matrices made a 2 x 61-node cable 8 times slower.
        matrices = {key: _sparse(value) if key != "forceVector" else value for key, value in matrices.items()}
        empty = _sparse(np.zeros((size, size)))
        mass = _sparse(mass)

        def zero_jacobian(mbs, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
            return empty

        functions = (0, zero_jacobian)
    obj = mbs.AddObject(eii.ObjectGenericODE2(
        nodeNumbers=nodes, massMatrix=mass,
        forceUserFunction=functions[0], jacobianUserFunction=functions[1], **matrices))
    segments = np.zeros((0, 2), np.int64) if contact is None else contact.segments
    return CableForceItems(obj, joints, stiffness, damping, elements, (spring, *functions, matrices),
                           segments, contact, (rest, axial_k, axial_c) if effects.slack else (), node_contact, kink)


def _per_item(cables: list[CableSpec], counts: list[int], fewer: int, value) -> np.ndarray:
    """``value(cable)`` for each of the n - ``fewer`` joints (2) or elements (1) of each cable of n nodes."""
    return np.concatenate([np.full(n - fewer, value(c)) for c, n in zip(cables, counts)])


def _bending_blocks(spring):
    """Sparse pattern and value filler of the bending joints' 6 x 6 blocks."""
    rows, columns = block_pattern(spring.joints, 2)

    def fill(positions, velocities, factor_position, factor_velocity, out_values):
        bending.bending_triplet_values(positions, velocities, spring.joints, spring.stiffness, spring.damping,
                                       factor_position, factor_velocity, out_values)
    return rows, columns, fill


def _slack_blocks(elements, rest, axial_k, axial_c, kink, cut):
    """Sparse pattern and value filler of the tension-only elements' 4 x 4 blocks (``kink``: the
    one-entry array of the first step's kink strain, :class:`CableForceItems`; ``cut``: the
    :class:`cdpr_exu.physics.axial.CutSlopes` of the force function)."""
    rows, columns = axial.slack_triplet_pattern(elements)

    def fill(positions, velocities, factor_position, factor_velocity, out_values):
        axial.slack_triplet_values(positions, velocities, elements, rest, axial_k, axial_c,
                                   factor_position, factor_velocity, out_values, kink[0], cut.active)
    return rows, columns, fill


def _sparse_jacobian_function(blocks, reference, positions, where, read_gaps):
    """A ``jacobianUserFunction`` returning ``f_q K + f_q_t D`` as sparse triplets in a fixed pattern:
    ``blocks`` lists ``(rows, columns, fill)`` per force, ``fill(positions, velocities, f_q, f_q_t,
    out_values)`` writing the values; ``where`` as :func:`~cdpr_exu.builder.chain_3d.generic_state`;
    ``read_gaps(mbs)`` refreshes a frozen contact's state."""
    size = reference.size
    bounds = np.cumsum([0] + [rows.size for rows, _, _ in blocks])
    rows, columns, slot = distinct_places(np.concatenate([rows for rows, _, _ in blocks]),
                                          np.concatenate([columns for _, columns, _ in blocks]))
    triplets = np.zeros((rows.size, 3))  # each place off the diagonal once: sum_into_places
    triplets[:, 0], triplets[:, 1] = rows, columns
    every_value = np.zeros(slot.size)
    values = [every_value[first:last] for first, last in zip(bounds[:-1], bounds[1:])]
    container = exu.MatrixContainer()

    def jacobian_function(mbs, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001 - Exudyn's signature
        displacements, velocities = generic_state(mbs, item, where)
        read_gaps(mbs)
        np.add(reference, displacements, out=positions)
        for (_, _, fill), out_values in zip(blocks, values):
            fill(positions, velocities, float(f_q), float(f_q_t), out_values)
        sum_into_places(every_value, slot, triplets)
        container.SetWithSparseMatrix(triplets, numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
        return container

    return jacobian_function


def _pulley_arrays(counts: list[int], pulleys: list[Pulley] | None, per_cable: list[np.ndarray] | None,
                   refusal: str) -> tuple | None:
    """The global node indices of ``per_cable``'s cable-local indices and their pulleys' centres, radii,
    contact stiffnesses and dampings, one per index; None when there are none."""
    if per_cable is None or not any(len(n) for n in per_cable):
        return None
    if pulleys is None or len(pulleys) != len(counts) or len(per_cable) != len(counts):
        raise ValueError(refusal)
    first = np.cumsum([0] + list(counts[:-1]))
    indices = np.concatenate([start + np.asarray(n, dtype=np.int64) for start, n in zip(first, per_cable)])
    return (indices, *[np.repeat(np.array([getattr(p, name) for p in pulleys], dtype=float),
                                 [len(n) for n in per_cable], axis=0)
                       for name in ("center", "radius", "contact_stiffness", "contact_damping")])


def _node_contact(counts: list[int], pulleys: list[Pulley] | None, contact_nodes: list[np.ndarray] | None,
                  frozen: bool) -> NodePulleyContact | None:
    """The node rim contacts of the listed nodes with their cables' pulleys, frozen or smooth (None if none)."""
    arrays = _pulley_arrays(counts, pulleys, contact_nodes,
                            "node contact needs one pulley and one list of contact nodes per cable")
    if arrays is None:
        return None
    if frozen:
        return FrozenNodeContact(sum(counts), *arrays)
    return NodePulleyContact(sum(counts), *arrays, band=node_contact_module.CONTACT_ONSET_DEPTH)


def _frozen_contact(mbs: exu.MainSystem, contact: FrozenNodeContact, reference: np.ndarray, positions: np.ndarray,
                    where: list):
    """Keep the frozen contact's gaps in a ``NodeGenericData`` (initialised at ``reference``, so restored by the
    solver with a rejected step) and switch them in the system's PostNewton function, as Exudyn's contact
    items do theirs (their step-size recommendation is off in every run: run.solver). Returns
    ``read_gaps(mbs)``, which loads the gaps into ``contact`` (the force functions call it first)."""
    contact.switch(reference, contact.gaps)  # the gaps d - r_p - r_n [m] at the start
    data_node = mbs.AddNode(eii.NodeGenericData(initialCoordinates=contact.gaps.tolist(),
                                                numberOfDataCoordinates=contact.gaps.size))
    place = []

    def read_gaps(mbs):
        data = mbs.systemData
        if not place:
            index = np.asarray(data.GetNodeLTGData(data_node), dtype=np.int64)
            place.append(slice(int(index[0]), int(index[0]) + index.size))
        contact.gaps = data.GetDataCoordinates()[place[0]]

    def post_newton(mbs, t):  # noqa: ARG001 - Exudyn's signature
        data = mbs.systemData
        read_gaps(mbs)
        np.add(reference, data.GetODE2Coordinates()[where[0]], out=positions)
        values = data.GetDataCoordinates()
        error = contact.switch(positions, values[place[0]])
        data.SetDataCoordinates(values)
        return [error, -1.0]

    mbs.SetPostNewtonUserFunction(post_newton)
    return read_gaps


def _segment_contact(counts: list[int], pulleys: list[Pulley] | None,
                     contact_elements: list[np.ndarray] | None) -> SegmentPulleyContact | None:
    """The segment rim contacts of the listed elements with their cables' pulleys (None if none)."""
    arrays = _pulley_arrays(counts, pulleys, contact_elements,
                            "segment contact needs one pulley and one list of contact elements per cable")
    if arrays is None:
        return None
    first, *per_segment = arrays
    return SegmentPulleyContact(sum(counts), np.column_stack([first, first + 1]), *per_segment)


def _sparse(matrix: np.ndarray) -> exu.MatrixContainer:
    """Exudyn sparse-triplet container of a (square) NumPy matrix."""
    rows, columns = np.nonzero(matrix)
    container = exu.MatrixContainer()
    container.SetWithSparseMatrix(np.column_stack([rows, columns, matrix[rows, columns]]).reshape(-1, 3),
                                  numberOfRows=matrix.shape[0], numberOfColumns=matrix.shape[1],
                                  useDenseMatrix=False)
    return container


def _linear_bending_matrices(cables: list[CableSpec], counts: list[int], joints: np.ndarray, stiffness: np.ndarray,
                             damping: np.ndarray, reference: np.ndarray) -> dict[str, np.ndarray]:
    """Constant matrices of the linear curvature-vector bending (``Effects.bending_model = "linear"``).

    The spring ``(k_theta / l0i^2) |p_a - 2 p_b + p_c|^2 / 2`` acts on the absolute
    positions p = q_ref + q, while Exudyn multiplies K by the displacement q; the force
    vector ``-K q_ref`` supplies the rest, so any straight, evenly spaced cable is free of
    bending, whatever the (wrapped) reference configuration. For equal element lengths
    its moment is k_theta sin(theta) instead of k_theta theta: 17 % less at 60 degrees. Returns the
    ``stiffnessMatrix``, ``dampingMatrix`` (2N, 2N) [N/m, N s/m] and ``forceVector`` (2N,) [N].
    """
    lengths = _per_item(cables, counts, 2, lambda c: c.element_length)
    n_nodes = reference.size // 2
    k_matrix = bending.curvature_stiffness_matrix(n_nodes, joints, stiffness, lengths)
    d_matrix = bending.curvature_stiffness_matrix(n_nodes, joints, damping, lengths)
    return {"stiffnessMatrix": k_matrix, "dampingMatrix": d_matrix, "forceVector": -k_matrix @ reference}


def element_tensions(cable: CableSpec, positions: np.ndarray, velocities: np.ndarray,
                     effects: Effects, rest_length: np.ndarray | None = None) -> np.ndarray:
    """Axial force of each element, as the spring-dampers compute it (tension > 0).

    ``positions``, ``velocities`` (..., n + 1, 2) [m, m/s] -> (..., n) [N]; with ``effects.slack``
    the tension-only law of :func:`cdpr_exu.physics.axial.tension_law`. ``rest_length`` (..., n) [m]:
    each element's when it differs from the nominal one (the winch element holding slack rope,
    :func:`cdpr_exu.builder.winch.reservoir_split`); stiffness and damping scale as 1 / rest length.
    """
    delta = np.diff(positions, axis=-2)
    delta_rate = np.diff(velocities, axis=-2)
    length = np.linalg.norm(delta, axis=-1)
    length_rate = np.einsum("...i,...i->...", delta, delta_rate) / np.where(length > 0, length, 1.0)
    rest = cable.element_length if rest_length is None else np.asarray(rest_length, dtype=float)
    scale = cable.element_length / rest
    extension = length - rest
    force = cable.axial_stiffness * scale * extension
    if effects.axial_damping:
        force = force + cable.axial_damping * scale * length_rate
    if effects.slack:  # axial.tension_law, vectorised: nothing below the rest length, a C1 switch above
        x = np.clip(extension / (axial.TAUT_BAND * rest), 0.0, 1.0)
        force = np.maximum(force, 0.0) * x * x * (3.0 - 2.0 * x)
    return force


#: Stiffness of an "inextensible" massless rope, as a multiple of its elastic EA:
#: stiff enough that its stretch (about 1e-3 of the elastic one) is negligible, soft
#: enough for the implicit solver's Newton iteration at the usual step sizes.
INEXTENSIBLE_STIFFNESS_FACTOR = 1.0e3


@dataclass
class RopeItems:
    """A massless cable: the ``ObjectConnectorReevingSystemSprings`` ``rope`` (winch point, pulley
    sheave, platform anchor), the one-coordinate ``drum_node`` (its prescribed value is the paid-out
    length change) and its ``drum_marker``; ``winch_point`` (2,) [m] the rope's fixed start (x, z)."""

    rope: int
    drum_node: int
    drum_marker: int
    winch_point: np.ndarray


def add_rope(mbs: exu.MainSystem, cable: CableSpec, pulley_center, pulley_radius: float, side: int,
             anchor_marker: int, winch_point, ground_coordinate_marker: int, effects: Effects) -> RopeItems:
    """Add a massless rope from a fixed winch point over the pulley to the platform anchor.

    The rope force is uniform along it (frictionless sheave): EA / L times the stretch
    over the current length L, plus the damping dn A / L times the stretch rate; with
    ``effects.slack`` compression is cut off (Exudyn's regularisation force, 0.1 N).
    Exudyn's sheave wraps the rope on the side given by the sign of its axis: +z for a
    cable hanging on the pulley's right side, -z on its left (``side``). The paid-out
    length change lambda - lambda(0) is a prescribed coordinate that Exudyn adds to the
    rope's reference length.

    ``pulley_center``, ``winch_point`` (x, z) [m] (the rope's fixed start below the pulley);
    ``pulley_radius`` [m] (0 for a point exit); ``anchor_marker`` the platform anchor's
    ``MarkerBodyRigid``; ``ground_coordinate_marker`` a coordinate marker that is always 0.
    """
    winch_point = np.asarray(winch_point, dtype=float)
    winch_ground = mbs.AddObject(eii.ObjectGround(referencePosition=[winch_point[0], winch_point[1], 0.0]))
    winch_marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=winch_ground))
    pulley_ground = mbs.AddObject(eii.ObjectGround(referencePosition=[pulley_center[0], pulley_center[1], 0.0]))
    pulley_marker = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=pulley_ground))
    drum = mbs.AddNode(eii.NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[0.0],
                                           initialCoordinates_t=[0.0], numberOfODE2Coordinates=1))
    # The drum coordinate is prescribed (winch constraint); this small mass only keeps
    # the mass matrix regular.
    mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=[drum], massMatrix=np.eye(1) * 1.0e-3))
    drum_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=drum, coordinate=0))
    stiffness = cable.axial_rigidity * (1.0 if effects.axial_elasticity else INEXTENSIBLE_STIFFNESS_FACTOR)
    damping = cable.damping_constant * cable.area if effects.axial_damping else 0.0
    rope = mbs.AddObject(eii.ObjectConnectorReevingSystemSprings(
        markerNumbers=[winch_marker, pulley_marker, anchor_marker, drum_marker, ground_coordinate_marker],
        hasCoordinateMarkers=True, coordinateFactors=[1.0, 1.0],
        stiffnessPerLength=stiffness, dampingPerLength=damping, referenceLength=cable.unstrained_length,
        sheavesAxes=exu.Vector3DList([[0.0, 0.0, float(side)]] * 3),
        sheavesRadii=[0.0, float(pulley_radius), 0.0],
        regularizationForce=0.1 if effects.slack else -1.0))
    return RopeItems(rope, drum, drum_marker, winch_point)
