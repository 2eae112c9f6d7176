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

from cdpr_exu.scenes.scene import WinchSpec


@dataclass
class WinchItems:
    """The ``ObjectConnectorCoordinate`` constraints prescribing x and z of a cable's winch node."""

    horizontal: int
    vertical: int


def add_winch(mbs: exu.MainSystem, ground_coordinate_marker: int, node: int,
              drive_height: bool = True) -> WinchItems:
    """Prescribe the winch node ``node`` (node 0): x held, z driven by the offset set per step.

    With ``drive_height`` False only x is held (a servo drum then drives z, see
    :func:`add_servo_drum`) and ``vertical`` is -1 until the drum is added.
    ``ground_coordinate_marker``: a ``MarkerNodeCoordinate`` on a ground node (always 0).
    """
    constraints = []
    for coordinate in ((0, 1) if drive_height else (0,)):
        marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node, coordinate=coordinate))
        constraints.append(mbs.AddObject(eii.ObjectConnectorCoordinate(
            markerNumbers=[ground_coordinate_marker, marker], offset=0.0)))
    return WinchItems(constraints[0], constraints[1] if drive_height else -1)


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
    u = u_ff - K x. Returns K, shape (3,) [N/(m s), N/m, N s/m].
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
    """The drum of a servo winch: a one-coordinate node s (paid-out change) [m], the ``LoadCoordinate``
    ``load`` of the motor force on it [N], the servo ``gains`` (3,) and the ``connector`` joining s to the winch node."""

    drum_node: int
    load: int
    gains: np.ndarray
    connector: int


def add_servo_drum(mbs: exu.MainSystem, node: int, vertical: int, spec: WinchSpec) -> ServoItems:
    """Drive the winch node's up coordinate (index ``vertical``: the Space's) by a drum under a motor force.

    The drum coordinate s is the paid-out length change (rope taken off the drum); the winch node's
    height follows it through an offset-free ``ObjectConnectorCoordinate`` (the connector).
    """
    drum = mbs.AddNode(eii.NodeGenericODE2(referenceCoordinates=[0.0], initialCoordinates=[0.0],
                                           initialCoordinates_t=[0.0], numberOfODE2Coordinates=1))
    mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=[drum], massMatrix=np.eye(1) * spec.drum_mass))
    drum_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=drum, coordinate=0))
    node_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=node, coordinate=vertical))
    connector = mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[drum_marker, node_marker], offset=0.0))
    load = mbs.AddLoad(eii.LoadCoordinate(markerNumber=drum_marker, load=0.0))
    return ServoItems(drum, load, servo_gains(spec), connector)


