"""Bringing a built spatial robot (:mod:`cdpr_exu.builder.robot_3d`) to rest before a run, and the static
and dynamic solver settings of those runs.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import exudyn as exu
import numpy as np
from exudyn.rigidBodyUtilities import RotationMatrix2EulerParameters

from cdpr_exu.builder.robot_3d import anchor_forces, anchor_points, chain_positions, platform_pose, swivel_angles
from cdpr_exu.core.errors import SolverFailure, UnreachableError
from cdpr_exu.core.geometry import rotation_vector
from cdpr_exu.run.solver import quiet_exudyn
from cdpr_exu.statics.chain_statics import ChainCable, ChainRobot, solve_chain_statics


@dataclass(frozen=True, eq=False)
class SpatialStaticResult:
    """Exudyn's static solution of the lumped robot: the platform's pose, the joint reactions on it
    ``forces_on_platform`` (m, 3) [N] at ``anchor_points`` (m, 3) [m] and their norms ``tensions_at_anchor``
    (m,) [N] (what a load cell reads: the catenary's ``tension_at_anchor`` to O(n^-2))."""

    position: np.ndarray
    rotation: np.ndarray
    rotation_vector: np.ndarray
    forces_on_platform: np.ndarray
    anchor_points: np.ndarray
    tensions_at_anchor: np.ndarray
    wall_time: float


def static_settings(tolerance=1e-9):
    """Settings of Exudyn's static solver (one load step, Newton to ``tolerance``), planar or spatial."""
    settings = exu.SimulationSettings()
    settings.solution.file.write = False  # else Exudyn writes solution/ into the working folder
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    static = settings.staticSolver
    static.verboseMode = 0
    static.numberOfLoadSteps = 1
    static.newton.maxIterations = 50
    static.newton.relativeTolerance = tolerance
    static.newton.absoluteTolerance = tolerance
    return settings


#: How long :func:`settle` integrates a robot over swivel pulleys [s], and at what step.
SETTLE_TIME, SETTLE_STEP = 0.5, 5.0e-3


def settle(mbs, items, duration=SETTLE_TIME, step_size=SETTLE_STEP):
    """Let the assembled robot come to rest from its initial configuration and make that its start.

    The fallback of :func:`start_at_rest`, whose chain statics find the same equilibrium 200 times
    faster (benchmarks/results/swivel_start.md). After this settle (zero initial accelerations: the
    consistent ones put tens of joules into the first step) Exudyn's static solver, which does not
    converge from the catenary start over a swivel pulley, takes the state to its equilibrium (the
    Kelvin-Voigt creep leaves it millimetres off); where it fails, with a ``RuntimeWarning``.
    """
    settings = dynamic_settings(duration, step_size, spectral_radius=0.0, tolerance=1e-6)
    ti = settings.timeIntegration
    ti.newton.useModifiedNewton = True
    ti.newton.modifiedNewtonJacUpdatePerStep = True
    ti.adaptiveStep = True
    ti.minimumStepSize = step_size * 1e-4
    ti.generalizedAlpha.computeInitialAccelerations = False
    try:
        with quiet_exudyn():
            mbs.SolveDynamic(settings)
    except (exu.SolverError, RuntimeError, SystemError) as error:
        raise SolverFailure(f"settling the robot over its swivel pulleys failed: {error}") from None
    settled = _start_at_rest(mbs)
    try:
        solve_static(mbs, items)
    except SolverFailure as failure:
        mbs.systemData.SetODE2Coordinates(settled, exu.ConfigurationType.Current)  # not where Newton wandered
        warnings.warn(f"the robot starts from its dynamic settle, not from its static equilibrium "
                      f"(the Kelvin-Voigt creep leaves it millimetres off): {failure}", RuntimeWarning, stacklevel=2)
    _start_at_rest(mbs)


def _start_at_rest(mbs):
    """Make the current configuration the initial one, at rest, at time 0; returns its coordinates."""
    state = np.asarray(mbs.systemData.GetODE2Coordinates())
    mbs.systemData.SetODE2Coordinates(state, exu.ConfigurationType.Initial)
    mbs.systemData.SetODE2Coordinates_t(np.zeros_like(state), exu.ConfigurationType.Initial)
    mbs.systemData.SetODE2Coordinates(state, exu.ConfigurationType.Current)
    mbs.systemData.SetODE2Coordinates_t(np.zeros_like(state), exu.ConfigurationType.Current)
    mbs.systemData.SetTime(0.0, exu.ConfigurationType.Initial)
    return state


def chain_statics_robot(mbs, items) -> ChainRobot:
    """The chain statics' model of a built, assembled robot, read from its items (first nodes held where
    the initial configuration has them)."""
    platform, chain = items.platform, items.chain
    cables = []
    for i, cable in enumerate(platform.cables):
        held = chain_positions(mbs, items, i, current=False)[0]
        cables.append(ChainCable(
            exit_point=held, node_masses=tuple(float(m) for m in items.node_masses[i]),
            element_length=float(items.unstrained_lengths[i]) / chain.n_elements,
            axial_stiffness=float(items.axial_stiffnesses[i]), bending_stiffness=float(items.bending_stiffnesses[i]),
            slack=chain.tension_only, anchor=cable.anchor,
            pulley=items.swivel_pulleys[i], winch_elements=int(items.winch_elements[i])))
    return ChainRobot(tuple(cables), platform.mass, platform.gravity, chain.anchor_spring_factor)


def set_configuration(mbs, items, equilibrium):
    """Put the assembled robot at rest in a chain-statics ``equilibrium``, initial and current."""
    q = np.array(mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Initial))
    for spec, nodes in zip(items.chains, equilibrium.nodes):
        displacement = np.asarray(nodes, float).ravel() - spec.reference
        for k, node in enumerate(spec.nodes):
            index = mbs.GetNodeODE2Index(node)
            q[index:index + 3] = displacement[3 * k:3 * k + 3]
    for swivel, psi in zip(items.swivels or [], equilibrium.swivel_angles):
        if swivel is not None:
            q[mbs.GetNodeODE2Index(swivel.node)] = float(psi) - swivel.psi_reference
    index = mbs.GetNodeODE2Index(items.platform_node)
    reference = np.asarray(mbs.GetNodeParameter(items.platform_node, "referenceCoordinates"), float)
    q[index:index + 3] = np.asarray(equilibrium.position, float) - reference[:3]
    if not items.is_point_mass:
        parameters = np.asarray(RotationMatrix2EulerParameters(np.asarray(equilibrium.rotation, float)), float)
        if float(parameters @ reference[3:7]) < 0.0:
            parameters = -parameters  # the same rotation, nearest the reference
        q[index + 3:index + 7] = parameters - reference[3:7]
    mbs.systemData.SetODE2Coordinates(q, exu.ConfigurationType.Current)
    _start_at_rest(mbs)


