"""Benchmark: the paper scene on every model of the ladder, wall time per simulated second.

Runs ``paper-circle`` (10 s, 15 elements per cable) on the presets ``ideal``,
``elastic``, ``catenary``, ``full``, on ``full`` with the linear curvature-vector
bending and on ``full`` with the pulley contact on element segments, at several step sizes, all in this one process (one core), and prints wall
time per simulated second, the ratio to real time (from the wall time and from the
process's CPU time, which the load of other processes on a shared machine disturbs
far less), and the cost relative to ``full`` at the smallest step: ratios measured in
one run, not absolute speeds.

The target (reported, not asserted): ``full`` at least 10 times faster than real time
on one core. For each ``full`` run the accuracy is given as the platform position
error after 1 s against the accuracy study's reference (``full``, 90 elements,
5e-4 s; read from ``results/accuracy/paper_circle/reference.npz`` when it exists,
see ``examples/accuracy_vs_time.py``), else against ``full`` at 15 elements and
5e-4 s (the step-size error only).

Run: ``python benchmarks/bench_presets.py [--end-time 10] [--steps 2e-3 5e-3 1e-2]``.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cdpr_exu.core.errors import SolverFailure
from cdpr_exu.scenes.scene import Effects, load_scene
from cdpr_exu.run.simulate import simulate

MODELS = (("ideal", {}), ("elastic", {}), ("catenary", {}), ("full", {}), ("full", {"bending_model": "linear"}),
          ("full", {"pulley_contact_model": "segment"}))
REFERENCE = Path(__file__).resolve().parent.parent / "results" / "accuracy" / "paper_circle" / "reference.npz"
#: Errors are measured after the start-up jolt [s].
AFTER = 1.0


def model_label(preset: str, overrides: dict) -> str:
    names = {"bending_model": "bending", "pulley_contact_model": "contact"}
    return preset + "".join(f", {v} {names[k]}" if k in names else f", {k}={v}" for k, v in overrides.items())


def run(base, preset: str, overrides: dict, step: float, end_time: float):
    scene = base.with_changes(effects=Effects.from_preset(preset, **overrides),
                              solver=replace(base.solver, step_size=step, end_time=end_time))
    cpu = time.process_time()
    try:
        result, status = simulate(scene), "completed"
    except SolverFailure as err:
        result, status = err.partial_result, f"failed at {err.time:.2f} s"
    result.metadata["cpu_time_s"] = time.process_time() - cpu
    return result, status


def path_error(result, reference_time, reference_pose) -> tuple[float, float]:
    """Max and RMS platform position error after AFTER s on the reference's times [m]."""
    mask = (reference_time >= AFTER) & (reference_time <= result.time[-1] + 1e-9)
    times = reference_time[mask]
    x = np.interp(times, result.time, result.pose[:, 0])
    z = np.interp(times, result.time, result.pose[:, 1])
    error = np.hypot(x - reference_pose[mask, 0], z - reference_pose[mask, 1])
    return float(error.max()), float(np.sqrt(np.mean(error**2)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=10.0)
    parser.add_argument("--steps", type=float, nargs="+", default=[2e-3, 5e-3, 1e-2])
    args = parser.parse_args()
    base = load_scene("paper-circle")
    for preset, overrides in MODELS:  # warm-up: numba kernels, imports, Exudyn code paths
        run(base, preset, overrides, 2e-3, 0.02)

    if REFERENCE.exists() and args.end_time == 10.0:
        with np.load(REFERENCE) as data:
            reference_time, reference_pose = data["time"], data["pose"]
        reference_name = "full, 90 elements, 5e-4 s (results/accuracy/paper_circle/reference.npz)"
    else:
        result, _ = run(base, "full", {}, 5e-4, args.end_time)
        reference_time, reference_pose = result.time, result.pose
        reference_name = "full, 15 elements, 5e-4 s (step-size error only)"

    rows = []
    for preset, overrides in MODELS:
        for step in args.steps:
            result, status = run(base, preset, overrides, step, args.end_time)
            error = path_error(result, reference_time, reference_pose) if status == "completed" else (np.nan, np.nan)
            rows.append((model_label(preset, overrides), step, status, result.wall_time,
                         result.metadata["cpu_time_s"], result.simulated_time,
                         result.newton_iterations / max(result.steps, 1), *error))
    smallest = min(args.steps)
    full_wall = next(r[3] / r[5] for r in rows if r[0] == "full" and r[1] == smallest and r[2] == "completed")
    print(f"paper-circle, {args.end_time:g} s, 15 elements per cable, one process (one core)")
    print(f"accuracy: max / RMS platform position error after {AFTER:g} s against {reference_name}")
    print(f"{'model':24s} {'step [s]':>9s} {'wall/sim s':>11s} {'x real time':>12s} {'(CPU time)':>11s} "
          f"{'cost vs full ' + format(smallest, 'g'):>19s} {'Newton/step':>12s} {'max err [mm]':>13s} "
          f"{'rms err [mm]':>13s}  status")
    for label, step, status, wall, cpu, simulated, newton, error_max, error_rms in rows:
        per_second = wall / simulated if simulated > 0 else np.nan
        print(f"{label:24s} {step:9.0e} {per_second:11.3f} {1 / per_second:12.1f} {simulated / cpu:11.1f} "
              f"{per_second / full_wall:19.2f} {newton:12.2f} {1000 * error_max:13.2f} {1000 * error_rms:13.2f}  "
              f"{status}")
    full = [r for r in rows if r[0] == "full" and r[2] == "completed"]
    fast = [r for r in full if r[5] / r[3] >= 10.0]
    if fast:
        label, step, _, wall, cpu, simulated, _, error_max, error_rms = min(fast, key=lambda r: r[7])
        print(f"\ntarget met: full at step {step:g} s runs {simulated / wall:.1f} x faster than real time "
              f"({simulated / cpu:.1f} x by CPU time), max error {1000 * error_max:.1f} mm, "
              f"RMS {1000 * error_rms:.1f} mm after {AFTER:g} s")
    else:
        best = max(full, key=lambda r: r[5] / r[3])
        print(f"\ntarget not met: full is at most {best[5] / best[3]:.1f} x faster than real time by wall time "
              f"({best[5] / best[4]:.1f} x by CPU time; step {best[1]:g} s) on this machine now")


if __name__ == "__main__":
    main()
