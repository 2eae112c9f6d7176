"""Accuracy against cost: the model ladder over element counts and step sizes.

One scene (planar or spatial, under ideal inverse kinematics) is run on every model of
the ladder (the presets, and ``full`` with the linear bending) over elements per cable and
time steps, and each run is compared with a *reference*, ``full`` at the finest
discretisation. A row holds the configuration, its status (a refused or stopped run is a
result too), its cost and its errors against the reference: ``path`` (moving scenes) the
platform position error from ``after`` seconds on (max and RMS), the largest rotation
error and the tension error at the platform ends; ``final`` (a held pose, fixed winches)
the same of the final state, and the final speed (whether the run came to rest). From
the rows: the Pareto front, the cheapest configuration per tolerance, and what each
effect changes and costs against ``full`` at the same discretisation.

Cost (:data:`COST`) is the CPU time of the single-threaded worker over the whole run:
on a shared machine the wall time of the same run varied twofold, the CPU time by a
few per cent. Command line: ``cdpr study accuracy SCENE --out DIR [--quick]``.
"""

from __future__ import annotations

import csv
import json
import math
import os
import warnings
from concurrent.futures import Executor, Future, as_completed
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from cdpr_exu.core.errors import CoarseOutputWarning, SceneError
from cdpr_exu.core.output import (check_output_folder, clear_outputs, finite_number as _finite, write_npz,
                                  write_summary)
from cdpr_exu.results.result import provenance
from cdpr_exu.scenes.scene import load_scene, save_scene, scene_from_dict
from cdpr_exu.space import PLANE, SPACE, Space
from cdpr_exu.scenes.trajectories import HoldTrajectory
from cdpr_exu.studies.study import apply_parameters, executor_for, progress_bar, recorded_run

#: Position tolerances of the tolerance table [m].
TOLERANCES = (1.0e-3, 1.0e-2, 5.0e-2)

#: The cost a run is judged by: the CPU time of its single-threaded process [s].
COST = "cpu_time_s"

#: Presets whose cables are massless ropes: the number of elements does not apply.
MASSLESS_PRESETS = ("ideal", "elastic")

#: Files the study writes into its output folder.
ACCURACY_FILES = {
    "csv": "accuracy.csv",
    "json": "accuracy.json",
    "pareto": "pareto.png",
    "tables": "tables.md",
    "reference": "reference.npz",
    "scene": "base_scene.toml",
}


@dataclass(frozen=True)
class Configuration:
    """One run of the study: a preset, its elements per cable (None for the massless presets), its
    ``step_size`` [s] and further ``(path, value)`` overrides (:mod:`cdpr_exu.studies.study`'s paths)."""

    preset: str
    n_elements: int | None
    step_size: float
    overrides: tuple[tuple[str, Any], ...] = ()

    @property
    def model(self) -> str:
        """The preset and its overrides, e.g. ``full, linear bending``."""
        return model_name(self.preset, self.overrides)

    @property
    def label(self) -> str:
        """Short description, e.g. ``full n=15 h=2e-03``."""
        n = "" if self.n_elements is None else f" n={self.n_elements}"
        return f"{self.model}{n} h={self.step_size:.0e}"

    def scene_data(self, base_data: Mapping[str, Any]) -> dict[str, Any]:
        """Plain scene data (not validated) from the base scene's: the preset's effects with the ``effects.*``
        overrides (the base's replaced), the other overrides applied as parameter paths."""
        assignments: list[tuple[str, Any]] = [("solver.step_size", self.step_size)]
        if self.n_elements is not None:
            assignments.append(("cables.n_elements", self.n_elements))
        effects: dict[str, Any] = {"preset": self.preset}
        for path, value in self.overrides:
            if path.startswith("effects."):
                effects[path[len("effects."):]] = value
            else:
                assignments.append((path, value))
        data = apply_parameters(base_data, assignments)
        data["effects"] = effects
        return data


