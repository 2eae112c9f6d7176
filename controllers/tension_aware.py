"""Tension-aware winch commands: sag and stretch compensation from the cables' statics, planar and spatial.

For each sample of the reference the controller solves the platform's kineto-static
equilibrium on elastic catenaries (:mod:`cdpr_exu.statics.statics`) or on the simulator's own
lumped chains (``statics="chain"``, :mod:`cdpr_exu.statics.chain_statics`: the polygon over the
pulley and the bending where the cable leaves it; 5 ms per pose against 3 ms); its unstrained
lengths are the command, tabulated on a coarse grid and interpolated by a cubic spline. What
differs by dimension is behind one interface (:data:`EQUILIBRIA`): planar, the rotation is the
one the balance imposes; spatial, the tensions nearest the previous sample's, from those at
rest (an over-constrained robot keeps its internal tension), and the spatial chain statics
steps the lengths by the change of the straight exit-to-anchor distances. ``dynamic`` adds the
inertial load -M a of the reference; ``chordal_correction`` (planar) corrects for the lumped
model's polygon of chords over the pulley, which needs up to 3 cm less cable than the arc with
the paper's elements (it compensates the simulator's discretisation, not a real cable);
``start``: :data:`controllers.base.STARTS` (the spatial catenary's default "relative" cancels
its 1e-5 m offset from the chains on IPAnema). Plain NumPy/SciPy.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.interpolate import CubicSpline

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.core.validation import shown
from cdpr_exu.space import PLANE, SPACE
from cdpr_exu.statics import chain_statics, statics
from cdpr_exu.statics.kinematics import anchor_points, ideal_paid_out, initial_cable_nodes

from .base import CommandStart, Measurement, WinchCommand
from .feedback import FilteredPositionPI
from .loop_design import DESIGNED


def chain_length(scene, anchors: np.ndarray) -> np.ndarray:
    """Paid-out length (m,) [m] of each straight, inextensible planar chain laid from ``anchors`` back over
    its pulley with exact chords (:func:`~cdpr_exu.statics.kinematics.initial_cable_nodes`)."""
    lengths = []
    for i, (cable, pulley) in enumerate(zip(scene.cables, scene.exits)):
        nodes = initial_cable_nodes(pulley.center, pulley.radius, pulley.side, anchors[i],
                                    cable.element_length, cable.n_elements)
        lengths.append(pulley.paid_out_length(cable.unstrained_length, nodes[0]))
    return np.asarray(lengths)


#: Cable models the equilibria can be solved with (module notes).
STATICS_MODELS = ("catenary", "chain")


class _PlanarEquilibria:
    """The planar robot's equilibria: the platform's rotation is the one its balance takes."""

    #: Today's defaults of the options left at None
    dynamic = False
    table_spacing = 2e-3
    starts = {"catenary": "absolute", "chain": "absolute"}
    from_rest = True

    @staticmethod
    def solver(controller, scene, initial_paid_out):
        """``solve(pose, acceleration) -> lengths`` [m] along the reference (the chain continued)."""
        platform = statics.catenary_platform(scene)
        chain = chain_statics.chain_robot(scene) if controller.statics == "chain" else None
        chordal = controller.chordal_correction and all(exit_.wraps for exit_ in scene.exits)
        state = {"previous": None}

        def solve(pose, acceleration):
            wrench = statics.inertial_wrench(platform, acceleration[:2], acceleration[2]) if controller.dynamic else None
            if chain is not None:
                equilibrium = _chain_equilibrium(chain, platform, pose, wrench, state["previous"])
                state["previous"] = equilibrium
                controller.equilibria.append(equilibrium)
                return equilibrium.paid_out
            equilibrium = statics.solve_inverse_statics(platform, pose[:2], external_wrench=wrench)
            controller.equilibria.append(equilibrium)
            lengths = equilibrium.unstrained_lengths
            if chordal:
                pose_eq = np.array([*pose[:2], equilibrium.rotation])
                anchors = anchor_points(pose_eq, np.asarray(scene.platform.anchors))
                lengths = lengths + (chain_length(scene, anchors) - ideal_paid_out(scene, pose_eq[None, :])[0][0])
            return lengths
        return solve


def _chain_equilibrium(chain, platform, pose, wrench, previous):
    """Planar chain statics at one reference pose, continued from the previous one when there is one."""
    if previous is not None:
        try:
            return chain_statics.solve_inverse_chain_statics(chain, pose[:2], external_wrench=wrench, guess=previous)
        except UnreachableError:
            pass  # start afresh from the catenary below
    start = statics.solve_inverse_statics(platform, pose[:2], external_wrench=wrench)
    return chain_statics.solve_inverse_chain_statics(chain, (*pose[:2], start.rotation), external_wrench=wrench,
                                                     tension_guess=[c.tension_at_anchor for c in start.cables])


class _SpatialEquilibria:
    """The spatial robot's equilibria: the tensions nearest the previous sample's."""

    #: Today's defaults of the options left at None
    dynamic = True
    table_spacing = 0.0
    starts = {"catenary": "relative", "chain": "absolute"}
    from_rest = False

    @staticmethod
    def _inertial(controller, mass, acceleration):
        """The d'Alembert wrench -M a (6,) of the reference's acceleration (angular left out)."""
        return np.concatenate([-mass * acceleration[:3] if controller.dynamic else np.zeros(3), np.zeros(3)])

    @staticmethod
    def solver(controller, scene, initial):
        """``solve(pose, acceleration) -> lengths`` [m] along the reference, the tensions continued."""
        if controller.chordal_correction:
            raise SceneError(f"chordal_correction corrects the planar pulley's polygon of chords; scene {scene.name!r} "
                             "is spatial (use statics='chain' for the simulator's own chains)")
        if initial is None:
            raise SceneError("the spatial tension-aware lengths start from the paid-out lengths: give initial_paid_out")
        initial = np.asarray(initial, dtype=float)
        kernel = _SpatialEquilibria._chain_solver if controller.statics == "chain" else _SpatialEquilibria._catenary_solver
        return kernel(controller, scene, initial)

    @staticmethod
    def _catenary_solver(controller, scene, initial):
        """pose, acceleration -> lengths [m] on elastic catenaries, the horizontal tensions continued."""
        platform = statics.catenary_platform(scene)
        rest = statics.solve_statics(platform, initial)
        state = {"tensions": np.array([c.catenary.horizontal_tension for c in rest.cables])}

        def solve(pose, acceleration):
            inertial = _SpatialEquilibria._inertial(controller, platform.mass, acceleration)
            inverse = statics.solve_inverse_statics(platform, pose, inertial, initial_guess=state["tensions"])
            state["tensions"] = inverse.horizontal_tensions
            controller.equilibria.append(inverse)
            return inverse.unstrained_lengths
        return solve

    @staticmethod
    def _chain_solver(controller, scene, initial):
        """pose, acceleration -> lengths [m] on the lumped chains, the anchor tensions continued: one Newton
        solve per held chain inside a Gauss-Newton on the lengths (the platform's balance)."""
        from cdpr_exu.core.geometry import rotation_from_vector

        platform = statics.catenary_platform(scene)
        robot = chain_statics.chain_robot(scene)
        wraps = [exit_.wraps for exit_ in scene.exits]  # over a swivel pulley: held below it, on its axis
        inverse_statics = chain_statics.InverseChainStatics(robot)
        catenary_rest = statics.solve_statics(platform, initial)
        started = chain_statics.robot_paid_out(robot, initial)
        rest = chain_statics.solve_chain_statics(started, *chain_statics.catenary_start(started, catenary_rest))
        # the straight distances change as the paid-out lengths: from each exit's fixed point (a swivel's inlet)
        exits = scene.exit_points
        anchors = np.array([c.anchor for c in robot.cables])
        state = {"tensions": rest.tensions_at_anchor, "horizontal": np.array([c.catenary.horizontal_tension
                                                                             for c in catenary_rest.cables]),
                 "previous": None}
        if any(wraps):
            # over swivel pulleys the first sample starts from the rest: the catenaries hang lower (no bending
            # over the disc: 22 mm on spatial-four-cable-swivel) and cannot start a chain up the axis
            state["previous"] = (replace(rest, paid_out=np.array(initial, dtype=float), iterations=0),
                                 np.linalg.norm(exits - rest.position - anchors @ rest.rotation.T, axis=1))

        def anchor_points_at(pose):
            rotation = np.eye(3) if robot.is_point_mass else rotation_from_vector(pose[3:6])
            return pose[:3] + anchors @ rotation.T

        def catenary_guess(pose, inertial):
            """Lengths and nodes of the catenary inverse at ``pose`` (a swivel's chain keeps its nodes)."""
            inverse = statics.solve_inverse_statics(platform, pose, inertial, initial_guess=state["horizontal"])
            state["horizontal"] = inverse.horizontal_tensions
            points = anchor_points_at(pose)
            nodes = []
            for i, (cable, chain, length, point) in enumerate(zip(platform.cables, robot.cables,
                                                                  inverse.unstrained_lengths, points)):
                if wraps[i]:
                    nodes.append(state["previous"][0].nodes[i])
                    continue
                shape, _ = statics.forward_cable(cable, length, point)
                nodes.append(shape.points(length - np.linspace(0.0, length, chain.n_elements + 1)))
            return inverse.unstrained_lengths, nodes

        def solve(pose, acceleration):
            inertial = _SpatialEquilibria._inertial(controller, robot.mass, acceleration)
            previous = state["previous"]
            angles = None
            if previous is None:
                lengths, nodes = catenary_guess(pose, inertial)
            else:  # the previous lengths, changed as the straight cables change
                chords = np.linalg.norm(exits - anchor_points_at(pose), axis=1)
                lengths = previous[0].paid_out + chords - previous[1]
                nodes, angles = previous[0].nodes, previous[0].swivel_angles
            try:
                inverse = inverse_statics.solve(pose, state["tensions"], lengths=lengths, nodes=nodes,
                                                external_wrench=inertial, swivel_angles=angles)
            except UnreachableError:
                if previous is None:
                    raise
                lengths, nodes = catenary_guess(pose, inertial)
                inverse = inverse_statics.solve(pose, state["tensions"], lengths=lengths, nodes=nodes,
                                                external_wrench=inertial, swivel_angles=angles)
            state["tensions"] = inverse.tensions_at_anchor
            state["previous"] = (inverse, np.linalg.norm(exits - anchor_points_at(pose), axis=1))
            controller.equilibria.append(inverse)
            return inverse.paid_out
        return solve


#: The equilibria of each space: ``solver`` and today's defaults.
EQUILIBRIA = {PLANE: _PlanarEquilibria, SPACE: _SpatialEquilibria}


class TensionAwareController:
    """Open-loop unstrained lengths from the equilibrium of each reference pose, planar or spatial.

    Options left at None take the space's defaults (:data:`EQUILIBRIA`); see the module notes.

    Parameters
    ----------
    table_period : float [s]
        Time grid of the equilibrium table (a planar reference from rest: zero rate at t = 0).
    table_spacing : float [m], optional
        Where the reference is slow, the period grows until it moves this far in one (at
        most 0.25 s); 0 keeps ``table_period``.
    start : {"absolute", "relative", "calibrated"}, optional
        A start given names the controller (``tension_aware_relative``...).

    Raises
    ------
    SceneError
        If an option is out of its range (naming it); at ``reset``, for one the scene's space
        has no physics for (``chordal_correction`` on a spatial scene).
    """

    uses_pose = False
    uses_tension = False

    def __init__(self, dynamic: bool | None = None, table_period: float = 0.02, chordal_correction: bool = False,
                 statics: str = "catenary", table_spacing: float | None = None, start: str | None = None):
        if not np.isfinite(table_period) or table_period <= 0:
            raise SceneError(f"table_period must be positive, got {shown(table_period)}")
        if table_spacing is not None and (not np.isfinite(table_spacing) or table_spacing < 0):
            raise SceneError(f"table_spacing must be zero or positive, got {shown(table_spacing)}")
        if statics not in STATICS_MODELS:
            raise SceneError(f"statics must be one of {STATICS_MODELS}, got {shown(statics)}")
        if statics == "chain" and chordal_correction:
            raise SceneError("chordal_correction is for statics='catenary': the chain statics has the polygon already")
        self._options = {"dynamic": dynamic, "table_spacing": table_spacing, "start": start}
        self.start = CommandStart("absolute" if start is None else start)
        self.uses_pose = self.uses_pose or self.start.uses_pose
        self.dynamic = bool(dynamic)
        self.chordal_correction = bool(chordal_correction)
        self.statics = statics
        self.table_period = float(table_period)
        self.table_spacing = table_spacing
        self.name = ("tension_aware" + ("_chain" if statics == "chain" else "") + ("_dynamic" if dynamic else "")
                     + ("_chordal" if self.chordal_correction else "") + ("" if start is None else f"_{start}"))
        self._spline = None
        self.equilibria: list = []

    def _resolve(self, scene):
        """The equilibria of ``scene``'s space, with the options left at None set to its defaults."""
        kernel = EQUILIBRIA[scene.space]
        dynamic, spacing, start = (self._options[k] for k in ("dynamic", "table_spacing", "start"))
        self.dynamic = kernel.dynamic if dynamic is None else bool(dynamic)
        self.table_spacing = float(kernel.table_spacing if spacing is None else spacing)
        if start is None:
            self.start = CommandStart(kernel.starts[self.statics])
        return kernel

    def compensated_lengths(self, scene, times: np.ndarray, initial_paid_out=None) -> np.ndarray:
        """Unstrained paid-out lengths (N, m) [m] that hold the platform on the reference at ``times`` (the
        spatial ones from the rest with ``initial_paid_out``); UnreachableError naming the time of a pose
        with no equilibrium."""
        solve = self._resolve(scene).solver(self, scene, initial_paid_out)
        poses = np.atleast_2d(scene.trajectory.pose(times))
        accelerations = np.atleast_2d(scene.trajectory.acceleration(times))
        size = scene.space.position_size
        lengths = np.zeros((len(times), scene.n_cables))
        self.equilibria = []
        for k, (t, pose, acceleration) in enumerate(zip(times, poses, accelerations)):
            try:
                lengths[k] = solve(pose, acceleration)
            except UnreachableError as err:
                raise UnreachableError(f"the reference at t = {t:.3f} s, position {np.round(pose[:size], 4).tolist()} "
                                       f"m, cannot be held by the cables: {err}") from None
        return lengths

    def _period(self, scene) -> float:
        """Table period [s]: ``table_period``, longer where the reference moves under ``table_spacing``."""
        if self.table_spacing == 0:
            return self.table_period
        times = np.linspace(0.0, scene.solver.end_time, 400)
        velocity = np.atleast_2d(scene.trajectory.velocity(times))[:, :scene.space.position_size]
        speed = float(np.linalg.norm(velocity, axis=1).max())
        if speed == 0:
            return self.table_period
        return max(self.table_period, min(self.table_spacing / speed, 0.25))

    def reset(self, scene, initial_paid_out) -> None:
        """Solve the equilibria along the reference and tabulate the commands."""
        kernel = self._resolve(scene)
        end = scene.solver.end_time
        count = max(int(np.ceil(end / self._period(scene))), 3) + 1
        times = np.linspace(0.0, end, count)
        lengths = self.compensated_lengths(scene, times, initial_paid_out)
        commands = self.start.commands(scene, lengths, initial_paid_out)
        at_rest = kernel.from_rest and not (np.any(scene.trajectory.velocity(0.0))
                                            or np.any(scene.trajectory.acceleration(0.0)))
        start = (1, np.zeros(scene.n_cables)) if at_rest else "not-a-knot"  # from rest: zero rate at t = 0
        self._spline = CubicSpline(times, commands, axis=0, bc_type=(start, "not-a-knot"))
        self._rate = self._spline.derivative()

    def feed_forward(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Tabulated command and its rate at time t [m, m/s]."""
        if self._spline is None:
            raise RuntimeError(f"{type(self).__name__}.reset(scene, initial_paid_out) must be called first")
        return np.asarray(self._spline(t), dtype=float), np.asarray(self._rate(t), dtype=float)

    def command(self, measurement: Measurement) -> WinchCommand:
        lengths, rates = self.feed_forward(measurement.time)
        return WinchCommand(lengths - self.start.offset(measurement), rates)


class ClosedLoopTensionAwareController(TensionAwareController):
    """Tension-aware feed-forward plus the PI feedback of :class:`controllers.feedback.FilteredPositionPI`
    (its options; the others as :class:`TensionAwareController`)."""

    uses_pose = True

    def __init__(self, proportional_gain: float = DESIGNED.proportional_gain,
                 integral_gain: float = DESIGNED.integral_gain, start_time: float = 0.5,
                 cutoff: float = DESIGNED.cutoff, rotation: bool = False, margin_check: str = "off", **kwargs):
        super().__init__(**kwargs)
        self.feedback = FilteredPositionPI(proportional_gain, integral_gain, cutoff, start_time, rotation, margin_check)
        self.name = "closed_loop_" + self.name

    def reset(self, scene, initial_paid_out) -> None:
        super().reset(scene, initial_paid_out)
        self.feedback.reset(scene)

    def command(self, measurement: Measurement) -> WinchCommand:
        if measurement.platform_pose is None:
            raise SceneError(f"{self.name} needs the measured platform pose")
        lengths, rates = self.feed_forward(measurement.time)
        return WinchCommand(lengths - self.start.offset(measurement) + self.feedback.correction(measurement), rates)
