"""Speed of the one run loop (issue 25): CPU time, real-time factor, steps and Newton iterations per step.

Table mode (the default) runs, one after the other in this process, the paper circle at n = 30, 60 and
120 elements per cable with 1e-2 s steps, the shipped ``paper-circle`` (the paper's start), the 60-element and
shipped runs again with ``solver.start = "steady"`` (issue 25 item 4) and the spatial scenes, and prints
for each: CPU time of the solve (``Result.cpu_time``, process CPU time, never wall time), times faster
than real time, steps, Newton iterations and Jacobian updates per step, discontinuous iterations, the
start-up share (CPU time of the first 0.05 s, a run of its own, over the whole run's), the cost exponent
from 30 to 120 elements, and for the planar rows the platform's largest distance and rotation from the
converged reference :data:`REFERENCE` of the same start (the spatial scenes' references are ``bench_spatial.py``'s). The
ratios come from one run on one machine; the machines are shared and noisy: compare ratios.

A/B mode measures one change: ``--ab A B`` runs the same scene alternately (A, B, A, B, ...) in fresh
processes, each importing ``cdpr_exu`` from the source folder given (a checkout of the commit before and
after the change), and prints the best of ``--rounds`` CPU times of each, their ratio, and whether the
two paths are the same bit for bit (a digest of every recorded array). ``--fast A|B|both`` loads
Exudyn's fast module (``sys.exudynFast``) in that side; ``--start paper steady`` runs one
source with each start (``--ab . . --start paper steady``).

Run: ``python benchmarks/bench_speed.py [--end-time 10] [--out benchmarks/results/speed.md]``, or
``python benchmarks/bench_speed.py --ab /tmp/before . --scene paper-circle --elements 60 --step 1e-2``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import subprocess
import sys
from pathlib import Path

#: Rows: scene, elements per cable and step [s] (None: the scene's), ``solver.start`` (None: the scene's).
PLANAR = ([("paper-circle", n, 1e-2, "paper") for n in (30, 60, 120)] + [("paper-circle", None, None, "paper")]
          + [("paper-circle", 60, 1e-2, "steady"), ("paper-circle", None, None, "steady")])
#: The planar rows' converged reference, one per start (a different start is a different path): the paper circle
#: at 120 elements per cable and 2.5e-3 s steps (0.04 mm from 240 elements at 1.25e-3 s, docs/accuracy.md).
REFERENCE = ("paper-circle", 120, 2.5e-3)
#: The simulated time whose CPU share is the start-up's [s].
START_UP = 0.05
SPATIAL = [(name, None, None, None) for name in
           ("spatial-cogiro", "spatial-ipanema", "spatial-cogiro-mismatch", "spatial-four-cable-swivel")]


def run_one(name: str, elements: int | None, step: float | None, end_time: float | None,
            poses: dict | None = None, start: str | None = None) -> dict:
    """One run of the scene ``name`` (``elements`` per cable, ``step`` [s] and ``solver.start`` where given): its
    figures; its times, platform and reference poses into ``poses`` if given."""
    from dataclasses import replace

    import numpy as np

    from cdpr_exu.run.simulate import simulate
    from cdpr_exu.scenes.scene import load_scene

    scene = load_scene(name)
    solver = scene.solver if start is None else replace(scene.solver, start=start)
    if step is not None:
        solver = replace(solver, step_size=step)
    if end_time is not None:
        solver = replace(solver, end_time=min(end_time, solver.end_time))
    cables = scene.cables if elements is None else tuple(replace(c, n_elements=elements) for c in scene.cables)
    result = simulate(scene.with_changes(cables=cables, solver=solver))
    if poses is not None:
        poses.update(time=result.time, pose=result.pose, reference=result.reference)
    digest = hashlib.sha256()
    for array in (result.time, result.pose, result.paid_out, *result.nodes, *result.tensions):
        digest.update(np.ascontiguousarray(array).tobytes())
    return {"scene": name, "start": solver.start, "n_elements": cables[0].n_elements, "step_size_s": solver.step_size,
            "cpu_time_s": result.cpu_time, "simulated_time_s": result.simulated_time,
            "real_time_factor": result.simulated_time / result.cpu_time, "steps": result.steps,
            "newton_per_step": result.newton_iterations / max(result.steps, 1),
            "jacobians_per_step": result.jacobians / max(result.steps, 1),
            "discontinuous_iterations": result.discontinuous_iterations, "digest": digest.hexdigest()[:16]}


def _worker(args) -> None:
    """A fresh process's one run (A/B mode): warm the numba caches, then run and print JSON."""
    if args.fast:
        sys.exudynFast = True
    import exudyn  # noqa: F401 - loaded here, after the choice of module

    from dataclasses import replace

    from cdpr_exu.run.simulate import simulate
    from cdpr_exu.scenes.scene import load_scene

    warm = load_scene(args.scene)
    simulate(warm.with_changes(solver=replace(warm.solver, end_time=2 * warm.solver.step_size)))
    print(json.dumps(run_one(args.scene, args.elements, args.step, args.end_time, start=args.start[0])))


