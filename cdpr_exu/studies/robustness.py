"""Robustness as a measured property: controllers run on plants that differ from their model.

Each plant of the grid is the controllers' model (a scene's
:meth:`~cdpr_exu.scenes.scene.Scene.controller_scene`) with relative errors on its platform's
mass and inertia, its cables' linear density and Young's modulus, and its pulleys moved apart
(:func:`perturbed`); it carries the model as its ``[controller_model]``, so the controllers plan
on the model while the run simulates the plant. Each (grid point, controller) is one run on
the pool of :mod:`cdpr_exu.studies.study`, appended to ``rows.jsonl`` as it finishes (a study
started again resumes). Standard library only at the top, as :mod:`cdpr_exu.studies.study`.
"""

from __future__ import annotations

import csv
import itertools
import json
import os
from concurrent.futures import as_completed
from pathlib import Path
from typing import Any, Mapping, Sequence

from cdpr_exu.core.errors import CdprError, SceneError
from cdpr_exu.studies.study import SINGLE_THREAD_ENVIRONMENT, executor_for, progress_bar, warm_up

#: Files a robustness study writes.
ROBUSTNESS_FILES = {"rows": "rows.jsonl", "csv": "robustness.csv", "json": "robustness.json",
                    "table": "robustness.md", "scene": "base_scene.toml"}

#: The model errors of a grid point: relative (plant = model x (1 + error)), but ``exit_offset`` [m], how far
#: each pulley's centre lies further out horizontally.
ERRORS = ("platform_mass", "cable_density", "cable_stiffness", "exit_offset")

#: The columns of a row, in order.
COLUMNS = (*ERRORS, "controller", "status", "completed", "max_position_error_m", "rms_position_error_m",
           "max_error_vs_ideal_ik", "min_element_tension_N", "slack_time_s", "elements_pushed", "failure_time_s")


def error_grid(platform_mass=(-0.2, 0.0, 0.2), cable_density=(-0.2, 0.0, 0.2), cable_stiffness=(0.0,),
               exit_offset=(0.0,)) -> list[dict]:
    """Every combination of the errors, as ``{error: value}`` dicts (:data:`ERRORS`)."""
    return [dict(zip(ERRORS, values))
            for values in itertools.product(platform_mass, cable_density, cable_stiffness, exit_offset)]


def perturbed(model, platform_mass: float = 0.0, cable_density: float = 0.0, cable_stiffness: float = 0.0,
              exit_offset: float = 0.0):
    """The plant: ``model`` with the errors of :data:`ERRORS`, carrying ``model``'s values as its controller
    model. SceneError for a relative error at or below -1 or an offset not finite (naming it), an offset on
    exits that are not pulleys, or a plant that is no valid robot."""
    import math
    from dataclasses import replace

    from cdpr_exu.exits import Pulley
    from cdpr_exu.scenes.scene import ControllerModel

    for name, value in (("platform_mass", platform_mass), ("cable_density", cable_density),
                        ("cable_stiffness", cable_stiffness)):
        if not isinstance(value, (int, float)) or not value > -1.0:
            raise SceneError(f"{name} must be a relative error above -1, got {value!r}")
    if not isinstance(exit_offset, (int, float)) or not math.isfinite(exit_offset):
        raise SceneError(f"exit_offset must be a finite distance [m], got {exit_offset!r}")
    exits, pulleys = model.exits, ()
    if exit_offset:
        if not all(isinstance(e, Pulley) for e in exits):
            raise SceneError(f"exit_offset moves pulleys; scene {model.name!r} has {[e.kind for e in exits]} exits")
        middle = sum(e.center[0] for e in exits) / len(exits)
        exits = tuple(replace(e, center=(e.center[0] + math.copysign(1.0, e.center[0] - middle) * exit_offset,
                                         e.center[1])) for e in exits)
        pulleys = tuple({"center": e.center} for e in model.exits)
    platform, scale = model.platform, 1.0 + platform_mass
    inertia = platform.inertia
    changes = {"mass": platform.mass * scale}
    if inertia is not None:
        changes["inertia"] = inertia * scale if isinstance(inertia, (int, float)) else tuple(v * scale for v in inertia)
    believed = ControllerModel(platform={"mass": platform.mass, **({} if inertia is None else {"inertia": inertia})},
                               cables=tuple({"linear_density": c.linear_density, "youngs_modulus": c.youngs_modulus}
                                            for c in model.cables), pulleys=pulleys)
    cables = tuple(replace(c, linear_density=c.linear_density * (1.0 + cable_density),
                           youngs_modulus=c.youngs_modulus * (1.0 + cable_stiffness)) for c in model.cables)
    return replace(model, platform=replace(platform, **changes), cables=cables, exits=exits, controller_model=believed)


