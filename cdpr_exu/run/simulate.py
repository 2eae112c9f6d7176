"""Runs a scene through Exudyn's implicit generalized-alpha solver.

:func:`simulate` builds the model, asks the controller for winch commands once per
time step (a pre-step function), records the state at the output times (a post-step
function), and returns a :class:`~cdpr_exu.results.result.Result`. If the solver fails
mid-run, :class:`~cdpr_exu.core.errors.SolverFailure` says at what time and why, and
carries the result up to that time.
"""

from __future__ import annotations

import time as _time
from pathlib import Path
from typing import Callable

import exudyn as exu
import numpy as np
from numba import njit

from controllers.base import Controller, Measurement, SmoothStart
from controllers.ideal_ik import IdealIKController

from cdpr_exu.builder.cable import arm_first_step_kink, element_tensions
from cdpr_exu.core.errors import RunInterrupted, SceneError, SolverFailure
from cdpr_exu.builder.model import Model, build_model
from cdpr_exu.builder.robot_3d import Model3D
from cdpr_exu.core.geometry import penetration
from cdpr_exu.results.result import Result
from cdpr_exu.run.solver import (interrupt_flag, likely_cause, output_times, progress_reporter, quiet_exudyn,
                                  solver_report, solver_settings)
from cdpr_exu.run.run_3d import Run3D
from cdpr_exu.scenes.scene import Scene
from cdpr_exu.statics.workspace import check_reference
from cdpr_exu.builder.winch import RopeReservoir, ServoDrums, set_paid_out_length


#: A run stops when an element's strain exceeds this: the lumped model has left the
#: range where it describes a steel cable (real cables break near 1-2 % strain).
MAX_STRAIN = 0.05
#: A run stops when a node lies deeper than this fraction of the pulley radius inside
#: a pulley: the cable is slipping through it, which penalty contact on nodes allows
#: when an element is long compared with the contact's reach.
MAX_PENETRATION_FRACTION = 0.5


@njit(cache=True)
def _any_element_fault(q, node_index, reference_nodes, start, rest, slack, centers, radii, limit, depth_fraction):
    """Whether any element is strained beyond ``limit`` or cuts deeper than ``depth_fraction`` of its
    pulley's radius (empty ``radii``: no pulley check): :meth:`_Monitor.problem`'s test in one compiled loop
    (about 3 us against 230 us of NumPy calls per sample at 2 x 61 nodes), erring towards a fault by 1e-12
    so that the exact check runs wherever it could fail."""
    for e in range(start.size):
        a, b = start[e], start[e] + 1
        ax = reference_nodes[a, 0] + q[node_index[a, 0]]
        ay = reference_nodes[a, 1] + q[node_index[a, 1]]
        cx = reference_nodes[b, 0] + q[node_index[b, 0]] - ax
        cy = reference_nodes[b, 1] + q[node_index[b, 1]] - ay
        chord2 = cx * cx + cy * cy
        strain = np.sqrt(chord2) / rest[e] - 1.0
        if (strain > limit * (1.0 - 1e-12)) or (not slack and strain < -limit * (1.0 - 1e-12)):
            return True
        if radii.size:
            px, py = centers[e, 0] - ax, centers[e, 1] - ay
            t = min(max((px * cx + py * cy) / max(chord2, 1e-300), 0.0), 1.0)
            dx, dy = ax + t * cx - centers[e, 0], ay + t * cy - centers[e, 1]
            if radii[e] - np.sqrt(dx * dx + dy * dy) > depth_fraction * radii[e] * (1.0 - 1e-12):
                return True
    return False