class ServoDrums:
    """The servo law of a model's drums, in both dimensions: once per step (Exudyn's pre-step) the motor force
    u = u_ff - K (integral e, e, e') [N], e = s - s_cmd, with the winch-end tension fed forward (u_ff = -T:
    the cable pulls rope off the drum)."""

    def __init__(self, mbs: exu.MainSystem, servos: list[ServoItems], initial_paid_out: np.ndarray):
        self.servos, self.initial = servos, initial_paid_out
        self.index = [mbs.GetNodeODE2Index(servo.drum_node) for servo in servos]
        self.integral = np.zeros(len(servos))
        self.time = 0.0

    def measured(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The paid-out lengths and rates the drums measure, (m,) each [m, m/s], from the state vectors."""
        return self.initial + q[self.index], v[self.index]

    def drive(self, mbs: exu.MainSystem, t: float, command, q: np.ndarray, v: np.ndarray, tensions) -> None:
        """Set each drum's motor force for the ``command`` at ``t`` [s]; ``tensions`` (m,) [N] of the winch elements."""
        dt, self.time = t - self.time, t
        for i, (servo, index) in enumerate(zip(self.servos, self.index)):
            error = q[index] - (command.paid_out[i] - self.initial[i])
            error_rate = v[index] - command.paid_out_rate[i]
            self.integral[i] += error * dt
            force = float(-tensions[i] - servo.gains @ np.array([self.integral[i], error, error_rate]))
            mbs.SetLoadParameter(servo.load, "load", force)


# --------------------------------------------------------------------------- slack rope at the winch

#: A tension-only winch element (element 0) may shorten to this fraction of its nominal
#: length while slack; rope that would shorten it further goes into the reservoir.
RESERVOIR_THRESHOLD = 0.75

#: Strain past its rest length to which hauling in a slack cable's surplus may take the winch element
#: (:func:`reservoir_split`): two widths of the tension law's switch band (:data:`cdpr_exu.physics.axial.TAUT_BAND`),
#: so that the element lands taut rather than on the law's kink, where Newton converges slowly.
TAUT_MARGIN = 2.0e-5


def reservoir_split(paid_out_change: float, node_offset: float, surplus: float, element_length: float,
                    rest_length: float, threshold: float = RESERVOIR_THRESHOLD) -> tuple[float, float]:
    """Split a winch command between moving the winch node and the slack rope at the drum.

    A slack cable's rope paid out while nothing pulls it away piles up at the drum; in the
    lumped model the winch node would instead run into the next node and collapse the first
    element. So the node never moves where its element would be shorter than ``threshold`` of
    its nominal length: the rest is kept as *surplus* at the drum, added to the first element's
    rest length. Hauling in a slack cable takes up the surplus first, but no more than the
    element's slack and :data:`TAUT_MARGIN` (more at once snaps the element taut within one
    step; exactly the slack leaves it on the law's kink, where Newton converges slowly); once
    the cable is taut again the surplus is rope of that taut element and hauling in moves the
    node (shrinking a taut element's rest length instead would make it lag the command by its
    Kelvin-Voigt time constant). Rope is conserved: ``node_offset + surplus == paid_out_change``.

    Parameters
    ----------
    paid_out_change : float [m]
        The command: paid-out length minus its initial value (positive: the node moves up).
    node_offset, surplus : float [m]
        The winch node's current offset up the winch line and the rope held at the drum (>= 0).
    element_length, rest_length : float [m]
        The first element's current length |p_1 - p_0| and nominal rest length (no surplus).
    threshold : float
        Shortest length of the first element, as a fraction of ``rest_length``.

    Returns the new ``(node_offset, surplus)`` [m].
    """
    wanted = paid_out_change - surplus  # where the node goes if the surplus stays
    slack = rest_length + surplus - element_length  # how much shorter than its rest length the element is
    if wanted > node_offset or slack <= 0.0:
        node = wanted
    else:  # the surplus goes first, but no more of it than the slack (and a margin): the rest moves the node
        node = min(node_offset, paid_out_change, wanted + slack + TAUT_MARGIN * rest_length)
    highest = node_offset + element_length - threshold * rest_length  # the first element at its shortest
    node = min(node, highest)
    return node, paid_out_change - node


@dataclass
class RopeReservoir:
    """The slack rope held at each winch drum, and the first elements it lengthens.

    Per cable (m,): ``first_elements`` the winch element's index in the tension-only arrays,
    ``nominal_rest_length``, ``axial_rigidity`` and ``damping_rigidity`` its l0, E A and d_n A
    [m, N, N s] (stiffness E A / l, damping d_n A / l for its current rest length l), and
    ``surplus``, ``node_offset``, ``max_surplus`` [m]. ``rest_length``, ``stiffness`` and
    ``damping`` are the arrays the force kernel reads (changed in place).
    """

    first_elements: np.ndarray
    nominal_rest_length: np.ndarray
    axial_rigidity: np.ndarray
    damping_rigidity: np.ndarray
    rest_length: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    surplus: np.ndarray
    node_offset: np.ndarray
    max_surplus: np.ndarray

    def update(self, paid_out_change: np.ndarray, element_lengths: np.ndarray) -> np.ndarray:
        """Split this step's commands (shape (m,) [m]); returns the winch nodes' offsets [m]."""
        for i, e in enumerate(self.first_elements):
            node, surplus = reservoir_split(float(paid_out_change[i]), float(self.node_offset[i]),
                                            float(self.surplus[i]), float(element_lengths[i]),
                                            float(self.nominal_rest_length[i]))
            self.node_offset[i], self.surplus[i] = node, surplus
            rest = self.nominal_rest_length[i] + surplus
            self.rest_length[e] = rest
            self.stiffness[e] = self.axial_rigidity[i] / rest
            self.damping[e] = self.damping_rigidity[i] / rest
            self.max_surplus[i] = max(self.max_surplus[i], surplus)
        return self.node_offset.copy()
