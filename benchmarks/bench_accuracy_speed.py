"""Accuracy against speed of the paper circle: x real time, Newton iterations and error over n.

For n = 15, 30, 60, 120 and 240 elements per cable, at the shipped step (2e-3 s) and at
1e-2 s, runs the paper circle (full model) and prints: times faster than real time (CPU
time of the single-threaded run), Newton iterations per step, and the largest position error after 1 s against
the converged reference of the accuracy study (``results/accuracy/paper_circle/reference.npz``:
90 elements, 5e-4 s). It also fits the exponent of the cost in n from 30 to 240 elements,
and says which issue-14 targets the run meets. All ratios come from one run on one
machine; the machines are shared and noisy, so compare ratios, not seconds.

It also gives the error estimate of ``cdpr run`` (:mod:`cdpr_exu.run.error_estimate`) for
each run whose companion (twice the elements, same step) is in the table, beside its error
against the reference: how well the estimate tells the true error.

Run: ``python benchmarks/bench_accuracy_speed.py [--end-time 10]``; writes
``benchmarks/results/accuracy_speed.md`` and ``accuracy_speed.json`` (every number of the
table and the text, the estimates too). A shorter ``--end-time`` compares the error over
that part of the circle only.
"""

from __future__ import annotations

import argparse
import cProfile
import os
import platform
import pstats
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cdpr_exu.core.errors import SolverFailure
from cdpr_exu.core.output import write_json
from cdpr_exu.run.error_estimate import AFTER, path_distance, richardson_factor
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.run.simulate import simulate

ELEMENTS = (15, 30, 60, 120, 240)
STEPS = (2e-3, 1e-2)
REFERENCE = Path(__file__).resolve().parents[1] / "results" / "accuracy" / "paper_circle" / "reference.npz"