class _Monitor:
    """Checks each recorded sample for states the model cannot describe, all elements at once (the cable
    reported is the first that fails). Every sample is checked, so a diverging run stops within one output
    period; a compiled pass (:func:`_any_element_fault`) clears a sound sample, the NumPy check below names
    the fault."""

    def __init__(self, scene: Scene, indices: dict[str, np.ndarray], reference: np.ndarray):
        self.scene = scene
        lumped = [i for i in range(len(scene.cables)) if f"cable_{i}" in indices]
        self.cable_numbers = np.array(lumped, dtype=int)
        self.check_pulleys = scene.pulley_contact
        self.on_segments = scene.contact_model is not None and scene.contact_model.on_segments
        self.rest = np.zeros(0)  # rest length of each element [m]; none: massless ropes, no element to check
        if lumped:  # flat arrays: node coordinates (N, 2), element starts, each element's cable
            self.node_index = np.concatenate([indices[f"cable_{i}"] for i in lumped])
            self.reference_nodes = reference[self.node_index]
            counts = [len(indices[f"cable_{i}"]) for i in lumped]
            first_node = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)
            self.start = np.concatenate([f + np.arange(n - 1) for f, n in zip(first_node, counts)])
            self.element_cable = np.concatenate([np.full(n - 1, k) for k, n in enumerate(counts)]).astype(int)
            self.first_element = np.concatenate([[0], np.cumsum([n - 1 for n in counts])[:-1]]).astype(int)
            self.rest = np.concatenate([np.full(scene.cables[i].n_elements, scene.cables[i].element_length)
                                        for i in lumped])
        self.centers, self.radii = np.zeros((0, 2)), np.zeros(0)
        if self.check_pulleys and lumped:
            self.centers = scene.exit_points[lumped][self.element_cable]
            self.radii = np.array([exit_.radius for exit_ in scene.exits])[lumped][self.element_cable]
        self.platform_index = indices["platform"]
        self.reference_pose = reference[self.platform_index]
        # No pose of a platform hung on these cables lies farther from every pulley
        # than the longest cable; the box of those reaches bounds every sane state.
        centers = scene.exit_points
        reach = max(c.unstrained_length for c in scene.cables) * (1.0 + MAX_STRAIN) + max(
            np.abs(np.asarray(scene.platform.anchors)).max(), 0.0)
        self.box = (centers.min(axis=0) - reach, centers.max(axis=0) + reach)
        # A suspended platform (starting below every pulley) that rises above the
        # highest pulley rim is held there only by cables that push.
        tops = scene.exit_tops
        suspended = scene.platform.initial_pose[1] < centers[:, 1].min()
        self.ceiling = tops.max() if suspended else np.inf

    def problem(self, t: float, q: np.ndarray, surplus: np.ndarray | None = None) -> str | None:
        """What is wrong at time ``t`` [s], or None; ``surplus`` (m,) [m]: slack rope held at each drum,
        which lengthens the winch element (:func:`cdpr_exu.builder.winch.reservoir_split`)."""
        if not np.all(np.isfinite(q)):
            return f"the coordinates are no longer finite at t = {t:.4f} s"
        rest = self.rest
        if surplus is not None and rest.size:
            rest = rest.copy()
            rest[self.first_element] += np.asarray(surplus)[self.cable_numbers]
        if rest.size and _any_element_fault(q, self.node_index, self.reference_nodes, self.start, rest,
                                            self.scene.effects.slack, self.centers, self.radii, MAX_STRAIN,
                                            MAX_PENETRATION_FRACTION):
            positions = self.reference_nodes + q[self.node_index]
            a, b = positions[self.start], positions[self.start + 1]
            chord = b - a
            strain = np.linalg.norm(chord, axis=1) / rest - 1.0
            if self.scene.effects.slack:
                strain = np.maximum(strain, 0.0)  # a tension-only element may go slack: shortening is no fault
            strained = np.abs(strain) > MAX_STRAIN
            cut = np.zeros_like(strained)
            if self.check_pulleys:  # closest point of each element to its pulley centre
                t_closest = np.clip(np.einsum("ij,ij->i", self.centers - a, chord)
                                    / np.maximum(np.einsum("ij,ij->i", chord, chord), 1e-300), 0.0, 1.0)
                distance = np.linalg.norm(a + t_closest[:, None] * chord - self.centers, axis=1)
                depth = np.maximum(self.radii - distance, 0.0)
                cut = depth > MAX_PENETRATION_FRACTION * self.radii
            if strained.any() or cut.any():
                k = int(self.element_cable[np.flatnonzero(strained | cut)[0]])  # the first cable that fails
                i = int(self.cable_numbers[k])
                mine = self.element_cable == k
                if strained[mine].any():
                    worst = int(np.argmax(np.abs(strain[mine])))
                    value = strain[mine][worst]
                    return (f"element {worst} of cable {i + 1} is strained by {100 * value:+.4g} % at t = {t:.4f} s "
                            f"(limit {100 * MAX_STRAIN:.0f} %): the run has left the model's valid range")
                element = int(np.argmax(depth[mine]))
                advice = ("segment contact: the rim contact is too soft for the cable tension; raise "
                          f"pulleys[{i}].contact_stiffness" if self.on_segments else
                          "contact acts on nodes only; use more elements, or "
                          "effects.pulley_contact_model = 'segment'")
                return (f"element {element} of cable {i + 1} cuts {1000 * depth[mine][element]:.0f} mm deep into "
                        f"pulley {i + 1} at t = {t:.4f} s: the cable is slipping through the pulley ({advice})")
        pose = self.reference_pose + q[self.platform_index]
        if np.any(pose[:2] < self.box[0]) or np.any(pose[:2] > self.box[1]):
            return (f"the platform left the reachable region at t = {t:.4f} s (it is at x = {pose[0]:.3f} m, "
                    f"z = {pose[1]:.3f} m): the integration has diverged")
        if pose[1] > self.ceiling:
            return (f"the platform rose above the pulleys at t = {t:.4f} s (z = {pose[1]:.3f} m): only pushing "
                    f"cables can hold it there; the run has diverged (try a smaller step, or effects.slack = true)")
        return None