def model_name(preset: str, overrides: Sequence[tuple[str, Any]] = ()) -> str:
    """Readable name of a preset with overrides (``full, segment contact``, ``full, slack=false``)."""
    parts = [preset]
    for path, value in overrides:
        key = path.split(".")[-1]
        if key == "bending_model":
            parts.append(f"{value} bending")
        elif key == "pulley_contact_model":
            parts.append(f"{value} contact")
        else:
            parts.append(f"{key}={json.dumps(value) if isinstance(value, bool) else value}")
    return ", ".join(parts)


LINEAR_BENDING = (("effects.bending_model", "linear"),)


@dataclass(frozen=True)
class AccuracyGrid:
    """Which configurations an accuracy study runs.

    Parameters
    ----------
    models : tuple of (preset, overrides)
        The ladder; massless presets run once per step size.
    reference : Configuration
        What every run is compared with.
    variants : tuple of overrides
        Single-effect variants of ``full``, run at ``variant_resolution`` (n_elements, step_size
        [s]) only, where every model runs too and the effects are compared.
    end_time : float or None [s]
        Overrides the scene's end time.
    after : float [s]
        Path errors are measured from this time on (from 0 if the run is not longer).
    """

    models: tuple[tuple[str, tuple], ...]
    n_elements: tuple[int, ...]
    step_sizes: tuple[float, ...]
    reference: Configuration
    variants: tuple[tuple[tuple[str, Any], ...], ...] = ()
    variant_resolution: tuple[int, float] | None = None
    end_time: float | None = None
    after: float = 1.0

    def configurations(self) -> list[Configuration]:
        """Every configuration, the reference first, without duplicates."""
        out = [self.reference]
        for preset, overrides in self.models:
            counts = (None,) if preset in MASSLESS_PRESETS else self.n_elements
            out.extend(Configuration(preset, n, h, tuple(overrides)) for n in counts for h in self.step_sizes)
        if self.variant_resolution is not None:
            n, h = self.variant_resolution
            for preset, overrides in self.models:
                out.append(Configuration(preset, None if preset in MASSLESS_PRESETS else n, h, tuple(overrides)))
            out.extend(Configuration("full", n, h, tuple(v)) for v in self.variants)
        unique: list[Configuration] = []
        for configuration in out:
            if configuration not in unique:
                unique.append(configuration)
        return unique


#: The ladder: every preset, and the full model with the linear bending.
LADDER = (("ideal", ()), ("elastic", ()), ("catenary", ()), ("full", ()), ("full", LINEAR_BENDING))

#: Single-effect variants of the full model compared at the variant resolution.
EFFECT_VARIANTS = (
    (("effects.bending_damping", False),),
    (("effects.bending_model", "linear"), ("effects.bending_damping", False)),
    (("effects.slack", False),),  # the paper's spring elements, which push
    (("cables.mass_lumping", "paper"),),
    (("effects.pulley_contact_model", "segment"),),
)

#: The grid of ``examples/accuracy_vs_time.py`` (about 6 minutes per scene on 2 cores).
FULL_GRID = AccuracyGrid(
    models=LADDER,
    n_elements=(8, 10, 15, 20, 30, 45, 60),
    step_sizes=(5.0e-4, 1.0e-3, 2.0e-3, 5.0e-3, 1.0e-2),
    reference=Configuration("full", 90, 5.0e-4),
    variants=EFFECT_VARIANTS,
    variant_resolution=(30, 1.0e-3),
)

#: A small grid for tests and a first look: 1.5 s of the scene, reference = finest run.
QUICK_GRID = AccuracyGrid(
    models=(("ideal", ()), ("full", ()), ("full", LINEAR_BENDING)),
    n_elements=(12, 20),
    step_sizes=(2.0e-3, 5.0e-3),
    reference=Configuration("full", 20, 2.0e-3),
    end_time=1.5,
    after=1.0,
)


#: The spatial ladder: a spatial scene's cables are lumped and elastic.
SPATIAL_LADDER = (("catenary", ()), ("full", ()))

#: Single-effect variants of the full model on a spatial scene.
SPATIAL_EFFECT_VARIANTS = (
    (("effects.bending_damping", False),),
    (("effects.bending", False), ("effects.bending_damping", False)),
    (("effects.slack", False),),
    (("cables.mass_lumping", "paper"),),
)

