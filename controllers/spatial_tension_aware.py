"""Tension-aware joint-space control of spatial robots: sag and stretch from the cables' statics.

At samples of the reference (every :data:`SAMPLE_PERIOD` s) the controller finds the
unstrained lengths that hold the platform at the reference pose, with the reference's
acceleration as a d'Alembert force (the platform's, -M a; the cables' inertia and the
platform's angular acceleration are left out), and the tensions nearest the previous
sample's, starting from the tensions the robot has at rest with the lengths it starts
with. An over-constrained robot so keeps the internal tension it started with. The
lengths are interpolated by a cubic spline (its derivative is the rate). Open loop: it
reads neither pose nor tension.

Two cable models (``statics``), as the planar :class:`controllers.tension_aware.TensionAwareController`:

* ``"catenary"``: continuous elastic catenaries without bending
  (:func:`cdpr_exu.statics.statics.solve_inverse_statics`, the horizontal
  tensions kept near the previous sample's); the command is the initial paid-out length
  plus the change of these lengths, which cancels at the start the offset between the
  catenary and the simulator's chains (1e-5 m on IPAnema);
* ``"chain"``: the simulator's own lumped cables, n straight elements with the nodes'
  weight and the exact-angle bending (:func:`cdpr_exu.statics.chain_statics.
  solve_inverse_chain_statics`, the tensions at the anchors kept near the previous
  sample's). With the pose given, each chain hangs between two fixed points, so the cables
  decouple and only the platform's balance (six equations) ties their m lengths together:
  one small Newton solve per cable inside a Gauss-Newton on the lengths, started from the
  previous sample's lengths plus the change of the straight exit-to-anchor distance (the
  first sample from the catenary inverse). What it adds over the catenary is the
  simulator's discretisation (chords for arcs, lumped weights) and the bending. The
  command is these lengths themselves, as the planar chain version's: the run blends
  the offset from the paid-out lengths in over its start
  (:class:`controllers.base.SmoothStart`), so the platform also leaves where the
  initial lengths hold it (20 um off IPAnema's reference) for the reference. Over a
  swivel pulley the held chain runs from its winch end up the axis and over the disc,
  psi solved with it, and a length is paid out as the run's swivel winch pays it out
  (the elements kept, the winch end moved up the axis); the straight distance is then
  the inlet's, and the first sample starts from the rest the robot starts in (the
  catenaries, without the bending over the disc, hang 22 mm lower on
  spatial-four-cable-swivel, and their nodes do not run over a disc).

Units SI.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.interpolate import CubicSpline

from cdpr_exu.core.validation import shown

from .base import CommandStart, Measurement, WinchCommand

#: Spacing of the statics samples along the reference [s].
SAMPLE_PERIOD = 0.02

#: Cable models the equilibria can be solved with (see the module notes).
STATICS_MODELS = ("catenary", "chain")


class SpatialTensionAwareController:
    """Lengths of the cables that hold the reference pose (spatial scenes).

    Parameters
    ----------
    sample_period : float [s]
        Spacing of the statics samples (a cubic spline between them).
    statics : {"catenary", "chain"}
        The cable model of the equilibria (see the module notes).
    start : {"absolute", "relative", "calibrated"}, optional
        Where the commands start from (:data:`controllers.base.STARTS`). Default: today's, "relative" for
        the catenary and "absolute" for the chain.
    """

    uses_pose = False
    uses_tension = False

    def __init__(self, sample_period: float = SAMPLE_PERIOD, statics: str = "catenary",
                 start: str | None = None) -> None:
        from cdpr_exu.core.errors import SceneError

        if not np.isfinite(sample_period) or sample_period <= 0:
            raise SceneError(f"sample_period must be positive [s], got {shown(sample_period)}")
        if statics not in STATICS_MODELS:
            raise SceneError(f"statics must be one of {STATICS_MODELS}, got {shown(statics)}")
        self.sample_period = float(sample_period)
        self.statics = statics
        default = "absolute" if statics == "chain" else "relative"
        self.start = CommandStart(default if start is None else start)
        self.uses_pose = self.start.uses_pose
        self.name = ("tension_aware" + ("_chain" if statics == "chain" else "")
                     + ("" if self.start.start == default else f"_{self.start.start}"))
        self._spline = None
        self.inverses: list = []

    def reset(self, scene, initial_paid_out) -> None:
        """Solve the inverse statics along ``scene.trajectory`` and tabulate the commands.

        Raises
        ------
        UnreachableError
            If a sampled reference pose cannot be held by cables that pull (naming the time).
        SceneError
            With ``statics="chain"``, for a scene the chain statics do not model (a bending model other
            than the exact angle).
        """
        from cdpr_exu.core.errors import UnreachableError

        initial = np.asarray(initial_paid_out, dtype=float)
        end = scene.solver.end_time
        times = np.linspace(0.0, end, max(int(np.ceil(end / self.sample_period)), 3) + 1)
        poses = np.atleast_2d(scene.trajectory.pose(times))
        accelerations = np.atleast_2d(scene.trajectory.acceleration(times))
        solve = self._chain_solver(scene, initial) if self.statics == "chain" else self._catenary_solver(scene, initial)
        lengths = np.empty((len(times), len(initial)))
        self.inverses = []
        for k, (t, pose, acceleration) in enumerate(zip(times, poses, accelerations)):
            try:
                lengths[k] = solve(pose, acceleration)
            except UnreachableError as err:
                raise UnreachableError(f"the reference at t = {t:.3f} s: {err}") from None
        # catenary ("relative"): the change of the lengths from the paid-out ones, which cancels the catenary's
        # offset from the simulator's chains at the start; chain ("absolute"): the lengths themselves (the run
        # blends the offset from the paid-out lengths in, SmoothStart), as the planar chain version
        commands = self.start.commands(scene, lengths, initial)
        self._spline = CubicSpline(times, commands, axis=0)
        self._rate = self._spline.derivative()

    def _catenary_solver(self, scene, initial):
        """pose, acceleration -> lengths [m] on elastic catenaries, the horizontal tensions continued."""
        from cdpr_exu.statics.statics import catenary_platform, solve_inverse_statics, solve_statics

        platform = catenary_platform(scene)
        rest = solve_statics(platform, initial)
        state = {"tensions": np.array([c.catenary.horizontal_tension for c in rest.cables])}

        def solve(pose, acceleration):
            inertial = np.concatenate([-platform.mass * acceleration[:3], np.zeros(3)])
            inverse = solve_inverse_statics(platform, pose, inertial, initial_guess=state["tensions"])
            state["tensions"] = inverse.horizontal_tensions
            self.inverses.append(inverse)
            return inverse.unstrained_lengths
        return solve

    def _chain_solver(self, scene, initial):
        """pose, acceleration -> lengths [m] on the lumped chains, the anchor tensions continued."""
        from cdpr_exu.core.errors import UnreachableError
        from cdpr_exu.statics.statics import catenary_platform, forward_cable, solve_inverse_statics, solve_statics
        from cdpr_exu.statics.chain_statics import (InverseChainStatics, catenary_start, chain_robot, robot_paid_out,
                                                    solve_chain_statics)
        from cdpr_exu.core.geometry import rotation_from_vector

        platform = catenary_platform(scene)
        robot = chain_robot(scene)
        over_swivel = [cable.pulley is not None for cable in robot.cables]
        inverse_statics = InverseChainStatics(robot)
        catenary_rest = solve_statics(platform, initial)
        started = robot_paid_out(robot, initial)
        rest = solve_chain_statics(started, *catenary_start(started, catenary_rest))
        # the straight distances change as the paid-out lengths: from the exit point, or the swivel pulley's inlet
        exits = np.array([cable.pulley.inlet_array if swivel else cable.exit_point
                          for cable, swivel in zip(robot.cables, over_swivel)])
        anchors = np.array([c.anchor for c in robot.cables])
        state = {"tensions": rest.tensions_at_anchor, "horizontal": np.array([c.catenary.horizontal_tension
                                                                             for c in catenary_rest.cables]),
                 "previous": None}
        if any(over_swivel):
            # Over swivel pulleys the first sample starts from the rest the robot starts in, not from the
            # catenaries: these hang lower (no bending over the disc: 22 mm on spatial-four-cable-swivel), and
            # their nodes cannot start a chain that runs up the axis and over the disc
            state["previous"] = (replace(rest, paid_out=np.array(initial, dtype=float), iterations=0),
                                 np.linalg.norm(exits - rest.position - anchors @ rest.rotation.T, axis=1))

        def anchor_points(pose):
            rotation = np.eye(3) if robot.is_point_mass else rotation_from_vector(pose[3:6])
            return pose[:3] + anchors @ rotation.T

        def catenary_guess(pose, inertial):
            """Lengths and nodes of the catenary inverse at ``pose`` (a start far from any previous sample);
            a chain over a swivel pulley keeps the previous sample's nodes."""
            inverse = solve_inverse_statics(platform, pose, inertial, initial_guess=state["horizontal"])
            state["horizontal"] = inverse.horizontal_tensions
            points = anchor_points(pose)
            nodes = []
            for i, (cable, chain, length, point) in enumerate(zip(platform.cables, robot.cables,
                                                                  inverse.unstrained_lengths, points)):
                if over_swivel[i]:
                    nodes.append(state["previous"][0].nodes[i])
                    continue
                shape, _ = forward_cable(cable, length, point)
                nodes.append(shape.points(length - np.linspace(0.0, length, chain.n_elements + 1)))
            return inverse.unstrained_lengths, nodes

        def solve(pose, acceleration):
            inertial = np.concatenate([-robot.mass * acceleration[:3], np.zeros(3)])
            previous = state["previous"]
            angles = None
            if previous is None:
                lengths, nodes = catenary_guess(pose, inertial)
            else:  # the previous lengths, changed as the straight cables change
                points = anchor_points(pose)
                chords = np.linalg.norm(exits - points, axis=1)
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
            state["previous"] = (inverse, np.linalg.norm(exits - anchor_points(pose), axis=1))
            self.inverses.append(inverse)
            return inverse.paid_out
        return solve

    def command(self, measurement: Measurement) -> WinchCommand:
        if self._spline is None:
            raise RuntimeError("SpatialTensionAwareController.reset(scene) must be called before command()")
        t = measurement.time
        return WinchCommand(np.asarray(self._spline(t), dtype=float) - self.start.offset(measurement),
                            np.asarray(self._rate(t), dtype=float))
