"""The rigid planar platform and its cable anchors (paper sec. 2.3, eqs. 16-18).

The platform is an Exudyn ``NodeRigidBody2D`` + ``ObjectRigidBody2D`` with
coordinates (x, y, rotation) = the paper's (x, z, theta): rotation positive
counter-clockwise, anchors p_i = r + R(theta) b_i. The last node of each cable is
joined to its anchor by a revolute joint (``ObjectJointRevolute2D``).
"""

from __future__ import annotations

from dataclasses import dataclass

import exudyn as exu
import exudyn.itemInterface as eii

from .scene import Effects, PlatformSpec


@dataclass
class PlatformItems:
    """Exudyn indices of the platform's items."""

    node: int
    body: int
    anchor_markers: list[int]
    joints: list[int]
    load: int | None


def add_platform(mbs: exu.MainSystem, platform: PlatformSpec, effects: Effects,
                 gravity: float) -> PlatformItems:
    """Add the platform body at its initial pose, its anchor markers and its weight.

    Parameters
    ----------
    platform : PlatformSpec
    effects : Effects
    gravity : float [m/s^2]
        Magnitude of gravity along -z.
    """
    x, z, rotation = platform.initial_pose
    node = mbs.AddNode(eii.NodeRigidBody2D(referenceCoordinates=[x, z, rotation]))
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


def attach_cable(mbs: exu.MainSystem, items: PlatformItems, anchor_index: int, node_marker: int) -> int:
    """Join a cable's last node to anchor ``anchor_index`` with a revolute joint."""
    joint = mbs.AddObject(eii.ObjectJointRevolute2D(
        markerNumbers=[items.anchor_markers[anchor_index], node_marker]))
    items.joints.append(joint)
    return joint
