"""A spatial cable over a swivel pulley in Exudyn.

:func:`add_swivel_pulley` adds, to a chain of :func:`cdpr_exu.builder.chain_3d.add_spatial_chain`,
the swivel coordinate psi [rad] (a ``NodeGenericODE2`` with one coordinate) and one
``ObjectGenericODE2`` over the chain's nodes and psi that carries the swivel's inertia
J_s (its mass matrix), its bearing damping d_s and the contact of
:mod:`cdpr_exu.physics.swivel_pulley`, with the sparse analytic Jacobian (psi rows and
columns included). :func:`run_swivel_pendulum` is the measured scene: a mass on a cable
over the pulley, swinging around the axis. Units SI; z up.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass, field

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.physics import swivel_pulley as sp
from cdpr_exu.builder.chain_3d import SpatialChainItems, add_spatial_chain, chain_energy


@dataclass
class SwivelItems:
    """Item indices of a swivel pulley in Exudyn.

    Attributes
    ----------
    node : int
        The ``NodeGenericODE2`` of psi.
    obj : int
        The ``ObjectGenericODE2`` over the chain's nodes and psi.
    psi_reference : float [rad]
        Reference value of psi (Exudyn's coordinate is the displacement from it).
    contact_nodes : ndarray of int64, shape (C,)
        Chain nodes that can touch the pulley.
    user_functions : tuple
        Keeps the Python callables alive as long as the model.
    """

    node: int
    obj: int
    psi_reference: float
    contact_nodes: np.ndarray
    user_functions: tuple = field(default_factory=tuple)


def _sparse(triplets, size):
    container = exu.MatrixContainer()
    container.SetWithSparseMatrix(np.asarray(triplets, dtype=float).reshape(-1, 3), numberOfRows=size,
                                  numberOfColumns=size, useDenseMatrix=False)
    return container


def add_swivel_pulley(mbs: exu.MainSystem, chain: SpatialChainItems, pulley: sp.SwivelPulley, psi: float = 0.0,
                      psi_rate: float = 0.0, contact_nodes=None) -> SwivelItems:
    """Add a swivel pulley under the nodes of ``chain``.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    chain : SpatialChainItems
    pulley : SwivelPulley
    psi, psi_rate : float [rad, rad/s]
        Initial swivel angle and rate.
    contact_nodes : array_like of int, shape (C,), optional
        Chain nodes (0-based within the chain) that can touch the pulley; all by default.
    """
    n_points = len(chain.nodes)
    nodes = (np.arange(n_points) if contact_nodes is None else np.asarray(contact_nodes)).astype(np.int64)
    size = 3 * n_points + 1
    last = size - 1
    psi_node = mbs.AddNode(eii.NodeGenericODE2(numberOfODE2Coordinates=1, referenceCoordinates=[float(psi)],
                                                initialCoordinates=[0.0], initialCoordinates_t=[float(psi_rate)]))
    inlet = pulley.inlet_array
    args = (nodes, inlet, pulley.radius, pulley.groove_radius, pulley.flange_height, pulley.contact_stiffness,
            pulley.contact_damping, pulley.onset_band)
    reference = chain.reference
    positions = np.zeros(3 * n_points)
    velocities = np.zeros(3 * n_points)
    force = np.zeros(size)
    rows, columns = sp.swivel_contact_pattern(nodes, size)
    triplets = np.zeros((rows.size + 1, 3))
    triplets[:-1, 0], triplets[:-1, 1] = rows, columns
    triplets[-1, :2] = last
    values = np.zeros(rows.size)
    container = exu.MatrixContainer()
    bearing = pulley.bearing_damping
    psi_reference = float(psi)

    def _state(q, q_t):
        q = np.asarray(q)
        q_t = np.asarray(q_t)
        np.add(reference, q[:last], out=positions)
        velocities[:] = q_t[:last]
        return psi_reference + q[last], q_t[last]

    def force_function(mbs_, t, item, q, q_t):  # noqa: ARG001 - Exudyn's signature
        angle, rate = _state(q, q_t)
        force[:] = 0.0
        sp.swivel_contact_force(positions, velocities, angle, rate, *args, force)
        force[last] -= bearing * rate
        return force

    def jacobian_function(mbs_, t, item, q, q_t, f_q, f_q_t):  # noqa: ARG001
        angle, rate = _state(q, q_t)
        triplets[:-1, 2] = sp.swivel_contact_values(positions, velocities, angle, rate, *args, float(f_q),
                                                    float(f_q_t), values)
        triplets[-1, 2] = float(f_q_t) * bearing
        container.SetWithSparseMatrix(triplets, numberOfRows=size, numberOfColumns=size, useDenseMatrix=False)
        return container

    mass = _sparse([[last, last, pulley.swivel_inertia]], size)
    obj = mbs.AddObject(eii.ObjectGenericODE2(nodeNumbers=list(chain.nodes) + [psi_node], massMatrix=mass,
                                               forceUserFunction=force_function,
                                               jacobianUserFunction=jacobian_function))
    return SwivelItems(psi_node, obj, psi_reference, nodes, (force_function, jacobian_function, container, mass))


def swivel_energy(items: SwivelItems, chain: SpatialChainItems, pulley: sp.SwivelPulley, q_chain: np.ndarray,
                  psi_displacement: float, psi_rate: float) -> float:
    """Energy [J] the swivel adds: contact potential and J_s psi_dot^2 / 2 (q_chain: displacements (3N,))."""
    positions = chain.reference + q_chain
    potential = sp.swivel_contact_energy(positions, items.psi_reference + psi_displacement, items.contact_nodes,
                                         pulley.inlet_array, pulley.radius, pulley.groove_radius,
                                         pulley.flange_height, pulley.contact_stiffness, pulley.onset_band)
    return potential + 0.5 * pulley.swivel_inertia * psi_rate**2


@dataclass
class SwivelRun:
    """Histories of a run of :func:`run_swivel_pendulum` (one row per step, t = 0 first).

    Attributes
    ----------
    time : ndarray (S,) [s]
    energy : ndarray (S,) [J]
        Mechanical energy: kinetic (nodes and swivel), gravity, axial, bending, contact.
    dissipated : ndarray (S,) [J]
        Energy taken out by the bearing so far, integral d_s psi_dot^2 dt (trapezoidal).
    psi : ndarray (S,) [rad]
    mass_azimuth : ndarray (S,) [rad]
        Azimuth of the end mass seen from the axis (where ideal kinematics puts psi).
    in_contact : ndarray (S,) of int
        Nodes touching the pulley.
    positions : ndarray (S', N, 3) [m]
        Node positions every ``record_every`` rows (the first row included).
    final_positions : ndarray (N, 3) [m]
        Node positions at the last step.
    newton_iterations, steps : int
    wall_time : float [s]
    failed : str
        Empty, or why the run stopped early (the solver's error, or the energy rose by more
        than ``abort_rise``).
    guard_rejections : int
        Steps repeated smaller by the energy guard (``energy_guard``).
    """

    time: np.ndarray
    energy: np.ndarray
    dissipated: np.ndarray
    psi: np.ndarray
    mass_azimuth: np.ndarray
    in_contact: np.ndarray
    positions: np.ndarray
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
                        psi: float = 0.0, psi_offset: float = 0.0, swing: bool = True, rate_factor: float = 1.0,
                        spectral_radius: float = 0.5, gravity: float = 9.81, record_every: int = 1,
                        newton_tolerance: float = 1e-10, verbose: int = 0, initial_accelerations: bool = True,
                        adaptive: bool = True, abort_rise: float = math.inf,
                        settle_statically: bool = False, max_newton_iterations: int = 25,
                        energy_guard: float | None = None, modified_newton: bool = False) -> SwivelRun:
    """Run a mass on a cable over a swivel pulley: a conical pendulum (``swing``) or a hang.

    The cable (held at ``winch_length`` [m] below the inlet on the axis) comes up the axis,
    wraps the disc at azimuth ``psi`` and leaves at ``cone_angle`` [rad] from the vertical
    for ``free_length`` [m] to the ``end_mass`` [kg]. With ``swing`` the whole cable and the
    swivel start turning rigidly about the axis at the conical pendulum's rate
    omega = rate_factor sqrt(g tan(angle) / R), R the mass's distance from the axis (1: a circle;
    less: the mass swings in and out, its azimuth rate varies); the swivel starts at
    ``psi + psi_offset``. Step ``step`` [s], generalized-alpha with ``spectral_radius``,
    full Newton (or modified, Jacobian each step, with ``modified_newton``); no damping but
    the bearing's (and ``axial_damping`` [N s/m] per element).
    With ``settle_statically``, Exudyn's static solver then starts from the final state, and
    ``final_positions`` and the last ``psi`` are its rest state. With ``energy_guard`` [J],
    a step whose Newton solution gains more than that over the last accepted step is
    repeated at a quarter of its size (down to step / 1000).
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
    chain = add_spatial_chain(mbs, path, masses, axial_stiffness, axial_damping, bending_stiffness, gravity)
    inlet = pulley.inlet_array
    reach = math.hypot(path[-1, 0] - inlet[0], path[-1, 1] - inlet[1])
    omega = math.sqrt(gravity * math.tan(cone_angle) / reach) if swing and cone_angle > 0.0 else 0.0
    omega *= rate_factor
    swivel = add_swivel_pulley(mbs, chain, pulley, psi + psi_offset, omega)
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
    ti.verboseMode = verbose
    ti.generalizedAlpha.spectralRadius = spectral_radius
    ti.generalizedAlpha.computeInitialAccelerations = initial_accelerations
    ti.newton.useModifiedNewton = modified_newton
    ti.newton.modifiedNewtonJacUpdatePerStep = True  # as the planar runs (cdpr_exu.simulate)
    ti.newton.relativeTolerance = newton_tolerance
    ti.newton.maxIterations = max_newton_iterations
    # Exudyn halves the step where Newton fails (a node entering the stiff contact) and
    # grows it back; the steps taken are reported (SwivelRun.steps).
    ti.adaptiveStep = adaptive
    ti.minimumStepSize = step * 1e-4
    settings.solution.file.write = False
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse

    chain_index = np.array([mbs.GetNodeODE2Index(node) + k for node in chain.nodes for k in range(3)])
    psi_index = mbs.GetNodeODE2Index(swivel.node)
    rows = {key: [] for key in ("time", "energy", "psi", "azimuth", "contact", "positions", "rate")}
    bending = 0.0 if chain.bending is None else bending_stiffness

    def state(mbs_, configuration):
        q_all = np.asarray(mbs_.systemData.GetODE2Coordinates(configuration))
        v_all = np.asarray(mbs_.systemData.GetODE2Coordinates_t(configuration))
        q, v = q_all[chain_index], v_all[chain_index]
        dpsi, rate = float(q_all[psi_index]), float(v_all[psi_index])
        energy = chain_energy(chain, masses, q, v, axial_stiffness, bending, gravity)
        energy += swivel_energy(swivel, chain, pulley, q, dpsi, rate)
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
        if len(rows["time"]) % record_every == 1 or record_every == 1:
            rows["positions"].append(points.copy())
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
            """Repeat a step at a quarter of its size if its converged state gained more than
            ``energy_guard`` [J]: nothing in this scene can supply energy (no moving winch)."""
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
        static = exu.SimulationSettings()
        static.staticSolver.newton.relativeTolerance = 1e-10
        static.staticSolver.newton.absoluteTolerance = 1e-12
        static.staticSolver.newton.maxIterations = 50
        static.linearSolver.solverType = exu.LinearSolverType.EigenSparse
        static.solution.file.write = False
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
                     np.unwrap(np.array(rows["azimuth"])), np.array(rows["contact"]),
                     np.array(rows["positions"]), last.copy(),
                     int(iterations), int(steps), wall, failed, rejected[0])
