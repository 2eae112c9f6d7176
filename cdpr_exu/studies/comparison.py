"""Controller comparison: the same scene under every controller, tabulated and plotted.

``cdpr compare paper-circle --out results/controllers`` runs the scene under each
controller of :data:`CONTROLLERS`, writes ``summary.json`` (keyed by controller name),
``comparison.md`` (a Markdown table), a ``pose.csv`` per controller and the figures
``comparison_paths.png`` and ``comparison_errors.png``; each controller's wall time and
real-time factor go to ``timing.json``, so that the other files are the same from run to run. Errors are actual - reference,
measured after the start-up (``--after``, default 1 s).

By default the comparison starts a circle reference smoothly from rest
(:data:`COMPARISON_RAMP_TIME`, ``--ramp-time``; 0 keeps the scene's own start): the
paper's circle starts at full speed, a jolt that no real robot would be commanded and
that throws the cables slack (0.12 s on ideal IK with tension-only cables, 299 N peaks)
without saying anything about how well a controller tracks. The scene written with the
results (``scene.toml``) records the start used.

A spatial scene runs under :data:`SPATIAL_CONTROLLERS` (:func:`compare_spatial`): ``summary.json``,
``comparison.md`` (:func:`spatial_comparison_table`) and an ``overview_<controller>.png`` each.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Callable

import numpy as np

from controllers.ideal_ik import IdealIKController
from controllers.tension_aware import ClosedLoopTensionAwareController, TensionAwareController
from controllers.spatial_feedback import spatial_closed_loop_tension_aware
from controllers.spatial_tension_aware import SpatialTensionAwareController

from cdpr_exu.core.errors import CdprError, RunInterrupted, SceneError, SolverFailure
from cdpr_exu.core.output import (check_output_folder, clear_outputs, fixed, write_pose_csv,
                                  write_summary)
from cdpr_exu.results.result import POSE_COLUMNS, Result, provenance, warning_flags
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import Scene, save_scene
from cdpr_exu.scenes.trajectories import CircleTrajectory
from cdpr_exu.studies.learning import (DEFAULT_RULE, StoppingRule, closed_loop_model_feed_forward_controller,
                                      ilc_controller, model_feed_forward_controller)

#: The controllers compared by default, by name, each a factory.
CONTROLLERS: dict[str, Callable[[], object]] = {
    "ideal_ik": IdealIKController,
    "tension_aware": TensionAwareController,
    "tension_aware_chordal": lambda: TensionAwareController(chordal_correction=True),
    "tension_aware_dynamic_chordal": lambda: TensionAwareController(dynamic=True, chordal_correction=True),
    "tension_aware_chain": lambda: TensionAwareController(statics="chain"),
    "closed_loop_tension_aware": lambda: ClosedLoopTensionAwareController(dynamic=True, chordal_correction=True),
    "model_feed_forward": model_feed_forward_controller,
    "closed_loop_model_feed_forward": closed_loop_model_feed_forward_controller,
    "ilc": ilc_controller,
}
#: Controllers that learn over trials before their run (cdpr_exu.studies.learning), made with the
#: comparison's stopping rule and progress report.
LEARNING_CONTROLLERS: dict[str, Callable[..., object]] = {
    "model_feed_forward": model_feed_forward_controller,
    "closed_loop_model_feed_forward": closed_loop_model_feed_forward_controller,
    "ilc": ilc_controller,
}

#: Ramp time [s] of the smooth start `cdpr compare` gives a circle that starts at full speed.
COMPARISON_RAMP_TIME = 1.0


def smooth_start(scene: Scene, ramp_time: float = COMPARISON_RAMP_TIME) -> Scene:
    """``scene`` with its circle reference starting smoothly from rest over ``ramp_time`` [s].

    Only a circle (planar or spatial: one kind) that starts at full speed (``ramp_time = 0``) is changed; other
    references (hold, point-to-point) already start from rest, and a circle with its own
    ramp keeps it. ``ramp_time = 0`` returns the scene unchanged.
    """
    if ramp_time < 0 or not np.isfinite(ramp_time):
        raise SceneError(f"ramp_time must be zero or positive [s], got {ramp_time!r}")
    trajectory = scene.trajectory
    if ramp_time == 0 or not isinstance(trajectory, CircleTrajectory) or trajectory.ramp_time > 0:
        return scene
    return scene.with_changes(trajectory=replace(trajectory, ramp_time=float(ramp_time)))


_COLUMNS = (
    ("max_position_error_m", "max pos. error [mm]", 1000.0),
    ("rms_position_error_m", "RMS pos. error [mm]", 1000.0),
    ("max_abs_error_x_m", "max \\|err x\\| [mm]", 1000.0),
    ("max_abs_error_z_m", "max \\|err z\\| [mm]", 1000.0),
    ("max_abs_rotation_deg", "max \\|rotation\\| [deg]", 1.0),
    ("min_element_tension_N", "min tension [N]", 1.0),
    ("slack_time_s", "slack time [s]", 1.0),
)  # no wall time: it changes from run to run, and the table is tracked (issue 23.18); it is in timing.json


def compare_controllers(scene: Scene, names: list[str] | None = None, *, out: str | Path | None = None,
                        after: float = 1.0, progress: bool = False,
                        learning_rule: StoppingRule = DEFAULT_RULE,
                        report: Callable[[str, dict], None] | None = None,
                        learning_report: Callable[[str], None] | None = None) -> dict[str, dict]:
    """Run ``scene`` under each named controller; returns their summaries by name.

    A controller that refuses the reference (e.g. a pose that needs a pushing cable)
    or whose run fails is recorded with its status; the others still run. The
    learning controllers (:data:`LEARNING_CONTROLLERS`) run their trials first, as
    ``learning_rule`` says (their per-trial errors go into the summary as ``trials``).
    ``report(name, summary)`` is called as each controller's run ends (not for a refused
    one), ``learning_report`` with each line of the learning controllers' progress
    (:class:`cdpr_exu.studies.learning.Learner`); ``cdpr compare`` prints both.
    """
    names = list(names or CONTROLLERS)
    unknown = [n for n in names if n not in CONTROLLERS]
    if unknown:
        raise SceneError(f"unknown controller(s) {unknown}; known: {list(CONTROLLERS)}")
    summaries: dict[str, dict] = {}
    results: dict[str, Result] = {}
    try:
        for name in names:
            if name in LEARNING_CONTROLLERS:
                controller = LEARNING_CONTROLLERS[name](learning_rule, after=after, report=learning_report, plant=scene)
            else:
                controller = CONTROLLERS[name]()
            try:
                result = simulate(scene, controller, progress=progress)
            except SolverFailure as err:
                result = err.partial_result
            except RunInterrupted as err:  # Ctrl-C inside a run: keep this one's part too
                results[name] = err.partial_result
                summaries[name] = {**err.partial_result.summary(after=after), "controller": name}
                raise
            except CdprError as err:  # a refused reference is a result of the comparison too
                summaries[name] = {"controller": name, "status": f"refused: {err}"}
                continue
            results[name] = result
            summary = result.summary(after=after)
            summary["controller"] = name
            learning = getattr(getattr(controller, "learner", None), "learning", None)
            if learning is not None:
                summary["learning"] = learning.to_dict()
            slack = [s for s in summary["slack_time_per_cable_s"] if s is not None]
            summary["slack_time_s"] = max(slack) if slack else None
            if "tension_limit_violations" in summary:
                summary["tension_limit_violation_count"] = len(summary["tension_limit_violations"])
            summaries[name] = summary
            if report is not None:
                report(name, summary)
    except KeyboardInterrupt:  # Ctrl-C, inside a run or between two: keep the controllers done so far
        if out is not None and summaries:
            _write(scene, summaries, {k: r for k, r in results.items() if k in summaries}, Path(out), after)
        raise
    base = summaries.get("ideal_ik", {}).get("max_position_error_m")
    if base is not None:
        for summary in summaries.values():
            if (summary.get("max_position_error_m") or 0.0) > 0:
                summary["error_reduction_vs_ideal_ik"] = base / summary["max_position_error_m"]
    if out is not None:
        _write(scene, summaries, results, Path(out), after)
    return summaries


def markdown_table(summaries: dict[str, dict]) -> str:
    """The comparison as a Markdown table."""
    columns = _COLUMNS
    if any("tension_limit_violation_count" in s for s in summaries.values()):  # a scene with tension limits
        columns = (*columns, ("tension_limit_violation_count", "tension limit violations", 1.0))
    header = "| controller | " + " | ".join(title for _, title, _ in columns) + " | vs ideal IK | status |"
    lines = [header, "|" + "---|" * (len(columns) + 3)]
    for name, summary in summaries.items():
        cells = []
        for key, _, scale in columns:
            value = summary.get(key)
            cells.append("" if value is None else (str(value) if isinstance(value, int) else fixed(scale * value, 2)))
        ratio = summary.get("error_reduction_vs_ideal_ik")
        flags = "".join(f"; {flag}" for flag in warning_flags(summary))  # what a real robot cannot do
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {'' if ratio is None else f'{ratio:.1f}x'} | "
                     f"{summary.get('status', '')}{flags} |")
    return "\n".join(lines) + "\n"


def _write(scene: Scene, summaries: dict, results: dict, out: Path, after: float) -> None:
    from cdpr_exu.post.plots import plot_comparison

    clear_outputs(check_output_folder(out, command="compare"), "compare")  # no file of an earlier comparison stays
    save_scene(scene, out / "scene.toml")
    document = {"scene": scene.name, "errors_measured_after_s": after, "error_convention": "actual - reference",
                "controllers": summaries, **provenance()}
    write_summary(out, document)
    (out / "comparison.md").write_text(f"{scene.name}: errors after {after} s (actual - reference)\n\n"
                                       + markdown_table(summaries))
    for name, result in results.items():
        write_pose_csv(out / f"pose_{name}.csv", result.time, result.pose, result.reference,
                       POSE_COLUMNS[result.space])
    if results:
        plot_comparison(scene, results, out)


# --------------------------------------------------------------------------- spatial scenes

#: The controllers that run on spatial scenes, by name (``cdpr compare`` on a spatial scene).
SPATIAL_CONTROLLERS = {
    "ideal_ik": IdealIKController,
    "tension_aware": SpatialTensionAwareController,
    "tension_aware_chain": lambda: SpatialTensionAwareController(statics="chain"),
    "closed_loop_tension_aware": spatial_closed_loop_tension_aware,
}


def spatial_controller_names(scene: Scene) -> list[str]:
    """The controllers ``cdpr compare`` runs on ``scene`` by default: all of :data:`SPATIAL_CONTROLLERS` (over
    swivel pulleys too: the chain version's held chains run over the disc, their winch ends moved as the run's)."""
    return list(SPATIAL_CONTROLLERS)


_SPATIAL_COLUMNS = (("max_position_error_m", "max pos. error [mm]", 1000.0), ("rms_position_error_m", "RMS pos. error [mm]", 1000.0),
            ("max_rotation_error_deg", "max rotation error [deg]", 1.0),
            ("min_element_tension_N", "min tension [N]", 1.0), ("max_element_tension_N", "max tension [N]", 1.0))


def spatial_comparison_table(summaries: dict) -> str:
    """The spatial comparison as a Markdown table (errors after the summaries' ``after``); a scene
    with tension limits gets a column counting the violations, as the planar table does."""
    columns = _SPATIAL_COLUMNS
    if any("tension_limit_violations" in s for s in summaries.values()):
        columns = (*columns, ("tension_limit_violation_count", "tension limit violations", 1.0))
        summaries = {name: {**s, "tension_limit_violation_count": len(s.get("tension_limit_violations", []))}
                     for name, s in summaries.items()}
    lines = ["| controller | " + " | ".join(title for _, title, _ in columns) + " | vs ideal IK | status |",
             "|" + "---|" * (len(columns) + 3)]
    base = summaries.get("ideal_ik", {}).get("max_position_error_m")
    for name, s in summaries.items():
        cells = ["" if s.get(key) is None else f"{scale * s[key]:.4g}" for key, _, scale in columns]
        worst = s.get("max_position_error_m")
        ratio = f"{base / worst:.1f}x" if base and worst else ""
        flags = "".join(f"; {flag}" for flag in warning_flags(s))  # what a real robot cannot do
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {ratio} | {s.get('status', '')}{flags} |")
    return "\n".join(lines) + "\n"


def compare_spatial(scene: Scene, names: list[str] | None = None, out: str | Path | None = None,
                    after: float = 1.0, report: Callable[[str, dict], None] | None = None) -> dict[str, dict]:
    """Run a spatial scene under each named controller; write summary.json, comparison.md and each
    controller's overview figure to ``out``. Returns the summaries by name; ``report(name, summary)``
    is called as each run ends (``cdpr compare`` prints it).

    As the planar comparison: a run that fails is recorded with its status and partial
    figures, a controller that refuses the scene with ``refused: ...``, and the others still
    run; on Ctrl-C (inside a run or between two) the controllers done so far and the
    interrupted one's partial run are written before the interrupt goes on.
    """
    names = list(names or spatial_controller_names(scene))
    unknown = [n for n in names if n not in SPATIAL_CONTROLLERS]
    if unknown:
        raise SceneError(f"unknown controller(s) {unknown} for a spatial scene; known: {list(SPATIAL_CONTROLLERS)}")
    if out is not None:  # an earlier comparison's files go before the first of this one is written

        clear_outputs(check_output_folder(out, command="compare"), "compare")
    summaries, results = {}, {}
    try:
        for name in names:
            try:
                result = simulate(scene, SPATIAL_CONTROLLERS[name]())
            except SolverFailure as err:
                result = err.partial_result
                if result is None:  # it failed before its first step (settling the robot)
                    summaries[name] = {"controller": name, "status": f"failed: {err}"}
                    continue
            except RunInterrupted as err:  # Ctrl-C inside a run: keep this one's part too
                results[name] = err.partial_result
                summaries[name] = err.partial_result.summary(after)
                raise
            except CdprError as err:  # a controller that refuses the scene is a result of the comparison too
                summaries[name] = {"controller": name, "status": f"refused: {err}"}
                continue
            results[name], summaries[name] = result, result.summary(after)
            if report is not None:
                report(name, summaries[name])
    except KeyboardInterrupt:  # keep what was computed, then let the interrupt go on
        if out is not None and summaries:
            _write_spatial_comparison(scene, summaries, results, Path(out), after)
        raise
    if out is not None:
        _write_spatial_comparison(scene, summaries, results, Path(out), after)
    return summaries


def _write_spatial_comparison(scene: Scene, summaries: dict, results: dict, out: Path, after: float) -> None:
    """Write summary.json, comparison.md and each run's overview_<controller>.png into ``out``."""
    from cdpr_exu.post.plots import plot_spatial_run

    out.mkdir(parents=True, exist_ok=True)
    write_summary(out, {"scene": scene.name, "dimension": 3, "errors_measured_after_s": after,
                        "error_convention": "actual - reference", "controllers": summaries, **provenance()})
    (out / "comparison.md").write_text(spatial_comparison_table(summaries))
    for name, result in results.items():
        plot_spatial_run(result, out / f"overview_{name}.png", after)
