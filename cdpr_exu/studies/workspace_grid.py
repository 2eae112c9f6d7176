"""The workspace that sagging cables leave: a grid of platform positions under the massless and the catenary model.

Each position of a :class:`WorkspaceGrid` (at each of its orientations) is checked by both models of
:mod:`cdpr_exu.statics.feasibility`: one row per position and orientation with their statuses and, per cable,
the tensions, lengths and sags. A position is held by a model when it is held at every orientation; the
summary gives the volume (area, for a grid over two axes) each model holds and the share of the massless
workspace the catenary model keeps. Chunks of the grid run on the process pool or Dask cluster of
:mod:`cdpr_exu.studies.study`; each chunk's rows are appended to ``points.jsonl`` as it finishes, and a grid
started again into the same folder skips the rows found there (it resumes).

This module imports only the standard library and the study's helpers at its top, so that a spawned worker
sets its thread limits before NumPy loads.
"""

from __future__ import annotations

import csv
import itertools
import json
import math
import os
from collections import Counter
from concurrent.futures import as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from cdpr_exu.core.errors import OutputError, SceneError
from cdpr_exu.core.validation import entries
from cdpr_exu.studies.study import executor_for, progress_bar

#: Files a workspace grid writes.
WORKSPACE_FILES = {"rows": "points.jsonl", "spec": "grid.json", "csv": "workspace.csv", "json": "summary.json",
                   "table": "summary.md", "scene": "scene.toml"}
#: Largest memory the rows of a grid may take [bytes]; a grid needing more is refused before it starts.
MAX_GRID_BYTES = 2**30
#: Memory of one value of a row held in Python [bytes] (a float object, its slot in a dict, its share of
#: the keys): the grid's estimate is rows x columns x this.
BYTES_PER_VALUE = 100
#: Per-cable columns of a row ({} the cable's number, 1..m).
CABLE_COLUMNS = ("massless_tension_{}_N", "catenary_anchor_tension_{}_N", "catenary_exit_tension_{}_N",
                 "massless_length_{}_m", "catenary_unstrained_length_{}_m", "catenary_sag_{}_m")


@dataclass(frozen=True)
class WorkspaceGrid:
    """Platform positions, every combination of the values [m] of each position axis (``labels``: the space's,
    in order; one value: the axis is fixed), and the ``orientations`` [rad] (each the space's rotation as a
    tuple) that must all hold."""

    labels: tuple
    values: tuple
    orientations: tuple

    @property
    def size(self) -> int:
        return math.prod(len(v) for v in self.values)

    @property
    def varied(self) -> tuple:
        """Indices of the axes with more than one value."""
        return tuple(i for i, v in enumerate(self.values) if len(v) > 1)

    @property
    def cell(self) -> float:
        """Volume (area, length) each position stands for [m^k]: the product of the varied axes' steps."""
        return math.prod((self.values[i][-1] - self.values[i][0]) / (len(self.values[i]) - 1) for i in self.varied)

    def positions(self) -> list:
        return list(itertools.product(*self.values))

    def to_dict(self) -> dict:
        return {"axes": dict(zip(self.labels, map(list, self.values))), "orientations": list(map(list, self.orientations))}


def start_pose(scene) -> list:
    """The pose the grid's fixed axes and orientation default to [m, rad]: ``platform.initial_pose``, else the
    reference's at t = 0, else the origin unrotated."""
    if scene.platform.initial_pose is not None or scene.trajectory is None:
        return list(scene.platform.initial_pose or [0.0] * scene.space.pose_size)
    return [float(v) for v in scene.trajectory.pose(0.0)]