class _Recorder:
    """Stores Exudyn's coordinates at the output times (called once per step).

    Each sample is the state at the end of the first step that reaches its output time, with that step's
    time: never an interpolation, which across a step where an element snaps taut or a node strikes the
    rim made elements look slack and nodes cut into the pulley.
    """

    def __init__(self, model: Model, output_period: float, end_time: float):
        self.model = model
        self.indices = model.coordinate_indices()
        self.output_times = output_times(end_time, output_period)
        count = len(self.output_times)
        size = model.mbs.systemData.GetODE2Coordinates().size
        self.q = np.full((count, size), np.nan)
        self.v = np.full((count, size), np.nan)
        self.times = np.full(count, np.nan)
        self.paid_out = np.full((count, len(model.winches)), np.nan)
        self.rope_forces = np.full((count, len(model.ropes)), np.nan)
        self.surplus = np.zeros((count, len(model.winches)))  # slack rope at each drum [m]
        self.count = 0

    def record_if_due(self, t: float, paid_out: np.ndarray, surplus: np.ndarray | None = None) -> bool:
        """Store the state if an output time is due; True if stored."""
        if self.count < len(self.output_times) and t >= self.output_times[self.count] - 1e-9:
            data = self.model.mbs.systemData
            self.q[self.count] = data.GetODE2Coordinates()
            self.v[self.count] = data.GetODE2Coordinates_t()
            self.times[self.count] = t
            self.paid_out[self.count] = paid_out
            if surplus is not None:
                self.surplus[self.count] = surplus
            for i, rope in enumerate(self.model.ropes):
                self.rope_forces[self.count, i] = self.model.mbs.GetObjectOutput(rope.rope, exu.OutputVariableType.ForceLocal)
            self.count += 1
            return True
        return False

    def result(self, scene: Scene, controller_name: str) -> Result:
        """Convert the recorded coordinates to a Result in the x-z plane."""
        k = self.count
        q, v = self.q[:k], self.v[:k]
        times = self.times[:k]
        ref_q = self.model.mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Reference)
        platform_idx = self.indices["platform"]
        pose = ref_q[platform_idx] + q[:, platform_idx]
        velocity = v[:, platform_idx]
        nodes, node_velocities, tensions, depth = [], [], [], []
        if self.model.ropes:
            nodes, node_velocities, tensions = _rope_series(scene, self.model, pose, self.paid_out[:k],
                                                            self.rope_forces[:k], times)
            depth = [np.zeros(k) for _ in self.model.ropes]
        for i, cable in enumerate(scene.cables if not self.model.ropes else ()):
            idx = self.indices[f"cable_{i}"]
            positions = ref_q[idx] + q[:, idx]
            velocities = v[:, idx]
            nodes.append(positions)
            node_velocities.append(velocities)
            rest = np.full((k, cable.n_elements), cable.element_length)
            rest[:, 0] += self.surplus[:k, i]  # the winch element holds the slack rope at the drum
            tensions.append(element_tensions(cable, positions, velocities, scene.effects, rest))
            if scene.exits[i].wraps:
                depth.append(penetration(scene.exits[i], positions).max(axis=1))
            else:
                depth.append(np.zeros(k))
        reference = scene.trajectory.pose(times) if k else np.zeros((0, 3))
        return Result(
            scene_name=scene.name, controller=controller_name, dimension=scene.space.dimension, time=times,
            pose=pose, velocity=velocity, reference=np.atleast_2d(reference).reshape(-1, 3),
            nodes=nodes, node_velocities=node_velocities, tensions=tensions, paid_out=self.paid_out[:k],
            pulley_penetration=np.column_stack(depth) if depth else np.zeros((k, 0)),
        )