def make_controller(kind: str, plant, options: Mapping[str, Any] | None = None, after: float = 1.0):
    """A controller of ``kind`` (:data:`controllers.registry.CONTROLLERS`) for a run of ``plant``, with the
    kind's ``options``; learning kinds learn on ``plant``. SceneError for an unknown kind or one with no
    physics in ``plant``'s dimension."""
    from controllers.registry import controller_kind
    from cdpr_exu.studies.learning import learners

    controller = controller_kind(kind)
    extra = {"learner": learners(plant, after=after)} if controller.learns else {}
    return controller(plant, **extra, **dict(options or {}))


def run_point(plant_data: dict, kind: str, options: dict | None = None, after: float = 1.0) -> dict[str, Any]:
    """A study's worker: ``plant_data`` under a controller of ``kind``; returns ``status``, ``completed`` and
    the figures of :data:`COLUMNS`, never raising for a refused or failed run."""
    for name, value in SINGLE_THREAD_ENVIRONMENT.items():
        os.environ.setdefault(name, value)
    from cdpr_exu.core.errors import SolverFailure
    from cdpr_exu.run.simulate import simulate
    from cdpr_exu.scenes.scene import scene_from_dict

    try:
        plant = scene_from_dict(plant_data)
        warm_up(plant)
        try:
            result = simulate(plant, make_controller(kind, plant, options, after))
        except SolverFailure as err:
            if err.partial_result is None:
                raise
            result = err.partial_result
    except CdprError as err:
        return {"status": "refused: " + " ".join(str(err).split()), "completed": False}
    except Exception as err:  # noqa: BLE001 - a study records every failure and goes on
        return {"status": f"failed: {type(err).__name__}: " + " ".join(str(err).split()), "completed": False}
    summary = result.summary(after if after < plant.solver.end_time else 0.0)
    slack = [s for s in summary.get("slack_time_per_cable_s") or [] if s is not None]
    return {"status": result.status, "completed": result.status == "completed",
            **{k: summary.get(k) for k in ("max_position_error_m", "rms_position_error_m", "min_element_tension_N",
                                           "failure_time_s", "wall_time_s")},
            "slack_time_s": max(slack) if slack else None, "elements_pushed": bool(summary.get("elements_pushed"))}


def read_rows(out) -> list[dict]:
    """The rows already in ``out/rows.jsonl`` (a line cut short by an interruption is dropped)."""
    path = Path(out) / ROBUSTNESS_FILES["rows"]
    rows = []
    for line in path.read_text().splitlines() if path.exists() else ():
        try:
            rows.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return rows


def _key(row: Mapping[str, Any]) -> tuple:
    return (*(float(row.get(e, 0.0)) for e in ERRORS), str(row["controller"]))


def run_robustness(scene, controllers: Mapping[str, tuple[str, dict]], grid: Sequence[Mapping[str, float]],
                   out: str | Path | None = None, *, after: float = 1.0, workers: int | None = None,
                   scheduler: str | None = None, executor=None, progress: bool = True) -> list[dict]:
    """Run every controller on the plant of every grid point (``{error: value}``); one row each, grid order
    then controller order (:data:`COLUMNS`), errors from ``after`` [s] on.

    ``controllers``: ``{label: (kind, options)}``, ``ideal_ik`` added (the ratios are to it).
    With ``out``, rows go to ``rows.jsonl`` as they finish, rows found there are not run again,
    and :func:`write_robustness` writes the rest at the end. ``workers``, ``scheduler``,
    ``executor``: as :func:`cdpr_exu.studies.study.run_study`.
    """
    controllers = {"ideal_ik": ("ideal_ik", {}), **controllers}
    model = scene.controller_scene()
    done = {_key(r): r for r in (read_rows(out) if out is not None else [])}
    tasks = [({e: float(point.get(e, 0.0)) for e in ERRORS}, label) for point in grid for label in controllers]
    tasks = [(point, label) for point, label in tasks if _key({**point, "controller": label}) not in done]
    if out is not None:
        Path(out).mkdir(parents=True, exist_ok=True)
    bar = progress_bar(len(tasks), progress)
    try:
        if tasks:
            plants = {tuple(p.values()): perturbed(model, **p).to_dict() for p, _ in tasks}
            size = None if executor is not None or scheduler else min(workers or os.cpu_count() or 1, len(tasks))
            with executor_for(executor, size or workers, scheduler) as pool:
                futures = {pool.submit(run_point, plants[tuple(p.values())], *controllers[label], after): (p, label)
                           for p, label in tasks}
                for future in as_completed(futures):
                    point, label = futures[future]
                    try:
                        row, lost = future.result(), False
                    except Exception as err:  # noqa: BLE001 - a lost worker fails one run, not the study
                        row, lost = {"status": f"failed: worker error: {type(err).__name__}: {err}", "completed": False}, True
                    row = {**point, "controller": label, **row}
                    done[_key(row)] = row
                    if out is not None and not lost:  # a lost worker's run is run again when the study resumes
                        from cdpr_exu.core.output import strict

                        with open(Path(out) / ROBUSTNESS_FILES["rows"], "a") as handle:
                            handle.write(json.dumps(strict(row), allow_nan=False) + "\n")
                    bar.update(1)
    finally:
        bar.close()
    rows = []
    for point in grid:
        point = {e: float(point.get(e, 0.0)) for e in ERRORS}
        base = done.get(_key({**point, "controller": "ideal_ik"}), {})
        for label in controllers:
            # every error column, also on rows of a rows.jsonl written before a column existed
            row = {**point, **done.get(_key({**point, "controller": label}), {"controller": label,
                                                                              "status": "missing", "completed": False})}
            mine, theirs = row.get("max_position_error_m"), base.get("max_position_error_m")
            row["max_error_vs_ideal_ik"] = theirs / mine if row["completed"] and base.get("completed") and mine else None
            rows.append(row)
    if out is not None:
        write_robustness(out, rows, scene, after)
    return rows


