"""The driven winch end of each cable (paper sec. 3: a flow source along -z).

The winch end (node 0) hangs on the vertical line below the pulley. The winch
command is the *paid-out length* lambda(t) [m]: the cable length between the hang
point on the pulley and the platform anchor. Paying out moves node 0 up, hauling in
moves it down: z_0(t) = z_0(0) + lambda(t) - lambda(0), x_0 fixed. Both coordinates
of node 0 are prescribed by ``ObjectConnectorCoordinate`` constraints whose offsets
are updated once per time step (a pre-step function), never per Newton iteration.
"""

from __future__ import annotations

from dataclasses import dataclass

import exudyn as exu
import exudyn.itemInterface as eii


@dataclass
class WinchItems:
    """The two coordinate constraints on a cable's winch node.

    Attributes
    ----------
    horizontal, vertical : int
        ``ObjectConnectorCoordinate`` indices prescribing x and z of node 0.
    initial_height : float [m]
        z of node 0 at t = 0 (its Exudyn reference coordinate).
    """

    horizontal: int
    vertical: int
    initial_height: float


def add_winch(mbs: exu.MainSystem, ground_coordinate_marker: int, node: int, initial_height: float) -> WinchItems:
    """Prescribe the winch node: x held, z driven by the offset set per step.

    Parameters
    ----------
    ground_coordinate_marker : int
        A ``MarkerNodeCoordinate`` on a ground node (its coordinate is always 0).
    node : int
        The cable's node 0 (``NodePoint2D``).
    initial_height : float [m]
        z of node 0 at t = 0.
    """
    constraints = []
    for coordinate in (0, 1):
        marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node, coordinate=coordinate))
        constraints.append(mbs.AddObject(eii.ObjectConnectorCoordinate(
            markerNumbers=[ground_coordinate_marker, marker], offset=0.0)))
    return WinchItems(constraints[0], constraints[1], initial_height)


def set_paid_out_length(mbs: exu.MainSystem, winch: WinchItems, paid_out: float, initial_paid_out: float) -> None:
    """Move the winch node to where the paid-out length ``paid_out`` [m] puts it.

    The constraint acts on Exudyn's displacement coordinate of node 0, so the offset
    is the displacement from the initial height: lambda - lambda(0).
    """
    mbs.SetObjectParameter(winch.vertical, "offset", float(paid_out - initial_paid_out))
