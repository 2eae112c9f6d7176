"""The spatial robot's side of the one run loop (:func:`cdpr_exu.run.simulate.simulate`): :class:`Run3D`.

The robot (:mod:`cdpr_exu.builder.robot_3d`) starts at rest on its elastic-catenary equilibrium (over
swivel pulleys on the lumped robot's own: :func:`cdpr_exu.run.settle.start_at_rest`).

**The winch at a point exit** pays the cable out at a fixed point (over a swivel pulley the winch end
moves along the pulley's axis instead). The lumped cable keeps its n elements and follows its paid-out
length L(t): every element's length, stiffness and damping, the node masses and the bending scale with
L / n before every step, the masses in the weight and in the inertia: Exudyn keeps a mass matrix it counts
as constant (a robot without a rigid body: a point-mass platform's), so the winches have the solver compute it
again when they changed a mass (a rigid platform's is computed every step anyway). Its statics are the
elastic catenary's of length L; it leaves out the flow of material through the exit, an axial motion whose
inertia is small beside the platform's.

Units SI; z up, gravity along -z; poses ``(x, y, z, theta)`` with ``theta`` the platform's rotation vector.
"""

from __future__ import annotations

import time as _time
import warnings

import exudyn as exu
import numpy as np

from controllers.base import Controller, Measurement
from cdpr_exu.builder.robot_3d import Model3D, element_forces, platform_pose
from cdpr_exu.builder.winch import ServoDrums
from cdpr_exu.core.errors import SolverFailure
from cdpr_exu.core.geometry import rotation_from_vector, rotation_vector
from cdpr_exu.physics.swivel_pulley import SwivelStabilityWarning, stability_concerns
from cdpr_exu.results.result import Result
from cdpr_exu.run.settle import start_at_rest
from cdpr_exu.run.solver import output_times, solver_report
from cdpr_exu.run.rest import rest_above_exits
from cdpr_exu.scenes.scene import Scene

__all__ = ["Run3D"]


class _SpatialWinches:
    """The variable-length cables: before each step, every cable's elements follow its paid-out length."""

    def __init__(self, mbs, scene: Scene, items, lengths: np.ndarray):
        self.mbs, self.scene, self.items = mbs, scene, items
        self.n = scene.cables[0].n_elements
        self.applied = np.array(lengths, dtype=float)
        self.rate = np.zeros(len(self.applied))  # the winches' rate [m/s]: the last command's, as planar runs

    def set_lengths(self, lengths: np.ndarray, rates: np.ndarray) -> None:
        """Give every cable the paid-out length ``lengths`` (m,) [m], changing at ``rates`` (m,) [m/s].

        Over a swivel pulley the held winch end moves along the swivel axis instead. The rate goes to each
        element's damper as Exudyn's ``velocityOffset``: the Kelvin-Voigt damper acts on d(l - l0)/dt, so
        a cable paid out without stretching is not damped (without it a CoGiRo cable paid out at 0.25 m/s
        pulls with 740 N).
        """
        mbs, items = self.mbs, self.items
        set_object = mbs.SetObjectParameter
        self.rate = np.array(rates, dtype=float)
        masses_changed = False
        for i, (cable, exit_, chain, length, rate) in enumerate(zip(self.scene.cables, self.scene.exits, items.chains,
                                                                    lengths, rates)):
            if exit_.wraps:  # the winch end moves along the swivel axis: up when paying out
                if length != self.applied[i]:
                    mbs.SetObjectParameter(chain.holds[2], "offset", float(length - items.unstrained_lengths[i]))
                    self.applied[i] = length
                continue
            if chain.tension_only:  # the arrays the cable's numba kernels read
                chain.axial_rest_rate[:] = float(rate) / self.n
            for spring in chain.springs:
                set_object(spring, "velocityOffset", float(rate) / self.n)
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
                set_object(spring, "referenceLength", element)
                set_object(spring, "stiffness", stiffness)
                set_object(spring, "damping", damping)
            # rho l_e per node: the mass matrix of the chains' generic object, and their weight
            np.multiply(items.node_masses[i], float(length) / items.unstrained_lengths[i], out=chain.node_mass)
            masses_changed = True
            if chain.bending_stiffness is not None:
                chain.bending_stiffness[:] = items.bending_stiffnesses[i] * items.unstrained_lengths[i] / self.n / element
            if chain.bending_damping is not None:
                chain.bending_damping[:] = items.bending_dampings[i] * items.unstrained_lengths[i] / self.n / element
            self.applied[i] = length
        if masses_changed:  # the solver reuses the mass matrix it assembled at the start (reuseConstantMassMatrix)
            for forces in {chain.forces for chain in items.chains}:
                forces.masses_changed(mbs)
            mbs.sys["dynamicSolver"].ComputeMassMatrix(mbs)


