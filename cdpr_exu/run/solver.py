"""What the run loop and each dimension's run side share: Exudyn's settings and console, Ctrl-C, the
output times, the solver's own report of a failure, and the progress bar.

Below the run loop (:mod:`cdpr_exu.run.simulate`) and the spatial run side (:mod:`cdpr_exu.run.run_3d`),
so that the one :func:`~cdpr_exu.run.simulate.simulate` uses both without a circle of imports.
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


@contextlib.contextmanager
def quiet_exudyn():
    """Keep Exudyn's own console messages (failure banners, allocation warnings) to itself.

    The project reports failures in its own words; Exudyn's banner ("DYNAMIC SOLVER
    FAILED ... use showHints=True") and its memory-allocation warning would only
    confuse. Both go through ``exudyn.Print``, which ``exu.config.printToConsole``
    switches off; the setting is restored afterwards.
    """
    before = exu.config.printToConsole
    exu.config.printToConsole = False
    try:
        yield
    finally:
        exu.config.printToConsole = before


@contextlib.contextmanager
def interrupt_flag():
    """While active, Ctrl-C (SIGINT) sets ``flag["interrupted"]`` instead of raising.

    The solver's post-step function checks the flag and ends the time integration
    cleanly, so the samples computed so far are kept. Outside the main thread (where
    signal handlers cannot be installed) Ctrl-C behaves as usual.
    """
    flag = {"interrupted": False}
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return
    previous = signal.getsignal(signal.SIGINT)

    def handler(signum, frame):  # noqa: ARG001
        if flag["interrupted"]:  # a second Ctrl-C: the user insists
            raise KeyboardInterrupt
        flag["interrupted"] = True

    signal.signal(signal.SIGINT, handler)
    try:
        yield flag
    finally:
        signal.signal(signal.SIGINT, previous)


def solver_settings(scene: Scene, solution_file: str | Path | None = None) -> exu.SimulationSettings:
    """Exudyn settings of the implicit run of ``scene``.

    Generalized-alpha with the scene's spectral radius, the sparse LU solver, and
    (modified) Newton whose Jacobian is updated every step. The contact's own
    step-size recommendation is switched off (it shrinks steps to about 1e-6 s).
    """
    solver = scene.solver
    settings = exu.SimulationSettings()
    ti = settings.timeIntegration
    ti.numberOfSteps = solver.n_steps
    ti.endTime = solver.end_time
    ti.verboseMode = 0
    ti.generalizedAlpha.spectralRadius = solver.spectral_radius
    # By default start from zero accelerations. The consistent initial acceleration of a
    # straight cable's free nodes is -g, but the Kelvin-Voigt damping (c_i / m_i ~ 4e6
    # 1/s) cuts it off within microseconds; carried into the first step it injects a
    # start-up energy jolt (13 J on the paper scene at 1.7e-2 s steps). Without it the
    # paper circle's path moves by 0.7 mm and its step-size error halves; a drop from
    # rest, though, then converges at first order (SolverSpec.initial_accelerations).
    ti.generalizedAlpha.computeInitialAccelerations = bool(solver.initial_accelerations)
    ti.newton.useModifiedNewton = solver.newton == "modified"
    ti.newton.modifiedNewtonJacUpdatePerStep = True
    ti.newton.maxIterations = solver.max_newton_iterations
    # 1e-6 by default (SolverSpec.newton_tolerance): Exudyn's 1e-8 buys nothing at the
    # millimetres asked here, and on stiff massless ropes it sits at the residual's
    # round-off, so Newton stalls and the adaptive step shrinks up to 350-fold.
    ti.newton.relativeTolerance = solver.newton_tolerance
    ti.discontinuous.useRecommendedStepSize = False
    ti.adaptiveStep = True
    ti.minimumStepSize = solver.step_size * 1e-4
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    if solver.integrator == "rk44":
        # Explicit classical Runge-Kutta at the fixed step (comparison runs only).
        # SolveDynamic takes the solver type from these settings when called without
        # solverType; ``timeIntegration.explicitIntegration`` is the deprecated name of
        # ``timeIntegration.explicit``. The winch's ground-coordinate constraints are
        # eliminated (``explicit.eliminateConstraints``, Exudyn's default); the
        # platform joints must be spring-dampers (see cdpr_exu.builder.platform).
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
    """The output times of a run [s], shape (N,): the multiples of ``output_period`` from 0 up to
    ``end_time`` (none after it; the end time is one of them only when it is a multiple)."""
    count = int(math.floor(end_time / output_period + 1e-9)) + 1
    return np.arange(count) * output_period

def solver_report(mbs: exu.MainSystem, message: str) -> str:
    """What Exudyn's solver said when it stopped: its error string, time, step and residual.

    Exudyn's exception text is only "SolveDynamic terminated"; the stored solver
    (``mbs.sys["dynamicSolver"]``) knows why.
    """
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
    """A per-step callback that updates a tqdm bar or a user callable ~100 times."""
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