#: The grid of a spatial study (spatial runs cost more: 23 s on two workers for 2 s of the four-cable robot).
SPATIAL_FULL_GRID = AccuracyGrid(
    models=SPATIAL_LADDER,
    n_elements=(4, 6, 8, 12, 16),
    step_sizes=(5.0e-3, 1.0e-2, 2.0e-2),
    reference=Configuration("full", 32, 2.0e-3),
    variants=SPATIAL_EFFECT_VARIANTS,
    variant_resolution=(8, 1.0e-2),
)

SPATIAL_QUICK_GRID = AccuracyGrid(
    models=(("full", ()),),
    n_elements=(4, 8),
    step_sizes=(1.0e-2,),
    reference=Configuration("full", 16, 1.0e-2),
    end_time=1.5,
    after=1.0,
)


#: The default grids (quick, full) by the scene's Space.
GRIDS = {PLANE: (QUICK_GRID, FULL_GRID), SPACE: (SPATIAL_QUICK_GRID, SPATIAL_FULL_GRID)}


def grid_for(scene, quick: bool = False) -> AccuracyGrid:
    """The default grid of ``scene`` (:data:`GRIDS`), its element counts scaled up where an exit takes no
    fewer (:func:`fewest_elements`: over swivel pulleys, e.g. 4, 8 and 16 to 48, 96 and 192)."""
    grid = GRIDS[scene.space][0 if quick else 1]
    factor = math.ceil(fewest_elements(scene) / min(grid.n_elements))
    if factor <= 1:
        return grid
    resolution = grid.variant_resolution
    return replace(grid, n_elements=tuple(factor * n for n in grid.n_elements),
                   reference=replace(grid.reference, n_elements=factor * grid.reference.n_elements),
                   variant_resolution=None if resolution is None else (factor * resolution[0], resolution[1]))


def fewest_elements(scene) -> int:
    """The fewest elements per cable its exits take (:meth:`~cdpr_exu.exits.base.Exit.fewest_elements`)."""
    return max(exit_.fewest_elements(cable) for cable, exit_ in zip(scene.cables, scene.exits))


def run_configuration(scene_data: dict[str, Any]) -> dict[str, Any]:
    """Simulate one configuration given as plain scene data (the study's worker); never raises.

    Returns ``status``, ``wall_time_s``, ``cpu_time_s``, ``simulated_time_s``, ``steps``,
    ``newton_iterations``, ``failure_time_s`` and, for runs with samples, ``time`` (N,) [s],
    ``pose`` (N, 3 or 6) [m, rad], ``end_tensions`` (N, m) [N] at the platform ends and the
    platform's ``speed`` (N,) [m/s] (spatial: from finite differences of the positions).
    """
    empty = {"wall_time_s": math.nan, "cpu_time_s": math.nan, "simulated_time_s": math.nan, "steps": 0,
             "newton_iterations": 0, "failure_time_s": math.nan}
    # the study samples once per step where the step is coarser, knowingly
    _, result, status, cpu = recorded_run(scene_data, quiet=(CoarseOutputWarning,))
    if result is None:
        return {"status": status, **empty}
    pose = np.asarray(result.pose)
    finite = np.all(np.isfinite(pose), axis=1)
    tensions = np.column_stack([t[:, -1] for t in result.tensions]) if result.tensions else np.zeros((len(finite), 0))
    times = np.asarray(result.time)[finite]
    if result.velocity is not None:  # recorded (planar runs)
        speed = np.linalg.norm(result.velocity[finite, :result.space.position_size], axis=1)
    else:
        speed = (np.linalg.norm(np.gradient(result.position[finite], times, axis=0), axis=1) if len(times) > 1
                 else np.zeros(len(times)))
    return {
        "status": status,
        "wall_time_s": float(result.wall_time),
        "cpu_time_s": float(cpu),
        "simulated_time_s": float(times[-1]) if finite.any() else 0.0,
        "steps": int(result.steps),
        "newton_iterations": int(result.newton_iterations),
        "failure_time_s": math.nan if result.failure_time is None else float(result.failure_time),
        "time": times,
        "pose": pose[finite],
        "end_tensions": tensions[finite],
        "speed": speed,
    }


