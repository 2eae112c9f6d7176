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
import numpy as np

from .scene import WinchSpec


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


def add_winch(mbs: exu.MainSystem, ground_coordinate_marker: int, node: int, initial_height: float,
              drive_height: bool = True) -> WinchItems:
    """Prescribe the winch node: x held, z driven by the offset set per step.

    With ``drive_height`` False only x is held (a servo drum then drives z, see
    :func:`add_servo_drum`) and ``vertical`` is -1 until the drum is added.

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
    for coordinate in ((0, 1) if drive_height else (0,)):
        marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node, coordinate=coordinate))
        constraints.append(mbs.AddObject(eii.ObjectConnectorCoordinate(
            markerNumbers=[ground_coordinate_marker, marker], offset=0.0)))
    return WinchItems(constraints[0], constraints[1] if drive_height else -1, initial_height)


def set_paid_out_length(mbs: exu.MainSystem, winch: WinchItems, paid_out: float, initial_paid_out: float) -> None:
    """Move the winch node to where the paid-out length ``paid_out`` [m] puts it.

    The constraint acts on Exudyn's displacement coordinate of node 0, so the offset
    is the displacement from the initial height: lambda - lambda(0).
    """
    mbs.SetObjectParameter(winch.vertical, "offset", float(paid_out - initial_paid_out))


def servo_gains(spec: WinchSpec) -> np.ndarray:
    """State-feedback gains of the winch servo, designed with python-control.

    The drum seen along the cable is a mass m = J / r^2 driven by the motor force
    u = torque / r: s'' = u / m (the cable tension is a disturbance, fed forward and
    removed by the integral). With the state x = (integral of e, e, e'), e = s - s_cmd,
    u = u_ff - K x.

    Returns
    -------
    ndarray, shape (3,) [N/(m s), N/m, N s/m]
    """
    import control

    a = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    b = np.array([[0.0], [0.0], [1.0 / spec.drum_mass]])
    w = spec.servo_bandwidth
    if spec.servo_design == "pole_placement":
        gains = control.place(a, b, [-w, -1.1 * w, -1.2 * w])
    else:
        # Bryson's rule: 1 mm of error weighs as much as the force that accelerates the
        # drum mass by w^2 * 1 mm; the integral and rate states scaled by w.
        q = np.diag([(w / 1e-3) ** 2, 1.0 / 1e-3**2, (1.0 / (w * 1e-3)) ** 2])
        r = np.array([[1.0 / (spec.drum_mass * w**2 * 1e-3) ** 2]])
        gains, _, _ = control.lqr(a, b, q, r)
    return np.asarray(gains, dtype=float).reshape(3)


@dataclass
class ServoItems:
    """The drum of a servo winch: a one-coordinate node s (paid-out change) [m].

    Attributes
    ----------
    drum_node : int
    load : int
        ``LoadCoordinate`` of the motor force on the drum coordinate [N].
    gains : ndarray, shape (3,)
    """

    drum_node: int
    load: int
    gains: np.ndarray


def add_servo_drum(mbs: exu.MainSystem, winch: WinchItems, node: int, spec: WinchSpec) -> ServoItems:
    """Drive the height of the winch node by a drum under a motor force.

    The drum coordinate s is the paid-out length change (rope taken off the drum); the
    winch node's height follows it through the (now offset-free) vertical constraint.
    """
    drum = mbs.AddNode(eii.NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[0.0],
                                           initialCoordinates_t=[0.0], numberOfODE2Coordinates=1))
    mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=[drum], massMatrix=np.eye(1) * spec.drum_mass))
    drum_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=drum, coordinate=0))
    node_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node, coordinate=1))
    winch.vertical = mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[drum_marker, node_marker], offset=0.0))
    load = mbs.AddLoad(eii.LoadCoordinate(markerNumber=drum_marker, load=0.0))
    return ServoItems(drum, load, servo_gains(spec))


def servo_force(servo: ServoItems, error_integral: float, error: float, error_rate: float,
                feed_forward: float) -> float:
    """Motor force on the drum [N]: u = u_ff - K (integral e, e, e')."""
    return float(feed_forward - servo.gains @ np.array([error_integral, error, error_rate]))
