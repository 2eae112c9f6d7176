"""Controller comparison: the same scene under every controller, tabulated and plotted.

``cdpr compare SCENE --out DIR`` runs the scene under each controller the registry has for
it and writes what :func:`comparison_format` says (wall times to ``timing.json``, so the other
files are the same from run to run); errors are actual - reference, after ``--after`` seconds.
By default a circle that starts at full speed starts smoothly (:data:`COMPARISON_RAMP_TIME`):
the paper's jolt throws the cables slack (0.12 s on ideal IK, 299 N peaks) without saying
anything about how a controller tracks.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Callable

import numpy as np

from controllers.registry import CONTROLLERS, controllers_for

from cdpr_exu.space import PLANE, SPACE
from cdpr_exu.core.errors import CdprError, RunInterrupted, SceneError, SolverFailure
from cdpr_exu.core.output import (check_output_folder, clear_outputs, fixed, write_pose_csv,
                                  write_summary)
from cdpr_exu.results.result import Result, provenance, warning_flags
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import Scene, save_scene
from cdpr_exu.scenes.trajectories import CircleTrajectory
from cdpr_exu.studies.learning import DEFAULT_RULE, StoppingRule, learners

#: Ramp time [s] of the smooth start `cdpr compare` gives a circle that starts at full speed.
COMPARISON_RAMP_TIME = 1.0


def smooth_start(scene: Scene, ramp_time: float = COMPARISON_RAMP_TIME) -> Scene:
    """``scene`` with a circle that starts at full speed ramped up over ``ramp_time`` [s] (0: unchanged);
    other references start from rest already, and a circle keeps its own ramp."""
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
)  # no wall time: it changes from run to run (timing.json)


def compare_controllers(scene: Scene, names: list[str] | None = None, *, out: str | Path | None = None,
                        after: float = 1.0, progress: bool = False,
                        learning_rule: StoppingRule = DEFAULT_RULE,
                        report: Callable[[str, dict], None] | None = None,
                        learning_report: Callable[[str], None] | None = None) -> dict[str, dict]:
    """Run ``scene`` under each named controller (default :func:`controllers.registry.controllers_for` it);
    returns their summaries by name.

    An unknown name, or one with no physics in the scene's dimension, is refused before any
    run; a controller that refuses the reference or fails is recorded with its status. Learning
    controllers run their trials first (``learning_rule``; ``learning`` in the summary).
    ``report(name, summary)`` is called as each run ends, ``learning_report`` with each line of
    the learning. On Ctrl-C what is done so far is written before the interrupt goes on.
    """
    names = list(names or controllers_for(scene))
    unknown = [n for n in names if n not in CONTROLLERS]
    if unknown:
        raise SceneError(f"unknown controller(s) {unknown}; known: {list(CONTROLLERS)}")
    for name in names:
        CONTROLLERS[name].check(scene)
    output = comparison_format(scene)
    if out is not None:  # an earlier comparison's files go before the first of this one is written
        clear_outputs(check_output_folder(out, command="compare"), "compare")
    summaries: dict[str, dict] = {}
    results: dict[str, Result] = {}
    try:
        for name in names:
            kind = CONTROLLERS[name]
            options = {"learner": learners(scene, learning_rule, after=after, report=learning_report)} if kind.learns else {}
            controller = kind(scene, **options)
            try:
                result = simulate(scene, controller, progress=progress)
            except SolverFailure as err:
                result = err.partial_result
                if result is None:  # it failed before its first step (settling the robot)
                    summaries[name] = {"controller": name, "status": f"failed: {err}"}
                    continue
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
            summaries[name] = output.summary(summary)
            if report is not None:
                report(name, summary)
    except KeyboardInterrupt:  # Ctrl-C, inside a run or between two: keep the controllers done so far
        if out is not None and summaries:
            output.write(scene, summaries, {k: r for k, r in results.items() if k in summaries}, Path(out), after)
        raise
    output.compared(summaries)
    if out is not None:
        output.write(scene, summaries, results, Path(out), after)
    return summaries


def markdown_table(summaries: dict[str, dict]) -> str:
    """The comparison of a planar scene as a Markdown table."""
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


_SPATIAL_COLUMNS = (("max_position_error_m", "max pos. error [mm]", 1000.0), ("rms_position_error_m", "RMS pos. error [mm]", 1000.0),
            ("max_rotation_error_deg", "max rotation error [deg]", 1.0),
            ("min_element_tension_N", "min tension [N]", 1.0), ("max_element_tension_N", "max tension [N]", 1.0))


def spatial_comparison_table(summaries: dict) -> str:
    """The comparison of a spatial scene as a Markdown table (a column of tension-limit violations where
    there are limits)."""
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


class _PlanarComparison:
    """What a comparison of a planar scene writes: ``scene.toml``, ``summary.json``, ``comparison.md``, a
    ``pose_<controller>.csv`` each and :func:`cdpr_exu.post.plots.plot_comparison`'s figures."""

    table = staticmethod(markdown_table)

    @staticmethod
    def summary(summary: dict) -> dict:
        slack = [s for s in summary["slack_time_per_cable_s"] if s is not None]
        summary["slack_time_s"] = max(slack) if slack else None
        if "tension_limit_violations" in summary:
            summary["tension_limit_violation_count"] = len(summary["tension_limit_violations"])
        return summary

    @staticmethod
    def compared(summaries: dict) -> None:
        base = summaries.get("ideal_ik", {}).get("max_position_error_m")
        if base is not None:
            for summary in summaries.values():
                if (summary.get("max_position_error_m") or 0.0) > 0:
                    summary["error_reduction_vs_ideal_ik"] = base / summary["max_position_error_m"]

    @staticmethod
    def write(scene: Scene, summaries: dict, results: dict, out: Path, after: float) -> None:
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
                           result.space.pose_columns)
        if results:
            plot_comparison(scene, results, out)


class _SpatialComparison:
    """What a comparison of a spatial scene writes: ``summary.json``, ``comparison.md`` and an
    ``overview_<controller>.png`` each."""

    table = staticmethod(spatial_comparison_table)

    @staticmethod
    def summary(summary: dict) -> dict:
        return summary

    @staticmethod
    def compared(summaries: dict) -> None:
        """Nothing: the table computes the ratio to ideal IK."""

    @staticmethod
    def write(scene: Scene, summaries: dict, results: dict, out: Path, after: float) -> None:
        from cdpr_exu.post.plots import plot_spatial_run

        out.mkdir(parents=True, exist_ok=True)
        write_summary(out, {"scene": scene.name, "dimension": scene.space.dimension, "errors_measured_after_s": after,
                            "error_convention": "actual - reference", "controllers": summaries, **provenance()})
        (out / "comparison.md").write_text(spatial_comparison_table(summaries))
        for name, result in results.items():
            plot_spatial_run(result, out / f"overview_{name}.png", after)


#: What a comparison writes, by the scene's space (the committed results' formats, kept byte for byte).
_FORMATS = {PLANE: _PlanarComparison, SPACE: _SpatialComparison}


def comparison_format(scene: Scene):
    """What a comparison of ``scene`` writes and tabulates (``.table(summaries)``)."""
    return _FORMATS[scene.space]
