"""Robustness: the controllers on plants that differ from their model, and a loop designed from its margins.

Issue 27. The controllers' model is the paper's robot (``paper-circle``, its circle started from rest over
1 s as ``cdpr compare`` does); each plant is that model with its platform's mass (and inertia) and its cables'
density off by -20, 0 or +20 % (3 x 3), and, one at a time at the nominal mass and density, its cables'
Young's modulus off by -+20 % and its pulleys 3 mm further in or out (:mod:`cdpr_exu.studies.robustness`):
13 plants. Three steps, one command:

1. The position loop of ``closed_loop_tension_aware`` linearised on every plant at 8 poses of one turn
   (:mod:`controllers.loop_design`), with the gains chosen by trial before (``previous``: k_p = 2, k_i = 40 /s,
   f_c = 5 Hz) and the gains chosen from the margins (``designed``): >= 6 dB and >= 30 deg on every plant and
   pose, the smallest sensitivity at the circle's own frequency; the designed gains are the loop's defaults
   (:data:`controllers.loop_design.DESIGNED`: the script stops if the design picks others). ``margins.md``
   and ``margins.json``: the worst margins over the poses per plant, beside what the real run did
   (docs/robustness.md reads them).
2. Every controller on every plant (``robustness.md``, ``robustness.csv``, ``robustness.json``, a heat map
   per controller ``robustness_<controller>.png``), into ``results/robustness/planar/``.
3. The spatial CoGiRo-class and IPAnema-class robots (``spatial-cogiro``, ``spatial-ipanema``) under the
   chain correction's three starts (:data:`controllers.base.STARTS`) and the catenary's, the closed loop,
   ILC and the model feed-forward, nominal and with the 10 % model error of ``spatial-cogiro-mismatch``:
   ``results/robustness/spatial-cogiro/``, ``results/robustness/spatial-ipanema/``; and their loops
   (:data:`controllers.registry.SPATIAL_LOOP`: the closed loop's and the model feed-forward's, both with the
   rotation fed back, 6 x 6) linearised at 24 poses over each run, on both plants: ``margins.md`` and
   ``margins.json`` in each folder; the default gains are those the disk margin chooses over both robots (the
   script stops if the design picks others), beside the gains first chosen by trial (``previous``).

Rows are appended to each folder's ``rows.jsonl`` as runs finish (git-ignored, with wall times); a run of
this script that is interrupted resumes where it stopped; ``--fresh`` starts over. Errors are measured after
the first second. About 15 min of CPU time (the learning controllers' trials are most of it); the spatial
part about 12 min more.

Run::

    python examples/robustness_study.py [--workers N] [--fresh] [--skip-spatial]
"""

from __future__ import annotations

import argparse
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

from cdpr_exu.core.output import write_summary
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.studies.comparison import smooth_start
from cdpr_exu.studies.robustness import ERRORS, ROBUSTNESS_FILES, error_grid, perturbed, run_robustness
from controllers import loop_design
from controllers.registry import SPATIAL_LOOP, SPATIAL_LOOP_PREVIOUS

OUT = Path(__file__).resolve().parents[1] / "results" / "robustness"

#: The planar controllers: label -> (kind, options) (:func:`cdpr_exu.studies.robustness.make_controller`).
PLANAR = {
    "tension_aware": ("tension_aware", {}),
    "tension_aware_chain": ("tension_aware", {"statics": "chain"}),
    "tension_aware_chain_relative": ("tension_aware", {"statics": "chain", "start": "relative"}),
    "closed_loop_tension_aware": ("closed_loop_tension_aware", {}),
    "closed_loop_tension_aware_previous": ("closed_loop_tension_aware", asdict(loop_design.PREVIOUS)),
    "model_feed_forward": ("model_feed_forward", {}),
    "closed_loop_model_feed_forward": ("closed_loop_model_feed_forward", {}),
    "ilc": ("ilc", {}),
}

#: The spatial controllers (item 3): the catenary's and the chain's starts, the closed loop, ILC and the model
#: feed-forward (learned on the model) with and without the loop.
SPATIAL = {**{f"tension_aware{'_chain' if statics == 'chain' else ''}_{start}": ("tension_aware",
                                                                               {"statics": statics, "start": start})
              for statics in ("catenary", "chain") for start in ("absolute", "relative", "calibrated")},
           "closed_loop_tension_aware": ("closed_loop_tension_aware", {}),
           "closed_loop_tension_aware_previous": ("closed_loop_tension_aware", dict(SPATIAL_LOOP_PREVIOUS)),
           "ilc": ("ilc", {}),
           "model_feed_forward": ("model_feed_forward", {}),
           "closed_loop_model_feed_forward": ("closed_loop_model_feed_forward", {})}

