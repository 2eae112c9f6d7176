"""Tension-aware winch commands: sag and stretch compensation from catenary statics.

For each reference position the platform's kineto-static equilibrium on elastic
catenary cables (:func:`cdpr_exu.statics.statics.solve_inverse_statics`) gives the cable
tensions, the rotation the platform takes, and the unstrained lengths (wrap on the
pulley included) that put its centre on the reference. Those lengths are the command.
Options:

* ``dynamic=True`` adds the platform's inertial load -M a from the reference
  acceleration to the equilibrium (dynamic feed-forward; the cables' own inertia is
  neglected);
* ``chordal_correction=True`` accounts for the lumped model's own geometry over the
  pulley: its straight elements wrap the pulley as a polygon of chords, which needs
  less cable than the arc (up to 3 cm with the paper's 0.25 m elements on a 0.25 m
  pulley), by an amount that depends on where the nodes sit. The command is then the
  length of the straight discretised chain (the chord walk of
  :func:`cdpr_exu.statics.kinematics.initial_cable_nodes`) plus the catenary's sag and stretch
  correction (catenary length minus ideal length). A real cable has no such polygon:
  this option compensates the simulator's discretisation, and says so in its name;
* ``statics="chain"`` solves each equilibrium on the simulator's own lumped cables
  instead of continuous catenaries (:mod:`cdpr_exu.statics.chain_statics`): chains of straight
  elements with the nodes' weight, exact-angle bending springs and the penalty contact
  of the nodes on the pulleys. It has the polygon over the pulley, where the nodes sit
  on it, and the bending of the cable where it leaves the pulley, which the continuous
  catenary lacks; it costs about 5 ms per tabulated pose (the catenary: about 3 ms).
  As for ``chordal_correction``, what it adds over the catenary is the simulator's
  discretisation;
* :class:`ClosedLoopTensionAwareController` adds a PI correction from the measured
  platform position, mapped onto the cables by the ideal inverse-kinematics Jacobian
  (:class:`controllers.feedback.FilteredPositionPI`).

The commands are tabulated once per run on a coarse time grid and interpolated with a
cubic spline, so they and their rates are continuous. The cables start straight (the
paper's initial state), with a paid-out length that differs from the compensated one:
the run blends every controller's command from the initial length into its own
(:class:`controllers.base.SmoothStart`) instead of jumping.

Plain NumPy/SciPy; no Exudyn.
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from cdpr_exu.statics import chain_statics
from cdpr_exu.statics import statics
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.statics.kinematics import anchor_points, ideal_paid_out, initial_cable_nodes
from cdpr_exu.core.validation import shown

from .base import CommandStart, Measurement, WinchCommand
from .feedback import FilteredPositionPI


def chain_length(scene, anchors: np.ndarray) -> np.ndarray:
    """Paid-out length of each straight, inextensible lumped chain reaching ``anchors``, shape (m,) [m].

    The chain of n elements of length l0/n is laid from the anchor back over the pulley
    with exact chords (:func:`~cdpr_exu.statics.kinematics.initial_cable_nodes`); what is not
    hanging below the hang point is paid out.
    """
    lengths = []
    for i, (cable, pulley) in enumerate(zip(scene.cables, scene.exits)):
        nodes = initial_cable_nodes(pulley.center, pulley.radius, pulley.side, anchors[i],
                                    cable.element_length, cable.n_elements)
        lengths.append(pulley.paid_out_length(cable.unstrained_length, nodes[0]))
    return np.asarray(lengths)


#: Cable models the equilibria can be solved with: "catenary" (continuous elastic
#: catenaries, :mod:`cdpr_exu.statics.statics`) or "chain" (the simulator's own lumped chains,
#: :mod:`cdpr_exu.statics.chain_statics`).
STATICS_MODELS = ("catenary", "chain")


class TensionAwareController:
    """Open-loop unstrained lengths from the elastic-catenary equilibrium of each reference pose.

    Parameters
    ----------
    dynamic : bool
        Add the inertial load -M a of the reference acceleration (dynamic feed-forward).
    table_period : float [s]
        Time grid of the equilibrium table (interpolated by a cubic spline; where the
        reference starts from rest, the spline starts with zero rate).
    chordal_correction : bool
        Correct for the lumped model's polygon over the pulley (see the module notes).
    statics : {"catenary", "chain"}
        The cable model of the equilibria (see the module notes).
    table_spacing : float [m]
        Where the reference is slow, the table period grows until the reference moves
        this far in one period (at most 0.25 s); 0 keeps ``table_period``.
    start : {"absolute", "relative", "calibrated"}
        Where the commands start from (:data:`controllers.base.STARTS`); "absolute", the default, is today's.
    """

    uses_pose = False
    uses_tension = False

    def __init__(self, dynamic: bool = False, table_period: float = 0.02,
                 chordal_correction: bool = False, statics: str = "catenary", table_spacing: float = 2e-3,
                 start: str = "absolute"):
        if not np.isfinite(table_period) or table_period <= 0:
            raise SceneError(f"table_period must be positive, got {shown(table_period)}")
        if not np.isfinite(table_spacing) or table_spacing < 0:
            raise SceneError(f"table_spacing must be zero or positive, got {shown(table_spacing)}")
        if statics not in STATICS_MODELS:
            raise SceneError(f"statics must be one of {STATICS_MODELS}, got {shown(statics)}")
        if statics == "chain" and chordal_correction:
            raise SceneError("chordal_correction is for statics='catenary': the chain statics has the polygon already")
        self.start = CommandStart(start)
        self.uses_pose = self.uses_pose or self.start.uses_pose
        self.dynamic = bool(dynamic)
        self.chordal_correction = bool(chordal_correction)
        self.statics = statics
        self.table_period = float(table_period)
        self.table_spacing = float(table_spacing)
        self.name = ("tension_aware" + ("_chain" if statics == "chain" else "") + ("_dynamic" if self.dynamic else "")
                     + ("_chordal" if self.chordal_correction else "") + ("" if start == "absolute" else f"_{start}"))
        self._spline = None
        self.equilibria: list = []

    def compensated_lengths(self, scene, times: np.ndarray) -> np.ndarray:
        """Unstrained paid-out lengths that hold the platform on the reference, shape (N, m) [m].

        Raises
        ------
        UnreachableError
            If a reference pose needs a cable to push or has no equilibrium; the message
            names the time.
        """
        platform = statics.catenary_platform(scene)
        chain = chain_statics.chain_robot(scene) if self.statics == "chain" else None
        poses = scene.trajectory.pose(times)
        accelerations = scene.trajectory.acceleration(times)
        lengths = np.zeros((len(times), scene.n_cables))
        self.equilibria = []
        equilibrium = None
        for k, (t, pose, acceleration) in enumerate(zip(times, poses, accelerations)):
            wrench = statics.inertial_wrench(platform, acceleration[:2], acceleration[2]) if self.dynamic else None
            try:
                if chain is not None:
                    equilibrium = self._chain_equilibrium(chain, platform, pose, wrench, equilibrium)
                else:
                    equilibrium = statics.solve_inverse_statics(platform, pose[:2], external_wrench=wrench)
            except UnreachableError as err:
                raise UnreachableError(f"the reference at t = {t:.3f} s, position {np.round(pose[:2], 4).tolist()} m, "
                                       f"cannot be held by the cables: {err}") from None
            self.equilibria.append(equilibrium)
            if chain is not None:
                lengths[k] = equilibrium.paid_out
                continue
            lengths[k] = equilibrium.unstrained_lengths
            if self.chordal_correction and all(exit_.wraps for exit_ in scene.exits):
                pose_eq = np.array([*pose[:2], equilibrium.rotation])
                anchors = anchor_points(pose_eq, np.asarray(scene.platform.anchors))
                lengths[k] += chain_length(scene, anchors) - ideal_paid_out(scene, pose_eq[None, :])[0][0]
        return lengths

    @staticmethod
    def _chain_equilibrium(chain, platform, pose, wrench, previous):
        """Chain statics at one reference pose, continued from the previous one when there is one."""
        if previous is not None:
            try:
                return chain_statics.solve_inverse_chain_statics(chain, pose[:2], external_wrench=wrench, guess=previous)
            except UnreachableError:
                pass  # start afresh from the catenary below
        start = statics.solve_inverse_statics(platform, pose[:2], external_wrench=wrench)
        return chain_statics.solve_inverse_chain_statics(chain, (*pose[:2], start.rotation), external_wrench=wrench,
                                                         tension_guess=[c.tension_at_anchor for c in start.cables])

    def _period(self, scene) -> float:
        """Table period [s]: ``table_period``, or longer where the reference moves less
        than ``table_spacing`` in it (slow references need fewer equilibria)."""
        times = np.linspace(0.0, scene.solver.end_time, 400)
        speed = float(np.linalg.norm(scene.trajectory.velocity(times)[:, :2], axis=1).max())
        if self.table_spacing == 0 or speed == 0:
            return self.table_period
        return max(self.table_period, min(self.table_spacing / speed, 0.25))

    def reset(self, scene, initial_paid_out) -> None:
        """Solve the equilibria along the reference and tabulate the commands."""
        end = scene.solver.end_time
        count = max(int(np.ceil(end / self._period(scene))), 3) + 1
        times = np.linspace(0.0, end, count)
        lengths = self.compensated_lengths(scene, times)
        # start "absolute": the compensated length itself; the run takes up its offset from the
        # initial (straight-cable) paid-out length (controllers.base.SmoothStart)
        commands = self.start.commands(scene, lengths, initial_paid_out)
        at_rest = not (np.any(scene.trajectory.velocity(0.0)) or np.any(scene.trajectory.acceleration(0.0)))
        start = (1, np.zeros(scene.n_cables)) if at_rest else "not-a-knot"  # from rest: zero rate at t = 0
        self._spline = CubicSpline(times, commands, axis=0, bc_type=(start, "not-a-knot"))
        self._rate = self._spline.derivative()

    def feed_forward(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Tabulated command and its rate at time t [m, m/s]."""
        if self._spline is None:
            raise RuntimeError(f"{type(self).__name__}.reset(scene, initial_paid_out) must be called first")
        return np.asarray(self._spline(t)), np.asarray(self._rate(t))

    def command(self, measurement: Measurement) -> WinchCommand:
        lengths, rates = self.feed_forward(measurement.time)
        return WinchCommand(lengths - self.start.offset(measurement), rates)


