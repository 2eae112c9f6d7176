"""The rigid planar platform and its cable anchors (paper sec. 2.3, eqs. 16-18).

The platform is an Exudyn ``NodeRigidBody2D`` + ``ObjectRigidBody2D`` with
coordinates (x, y, rotation) = the paper's (x, z, theta): rotation positive
counter-clockwise, anchors p_i = r + R(theta) b_i. The last node of each cable is
joined to its anchor by a revolute joint (``ObjectJointRevolute2D``); for Exudyn's
explicit solvers, which refuse that joint, by a stiff spring-damper instead
(:func:`explicit_joint_spring`).
"""

from __future__ import annotations

from dataclasses import dataclass

import exudyn as exu
import exudyn.itemInterface as eii

from cdpr_exu.scenes.scene import CableSpec, Effects, PlatformSpec


@dataclass
class PlatformItems:
    """Exudyn indices of the platform's items."""

    node: int
    body: int
    anchor_markers: list[int]
    joints: list[int]
    load: int | None


def add_platform(mbs: exu.MainSystem, platform: PlatformSpec, effects: Effects,
                 gravity: float, velocity=None) -> PlatformItems:
    """Add the platform body at its initial pose (moving at ``velocity`` (3,) [m/s, m/s, rad/s], default at rest),
    its anchor markers and its weight (``gravity`` [m/s^2] along -z)."""
    x, z, rotation = platform.initial_pose
    node = mbs.AddNode(eii.NodeRigidBody2D(referenceCoordinates=[x, z, rotation],
                                           initialVelocities=[0.0] * 3 if velocity is None else list(velocity)))
    body = mbs.AddObject(eii.ObjectRigidBody2D(mass=platform.mass, inertia=platform.inertia,
                                               nodeNumber=node))
    anchors = [mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=body, localPosition=[bx, bz, 0.0]))
               for bx, bz in platform.anchors]
    load = None
    if effects.gravity and gravity > 0.0:
        center = mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=body, localPosition=[0.0, 0.0, 0.0]))
        load = mbs.AddLoad(eii.LoadForceVector(markerNumber=center,
                                               loadVector=[0.0, -platform.mass * gravity, 0.0]))
    return PlatformItems(node, body, anchors, [], load)


#: Stiffness of the explicit solvers' cable-to-platform spring, in units of the
#: cable's element axial stiffness k_i (see :func:`explicit_joint_spring`).
EXPLICIT_JOINT_STIFFNESS_FACTOR = 10.0


def explicit_joint_spring(cable: CableSpec) -> tuple[float, float]:
    """Stiffness and damping of the spring-damper that replaces the anchor joint in explicit runs.

    Explicit solvers refuse ``ObjectJointRevolute2D`` (an algebraic constraint). The
    cable's last node is then tied to its anchor by an ``ObjectConnectorCartesianSpringDamper``
    of stiffness k = 10 k_i in x and z (3.1e6 N/m for the paper's cable), critically
    damped on the last node's mass m_n: c = 2 sqrt(k m_n) (740 N s/m for the paper).

    Why 10 k_i: in series with the last element it adds 1/(10 n) of the cable's compliance
    (about 1 micrometre for the paper's cable), while its mode (h < 1.4 / sqrt(k / m_n),
    1.6e-4 s for the paper) stays slower than the cable's own limits on the explicit step, so
    the comparison stays about the cable, not the joint. Returns (stiffness [N/m], damping [N s/m]).
    """
    stiffness = EXPLICIT_JOINT_STIFFNESS_FACTOR * cable.axial_stiffness
    node_mass = float(cable.node_masses()[-1])
    return stiffness, 2.0 * (stiffness * node_mass) ** 0.5


def attach_cable(mbs: exu.MainSystem, items: PlatformItems, anchor_index: int, node_marker: int,
                 cable: CableSpec | None = None, explicit: bool = False) -> int:
    """Join a cable's last node to anchor ``anchor_index``; returns the joint's object index.

    ``explicit``: the stiff spring-damper of :func:`explicit_joint_spring` (which needs ``cable``)
    for explicit solvers instead of a revolute joint (the implicit solver's exact pin).
    """
    markers = [items.anchor_markers[anchor_index], node_marker]
    if explicit:
        if cable is None:
            raise ValueError("attach_cable(explicit=True) needs the cable to size its spring")
        stiffness, damping = explicit_joint_spring(cable)
        joint = mbs.AddObject(eii.ObjectConnectorCartesianSpringDamper(
            markerNumbers=markers, stiffness=[stiffness, stiffness, 0.0], damping=[damping, damping, 0.0]))
    else:
        joint = mbs.AddObject(eii.ObjectJointRevolute2D(markerNumbers=markers))
    items.joints.append(joint)
    return joint
