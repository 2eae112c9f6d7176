"""``cdpr study``: parameter sweeps (:mod:`cdpr_exu.studies.study`) and the accuracy study
(:mod:`cdpr_exu.studies.accuracy`)."""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, EXIT_RUN_FAILED
from cdpr_exu.core.output import check_output_folder
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.studies.accuracy import check_study_scene, format_tables, grid_for, run_accuracy_study
from cdpr_exu.studies.study import as_variations, format_table, run_study

EPILOG_STUDY = """examples:
  cdpr study sweep paper-circle --param cables.n_elements=10,15 --param platform.mass=1,2.5 --out results/study
  cdpr study sweep --help
"""

EPILOG_SWEEP = """examples:
  cdpr study sweep paper-circle --param cables.n_elements=8,10,15 --param platform.mass=1,2.5,5 --out out/grid
  cdpr study sweep paper-circle --param effects.preset=full,catenary --end-time 2 --out out/presets
  cdpr study sweep scene.toml --param 'cables[1].radius=0.004,0.006' --param solver.step_size=1e-3,2e-3 \\
      --zip --out out/zipped --workers 2
  cdpr study sweep paper-circle --param platform.mass=1,2.5,5 --out out/local-dask --scheduler local
  cdpr study sweep paper-circle --param platform.mass=1,2.5,5 --out out/cluster --scheduler tcp://10.0.0.1:8786

parameter paths name fields of the scene's TOML form: cables.n_elements (every cable),
cables[1].radius (one cable), platform.mass, solver.step_size, effects.bending,
effects.preset, trajectory.angular_rate, platform.initial_pose[1], ...
values are TOML scalars: 5, 2.5, 1e-3, true, false, "full" (or a bare word: full).

writes study.csv, study.json, base_scene.toml and vs_<parameter>.png (+ heatmap.png
for a 2-parameter grid) into --out. Failed and refused runs are recorded as rows.
"""


def _cmd_sweep(args: argparse.Namespace) -> int:
    scene = load_scene(args.scene)  # planar or spatial
    if args.end_time is not None:
        scene = scene.with_changes(solver=replace(scene.solver, end_time=args.end_time))
    if args.scheduler and args.scheduler != "local" and args.workers and not args.quiet:
        print("cdpr study: --workers is ignored with a remote --scheduler (its workers run the study)",
              file=sys.stderr)
    variations = as_variations(args.param)
    out = check_output_folder(args.out, command="study sweep")
    rows = run_study(scene, variations, out=out, progress=not args.quiet, after=args.after,
                     mode="zip" if args.zip else "grid", workers=args.workers, scheduler=args.scheduler)
    if not args.quiet:
        print(format_table(rows, variations))
        done = sum(row["status"] == "completed" for row in rows)
        print(f"{done} of {len(rows)} runs completed; written to {out}/")
    failed = sum(row["status"] != "completed" for row in rows)
    if failed:
        print(f"cdpr study sweep: {failed} of {len(rows)} runs did not complete (see the status column)",
              file=sys.stderr)
        return EXIT_RUN_FAILED
    return EXIT_OK


