"""``cdpr compare``: a scene under every controller, tabulated (:mod:`cdpr_exu.studies.comparison`)."""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, EXIT_RUN_FAILED, SceneError
from cdpr_exu.core.output import check_output_folder
from cdpr_exu.core.validation import non_negative
from cdpr_exu.results.result import raise_warnings, status_text
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.statics.workspace import check_reference
from cdpr_exu.studies.comparison import (COMPARISON_RAMP_TIME, CONTROLLERS, compare_controllers, comparison_format,
                                         smooth_start)
from cdpr_exu.studies.learning import DEFAULT_RULE, StoppingRule


def print_controller_row(name: str, summary: dict) -> None:
    """The line ``cdpr compare`` prints as a controller's run ends: max and RMS position error, status."""
    def mm(value):  # sub-millimetre errors (spatial robots) with their micrometres
        return "     n/a" if value is None else f"{1000 * value:8.2f}" if value >= 1e-3 else f"{1000 * value:8.4f}"
    print(f"  {name:32s} max {mm(summary['max_position_error_m'])} mm   "
          f"RMS {mm(summary['rms_position_error_m'])} mm   {status_text(summary)}")


def print_progress(line: str) -> None:
    """Print a line of the learning controllers' progress at once."""
    print(line, flush=True)


def _show(scene, summaries: dict, table, args: argparse.Namespace) -> list[str]:
    """Issue each controller's warnings, print ``table(summaries)`` unless ``--quiet``; returns the
    controllers whose run did not complete."""
    for name, summary in summaries.items():
        raise_warnings(summary, f"{scene.name} under {name}: ")
    if not args.quiet:
        print()
        print(table(summaries))
        if args.out:
            print(f"written to {args.out}/")
    return [name for name, summary in summaries.items() if summary.get("status") != "completed"]


def _cmd_compare(args: argparse.Namespace) -> int:
    non_negative("--after", args.after)
    non_negative("--ramp-time", args.ramp_time)
    check_output_folder(args.out, command="compare")
    scene = load_scene(args.scene)
    started = smooth_start(scene, args.ramp_time)
    if started is not scene and not args.quiet:
        print(f"{scene.name}: the circle starts smoothly from rest over {args.ramp_time} s "
              "(--ramp-time 0 keeps the scene's start at full speed)")
    scene = started
    if args.end_time is not None:
        scene = scene.with_changes(solver=replace(scene.solver, end_time=args.end_time))
    # A reference no controller can follow is bad input (exit 2), not six failed runs.
    check_reference(scene)
    try:
        rule = StoppingRule(max_trials=args.trials, min_improvement=args.min_improvement)
    except SceneError as err:
        raise SceneError(f"--trials / --min-improvement: {err}") from None
    names = args.controllers.split(",") if args.controllers else None
    if not args.quiet:
        print(f"{scene.name}: comparing controllers on the {scene.space.name} robot (errors after {args.after} s)")
    summaries = compare_controllers(scene, names, out=args.out, after=args.after, progress=False, learning_rule=rule,
                                    report=None if args.quiet else print_controller_row,
                                    learning_report=None if args.quiet else print_progress)
    failed = _show(scene, summaries, comparison_format(scene).table, args)
    if failed:
        print(f"cdpr compare: {len(failed)} of {len(summaries)} controllers did not complete: {', '.join(failed)}",
              file=sys.stderr)
        return EXIT_RUN_FAILED
    return EXIT_OK


def add_commands(subparsers) -> None:
    """Register ``cdpr compare``."""
    parser = subparsers.add_parser(
        "compare", help="run a scene under every controller and compare their errors",
        description="Run a scene under each controller (ideal inverse kinematics, tension-aware variants, "
        "closed loop) and write a table and figures of their errors.",
        epilog="examples:\n  cdpr compare paper-circle --out results/controllers\n"
               "  cdpr compare paper-circle-slow --controllers ideal_ik,tension_aware_chordal\n\n" + EXIT_CODES,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="shipped scene name or path to a .toml file")
    parser.add_argument("--out", help="output folder (summary.json, comparison.md, figures)")
    parser.add_argument("--controllers", help=f"comma-separated subset of: {', '.join(CONTROLLERS)}")
    parser.add_argument("--after", type=float, default=1.0, help="measure errors after this time [s] (default 1)")
    parser.add_argument("--end-time", type=float, help="override solver.end_time [s]")
    parser.add_argument("--ramp-time", type=float, default=COMPARISON_RAMP_TIME,
                        help="start a circle that starts at full speed smoothly from rest over this time [s] "
                             f"(default {COMPARISON_RAMP_TIME}; 0 keeps the scene's own start)")
    parser.add_argument("--trials", type=int, default=DEFAULT_RULE.max_trials,
                        help=f"most learning trials of ilc and model_feed_forward (default {DEFAULT_RULE.max_trials})")
    parser.add_argument("--min-improvement", type=float, default=DEFAULT_RULE.min_improvement,
                        help="stop learning when a trial's max error falls by less than this fraction "
                             f"(default {DEFAULT_RULE.min_improvement})")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    parser.set_defaults(func=_cmd_compare)