@dataclass(frozen=True, eq=False)
class RestStart:
    """How :func:`start_at_rest` brought the robot to rest: ``method`` "chain statics" or "dynamic settle",
    the chain ``statics``' equilibrium (None after the fallback), the largest change of a coordinate by
    Exudyn's static solver ``polish_shift`` [m, rad] (None: not polished)."""

    method: str
    statics: object
    polish_shift: float | None


def start_at_rest(mbs, items, max_iterations: int = 100) -> RestStart:
    """Bring the assembled robot from its initial (catenary) configuration to its static equilibrium by the
    chain statics and make that its start.

    The chain statics (on :func:`chain_statics_robot`, the same discrete model, at most
    ``max_iterations`` Newton steps) solve the robot over swivel pulleys, where Exudyn's static solver
    does not converge from the catenary start; Exudyn's static solver then polishes that state (1e-15),
    except on a rigid platform on exact spherical joints, where it diverges. If the chain statics fail,
    :func:`settle` is the fallback; if the polish fails, their state is the start; either with a
    ``RuntimeWarning``.
    """
    robot = chain_statics_robot(mbs, items)
    start = ([chain_positions(mbs, items, i, current=False) for i in range(len(items.chains))],
             *platform_pose(mbs, items, current=False), swivel_angles(mbs, items, current=False))
    try:
        statics = solve_chain_statics(robot, *start, max_iterations=max_iterations)
    except UnreachableError as failure:
        warnings.warn(f"the chain statics found no equilibrium ({failure}); the robot is brought to rest by the "
                      "dynamic settle instead (slower)", RuntimeWarning, stacklevel=2)
        settle(mbs, items)
        return RestStart("dynamic settle", None, None)
    set_configuration(mbs, items, statics)
    if not items.is_point_mass and items.chain.anchor_spring_factor is None:
        return RestStart("chain statics", statics, None)  # Exudyn's static solver diverges on these joints
    before = np.asarray(mbs.systemData.GetODE2Coordinates())
    try:
        solve_static(mbs, items)
    except SolverFailure as failure:
        set_configuration(mbs, items, statics)
        warnings.warn(f"Exudyn's static solver did not confirm the chain statics' equilibrium ({failure}); the robot "
                      "starts from the chain statics' state", RuntimeWarning, stacklevel=2)
        return RestStart("chain statics", statics, None)
    after = _start_at_rest(mbs)
    return RestStart("chain statics", statics, float(np.abs(after - before).max()))


def solve_static(mbs, items, settings=None):
    """Exudyn's static equilibrium of the assembled robot from its initial configuration; SolverFailure if
    it does not converge (as on a rigid platform on exact spherical joints)."""
    settings = static_settings() if settings is None else settings
    hint = ("" if items.is_point_mass or items.chain.anchor_spring_factor is not None else
            " (a rigid platform on exact spherical joints: set ChainSpec3D.anchor_spring_factor)")
    start = time.perf_counter()
    try:
        with quiet_exudyn():  # a failed static solve prints a page of hints
            converged = bool(mbs.SolveStatic(settings, showHints=False, showCausingItems=False))
    except (exu.SolverError, RuntimeError, SystemError) as error:
        raise SolverFailure(f"Exudyn's static solver failed: {error}{hint}") from None
    wall_time = time.perf_counter() - start
    if not converged:
        raise SolverFailure(f"Exudyn's static solver did not converge{hint}")
    position, rotation = platform_pose(mbs, items)
    forces = anchor_forces(mbs, items)
    return SpatialStaticResult(position, rotation, rotation_vector(rotation), forces, anchor_points(mbs, items),
                               np.linalg.norm(forces, axis=1), wall_time)


def dynamic_settings(end_time, step_size, spectral_radius=0.9, tolerance=1e-8):
    """Settings of the implicit generalised-alpha integrator at a fixed step, full Newton."""
    settings = exu.SimulationSettings()
    settings.solution.file.write = False
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    ti = settings.timeIntegration
    ti.endTime = float(end_time)
    ti.numberOfSteps = int(round(end_time / step_size))
    ti.verboseMode = 0
    ti.adaptiveStep = False
    ti.generalizedAlpha.spectralRadius = float(spectral_radius)
    ti.newton.useModifiedNewton = False
    ti.newton.relativeTolerance = tolerance
    ti.newton.absoluteTolerance = tolerance
    ti.newton.maxIterations = 25
    return settings