#: A run stops when the platform has turned farther than this from the reference's orientation [deg]:
#: it has left the workspace (issue 23.5: IPAnema ran on for 566 s to end 175 degrees off).
MAX_ROTATION_ERROR_DEG = 90.0


class _SpatialMonitor:
    """Checks the platform for states the run cannot come back from: not finite or above its highest exit
    (after every step: the position only), turned more than :data:`MAX_ROTATION_ERROR_DEG` from the reference
    (at the start and at every recorded sample: a turn is stopped within one output period)."""

    def __init__(self, scene: Scene):
        self.trajectory = scene.trajectory
        self.ceiling = float(scene.exit_points[:, 2].max())  # above it every cable pulls the platform down
        self.turns = not scene.platform.is_point_mass

    def problem(self, t: float, position: np.ndarray, rotation: np.ndarray | None = None) -> str | None:
        """What is wrong at ``t`` [s] with the platform at ``position`` (3,) [m], ``rotation`` (3, 3) (None:
        not checked)."""
        if not (np.isfinite(position).all() and (rotation is None or np.isfinite(rotation).all())):
            return f"the coordinates are no longer finite at t = {t:.4f} s"
        if position[2] > self.ceiling:
            if t == 0.0:  # where the robot came to rest (over swivel pulleys: the chain statics)
                return (f"the platform rests above its highest exit at t = 0 (z = {position[2]:.3f} m, the exit at "
                        f"{self.ceiling:.3f} m): only cables that push or bend could hold it there, which the "
                        "lumped chains do and a real cable cannot (cables too stiff in bending for their load?)")
            return (f"the platform rose above its highest exit at t = {t:.4f} s (z = {position[2]:.3f} m, the exit at "
                    f"{self.ceiling:.3f} m): only cables that push could hold it there; the run has diverged (a "
                    "winch command that jumps, or a smaller solver.step_size)")
        if self.turns and rotation is not None:
            reference = rotation_from_vector(np.asarray(self.trajectory.pose(t))[3:])
            # the angle between the two exceeds 90 degrees where trace(reference^T rotation) = 1 + 2 cos < 1
            if float(np.vdot(reference, rotation)) < 1.0 + 2.0 * np.cos(np.radians(MAX_ROTATION_ERROR_DEG)):
                angle = np.degrees(np.linalg.norm(rotation_vector(reference.T @ rotation)))
                return (f"the platform turned {angle:.0f} degrees away from the reference's orientation at "
                        f"t = {t:.4f} s (limit {MAX_ROTATION_ERROR_DEG:g}): it has left the workspace the cables hold "
                        "it in; the run is stopped")
        return None


def _warn_outside_measured_region(scene: Scene) -> None:
    """Warn where runs over a swivel pulley were not measured to keep their energy at these settings."""
    solver = scene.solver
    for exit_, cable in zip(scene.exits, scene.cables):
        if not exit_.wraps:
            continue
        for concern in stability_concerns(solver.newton == "modified", solver.spectral_radius, solver.newton_tolerance,
                                          cable.element_length, exit_.radius):
            warnings.warn(concern, SwivelStabilityWarning, stacklevel=4)  # simulate()'s caller
        return


def _rest_above_exits(scene: Scene, mbs, items) -> str | None:
    """Why the robot's rest over swivel pulleys cannot start a run (:func:`rest_above_exits`), or None."""
    position, rotation = platform_pose(mbs, items, current=False)
    lowest = min(float(element_forces(mbs, items, i, current=False).min()) for i in range(scene.n_cables))
    above = rest_above_exits(scene, position, rotation, lowest, items.initial)
    return None if above is None else f"the run cannot start from the robot's rest: {above}"


