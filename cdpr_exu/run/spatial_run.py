"""Dynamic runs of spatial scenes: the lumped robot following a 6-DOF reference (issue 15).

:func:`simulate_spatial` builds the scene's robot (:mod:`cdpr_exu.builder.spatial_robot`:
chains held at their exit points, a point-mass or rigid platform on spherical joints),
starts it at rest on its elastic-catenary equilibrium (over swivel pulleys on the lumped
robot's own equilibrium, found by the chain statics:
:func:`cdpr_exu.builder.spatial_robot.start_at_rest`), and integrates it with Exudyn's
implicit solver (the scene's ``[solver]``) while the winches follow the ideal inverse
kinematics of the reference: each cable's paid-out length is its initial length plus
the change of the straight distance from its exit point to its anchor along the
reference (:mod:`cdpr_exu.statics.kinematics`), the spatial counterpart of the
planar ``ideal_ik`` controller.

**The winch at a point exit.** A spatial scene's cable leaves the frame at a fixed
point, where the winch pays it out (over a swivel pulley the winch end moves along
the pulley's axis instead, :mod:`cdpr_exu.builder.spatial_robot`). The lumped cable keeps
its n elements and changes with its paid-out (unstrained) length L(t): every element's
unstrained length L / n, its axial stiffness E A n / L and damping d_n A n / L, the node
masses rho L / n (half at the ends) and their weights, and the bending stiffness
E J n / L and damping d_n J n / L, set before every step. This is a *variable-length* lumped cable: its
statics are those of the elastic catenary of length L (which depends on L only, not on
where along the cable the change happens), and its mass is the mass of the cable paid
out. What it leaves out is the flow of material through the exit: the nodes slide
along the cable by up to (L(t) - L(0)) (s / L) instead of the cable running in at the
exit, an axial motion whose inertia is small beside the platform's.

Units SI; z up, gravity along -z; poses ``(x, y, z, theta)`` with ``theta`` the platform's
rotation vector.
"""

from __future__ import annotations

import time as _time
import warnings
from pathlib import Path

import exudyn as exu
import numpy as np

from cdpr_exu.core.errors import RunInterrupted, SceneError, SolverFailure
from cdpr_exu.core.geometry import rotation_from_vector, rotation_vector
from cdpr_exu.builder.spatial_robot import build_spatial_robot, chain_positions, element_forces, platform_pose, \
    scene_chain_spec, start_at_rest
from cdpr_exu.statics.statics import catenary_platform, solve_statics
from cdpr_exu.physics.swivel_pulley import SwivelStabilityWarning, stability_concerns
from controllers.base import Controller, Measurement, SmoothStart
from controllers.ideal_ik import IdealIKController

from cdpr_exu.results.result import Result
from cdpr_exu.run.solver import (interrupt_flag, output_times, progress_reporter, quiet_exudyn, solver_report,
                                  solver_settings)
from cdpr_exu.run.spatial_rest import rest_above_exits
from cdpr_exu.scenes.scene import Scene, tension_limits
from cdpr_exu.statics.workspace import check_reference

__all__ = ["simulate_spatial", "build_spatial_model"]