def _axis(text: str, labels: Sequence[str]) -> tuple[str, tuple]:
    """``"x=-1:1:21"`` (21 values from -1 to 1 m) or ``"x=0.5"`` -> (label, (start, stop, count))."""
    label, _, spec = str(text).partition("=")
    label, parts = label.strip(), spec.split(":")
    if label not in labels:
        raise SceneError(f"grid {text!r}: the axis must be one of {', '.join(labels)} (write e.g. {labels[0]}=-1:1:21)")
    try:
        start, stop, count = (float(parts[0]), float(parts[0]), 1) if len(parts) == 1 else (
            float(parts[0]), float(parts[1]), int(parts[2]))
    except (ValueError, IndexError):
        start = math.nan
    if len(parts) not in (1, 3) or not math.isfinite(start) or not math.isfinite(stop):
        raise SceneError(f"grid {label}: {spec!r} must read START:STOP:COUNT or one value, finite numbers [m]")
    if count < 1 or (count > 1 and not start < stop):
        raise SceneError(f"grid {label}: {spec!r} is empty; it needs COUNT >= 1 and START < STOP (COUNT > 1)")
    return label, (start, stop, count)


def make_grid(scene, axes: Sequence[str], orientations: Sequence[Sequence[float]] | None = None) -> WorkspaceGrid:
    """The grid of ``axes`` (``"LABEL=START:STOP:COUNT"`` or ``"LABEL=VALUE"``; an axis not given stays at
    :func:`start_pose`'s) at ``orientations`` (each a sequence: the angle [rad] planar, the rotation vector
    [rad] spatial; default the start pose's). Raises SceneError before anything is allocated, naming the axis
    (unknown, malformed, not finite, empty, given twice), ``orientation[k]`` or ``grid`` (rows beyond
    :data:`MAX_GRID_BYTES`)."""
    space = scene.space
    labels, start = space.position_labels, start_pose(scene)
    if not axes:
        raise SceneError(f"grid: give at least one axis (e.g. {labels[0]}=-1:1:21)")
    given = {}
    for text in axes:
        label, spec = _axis(text, labels)
        if label in given:
            raise SceneError(f"grid {label}: given twice; give each axis once")
        given[label] = spec
    specs = [given.get(label, (float(start[i]),) * 2 + (1,)) for i, label in enumerate(labels)]
    rotations = orientations or [start[space.position_size:]]
    rotations = [entries(f"orientation[{k}]", r, space.rotation_size, "rad") for k, r in enumerate(rotations)]
    size = math.prod(count for *_, count in specs) * len(rotations)
    needed = size * len(columns(labels, scene.n_cables)) * BYTES_PER_VALUE
    if needed > MAX_GRID_BYTES:
        raise SceneError(f"grid: {size} positions and orientations need about {needed / 2**30:.1f} GiB for their "
                         f"rows, beyond the {MAX_GRID_BYTES / 2**30:g} GiB allowed; use fewer points")
    values = tuple(tuple(a + (b - a) * k / max(n - 1, 1) for k in range(n)) for a, b, n in specs)
    return WorkspaceGrid(labels, values, tuple(rotations))


# --------------------------------------------------------------------------- the workers


def evaluate_points(scene_data: dict, limits: list, tasks: list) -> list[dict]:
    """Both models at each ``(position index, orientation index, pose)`` of ``tasks``: one row each. The worker:
    top-level and picklable, it takes and returns plain data."""
    import numpy as np

    from cdpr_exu.scenes.scene import scene_from_dict
    from cdpr_exu.statics.feasibility import catenary_holding, massless_holding
    from cdpr_exu.statics.statics import catenary_platform

    scene = scene_from_dict(scene_data)
    platform, limits, labels = catenary_platform(scene), np.asarray(limits, dtype=float), scene.space.position_labels
    rows = []
    for point, orientation, pose in tasks:
        massless = massless_holding(scene, pose, limits)
        catenary = catenary_holding(scene, pose, limits, massless.anchor_tensions, platform)
        row = {"point": point, "orientation": orientation, **dict(zip(labels, pose)),
               "massless_status": massless.status, "catenary_status": catenary.status,
               "catenary_iterations": catenary.iterations}
        values = (massless.anchor_tensions, catenary.anchor_tensions, catenary.exit_tensions, massless.lengths,
                  catenary.lengths, catenary.sags)
        for column, value in zip(CABLE_COLUMNS, values):
            row.update({column.format(i + 1): None if value is None else float(value[i]) for i in range(scene.n_cables)})
        rows.append(row)
    return rows