#: Error figures of every compared run, in column order.
ERROR_FIGURES = ("position_error_max_m", "position_error_rms_m", "rotation_error_max_deg",
                 "tension_error_max_N", "tension_error_rms_N", "final_speed_m_s")


def compare(run: Mapping[str, Any], reference: Mapping[str, Any], comparison: str = "path",
            after: float = 1.0, space: Space = PLANE) -> dict[str, float]:
    """The :data:`ERROR_FIGURES` [m, deg, N, m/s] of one run against the reference (outcomes of
    :func:`run_configuration`); NaN where the run does not cover the compared times.

    ``comparison`` "path": on the reference's times from ``after`` [s] on, the run interpolated
    linearly; "final": the last samples. ``space``: what the poses are.
    """
    nan = {name: math.nan for name in ERROR_FIGURES}
    if "time" not in run or len(run["time"]) == 0:
        return nan
    t_ref = np.asarray(reference["time"])
    t_run = np.asarray(run["time"])
    speed = float(np.asarray(run["speed"])[-1])
    if comparison == "final":
        if t_run[-1] < t_ref[-1] - 1e-9:
            return {**nan, "final_speed_m_s": speed}
        reference_pose = np.asarray(reference["pose"])[-1:]
        pose = np.asarray(run["pose"])[-1:]
        tension_error = np.asarray(run["end_tensions"])[-1:] - np.asarray(reference["end_tensions"])[-1:]
    elif comparison == "path":
        mask = t_ref >= min(after, t_ref[-1]) - 1e-9
        times = t_ref[mask]
        if t_run[-1] < times[-1] - 1e-9:
            return {**nan, "final_speed_m_s": speed}
        pose = np.column_stack([np.interp(times, t_run, column) for column in np.asarray(run["pose"]).T])
        tensions = np.column_stack([np.interp(times, t_run, column) for column in np.asarray(run["end_tensions"]).T])
        reference_pose = np.asarray(reference["pose"])[mask]
        tension_error = tensions - np.asarray(reference["end_tensions"])[mask]
    else:
        raise SceneError(f"comparison must be 'path' or 'final', got {comparison!r}")
    position = np.linalg.norm((pose - reference_pose)[:, :space.position_size], axis=1)
    rotation = space.rotation_error_deg(pose, reference_pose)
    return {
        "position_error_max_m": float(position.max()),
        "position_error_rms_m": float(np.sqrt(np.mean(position**2))),
        "rotation_error_max_deg": float(rotation.max()),
        "tension_error_max_N": float(np.abs(tension_error).max()),
        "tension_error_rms_N": float(np.sqrt(np.mean(tension_error**2))),
        "final_speed_m_s": speed,
    }


def comparison_for(scene) -> str:
    """``"final"`` for a static scene (held pose, fixed winches), else ``"path"``."""
    static = isinstance(scene.trajectory, HoldTrajectory) and scene.winch.kind == "fixed"
    return "final" if static else "path"


def pareto_front(rows: Sequence[Mapping[str, Any]], error: str = "position_error_max_m") -> list[Mapping[str, Any]]:
    """Completed runs no other run beats in both cost (:data:`COST`) and ``error``, cheapest first."""
    candidates = sorted((r for r in rows if _usable(r, error)), key=lambda r: (r[COST], r[error]))
    front, best = [], math.inf
    for row in candidates:
        if row[error] < best:
            front.append(row)
            best = row[error]
    return front


def cheapest_meeting(rows: Sequence[Mapping[str, Any]], tolerance: float, error: str = "position_error_max_m",
                     model: str | None = None) -> Mapping[str, Any] | None:
    """The completed run of least cost (:data:`COST`) whose ``error`` is within ``tolerance``."""
    meeting = [r for r in rows if _usable(r, error) and r[error] <= tolerance and (model is None or r["model"] == model)]
    return min(meeting, key=lambda r: r[COST]) if meeting else None