class _SpatialWinches:
    """The variable-length cables: before each step, every cable's elements follow its paid-out length."""

    def __init__(self, mbs, scene: Scene, items, lengths: np.ndarray):
        self.mbs, self.scene, self.items = mbs, scene, items
        self.n = scene.cables[0].n_elements
        self.gravity = scene.gravity if (scene.effects.gravity and scene.effects.cable_mass) else 0.0
        self.applied = np.array(lengths, dtype=float)
        self.rate = np.zeros(len(self.applied))  # the winches' rate [m/s]: the last command's, as planar runs

    def set_lengths(self, lengths: np.ndarray, rates: np.ndarray) -> None:
        """Give every cable the paid-out length ``lengths`` (m,) [m], changing at ``rates`` (m,) [m/s].

        Over a swivel pulley the cable keeps its elements: its held winch end moves along
        the swivel axis by the change of the paid-out length (cable runs over the disc).

        The rate goes to each element's damper as Exudyn's ``velocityOffset``: the
        Kelvin-Voigt damper acts on the strain rate d(l - l0)/dt, so a cable that is paid
        out without stretching is not damped (without the offset the paper's damping
        constant on a CoGiRo cable paid out at 0.25 m/s pulls with 740 N).
        """
        mbs, items = self.mbs, self.items
        self.rate = np.array(rates, dtype=float)
        for i, (cable, chain, length, rate) in enumerate(zip(self.scene.cables, items.chains, lengths, rates)):
            if items.has_swivel(i):  # the winch end moves along the swivel axis: up when paying out
                if length != self.applied[i]:
                    mbs.SetObjectParameter(chain.holds[2], "offset", float(length - items.unstrained_lengths[i]))
                    self.applied[i] = length
                continue
            if chain.tension_only:  # the arrays the cable's numba kernels read
                chain.axial_rest_rate[:] = float(rate) / self.n
            for spring in chain.springs:
                mbs.SetObjectParameter(spring, "velocityOffset", float(rate) / self.n)
            if length == self.applied[i]:
                continue
            element = float(length) / self.n
            stiffness = cable.axial_rigidity / element
            damping = items.axial_dampings[i] * items.unstrained_lengths[i] / self.n / element
            if chain.tension_only:
                chain.axial_rest_length[:] = element
                chain.axial_stiffness[:] = stiffness
                chain.axial_damping[:] = damping
            for spring in chain.springs:
                mbs.SetObjectParameter(spring, "referenceLength", element)
                mbs.SetObjectParameter(spring, "stiffness", stiffness)
                mbs.SetObjectParameter(spring, "damping", damping)
            masses = items.node_masses[i] * (float(length) / items.unstrained_lengths[i])  # rho l_e per node
            for body, load, mass in zip(chain.masses, chain.loads or [None] * len(masses), masses):
                mbs.SetObjectParameter(body, "mass", float(mass))
                if load is not None:
                    mbs.SetLoadParameter(load, "loadVector", [0.0, 0.0, -float(mass) * self.gravity])
            if chain.bending_stiffness is not None:
                chain.bending_stiffness[:] = items.bending_stiffnesses[i] * items.unstrained_lengths[i] / self.n / element
            if chain.bending_damping is not None:
                chain.bending_damping[:] = items.bending_dampings[i] * items.unstrained_lengths[i] / self.n / element
            self.applied[i] = length


#: A run stops when the platform has turned farther than this from the reference's orientation [deg]:
#: it has left the workspace (issue 23.5: IPAnema ran on for 566 s to end 175 degrees off).
MAX_ROTATION_ERROR_DEG = 90.0


class _SpatialMonitor:
    """Checks the platform at the start and after each step for states the run cannot come back from
    (the spatial counterpart of the planar monitor): coordinates no longer finite, a platform above
    its highest exit (every cable pulls it down there: only cables that push could hold it), or one
    turned more than :data:`MAX_ROTATION_ERROR_DEG` from the reference's orientation."""

    def __init__(self, scene: Scene):
        self.trajectory = scene.trajectory
        self.ceiling = float(scene.exit_points[:, 2].max())  # above it every cable pulls the platform down
        self.turns = not scene.platform.is_point_mass

    def problem(self, t: float, position: np.ndarray, rotation: np.ndarray) -> str | None:
        """What is wrong at time ``t`` [s] with the platform at ``position`` (3,) [m], turned by ``rotation`` (3, 3),
        or None."""
        if not (np.all(np.isfinite(position)) and np.all(np.isfinite(rotation))):
            return f"the coordinates are no longer finite at t = {t:.4f} s"
        if position[2] > self.ceiling:
            if t == 0.0:  # where the robot came to rest (over swivel pulleys: the chain statics)
                return (f"the platform rests above its highest exit at t = 0 (z = {position[2]:.3f} m, the exit at "
                        f"{self.ceiling:.3f} m): only cables that push or bend could hold it there, which the "
                        "lumped chains do and a real cable cannot (cables too stiff in bending for their load?)")
            return (f"the platform rose above its highest exit at t = {t:.4f} s (z = {position[2]:.3f} m, the exit at "
                    f"{self.ceiling:.3f} m): only cables that push could hold it there; the run has diverged (a "
                    "winch command that jumps, or a smaller solver.step_size)")
        if self.turns:
            reference = rotation_from_vector(np.asarray(self.trajectory.pose(t))[3:])
            angle = np.degrees(np.linalg.norm(rotation_vector(reference.T @ rotation)))
            if angle > MAX_ROTATION_ERROR_DEG:
                return (f"the platform turned {angle:.0f} degrees away from the reference's orientation at "
                        f"t = {t:.4f} s (limit {MAX_ROTATION_ERROR_DEG:g}): it has left the workspace the cables hold "
                        "it in; the run is stopped")
        return None