def _rope_series(scene: Scene, model: Model, pose: np.ndarray, paid_out: np.ndarray, forces: np.ndarray,
                 times: np.ndarray):
    """Massless ropes' polylines (winch end, hang point, tangent point, anchor), rates and tensions."""
    from cdpr_exu.statics.kinematics import anchor_points

    k = len(times)
    anchors = anchor_points(pose, np.asarray(scene.platform.anchors)) if k else np.zeros((0, len(model.ropes), 2))
    nodes, velocities, tensions = [], [], []
    for i, cable in enumerate(scene.cables):
        points = np.zeros((k, 4, 2))
        exit_ = scene.exits[i]
        hang = exit_.hang_point
        for row in range(k):
            tangent = exit_.exit(anchors[row, i]).tangent_point
            points[row] = [exit_.winch_end(cable.unstrained_length, paid_out[row, i]), hang, tangent, anchors[row, i]]
        nodes.append(points)
        velocities.append(np.gradient(points, times, axis=0) if k > 1 else np.zeros_like(points))
        tensions.append(forces[:, i:i + 1])
    return nodes, velocities, tensions


class Run2D:
    """The planar robot's side of a run (:data:`RUNS`): before each step the controller's command drives
    the winches (kinematic lengths, servo motor forces, the slack-rope reservoir); after each step the
    outputs due are recorded (:class:`_Recorder`) and checked (:class:`_Monitor`). ``paid_out`` and
    ``rate`` (m,) [m, m/s] are the last commanded (servos: measured) lengths and rates."""

    def __init__(self, scene: Scene, model: Model):
        self.scene, self.model = scene, model
        self.controller: Controller | None = None
        self.report = None
        self.recorder = recorder = _Recorder(model, scene.solver.output_period, scene.solver.end_time)
        self.ref_q = ref_q = model.mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Reference)
        self.monitor = _Monitor(scene, recorder.indices, ref_q)
        self.indices = recorder.indices
        self.paid_out = model.initial_paid_out.copy()
        self.rate = np.zeros(len(scene.cables))
        self.stop_reason: str | None = None
        self.interrupted = {"interrupted": False}
        self.reservoir = _rope_reservoir(scene, model)
        self.first_step_kink = arm_first_step_kink(model.cable_forces)
        # coordinates of each cable's first two nodes, shape (m, 2, 2): its winch element
        self.first_nodes = (np.array([self.indices[f"cable_{i}"][:2] for i in range(len(scene.cables))])
                            if self.reservoir else np.zeros((0, 2, 2), dtype=int))
        self.drums = ServoDrums(model.mbs, model.servos, model.initial_paid_out)
        self.step_start = 0.0  # end of the last accepted step: the time of the state the solver has [s]
        self.start = _time.perf_counter()

    def initial_pose(self) -> None:
        """None: the controller starts from the scene's initial pose (the model is built there)."""
        return None

    def begin(self, controller: Controller, report) -> None:
        """Record the start (always runnable)."""
        self.controller, self.report = controller, report
        self.recorder.record_if_due(0.0, self.paid_out)
        self.start = _time.perf_counter()

    def _cable_tensions(self, q: np.ndarray, v: np.ndarray, i: int, which: slice) -> np.ndarray:
        """Tensions [N] of the elements of cable i between the nodes ``which`` (a slice of its nodes)."""
        idx = self.indices[f"cable_{i}"][which]
        return element_tensions(self.scene.cables[i], self.ref_q[idx] + q[idx], v[idx], self.scene.effects)

    def measurement(self, t: float) -> Measurement:
        """What the controller may see at time ``t`` [s]."""
        controller, model = self.controller, self.model
        pose = velocity = tensions = None
        if controller.uses_pose or controller.uses_tension:
            q = model.mbs.systemData.GetODE2Coordinates()
            v = model.mbs.systemData.GetODE2Coordinates_t()
            platform = self.indices["platform"]
            pose = self.ref_q[platform] + q[platform]
            velocity = v[platform]
            if controller.uses_tension and model.ropes:
                tensions = np.array([model.mbs.GetObjectOutput(r.rope, exu.OutputVariableType.ForceLocal)
                                     for r in model.ropes])
            elif controller.uses_tension:
                tensions = np.array([self._cable_tensions(q, v, i, slice(-2, None))[-1]
                                     for i in range(len(self.scene.cables))])
        return Measurement(t, self.paid_out.copy(), self.rate.copy(), pose, velocity, tensions,
                           state_time=self.step_start)

    def pre_step(self, mbs_, t: float) -> bool:
        """Exudyn's pre-step function: command and drive the winches; False stops the run."""
        model = self.model
        if self.scene.winch.kind == "fixed":
            return True
        try:
            if model.servos:
                q = mbs_.systemData.GetODE2Coordinates()
                v = mbs_.systemData.GetODE2Coordinates_t()
                self.paid_out, self.rate = self.drums.measured(q, v)
            command = self.controller.command(self.measurement(t))
            paid_out = np.asarray(command.paid_out, dtype=float).reshape(-1)
            if paid_out.shape != self.paid_out.shape or not np.all(np.isfinite(paid_out)):
                raise ValueError(f"the command must be {self.paid_out.size} finite lengths, got {command.paid_out!r}")
            if model.servos:
                tensions = [self._cable_tensions(q, v, i, slice(0, 2))[0] for i in range(len(model.servos))]
                self.drums.drive(mbs_, t, command, q, v, tensions)
                return True
        except Exception as err:  # noqa: BLE001 - reported as the cause of the stop
            self.stop_reason = (f"controller {self.controller.name!r} raised at t = {t:.4f} s: "
                                f"{type(err).__name__}: {err}")
            return False
        self.paid_out = paid_out
        self.rate = np.asarray(command.paid_out_rate, dtype=float).reshape(-1)
        targets = self.paid_out
        if self.reservoir is not None:  # slack rope paid out piles up at the drum (winch.reservoir_split)
            q = mbs_.systemData.GetODE2Coordinates()
            first = self.ref_q[self.first_nodes] + q[self.first_nodes]
            chord = first[:, 1] - first[:, 0]
            # |chord| as np.linalg.norm computes it (a dot product), for every cable at once
            lengths = np.sqrt((chord[:, None, :] @ chord[:, :, None]).ravel())
            targets = model.initial_paid_out + self.reservoir.update(targets - model.initial_paid_out, lengths)
        for winch, length, initial in zip(model.winches, targets, model.initial_paid_out):
            set_paid_out_length(mbs_, winch, length, initial)
        return True

    def post_step(self, mbs_, t: float) -> bool:  # noqa: ARG002 - Exudyn's signature
        """Exudyn's post-step function: record, check, report; False ends the integration."""
        self.step_start = t
        self.first_step_kink[0] = 0.0  # the zero-strain start is behind: Newton sees the law as it is
        if self.interrupted["interrupted"]:
            return False  # Ctrl-C: end the integration, keep what was computed
        surplus = None if self.reservoir is None else self.reservoir.surplus
        recorder = self.recorder
        if recorder.record_if_due(t, self.paid_out, surplus):
            self.stop_reason = self.monitor.problem(t, recorder.q[recorder.count - 1], surplus)
            if self.stop_reason is not None:
                return False  # ends the time integration; the samples so far are kept
        if self.report is not None:
            self.report(t, _time.perf_counter() - self.start)
        return True

    def result(self, controller_name: str, failure: str | None) -> Result:
        """What was recorded, as a :class:`Result`; after a failure it ends at its last finite sample."""
        recorder = self.recorder
        if failure is not None and not self.interrupted["interrupted"]:
            recorded = slice(0, recorder.count)
            finite_rows = np.all(np.isfinite(recorder.q[recorded]) & np.isfinite(recorder.v[recorded]), axis=1)
            if not finite_rows.all():
                recorder.count = int(np.argmin(finite_rows))
        result = recorder.result(self.scene, controller_name)
        if self.reservoir is not None:
            result.winch_reservoir = recorder.surplus[:len(result.time)].copy()
        return result

    def reached(self, result: Result) -> tuple[float, bool]:
        """The time of the last finite sample [s], and whether every output time was sampled."""
        finite = np.all(np.isfinite(result.pose), axis=1) if len(result.time) else np.zeros(0, bool)
        return float(result.time[finite][-1]) if finite.any() else 0.0, len(result.time) == len(self.recorder.output_times)

    def notes(self, failure: str, time: float) -> tuple[str, str]:
        """What the failure's message says before and after the cause: the step size and the likely cause."""
        return f" (step size {self.scene.solver.step_size} s)", f". {likely_cause(self.scene, failure, time)}"