class ClosedLoopTensionAwareController(TensionAwareController):
    """Tension-aware feed-forward plus PI feedback on the low-pass filtered platform position error.

    The feedback is :class:`controllers.feedback.FilteredPositionPI` (see there why the
    error is filtered and how a retried step is handled): the position error e = r_ref - r
    (x, z), filtered by a second-order Butterworth low-pass (cut-off ``cutoff`` [Hz]),
    turned into length corrections dlambda = U (k_p e_f + k_i integral(e_f) dt) with the
    ideal inverse-kinematics Jacobian U, fading in over ``start_time``.

    Parameters
    ----------
    proportional_gain : float [-]
    integral_gain : float [1/s]
    cutoff : float [Hz]
        Cut-off frequency of the error filter (> 0).
    start_time : float [s]
        The feedback (and its integral) fades in over this time from t = 0.
    dynamic, table_period, ...
        As :class:`TensionAwareController`.
    """

    uses_pose = True

    #: Damping ratio of the second-order error filter (Butterworth).
    FILTER_DAMPING = FilteredPositionPI.FILTER_DAMPING

    def __init__(self, proportional_gain: float = 2.0, integral_gain: float = 40.0, start_time: float = 0.5,
                 cutoff: float = 5.0, **kwargs):
        super().__init__(**kwargs)
        self.feedback = FilteredPositionPI(proportional_gain, integral_gain, cutoff, start_time)
        self.start_time = self.feedback.start_time
        self.cutoff = self.feedback.cutoff
        self.proportional_gain = self.feedback.proportional_gain
        self.integral_gain = self.feedback.integral_gain
        self.name = ("closed_loop_" + self.name)

    def reset(self, scene, initial_paid_out) -> None:
        super().reset(scene, initial_paid_out)
        self._scene = scene
        self.feedback.reset(scene)

    @property
    def _integral(self) -> np.ndarray:
        """Integral of the filtered position error at the last call [m s], shape (2,)."""
        return self.feedback.integral

    def _jacobian(self, pose: np.ndarray) -> np.ndarray:
        """d(lambda)/d(position) of the ideal cables at ``pose``, shape (m, 2) (:meth:`FilteredPositionPI.jacobian`)."""
        return self.feedback.jacobian(pose)

    def command(self, measurement: Measurement) -> WinchCommand:
        if measurement.platform_pose is None:
            raise SceneError(f"{self.name} needs the measured platform pose")
        lengths, rates = self.feed_forward(measurement.time)
        return WinchCommand(lengths - self.start.offset(measurement) + self.feedback.correction(measurement), rates)