def _usable(row: Mapping[str, Any], error: str) -> bool:
    """A completed, compared run other than the reference."""
    return (row.get("status") == "completed" and not row.get("is_reference")
            and _finite(row.get(error)) and _finite(row.get(COST)))


@dataclass
class AccuracyStudy:
    """The outcome of :func:`run_accuracy_study`: a row per configuration (the reference first; the
    ``moved_*`` errors against ``full`` at the variant resolution) and the time ``series`` of every run
    with samples, by run index (not written)."""

    rows: list[dict[str, Any]]
    reference: Configuration
    comparison: str
    scene_name: str
    end_time: float
    after: float
    grid: AccuracyGrid
    series: dict[int, dict[str, Any]] = field(default_factory=dict, repr=False)

    #: For the figure (:func:`cdpr_exu.post.study_plots.plot_pareto`).
    COST = COST
    TOLERANCES = TOLERANCES

    @property
    def reference_row(self) -> dict[str, Any]:
        return next(r for r in self.rows if r["is_reference"])

    def compared(self, error: str) -> list[dict[str, Any]]:
        """The completed, compared runs other than the reference, with a finite ``error`` and cost."""
        return [r for r in self.rows if _usable(r, error)]

    def front(self, error: str) -> list[Mapping[str, Any]]:
        """:func:`pareto_front` of the runs for ``error``."""
        return pareto_front(self.rows, error)


def check_study_scene(scene) -> None:
    """Refuse (SceneError) a scene without a ``[trajectory]``, before any run."""
    if scene.trajectory is None:
        raise SceneError(f"scene {scene.name!r} has no [trajectory]: `cdpr study accuracy` runs the scene's "
                         "reference (`cdpr static` gives a spatial scene's static mode)")


def _estimated_cost(configuration: Configuration) -> float:
    """Rough relative cost, to start the longest runs first."""
    n = configuration.n_elements or 4
    return n ** 1.5 / configuration.step_size


def run_accuracy_study(scene, grid: AccuracyGrid | None = None, *, out: str | Path | None = None,
                       workers: int | None = None, executor: Executor | None = None, progress: bool = True,
                       comparison: str | None = None) -> AccuracyStudy:
    """Run ``scene`` (a Scene, shipped name or TOML path) on every configuration of ``grid`` (default
    :func:`grid_for` it) and compare each with the reference.

    ``out``: folder for the files (:func:`write_accuracy_study`); ``workers``: single-threaded
    processes (default one per core), or ``executor`` (not shut down here); ``comparison``:
    default :func:`comparison_for` the scene. SceneError if the reference run does not complete.
    """
    base = load_scene(scene) if isinstance(scene, (str, Path)) else scene
    check_study_scene(base)
    grid = grid or grid_for(base)
    if grid.end_time is not None:
        base = base.with_changes(solver=replace(base.solver, end_time=grid.end_time))
    comparison = comparison or comparison_for(base)
    after = grid.after if grid.after < base.solver.end_time else 0.0
    base_data = base.to_dict()
    configurations = grid.configurations()
    rows: list[dict[str, Any]] = []
    pending: list[tuple[int, dict[str, Any]]] = []
    for index, configuration in enumerate(configurations):
        row = {"run": index, "model": configuration.model, "preset": configuration.preset,
               "n_elements": configuration.n_elements, "step_size_s": configuration.step_size,
               "overrides": "; ".join(f"{p}={v}" for p, v in configuration.overrides),
               "is_reference": configuration == grid.reference}
        rows.append(row)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", CoarseOutputWarning)
                data = scene_from_dict(configuration.scene_data(base_data)).to_dict()
        except SceneError as err:
            row["status"] = "refused: " + " ".join(str(err).split())
        else:
            pending.append((index, data))
    pending.sort(key=lambda item: -_estimated_cost(configurations[item[0]]))

    series: dict[int, dict[str, Any]] = {}
    bar = progress_bar(len(rows), progress)
    bar.update(len(rows) - len(pending))
    try:
        with executor_for(executor, min(workers or os.cpu_count() or 1, max(len(pending), 1)), None) as pool:
            futures: dict[Future, int] = {pool.submit(run_configuration, data): index for index, data in pending}
            for future in as_completed(futures):
                index = futures[future]
                try:
                    outcome = future.result()
                except Exception as err:  # noqa: BLE001 - a lost worker fails one run, not the study
                    outcome = {"status": f"failed: worker error: {type(err).__name__}: {err}"}
                if "time" in outcome:
                    series[index] = {k: outcome.pop(k) for k in ("time", "pose", "end_tensions", "speed")}
                rows[index].update(outcome)
                bar.update(1)
    finally:
        bar.close()

    reference_index = next(r["run"] for r in rows if r["is_reference"])
    if rows[reference_index]["status"] != "completed":
        raise SceneError(f"the reference run ({grid.reference.label}) did not complete: "
                         f"{rows[reference_index]['status']}")
    reference = series[reference_index]
    for row in rows:
        row.setdefault("wall_time_s", math.nan)
        row.setdefault(COST, math.nan)
        simulated = row.get("simulated_time_s", math.nan)
        row["real_time_factor"] = (simulated / row[COST]
                                   if _finite(simulated) and _finite(row[COST]) and row[COST] > 0 else math.nan)
        figures = compare(series[row["run"]], reference, comparison, after, base.space) if row["run"] in series else {}
        for name in ERROR_FIGURES:
            row[name] = figures.get(name, math.nan)
        if row["status"] != "completed":  # errors of a partial run are not comparable
            for name in ERROR_FIGURES[:-1]:
                row[name] = math.nan
    _effects_columns(rows, series, grid, comparison, after, base.space)
    study = AccuracyStudy(rows, grid.reference, comparison, base.name, base.solver.end_time, after, grid, series)
    if out is not None:
        write_accuracy_study(study, base, out)
    return study