def ab(args) -> None:
    """Alternate fresh processes of the two sources (and ``--start`` of each); best CPU time of each and whether
    the paths agree."""
    best, digests = {}, {}
    starts = args.start * 2 if len(args.start) == 1 else args.start
    for round_ in range(args.rounds):
        for side, source, start in zip("AB", args.ab, starts):
            env = {**os.environ, "PYTHONPATH": str(Path(source).resolve()), "MPLBACKEND": "Agg"}
            command = [sys.executable, __file__, "--worker", "--scene", args.scene,
                       *(["--elements", str(args.elements)] if args.elements else []),
                       *(["--step", str(args.step)] if args.step else []),
                       *(["--end-time", str(args.end_time)] if args.end_time else []), "--start", start,
                       *(["--fast"] if args.fast in (side, "both") else [])]
            row = json.loads(subprocess.run(command, env=env, check=True, capture_output=True,
                                            text=True).stdout.strip().splitlines()[-1])
            best[side] = min(best.get(side, math.inf), row["cpu_time_s"])
            digests.setdefault(side, set()).add(row["digest"])
            print(f"round {round_ + 1} {side} ({start} start): {row['cpu_time_s']:.3f} s CPU, {row['steps']} steps, "
                  f"{row['newton_per_step']:.2f} Newton and {row['jacobians_per_step']:.2f} Jacobians per step, "
                  f"digest {row['digest']}", flush=True)
    same = digests["A"] == digests["B"] and len(digests["A"]) == 1
    print(f"best of {args.rounds}: A {best['A']:.3f} s, B {best['B']:.3f} s CPU: B is x{best['A'] / best['B']:.3f} "
          f"faster; paths {'bit for bit the same' if same else 'DIFFER: ' + str(digests)}")


def table(args) -> None:
    """Every scene of the table once, in this process, after a warm-up; the planar rows against the reference."""
    import numpy as np

    from cdpr_exu.core.output import write_json

    run_one("paper-circle", None, None, START_UP)  # warm-up: numba, imports
    reference = {start: {} for start in ("paper", "steady")}
    reference_row = {start: run_one(*REFERENCE, args.end_time, poses, start) for start, poses in reference.items()}
    rows = []
    for name, n, step, start in PLANAR + SPATIAL:
        poses = {}
        row = run_one(name, n, step, args.end_time, poses, start)
        row["start_up_share"] = run_one(name, n, step, START_UP, start=start)["cpu_time_s"] / row["cpu_time_s"]
        row["error_mm"] = row["error_deg"] = None
        if start is not None:
            ref = reference[start]
            at = [np.interp(poses["time"], ref["time"], ref["pose"][:, k]) for k in range(3)]
            row["error_mm"] = 1e3 * float(np.hypot(*(poses["pose"][:, :2] - np.column_stack(at[:2])).T).max())
            row["error_deg"] = float(np.degrees(np.abs(poses["pose"][:, 2] - at[2]).max()))
        rows.append(row)
        print(f"{name:26s} {row['start']:6s} n = {row['n_elements']:3d}, step {row['step_size_s']:.0e} s: "
              f"{row['cpu_time_s']:7.2f} s CPU, {row['real_time_factor']:6.2f}x real time, {row['steps']} steps, "
              f"{row['newton_per_step']:.2f} Newton and {row['jacobians_per_step']:.2f} Jacobians per step, "
              f"{row['discontinuous_iterations']} discontinuous iterations, start-up "
              f"{100 * row['start_up_share']:.0f} %", flush=True)
    cost = {r["n_elements"]: r["cpu_time_s"] for r in rows[:3]}
    exponent = math.log(cost[120] / cost[30]) / math.log(4)
    shown = lambda value, digits: "-" if value is None else f"{value:.{digits}f}"  # noqa: E731
    lines = ["# Speed of the one run loop (issue 25), one run each", "",
             "CPU time of the solve (process CPU time, single-threaded); the machine is shared and noisy: "
             f"compare ratios. Start-up: the CPU share of the first {START_UP} s (a run of its own). Error: the "
             "platform's largest distance and rotation from the converged reference of the same start "
             "(`solver.start`; docs/accuracy.md, \"The start\"), the paper circle at "
             f"{REFERENCE[1]} elements and {REFERENCE[2]} s ({reference_row['paper']['cpu_time_s']:.1f} s CPU).", "",
             "| scene | start | elements per cable | step [s] | CPU time [s] | x real time | steps | Newton / step | "
             "Jacobians / step | discontinuous iterations | start-up share | error [mm] | error [deg] |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    lines += [f"| {r['scene']} | {r['start']} | {r['n_elements']} | {r['step_size_s']:g} | {r['cpu_time_s']:.2f} | "
              f"{r['real_time_factor']:.2f} | {r['steps']} | {r['newton_per_step']:.2f} | "
              f"{r['jacobians_per_step']:.2f} | "
              f"{r['discontinuous_iterations']} | {100 * r['start_up_share']:.0f} % | {shown(r['error_mm'], 2)} | "
              f"{shown(r['error_deg'], 3)} |" for r in rows]
    lines += ["", f"Cost of the paper circle from 30 to 120 elements at 1e-2 s grows as n^{exponent:.2f} "
              "(target: no faster than n^1.2)."]
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text("\n".join(lines) + "\n")
    write_json(Path(args.out).with_suffix(".json"), {"rows": rows, "reference": reference_row,
                                                     "cost_exponent_30_120": exponent, "cpu_count": os.cpu_count()})
    print(lines[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=None, help="simulated time per run [s] (default: the scene's)")
    parser.add_argument("--out", default="benchmarks/results/speed.md")
    parser.add_argument("--ab", nargs=2, metavar=("A", "B"), help="two source folders to compare (A/B mode)")
    parser.add_argument("--scene", default="paper-circle")
    parser.add_argument("--elements", type=int, default=None)
    parser.add_argument("--step", type=float, default=None)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--start", nargs="+", default=["paper"], choices=("paper", "steady"),
                        help="solver.start of the run (A/B mode: one for both sides, or one each)")
    parser.add_argument("--fast", nargs="?", const="both", default=None, help="Exudyn's fast module in A, B or both")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        _worker(args)
    elif args.ab:
        ab(args)
    else:
        table(args)


if __name__ == "__main__":
    main()
