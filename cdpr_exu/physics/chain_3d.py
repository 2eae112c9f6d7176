"""A spatial cable in Exudyn: 3-D mass points, axial spring-dampers and exact-angle bending.

:func:`add_spatial_chain` adds one chain of ``NodePoint`` + ``ObjectMassPoint`` items
joined by Exudyn's ``ObjectConnectorSpringDamper`` (axial, k = E A / l0, c = d_n A / l0),
with gravity along -z and the bending springs of :mod:`cdpr_exu.physics.bending_3d` in
one ``ObjectGenericODE2`` whose Jacobian is sparse triplets. Its first node can be held
(three coordinate constraints). Units SI; z up.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from . import bending_3d


@dataclass
class SpatialChainItems:
    """Item indices of a spatial chain.

    Attributes
    ----------
    nodes, masses, markers, springs : list of int
    bending : int or None
        The ``ObjectGenericODE2`` of the bending springs (None without bending).
    reference : ndarray, shape (3N,) [m]
        Reference positions of the nodes (Exudyn's coordinates are displacements from them).
    joints : ndarray of int, shape (J, 3)
    user_functions : tuple
        Keeps the Python callables alive as long as the model.
    loads : list of int
        The nodes' gravity ``LoadForceVector`` items (empty without gravity).
    bending_stiffness : ndarray, shape (J,) [N m/rad] or None
        The joints' stiffnesses, the very array the bending force reads (a winch that
        changes the cable's length scales it in place).
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


def add_spatial_chain(mbs: exu.MainSystem, positions: np.ndarray, node_masses: np.ndarray, axial_stiffness: float,
                      axial_damping: float, bending_stiffness: float, gravity: float = 9.81,
                      hold_first: bool = True) -> SpatialChainItems:
    """Add a chain through ``positions`` (N, 3) [m] (unstrained, at rest) to ``mbs``.

    Parameters
    ----------
    positions : ndarray, shape (N, 3) [m]
    node_masses : ndarray, shape (N,) [kg]
    axial_stiffness, axial_damping : float [N/m, N s/m]
        Of each element (E A / l0 and d_n A / l0 of its unstrained length l0).
    bending_stiffness : float [N m/rad]
        Of each joint (0: no bending object at all).
    gravity : float [m/s^2]
        Along -z.
    hold_first : bool
        Hold the first node in place.
    """
    positions = np.asarray(positions, dtype=float)
    nodes, masses, markers, springs, loads = [], [], [], [], []
    for point, mass in zip(positions, node_masses):
        node = mbs.AddNode(eii.NodePoint(referenceCoordinates=list(point)))
        masses.append(mbs.AddObject(eii.ObjectMassPoint(mass=float(mass), nodeNumber=node)))
        marker = mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node))
        if gravity:
            loads.append(mbs.AddLoad(eii.LoadForceVector(markerNumber=marker,
                                                         loadVector=[0.0, 0.0, -float(mass) * gravity])))
        nodes.append(node)
        markers.append(marker)
    for i in range(len(nodes) - 1):
        springs.append(mbs.AddObject(eii.ObjectConnectorSpringDamper(
            markerNumbers=[markers[i], markers[i + 1]], stiffness=axial_stiffness, damping=axial_damping,
            referenceLength=float(np.linalg.norm(positions[i + 1] - positions[i])))))
    if hold_first:
        ground = mbs.AddNode(eii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
        ground_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
        for coordinate in range(3):
            held = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=coordinate))
            mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[ground_marker, held]))
    joints = bending_3d.chain_joints([len(nodes)])
    reference = positions.ravel().copy()
    if bending_stiffness <= 0.0 or len(joints) == 0:
        return SpatialChainItems(nodes, masses, markers, springs, None, reference, joints, loads=loads)
    stiffness = np.full(len(joints), float(bending_stiffness))
    size = reference.size
    rows, columns = bending_3d.spatial_bending_pattern(joints)
    triplets = np.zeros((rows.size, 3))
    triplets[:, 0], triplets[:, 1] = rows, columns
    values = np.zeros(rows.size)
    current = np.zeros(size)
    force = np.zeros(size)
    container = exu.MatrixContainer()

    def force_function(mbs_, t, item, q, q_t):  # noqa: ARG001 - Exudyn's signature
        np.add(reference, q, out=current)
        return bending_3d.spatial_bending_force(current, joints, stiffness, force)

    def jacobian_function(mbs_, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
        np.add(reference, q, out=current)
        triplets[:, 2] = bending_3d.spatial_bending_stiffness(current, joints, stiffness, float(f_q), values)
        container.SetWithSparseMatrix(triplets, numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
        return container

    empty = exu.MatrixContainer()
    empty.SetWithSparseMatrix(np.zeros((0, 3)), numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
    bending = mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=nodes, massMatrix=empty,
                                                   forceUserFunction=force_function,
                                                   jacobianUserFunction=jacobian_function))
    return SpatialChainItems(nodes, masses, markers, springs, bending, reference, joints,
                             (force_function, jacobian_function, container), loads, stiffness)


def chain_energy(items: SpatialChainItems, node_masses: np.ndarray, q: np.ndarray, v: np.ndarray,
                 axial_stiffness: float, bending_stiffness: float, gravity: float = 9.81) -> float:
    """Mechanical energy [J] of the chain at displacements ``q`` and velocities ``v`` (3N,):
    kinetic, gravity (z up), axial springs and bending springs."""
    positions = items.reference + q
    points = positions.reshape(-1, 3)
    rest = np.linalg.norm(np.diff(items.reference.reshape(-1, 3), axis=0), axis=1)
    stretch = np.linalg.norm(np.diff(points, axis=0), axis=1) - rest
    energy = 0.5 * float(np.sum(node_masses * np.sum(v.reshape(-1, 3) ** 2, axis=1)))
    energy += gravity * float(np.sum(node_masses * points[:, 2]))
    energy += 0.5 * axial_stiffness * float(np.sum(stretch**2))
    if items.bending is not None:
        energy += bending_3d.spatial_bending_energy(positions, items.joints, np.full(len(items.joints), bending_stiffness))
    return energy
