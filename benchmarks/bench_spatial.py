"""Benchmark: the CoGiRo-class spatial scene (8 cables x 20 elements) against real time, and what each effect costs.

Runs ``spatial-cogiro`` (its 0.5 m circle under ideal inverse kinematics) for 5 s of
simulated time at its shipped step, with the scene's own effects (``full``: mass,
elasticity, axial damping, bending), then without bending, and at a finer step, all in
this one process (one core), after a short warm-up run so that no row pays numba's compilation:
ratios measured in one run, not absolute speeds. It prints x real time of the solve (from its wall
time and from its CPU time, ``Result.wall_time`` and ``Result.cpu_time``), Newton iterations per step, and the
largest position error after 1 s. The target (issue 15, reported, not asserted): at
least real time at the shipped step.

Run: ``python benchmarks/bench_spatial.py [--end-time 5]``; writes
``benchmarks/results/spatial.md``.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import load_scene

RESULTS = Path(__file__).resolve().parent / "results" / "spatial.md"


def variants(scene):
    """(label, scene) pairs: the shipped scene, without bending, and at half the step."""
    no_bending = replace(scene.effects, bending=False, bending_damping=False)
    half_step = replace(scene.solver, step_size=scene.solver.step_size / 2.0)
    return (("shipped (full, %g s)" % scene.solver.step_size, scene),
            ("no bending", replace(scene, effects=no_bending)),
            ("full, half the step", replace(scene, solver=half_step)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=5.0, help="simulated time per run [s]")
    args = parser.parse_args()
    scene = load_scene("spatial-cogiro")
    scene = replace(scene, solver=replace(scene.solver, end_time=args.end_time))
    simulate(replace(scene, solver=replace(scene.solver, end_time=0.05)))  # warm-up: numba compiles here
    rows = []
    for label, variant in variants(scene):
        result = simulate(variant)
        summary = result.summary(1.0)
        rows.append((label, args.end_time / result.wall_time, args.end_time / result.cpu_time,
                     result.newton_iterations / max(result.steps, 1), 1000.0 * summary["max_position_error_m"]))
        print(f"{label:28s} {rows[-1][1]:6.2f}x real time (CPU {rows[-1][2]:6.2f}x)  "
              f"{rows[-1][3]:5.2f} Newton it./step  max error {rows[-1][4]:.3f} mm", flush=True)
    lines = ["| spatial-cogiro, 8 cables x 20 elements | x real time (wall) | x real time (CPU) | "
             "Newton iterations / step | max position error after 1 s [mm] |", "|---|---|---|---|---|"]
    lines += [f"| {label} | {wall:.2f} | {cpu:.2f} | {iterations:.2f} | {error:.3f} |"
              for label, wall, cpu, iterations, error in rows]
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text("\n".join(lines) + "\n")
    print(f"written to {RESULTS}")


if __name__ == "__main__":
    main()
