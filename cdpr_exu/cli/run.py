"""``cdpr run``: run a planar or spatial scene, write its files and print its summary.

Examples::

    cdpr run paper-circle --out results/paper_circle
    cdpr run my_robot.toml --out out/my_robot --end-time 5 --step-size 1e-3
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, CdprError, RunInterrupted, SolverFailure
from cdpr_exu.core.output import (check_output_folder, clear_outputs, fixed, length_text, undate_solution_file,
                                  write_summary)
from cdpr_exu.results.result import Result, after_start_up, provenance, raise_warnings, status_text
from cdpr_exu.run.error_estimate import (elements_for_tolerance, estimate_error, estimate_line, parse_length,
                                         simulate_any, summary_entry)
from cdpr_exu.run.simulate import simulate
from cdpr_exu.run.spatial_run import SpatialResult, check_runnable, simulate_spatial
from cdpr_exu.scenes.scene import Scene, load_scene, save_scene
from cdpr_exu.statics.workspace import check_reference

#: Errors are measured after this start-up time in the printed "settled" figures [s].
SETTLED_AFTER = 1.0

EPILOG_RUN = """examples:
  cdpr run paper-circle --out results/paper_circle
  cdpr run scene.toml --out out/run1 --end-time 2 --step-size 1e-3 --quiet

