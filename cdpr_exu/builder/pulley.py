"""Node-pulley penalty contact (paper sec. 2.2), as a rim contact.

The paper's eqs. (14)-(15) push a node inside the pulley disc towards the centre,
k_p (x_p - x_i), a force largest at the rim that cannot let a cable run over a
pulley. We use the physical reading of its Fig. 3 instead: a node that enters the
disc of radius r_p is pushed back out along the outward normal with the force
k_p (r_p - d) (d its distance from the centre), plus c_p times the normal velocity
of penetration. Exudyn's built-in C++ ``ObjectContactSphereSphere`` computes exactly
this between a ground marker at the pulley centre (radius r_p) and the node (a
vanishing radius); with zero friction it accepts a plain position marker for the node.

Only nodes that can reach the pulley during the run get a contact item.
"""

from __future__ import annotations

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.exits import Pulley

#: Radius given to the node "sphere" [m]; Exudyn needs a positive radius.
NODE_CONTACT_RADIUS = 1.0e-9


def add_pulley_ground(mbs: exu.MainSystem, pulley: Pulley) -> int:
    """Add the ground marker at the pulley centre; returns the marker index."""
    ground = mbs.AddObject(eii.ObjectGround(referencePosition=[pulley.center[0], pulley.center[1], 0.0]))
    return mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground, localPosition=[0.0, 0.0, 0.0]))


def add_pulley_contact(mbs: exu.MainSystem, pulley: Pulley, pulley_marker: int,
                       node_markers: list[int], node_positions: np.ndarray) -> list[int]:
    """Add a rim contact between the pulley (``pulley_marker`` at its centre, :func:`add_pulley_ground`)
    and each listed cable node; ``node_positions`` (len(node_markers), 2) [m] initialise the contact
    gaps. Returns the contact objects' indices."""
    contacts = []
    center = np.asarray(pulley.center)
    for marker, position in zip(node_markers, np.asarray(node_positions, dtype=float)):
        gap = float(np.linalg.norm(position - center)) - pulley.radius - NODE_CONTACT_RADIUS
        data = mbs.AddNode(eii.NodeGenericData(initialCoordinates=[gap, 0.0, 0.0, 0.0],
                                               numberOfDataCoordinates=4))
        contacts.append(mbs.AddObject(eii.ObjectContactSphereSphere(
            markerNumbers=[pulley_marker, marker], nodeNumber=data,
            spheresRadii=[pulley.radius, NODE_CONTACT_RADIUS],
            contactStiffness=pulley.contact_stiffness, contactDamping=pulley.contact_damping,
            dynamicFriction=0.0, impactModel=0)))
    return contacts