class Run3D:
    """The spatial robot's side of a run (:data:`~cdpr_exu.run.simulate.RUNS`): the winches follow the
    command before every step; the steps that reach an output time (and the last) are recorded with their
    own time; every step is checked. SolverFailure at t = 0 if settling over swivel pulleys failed.
    """

    def __init__(self, scene: Scene, model: Model3D):
        self.scene, self.model = scene, model
        mbs, items = model.mbs, model.items
        if any(exit_.wraps for exit_ in scene.exits):
            _warn_outside_measured_region(scene)
            try:
                start_at_rest(mbs, items)  # the chain statics' equilibrium (the dynamic settle only if they fail)
            except SolverFailure as failure:  # the settle's solver knows why it stopped
                exudyn_said = str(failure).split(": ", 1)[-1]  # "SolveDynamic terminated", and no more
                raise SolverFailure(f"settling the robot over its swivel pulleys before the run failed: "
                                    f"{solver_report(mbs, exudyn_said)}", time=0.0) from None
        self.winches = _SpatialWinches(mbs, scene, items, model.initial_paid_out)
        self.drums = ServoDrums(mbs, model.servos, model.initial_paid_out)
        for chain in items.chains[:len(model.servos)]:  # the drums hold the winch ends now (builder.robot_3d)
            mbs.SetObjectParameter(chain.holds[2], "activeConnector", False)
        self.monitor = _SpatialMonitor(scene)
        self.outputs = output_times(scene.solver.end_time, scene.solver.output_period)
        m = scene.n_cables
        self.times, self.poses, self.paid, self.nodes, self.tensions = [], [], [], [[] for _ in range(m)], \
            [[] for _ in range(m)]
        # each cable's node coordinates in the system's state vectors: a sample reads those vectors once
        self.coordinates = [np.concatenate([np.arange(3) + mbs.GetNodeODE2Index(node) for node in chain.nodes])
                            for chain in items.chains]
        self.driven = scene.winch.kind != "fixed"
        self.next, self.step_start, self.reached_time = 0, 0.0, 0.0
        self.stop_reason: str | None = None
        self.interrupted = {"interrupted": False}
        self.controller: Controller | None = None
        self.report = None
        self.start = _time.perf_counter()

    def measured_state(self) -> tuple[np.ndarray, np.ndarray]:
        """The platform's pose [m, rad] and its time derivative [m/s, rad/s] now, each shape (6,)."""
        mbs, items = self.model.mbs, self.model.items
        position, rotation = platform_pose(mbs, items)
        velocity = np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.Velocity))
        angular = (np.zeros(3) if items.is_point_mass else
                   np.array(mbs.GetNodeOutput(items.platform_node, exu.OutputVariableType.AngularVelocity)))
        theta = rotation_vector(rotation)
        rate = self.scene.space.rotation_rate(theta, angular)
        return np.concatenate([position, theta]), np.concatenate([velocity, rate])

    def initial_pose(self) -> np.ndarray:
        """The pose the controller starts from: where the robot rests, shape (6,)."""
        return self.measured_state()[0]

    def measurement(self, t: float) -> Measurement:
        """What the controller may see when asked for the command at ``t`` [s]."""
        controller, winches = self.controller, self.winches
        if not (controller.uses_pose or controller.uses_tension):
            return Measurement(t, winches.applied.copy(), winches.rate.copy())
        pose, velocity = self.measured_state()
        # each cable's tension at its platform end: its last element's axial force as the model computes it
        tensions = (np.array([element_forces(self.model.mbs, self.model.items, i)[-1]
                              for i in range(self.scene.n_cables)]) if controller.uses_tension else None)
        return Measurement(t, winches.applied.copy(), winches.rate.copy(), pose, velocity, tensions,
                           state_time=self.step_start)

    def record(self, t: float) -> None:
        """Store the state now (the state vectors read once, not node by node)."""
        mbs, items = self.model.mbs, self.model.items
        position, rotation = platform_pose(mbs, items)
        self.times.append(t)
        self.rotation = rotation  # the monitor checks the turn here (post_step)
        self.poses.append(np.concatenate([position, rotation_vector(rotation)]))
        self.paid.append(self.winches.applied.copy())
        q, v = mbs.systemData.GetODE2Coordinates(), mbs.systemData.GetODE2Coordinates_t()
        for i in range(len(items.chains)):
            positions, forces = self._chain(i, q, v)
            self.nodes[i].append(positions)
            self.tensions[i].append(forces)

    def _chain(self, i: int, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cable ``i``'s node positions (n + 1, 3) [m] and element forces (n,) [N] (spring and damper),
        from the system's state vectors ``q``, ``v`` read once."""
        mbs, items, index = self.model.mbs, self.model.items, self.coordinates[i]
        positions = (items.chains[i].reference + q[index]).reshape(-1, 3)
        return positions, element_forces(mbs, items, i, positions=positions, velocities=v[index])

    def begin(self, controller: Controller, report) -> None:
        """Record the start; a start no run can come back from is the stop reason before the first step."""
        self.controller, self.report = controller, report
        self.record(0.0)
        self.next = 1
        mbs, items = self.model.mbs, self.model.items
        self.stop_reason = (_rest_above_exits(self.scene, mbs, items) if any(exit_.wraps for exit_ in self.scene.exits) else None) \
            or self.monitor.problem(0.0, *platform_pose(mbs, items))
        self.start = _time.perf_counter()

    def pre_step(self, mbs_, t) -> bool:  # noqa: ARG002 - Exudyn's signature
        """Exudyn's pre-step function: command the winches; False stops the run."""
        if not self.driven:
            return True
        try:
            if self.drums.servos:  # the drums measure what they paid out
                q, v = mbs_.systemData.GetODE2Coordinates(), mbs_.systemData.GetODE2Coordinates_t()
                self.winches.applied, self.winches.rate = self.drums.measured(q, v)
            command = self.controller.command(self.measurement(t))
            paid_out = np.asarray(command.paid_out, dtype=float).reshape(-1)
            rates = np.asarray(command.paid_out_rate, dtype=float).reshape(-1)
            lengths = self.model.initial_paid_out
            if paid_out.shape != lengths.shape or not (np.all(np.isfinite(paid_out)) and np.all(paid_out > 0.0)):
                raise ValueError(f"the command must be {lengths.size} finite positive lengths, got {command.paid_out!r}")
            if self.drums.servos:  # fed forward: the tension of each chain's winch element
                winch_ends = [self._chain(i, q, v)[1][0] for i in range(len(paid_out))]
                self.drums.drive(mbs_, t, command, q, v, winch_ends)
            else:
                self.winches.set_lengths(paid_out, rates)
        except Exception as err:  # noqa: BLE001 - reported as the cause of the stop, with the partial result
            self.stop_reason = (f"controller {self.controller.name!r} raised at t = {t:.4f} s: "
                                f"{type(err).__name__}: {err}")
            return False
        return True

    def post_step(self, mbs_, t) -> bool:  # noqa: ARG002 - Exudyn's signature
        """Exudyn's post-step function: record, check, report; False ends the integration."""
        self.step_start = self.reached_time = t  # the state the solver has for the next step's command
        times, outputs = self.times, self.outputs
        if self.interrupted["interrupted"]:
            if t > times[-1]:
                self.record(float(t))  # the last state computed belongs to the partial result
            return False
        due = self.next < len(outputs) and t >= outputs[self.next] - 1e-9
        if due or (t >= self.scene.solver.end_time - 1e-9 and t > times[-1]):
            self.record(float(t))
            while self.next < len(outputs) and t >= outputs[self.next] - 1e-9:
                self.next += 1
        # the position after every step, the turn at the samples (record's rotation)
        position = self.model.mbs.GetNodeOutput(self.model.items.platform_node, exu.OutputVariableType.Position)
        problem = self.monitor.problem(t, np.asarray(position), self.rotation if self.times[-1] == t else None)
        if problem is not None:
            if t > times[-1]:
                self.record(float(t))  # the state that stopped the run belongs to its result
            self.stop_reason = problem
            return False  # ends the integration; what was computed is kept
        if self.report is not None:
            self.report(t, _time.perf_counter() - self.start)
        return True

    def result(self, controller_name: str, failure: str | None) -> Result:  # noqa: ARG002 - every sample is kept
        """What was recorded, as a :class:`Result`."""
        time = np.asarray(self.times)
        return Result(self.scene.name, controller_name if self.driven else "fixed winches",
                      self.scene.space.dimension, time, np.asarray(self.poses),
                      np.atleast_2d(self.scene.trajectory.pose(time)), [np.asarray(s) for s in self.nodes],
                      [np.asarray(s) for s in self.tensions], np.asarray(self.paid))

    def reached(self, result: Result) -> tuple[float, bool]:  # noqa: ARG002
        """The solver's own time [s] (past the last sample) and whether it is the end time."""
        return self.reached_time, self.reached_time >= self.scene.solver.end_time - 1e-9

    def notes(self, failure: str, time: float) -> tuple[str, str]:  # noqa: ARG002
        """Nothing to add to a failure's message."""
        return "", ""
