"""A spatial cable in Exudyn: 3-D mass points, axial spring-dampers and exact-angle bending.

:func:`add_spatial_chain` adds one chain of ``NodePoint`` items, its axial elements either Exudyn's
``ObjectConnectorSpringDamper`` (k = E A / l0, c = d_n A / l0) or, with ``tension_only``, the
tension-only elements of :mod:`cdpr_exu.physics.axial_3d` (Exudyn's push when compressed).
:class:`ChainForces` gives chains, one or all of a robot's, one ``ObjectGenericODE2``: the nodes'
masses (its mass matrix), their weight along -z, the forces of :mod:`cdpr_exu.physics.bending_3d`
(bending springs, and dampers when ``bending_damping > 0``), the tension-only elements and the swivel
pulleys' contact and bearing damping (:mod:`cdpr_exu.physics.swivel_pulley`, their angles psi its last
coordinates), with one sparse triplet Jacobian: one force call per Newton iteration for the whole robot.
Units SI; z up.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.physics.sparse_blocks import block_pattern, distinct_places, sum_into_places
from cdpr_exu.physics import axial_3d
from cdpr_exu.physics import bending_3d
from cdpr_exu.physics import swivel_pulley
from cdpr_exu.physics.bending import cable_joints
from cdpr_exu.physics.axial import CUT_SLOPE_ITERATIONS, CutSlopes, cable_elements


@dataclass
class SpatialChainItems:
    """Item indices of a spatial chain.

    ``nodes``, ``markers``, ``springs`` (Exudyn's axial spring-dampers, none with tension-only
    elements) and ``holds`` (the three ``ObjectConnectorCoordinate`` holding the first node, whose
    ``offset`` moves it: a winch on a swivel axis) are item indices; ``reference`` (3N,) [m] the
    nodes' reference positions; ``joints`` (J, 3) the bending joints. ``forces`` is the
    :class:`ChainForces` that carries the chain (None before it has one), ``generic``
    its ``ObjectGenericODE2``, ``bending`` the same when the chain bends. ``node_mass`` (N,) [kg],
    ``bending_stiffness`` and ``bending_damping`` (J,) [N m/rad, N m s/rad], and with tension-only
    elements ``axial_elements`` (n, 2), ``axial_rest_length``, ``axial_stiffness``,
    ``axial_damping`` and ``axial_rest_rate`` (n,) [m, N/m, N s/m, m/s], are views of the very
    arrays the force functions read (None when absent): a winch paying out cable changes them in
    place between steps (the masses then reach Exudyn by :meth:`ChainForces.masses_changed`).
    """

    nodes: list
    markers: list
    springs: list
    reference: np.ndarray
    joints: np.ndarray
    node_mass: np.ndarray
    holds: list = field(default_factory=list)
    bending_stiffness: np.ndarray | None = None
    bending_damping: np.ndarray | None = None
    axial_elements: np.ndarray | None = None
    axial_rest_length: np.ndarray | None = None
    axial_stiffness: np.ndarray | None = None
    axial_damping: np.ndarray | None = None
    axial_rest_rate: np.ndarray | None = None
    forces: ChainForces | None = None

    @property
    def tension_only(self) -> bool:
        """The axial elements are tension-only (in ``generic``), not Exudyn spring-dampers."""
        return self.axial_rest_length is not None

    @property
    def generic(self) -> int | None:
        return None if self.forces is None else self.forces.generic

    @property
    def bending(self) -> int | None:
        return self.generic if self.bending_stiffness is not None else None


def add_spatial_chain(mbs: exu.MainSystem, positions: np.ndarray, node_masses: np.ndarray, axial_stiffness: float,
                      axial_damping: float, bending_stiffness: float, gravity: float = 9.81,
                      hold_first: bool = True, tension_only: bool = False, bending_damping: float = 0.0,
                      forces: bool = True) -> SpatialChainItems:
    """Add a chain through ``positions`` (N, 3) [m] (unstrained, at rest) to ``mbs``.

    Parameters
    ----------
    positions : ndarray, shape (N, 3) [m]
    node_masses : ndarray, shape (N,) [kg]
    axial_stiffness, axial_damping : float [N/m, N s/m]
        Of each element (E A / l0 and d_n A / l0).
    bending_stiffness, bending_damping : float [N m/rad, N m s/rad]
        Of each joint (0: none; dampers need bending).
    gravity : float [m/s^2]
        Along -z.
    hold_first : bool
        Hold the first node in place.
    tension_only : bool
        Tension-only axial elements in the generic object instead of Exudyn's spring-dampers.
    forces : bool
        Give the chain its own :class:`ChainForces` (False: the caller gives several chains one).
    """
    positions = np.asarray(positions, dtype=float)
    nodes = [mbs.AddNode(eii.NodePoint(referenceCoordinates=list(point))) for point in positions]
    markers = [mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node)) for node in nodes]
    rest = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    springs = [] if tension_only else [mbs.AddObject(eii.ObjectConnectorSpringDamper(
        markerNumbers=[markers[i], markers[i + 1]], stiffness=axial_stiffness, damping=axial_damping,
        referenceLength=float(rest[i]))) for i in range(len(nodes) - 1)]
    holds = []
    if hold_first:
        ground = mbs.AddNode(eii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
        ground_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
        for coordinate in range(3):
            held = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=coordinate))
            holds.append(mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[ground_marker, held])))
    joints = cable_joints([len(nodes)])
    bending = bending_stiffness > 0.0 and len(joints) > 0
    items = SpatialChainItems(nodes, markers, springs, positions.ravel().copy(), joints,
                              np.array(node_masses, dtype=float), holds,
                              np.full(len(joints), float(bending_stiffness)) if bending else None,
                              np.full(len(joints), float(bending_damping)) if bending and bending_damping > 0.0
                              else None)
    if tension_only:
        items.axial_elements = cable_elements([len(nodes)])
        items.axial_rest_length = rest
        items.axial_stiffness = np.full(len(rest), float(axial_stiffness))
        items.axial_damping = np.full(len(rest), float(axial_damping))
        items.axial_rest_rate = np.zeros(len(rest))
    if forces:
        ChainForces(mbs, [items], gravity)
    return items


def generic_state(mbs, item: int, where: list) -> tuple[np.ndarray, np.ndarray]:
    """The displacements q and velocities q_t [m, m/s] of the ``ObjectGenericODE2`` ``item``, read from the
    system's state vectors (``systemData``), not converted from the lists Exudyn hands its user functions
    (measured x1.09 of a paper-circle run's CPU time); the planar cables' object and the spatial chains' read
    theirs here. ``where`` caches the object's place in them (a slice where it is one block), found at the
    first call."""
    data = mbs.systemData
    if not where:
        index = np.asarray(data.GetObjectLTGODE2(item), dtype=np.int64)
        block = np.array_equal(index, np.arange(index[0], index[0] + index.size))
        where.append(slice(int(index[0]), int(index[0]) + index.size) if block else index)
    return data.GetODE2Coordinates()[where[0]], data.GetODE2Coordinates_t()[where[0]]


class ChainForces:
    """One ``ObjectGenericODE2`` (index ``generic``) for ``chains`` (:class:`SpatialChainItems`, all tension-only
    or none, all bending or none): their masses (its mass matrix), weight (``gravity`` [m/s^2] along -z),
    bending and tension-only elements; the chains' arrays become views of its own. ``cut_slopes``: damper-cut
    elements keep their taut slopes in a step's first iterations (:class:`~cdpr_exu.physics.axial.CutSlopes`);
    False over swivel pulleys, whose inlet elements the wrap truly cuts (:func:`~cdpr_exu.builder.robot_3d.build_spatial_robot`).
    ``swivels``: :class:`~cdpr_exu.builder.swivel_chain.SwivelItems` of these chains, whose angles psi are the
    object's last coordinates (after the nodes' 3 N), with their inertia J_s, contact and bearing damping."""

    def __init__(self, mbs, chains: list, gravity: float, cut_slopes: bool = True, swivels: tuple = ()):
        offsets = np.cumsum([0] + [len(chain.nodes) for chain in chains])
        nodes = [node for chain in chains for node in chain.nodes]
        points = 3 * len(nodes)  # the nodes' coordinates, then each swivel's psi
        size = points + len(swivels)

        def joined(name):  # the chains' arrays end to end, each chain's now a view of the whole (None: none)
            parts = [getattr(chain, name) for chain in chains]
            if parts[0] is None:
                return None
            whole = np.concatenate(parts)
            for chain, start, part in zip(chains, np.cumsum([0] + [len(p) for p in parts]), parts):
                setattr(chain, name, whole[start:start + len(part)])
            return whole

        def shifted(name):  # the chains' node pairs or triples, numbered in the whole
            return np.concatenate([getattr(chain, name) + offset for chain, offset in zip(chains, offsets)])

        self.masses = joined("node_mass")
        stiffness, damping = joined("bending_stiffness"), joined("bending_damping")
        joints = shifted("joints") if stiffness is not None else np.zeros((0, 3), dtype=np.int64)
        stiffness = np.zeros(0) if stiffness is None else stiffness
        rest, axial_k, axial_c, rest_rate = (joined(name) for name in (
            "axial_rest_length", "axial_stiffness", "axial_damping", "axial_rest_rate"))
        tension_only = rest is not None
        elements = shifted("axial_elements") if tension_only else np.zeros((0, 2), dtype=np.int64)
        reference = np.concatenate([chain.reference for chain in chains] + [[s.psi_reference for s in swivels]])
        bend = float(bending_3d.ISOTROPIC_BEND)
        bending_rows, bending_columns = block_pattern(joints, 3)
        axial_rows, axial_columns = block_pattern(elements, 3)
        split = bending_rows.size
        rows, columns, slot = distinct_places(np.concatenate([bending_rows, axial_rows]),
                                              np.concatenate([bending_columns, axial_columns]))
        # each swivel's contact: its psi's place (the last of the force the kernel adds into), its contact nodes
        # numbered in the whole, its pulley's parameters. Its triplets (contact, then bearing) come first, not summed
        # with the chains': Exudyn sums them as it did each swivel's own object (added before the chains'), and with
        # the weight taken before the contact forces the path is that of the separate objects to the last bit
        first = {id(chain): offset for chain, offset in zip(chains, offsets)}
        contacts = [(points + i, first[id(s.chain)] + s.contact_nodes, s.pulley.inlet_array,
                     *(getattr(s.pulley, name) for name in ("radius", "groove_radius", "flange_height",
                                                             "contact_stiffness", "contact_damping", "onset_band")))
                    for i, s in enumerate(swivels)]
        bearing = np.array([s.pulley.bearing_damping for s in swivels])
        patterns = [swivel_pulley.swivel_contact_pattern(contact[1], contact[0] + 1) for contact in contacts]
        psi = np.arange(points, size)  # the bearings' places
        ends = np.cumsum([0] + [pattern[0].size for pattern in patterns])
        own = ends[-1] + psi.size
        swivel_values = np.zeros(own)
        contact_values = [swivel_values[a:b] for a, b in zip(ends, ends[1:])]
        bearing_values = swivel_values[ends[-1]:]
        triplets = np.zeros((own + rows.size, 3))  # the chains' places off the diagonal once: sum_into_places
        triplets[:own, 0] = np.concatenate([pattern[0] for pattern in patterns] + [psi])
        triplets[:own, 1] = np.concatenate([pattern[1] for pattern in patterns] + [psi])
        triplets[own:, 0], triplets[own:, 1] = rows, columns
        values = np.zeros(slot.size)
        bending_values, axial_values = values[:split], values[split:]
        current, force = np.zeros(size), np.zeros(size)
        weight = np.zeros(len(nodes))
        container = exu.MatrixContainer()
        cut = CutSlopes(CUT_SLOPE_ITERATIONS if cut_slopes else 0)
        where = []

        def state(mbs_, item):
            displacements, velocities = generic_state(mbs_, item, where)
            np.add(reference, displacements, out=current)
            return velocities

        def force_function(mbs_, t, item, q, q_t):  # noqa: ARG001 - Exudyn's signature
            velocities = state(mbs_, item)
            cut.force_evaluated(t)
            bending_3d.spatial_bending_force(current, joints, stiffness, force)  # overwrites
            if damping is not None:
                bending_3d.add_spatial_bending_damping_force(current, velocities, joints, damping, bend, force)
            if tension_only:
                axial_3d.tension_only_force(current, velocities, elements, rest, axial_k, axial_c, rest_rate, force)
            np.multiply(self.masses, gravity, out=weight)
            force[2:points:3] -= weight
            for last, *contact in contacts:
                swivel_pulley.swivel_contact_force(current, velocities, current[last], velocities[last], *contact,
                                                   force[:last + 1])
            force[points:] -= bearing * velocities[points:]
            return force.tolist()  # a list crosses into Exudyn faster than an array

        def jacobian_function(mbs_, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
            velocities = state(mbs_, item)
            bending_3d.spatial_bending_stiffness(current, joints, stiffness, float(f_q), bending_values)
            if damping is not None:
                bending_3d.add_spatial_bending_damping_jacobian(current, velocities, joints, damping, bend,
                                                                float(f_q), float(f_q_t), bending_values)
            if tension_only:
                axial_3d.tension_only_triplet_values(current, velocities, elements, rest, axial_k, axial_c, rest_rate,
                                                     float(f_q), float(f_q_t), axial_values, cut.active)
            for (last, *contact), out in zip(contacts, contact_values):
                swivel_pulley.swivel_contact_values(current, velocities, current[last], velocities[last], *contact,
                                                    float(f_q), float(f_q_t), out)
            np.multiply(bearing, float(f_q_t), out=bearing_values)
            triplets[:own, 2] = swivel_values
            sum_into_places(values, slot, triplets[own:])
            container.SetWithSparseMatrix(triplets, numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
            return container

        self.size, self.points = size, points
        diagonal = np.arange(size, dtype=float)
        inertia = [s.pulley.swivel_inertia for s in swivels]
        self.mass_triplets = np.column_stack([diagonal, diagonal, np.concatenate([np.repeat(self.masses, 3), inertia])])
        self.mass_matrix = exu.MatrixContainer()
        self.mass_matrix.SetWithSparseMatrix(self.mass_triplets, numberOfRows=size, numberOfColumns=size,
                                             useDenseMatrix=False)
        self.user_functions = (force_function, jacobian_function, container)  # alive as long as the model
        self.generic = mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=nodes + [s.node for s in swivels],
                                                            massMatrix=self.mass_matrix,
                                                            forceUserFunction=force_function,
                                                            jacobianUserFunction=jacobian_function))
        for chain in chains:
            chain.forces = self

    def masses_changed(self, mbs) -> None:
        """Give Exudyn the masses the chains' ``node_mass`` hold now (the weight follows by itself)."""
        self.mass_triplets[:self.points, 2] = np.repeat(self.masses, 3)
        self.mass_matrix.SetWithSparseMatrix(self.mass_triplets, numberOfRows=self.size, numberOfColumns=self.size,
                                             useDenseMatrix=False)
        mbs.SetObjectParameter(self.generic, "massMatrix", self.mass_matrix)


