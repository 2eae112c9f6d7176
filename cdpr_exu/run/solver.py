"""What the run loop, each dimension's run side and the static mode share: Exudyn's settings and
console, Ctrl-C, the output times, the solver's report of a failure and its likely cause, the progress
bar. Below :mod:`cdpr_exu.run.simulate` and :mod:`cdpr_exu.run.run_3d`, so that neither imports the other.
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading
from pathlib import Path

import exudyn as exu
import numpy as np

from cdpr_exu.scenes.scene import Scene
from cdpr_exu.space import PLANE, SPACE

#: Whether modified Newton computes its Jacobian again at every step, by Space (always where an exit wraps).
#: A spatial robot at point exits converges with a Jacobian kept over steps: spatial-cogiro 2.7 Newton
#: iterations and 0.04 Jacobians per step instead of 1 and 1, x1.6 CPU, the path moved by 1e-5 mm. Without it the
#: swivel run takes 957 steps instead of 442 (x0.7), the planar paper circle at 60 elements and 1e-2 s 17.8 Newton
#: iterations and 10.6 Jacobians per step instead of 8.5 and 1.8 (x0.3).
FRESH_JACOBIAN = {PLANE: True, SPACE: False}

#: Where an exit wraps, after how many steps of at most how many Newton iterations a halved step doubles again, by
#: Space (None: Exudyn's 10 of <= 7). A step that fails over a swivel pulley is one kink (an inlet element's damper
#: cut) and the halved steps after it took as many iterations as full ones (4.3 and 4.7): spatial-four-cable-swivel
#: 532 -> 442 steps at (3, 5), the path within 0.04 mm. Planar pulleys keep Exudyn's: (3, 5) on the paper circle at
#: 60 elements and 1e-2 s gains nothing (steady start: 1012 -> 1004 steps, the same CPU) or costs (paper start:
#: 1317 -> 1428 steps).
STEP_RECOVERY = {PLANE: None, SPACE: (3, 5)}


@contextlib.contextmanager
def quiet_exudyn():
    """Keep Exudyn's console messages to itself while active: the project reports failures in its words."""
    before = exu.config.printToConsole
    exu.config.printToConsole = False
    try:
        yield
    finally:
        exu.config.printToConsole = before


@contextlib.contextmanager
def interrupt_flag():
    """While active (in the main thread), a first Ctrl-C sets ``flag["interrupted"]`` instead of raising:
    the post-step function ends the integration cleanly, keeping the samples so far."""
    flag = {"interrupted": False}
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return
    previous = signal.getsignal(signal.SIGINT)

    def handler(signum, frame):  # noqa: ARG001
        if flag["interrupted"]:
            raise KeyboardInterrupt
        flag["interrupted"] = True

    signal.signal(signal.SIGINT, handler)
    try:
        yield flag
    finally:
        signal.signal(signal.SIGINT, previous)


def solver_settings(scene: Scene, solution_file: str | Path | None = None) -> exu.SimulationSettings:
    """Exudyn settings of the run of ``scene`` (the contact's step-size recommendation, which shrinks steps
    to about 1e-6 s, off); ``solution_file``, if given, is written."""
    solver = scene.solver
    settings = exu.SimulationSettings()
    ti = settings.timeIntegration
    ti.numberOfSteps = solver.n_steps
    ti.endTime = solver.end_time
    ti.verboseMode = 0
    ti.generalizedAlpha.spectralRadius = solver.spectral_radius
    # Zero initial accelerations by default: a straight cable's consistent -g is cut off by the
    # Kelvin-Voigt damping within microseconds, and carried into the first step it injects a start-up
    # jolt (13 J on the paper scene at 1.7e-2 s); a drop from rest, though, then converges at first order.
    ti.generalizedAlpha.computeInitialAccelerations = bool(solver.initial_accelerations)
    ti.newton.useModifiedNewton = solver.newton == "modified"
    wraps = any(e.wraps for e in scene.exits)
    ti.newton.modifiedNewtonJacUpdatePerStep = FRESH_JACOBIAN[scene.space] or wraps
    ti.newton.maxIterations = solver.max_newton_iterations
    # 1e-6 by default: Exudyn's 1e-8 buys nothing at millimetres and sits at the round-off of stiff
    # massless ropes' residual, where Newton stalls and the adaptive step shrinks up to 350-fold.
    ti.newton.relativeTolerance = solver.newton_tolerance
    ti.discontinuous.useRecommendedStepSize = False
    ti.adaptiveStep = True
    ti.minimumStepSize = solver.step_size * 1e-4
    if wraps and STEP_RECOVERY[scene.space] is not None:
        ti.adaptiveStepRecoverySteps, ti.adaptiveStepRecoveryIterations = STEP_RECOVERY[scene.space]
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    # Analyse the sparsity pattern once where it never changes (x1.13 of the CPU time, bit for bit): the
    # exact-angle bending joints' blocks are never zero; without them a slack tension-only element drops
    # its entries and a pattern analysed before would order the LU differently (1e-14 m on the path).
    effects = scene.effects
    settings.linearSolver.reuseAnalyzedPattern = effects.bending and effects.bending_model == "exact"
    if solver.integrator == "rk44":
        # Explicit classical Runge-Kutta at the fixed step (comparison runs only); the winch's coordinate
        # constraints eliminated, the platform joints spring-dampers (cdpr_exu.builder.platform).
        ti.solverType = exu.DynamicSolverType.RK44
        ti.adaptiveStep = False
        ti.explicit.eliminateConstraints = True
    settings.solution.file.write = solution_file is not None
    if solution_file is not None:
        settings.solution.file.name = str(solution_file)
        settings.solution.file.writePeriod = solver.output_period
        settings.solution.file.binary = True
    return settings