def simulate(scene: Scene, controller: Controller | None = None, *, solution_file: str | Path | None = None,
             progress: bool | Callable[[float, float], None] = False,
             sparse_jacobian: bool | None = None) -> Result:
    """Simulate ``scene``, planar or spatial, under ``controller`` (default: ideal inverse kinematics).

    One run loop for both dimensions: the controller wrapped in :class:`SmoothStart` (its commands start at
    the paid-out lengths), Exudyn's implicit solver, one Result; the model's run side (:data:`RUNS`) holds
    what differs by dimension.

    ``solution_file``: also write Exudyn's solution file there; ``progress``: True shows a progress bar,
    a callable is called as ``progress(t, wall_time)`` about 100 times; ``sparse_jacobian``: planar runs'
    cable Jacobian sparse or dense (:func:`~cdpr_exu.builder.model.build_model`).

    Raises
    ------
    SceneError, UnreachableError
        Before the run (:func:`check_runnable`).
    SolverFailure, RunInterrupted
        When the solver fails or Ctrl-C stops it; ``.time`` and ``.partial_result`` say when and what was
        computed up to then.
    """
    check_runnable(scene)
    model = build_model(scene, sparse_jacobian=sparse_jacobian)
    run = RUNS[type(model)](scene, model)
    # The controller plans on its own model of the robot (the scene's controller model, if it has one),
    # never on the plant's parameters; what the winches paid out at t = 0 and the pose it starts from are
    # the plant's. Every controller starts from what the winches paid out at t = 0 (SmoothStart).
    controller = SmoothStart(controller or IdealIKController())
    controller.reset(scene.controller_scene(), model.initial_paid_out.copy(),
                     initial_pose=run.initial_pose() if controller.uses_pose else None)
    mbs, solver = model.mbs, scene.solver
    report = progress_reporter(progress, scene)
    run.begin(controller, report)
    cpu_start = _time.process_time()  # the solve's CPU time, beside its wall time (run.start)
    mbs.SetPreStepUserFunction(run.pre_step)
    mbs.SetPostStepUserFunction(run.post_step)
    failure = None
    with interrupt_flag() as interrupted, quiet_exudyn():
        run.interrupted = interrupted
        try:
            if run.stop_reason is None:
                mbs.SolveDynamic(solver_settings(scene, solution_file))
        except (exu.SolverError, RuntimeError, SystemError) as err:  # Exudyn's own cause, not only "terminated"
            failure = solver_report(mbs, " ".join(str(err).split()))
    failure = run.stop_reason or failure
    wall = _time.perf_counter() - run.start
    cpu = _time.process_time() - cpu_start
    if report is not None:
        report(None, wall)
    result = run.result(controller.name, failure)
    solved = mbs.sys.get("dynamicSolver")  # none when the start was refused
    result.wall_time, result.cpu_time = wall, cpu
    if solved is not None:
        it = solved.it
        result.steps, result.newton_iterations = int(it.currentStepIndex), int(it.newtonStepsCount)
        result.jacobians = int(it.newtonJacobiCount)
        result.discontinuous_iterations = int(it.discontinuousIterationsCount)
    result.metadata.update({"effects": scene.effects.preset, "step_size_s": solver.step_size,
                            "n_elements": [c.n_elements for c in scene.cables], "item_counts": model.item_counts(),
                            # above the highest exit every cable pulls the platform down (Result.summary)
                            "highest_exit_z_m": float(scene.exit_points[:, -1].max())})
    if scene.tension_limits is not None:  # (t_min, t_max) per cable; JSON has no inf: null is "no limit"
        result.metadata["tension_limits_N"] = [[c.min_tension, c.max_tension] for c in scene.cables]
    reached, complete = run.reached(result)
    if interrupted["interrupted"]:
        result.status, result.failure_time = f"interrupted at t = {reached:.4f} s", reached
        raise RunInterrupted(f"interrupted by the user at t = {reached:.4f} s of {solver.end_time} s",
                             time=reached, partial_result=result)
    if failure is None and not (complete and np.all(np.isfinite(result.pose))):
        failure = "the solution contains NaN or stopped before the end time"
    if failure is not None:
        result.status, result.failure_time = f"failed: {failure}", reached
        before, after = run.notes(failure, reached)
        raise SolverFailure(f"the run failed at t = {reached:.4f} s of {solver.end_time} s{before}: {failure}{after}",
                            time=reached, partial_result=result)
    return result


