"""The ``cdpr`` command: run scenes, and write what people want to look at.

Examples::

    cdpr run paper-circle --out results/paper_circle
    cdpr run my_robot.toml --out out/my_robot --end-time 5 --step-size 1e-3
    cdpr scenes
"""

from __future__ import annotations

import argparse
import importlib
import json
import sys
from dataclasses import replace
from pathlib import Path

from .errors import CdprError, SolverFailure
from .scene import Scene, load_scene, save_scene, shipped_scenes

#: Modules that add sub-commands: each has ``add_commands(subparsers)``, which adds
#: parsers whose ``func`` takes the parsed arguments and returns an exit code.
COMMAND_MODULES: tuple[str, ...] = ("cdpr_exu.comparison", "cdpr_exu.study", "cdpr_exu.viewer", "cdpr_exu.accuracy",
                                   "cdpr_exu.rest")

#: Errors are measured after this start-up time in the printed "settled" figures [s].
SETTLED_AFTER = 1.0

EPILOG_RUN = """examples:
  cdpr run paper-circle --out results/paper_circle
  cdpr run scene.toml --out out/run1 --end-time 2 --step-size 1e-3 --quiet
"""


def _scene_with_overrides(args: argparse.Namespace) -> Scene:
    scene = load_scene(args.scene)
    changes = {}
    if getattr(args, "end_time", None) is not None:
        changes["end_time"] = args.end_time
    if getattr(args, "step_size", None) is not None:
        changes["step_size"] = args.step_size
    if changes:
        scene = scene.with_changes(solver=replace(scene.solver, **changes))
    return scene


def _print_summary(summary: dict, settled: dict, out: Path | None) -> None:
    rows = [
        ("status", summary["status"], ""),
        ("max |error x|", f"{100 * summary['max_abs_error_x_m']:.2f} cm",
         f"{100 * settled['max_abs_error_x_m']:.2f} cm"),
        ("max |error z|", f"{100 * summary['max_abs_error_z_m']:.2f} cm",
         f"{100 * settled['max_abs_error_z_m']:.2f} cm"),
        ("error z range", f"{100 * summary['min_error_z_m']:+.2f} .. {100 * summary['max_error_z_m']:+.2f} cm",
         f"{100 * settled['min_error_z_m']:+.2f} .. {100 * settled['max_error_z_m']:+.2f} cm"),
        ("max |rotation|", f"{summary['max_abs_rotation_deg']:.2f} deg", f"{settled['max_abs_rotation_deg']:.2f} deg"),
        ("min element tension", f"{summary['min_element_tension_N']:.2f} N", f"{settled['min_element_tension_N']:.2f} N"),
        ("max pulley penetration", f"{1000 * summary['max_pulley_penetration_m']:.3f} mm", ""),
        ("simulated / wall time", f"{summary['simulated_time_s']:.2f} s / {summary['wall_time_s']:.2f} s",
         f"{summary['real_time_factor']:.1f}x real time"),
        ("steps / Newton iterations", f"{summary['steps']} / {summary['newton_iterations']}", ""),
    ]
    print(f"{summary['scene']} under {summary['controller']} (error = actual - reference)")
    print(f"  {'':26s} {'whole run':>22s}   {'after ' + str(SETTLED_AFTER) + ' s':>18s}")
    for name, whole, after in rows:
        print(f"  {name:26s} {whole:>22s}   {after:>18s}")
    if out is not None:
        print(f"  written to {out}/")


def run_scene(scene: Scene, out: Path | None, *, quiet: bool = False, figures: bool = True,
              controller=None) -> dict:
    """Run ``scene`` and write its files into ``out``; returns the summary.

    Writes ``scene.toml``, ``result.npz``, ``pose.csv``, ``summary.json``,
    ``solution.sol`` (Exudyn's solution file, for ``SolutionViewer``) and the figures.
    A failed run still writes what was computed up to the failure, then re-raises.
    """
    from .simulate import simulate

    solution_file = None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        save_scene(scene, out / "scene.toml")
        solution_file = out / "solution.sol"
    failure = None
    try:
        result = simulate(scene, controller, solution_file=solution_file, progress=not quiet)
    except SolverFailure as err:
        failure, result = err, err.partial_result
    summary = result.summary()
    settled = result.summary(after=SETTLED_AFTER)
    if out is not None:
        result.save(out)
        data = json.loads((out / "summary.json").read_text())
        data["after_start_up"] = {k: settled[k] for k in (
            "errors_measured_after_s", "max_abs_error_x_m", "max_abs_error_z_m", "min_error_z_m",
            "max_error_z_m", "max_position_error_m", "rms_position_error_m", "max_abs_rotation_deg",
            "min_element_tension_N")}
        data["error_convention"] = "actual - reference"
        (out / "summary.json").write_text(json.dumps(data, indent=2, default=str) + "\n")
        if figures and len(result.time) > 1:
            from .plots import plot_overview

            plot_overview(scene, result, out)
    if not quiet:
        _print_summary(summary, settled, out)
    if failure is not None:
        raise failure
    return summary


def _cmd_run(args: argparse.Namespace) -> int:
    scene = _scene_with_overrides(args)
    out = Path(args.out) if args.out else None
    run_scene(scene, out, quiet=args.quiet, figures=not args.no_figures)
    return 0


def _cmd_scenes(args: argparse.Namespace) -> int:  # noqa: ARG001
    for name in shipped_scenes():
        scene = load_scene(name)
        print(f"{name:24s} {scene.description}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``cdpr`` (every sub-command's ``--help`` has examples)."""
    parser = argparse.ArgumentParser(
        prog="cdpr", description="Simulate cable-driven parallel robots with massive, elastic, bending cables "
        "over pulleys (Exudyn, implicit solver). Units: SI.",
        epilog="examples:\n  cdpr run paper-circle --out results/paper_circle\n  cdpr scenes\n",
        formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a scene and write result, summary and figures",
                         description="Run a scene (a shipped name or a TOML file) under ideal "
                         "inverse-kinematics control and write its result, summary, Exudyn solution "
                         "file and figures.", epilog=EPILOG_RUN,
                         formatter_class=argparse.RawDescriptionHelpFormatter)
    run.add_argument("scene", help="shipped scene name (see `cdpr scenes`) or path to a .toml file")
    run.add_argument("--out", help="output folder (created); nothing is written without it")
    run.add_argument("--end-time", type=float, help="override solver.end_time [s]")
    run.add_argument("--step-size", type=float, help="override solver.step_size [s]")
    run.add_argument("--no-figures", action="store_true", help="skip the figures")
    run.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    run.set_defaults(func=_cmd_run)

    scenes = sub.add_parser("scenes", help="list the shipped scenes",
                            epilog="example:\n  cdpr scenes\n", formatter_class=argparse.RawDescriptionHelpFormatter)
    scenes.set_defaults(func=_cmd_scenes)
    for module_name in COMMAND_MODULES:
        module = importlib.import_module(module_name)
        module.add_commands(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``cdpr`` console script."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except SolverFailure as err:
        print(f"cdpr: solver failure: {err}", file=sys.stderr)
        return 3
    except CdprError as err:
        print(f"cdpr: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