#: The spatial robots (item 4): the CoGiRo-class and the IPAnema-class, each nominal and with a 10 % model error.
SPATIAL_SCENES = ("spatial-cogiro", "spatial-ipanema")

#: Poses the loop is linearised at: 8 over one turn of the circle, after the 1 s ramp.
POSES = 8

#: The spatial loops: controller -> whether it feeds the rotation back (:data:`controllers.registry.SPATIAL_LOOP`).
SPATIAL_LOOPS = dict.fromkeys(("closed_loop_tension_aware", "closed_loop_model_feed_forward"), SPATIAL_LOOP["rotation"])

#: Poses a spatial loop is linearised at: evenly over the whole run, the trajectory's ramp included.
SPATIAL_POSES = 24

#: The spatial gains the design chooses from (k_p, k_i [1/s], f_c [Hz]), around SPATIAL_LOOP's and below.
SPATIAL_CANDIDATES = [loop_design.LoopGains(p, i, c) for p in (0.1, 0.2, 0.3, 0.5) for i in (0.0, 1.0, 2.5, 5.0)
                      for c in (0.5, 1.0, 1.5, 2.0)]

#: The grid: mass x density, then stiffness and exit position one at a time
#: (:data:`~cdpr_exu.studies.robustness.ERRORS`).
GRID = [*error_grid(), *error_grid((0.0,), (0.0,), cable_stiffness=(-0.2, 0.2)),
        *error_grid((0.0,), (0.0,), exit_offset=(-0.003, 0.003))]

#: A plant's errors as the tables show them.
LABELS = {"platform_mass": ("mass", "{:+.0%}"), "cable_density": ("density", "{:+.0%}"),
          "cable_stiffness": ("stiffness", "{:+.0%}"), "exit_offset": ("exits [mm]", "{:+.0f}")}


def margins_rows(cases, grid, loops: dict, rows, delay: float) -> list[dict]:
    """Per loop (name -> (controller, gains, measured coordinates)) and plant: the worst margins over the poses,
    and what the real run did."""
    runs = {(*(r[e] for e in ERRORS), r["controller"]): r for r in rows}
    table = []
    for (name, (label, chosen, size)), (index, point) in ((g, p) for g in loops.items() for p in enumerate(grid)):
        margins = loop_design.worst([loop_design.loop_margins(replace(robot, outputs=size), jacobian[:, :size],
                                                              chosen, delay, response=response[:, :size, :size])
                                     for i, _, robot, jacobian, response in cases if i == index])
        point = {**dict.fromkeys(ERRORS, 0.0), **point}
        run = runs.get((*(point[e] for e in ERRORS), label), {})
        table.append({**{e: point[e] for e in ERRORS}, "gains": name, **asdict(chosen), **asdict(margins),
                      "run": ("completed" if run.get("completed") else f"failed at {run.get('failure_time_s') or 0.0:.1f} s"
                              if run else "not run"),
                      "max_position_error_m": run.get("max_position_error_m") if run.get("completed") else None,
                      "max_error_vs_ideal_ik": run.get("max_error_vs_ideal_ik")})
    return table


