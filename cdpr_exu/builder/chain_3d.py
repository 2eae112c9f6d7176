"""A spatial cable in Exudyn: 3-D mass points, axial spring-dampers and exact-angle bending.

:func:`add_spatial_chain` adds one chain of ``NodePoint`` + ``ObjectMassPoint`` items joined by
Exudyn's ``ObjectConnectorSpringDamper`` (k = E A / l0, c = d_n A / l0), gravity along -z, and
one ``ObjectGenericODE2`` with a sparse triplet Jacobian for the forces of
:mod:`cdpr_exu.physics.bending_3d` (bending springs, and dampers when ``bending_damping > 0``)
and, with ``tension_only``, the tension-only elements of :mod:`cdpr_exu.physics.axial_3d` in
place of Exudyn's spring-dampers (which push when compressed). Units SI; z up.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.physics.sparse_blocks import block_pattern
from cdpr_exu.physics import axial_3d
from cdpr_exu.physics import bending_3d
from cdpr_exu.physics.bending import cable_joints
from cdpr_exu.physics.axial import CutSlopes, cable_elements


@dataclass
class SpatialChainItems:
    """Item indices of a spatial chain.

    ``nodes``, ``masses``, ``markers``, ``springs`` (Exudyn's axial spring-dampers), ``loads``
    (gravity) and ``holds`` (the three ``ObjectConnectorCoordinate`` holding the first node, whose
    ``offset`` moves it: a winch on a swivel axis) are item indices; ``reference`` (3N,) [m] the
    nodes' reference positions; ``joints`` (J, 3) the bending joints. ``generic`` is the chain's
    ``ObjectGenericODE2`` (None when it has none), ``bending`` the same when it bends;
    ``user_functions`` keeps its Python callables alive. ``bending_stiffness`` and
    ``bending_damping`` (J,) [N m/rad, N m s/rad], and with tension-only elements
    ``axial_elements`` (n, 2), ``axial_rest_length``, ``axial_stiffness``, ``axial_damping`` and
    ``axial_rest_rate`` (n,) [m, N/m, N s/m, m/s], are the very arrays the force functions read
    (None when absent): a winch paying out cable changes them in place between steps.
    """

    nodes: list
    masses: list
    markers: list
    springs: list
    bending: int | None
    reference: np.ndarray
    joints: np.ndarray
    user_functions: tuple = field(default_factory=tuple)
    loads: list = field(default_factory=list)
    bending_stiffness: np.ndarray | None = None
    generic: int | None = None
    axial_elements: np.ndarray | None = None
    axial_rest_length: np.ndarray | None = None
    axial_stiffness: np.ndarray | None = None
    axial_damping: np.ndarray | None = None
    axial_rest_rate: np.ndarray | None = None
    holds: list = field(default_factory=list)
    bending_damping: np.ndarray | None = None

    @property
    def tension_only(self) -> bool:
        """The axial elements are tension-only (in ``generic``), not Exudyn spring-dampers."""
        return self.axial_rest_length is not None


def add_spatial_chain(mbs: exu.MainSystem, positions: np.ndarray, node_masses: np.ndarray, axial_stiffness: float,
                      axial_damping: float, bending_stiffness: float, gravity: float = 9.81,
                      hold_first: bool = True, tension_only: bool = False, bending_damping: float = 0.0,
                      isotropic_bend: float | None = None) -> SpatialChainItems:
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
    isotropic_bend : float or None
        The dampers' eps (None: :data:`cdpr_exu.physics.bending_3d.ISOTROPIC_BEND`).
    """
    positions = np.asarray(positions, dtype=float)
    nodes, masses, markers, springs, loads, holds = [], [], [], [], [], []
    for point, mass in zip(positions, node_masses):
        node = mbs.AddNode(eii.NodePoint(referenceCoordinates=list(point)))
        masses.append(mbs.AddObject(eii.ObjectMassPoint(mass=float(mass), nodeNumber=node)))
        marker = mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node))
        if gravity:  # the node's weight follows its mass as a winch pays the cable out (run_3d)
            loads.append(mbs.AddLoad(eii.LoadMassProportional(
                markerNumber=mbs.AddMarker(eii.MarkerBodyMass(bodyNumber=masses[-1])),
                loadVector=[0.0, 0.0, -gravity])))
        nodes.append(node)
        markers.append(marker)
    for i in range(0 if tension_only else len(nodes) - 1):
        springs.append(mbs.AddObject(eii.ObjectConnectorSpringDamper(
            markerNumbers=[markers[i], markers[i + 1]], stiffness=axial_stiffness, damping=axial_damping,
            referenceLength=float(np.linalg.norm(positions[i + 1] - positions[i])))))
    if hold_first:
        ground = mbs.AddNode(eii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
        ground_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
        for coordinate in range(3):
            held = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=coordinate))
            holds.append(mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[ground_marker, held])))
    joints = cable_joints([len(nodes)])
    reference = positions.ravel().copy()
    bending = bending_stiffness > 0.0 and len(joints) > 0
    if not bending and not tension_only:
        return SpatialChainItems(nodes, masses, markers, springs, None, reference, joints, loads=loads, holds=holds)
    bending_joints = joints if bending else np.zeros((0, 3), dtype=np.int64)
    stiffness = np.full(len(bending_joints), float(bending_stiffness))
    damped = bending and bending_damping > 0.0
    damping = np.full(len(bending_joints), float(bending_damping)) if damped else None
    bend = float(bending_3d.ISOTROPIC_BEND if isotropic_bend is None else isotropic_bend)
    if tension_only:
        elements = cable_elements([len(nodes)])
        rest = np.linalg.norm(np.diff(positions, axis=0), axis=1)
        axial_k = np.full(len(elements), float(axial_stiffness))
        axial_c = np.full(len(elements), float(axial_damping))
    else:
        elements = np.zeros((0, 2), dtype=np.int64)
        rest = axial_k = axial_c = np.zeros(0)
    rest_rate = np.zeros(len(elements))
    size = reference.size
    bending_rows, bending_columns = block_pattern(bending_joints, 3)
    axial_rows, axial_columns = block_pattern(elements, 3)
    split = bending_rows.size
    triplets = np.zeros((split + axial_rows.size, 3))
    triplets[:, 0] = np.concatenate([bending_rows, axial_rows])
    triplets[:, 1] = np.concatenate([bending_columns, axial_columns])
    bending_values = np.zeros(split)
    axial_values = np.zeros(axial_rows.size)
    current = np.zeros(size)
    force = np.zeros(size)
    container = exu.MatrixContainer()
    cut = CutSlopes()  # damper-cut elements keep their taut slopes in a step's first iterations

    def force_function(mbs_, t, item, q, q_t):  # noqa: ARG001 - Exudyn's signature
        np.add(reference, q, out=current)
        cut.force_evaluated(t)
        bending_3d.spatial_bending_force(current, bending_joints, stiffness, force)  # overwrites
        if damped:
            bending_3d.add_spatial_bending_damping_force(current, np.asarray(q_t), bending_joints, damping, bend, force)
        if tension_only:
            axial_3d.tension_only_force(current, np.asarray(q_t), elements, rest, axial_k, axial_c, rest_rate, force)
        return force

    def jacobian_function(mbs_, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
        np.add(reference, q, out=current)
        bending_3d.spatial_bending_stiffness(current, bending_joints, stiffness, float(f_q), bending_values)
        if damped:
            bending_3d.add_spatial_bending_damping_jacobian(current, np.asarray(q_t), bending_joints, damping, bend,
                                                            float(f_q), float(f_q_t), bending_values)
        triplets[:split, 2] = bending_values
        if tension_only:
            triplets[split:, 2] = axial_3d.tension_only_triplet_values(
                current, np.asarray(q_t), elements, rest, axial_k, axial_c, rest_rate, float(f_q), float(f_q_t),
                axial_values, cut.active)
        container.SetWithSparseMatrix(triplets, numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
        return container

    empty = exu.MatrixContainer()
    empty.SetWithSparseMatrix(np.zeros((0, 3)), numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
    generic = mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=nodes, massMatrix=empty,
                                                   forceUserFunction=force_function,
                                                   jacobianUserFunction=jacobian_function))
    common = dict(user_functions=(force_function, jacobian_function, container), loads=loads, holds=holds,
                  bending_stiffness=stiffness if bending else None, generic=generic, bending_damping=damping)
    if not tension_only:
        return SpatialChainItems(nodes, masses, markers, springs, generic, reference, joints, **common)
    return SpatialChainItems(nodes, masses, markers, springs, generic if bending else None, reference, joints,
                             axial_elements=elements, axial_rest_length=rest, axial_stiffness=axial_k,
                             axial_damping=axial_c, axial_rest_rate=rest_rate, **common)


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