def write_robustness(out, rows: Sequence[Mapping[str, Any]], scene, after: float = 1.0, plots: bool = True) -> dict:
    """Write :data:`ROBUSTNESS_FILES` and a heat map per controller into ``out``; returns the paths."""
    from cdpr_exu.core.output import csv_cell, write_summary
    from cdpr_exu.results.result import provenance
    from cdpr_exu.scenes.scene import save_scene

    out = Path(out)
    paths = {"scene": save_scene(scene, out / ROBUSTNESS_FILES["scene"]), "csv": out / ROBUSTNESS_FILES["csv"],
             "table": out / ROBUSTNESS_FILES["table"]}
    with open(paths["csv"], "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        writer.writerows([csv_cell(row.get(c)) for c in COLUMNS] for row in rows)
    document = {"scene": scene.name, "errors_measured_after_s": after, "error_convention": "actual - reference",
                "model_error": "plant = the controllers' model x (1 + error): platform mass and inertia, cable "
                               "linear density, cable Young's modulus; each pulley's centre exit_offset [m] "
                               "further out",
                "columns": list(COLUMNS),
                "rows": [dict(r) for r in rows], **provenance()}
    paths["json"] = write_summary(out, document, name=ROBUSTNESS_FILES["json"])
    paths["table"].write_text(robustness_table(rows))
    if plots:
        from cdpr_exu.post.study_plots import plot_robustness

        paths.update(plot_robustness(rows, out))
    return paths


def robustness_table(rows: Sequence[Mapping[str, Any]]) -> str:
    """A Markdown table, one line per controller over the grid."""
    groups: dict[str, list] = {}
    for row in rows:
        groups.setdefault(str(row["controller"]), []).append(row)
    lines = ["| controller | completed | worst max error [mm] | worst RMS error [mm] | vs ideal IK (worst - best) | "
             "lowest tension [N] | longest slack [s] | pushed | not completed at (mass, density, stiffness, exit [m]) |",
             "|---|---|---|---|---|---|---|---|---|"]

    def pick(group, key, how):
        values = [r[key] for r in group if r.get("completed") and r.get(key) is not None]
        return how(values) if values else None

    for name, group in groups.items():
        ratios = [pick(group, "max_error_vs_ideal_ik", min), pick(group, "max_error_vs_ideal_ik", max)]
        cells = [f"{sum(bool(r.get('completed')) for r in group)}/{len(group)}"]
        for key, scale in (("max_position_error_m", 1000.0), ("rms_position_error_m", 1000.0)):
            value = pick(group, key, max)
            cells.append("" if value is None else f"{scale * value:.2f}")
        cells.append("" if ratios[0] is None else f"{ratios[0]:.1f}x - {ratios[1]:.1f}x")
        for key, how in (("min_element_tension_N", min), ("slack_time_s", max)):
            value = pick(group, key, how)
            cells.append("" if value is None else f"{value:.2f}")
        cells.append(str(sum(bool(r.get("elements_pushed")) for r in group)))
        cells.append("; ".join("(" + ", ".join(f"{r.get(e, 0.0):+g}" for e in ERRORS) + ")" for r in group
                               if not r.get("completed")))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
