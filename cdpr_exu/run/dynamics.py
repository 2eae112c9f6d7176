"""Dynamic runs of an assembled spatial robot (:func:`run_dynamic`) or of one cable over a swivel
pulley (:func:`run_swivel_pendulum`), for tests and benchmarks; a scene runs in
:func:`cdpr_exu.run.simulate.simulate`. Units SI; z up.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass

import exudyn as exu
import numpy as np

from cdpr_exu.builder.chain_3d import ChainForces, add_spatial_chain, chain_energy
from cdpr_exu.builder.robot_3d import platform_pose, robot_energy
from cdpr_exu.run.settle import dynamic_settings, static_settings
from cdpr_exu.builder.swivel_chain import add_swivel_pulley, swivel_energy
from cdpr_exu.core.errors import SolverFailure
from cdpr_exu.core.geometry import rotation_vector
from cdpr_exu.core.validation import positive
from cdpr_exu.physics import swivel_pulley as sp


@dataclass(frozen=True, eq=False)
class SpatialRunResult:
    """A dynamic run at each step's start and the end: ``time`` (k,) [s], the platform's ``position`` (k, 3)
    [m] and ``rotation_vector`` (k, 3) [rad], ``energy`` (k,) [J] if asked, ``wall_time`` [s]."""

    time: np.ndarray
    position: np.ndarray
    rotation_vector: np.ndarray
    energy: np.ndarray | None
    wall_time: float
    newton_iterations: int


def run_dynamic(mbs, items, end_time, step_size, spectral_radius=0.9, record_energy=False, settings=None):
    """Integrate the assembled robot from its initial configuration over ``end_time`` at ``step_size`` [s],
    with :func:`robot_energy` at every step if ``record_energy``; SolverFailure if it fails."""
    end_time, step_size = positive("end_time", end_time), positive("step_size", step_size)
    settings = dynamic_settings(end_time, step_size, spectral_radius) if settings is None else settings
    times, positions, rotations, energies = [], [], [], []

    def record(mbs_, t):
        position, rotation = platform_pose(mbs_, items)
        times.append(t)
        positions.append(position)
        rotations.append(rotation_vector(rotation))
        if record_energy:
            energies.append(robot_energy(mbs_, items))
        return True

    mbs.SetPreStepUserFunction(record)
    start = time.perf_counter()
    try:
        mbs.SolveDynamic(settings)
    except (exu.SolverError, RuntimeError, SystemError) as error:
        raise SolverFailure(f"Exudyn's dynamic solver failed: {error}") from None
    finally:
        mbs.SetPreStepUserFunction(0)
    wall_time = time.perf_counter() - start
    record(mbs, float(mbs.systemData.GetTime()))
    iterations = int(mbs.sys["dynamicSolver"].it.newtonStepsCount) if "dynamicSolver" in mbs.sys else -1
    return SpatialRunResult(np.array(times), np.array(positions), np.array(rotations),
                            np.array(energies) if record_energy else None, wall_time, iterations)


@dataclass
class SwivelRun:
    """Histories of a run of :func:`run_swivel_pendulum`, one row per step (t = 0 first).

    Attributes
    ----------
    time, psi, energy : ndarray (S,) [s], [rad], [J]
    dissipated : ndarray (S,) [J]
        Energy taken out by the bearing so far, integral d_s psi_dot^2 dt (trapezoidal).
    mass_azimuth : ndarray (S,) [rad]
        Azimuth of the end mass seen from the axis (where ideal kinematics puts psi).
    in_contact : ndarray (S,) of int
        Nodes touching the pulley.
    final_positions : ndarray (N, 3) [m]
    failed : str
        Empty, or why the run stopped early (the solver's error, or an energy rise above ``abort_rise``).
    """

    time: np.ndarray
    energy: np.ndarray
    dissipated: np.ndarray
    psi: np.ndarray
    mass_azimuth: np.ndarray
    in_contact: np.ndarray
    final_positions: np.ndarray
    newton_iterations: int
    steps: int
    wall_time: float
    failed: str = ""
    guard_rejections: int = 0

    @property
    def energy_rise(self) -> float:
        """Largest rise of the mechanical energy above its start [J] (0 if it never rises)."""
        return float(max(0.0, np.max(self.energy - self.energy[0])))

    @property
    def balance_error(self) -> float:
        """Largest |E(t) + dissipated(t) - E(0)| [J]: energy the scheme made or lost."""
        return float(np.max(np.abs(self.energy + self.dissipated - self.energy[0])))

    @property
    def iterations_per_step(self) -> float:
        """Newton iterations per step taken (those of repeated or halved steps included)."""
        return self.newton_iterations / max(1, self.steps)


def run_swivel_pendulum(pulley: sp.SwivelPulley, step: float, end_time: float, *, end_mass: float = 2.0,
                        cone_angle: float = math.radians(30.0), free_length: float = 1.0,
                        winch_length: float = 0.3, element_length: float = 0.05, cable_radius: float = 0.002,
                        youngs_modulus: float = 1.0e9, linear_density: float = 0.05, axial_damping: float = 0.0,
                        psi: float = 0.0, swing: bool = True, rate_factor: float = 1.0,
                        spectral_radius: float = 0.5, gravity: float = 9.81, newton_tolerance: float = 1e-10,
                        abort_rise: float = math.inf,
                        settle_statically: bool = False, energy_guard: float | None = None,
                        modified_newton: bool = False) -> SwivelRun:
    """Run a mass on a cable over a swivel pulley: a conical pendulum (``swing``) or a hang.

    The cable (held at ``winch_length`` [m] below the inlet on the axis) comes up the axis, wraps the
    disc at azimuth ``psi`` and leaves at ``cone_angle`` [rad] from the vertical for ``free_length`` [m]
    to the ``end_mass`` [kg]. With ``swing`` the cable and the swivel start turning rigidly about the
    axis at omega = rate_factor sqrt(g tan(angle) / R), R the mass's distance from the axis (1: the
    conical pendulum's circle; less: the mass swings in and out). Step ``step`` [s], adaptive,
    generalized-alpha at ``spectral_radius``, full (or ``modified_newton``) Newton; no damping but the
    bearing's and ``axial_damping`` [N s/m]. With ``settle_statically``, Exudyn's static solver then
    starts from the final state (``final_positions`` and the last ``psi`` are its rest). With
    ``energy_guard`` [J], a step that gains more than that is repeated at a quarter of its size (down to
    step / 1000).
    """
    if energy_guard is None:
        for concern in sp.stability_concerns(modified_newton, spectral_radius, newton_tolerance, element_length,
                                             pulley.radius):
            warnings.warn(concern + "; set energy_guard", sp.SwivelStabilityWarning, stacklevel=2)
    path = sp.cable_path_over_swivel(pulley, psi, winch_length, free_length, cone_angle, element_length)
    spacing = np.linalg.norm(np.diff(path, axis=0), axis=1)
    masses = np.zeros(len(path))
    masses[:-1] += 0.5 * linear_density * spacing
    masses[1:] += 0.5 * linear_density * spacing
    masses[-1] += end_mass
    area = math.pi * cable_radius**2
    length = float(np.mean(spacing))
    axial_stiffness = youngs_modulus * area / length
    bending_stiffness = youngs_modulus * math.pi * cable_radius**4 / 4.0 / length

    container = exu.SystemContainer()
    mbs = container.AddSystem()
    chain = add_spatial_chain(mbs, path, masses, axial_stiffness, axial_damping, bending_stiffness, gravity,
                              forces=False)
    inlet = pulley.inlet_array
    reach = math.hypot(path[-1, 0] - inlet[0], path[-1, 1] - inlet[1])
    omega = math.sqrt(gravity * math.tan(cone_angle) / reach) if swing and cone_angle > 0.0 else 0.0
    omega *= rate_factor
    swivel = add_swivel_pulley(mbs, chain, pulley, psi, omega)
    ChainForces(mbs, [chain], gravity, swivels=[swivel])
    mbs.Assemble()
    n3 = 3 * len(path)
    if omega:
        relative = path - inlet
        rates = omega * np.column_stack([-relative[:, 1], relative[:, 0], np.zeros(len(path))])
        start = np.asarray(mbs.systemData.GetODE2Coordinates_t(exu.ConfigurationType.Initial))
        index = [mbs.GetNodeODE2Index(node) for node in chain.nodes]
        for i, node_index in enumerate(index):
            start[node_index:node_index + 3] = rates[i]
        mbs.systemData.SetODE2Coordinates_t(start, exu.ConfigurationType.Initial)

    settings = exu.SimulationSettings()
    ti = settings.timeIntegration
    ti.numberOfSteps = int(round(end_time / step))
    ti.endTime = end_time
    ti.generalizedAlpha.spectralRadius = spectral_radius
    ti.newton.useModifiedNewton = modified_newton
    ti.newton.modifiedNewtonJacUpdatePerStep = True  # as the planar runs (cdpr_exu.simulate)
    ti.newton.relativeTolerance = newton_tolerance
    # Exudyn's adaptive step (its default) halves the step where Newton fails (a node entering the
    # stiff contact) and grows it back; the steps taken are reported (SwivelRun.steps).
    ti.minimumStepSize = step * 1e-4
    settings.solution.file.write = False
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse

    chain_index = np.array([mbs.GetNodeODE2Index(node) + k for node in chain.nodes for k in range(3)])
    psi_index = mbs.GetNodeODE2Index(swivel.node)
    rows = {key: [] for key in ("time", "energy", "psi", "azimuth", "contact", "rate")}
    bending = 0.0 if chain.bending is None else bending_stiffness

    def state(mbs_, configuration):
        q_all = np.asarray(mbs_.systemData.GetODE2Coordinates(configuration))
        v_all = np.asarray(mbs_.systemData.GetODE2Coordinates_t(configuration))
        q, v = q_all[chain_index], v_all[chain_index]
        dpsi, rate = float(q_all[psi_index]), float(v_all[psi_index])
        energy = chain_energy(chain, masses, q, v, axial_stiffness, bending, gravity)
        energy += swivel_energy(swivel, q, dpsi, rate)
        return q, dpsi, rate, energy

    def record(mbs_, t, configuration=exu.ConfigurationType.Current):
        q, dpsi, rate, energy = state(mbs_, configuration)
        accepted[0] = energy
        points = (chain.reference + q).reshape(-1, 3)
        force = sp.swivel_contact_force(points.ravel().copy(), np.zeros(n3), swivel.psi_reference + dpsi, 0.0,
                                        *(swivel.contact_nodes, inlet, pulley.radius, pulley.groove_radius,
                                          pulley.flange_height, pulley.contact_stiffness, 0.0, pulley.onset_band),
                                        np.zeros(n3 + 1))
        rows["time"].append(t)
        rows["energy"].append(energy)
        rows["psi"].append(swivel.psi_reference + dpsi)
        rows["rate"].append(rate)
        rows["azimuth"].append(sp.exit_azimuth(points[-1], inlet))
        rows["contact"].append(int(np.count_nonzero(np.any(force[:n3].reshape(-1, 3) != 0.0, axis=1))))
        last[:] = points
        if energy - rows["energy"][0] > abort_rise:
            aborted.append(t)
            return False  # stops the run
        return True

    aborted = []
    accepted = [0.0]  # energy after the last accepted step [J]
    rejected = [0]
    last = np.zeros((len(path), 3))
    record(mbs, 0.0, exu.ConfigurationType.Initial)
    mbs.SetPostStepUserFunction(record)
    if energy_guard is not None:
        minimum = step * 1e-3

        def guard(mbs_, t):
            """Repeat a step that gained more than ``energy_guard`` (no moving winch supplies energy)."""
            size = mbs_.sys["dynamicSolver"].it.currentStepSize
            if state(mbs_, exu.ConfigurationType.Current)[3] - accepted[0] > energy_guard and size > minimum:
                rejected[0] += 1
                return [1e3, max(minimum, 0.25 * size)]  # an error above the goal: repeat the step
            return [0.0, -1.0]

        mbs.SetPostNewtonUserFunction(guard)
    failed = ""
    started = time.perf_counter()
    try:
        mbs.SolveDynamic(settings)
    except Exception as error:  # noqa: BLE001 - exu.SolverError and friends: report, keep what ran
        failed = f"{type(error).__name__}: {error}"[:300]
    wall = time.perf_counter() - started
    if settle_statically and not failed and not aborted:
        # Exudyn's static solver from where the run ended: the rest state without a swing left
        mbs.SetPostStepUserFunction(0)
        mbs.systemData.SetODE2Coordinates(mbs.systemData.GetODE2Coordinates(), exu.ConfigurationType.Initial)
        static = static_settings(1e-10)
        static.staticSolver.newton.absoluteTolerance = 1e-12
        mbs.SolveStatic(static)
        q_all = np.asarray(mbs.systemData.GetODE2Coordinates())
        last[:] = (chain.reference + q_all[chain_index]).reshape(-1, 3)
        rows["psi"][-1] = swivel.psi_reference + float(q_all[psi_index])
    if aborted and not failed:
        failed = f"aborted at t = {aborted[0]:.4g} s: energy rose by more than {abort_rise:g} J"
    iterations = mbs.sys["dynamicSolver"].it.newtonStepsCount if "dynamicSolver" in mbs.sys else -1
    steps = mbs.sys["dynamicSolver"].it.currentStepIndex if "dynamicSolver" in mbs.sys else len(rows["time"]) - 1
    t = np.array(rows["time"])
    rate = np.array(rows["rate"])
    power = pulley.bearing_damping * rate**2
    dissipated = np.concatenate([[0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))])
    return SwivelRun(t, np.array(rows["energy"]), dissipated, np.unwrap(np.array(rows["psi"])),
                     np.unwrap(np.array(rows["azimuth"])), np.array(rows["contact"]), last.copy(),
                     int(iterations), int(steps), wall, failed, rejected[0])