def _effects_columns(rows: list[dict[str, Any]], series: Mapping[int, Mapping[str, Any]], grid: AccuracyGrid,
                     comparison: str, after: float, space: Space) -> None:
    """``moved_*`` columns: each run at the variant resolution against ``full`` there."""
    for row in rows:
        row["moved_position_max_m"] = row["moved_position_rms_m"] = row["moved_rotation_max_deg"] = math.nan
        row["moved_tension_rms_N"] = row["cost_relative_to_full"] = math.nan
        row["at_variant_resolution"] = False
    if grid.variant_resolution is None:
        return
    n, h = grid.variant_resolution
    full = next((r for r in rows if r["model"] == "full" and r["n_elements"] == n and r["step_size_s"] == h), None)
    if full is None or full.get("status") != "completed":
        return
    for row in rows:
        if row["step_size_s"] != h or row["n_elements"] not in (n, None):
            continue
        row["at_variant_resolution"] = True
        if row.get("status") != "completed" or row["run"] not in series:
            continue
        moved = compare(series[row["run"]], series[full["run"]], comparison, after, space)
        row["moved_position_max_m"] = moved["position_error_max_m"]
        row["moved_position_rms_m"] = moved["position_error_rms_m"]
        row["moved_rotation_max_deg"] = moved["rotation_error_max_deg"]
        row["moved_tension_rms_N"] = moved["tension_error_rms_N"]
        row["cost_relative_to_full"] = row[COST] / full[COST]


COLUMNS = ("run", "model", "preset", "overrides", "n_elements", "step_size_s", "is_reference", "status",
           "cpu_time_s", "wall_time_s", "real_time_factor", "simulated_time_s", "steps", "newton_iterations",
           "failure_time_s", *ERROR_FIGURES, "at_variant_resolution", "moved_position_max_m", "moved_position_rms_m",
           "moved_rotation_max_deg", "moved_tension_rms_N", "cost_relative_to_full")


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return "" if math.isnan(value) else f"{value:.6g}"
    return str(value)


