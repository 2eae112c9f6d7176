"""``cdpr run``: run a planar or spatial scene, write its files and print its summary."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, CdprError, RunInterrupted, SolverFailure
from cdpr_exu.core.output import check_output_folder, clear_outputs, fixed, length_text, undate_solution_file
from cdpr_exu.results.result import raise_warnings, status_text
from cdpr_exu.run.error_estimate import (elements_for_tolerance, estimate_error, estimate_line, parse_length,
                                         summary_entry)
from cdpr_exu.run.simulate import check_runnable, simulate
from cdpr_exu.scenes.scene import Scene, load_scene, save_scene
from cdpr_exu.space import PLANE, SPACE, Space

#: Errors are measured after this start-up time in the printed "settled" figures [s].
SETTLED_AFTER = 1.0

EPILOG_RUN = """examples:
  cdpr run paper-circle --out results/paper_circle
  cdpr run scene.toml --out out/run1 --end-time 2 --step-size 1e-3 --quiet

""" + EXIT_CODES


def _scene_with_overrides(args: argparse.Namespace, scene: Scene) -> Scene:
    """``scene`` with ``--end-time`` and ``--step-size`` applied."""
    changes = {key: getattr(args, key) for key in ("end_time", "step_size") if getattr(args, key) is not None}
    return scene.with_changes(solver=replace(scene.solver, **changes)) if changes else scene


def _figure(value, scale: float = 1.0, unit: str = "", digits: int = 2, sign: bool = False) -> str:
    """A printed figure, or "n/a" when it does not exist (None); never "nan" or "-0.00"."""
    if value is None:
        return "n/a"
    text = fixed(scale * value, digits)
    if sign and not text.startswith("-"):
        text = "+" + text
    return f"{text} {unit}".rstrip()


def _print_summary(summary: dict, settled: dict, space: Space, out: Path | None) -> None:
    """Print a run's summary: one table of errors (rows from the Space's labels) over the whole run and
    after :data:`SETTLED_AFTER`, tensions, slack and cost; then tension-limit violations, notes, folder."""
    def pair(key, scale, unit, digits=2):  # a figure a space leaves out is n/a (and its row not printed)
        return _figure(summary.get(key), scale, unit, digits), _figure(settled.get(key), scale, unit, digits)

    def length(key):  # centimetres as the paper's tables; below 1 mm (a spatial robot) never "0.00 cm"
        return tuple("n/a" if s.get(key) is None else _figure(s[key], 100, "cm") if abs(s[key]) >= 1e-3
                     else length_text(s[key]) for s in (summary, settled))

    def vertical_range(s):
        if s[f"min_error_{vertical}_m"] is None:
            return "n/a"
        return (f"{_figure(s[f'min_error_{vertical}_m'], 100, '', sign=True)} .. "
                f"{_figure(s[f'max_error_{vertical}_m'], 100, '', sign=True)} cm")

    def position(s):
        if s["max_position_error_m"] is None:
            return "n/a"
        return f"{length_text(s['max_position_error_m'])} / {length_text(s['rms_position_error_m'])}"

    vertical = space.position_labels[space.vertical]
    factor = summary["real_time_factor"]
    rows = [
        ("status", status_text(summary), ""),
        *((f"max |error {axis}|", *length(f"max_abs_error_{axis}_m")) for axis in space.position_labels),
        (f"error {vertical} range", vertical_range(summary), vertical_range(settled)),
        ("max / RMS position error", position(summary), position(settled)),
        ("max |rotation|", *pair("max_abs_rotation_deg", 1, "deg")),
        ("max rotation error", *pair("max_rotation_error_deg", 1, "deg", 4)),
        # tensions, slack and limits: over the whole run only (Result.summary)
        ("min element tension", _figure(summary["min_element_tension_N"], 1, "N"), ""),
        ("min tension per cable", " / ".join(_figure(v, 1, "N") for v in summary["min_tension_per_cable_N"]), ""),
        ("slack time per cable", " / ".join(_figure(v, 1, "s") for v in summary["slack_time_per_cable_s"]), ""),
        ("max pulley penetration", _figure(summary["max_pulley_penetration_m"], 1000, "mm", 3), ""),
        ("simulated / wall / CPU", f"{summary['simulated_time_s']:.2f} s / {summary['wall_time_s']:.2f} s / "
                                    f"{summary['cpu_time_s']:.2f} s",
         "n/a" if factor is None else f"{factor:.1f}x real time"),
        ("steps / Newton iterations", f"{summary['steps']} / {summary['newton_iterations']}", ""),
    ]
    left_out = NOT_PRINTED[space]
    if "tension_limit_violations" in summary:
        violations = summary["tension_limit_violations"]
        rows.append(("tension limits", f"{len(violations)} violation(s)" if violations else "none", ""))
    print(f"{summary['scene']} under {summary['controller']} (error = actual - reference)")
    print(f"  {'':26s} {'whole run':>22s}   {'after ' + str(SETTLED_AFTER) + ' s':>18s}")
    for name, whole, after in rows:
        if name not in left_out:
            print(f"  {name:26s} {whole:>22s}   {after:>18s}")
    for v in summary.get("tension_limit_violations", []):
        print(f"  cable {v['cable']} beyond its {v['limit']} ({v['limit_N']:g} N) from t = {v['first_time_s']:.3f} s "
              f"for {v['duration_s']:.3f} s, reaching {v['extreme_N']:.4g} N")
    for note in dict.fromkeys(summary["notes"] + settled["notes"]):
        print(f"  note: {note}")
    if out is not None:
        print(f"  written to {out}/")


#: Rows of the printed summary a space leaves out.
NOT_PRINTED = {PLANE: ("max / RMS position error", "max rotation error"), SPACE: ("max pulley penetration",)}

def run_scene(scene: Scene, out: Path | None, *, quiet: bool = False, figures: bool = True,
              controller=None, error_estimate: bool = False) -> dict:
    """Run ``scene`` and write its files into ``out``; returns the summary.

    Writes ``scene.toml`` (a rerun from it gives the same result), ``result.npz``, ``pose.csv``,
    ``summary.json`` (wall-clock figures in ``timing.json``), ``solution.sol`` (its date blanked) and the
    figures, after removing an earlier run's files there (:func:`~cdpr_exu.core.output.clear_outputs`).
    ``out`` and the reference are checked before anything is written; a failed or interrupted run writes
    what was computed, then re-raises. With ``error_estimate`` a companion run estimates the
    discretisation error (:mod:`cdpr_exu.run.error_estimate`).
    """
    check_runnable(scene)  # before scene.toml is written
    solution_file = None
    if out is not None:
        out = check_output_folder(out, command="run")
        clear_outputs(out, "run")  # none of the run this one replaces stays beside it
        save_scene(scene, out / "scene.toml")
        solution_file = out / "solution.sol"
    failure = None
    try:
        result = simulate(scene, controller, solution_file=solution_file, progress=not quiet)
    except (SolverFailure, RunInterrupted) as err:
        failure, result = err, err.partial_result
        if result is None:  # it stopped before its first sample (settling a spatial robot)
            raise
    summary = result.summary()
    settled = result.summary(after=SETTLED_AFTER)
    estimate = None
    if error_estimate and failure is None:
        if not quiet:
            print("estimating the discretisation error (a companion run) ...", flush=True)
        try:
            estimate = estimate_error(scene, result, None if controller is None else type(controller),
                                      after=SETTLED_AFTER)
        except KeyboardInterrupt as err:  # Ctrl-C in the companion run: write this run's result, then stop
            failure = err
    if out is not None:
        result.save(out, SETTLED_AFTER, None if estimate is None else summary_entry(estimate))
        if solution_file is not None and solution_file.is_file():
            undate_solution_file(solution_file)
        if figures and len(result.time) > 1:
            from cdpr_exu.post.plots import plot_overview  # matplotlib only where a figure is drawn

            plot_overview(scene, result, out, after=SETTLED_AFTER)
    if failure is None:  # a completed run that pushed is not clean: say so once, quiet or not
        raise_warnings(summary, f"{scene.name} under {result.controller}: ")
    if not quiet:
        _print_summary(summary, settled, result.space, out)
        if estimate is not None:
            print(estimate_line(estimate))
    if failure is not None:
        raise failure
    return summary


def _elements_for(scene, tolerance: float, quiet: bool):
    """The scene with the fewest elements per cable that the error model says meet ``tolerance`` [m]
    (:func:`~cdpr_exu.run.error_estimate.elements_for_tolerance`)."""
    n = max(c.n_elements for c in scene.cables)
    pilot = estimate_error(scene, simulate(scene), after=SETTLED_AFTER)
    if pilot.max_position_error_m is None:
        raise CdprError(f"--tolerance: no error estimate for this scene ({pilot.note})")
    needed = elements_for_tolerance(n, pilot.max_position_error_m, tolerance)
    if not quiet:
        print(f"--tolerance {1000 * tolerance:g} mm: estimated {length_text(pilot.max_position_error_m)} at {n} "
              f"elements per cable; the error model e ~ n^-2 asks for {needed} elements"
              + (" (kept)" if needed == n else ""))
    return scene.with_changes(cables=tuple(replace(c, n_elements=needed) for c in scene.cables))


def _cmd_run(args: argparse.Namespace) -> int:
    # the scene first (loaded once: its warnings are printed once), so that a refused one leaves no output folder
    scene = _scene_with_overrides(args, load_scene(args.scene))
    out = check_output_folder(args.out, command="run")
    tolerance = None if args.tolerance is None else parse_length(args.tolerance)
    if tolerance is not None:
        scene = _elements_for(scene, tolerance, args.quiet)
    run_scene(scene, out, quiet=args.quiet, figures=not args.no_figures,
              error_estimate=not args.no_error_estimate)
    return EXIT_OK


def add_commands(subparsers) -> None:
    """Register ``cdpr run``."""
    run = subparsers.add_parser("run", help="run a scene and write result, summary and figures",
                                description="Run a scene (a shipped name or a TOML file) under ideal "
                                "inverse-kinematics control and write its result, summary, Exudyn solution "
                                "file and figures.", epilog=EPILOG_RUN,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    run.add_argument("scene", help="shipped scene name (see `cdpr scenes`) or path to a .toml file")
    run.add_argument("--out", help="output folder (created); nothing is written without it")
    run.add_argument("--end-time", type=float, help="override solver.end_time [s]")
    run.add_argument("--step-size", type=float, help="override solver.step_size [s]")
    run.add_argument("--no-figures", action="store_true", help="skip the figures")
    run.add_argument("--no-error-estimate", action="store_true",
                     help="skip the companion run that estimates the discretisation error")
    run.add_argument("--tolerance", metavar="LENGTH",
                     help="position error to meet, e.g. 5mm: a pilot run with the scene's elements and its "
                     "error estimate first, then the fewest elements per cable, never fewer than the scene has, "
                     "that the error model says meet it (printed)")
    run.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    run.set_defaults(func=_cmd_run)