def _warn_outside_measured_region(scene: Scene) -> None:
    """Warn (:class:`cdpr_exu.physics.swivel_pulley.SwivelStabilityWarning`) when the scene's solver settings lie
    outside the region where runs over a swivel pulley were measured to keep their energy."""
    solver = scene.solver
    for swivel, cable in zip(scene.swivel_exits, scene.cables):
        if swivel is None:
            continue
        for concern in stability_concerns(solver.newton == "modified", solver.spectral_radius, solver.newton_tolerance,
                                          cable.element_length, swivel.radius):
            warnings.warn(concern, SwivelStabilityWarning, stacklevel=3)
        return


def _rest_above_exits(scene: Scene, mbs, items) -> str | None:
    """Why the lumped robot's rest (over swivel pulleys) cannot start a run, or None: it holds the platform
    above its exits (:func:`cdpr_exu.run.spatial_rest.rest_above_exits`: its bending or pushing elements do)."""
    position, rotation = platform_pose(mbs, items, current=False)
    lowest = min(float(element_forces(mbs, items, i, current=False).min()) for i in range(scene.n_cables))
    above = rest_above_exits(scene, position, rotation, lowest, items.initial)
    return None if above is None else f"the run cannot start from the robot's rest: {above}"


def check_runnable(scene: Scene) -> None:
    """Refuse a scene ``cdpr run`` cannot run, before anything is built or written: no ``[trajectory]``,
    or a reference the cables cannot follow (:func:`cdpr_exu.statics.workspace.check_reference`).

    Raises
    ------
    SceneError, UnreachableError
    """
    if scene.trajectory is None:
        raise SceneError(f"scene {scene.name!r} has no [trajectory]: `cdpr run` needs one (`cdpr static` does not)")
    check_reference(scene)


def build_spatial_model(scene: Scene):
    """The scene's lumped robot in a new Exudyn system, assembled in its catenary start; returns (mbs, items).

    What :func:`simulate_spatial` integrates and what a replay of its solution file
    (:func:`cdpr_exu.post.viewer.load_replay`) rebuilds: the same items in the same order, so the
    same coordinates. The start over swivel pulleys (:func:`start_at_rest`) moves only the
    initial coordinates, which a replay takes from the solution file.

    Raises
    ------
    UnreachableError
        If no static equilibrium of the scene's lengths exists to start from.
    """
    platform = catenary_platform(scene)
    lengths = scene.unstrained_lengths
    start = solve_statics(platform, lengths)
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, platform, lengths, scene_chain_spec(scene), initial=start, swivels=scene.swivel_exits)
    mbs.Assemble()
    return mbs, items