def columns(labels: Sequence[str], n_cables: int) -> list[str]:
    """The columns of a row, in order (the per-cable ones numbered 1..m before their unit)."""
    per_cable = [c.format(i) for c in CABLE_COLUMNS for i in range(1, n_cables + 1)]
    return ["point", "orientation", *labels, "massless_status", "catenary_status", "catenary_iterations", *per_cable]


# --------------------------------------------------------------------------- the grid


def run_workspace(scene, grid: WorkspaceGrid, limits, out=None, *, workers: int | None = None,
                  scheduler: str | None = None, executor=None, progress: bool = True, chunk: int = 50) -> list[dict]:
    """Check every position and orientation of ``grid`` (:func:`make_grid`) under both models within ``limits``
    (m, 2) [N] (:func:`~cdpr_exu.statics.feasibility.tension_bounds`), ``chunk`` per task; one row each, position
    order then orientation order (:func:`columns`). With ``out``, rows are appended to ``points.jsonl`` as their
    chunk finishes and those found there are not checked again (``grid.json`` must be this grid's, else refused);
    the files are written at the end (:func:`write_workspace`). ``workers``, ``scheduler``, ``executor``: as
    :func:`cdpr_exu.studies.study.run_study`."""
    from cdpr_exu.core.output import json_text, strict

    limits = [[float(low), float(high)] for low, high in limits]
    data = scene.to_dict()
    spec = json_text({"scene": data, "limits_N": limits, **grid.to_dict()})
    done = {}
    if out is not None:
        out = Path(out)
        found = out / WORKSPACE_FILES["spec"]
        if found.exists() and found.read_text() != spec and (out / WORKSPACE_FILES["rows"]).exists():
            raise OutputError(f"--out {out}: holds the rows of another grid, scene or limits ({found.name}); give "
                              "another folder, or remove its points.jsonl to start afresh")
        out.mkdir(parents=True, exist_ok=True)
        found.write_text(spec)
        journal = out / WORKSPACE_FILES["rows"]
        for line in journal.read_text().splitlines() if journal.exists() else ():
            try:
                row = json.loads(line)
            except json.JSONDecodeError:
                continue  # a line an interruption cut short: rewritten without it below
            done[(row["point"], row["orientation"])] = row
        journal.write_text("".join(json.dumps(r, allow_nan=False) + "\n" for r in done.values()))
    tasks = [(p, o, [*position, *rotation]) for p, position in enumerate(grid.positions())
             for o, rotation in enumerate(grid.orientations) if (p, o) not in done]
    chunks = [tasks[k:k + chunk] for k in range(0, len(tasks), chunk)]
    bar = progress_bar(len(tasks), progress)
    try:
        if chunks:
            size = None if executor is not None or scheduler else min(workers or os.cpu_count() or 1, len(chunks))
            with executor_for(executor, size or workers, scheduler) as pool:
                futures = {pool.submit(evaluate_points, data, limits, part): part for part in chunks}
                for future in as_completed(futures):
                    rows = future.result()
                    done.update({(r["point"], r["orientation"]): r for r in rows})
                    if out is not None:
                        with open(out / WORKSPACE_FILES["rows"], "a") as handle:
                            handle.writelines(json.dumps(strict(r), allow_nan=False) + "\n" for r in rows)
                    bar.update(len(rows))
    finally:
        bar.close()
    rows = [done[(p, o)] for p in range(grid.size) for o in range(len(grid.orientations))]
    if out is not None:
        write_workspace(out, rows, scene, grid, limits)
    return rows