def solver_floor(scene) -> float:
    """Times faster than real time of Exudyn's own C++ work in one run of ``scene``.

    The run goes under cProfile (timed in CPU time); the self time of Exudyn's ``SolveSystem`` is the solver's
    time without the Python functions it calls (the cables' forces and Jacobians, the
    pre- and post-step functions): the speed this model would have if those cost
    nothing. cProfile's own bookkeeping per call makes it a slight underestimate.
    """
    profile = cProfile.Profile(time.process_time)
    profile.enable()
    result = simulate(scene)
    profile.disable()
    own = sum(stats[2] for key, stats in pstats.Stats(profile).stats.items() if key[2].endswith("SolveSystem>"))
    return result.simulated_time / own


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=10.0, help="simulated time per run [s] (default 10)")
    parser.add_argument("--out", default="benchmarks/results/accuracy_speed.md")
    args = parser.parse_args()
    paper = load_scene("paper-circle")
    reference = np.load(REFERENCE)
    simulate(paper.with_changes(solver=replace(paper.solver, end_time=0.05)))  # warm-up: numba, imports
    rows, results = [], {}
    for step in STEPS:
        for n in ELEMENTS:
            scene = paper.with_changes(cables=tuple(replace(c, n_elements=n) for c in paper.cables),
                                       solver=replace(paper.solver, end_time=args.end_time, step_size=step))
            cpu = time.process_time()
            try:
                result = simulate(scene)
            except SolverFailure as failure:  # a row too: where and why it stopped
                rows.append((step, n, None, None, None, None, f"failed at t = {failure.time:.2f} s"))
                print(f"step {step:.0e} s, n = {n:3d}: failed at t = {failure.time:.4f} s", flush=True)
                continue
            cpu = time.process_time() - cpu
            results[step, n] = result
            reference_pose = np.array([np.interp(result.time, reference["time"], reference["pose"][:, k])
                                       for k in range(2)]).T
            after = result.time >= min(1.0, 0.5 * args.end_time) - 1e-9  # after the start-up (half of a short run)
            error = float(np.linalg.norm(result.pose[after, :2] - reference_pose[after], axis=1).max())
            speed = result.simulated_time / cpu
            iterations = result.newton_iterations / max(result.steps, 1)
            rows.append((step, n, speed, iterations, error, cpu, "completed"))
            print(f"step {step:.0e} s, n = {n:3d}: {speed:6.2f}x real time, {iterations:5.2f} Newton iterations "
                  f"per step, error {1000 * error:7.3f} mm", flush=True)
    lines = [f"# Accuracy against speed, paper circle (full model, {args.end_time} s, one run each)", "",
             "Error: largest platform position error after 1 s (after half the run if shorter) against the converged reference "
             "(90 elements, 5e-4 s). CPU time of one single-threaded run (the wall time of a shared machine varies with its load); compare ratios.", "",
             "| step [s] | elements per cable | x real time | Newton iterations / step | error [mm] | status |",
             "|---|---|---|---|---|---|"]
    for step, n, speed, iterations, error, _, status in rows:
        if speed is None:  # no numbers for a failed run: empty cells, not "nan"
            lines.append(f"| {step:g} | {n} | | | | {status} |")
        else:
            lines.append(f"| {step:g} | {n} | {speed:.2f} | {iterations:.2f} | {error * 1000:.3f} | {status} |")
    rows = [row for row in rows if row[2] is not None]
    lines.append("")
    for step in STEPS:
        fit = [(n, cpu) for s, n, _, _, _, cpu, _ in rows if s == step and n >= 30]
        if len(fit) < 2:
            lines.append(f"Cost in n at step {step:g} s: fewer than two completed runs from 30 elements on.")
            continue
        exponent = np.polyfit(np.log([n for n, _ in fit]), np.log([w for _, w in fit]), 1)[0]
        lines.append(f"Cost from {fit[0][0]} to {fit[-1][0]} elements at step {step:g} s grows as n^{exponent:.2f} "
                     f"(target: no faster than n^1.2).")
    within = [(speed, step, n) for step, n, speed, _, error, _, _ in rows if error <= 1e-3]
    if within:
        speed, step, n = max(within)
        lines.append(f"Fastest run within 1 mm of the converged answer: {speed:.2f}x real time "
                     f"({n} elements, step {step:g} s; target: 20x).")
    shipped = next(speed for step, n, speed, *_ in rows if step == 2e-3 and n == 15)
    lines.append(f"The shipped scene (15 elements, 2e-3 s): {shipped:.2f}x real time (target: 15x).")
    lines.append("")
    lines.append("Exudyn's C++ work alone (the self time of its SolveSystem under cProfile: no Python "
                 "force, Jacobian or step function counted), the ceiling of trimming Python:")
    floors = []
    for step, n in ((2e-3, 15), *(((step, n),) if within else ())):
        scene = paper.with_changes(cables=tuple(replace(c, n_elements=n) for c in paper.cables),
                                   solver=replace(paper.solver, end_time=args.end_time, step_size=step))
        floors.append({"step_size_s": step, "n_elements": n, "real_time_factor": solver_floor(scene)})
        lines.append(f"- {n} elements, step {step:g} s: {floors[-1]['real_time_factor']:.1f}x real time.")
    # cdpr run's error estimate of each run whose companion (2n, same step) ran: the Richardson
    # formula of cdpr_exu.run.error_estimate on the two paths, as `cdpr run` computes it
    estimates = {}
    for (step, n), result in results.items():
        companion = results.get((step, 2 * n))
        if companion is not None and args.end_time > AFTER:
            estimates[step, n] = path_distance(result, companion, AFTER) * richardson_factor(2.0)
    lines.append("")
    lines.append(f"cdpr run's error estimate (Richardson from the run with twice the elements, after {AFTER:g} s) "
                 "against the error above:")
    for (step, n), estimate in sorted(estimates.items()):
        error = next(row[4] for row in rows if row[:2] == (step, n))
        lines.append(f"- {n} elements, step {step:g} s: {1000 * estimate:.2f} mm estimated, "
                     f"{1000 * error:.2f} mm true ({estimate / error:.2f}x).")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text("\n".join(lines) + "\n")
    fits = []
    for step in STEPS:
        fit = [(n, cpu) for s, n, _, _, _, cpu, _ in rows if s == step and n >= 30]
        if len(fit) >= 2:
            fits.append({"step_size_s": step, "from_n": fit[0][0], "to_n": fit[-1][0],
                         "exponent": float(np.polyfit(np.log([n for n, _ in fit]), np.log([w for _, w in fit]), 1)[0])})
    table = []
    for step, n, speed, iterations, error, cpu, status in rows:
        row = {"step_size_s": step, "n_elements": n, "status": status, "cpu_time_s": cpu,
               "real_time_factor": speed, "newton_iterations_per_step": iterations, "max_position_error_m": error}
        if (step, n) in estimates:
            row["error_estimate_m"] = estimates[step, n]
            row["estimate_over_error"] = estimates[step, n] / error
        table.append(row)
    fastest = max(within) if within else None
    write_json(Path(args.out).with_suffix(".json"), {
        "scene": "paper-circle", "end_time_s": args.end_time, "machine": platform.machine(),
        "cpu_count": os.cpu_count(), "errors_measured_after_s": min(1.0, 0.5 * args.end_time),
        "rows": table, "cost_exponents": fits,
        "fastest_within_1mm": None if fastest is None else
        {"real_time_factor": fastest[0], "step_size_s": fastest[1], "n_elements": fastest[2]},
        "shipped_real_time_factor": shipped, "solver_only": floors})
    print("\n".join(lines[-8:]))


if __name__ == "__main__":
    main()