def margins_markdown(table, labels=LABELS) -> str:
    lines = ["| " + " | ".join(label for label, _ in labels.values()) + " | gains (k_p, k_i [1/s], f_c [Hz]) | "
             "gain margin [dB] | phase margin [deg] | disk margin | sensitivity peak | min pole damping | linear model "
             "| run | max error [mm] | vs ideal IK |", "|---" * (len(labels) + 10) + "|"]
    for r in table:
        error, ratio = r["max_position_error_m"], r["max_error_vs_ideal_ik"]
        plant = " | ".join(form.format(r[e] * (1000.0 if e == "exit_offset" else 1.0))
                           for e, (_, form) in labels.items())
        lines.append(f"| {plant} | {r['gains']} ({r['proportional_gain']:g}, "
                     f"{r['integral_gain']:g}, {r['cutoff']:g}) | {r['gain_margin_db']:.1f} | {r['phase_margin_deg']:.1f} | "
                     f"{r['disk_margin']:.2f} | {r['sensitivity_peak']:.2f} | {r['min_damping']:.3f} | "
                     f"{'stable' if r['stable'] else 'UNSTABLE'} | {r['run']} | "
                     f"{'' if error is None else f'{1000 * error:.2f}'} | {'' if ratio is None else f'{ratio:.1f}x'} |")
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    parser.add_argument("--fresh", action="store_true", help="forget the rows of an earlier run (rows.jsonl)")
    parser.add_argument("--skip-spatial", action="store_true", help="the planar study only")
    args = parser.parse_args()
    if args.fresh:
        for folder in ("planar", *SPATIAL_SCENES):
            (OUT / folder / ROBUSTNESS_FILES["rows"]).unlink(missing_ok=True)

    model = smooth_start(load_scene("paper-circle"))
    grid, delay = GRID, model.solver.step_size
    turn = 2 * np.pi / model.trajectory.angular_rate
    cases = loop_design.loop_cases(model, [perturbed(model, **point) for point in grid],
                                   1.0 + turn * np.arange(POSES) / POSES)
    designed, _ = loop_design.design_gains(cases, delay, model.trajectory.angular_rate / (2 * np.pi))
    if designed != loop_design.DESIGNED:
        raise SystemExit(f"the margins now pick {designed}, not the defaults {loop_design.DESIGNED}: update "
                         "controllers.loop_design.DESIGNED (and the closed-loop golden cases) first")
    gains = {"previous": ("closed_loop_tension_aware_previous", loop_design.PREVIOUS, 2),
             "designed": ("closed_loop_tension_aware", designed, 2)}
    rows = run_robustness(model, PLANAR, grid, OUT / "planar", workers=args.workers)
    table = margins_rows(cases, grid, gains, rows, delay)
    write_summary(OUT / "planar", {"scene": model.name, "poses_per_plant": POSES, "delay_s": delay,
                                   "design": "gain margin >= 6 dB and phase margin >= 30 deg on every plant and pose; "
                                             "the smallest worst sensitivity at the circle's frequency",
                                   "rows": table}, name="margins.json")
    (OUT / "planar" / "margins.md").write_text(margins_markdown(table))
    print((OUT / "planar" / ROBUSTNESS_FILES["table"]).read_text())
    print(margins_markdown(table))
    if not args.skip_spatial:
        spatial_study(args.workers)
    print(f"written to {OUT}/")


def spatial_study(workers) -> None:
    """The spatial robots' runs (item 3) and their loops' margins, the gains designed over both robots."""
    grid = [{"platform_mass": 0.0, "cable_density": 0.0}, {"platform_mass": 0.1, "cable_density": -0.1}]
    studies = {}
    for name in SPATIAL_SCENES:
        scene = load_scene(name)
        rows = run_robustness(scene, SPATIAL, grid, OUT / name, workers=workers)
        print((OUT / name / ROBUSTNESS_FILES["table"]).read_text())
        times = scene.solver.end_time * (np.arange(SPATIAL_POSES) + 0.5) / SPATIAL_POSES  # the ramp's poses too
        studies[name] = (scene, rows, times, loop_design.loop_cases(scene, [perturbed(scene, **p) for p in grid], times,
                                                                    rotation=True))
    delays = {scene.solver.step_size for scene, *_ in studies.values()}
    frequency = max(scene.trajectory.angular_rate / (2 * np.pi) for scene, *_ in studies.values())
    designed, _ = loop_design.design_gains([case for *_, cases in studies.values() for case in cases], max(delays),
                                           frequency, candidates=SPATIAL_CANDIDATES, disk_only=True)
    default, previous = (loop_design.LoopGains(*(gains[k] for k in ("proportional_gain", "integral_gain", "cutoff")))
                         for gains in (SPATIAL_LOOP, SPATIAL_LOOP_PREVIOUS))
    if designed != default:
        raise SystemExit(f"the margins now pick {designed} for the spatial loop, not the defaults {default}: update "
                         "controllers.registry.SPATIAL_LOOP (and the spatial closed-loop golden cases) first")
    for name, (scene, rows, times, cases) in studies.items():
        loops = {**{label: (label, default, 6 if rotation else 3) for label, rotation in SPATIAL_LOOPS.items()},
                 "previous": ("closed_loop_tension_aware_previous", previous, 6)}
        table = margins_rows(cases, grid, loops, rows, scene.solver.step_size)
        write_summary(OUT / name, {"scene": name, "poses_s": times.tolist(), "delay_s": scene.solver.step_size,
                                   "loops": {label: {**SPATIAL_LOOP, "rotation": rotation}
                                             for label, rotation in SPATIAL_LOOPS.items()},
                                   "design": "gain margin >= 6 dB and phase margin >= 30 deg on both robots, both plants "
                                             "and every pose, rotation fed back; the smallest worst sensitivity at the "
                                             "circles' frequency: the defaults (controllers.registry.SPATIAL_LOOP)",
                                   "rows": table}, name="margins.json")
        (OUT / name / "margins.md").write_text(margins_markdown(table, {e: LABELS[e] for e in grid[0]}))
        print(margins_markdown(table, {e: LABELS[e] for e in grid[0]}))


if __name__ == "__main__":  # required: the worker processes are spawned and re-import this file
    main()
