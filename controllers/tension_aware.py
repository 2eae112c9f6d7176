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
  platform position, mapped onto the cables by the ideal inverse-kinematics Jacobian.

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
from cdpr_exu.statics.kinematics import anchor_points, cable_unit_vectors, initial_cable_nodes, pulley_arrays

from .base import Measurement, WinchCommand
from .ideal_ik import ideal_paid_out


def suspended_platform(scene) -> statics.SuspendedPlatform:
    """The catenary-statics model of a scene's robot (pulleys or fixed exits).

    Parameters
    ----------
    scene : cdpr_exu.scenes.scene.Scene

    Returns
    -------
    statics.SuspendedPlatform
        Cable weight per length rho0 g [N/m], EA [N], anchors, pulleys, platform mass.
    """
    cables = []
    for cable, pulley, anchor in zip(scene.cables, scene.exits, scene.platform.anchors):
        weight = cable.linear_density * scene.gravity if (scene.effects.cable_mass and scene.effects.gravity) else 0.0
        cables.append(statics.SuspendedCable(weight, cable.axial_rigidity, anchor=anchor, pulley=pulley))
    gravity = scene.gravity if scene.effects.gravity else 0.0
    return statics.SuspendedPlatform(tuple(cables), scene.platform.mass, gravity, scene.platform.inertia)


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