""" + EXIT_CODES


def _scene_with_overrides(args: argparse.Namespace, scene: Scene | None = None) -> Scene:
    """``scene`` (default: the one ``args.scene`` names, loaded) with ``--end-time`` and ``--step-size`` applied."""
    scene = load_scene(args.scene) if scene is None else scene
    changes = {}
    if getattr(args, "end_time", None) is not None:
        changes["end_time"] = args.end_time
    if getattr(args, "step_size", None) is not None:
        changes["step_size"] = args.step_size
    if changes:
        scene = scene.with_changes(solver=replace(scene.solver, **changes))
    return scene


def _figure(value, scale: float = 1.0, unit: str = "", digits: int = 2, sign: bool = False) -> str:
    """A printed figure, or "n/a" when it does not exist (None); never "nan" or "-0.00"."""
    if value is None:
        return "n/a"
    text = fixed(scale * value, digits)
    if sign and not text.startswith("-"):
        text = "+" + text
    return f"{text} {unit}".rstrip()


def _print_violations_and_notes(summary: dict, settled: dict, out: Path | None) -> None:
    """The end of a run's printed summary, planar or spatial: each tension-limit violation, the notes of
    the whole run and of the settled part (once each), and the output folder."""
    for v in summary.get("tension_limit_violations", []):
        print(f"  cable {v['cable']} beyond its {v['limit']} ({v['limit_N']:g} N) from t = {v['first_time_s']:.3f} s "
              f"for {v['duration_s']:.3f} s, reaching {v['extreme_N']:.4g} N")
    for note in dict.fromkeys(summary["notes"] + settled["notes"]):
        print(f"  note: {note}")
    if out is not None:
        print(f"  written to {out}/")


def _print_summary(summary: dict, settled: dict, out: Path | None) -> None:
    def pair(key, scale, unit, digits=2):
        return _figure(summary[key], scale, unit, digits), _figure(settled[key], scale, unit, digits)

    def z_range(s):
        if s["min_error_z_m"] is None:
            return "n/a"
        return f"{_figure(s['min_error_z_m'], 100, '', sign=True)} .. {_figure(s['max_error_z_m'], 100, '', sign=True)} cm"

    factor = summary["real_time_factor"]
    rows = [
        ("status", status_text(summary), ""),
        ("max |error x|", *pair("max_abs_error_x_m", 100, "cm")),
        ("max |error z|", *pair("max_abs_error_z_m", 100, "cm")),
        ("error z range", z_range(summary), z_range(settled)),
        ("max |rotation|", *pair("max_abs_rotation_deg", 1, "deg")),
        # tensions, slack and limits: over the whole run only (Result.summary)
        ("min element tension", _figure(summary["min_element_tension_N"], 1, "N"), ""),
        ("min tension per cable", " / ".join(_figure(v, 1, "N") for v in summary["min_tension_per_cable_N"]), ""),
        ("slack time per cable", " / ".join(_figure(v, 1, "s") for v in summary["slack_time_per_cable_s"]), ""),
        ("max pulley penetration", _figure(summary["max_pulley_penetration_m"], 1000, "mm", 3), ""),
        ("simulated / wall time", f"{summary['simulated_time_s']:.2f} s / {summary['wall_time_s']:.2f} s",
         "n/a" if factor is None else f"{factor:.1f}x real time"),
        ("steps / Newton iterations", f"{summary['steps']} / {summary['newton_iterations']}", ""),
    ]
    if "tension_limit_violations" in summary:
        violations = summary["tension_limit_violations"]
        rows.append(("tension limits", f"{len(violations)} violation(s)" if violations else "none", ""))
    print(f"{summary['scene']} under {summary['controller']} (error = actual - reference)")
    print(f"  {'':26s} {'whole run':>22s}   {'after ' + str(SETTLED_AFTER) + ' s':>18s}")
    for name, whole, after in rows:
        print(f"  {name:26s} {whole:>22s}   {after:>18s}")
    _print_violations_and_notes(summary, settled, out)


def run_scene(scene: Scene, out: Path | None, *, quiet: bool = False, figures: bool = True,
              controller=None, error_estimate: bool = False) -> dict:
    """Run ``scene`` and write its files into ``out``; returns the summary.

    Writes ``scene.toml``, ``result.npz``, ``pose.csv``, ``summary.json``,
    ``solution.sol`` (Exudyn's solution file, for ``SolutionViewer``) and the figures,
    after removing the files of an earlier run there (:func:`cdpr_exu.core.output.clear_outputs`;
    a folder of another command's output is refused).
    A failed or interrupted (Ctrl-C) run still writes what was computed up to then,
    then re-raises. ``out`` and the reference (:func:`cdpr_exu.statics.workspace.check_reference`)
    are checked before anything is written. With ``error_estimate``
    a companion run estimates the discretisation error (:mod:`cdpr_exu.run.error_estimate`).
    """
    # A reference the cables cannot reach or hold is refused before anything is written
    # (simulate checks it too, but only after scene.toml would be in the folder).
    check_reference(scene)
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
        result.save(out)
        data = {**summary, **provenance()}
        if estimate is not None:
            data.update(summary_entry(estimate))
        data.update({k: v for k, v in result.metadata.items() if k not in data})
        data["after_start_up"] = after_start_up(settled, Result.ERROR_FIGURES)
        data["error_convention"] = "actual - reference"
        write_summary(out, data)
        if solution_file is not None and solution_file.is_file():
            undate_solution_file(solution_file)
        if figures and len(result.time) > 1:
            from cdpr_exu.post.plots import plot_overview  # matplotlib only where a figure is drawn

            plot_overview(scene, result, out)
    if failure is None:  # a completed run that pushed is not clean: say so once, quiet or not
        raise_warnings(summary, f"{scene.name} under {result.controller}: ")
    if not quiet:
        _print_summary(summary, settled, out)
        if estimate is not None:
            print(estimate_line(estimate))
    if failure is not None:
        raise failure
    return summary


def _print_spatial_summary(summary: dict, after: float, out: Path | None) -> None:
    """Print a spatial run's :meth:`SpatialResult.run_summary`: errors over the whole run and after ``after`` [s],
    each cable's lowest tension and slack time (whole run), its tension-limit violations and notes."""
    settled = summary["after_start_up"]

    def errors(s):
        return f"{length_text(s['max_position_error_m'])} / {length_text(s['rms_position_error_m'])}"

    def degrees(s):
        return "n/a" if s["max_rotation_error_deg"] is None else f"{s['max_rotation_error_deg']:.4f} deg"

    def per_cable(values, unit, digits):
        return " / ".join("n/a" if v is None else f"{fixed(v, digits)} {unit}" for v in values)

    factor = summary["real_time_factor"]
    print(f"{summary['scene']} under {summary['controller']} (spatial; error = actual - reference)")
    print(f"  {'':26s} {'whole run':>22s}   {'after ' + f'{after:g}' + ' s':>22s}")
    print(f"  {'status':26s} {status_text(summary)}")
    print(f"  {'max / RMS position error':26s} {errors(summary):>22s}   {errors(settled):>22s}")
    print(f"  {'max rotation error':26s} {degrees(summary):>22s}   {degrees(settled):>22s}")
    print(f"  {'min tension per cable':26s} {per_cable(summary['min_tension_per_cable_N'], 'N', 1)}")
    print(f"  {'slack time per cable':26s} {per_cable(summary['slack_time_per_cable_s'], 's', 3)}")
    print(f"  {'simulated / wall time':26s} {summary['simulated_time_s']:.2f} s / {summary['wall_time_s']:.2f} s"
          + ("" if factor is None else f" ({factor:.1f}x real time)")
          + f", {summary['steps']} steps, {summary['newton_iterations']} Newton iterations")
    if "tension_limit_violations" in summary:
        count = len(summary["tension_limit_violations"])
        print(f"  {'tension limits':26s} {f'{count} violation(s)' if count else 'none'}")
    _print_violations_and_notes(summary, settled, out)


def run_spatial_scene(scene: Scene, out: Path | None, *, quiet: bool = False, figures: bool = True,
                      after: float = 1.0, error_estimate: bool = False) -> SpatialResult:
    """``cdpr run`` on a spatial scene: run, write into ``out``, print a summary.

    Writes what ``cdpr run`` writes for every scene: ``scene.toml`` (the scene as run: a
    rerun from it gives the same result), ``result.npz``, ``pose.csv``, ``summary.json``
    (wall-clock figures in ``timing.json``), ``solution.sol`` (Exudyn's solution file, its
    date blanked, for ``cdpr view``) and (``figures``) ``overview.png``. The scene and its
    reference are checked before anything is written. On a solver failure or Ctrl-C the
    partial result is written before the error propagates. With ``error_estimate`` a
    companion run estimates the discretisation error (:mod:`cdpr_exu.run.error_estimate`):
    ``error_estimate`` in summary.json and a printed line.
    """
    check_runnable(scene)  # before scene.toml is in the folder
    solution_file = None
    if out is not None:
        out = check_output_folder(out, command="run")
        clear_outputs(out, "run")  # none of the run this one replaces stays beside it (a planar one's figures)
        save_scene(scene, out / "scene.toml")
        solution_file = out / "solution.sol"

    def write(result: SpatialResult, extra: dict | None = None) -> None:
        if out is not None:
            result.save(out, after, extra)
            if figures:
                from cdpr_exu.post.plots import plot_spatial_run  # matplotlib only where a figure is drawn

                plot_spatial_run(result, out / "overview.png", after)
            if solution_file.is_file():
                undate_solution_file(solution_file)

    try:
        result = simulate_spatial(scene, progress=not quiet, solution_file=solution_file)
    except (SolverFailure, RunInterrupted) as err:  # keep what was computed
        if err.partial_result is not None:
            write(err.partial_result)
        raise
    estimate, interrupt = None, None
    if error_estimate:
        if not quiet:
            print("estimating the discretisation error (a companion run) ...", flush=True)
        try:
            estimate = estimate_error(scene, result, after=after)
        except KeyboardInterrupt as err:  # Ctrl-C in the companion run: write this run's result, then stop
            interrupt = err
    write(result, None if estimate is None else summary_entry(estimate))
    summary = result.run_summary(after)
    raise_warnings(summary, f"{scene.name} under {result.controller}: ")  # not clean: said once, quiet or not
    if not quiet:
        _print_spatial_summary(summary, after, out)
        if estimate is not None:
            print(estimate_line(estimate))
    if interrupt is not None:
        raise interrupt
    return result


def _elements_for(scene, tolerance: float, quiet: bool):
    """The scene (planar or spatial) with the fewest elements per cable, never fewer than it has, that the error
    model says meet ``tolerance`` [m] (:func:`cdpr_exu.run.error_estimate.elements_for_tolerance` says why not fewer)."""
    n = max(c.n_elements for c in scene.cables)
    pilot = estimate_error(scene, simulate_any(scene), after=SETTLED_AFTER)
    if pilot.max_position_error_m is None:
        raise CdprError(f"--tolerance: no error estimate for this scene ({pilot.note})")
    needed = elements_for_tolerance(n, pilot.max_position_error_m, tolerance)
    if not quiet:
        print(f"--tolerance {1000 * tolerance:g} mm: estimated {length_text(pilot.max_position_error_m)} at {n} "
              f"elements per cable; the error model e ~ n^-2 asks for {needed} elements"
              + (" (kept)" if needed == n else ""))
    return scene.with_changes(cables=tuple(replace(c, n_elements=needed) for c in scene.cables))


def _cmd_run(args: argparse.Namespace) -> int:
    out = check_output_folder(args.out, command="run")
    tolerance = None if args.tolerance is None else parse_length(args.tolerance)
    scene = load_scene(args.scene)  # loaded once: a warning of the scene file is printed once
    if scene.dimension == 3:  # one run command when simulate() is one (issue 24, slice 9)
        changes = {k: v for k, v in (("end_time", args.end_time), ("step_size", args.step_size)) if v is not None}
        scene = replace(scene, solver=replace(scene.solver, **changes))
        if tolerance is not None:
            scene = _elements_for(scene, tolerance, args.quiet)
        run_spatial_scene(scene, out, quiet=args.quiet, figures=not args.no_figures,
                          error_estimate=not args.no_error_estimate)
        return EXIT_OK
    scene = _scene_with_overrides(args, scene)
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