def chain_energy(items: SpatialChainItems, node_masses: np.ndarray, q: np.ndarray, v: np.ndarray,
                 axial_stiffness: float, bending_stiffness: float, gravity: float = 9.81) -> float:
    """Mechanical energy [J] of the chain at displacements ``q`` and velocities ``v`` (3N,):
    kinetic, gravity (z up), axial and bending springs (tension-only elements: the energy of
    their law with the items' own arrays, and ``axial_stiffness`` is not used)."""
    positions = items.reference + q
    points = positions.reshape(-1, 3)
    energy = 0.5 * float(np.sum(node_masses * np.sum(v.reshape(-1, 3) ** 2, axis=1)))
    energy += gravity * float(np.sum(node_masses * points[:, 2]))
    if items.tension_only:
        energy += axial_3d.tension_only_energy(positions, items.axial_elements, items.axial_rest_length,
                                               items.axial_stiffness)
    else:
        rest = np.linalg.norm(np.diff(items.reference.reshape(-1, 3), axis=0), axis=1)
        stretch = np.linalg.norm(np.diff(points, axis=0), axis=1) - rest
        energy += 0.5 * axial_stiffness * float(np.sum(stretch**2))
    if items.bending is not None:
        energy += bending_3d.spatial_bending_energy(positions, items.joints, np.full(len(items.joints), bending_stiffness))
    return energy