def check_runnable(scene: Scene) -> None:
    """Refuse a scene :func:`simulate` cannot run, before anything is built or written: SceneError without
    a ``[trajectory]``, UnreachableError for a reference the cables cannot follow (``check_reference``)."""
    if scene.trajectory is None:
        raise SceneError(f"scene {scene.name!r} has no [trajectory]: `cdpr run` needs one (`cdpr static` does not)")
    check_reference(scene)


#: The run side of each dimension's model, ``RUNS[type(model)](scene, model)``, behind one interface:
#: ``initial_pose()``, ``begin(controller, report)``, ``pre_step``, ``post_step``, ``stop_reason``,
#: ``interrupted``, ``start``, ``result(name, failure)``, ``reached(result)``, ``notes(failure, time)``.
RUNS = {Model: Run2D, Model3D: Run3D}


def _rope_reservoir(scene: Scene, model: Model) -> RopeReservoir | None:
    """The slack-rope reservoir of kinematic winches on tension-only lumped cables (else None)."""
    forces = model.cable_forces
    if not (scene.effects.slack and scene.winch.kind == "kinematic" and forces is not None and forces.slack_arrays):
        return None
    rest, stiffness, damping = forces.slack_arrays
    counts = [cable.n_elements for cable in scene.cables]
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)
    m = len(scene.cables)
    return RopeReservoir(
        first_elements=first, nominal_rest_length=rest[first].copy(),
        axial_rigidity=stiffness[first] * rest[first], damping_rigidity=damping[first] * rest[first],
        rest_length=rest, stiffness=stiffness, damping=damping,
        surplus=np.zeros(m), node_offset=np.zeros(m), max_surplus=np.zeros(m))