def output_times(end_time: float, output_period: float) -> np.ndarray:
    """The output times of a run [s], shape (N,): multiples of ``output_period`` from 0 to ``end_time``."""
    count = int(math.floor(end_time / output_period + 1e-9)) + 1
    return np.arange(count) * output_period

def solver_report(mbs: exu.MainSystem, message: str) -> str:
    """What Exudyn's solver said when it stopped (its error string, time, step, residual): the exception's
    text is only "SolveDynamic terminated"."""
    solver = mbs.sys.get("dynamicSolver") if hasattr(mbs, "sys") else None
    if solver is None:
        return f"Exudyn's solver stopped: {message}"
    try:
        reason = solver.GetErrorString().strip() or message
        it, conv = solver.it, solver.conv
        details = [f"at t = {it.currentTime:.6g} s", f"step size then {it.currentStepSize:.3g} s"]
        if not conv.newtonConverged:
            details.append(f"Newton residual {conv.residual:.3g}")
        if conv.linearSolverFailed:
            details.append(f"the linear solver failed (singular Jacobian, row {conv.linearSolverCausingRow})")
        if conv.massMatrixNotInvertible:
            details.append("the mass matrix is not invertible")
    except Exception:  # noqa: BLE001 - the report must never hide the failure itself
        return f"Exudyn's solver stopped: {message}"
    return f"Exudyn's solver stopped ({message}): {reason} ({', '.join(details)})"

def progress_reporter(progress, scene: Scene):
    """A per-step callback that updates a tqdm bar or calls ``progress(t, wall)`` about 100 times."""
    if not progress:
        return None
    end = scene.solver.end_time
    every = end / 100.0
    last = {"t": -1.0}
    if callable(progress):
        def report(t, wall):
            if t is None or t - last["t"] >= every:
                last["t"] = end if t is None else t
                progress(end if t is None else t, wall)
        return report
    from tqdm import tqdm

    # disable=None: no bar when the output is not a terminal (logs, CI), so it never floods them.
    bar = tqdm(total=end, unit="s", disable=None, mininterval=0.25,
               bar_format="{desc}{percentage:3.0f}%|{bar}| {n:.2f}/{total:.2f} s simulated [{elapsed}{postfix}]",
               desc=scene.name + " ")

    def report(t, wall):
        if t is None:
            bar.close()
            return
        if t - last["t"] >= every or t >= end - 1e-9:
            last["t"] = t
            bar.n = min(t, end)
            bar.set_postfix_str(f"{t / wall:.1f}x real time" if wall > 0 else "", refresh=False)
            bar.refresh()
    return report


#: Largest step of Exudyn's explicit RK44 on a real negative eigenvalue, times -lambda
#: (the classical Runge-Kutta stability interval is [-2.785, 0]).
RK44_STABILITY_LIMIT = 2.785


def explicit_step_limit(scene: Scene) -> float:
    """Estimated largest stable step [s] of explicit RK44 on ``scene``'s cables: the zig-zag mode's
    eigenvalue is about -4 c_i / m_i (undamped: 2 sqrt(k_i / m_i), with contact sqrt(k_p / m_i) more)."""
    limits = []
    for cable, pulley in zip(scene.cables, scene.exits):
        mass = float(cable.node_masses()[1:-1].min()) if cable.n_elements > 1 else cable.element_mass
        damping = cable.axial_damping if scene.effects.axial_damping else 0.0
        stiffness = cable.axial_stiffness if scene.effects.axial_elasticity else 0.0
        rate = 4.0 * damping / mass
        frequency = 2.0 * math.sqrt(stiffness / mass)
        if scene.pulley_contact:
            frequency = math.hypot(frequency, math.sqrt(pulley.contact_stiffness / mass))
        limits.append(RK44_STABILITY_LIMIT / max(rate, frequency, 1e-300))
    return min(limits)