def _smoothstep(s: np.ndarray) -> np.ndarray:
    """Quintic ramp from 0 to 1 on s in [0, 1] with zero first and second derivatives."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10.0 - 15.0 * s + 6.0 * s**2)


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
    """

    uses_pose = False
    uses_tension = False

    def __init__(self, dynamic: bool = False, table_period: float = 0.02,
                 chordal_correction: bool = False, statics: str = "catenary", table_spacing: float = 2e-3):
        if not np.isfinite(table_period) or table_period <= 0:
            raise SceneError(f"table_period must be positive, got {table_period!r}")
        if not np.isfinite(table_spacing) or table_spacing < 0:
            raise SceneError(f"table_spacing must be zero or positive, got {table_spacing!r}")
        if statics not in STATICS_MODELS:
            raise SceneError(f"statics must be one of {STATICS_MODELS}, got {statics!r}")
        if statics == "chain" and chordal_correction:
            raise SceneError("chordal_correction is for statics='catenary': the chain statics has the polygon already")
        self.dynamic = bool(dynamic)
        self.chordal_correction = bool(chordal_correction)
        self.statics = statics
        self.table_period = float(table_period)
        self.table_spacing = float(table_spacing)
        self.name = ("tension_aware" + ("_chain" if statics == "chain" else "") + ("_dynamic" if self.dynamic else "")
                     + ("_chordal" if self.chordal_correction else ""))
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
        platform = suspended_platform(scene)
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
            if self.chordal_correction and scene.cable_exit == "pulley":
                pose_eq = np.array([*pose[:2], equilibrium.rotation])
                anchors = anchor_points(pose_eq, np.asarray(scene.platform.anchors))
                lengths[k] += chain_length(scene, anchors) - ideal_paid_out(scene, pose_eq[None, :])[0][0]
        return lengths

    @staticmethod
    def _chain_equilibrium(chain, platform, pose, wrench, previous):
        """Chain statics at one reference pose, continued from the previous one when there is one."""
        if previous is not None:
            try:
                return chain_statics.solve_chain_statics(chain, pose[:2], external_wrench=wrench, guess=previous)
            except UnreachableError:
                pass  # start afresh from the catenary below
        start = statics.solve_inverse_statics(platform, pose[:2], external_wrench=wrench)
        return chain_statics.solve_chain_statics(chain, pose[:2], start.rotation, external_wrench=wrench,
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
        # The command is the compensated length itself; the run takes up its offset from
        # the initial (straight-cable) paid-out length (controllers.base.SmoothStart).
        commands = lengths
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
        return WinchCommand(lengths, rates)


class ClosedLoopTensionAwareController(TensionAwareController):
    """Tension-aware feed-forward plus PI feedback on the low-pass filtered platform position error.

    The position error e = r_ref - r (x, z) passes a second-order low-pass filter
    (Butterworth, cut-off ``cutoff`` [Hz]) and is turned into length corrections with the
    ideal inverse-kinematics Jacobian U (rows: unit vectors from each pulley's tangent
    point to its anchor): a length change U d moves the platform by about d. The
    correction is dlambda = U (k_p e_f + k_i integral(e_f) dt), e_f the filtered error,
    with the integral and the feedback fading in over ``start_time``.

    Why the filter: with tension-only cables, the unfiltered loop (k_p = 2) passed the
    platform's jolts straight into the winch command (command accelerations up to
    1300 m/s^2 measured, against 5 m/s^2 open loop); a winch element that then went
    slack snapped taut and the run diverged (0.9 s into paper-circle-mismatch). The filter
    keeps the command smooth above a few hertz, where the measured position response
    has no usable phase. (Velocity feedback was tried and dropped: it feeds the
    start-up jolt into the winch command and the run diverges.)

    The filter and the integral are integrated from one call to the next; a call at or
    before an earlier one (the solver retrying a step with a smaller size) restarts from
    the state the controller had at the last earlier time, so a retried step is not
    counted twice.

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
    FILTER_DAMPING = np.sqrt(0.5)

    def __init__(self, proportional_gain: float = 2.0, integral_gain: float = 40.0, start_time: float = 0.5,
                 cutoff: float = 5.0, **kwargs):
        super().__init__(**kwargs)
        if not np.isfinite(start_time) or start_time < 0:
            raise SceneError(f"start_time must be zero or positive, got {start_time!r}")
        if not np.isfinite(cutoff) or cutoff <= 0:
            raise SceneError(f"cutoff must be positive [Hz], got {cutoff!r}")
        self.start_time = float(start_time)
        self.cutoff = float(cutoff)
        for name, value in (("proportional_gain", proportional_gain), ("integral_gain", integral_gain)):
            if not np.isfinite(value) or value < 0:
                raise SceneError(f"{name} must be zero or positive, got {value!r}")
        self.proportional_gain = float(proportional_gain)
        self.integral_gain = float(integral_gain)
        self.name = ("closed_loop_" + self.name)

    def reset(self, scene, initial_paid_out) -> None:
        super().reset(scene, initial_paid_out)
        self._scene = scene
        # (time, filtered error, its rate, integral of the filtered error): one entry per call.
        self._history = [(0.0, np.zeros(2), np.zeros(2), np.zeros(2))]

    @property
    def _integral(self) -> np.ndarray:
        """Integral of the filtered position error at the last call [m s], shape (2,)."""
        return self._history[-1][3]

    def _jacobian(self, pose: np.ndarray) -> np.ndarray:
        """d(lambda)/d(position) of the ideal cables at ``pose``, shape (m, 2).

        Moving an anchor by d changes the ideal length by u . d, u the unit vector
        from the cable's exit point to the anchor (with the rotation held).
        """
        scene = self._scene
        anchors = np.asarray(scene.platform.anchors)
        return -cable_unit_vectors(pose, anchors, *pulley_arrays(scene.exits))

    def _advance(self, time: float, error: np.ndarray, weight: float):
        """The filter and integral state at ``time`` [s] from the last earlier call, and stored."""
        history = self._history
        while len(history) > 1 and history[-1][0] >= time:
            history.pop()  # a retried step: start again from the last earlier state
        last, filtered, rate, integral = history[-1]
        dt = time - last
        if dt <= 0:
            return filtered, integral
        omega = 2.0 * np.pi * self.cutoff
        # Semi-implicit Euler on e_f'' = omega^2 (e - e_f) - 2 zeta omega e_f', substeps of 0.2 / omega.
        substeps = max(1, int(np.ceil(dt * omega / 0.2)))
        h = dt / substeps
        filtered, rate = filtered.copy(), rate.copy()
        for _ in range(substeps):
            rate += h * (omega**2 * (error - filtered) - 2.0 * self.FILTER_DAMPING * omega * rate)
            filtered += h * rate
        integral = integral + filtered * dt * weight
        history.append((time, filtered, rate, integral))
        if len(history) > 64:  # retries reach back one step: a short history is enough
            del history[:-16]
        return filtered, integral

    def command(self, measurement: Measurement) -> WinchCommand:
        if measurement.platform_pose is None:
            raise SceneError(f"{self.name} needs the measured platform pose")
        lengths, rates = self.feed_forward(measurement.time)
        reference = self._scene.trajectory.pose(measurement.time)
        error = reference[:2] - measurement.platform_pose[:2]
        # The integral and the feedback fade in with the start-up blend (weight 0 at t = 0,
        # 1 from start_time on): switched on at once, the winch speed jumps and the axially
        # over-damped winch element pushes (-62 N measured at the switch with spring cables).
        weight = float(_smoothstep(np.array(measurement.time / self.start_time))) if self.start_time > 0 else 1.0
        filtered, integral = self._advance(measurement.time, error, weight)
        feedback = weight * (self.proportional_gain * filtered + self.integral_gain * integral)
        correction = self._jacobian(reference) @ feedback
        return WinchCommand(lengths + correction, rates)
