"""``cdpr static``: a scene brought to rest (:mod:`cdpr_exu.run.rest`)."""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, SolverFailure, SuspectAnswerWarning
from cdpr_exu.core.output import check_output_folder, clear_outputs, write_summary
from cdpr_exu.results.result import provenance
from cdpr_exu.run.rest import DEFAULT_MAX_TIME, DEFAULT_TOLERANCE, solve_rest
from cdpr_exu.scenes.scene import Scene, load_scene, save_scene

EPILOG = """examples:
  cdpr static paper-catenary-fixed --out results/static_fixed
  cdpr static paper-catenary --out results/static_pulleys --tolerance 1e-7
  cdpr static spatial-four-cable --out results/static_spatial

A spatial scene (dimension = 3) is solved directly by Exudyn's static solver, started on
its elastic-catenary statics (--tolerance, --max-time and --no-polish do not apply), and
reports the platform's position and rotation beside the catenary answer; it warns when the
two lie more than 5 % of the shortest cable apart or an element is compressed, and fails
(exit 3, with the cause) on an equilibrium that holds the platform above its exits.
"""


def _write_static_failure(scene: Scene, err: SolverFailure, out: Path) -> None:
    """Write what a failed ``cdpr static`` knows: the scene, the cause and the last state."""
    clear_outputs(out, "static")  # no file of an earlier `cdpr static` there stays beside these
    save_scene(scene, out / "scene.toml")
    partial = err.partial_result if isinstance(err.partial_result, dict) else {}
    write_summary(out, {"scene": scene.name, "status": f"failed: {err}", "failure_time_s": err.time,
                        "last_state": partial, **provenance()})


def _cmd_static(args: argparse.Namespace) -> int:
    out = check_output_folder(args.out, command="static")
    scene = load_scene(args.scene)
    try:
        rest = solve_rest(scene, tolerance=args.tolerance, max_time=args.max_time, polish=not args.no_polish)
    except SolverFailure as err:
        if out is not None:
            _write_static_failure(scene, err, out)
            print(f"cdpr static: the scene, the cause and the last state are written to {out}/", file=sys.stderr)
        raise
    if out is not None:
        from cdpr_exu.post.plots import plot_rest  # matplotlib only where a figure is drawn

        clear_outputs(out, "static")  # no file of an earlier `cdpr static` there stays beside these
        rest.save(out)
        plot_rest(rest, out / "rest_profile.png")
    if not args.quiet:
        print("\n".join(rest.summary_lines() + ([f"  written to {out}/"] if out is not None else [])))
    for text in rest.warnings:  # also in summary.json
        warnings.warn(text, SuspectAnswerWarning, stacklevel=2)
    return EXIT_OK


def add_commands(subparsers) -> None:
    """Register ``cdpr static``."""
    parser = subparsers.add_parser(
        "static", help="bring a scene to rest and write its static state",
        description="Bring a scene to rest with the winches held (a planar scene: dynamics with its own damping, "
        "then Exudyn's static solver; a spatial one: Exudyn's static solver from its catenaries), and write "
        "summary.json (platform pose, end forces, nodes), rest_profile.png and, planar, rest.npz.", epilog=EPILOG + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="shipped scene name (see `cdpr scenes`) or path to a .toml file")
    parser.add_argument("--out", help="output folder (created); nothing is written without it")
    parser.add_argument("--tolerance", type=float, default=DEFAULT_TOLERANCE,
                        help=f"largest node speed counted as rest [m/s] (default {DEFAULT_TOLERANCE:g})")
    parser.add_argument("--max-time", type=float, default=DEFAULT_MAX_TIME,
                        help=f"give up after this much simulated time [s] (default {DEFAULT_MAX_TIME:g})")
    parser.add_argument("--no-polish", action="store_true", help="skip Exudyn's static solver after the dynamics")
    parser.add_argument("-q", "--quiet", action="store_true", help="print nothing")
    parser.set_defaults(func=_cmd_static)
