"""Adds one lumped-mass cable to an Exudyn system, effect by effect (paper sec. 2.1).

A cable of n elements has n + 1 mass points, node 0 at the winch end and node n at
the platform anchor. Each element is an axial spring-damper (k_i, c_i); each interior
node carries a rotational spring-damper (k_theta, c_theta) on the relative angle of
its two elements. The axial items are Exudyn's built-in C++ spring-dampers; the
bending of all cables is one ``ObjectGenericODE2`` whose force and analytic Jacobian
are numba kernels (:mod:`cdpr_exu.bending`): one Python call per Newton iteration for
the whole robot.

Exudyn items live in its x-y plane: the paper's (x, z) maps to Exudyn's (x, y).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from . import bending
from .scene import CableSpec, Effects


@dataclass
class CableItems:
    """Exudyn indices of one cable's items.

    Attributes
    ----------
    nodes : list of int
        ``NodePoint2D`` indices, winch end first, length n + 1.
    markers : list of int
        ``MarkerNodePosition`` of each node.
    reference : ndarray, shape (n + 1, 2) [m]
        Reference (initial) node positions in the x-z plane.
    springs : list of int
        Axial ``ObjectConnectorSpringDamper`` indices, length n (empty if elasticity is off).
    loads : list of int
        Gravity ``LoadForceVector`` indices.
    """

    nodes: list[int]
    markers: list[int]
    reference: np.ndarray
    springs: list[int] = field(default_factory=list)
    loads: list[int] = field(default_factory=list)
    masses: np.ndarray | None = None


def add_cable(mbs: exu.MainSystem, cable: CableSpec, nodes_xz: np.ndarray, effects: Effects,
              gravity: float) -> CableItems:
    """Add the mass points, axial spring-dampers and gravity loads of one cable.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    cable : CableSpec
    nodes_xz : ndarray, shape (n + 1, 2) [m]
        Initial node positions (x, z), winch end first; each element should start at
        its unstrained length.
    effects : Effects
        Which items to add (axial damping, gravity).
    gravity : float [m/s^2]
        Magnitude of gravity along -z.

    Returns
    -------
    CableItems
    """
    nodes_xz = np.asarray(nodes_xz, dtype=float)
    masses = cable.node_masses()
    items = CableItems(nodes=[], markers=[], reference=nodes_xz.copy(), masses=masses)
    for (x, z), mass in zip(nodes_xz, masses):
        node = mbs.AddNode(eii.NodePoint2D(referenceCoordinates=[x, z]))
        mbs.AddObject(eii.ObjectMassPoint2D(mass=float(mass), nodeNumber=node))
        items.nodes.append(node)
        items.markers.append(mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node)))
    damping = cable.axial_damping if effects.axial_damping else 0.0
    for a, b in zip(items.markers[:-1], items.markers[1:]):
        items.springs.append(mbs.AddObject(eii.ObjectConnectorSpringDamper(
            markerNumbers=[a, b], referenceLength=cable.element_length,
            stiffness=cable.axial_stiffness, damping=damping)))
    if effects.gravity and gravity > 0.0:
        for marker, mass in zip(items.markers, masses):
            items.loads.append(mbs.AddLoad(eii.LoadForceVector(
                markerNumber=marker, loadVector=[0.0, -float(mass) * gravity, 0.0])))
    return items


@dataclass
class BendingItems:
    """The one ``ObjectGenericODE2`` that carries the bending of every cable.

    ``user_functions`` keeps the Python callables alive as long as the model.
    """

    object: int
    joints: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    user_functions: tuple = ()


def add_bending(mbs: exu.MainSystem, cables: list[CableSpec], items: list[CableItems],
                effects: Effects) -> BendingItems | None:
    """Add the exact-angle bending spring-dampers of all cables as one generic object.

    Returns None when ``effects.bending`` is off (then no item and no cost).
    The force user function receives Exudyn's displacement coordinates ``q``; the
    reference positions are added here. Its Jacobian is analytic (numba kernel),
    ``fODE2 * K + fODE2_t * D`` with K = -df/dq, D = -df/dq_t.
    """
    if not effects.bending:
        return None
    counts = [len(it.nodes) for it in items]
    joints = bending.cable_joints(counts)
    stiffness = np.concatenate([np.full(n - 2, c.bending_stiffness) for c, n in zip(cables, counts)])
    damping = np.concatenate([
        np.full(n - 2, c.bending_damping if effects.bending_damping else 0.0) for c, n in zip(cables, counts)
    ])
    reference = np.concatenate([it.reference for it in items]).ravel()
    spring = bending.BendingSpringDamper(len(reference) // 2, joints, stiffness, damping)
    positions = np.zeros(reference.size)

    def force_function(mbs, t, item, q, q_t):  # noqa: ARG001 - Exudyn's signature
        np.add(reference, q, out=positions)
        return spring.force(positions, np.asarray(q_t))

    def jacobian_function(mbs, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
        np.add(reference, q, out=positions)
        return spring.jacobian_weighted(positions, np.asarray(q_t), f_q, f_q_t)

    nodes = [n for it in items for n in it.nodes]
    obj = mbs.AddObject(eii.ObjectGenericODE2(
        nodeNumbers=nodes, massMatrix=np.zeros((reference.size, reference.size)),
        forceUserFunction=force_function, jacobianUserFunction=jacobian_function))
    return BendingItems(obj, joints, stiffness, damping, (spring, force_function, jacobian_function))


def element_tensions(cable: CableSpec, positions: np.ndarray, velocities: np.ndarray,
                     effects: Effects) -> np.ndarray:
    """Axial force of each element, as the spring-dampers compute it (tension > 0).

    Parameters
    ----------
    cable : CableSpec
    positions, velocities : ndarray, shape (..., n + 1, 2) [m, m/s]

    Returns
    -------
    ndarray, shape (..., n) [N]
    """
    delta = np.diff(positions, axis=-2)
    delta_rate = np.diff(velocities, axis=-2)
    length = np.linalg.norm(delta, axis=-1)
    length_rate = np.einsum("...i,...i->...", delta, delta_rate) / np.where(length > 0, length, 1.0)
    force = cable.axial_stiffness * (length - cable.element_length)
    if effects.axial_damping:
        force = force + cable.axial_damping * length_rate
    return force
