"""Swivel pulley stability map (issue 15, item 2): which swivel inertia J_s and bearing
damping d_s hold, measured on a pendulum swinging around the swivel axis.

Scene (:func:`cdpr_exu.run.dynamics.run_swivel_pendulum`): a 2 kg mass on a
1.56 m cable (radius 2 mm, E = 1e9 Pa, 0.05 kg/m, 0.05 m elements, no axial damping)
that comes up the axis from 0.3 m below the inlet, wraps the r_p = 0.1 m swivel pulley
(r_g = h = 0.01 m, k_p = 1e6 N/m, no contact damping) and leaves it at 30 degrees from
the vertical for 1 m. Everything starts turning rigidly about the axis at 0.7 times the
conical pendulum's rate, so the mass swings in and out and its azimuth rate varies: the
swivel has to speed up and slow down to follow it. 10 s, generalized-alpha, adaptive step
(Exudyn halves the step where Newton fails).

For each (J_s, d_s), step, Newton settings (full or modified, relative tolerance, spectral
radius) and energy guard (a step whose
Newton solution gains more than the guard over the last accepted step is repeated at a
quarter of its size) it writes the largest rise of
the mechanical energy above its start (nothing dissipates but the bearing and the
integrator), the largest |E + bearing dissipation - E0|, the largest lag of psi behind
the mass's azimuth after the first second, Newton iterations per step and the steps
taken. A run whose energy rises by more than 10 J is stopped there ("gained").

Run: ``python benchmarks/bench_swivel_pulley.py [--end-time 10]``; writes
``benchmarks/results/swivel_pulley.md``. About 20 minutes on one core.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

from cdpr_exu.run.dynamics import run_swivel_pendulum
from cdpr_exu.physics.swivel_pulley import SwivelPulley

INERTIAS = (1e-6, 1e-4, 1e-2, 1.0)  # kg m^2
DAMPINGS = (0.0, 1e-3, 1e-1)  # N m s
STEPS = (5e-3, 2e-3)  # s
#: Newton relative tolerance, energy guard [J], modified Newton, spectral radius; the last two
#: are the planar runs' defaults (cdpr_exu.scene.SolverSpec: modified Newton, 1e-6, 0).
CONFIGURATIONS = ((1e-8, None, False, 0.5), (1e-10, None, False, 0.5), (1e-8, 1e-3, False, 0.5),
                  (1e-6, None, False, 0.5), (1e-6, None, True, 0.0), (1e-6, 1e-3, True, 0.0))
ABORT_RISE = 10.0  # J: several times the pendulum's kinetic energy (about 2 J)
HOLDS_BELOW = 0.1  # J: a run "holds" if its energy never rises more than this


def _measure(inertia, damping, step, tolerance, end_time, rate_factor=0.7, spectral_radius=0.5,
             element_length=0.05, guard=None, hang=False, modified=False):
    pulley = SwivelPulley(swivel_inertia=inertia, bearing_damping=damping)
    run = run_swivel_pendulum(pulley, step, end_time, rate_factor=rate_factor, spectral_radius=spectral_radius,
                              newton_tolerance=tolerance, abort_rise=ABORT_RISE,
                              element_length=element_length, energy_guard=guard,
                              swing=not hang, cone_angle=0.0 if hang else math.radians(30.0),
                              modified_newton=modified)
    lag = np.degrees(np.abs(run.psi - run.mass_azimuth))
    late = lag[run.time > 1.0]
    verdict = "holds" if not run.failed and run.energy_rise < HOLDS_BELOW else (
        "gained" if run.energy_rise >= HOLDS_BELOW else "failed")
    return {"J_s": inertia, "d_s": damping, "step": step, "tol": tolerance, "rho": spectral_radius,
            "guard": "-" if guard is None else f"{guard:g}", "rejections": run.guard_rejections,
            "rate_factor": rate_factor, "newton": "modified" if modified else "full",
            "element": element_length, "verdict": verdict, "t_end": run.time[-1], "rise": run.energy_rise,
            "balance": run.balance_error, "lag": f"{late.max():.2f}" if late.size else "n/a",
            "its": run.iterations_per_step, "steps": run.steps, "wall": run.wall_time,
            "contact": (int(run.in_contact[run.time > 0.1].min()) if np.any(run.time > 0.1) else "n/a"),
            "hang": hang}


def _row(r):
    rise = f"{r['rise']:.3g}" if r["verdict"] != "gained" or r["rise"] < ABORT_RISE else f"> {ABORT_RISE:g}"
    return (f"| {r['J_s']:g} | {r['d_s']:g} | {r['step']:g} | {r['newton']} | {r['rho']:g} | {r['tol']:g} | "
            f"{r['guard']} | {r['verdict']} | "
            f"{r['t_end']:.2f} | {rise} | {r['balance']:.3g} | {r['lag']} | {r['its']:.2f} | {r['steps']} | "
            f"{r['rejections']} | {r['contact']} | {r['wall']:.1f} |")


HEADER = ("| J_s [kg m^2] | d_s [N m s] | step [s] | Newton | spectral radius | Newton rel. tol. | energy guard [J] | "
          "verdict | reached [s] | "
          "energy rise [J] | balance error [J] | psi lag after 1 s [deg] | Newton it. / step | steps taken | "
          "steps repeated by the guard | fewest nodes in contact after 0.1 s | wall [s] |\n"
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=10.0, help="simulated time per run [s] (default 10)")
    parser.add_argument("--out", default="benchmarks/results/swivel_pulley.md")
    args = parser.parse_args()
    started = time.perf_counter()
    grid = []
    for tolerance, guard, modified, rho in CONFIGURATIONS:
        for step in STEPS:
            for inertia in INERTIAS:
                for damping in DAMPINGS:
                    grid.append(_measure(inertia, damping, step, tolerance, args.end_time, guard=guard,
                                         modified=modified, spectral_radius=rho))
                    print(_row(grid[-1]), flush=True)
    extra = []
    for rho, guard in ((0.0, None), (1.0, None), (1.0, 1e-3)):
        for step in STEPS:
            extra.append(_measure(1e-2, 1e-3, step, 1e-10, args.end_time, spectral_radius=rho, guard=guard))
            print(rho, _row(extra[-1]), flush=True)
    for step in STEPS:  # the mass hanging still below the pulley, released at rest: psi never moves
        extra.append(_measure(1e-2, 1e-3, step, 1e-10, args.end_time, spectral_radius=1.0, hang=True))
        print("hang", _row(extra[-1]), flush=True)
    coarse = []
    for tolerance, guard, modified, rho in ((1e-10, None, False, 0.5), (1e-10, 1e-3, False, 0.5),
                                            (1e-6, None, True, 0.0)):
        for step in STEPS:
            coarse.append(_measure(1e-2, 1e-3, step, tolerance, args.end_time, element_length=0.1, guard=guard,
                                   modified=modified, spectral_radius=rho))
            print("coarse", _row(coarse[-1]), flush=True)
    circle = []
    for tolerance, modified, rho in ((1e-10, False, 0.5), (1e-6, True, 0.0)):
        for step in STEPS:
            circle.append(_measure(1e-2, 1e-3, step, tolerance, args.end_time, rate_factor=1.0, modified=modified,
                                   spectral_radius=rho))
            print("circle", _row(circle[-1]), flush=True)

    lines = [f"# Swivel pulley stability map (pendulum around the axis, {args.end_time:g} s per run)", "",
             __doc__.split("\n\n")[1].replace("\n", " "), "",
             f"Verdict: 'holds' = ran to the end with the energy never more than {HOLDS_BELOW:g} J above its start; "
             f"'gained' = the energy rose by more (runs stop at a {ABORT_RISE:g} J rise); 'failed' = Newton failed "
             "at the smallest step. Elements 0.05 m, unless said.", "",
             "## J_s x d_s x step x Newton settings x energy guard", "", HEADER]
    lines += [_row(r) for r in grid]
    lines += ["", "## Spectral radius (J_s = 1e-2 kg m^2, d_s = 1e-3 N m s, tolerance 1e-10; 'hang': the mass "
              "released at rest hanging straight below the pulley, a planar motion in which psi never moves)", "",
              HEADER.replace("| J_s", "| run | J_s").replace("|---|", "|---|---|", 1)]
    lines += [f"| {'hang' if r['hang'] else 'pendulum'} " + _row(r) for r in extra]
    lines += ["", "## Elements as long as the pulley radius (0.1 m; J_s = 1e-2 kg m^2, d_s = 1e-3 N m s)", "",
              HEADER]
    lines += [_row(r) for r in coarse]
    lines += ["", "## The conical pendulum proper (started at the conical rate: the mass circles; J_s = 1e-2 kg m^2, "
              "d_s = 1e-3 N m s)", "", HEADER]
    lines += [_row(r) for r in circle]
    held = [r for r in grid if r["verdict"] == "holds"]
    counts = []
    for tolerance, guard, modified, rho in CONFIGURATIONS:
        label = "-" if guard is None else f"{guard:g}"
        newton = "modified" if modified else "full"
        mine = [r for r in grid if r["tol"] == tolerance and r["guard"] == label and r["newton"] == newton
                and r["rho"] == rho]
        counts.append(f"{sum(r['verdict'] == 'holds' for r in mine)} of {len(mine)} with {newton} Newton, "
                      f"spectral radius {rho:g}, tolerance {tolerance:g}"
                      + ("" if guard is None else f", the {guard:g} J energy guard"))
    lines += ["", f"Runs that hold in the grid: {len(held)} of {len(grid)} (" + "; ".join(counts) + "). "
              f"Total wall time {time.perf_counter() - started:.0f} s on a shared 2-core machine.", ""]
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text("\n".join(lines))
    print("wrote", args.out)


if __name__ == "__main__":
    main()