def _add_sweep(study: argparse._SubParsersAction) -> None:
    sweep = study.add_parser(
        "sweep", help="run a scene over a grid of parameter values",
        description="Run a scene once per combination of parameter values (a grid, or --zip), in "
        "parallel, and write a CSV/JSON table and summary plots. Failed and refused runs are recorded, "
        "not fatal.", epilog=EPILOG_SWEEP + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    sweep.add_argument("scene", help="shipped scene name (see `cdpr scenes`) or path to a .toml file")
    sweep.add_argument("--param", action="append", required=True, metavar="PATH=V1,V2,...",
                       help="a parameter and its values; repeat for more parameters")
    sweep.add_argument("--zip", action="store_true",
                       help="run the i-th values of all parameters together instead of the grid")
    sweep.add_argument("--out", required=True, help="output folder (created)")
    sweep.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    sweep.add_argument("--scheduler", metavar="ADDRESS|local",
                       help="run on a Dask cluster: its scheduler's address (tcp://host:8786), or 'local' "
                       "to start one on this machine")
    sweep.add_argument("--end-time", type=float, help="override solver.end_time of every run [s]")
    sweep.add_argument("--after", type=float, default=1.0,
                       help="measure errors from this time on [s] (default 1; 0 for runs not longer)")
    sweep.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no table")
    sweep.set_defaults(func=_cmd_sweep)


EPILOG_ACCURACY = """examples:
  cdpr study accuracy paper-circle --out results/accuracy/paper_circle
  cdpr study accuracy paper-catenary --out results/accuracy/paper_catenary
  cdpr study accuracy paper-circle --out /tmp/quick --quick
  cdpr study accuracy spatial-ipanema --out /tmp/ipanema --quick

runs the scene on every preset (ideal, elastic, catenary, full) and the full model
with linear bending, over elements per cable (8..60) and step sizes (5e-4..1e-2 s),
against a reference (full, 90 elements, 5e-4 s); --quick: a small grid, 1.5 s.
A static scene (held pose, fixed winches) compares final states, others the path.

spatial scenes (dimension = 3, with a [trajectory]) run under ideal inverse kinematics on
the catenary and full presets over 4..16 elements and 5e-3..2e-2 s against (full, 32
elements, 2e-3 s); --quick: full at 4 and 8 elements, 1e-2 s, against 16, 1.5 s.
Errors: the platform centre's 3-D path and the angle between the orientations.
writes accuracy.csv, accuracy.json, tables.md (tolerance table, effects table),
pareto.png and reference.npz into --out.
"""


def _cmd_accuracy(args: argparse.Namespace) -> int:
    scene = load_scene(args.scene)  # planar or spatial
    check_study_scene(scene)  # before the output folder is made
    grid = grid_for(scene, args.quick)
    if args.end_time is not None:
        grid = replace(grid, end_time=args.end_time)

    out = check_output_folder(args.out, command="study accuracy")
    start = time.perf_counter()
    study = run_accuracy_study(scene, grid, out=out, workers=args.workers, progress=not args.quiet,
                               comparison=args.compare)
    if not args.quiet:
        print(format_tables(study))
        print(f"\n{len(study.rows)} runs in {time.perf_counter() - start:.0f} s; written to {out}/")
    return 0


def _add_accuracy(study: argparse._SubParsersAction) -> None:
    accuracy = study.add_parser(
        "accuracy", help="error against run time over the model ladder, elements and step sizes",
        description="Run a scene on every model of the ladder over elements per cable and step sizes, "
        "compare each run with a reference (the full model, finest discretisation), and write the "
        "Pareto front of error against run time (CPU time) and the cheapest configuration per tolerance.",
        epilog=EPILOG_ACCURACY + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    accuracy.add_argument("scene", help="shipped scene name (see `cdpr scenes`) or path to a .toml file")
    accuracy.add_argument("--out", required=True, help="output folder (created)")
    accuracy.add_argument("--quick", action="store_true", help="a small grid over 1.5 s (a minute or less)")
    accuracy.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    accuracy.add_argument("--end-time", type=float, help="override the end time of every run [s]")
    accuracy.add_argument("--compare", choices=("path", "final"),
                          help="compare the path after 1 s or the final state (default: final for static scenes)")
    accuracy.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no tables")
    accuracy.set_defaults(func=_cmd_accuracy)


def add_commands(subparsers: argparse._SubParsersAction) -> None:
    """Add ``cdpr study`` with its sub-commands ``sweep`` and ``accuracy`` to the ``cdpr`` command."""
    study = subparsers.add_parser("study", help="parameter studies over a scene, in parallel",
                                  description="Parameter studies: run a scene over many parameter values "
                                  "on all cores or on a Dask cluster, and tabulate and plot the results.",
                                  epilog=EPILOG_STUDY + "\n" + EXIT_CODES,
                                  formatter_class=argparse.RawDescriptionHelpFormatter)
    study_sub = study.add_subparsers(dest="study_command", required=True, metavar="COMMAND")
    _add_sweep(study_sub)
    _add_accuracy(study_sub)