def _cause_hints(scene: Scene, failure: str) -> list[str]:
    """Hints that follow the cause the monitor (or Exudyn) named in ``failure``."""
    hints = []
    if "is strained by +" in failure:
        hints.append("an element stretched beyond the strain limit: the cable is too soft for its load "
                     "(cables[i].youngs_modulus, platform.mass), or the winch command pulls against the platform")
    elif "is strained by -" in failure:
        hints.append("a slack (tension-only) element shortened beyond the monitor's strain limit: the cable "
                     "went slack and bunched up, which the monitor counts as leaving the model's range "
                     "(simulate.MAX_STRAIN)" if scene.effects.slack else
                     "an element was compressed beyond the strain limit: the cable pushes, which a real cable "
                     "cannot (effects.slack = true makes elements tension-only)")
    if "deep into pulley" in failure:
        hints.append("a node or element slipped into the pulley: elements too long for the pulley radius "
                     "(cables[i].n_elements) or a contact too soft for the tension (pulleys[i].contact_stiffness)")
    if "rose above the pulleys" in failure:
        hints.append("the platform was thrown upwards: only pushing cables can hold it above the pulleys; "
                     "a start-up jolt at a large solver.step_size or a reference that accelerates downwards "
                     "faster than gravity does this (effects.slack = true lets the cables go slack instead)")
    if "left the reachable region" in failure or "no longer finite" in failure:
        hints.append("the integration diverged: solver.step_size is too large for the stiffest mode "
                     "(axial stiffness or pulley contact), or solver.spectral_radius near 1 leaves it undamped")
    if "minimum step size" in failure or "Newton" in failure:
        hints.append("Newton's iteration found no solution even for tiny steps: a force jumps within a step "
                     "(a winch command that jumps, a slack cable snapping taut, a node striking the rim)")
    return hints


def first_step_hints(scene: Scene) -> list[str]:
    """What in ``scene`` can make the very first step fail (a run that stops at t = 0)."""
    hints = []
    solver = scene.solver
    cable = scene.cables[0]
    mass = cable.element_mass if scene.effects.cable_mass else scene.platform.mass
    if scene.pulley_contact:
        worst = max(scene.exits, key=lambda p: p.contact_stiffness)
        # The paper's pulley (1e7 N/m on 0.0875 kg nodes) runs at 2e-3 s: k h^2 / m = 457.
        ratio = worst.contact_stiffness * solver.step_size**2 / mass
        if ratio > 1e4:
            hints.append(f"pulleys[i].contact_stiffness = {worst.contact_stiffness:g} N/m is stiff for "
                         f"solver.step_size = {solver.step_size} s (k h^2 / m = {ratio:.3g}; the paper scene runs "
                         "at 457): the nodes resting on the rim cannot be balanced in one step")
    if scene.effects.axial_elasticity and scene.effects.cable_mass:
        ratio = cable.axial_stiffness * solver.step_size**2 / cable.element_mass
        if ratio > 1e5:
            hints.append(f"cables[i] axial stiffness ({cable.axial_stiffness:.3g} N/m per element) is stiff for "
                         f"solver.step_size = {solver.step_size} s (k h^2 / m = {ratio:.3g})")
    if solver.max_newton_iterations < 4:
        hints.append(f"solver.max_newton_iterations = {solver.max_newton_iterations} is too few for Newton to "
                     "converge from the initial state")
    if not hints:
        hints.append("the initial state is far from balanced (platform.initial_pose against the cables' "
                     "lengths) or solver.step_size is too large; try a smaller step")
    return hints


def likely_cause(scene: Scene, failure: str = "", failure_time: float | None = None) -> str:
    """A hint at what most likely made the integration fail, after the cause named in ``failure`` and the
    time of the stop ``failure_time`` [s] (within the first step: what in the scene makes it fail)."""
    hints = []
    if scene.solver.integrator == "rk44":
        limit = explicit_step_limit(scene)
        if scene.solver.step_size > limit:
            hints.append(f"explicit RK44 is unstable above a step of about {limit:.2g} s on these cables "
                         f"(axial damping c_i / m_i and stiffness); use a smaller step or the implicit solver")
    if failure_time is not None and failure_time < scene.solver.step_size:
        hints += ["at t = 0 the first step failed: " + hint for hint in first_step_hints(scene)]
    hints += _cause_hints(scene, failure)
    downward = -_steepest_downward_acceleration(scene)
    if scene.winch.kind == "kinematic" and downward > scene.gravity > 0.0:
        hints.append(f"the reference accelerates the platform downwards at up to {downward:.3g} m/s^2, more than "
                     f"gravity ({scene.gravity} m/s^2): cables can only pull, so they go slack"
                     + ("" if scene.effects.slack else " (with effects.slack off they push instead)"))
    if not hints and not scene.effects.bending:
        hints.append("bending is off: the paper scene relies on bending stiffness to stay well-behaved")
    if not hints and scene.solver.integrator == "generalized_alpha" and scene.solver.spectral_radius > 0.9:
        hints.append("spectral radius near 1 leaves the stiff axial modes undamped; try 0")
    if not hints:
        hints.append("a sudden jump of the winch command or the step size; try a smaller solver.step_size")
    return "Likely cause: " + "; ".join(dict.fromkeys(hints)) + "."


def _steepest_downward_acceleration(scene: Scene) -> float:
    """Most negative vertical acceleration of the reference over the run [m/s^2] (0 if none)."""
    try:
        times = np.linspace(0.0, scene.solver.end_time, 2001)
        acceleration = np.asarray(scene.trajectory.acceleration(times), dtype=float)[:, 1]
        return float(min(acceleration.min(), 0.0))
    except Exception:  # noqa: BLE001 - a hint must never raise
        return 0.0