def held_positions(rows: Sequence[dict], grid: WorkspaceGrid) -> dict[str, list[bool]]:
    """Per model (``massless``, ``catenary``), whether each position is held at every orientation, grid order."""
    held = {model: [True] * grid.size for model in ("massless", "catenary")}
    for row in rows:
        for model in held:
            held[model][row["point"]] &= row[f"{model}_status"] == "held"
    return held


def summarise(rows: Sequence[dict], grid: WorkspaceGrid) -> dict[str, Any]:
    """The positions and volume [m^k] each model holds, the share of the massless workspace the catenary model
    keeps (None when the massless model holds nothing), the positions only the catenary model holds (at least:
    it searches only near the massless tensions) and the count of each status."""
    held = held_positions(rows, grid)
    both = sum(a and b for a, b in zip(held["massless"], held["catenary"]))
    counts = {model: sum(flags) for model, flags in held.items()}
    unit = f"m^{len(grid.varied)}"
    statuses = {model: dict(sorted(Counter(r[f"{model}_status"] for r in rows).items())) for model in held}
    return {"positions": grid.size, "orientations": len(grid.orientations), "cell": grid.cell, "unit": unit,
            "held_positions": counts, "held_volume": {m: c * grid.cell for m, c in counts.items()},
            "held_by_both": both, "catenary_only": counts["catenary"] - both,
            "catenary_keeps": both / counts["massless"] if counts["massless"] else None,
            "lost_to_sag": 1.0 - both / counts["massless"] if counts["massless"] else None, "statuses": statuses}


def summary_markdown(name: str, summary: dict, limits) -> str:
    """The summary as Markdown."""
    unit, volume, kept = summary["unit"], summary["held_volume"], summary["catenary_keeps"]
    lines = [f"# Workspace of {name}", "",
             f"{summary['positions']} positions x {summary['orientations']} orientation(s), {summary['cell']:.4g} "
             f"{unit} each; tensions within [{min(l for l, _ in limits):g}, {max(h for _, h in limits):g}] N.", "",
             f"| model | positions held | {'volume' if unit == 'm^3' else 'size'} [{unit}] |", "|---|---|---|"]
    lines += [f"| {m} | {summary['held_positions'][m]} | {volume[m]:.4g} |" for m in ("massless", "catenary")]
    lines += ["", f"The catenary model keeps {'n/a' if kept is None else f'{100 * kept:.1f} %'} of the massless "
              f"workspace; at least {summary['catenary_only']} positions are held by the catenary model only."]
    return "\n".join(lines) + "\n"


def write_workspace(out, rows: Sequence[dict], scene, grid: WorkspaceGrid, limits, plots: bool = True) -> dict:
    """Write ``workspace.csv`` (empty cells where a model does not hold), ``summary.json``, ``summary.md``,
    ``scene.toml`` and the figures (:func:`cdpr_exu.post.workspace_plots.plot_workspace`); return the paths."""
    from cdpr_exu.core.output import clear_outputs, csv_cell, write_json
    from cdpr_exu.scenes.scene import save_scene

    out = Path(out)
    clear_outputs(out, "workspace")  # no figure of an earlier grid stays
    names = columns(grid.labels, scene.n_cables)
    paths = {"scene": save_scene(scene, out / WORKSPACE_FILES["scene"]), "csv": out / WORKSPACE_FILES["csv"],
             "table": out / WORKSPACE_FILES["table"]}
    with open(paths["csv"], "w", newline="") as handle:
        csv.writer(handle).writerows([names, *([csv_cell(row.get(c)) for c in names] for row in rows)])
    summary = summarise(rows, grid)
    paths["json"] = write_json(out / WORKSPACE_FILES["json"], {"scene": scene.name, "limits_N": limits,
                                                               **grid.to_dict(), **summary})
    paths["table"].write_text(summary_markdown(scene.name, summary, limits))
    if plots:
        from cdpr_exu.post.workspace_plots import plot_workspace

        paths.update(plot_workspace(grid.labels, grid.values, held_positions(rows, grid), out, scene.name))
    return paths