def simulate_spatial(scene: Scene, controller: Controller | None = None, progress=False, *,
                     solution_file: str | Path | None = None, sparse_jacobian: bool | None = None) -> Result:  # noqa: ARG001
    """The spatial run loop behind :func:`cdpr_exu.run.simulate.simulate`: run ``scene``'s reference under
    ``controller`` (default: ideal inverse kinematics). (``sparse_jacobian`` is the planar builder's choice;
    the spatial robot's Jacobian is Exudyn's own.)

    The controller is any :class:`controllers.base.Controller` that works on spatial
    scenes (:class:`controllers.ideal_ik.IdealIKController`,
    :class:`controllers.tension_aware.TensionAwareController` (catenary or, with
    ``statics="chain"``, the simulator's own chains), its closed loop; every kind of
    :data:`controllers.registry.CONTROLLERS` made for a spatial scene); it is asked
    for the winch commands before every step, wrapped in
    :class:`controllers.base.SmoothStart` as on planar scenes (its commands start at the
    paid-out lengths). A controller with ``uses_pose`` reads the platform's pose
    (x, y, z, rotation vector) and velocity (linear, global angular) at the start of the
    step (``Measurement.state_time``); one with ``uses_tension`` reads these and each
    cable's tension at its platform end (its last element's axial force, shape (m,) [N],
    as planar runs give it) at the same state.

    ``solution_file`` also writes Exudyn's solution file there (every output period), for
    ``SolutionViewer`` on the model :func:`build_spatial_model` rebuilds.

    Raises
    ------
    SceneError
        If the scene has no ``[trajectory]``.
    UnreachableError
        If no static equilibrium of the scene's lengths exists to start from.
    SolverFailure
        If the solver fails; ``.time`` and ``.partial_result`` say when and what was computed. Also
        (at t = 0, no partial result) if the lumped robot's rest over swivel pulleys holds the
        platform above its exits.
    """
    check_runnable(scene)
    mbs, items = build_spatial_model(scene)
    lengths = scene.unstrained_lengths
    if any(scene.swivel_exits):
        _warn_outside_measured_region(scene)
        try:
            start_at_rest(mbs, items)  # the chain statics' equilibrium (the dynamic settle only if they fail)
        except SolverFailure as failure:  # the settle's solver knows why it stopped
            exudyn_said = str(failure).split(": ", 1)[-1]  # "SolveDynamic terminated", and no more
            raise SolverFailure(f"settling the robot over its swivel pulleys before the run failed: "
                                f"{solver_report(mbs, exudyn_said)}", time=0.0) from None
    winches = _SpatialWinches(mbs, scene, items, lengths)
    solver = scene.solver
    outputs = output_times(solver.end_time, solver.output_period)
    m, n = scene.n_cables, scene.cables[0].n_elements
    times, poses, paid, node_series, tension_series = [], [], [], [[] for _ in range(m)], [[] for _ in range(m)]
    kinematic = scene.winch.kind == "kinematic"

    def measured_state() -> tuple[np.ndarray, np.ndarray]:
        """The platform's pose (x, y, z, rotation vector) [m, rad] and velocity (linear, global angular)
        [m/s, rad/s] now, each shape (6,)."""
        position, rotation = platform_pose(mbs, items)
        velocity = np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.Velocity))
        angular = (np.zeros(3) if items.is_point_mass else
                   np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.AngularVelocity)))
        return np.concatenate([position, rotation_vector(rotation)]), np.concatenate([velocity, angular])

    def measured_tensions() -> np.ndarray:
        """Each cable's tension at its platform end now, shape (m,) [N]: its last element's axial force as
        the model computes it (the Kelvin-Voigt law on the strain rate; tension-only where the scene says so),
        as planar runs give it."""
        return np.array([element_forces(mbs, items, i)[-1] for i in range(m)])

    controller = controller or IdealIKController()
    # Every controller starts from what the winches paid out at t = 0 (SmoothStart), as on planar scenes.
    controller = SmoothStart(controller)
    # It plans on its own model of the robot (the scene's [controller_model], if any); what the
    # winches paid out at t = 0 and the pose it starts from are the plant's.
    controller.reset(scene.controller_scene(), lengths.copy(),
                     initial_pose=measured_state()[0] if controller.uses_pose else None)
    state = {"next": 0, "failure": None, "step_start": 0.0, "reached": 0.0}

    def measurement(t: float) -> Measurement:
        """What the controller may see when asked for the command at ``t`` [s]."""
        if not (controller.uses_pose or controller.uses_tension):
            return Measurement(t, winches.applied.copy(), winches.rate.copy())
        pose, velocity = measured_state()
        tensions = measured_tensions() if controller.uses_tension else None
        return Measurement(t, winches.applied.copy(), winches.rate.copy(), pose, velocity, tensions,
                           state_time=state["step_start"])

    def record(t: float) -> None:
        position, rotation = platform_pose(mbs, items)
        times.append(t)
        poses.append(np.concatenate([position, rotation_vector(rotation)]))
        paid.append(winches.applied.copy())
        for i in range(m):
            positions = chain_positions(mbs, items, i)
            node_series[i].append(positions)
            tension_series[i].append(element_forces(mbs, items, i, positions=positions))  # spring and damper

    def pre_step(mbs_, t):  # noqa: ARG001
        if not kinematic:
            return True
        try:
            command = controller.command(measurement(t))
            paid_out = np.asarray(command.paid_out, dtype=float).reshape(-1)
            rates = np.asarray(command.paid_out_rate, dtype=float).reshape(-1)
            if paid_out.shape != lengths.shape or not (np.all(np.isfinite(paid_out)) and np.all(paid_out > 0.0)):
                raise ValueError(f"the command must be {lengths.size} finite positive lengths, got {command.paid_out!r}")
            winches.set_lengths(paid_out, rates)
        except Exception as err:  # noqa: BLE001 - reported as the cause of the stop, with the partial result
            state["failure"] = (f"controller {controller.name!r} raised at t = {t:.4f} s: "
                                f"{type(err).__name__}: {err}")
            return False
        return True

    def post_step(mbs_, t):  # noqa: ARG001
        state["step_start"] = state["reached"] = t  # the state the solver has for the next step's command
        if interrupted["interrupted"]:
            if t > times[-1]:
                record(float(t))  # the last state computed belongs to the partial result
            return False
        # One sample per step that reaches an output time, with the step's own time, as the
        # planar run records: a real state, labelled when it was. After a shrunk step the
        # steps end up to one step after the output times; the time says so. The step that
        # ends the run is recorded too, so the result ends at the end time, on the output
        # grid or not.
        due = state["next"] < len(outputs) and t >= outputs[state["next"]] - 1e-9
        if due or (t >= solver.end_time - 1e-9 and t > times[-1]):
            record(float(t))
            while state["next"] < len(outputs) and t >= outputs[state["next"]] - 1e-9:
                state["next"] += 1
        position, rotation = platform_pose(mbs, items)
        problem = monitor.problem(t, position, rotation)
        if problem is not None:
            if t > times[-1]:
                record(float(t))  # the state that stopped the run belongs to its result
            state["failure"] = problem
            return False  # ends the integration; what was computed is kept
        if report is not None:
            report(t, _time.perf_counter() - wall_start)
        return True

    report = progress_reporter(progress, scene)
    monitor = _SpatialMonitor(scene)
    record(0.0)
    state["next"] = 1
    # a start no run can come back from: over swivel pulleys, a rest held up by the chains' bending (with its cause)
    state["failure"] = (_rest_above_exits(scene, mbs, items) if any(scene.swivel_exits) else None) \
        or monitor.problem(0.0, *platform_pose(mbs, items))
    mbs.SetPreStepUserFunction(pre_step)
    mbs.SetPostStepUserFunction(post_step)
    wall_start = _time.perf_counter()
    with interrupt_flag() as interrupted, quiet_exudyn():
        try:
            if state["failure"] is None:
                mbs.SolveDynamic(solver_settings(scene, solution_file))
        except (exu.SolverError, RuntimeError, SystemError) as err:  # Exudyn's own cause, not only "terminated"
            state["failure"] = state["failure"] or solver_report(mbs, " ".join(str(err).split()))
    wall = _time.perf_counter() - wall_start
    if report is not None:
        report(None, wall)
    time_array = np.asarray(times)
    pose = np.asarray(poses)
    paid_out = np.asarray(paid)
    nodes = [np.asarray(series) for series in node_series]
    tensions = [np.asarray(series) for series in tension_series]
    solved = mbs.sys.get("dynamicSolver")  # none when the start was refused
    steps, newton = (0, 0) if solved is None else (solved.it.currentStepIndex, solved.it.newtonStepsCount)
    result = Result(scene.name, controller.name if kinematic else "fixed winches", scene.space.dimension, time_array,
                    pose, np.atleast_2d(scene.trajectory.pose(time_array)), nodes, tensions, paid_out,
                    wall_time=wall, steps=int(steps), newton_iterations=int(newton))
    if tension_limits(scene.cables) is not None:  # (t_min, t_max) per cable; JSON has no inf: null is "no limit"
        result.metadata["tension_limits_N"] = [[c.min_tension, c.max_tension] for c in scene.cables]
    result.metadata["highest_exit_z_m"] = float(scene.exit_points[:, 2].max())
    reached = state["reached"]  # the solver's own time: the samples may end up to one output period before it
    if interrupted["interrupted"]:
        result.status, result.failure_time = f"interrupted at t = {reached:.4f} s", reached
        raise RunInterrupted(f"interrupted by the user at t = {reached:.4f} s of {solver.end_time} s",
                             time=reached, partial_result=result)
    elif state["failure"] is not None or reached < solver.end_time - 1e-9 or not np.all(np.isfinite(pose)):
        cause = state["failure"] or "the solution stopped before the end time or contains NaN"
        result.status, result.failure_time = f"failed: {cause}", reached
        raise SolverFailure(f"the spatial run failed at t = {reached:.4f} s of {solver.end_time} s: {cause}",
                            time=reached, partial_result=result)
    return result