def write_accuracy_study(study: AccuracyStudy, base_scene, out: str | Path) -> dict[str, Path]:
    """Write the CSV, JSON, tables, Pareto plot (:func:`cdpr_exu.post.study_plots.plot_pareto`) and the
    reference's series into ``out``."""
    out = check_output_folder(out, command="study accuracy")
    clear_outputs(out, "study accuracy")  # no file of an earlier accuracy study stays
    paths = {"scene": save_scene(base_scene, out / ACCURACY_FILES["scene"])}
    with open(out / ACCURACY_FILES["csv"], "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        for row in study.rows:
            writer.writerow([_cell(row.get(c)) for c in COLUMNS])
    paths["csv"] = out / ACCURACY_FILES["csv"]
    reference_row = study.reference_row
    info = {
        "scene": study.scene_name,
        "end_time_s": study.end_time,
        "comparison": study.comparison,
        "errors_measured_after_s": study.after if study.comparison == "path" else None,
        "reference": {"configuration": study.reference.label, "preset": study.reference.preset,
                      "n_elements": study.reference.n_elements, "step_size_s": study.reference.step_size,
                      "cpu_time_s": reference_row[COST], "wall_time_s": reference_row["wall_time_s"]},
        "cost": "cpu_time_s: CPU time of the single-threaded run, model building included",
        "tolerances_m": list(TOLERANCES),
        "grid": {"models": [model_name(p, o) for p, o in study.grid.models],
                 "n_elements": list(study.grid.n_elements), "step_sizes_s": list(study.grid.step_sizes),
                 "variants": [model_name("full", v) for v in study.grid.variants],
                 "variant_resolution": study.grid.variant_resolution},
        "rows": [{c: row.get(c) for c in COLUMNS} for row in study.rows],  # NaN as null (write_summary)
        **provenance(),
    }
    # the measured times stay: error against CPU time is the study's subject (README, "Outputs")
    write_summary(out, info, name=ACCURACY_FILES["json"], keep=("cpu_time_s", "wall_time_s", "real_time_factor"))
    paths["json"] = out / ACCURACY_FILES["json"]
    reference = study.series[reference_row["run"]]
    write_npz(out / ACCURACY_FILES["reference"], **reference)
    paths["reference"] = out / ACCURACY_FILES["reference"]
    (out / ACCURACY_FILES["tables"]).write_text(format_tables(study) + "\n")
    paths["tables"] = out / ACCURACY_FILES["tables"]
    from cdpr_exu.post.study_plots import plot_pareto

    paths["pareto"] = plot_pareto(study, out / ACCURACY_FILES["pareto"])
    return paths


def _mm(value: Any) -> str:
    return f"{1000 * value:.3g}" if _finite(value) else "-"


def _seconds(value: Any) -> str:
    return f"{value:.2f}" if _finite(value) else "-"


def _markdown(head: Sequence[str], lines: Sequence[Sequence[str]]) -> str:
    out = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    out.extend("| " + " | ".join(line) + " |" for line in lines)
    return "\n".join(out)


def _configuration_cell(row: Mapping[str, Any]) -> str:
    n = "-" if row.get("n_elements") is None else str(row["n_elements"])
    return f"{row['model']} | {n} | {row['step_size_s']:.0e}"


def format_tables(study: AccuracyStudy) -> str:
    """Markdown tables: tolerances, per-model best, effects, and the runs that did not complete."""
    rows = study.rows
    ref = study.reference_row
    what = ("platform position error after " f"{study.after:g} s (max over time)" if study.comparison == "path"
            else "final platform position error")
    parts = [f"# Accuracy against cost: {study.scene_name}, {study.end_time:g} s",
             "",
             f"Reference: {study.reference.label} ({ref[COST]:.1f} s CPU time). "
             f"Error: {what}, against the reference. Cost: the CPU time of the single-threaded "
             "run (model building included; about its wall time on an idle core); x real time = "
             "simulated time / CPU time.",
             "",
             "## Cheapest configuration meeting each tolerance",
             ""]
    lines = []
    for tolerance in TOLERANCES:
        best = cheapest_meeting(rows, tolerance)
        if best is None:
            lines.append([f"{1000 * tolerance:g} mm", "none", "-", "-", "-", "-", "-", "-"])
            continue
        lines.append([f"{1000 * tolerance:g} mm", _configuration_cell(best), _seconds(best[COST]),
                      f"{best['real_time_factor']:.1f}", _mm(best["position_error_max_m"]),
                      _mm(best["position_error_rms_m"]), f"{best['tension_error_rms_N']:.3g}"])
    parts.append(_markdown(["tolerance", "model", "n", "step [s]", "CPU [s]", "x real time", "max err [mm]",
                            "rms err [mm]", "tension rms err [N]"], lines))
    parts += ["", "## Each model: cheapest run per tolerance (CPU time [s]) and its best run", ""]
    lines = []
    for model in dict.fromkeys(r["model"] for r in rows):
        members = [r for r in rows if r["model"] == model]
        done = [r for r in members if _usable(r, "position_error_max_m")]
        cells = [model]
        for tolerance in TOLERANCES:
            best = cheapest_meeting(rows, tolerance, model=model)
            cells.append("-" if best is None else f"{best[COST]:.2f} (n={best['n_elements'] or '-'}, "
                         f"h={best['step_size_s']:.0e})")
        if done:
            best = min(done, key=lambda r: r["position_error_max_m"])
            cells += [_mm(best["position_error_max_m"]), f"n={best['n_elements'] or '-'}, h={best['step_size_s']:.0e}",
                      _seconds(best[COST])]
        else:
            cells += ["-", "-", "-"]
        status = {}
        for r in members:
            kind = r["status"].split(":")[0]
            status[kind] = status.get(kind, 0) + 1
        cells.append(", ".join(f"{v} {k}" for k, v in status.items()))
        lines.append(cells)
    parts.append(_markdown(["model", *[f"<= {1000 * t:g} mm" for t in TOLERANCES], "best err [mm]", "at",
                            "its CPU [s]", "runs"], lines))
    effects = [r for r in rows if r.get("at_variant_resolution")]
    if effects:
        n, h = study.grid.variant_resolution
        parts += ["", f"## What each model and effect changes, against `full` at n = {n}, h = {h:g} s", "",
                  "(massless presets at the same step; moved = difference of the platform "
                  + ("path after " + f"{study.after:g} s" if study.comparison == "path" else "final position")
                  + "; cost = CPU time / that of full)", ""]
        lines = []
        for r in effects:
            lines.append([r["model"], "-" if r["n_elements"] is None else str(r["n_elements"]),
                          r["status"].split(":")[0], _mm(r["moved_position_max_m"]), _mm(r["moved_position_rms_m"]),
                          f"{r['moved_rotation_max_deg']:.3g}" if _finite(r["moved_rotation_max_deg"]) else "-",
                          f"{r['moved_tension_rms_N']:.3g}" if _finite(r["moved_tension_rms_N"]) else "-",
                          _seconds(r[COST]),
                          f"{r['cost_relative_to_full']:.2f}" if _finite(r["cost_relative_to_full"]) else "-"])
        parts.append(_markdown(["model", "n", "status", "moved max [mm]", "moved rms [mm]", "rotation [deg]",
                                "tension rms [N]", "CPU [s]", "cost"], lines))
    if study.comparison == "final":
        moving = [r for r in rows if r["status"] == "completed" and _finite(r.get("final_speed_m_s"))
                  and r["final_speed_m_s"] > 1e-3]
        if moving:
            parts += ["", "## Runs not at rest at the end (platform speed above 1 mm/s)", ""]
            parts.append(_markdown(["model", "n", "step [s]", "final speed [m/s]"],
                                   [[*_configuration_cell(r).split(" | "), f"{r['final_speed_m_s']:.3g}"] for r in moving]))
    bad = [r for r in rows if r["status"] != "completed"]
    if bad:
        parts += ["", "## Runs that did not complete", ""]
        lines = []
        for r in bad:
            kind, _, cause = r["status"].partition(": ")
            cause = cause.split(". Likely cause")[0]
            if len(cause) > 160:
                cause = cause[:157] + "..."
            when = f"{r['failure_time_s']:.2f}" if _finite(r.get("failure_time_s")) else "-"
            lines.append([*_configuration_cell(r).split(" | "), kind, when, cause.replace("|", "/")])
        parts.append(_markdown(["model", "n", "step [s]", "status", "stopped at [s]", "cause"], lines))
    return "\n".join(parts)
