"""Benchmark: the shipped spatial scenes against real time, and what their solve costs per step (issue 25).

Runs ``spatial-cogiro``, ``spatial-ipanema``, ``spatial-cogiro-mismatch`` (their circles under ideal inverse
kinematics) and ``spatial-four-cable-swivel`` over their whole end time at their shipped steps, through the one
run loop (:func:`cdpr_exu.run.simulate.simulate`), each ``--rounds`` times in this process (one core, after a short
warm-up run so that no row pays numba's compilation), and prints for each the best CPU time of the solve
(``Result.cpu_time``: process CPU time, never wall time), times faster than real time, steps, Newton iterations
and Jacobians (factorisations) per step. Single-threaded: set ``OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
NUMBA_NUM_THREADS=1``. The machines are shared and noisy: compare ratios measured side by side
(``benchmarks/bench_speed.py --ab`` for one change). Targets (reported, not asserted): cogiro and ipanema >= 8x,
the swivel scene >= 2x.

Run: ``python benchmarks/bench_spatial.py [--rounds 3] [--end-time T]``; writes ``benchmarks/results/spatial.md``.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import cdpr_exu.run.simulate as run_loop
from cdpr_exu.scenes.scene import load_scene

RESULTS = Path(__file__).resolve().parent / "results" / "spatial.md"
SCENES = ("spatial-cogiro", "spatial-ipanema", "spatial-cogiro-mismatch", "spatial-four-cable-swivel")
TARGETS = {"spatial-cogiro": 8.0, "spatial-ipanema": 8.0, "spatial-four-cable-swivel": 2.0}


def measured(scene) -> dict:
    """One run of ``scene``: CPU time [s], x real time, steps, Newton iterations and Jacobians per step."""
    models, build = [], run_loop.build_model
    run_loop.build_model = lambda *args, **kwargs: models.append(build(*args, **kwargs)) or models[-1]
    try:  # the model is kept to read the solver's Jacobian count, which the Result does not carry
        result = run_loop.simulate(scene)
    finally:
        run_loop.build_model = build
    steps = max(result.steps, 1)
    return {"cpu_time_s": result.cpu_time, "real_time_factor": result.simulated_time / result.cpu_time,
            "steps": result.steps, "newton_per_step": result.newton_iterations / steps,
            "jacobians_per_step": models[0].mbs.sys["dynamicSolver"].it.newtonJacobiCount / steps}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=3, help="runs per scene, the best CPU time kept")
    parser.add_argument("--end-time", type=float, default=None, help="simulated time per run [s] (default: the scene's)")
    args = parser.parse_args()
    warm = load_scene(SCENES[-1])
    run_loop.simulate(replace(warm, solver=replace(warm.solver, end_time=0.05)))  # numba compiles here
    lines = ["# The shipped spatial scenes against real time (benchmarks/bench_spatial.py)", "",
             f"Best of {args.rounds} runs in one process, CPU time of the solve, single-threaded; the machine is "
             "shared and noisy: compare ratios.", "",
             "| scene | end time [s] | CPU time [s] | x real time | target | steps | Newton iterations / step | "
             "Jacobians / step |", "|---|---|---|---|---|---|---|---|"]
    for name in SCENES:
        scene = load_scene(name)
        if args.end_time is not None:
            scene = replace(scene, solver=replace(scene.solver, end_time=min(args.end_time, scene.solver.end_time)))
        row = min((measured(scene) for _ in range(args.rounds)), key=lambda r: r["cpu_time_s"])
        target = f">= {TARGETS[name]:g}" if name in TARGETS else ""
        lines.append(f"| {name} | {scene.solver.end_time:g} | {row['cpu_time_s']:.2f} | {row['real_time_factor']:.2f} | "
                     f"{target} | {row['steps']} | {row['newton_per_step']:.2f} | {row['jacobians_per_step']:.2f} |")
        print(lines[-1], flush=True)
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text("\n".join(lines) + "\n")
    print(f"written to {RESULTS}")


if __name__ == "__main__":
    main()
