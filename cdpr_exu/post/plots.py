"""Figures of a run: the robot at several instants, the platform's path, rotation, errors and cable
tensions (the paper's Figs. 6 and 7), controller comparisons, a spatial run's overview
(:func:`plot_spatial_run`) and the rest of the static mode (:func:`plot_rest`).

Each writes PNGs and returns their paths, drawn on :class:`matplotlib.figure.Figure` with the Agg
canvas (no pyplot state: safe in worker processes, no display). A failed or partial run is plotted as
far as it goes: rows whose pose is not finite are left out, an instant never reached is marked.
Planar positions are in the paper's x-z plane, the rotation positive counter-clockwise; errors are
actual - reference.
"""

from __future__ import annotations

import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Iterable, Mapping, Sequence

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Polygon
from matplotlib.transforms import ScaledTranslation

from cdpr_exu.core.errors import CdprError
from cdpr_exu.core.geometry import anchor_points, rotation_angles_deg
from cdpr_exu.results.result import Result
from cdpr_exu.scenes.scene import Scene
from cdpr_exu.space import PLANE, SPACE

if TYPE_CHECKING:  # pragma: no cover
    from cdpr_exu.run.rest import Rest

#: Resolution of the written PNGs [dots per inch].
DPI = 150

#: File names written by :func:`plot_overview`, by kind.
OVERVIEW_FILES = {
    "snapshots": "snapshots.png",
    "path": "path.png",
    "rotation": "rotation.png",
    "errors": "errors.png",
    "tensions": "tensions.png",
    "overview": "overview.png",
}

_REFERENCE_STYLE = dict(color="0.35", linestyle="--", linewidth=1.2)
_CABLE_COLORS = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown")
_PLATFORM_COLOR = "0.25"
_PULLEY_COLOR = "0.55"


def new_figure(width: float, height: float, left: float = 0.85, right: float = 0.2, bottom: float = 0.6,
               top: float = 0.4, wspace: float = 0.0, hspace: float = 0.0, columns: int = 1,
               lines: int = 1) -> Figure:
    """A figure with an Agg canvas and fixed margins [inches] (half the drawing time of a layout engine)."""
    figure = Figure(figsize=(width, height))
    FigureCanvasAgg(figure)
    axes_width = (width - left - right - wspace * (columns - 1)) / columns
    axes_height = (height - bottom - top - hspace * (lines - 1)) / lines
    figure.subplots_adjust(left=left / width, right=1.0 - right / width, bottom=bottom / height,
                           top=1.0 - top / height, wspace=wspace / axes_width, hspace=hspace / axes_height)
    return figure


def save_figure(figure: Figure, path: str | Path) -> Path:
    """Write ``figure`` as PNG to ``path`` (parent folders made; "tight": grown to hold every artist)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=DPI, format="png", bbox_inches="tight", pad_inches=0.1)
    return path


def _cable_color(i: int) -> str:
    return _CABLE_COLORS[i % len(_CABLE_COLORS)]


def _valid_rows(result: Result) -> np.ndarray:
    """Indices of the samples whose time and platform pose are finite, shape (K,)."""
    time = np.asarray(result.time, dtype=float)
    pose = np.asarray(result.pose, dtype=float).reshape(len(time), -1)
    ok = np.isfinite(time) & np.all(np.isfinite(pose), axis=1)
    return np.flatnonzero(ok)


def _last_time(result: Result) -> float | None:
    """Time of the last valid sample [s], or None if there is none."""
    rows = _valid_rows(result)
    return float(result.time[rows[-1]]) if len(rows) else None


def _reference_path(scene: Scene | None, result: Result | None) -> np.ndarray:
    """The reference path (x, z) (K, 2) [m]: the scene's over its whole end time, else the result's."""
    if scene is not None and scene.trajectory is not None:
        end = float(scene.solver.end_time)
        if result is not None and len(result.time) and np.isfinite(result.time).any():
            end = max(end, float(np.nanmax(result.time)))
        t = np.linspace(0.0, end, max(200, int(end * 60)))
        return np.asarray(scene.trajectory.pose(t), dtype=float)[:, :2]
    if result is not None:
        return np.asarray(result.reference, dtype=float)[:, :2]
    return np.zeros((0, 2))


def _platform_corners(scene: Scene, pose: np.ndarray) -> np.ndarray:
    """World corners of the platform rectangle at ``pose`` (x, z, phi), shape (4, 2) [m]."""
    width, height = scene.platform.size
    local = np.array([[-width, -height], [width, -height], [width, height], [-width, height]]) / 2.0
    return anchor_points(pose, local)


def _robot_limits(scene: Scene, result: Result, rows: np.ndarray, margin: float = 0.12):
    """Axis limits (xmin, xmax, zmin, zmax) [m] holding pulleys, cables, platform, path."""
    points = [np.asarray(p.point) + np.array([sx, sz]) * p.radius
              for p in scene.exits for sx, sz in ((-1, -1), (1, 1))]
    points = [np.asarray(points)]
    for nodes in result.nodes:
        nodes = np.asarray(nodes, dtype=float)[rows].reshape(-1, 2)
        points.append(nodes[np.all(np.isfinite(nodes), axis=1)])
    for k in rows[:: max(1, len(rows) // 50)]:
        points.append(_platform_corners(scene, np.asarray(result.pose[k], dtype=float)))
    if len(rows) == 0:
        points.append(_platform_corners(scene, np.asarray(scene.platform.initial_pose, dtype=float)))
    reference = _reference_path(scene, result)
    points.append(reference[np.all(np.isfinite(reference), axis=1)])
    allpoints = np.concatenate(points, axis=0)
    low, high = allpoints.min(axis=0), allpoints.max(axis=0)
    return low[0] - margin, high[0] + margin, low[1] - margin, high[1] + margin


def _nearest_row(result: Result, rows: np.ndarray, t: float) -> int | None:
    """Index of the valid sample nearest to time ``t``, or None if the run ended before."""
    if len(rows) == 0:
        return None
    times = np.asarray(result.time, dtype=float)[rows]
    spacing = float(np.median(np.diff(times))) if len(times) > 1 else 0.0
    if t > times[-1] + 0.5 * spacing + 1e-9:
        return None
    return int(rows[np.argmin(np.abs(times - t))])


def _draw_pulleys(ax, scene: Scene) -> None:
    for pulley in scene.exits:
        ax.add_patch(Circle(pulley.point, pulley.radius, facecolor="0.92", edgecolor=_PULLEY_COLOR,
                            linewidth=1.2, zorder=1))
        ax.plot(*pulley.point, marker="+", color=_PULLEY_COLOR, markersize=5, zorder=1)


def _free_span_sag(scene: Scene, i: int, nodes: np.ndarray):
    """``(start, end, sag)`` [m]: cable ``i``'s chord from the exit's tangent point to the anchor and the
    largest distance below it of a free node; None where no chord forms."""
    if not np.all(np.isfinite(nodes)):
        return None
    anchor = nodes[-1]
    pulley = scene.exits[i]
    center, radius = np.asarray(pulley.point, dtype=float), pulley.radius
    try:
        start = np.asarray(pulley.exit(anchor).tangent_point, dtype=float)
    except (CdprError, ValueError):
        return None
    chord = anchor - start
    length = float(np.linalg.norm(chord))
    if length <= 0.0:
        return None
    direction = chord / length
    normal = np.array([-direction[1], direction[0]])
    if normal[1] > 0.0:  # the sag is measured downwards
        normal = -normal
    relative = nodes - start
    along = relative @ direction
    below = relative @ normal
    on_pulley = np.flatnonzero(np.linalg.norm(nodes - center, axis=1) <= radius * 1.02 + 1e-9)
    first_free = on_pulley[-1] + 1 if len(on_pulley) else 1
    free = np.zeros(len(nodes), dtype=bool)
    free[first_free:] = True
    free &= (along > 0.0) & (along < length)
    sag = float(np.max(below[free], initial=0.0))
    return start, anchor, sag


def _draw_chords(ax, scene: Scene, result: Result, k: int) -> None:
    """Dotted straight chords of the free spans, with each cable's sag written by it."""
    for i, nodes in enumerate(result.nodes):
        xy = np.asarray(nodes[k], dtype=float)
        chord = _free_span_sag(scene, i, xy)
        if chord is None:
            continue
        start, end, sag = chord
        ax.plot([start[0], end[0]], [start[1], end[1]], color=_cable_color(i), linestyle=":",
                linewidth=0.9, alpha=0.8, zorder=2.8)
        middle = 0.5 * (start + end)
        angle = np.degrees(np.arctan2(end[1] - start[1], end[0] - start[0]))
        angle = (angle + 90.0) % 180.0 - 90.0  # keep the text upright
        ax.annotate(f"sag {100 * sag:.1f} cm", middle, xytext=(0, 5), textcoords="offset points",
                    ha="center", va="bottom", fontsize=7, color=_cable_color(i), rotation=angle,
                    rotation_mode="anchor", transform_rotates_text=True, zorder=6)


def _draw_robot(ax, scene: Scene, result: Result, k: int, alpha: float = 1.0,
                markers: bool = True, zorder: float = 3) -> None:
    """Draw the cables (node polylines) and the platform rectangle at sample ``k``."""
    pose = np.asarray(result.pose[k], dtype=float)
    for i, nodes in enumerate(result.nodes):
        xy = np.asarray(nodes[k], dtype=float)
        ax.plot(xy[:, 0], xy[:, 1], color=_cable_color(i), linewidth=1.4, alpha=alpha, zorder=zorder,
                marker="o" if markers else None, markersize=2.2, markeredgewidth=0)
        ax.plot(xy[0, 0], xy[0, 1], marker="s", color=_cable_color(i), markersize=4.5, alpha=alpha,
                zorder=zorder)
    corners = _platform_corners(scene, pose)
    ax.add_patch(Polygon(corners, closed=True, facecolor=(*to_rgb("0.75"), 0.9 * alpha),
                         edgecolor=(*to_rgb(_PLATFORM_COLOR), alpha), linewidth=1.2, zorder=zorder + 0.5))
    ax.plot(pose[0], pose[1], marker="o", color=_PLATFORM_COLOR, markersize=2.5, alpha=alpha,
            zorder=zorder + 0.6)


def _legend(ax, **kwargs) -> None:
    """A legend, if anything in ``ax`` has a label (an empty run has none)."""
    if ax.get_legend_handles_labels()[1]:
        ax.legend(**kwargs)


def _legend_below(ax) -> None:
    """A frameless legend in one line under the x label of ``ax``."""
    below = ScaledTranslation(0.0, -0.5, ax.figure.dpi_scale_trans)
    _legend(ax, fontsize=8, loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=ax.transAxes + below,
            ncol=4, frameon=False)


def _set_limits(ax, limits) -> None:
    ax.set_xlim(limits[0], limits[1])
    ax.set_ylim(limits[2], limits[3])
    ax.set_aspect("equal", adjustable="box")


def _no_data(ax, message: str) -> None:
    ax.text(0.5, 0.5, message, transform=ax.transAxes, ha="center", va="center",
            color="tab:red", fontsize=9, bbox=dict(facecolor="white", edgecolor="tab:red", alpha=0.9))


def _status_note(result: Result) -> str:
    """'' for a completed run, else a short note of where it stopped."""
    if result.status == "completed":
        rows = _valid_rows(result)
        if len(rows) == len(result.time):
            return ""
    last = _last_time(result)
    when = f"{last:.3g} s" if last is not None else "t = 0"
    cause = result.status if result.status != "completed" else "partial result"
    return f"{cause} (data up to {when})"


def _mark_end(ax, result: Result) -> None:
    """A vertical line at the last valid sample of a failed or partial run."""
    note = _status_note(result)
    last = _last_time(result)
    if note and last is not None:
        ax.axvline(last, color="tab:red", linewidth=0.8, linestyle=":")
        ax.text(last, 0.03, " run ends", transform=ax.get_xaxis_transform(), color="tab:red",
                fontsize=8, ha="left", va="bottom")


def _time_axis(ax, scene: Scene | None, result: Result) -> None:
    ax.set_xlabel("time t [s]")
    end = float(scene.solver.end_time) if scene is not None else None
    if end is None and len(result.time) and np.isfinite(result.time).any():
        end = float(np.nanmax(result.time))
    if end:
        ax.set_xlim(0.0, end)
    ax.grid(True, linewidth=0.4, alpha=0.6)


def _snapshot_axes(ax, scene: Scene, result: Result, rows: np.ndarray, t: float, limits) -> None:
    """One panel of Fig. 6: the robot at time ``t`` with the reference and the path so far."""
    _draw_pulleys(ax, scene)
    reference = _reference_path(scene, result)
    ax.plot(reference[:, 0], reference[:, 1], zorder=2, **_REFERENCE_STYLE)
    k = _nearest_row(result, rows, t)
    if k is None:
        last = _last_time(result)
        _no_data(ax, f"not reached\n(run ends at {last:.3g} s)" if last is not None else "no data")
        ax.set_title(f"t = {t:g} s", fontsize=10)
    else:
        so_far = rows[rows <= k]
        pose = np.asarray(result.pose, dtype=float)[so_far]
        ax.plot(pose[:, 0], pose[:, 1], color="black", linewidth=1.0, zorder=2.5)
        _draw_chords(ax, scene, result, k)
        _draw_robot(ax, scene, result, k)
        ax.set_title(f"t = {float(result.time[k]):.2f} s", fontsize=10)
    _set_limits(ax, limits)
    ax.grid(True, linewidth=0.4, alpha=0.5)


def _fading_snapshot_axes(ax, scene: Scene, result: Result, times: Sequence[float], limits) -> None:
    """The robot at several instants in one panel, earlier instants fainter."""
    rows = _valid_rows(result)
    _draw_pulleys(ax, scene)
    reference = _reference_path(scene, result)
    ax.plot(reference[:, 0], reference[:, 1], zorder=2, **_REFERENCE_STYLE)
    pose = np.asarray(result.pose, dtype=float)[rows]
    ax.plot(pose[:, 0], pose[:, 1], color="black", linewidth=1.0, zorder=2.5)
    samples = [k for k in (_nearest_row(result, rows, t) for t in times) if k is not None]
    samples = sorted(set(samples))
    for j, k in enumerate(samples):
        alpha = min(1.0, 0.2 + 0.8 * (j + 1) / len(samples))
        _draw_robot(ax, scene, result, k, alpha=alpha, markers=(j == len(samples) - 1), zorder=3 + j)
    if samples:
        shown = ", ".join(f"{float(result.time[k]):g}" for k in samples)
        ax.set_title(f"robot at t = {shown} s (later = darker)", fontsize=10)
    else:
        _no_data(ax, "no data")
    _set_limits(ax, limits)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.grid(True, linewidth=0.4, alpha=0.5)


def _path_axes(ax, scene: Scene | None, result: Result) -> None:
    """Fig. 7a: reference and actual path of the platform centre, equal aspect."""
    reference = _reference_path(scene, result)
    ax.plot(reference[:, 0], reference[:, 1], label="reference", **_REFERENCE_STYLE)
    rows = _valid_rows(result)
    pose = np.asarray(result.pose, dtype=float)[rows]
    if len(pose):
        ax.plot(pose[:, 0], pose[:, 1], color="tab:blue", linewidth=1.4, label="actual")
        ax.plot(pose[0, 0], pose[0, 1], "o", color="tab:green", markersize=5, label="start", zorder=4)
        ax.plot(pose[-1, 0], pose[-1, 1], "s", color="tab:blue" if not _status_note(result) else "tab:red",
                markersize=5, label="end" if not _status_note(result) else "run ends", zorder=4)
    else:
        _no_data(ax, "no data")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title("Path of the platform centre", fontsize=10)
    ax.grid(True, linewidth=0.4, alpha=0.6)
    _legend_below(ax)


def _rotation_axes(ax, scene: Scene | None, result: Result) -> None:
    """Fig. 7b: platform rotation over time [deg]."""
    rows = _valid_rows(result)
    time = np.asarray(result.time, dtype=float)
    ax.plot(time, np.degrees(np.asarray(result.reference, dtype=float)[:, 2]),
            label="reference", **_REFERENCE_STYLE)
    ax.plot(time[rows], np.degrees(np.asarray(result.pose, dtype=float)[rows, 2]),
            color="tab:blue", linewidth=1.4, label="actual")
    if len(rows) == 0:
        _no_data(ax, "no data")
    _time_axis(ax, scene, result)
    ax.set_ylabel("rotation φ [deg] (counter-clockwise +)")
    ax.set_title("Platform rotation", fontsize=10)
    _legend(ax, fontsize=8, loc="best")
    _mark_end(ax, result)


def _errors_axes(ax, scene: Scene | None, result: Result) -> None:
    """Fig. 7c: x and z position error over time [cm]."""
    rows = _valid_rows(result)
    time = np.asarray(result.time, dtype=float)[rows]
    error = 100.0 * (np.asarray(result.pose, dtype=float)[rows, :2]
                     - np.asarray(result.reference, dtype=float)[rows, :2])
    ax.axhline(0.0, color="0.3", linewidth=0.8)
    ax.plot(time, error[:, 0], color="tab:blue", linewidth=1.4, label="x error")
    ax.plot(time, error[:, 1], color="tab:red", linewidth=1.4, label="z error")
    if len(rows) == 0:
        _no_data(ax, "no data")
    _time_axis(ax, scene, result)
    ax.set_ylabel("error, actual − reference [cm]")
    ax.set_title("Position error of the platform centre", fontsize=10)
    _legend(ax, fontsize=8, loc="best")
    _mark_end(ax, result)


def plot_snapshots(scene: Scene, result: Result, path: str | Path,
                   times: Iterable[float] = (0, 2, 4, 6, 8, 10)) -> Path:
    """The robot at the instants ``times`` [s] (the nearest samples) in the x-z plane (paper Fig. 6), one
    panel each, with the reference (dashed) and the path so far (solid)."""
    times = [float(t) for t in times]
    rows = _valid_rows(result)
    limits = _robot_limits(scene, result, rows)
    n = max(1, len(times))
    columns = min(3, n)
    lines = int(np.ceil(n / columns))
    width_m, height_m = limits[1] - limits[0], limits[3] - limits[2]
    panel_width = 3.9
    panel_height = panel_width * height_m / width_m
    left, right, bottom, top, wspace, hspace = 0.65, 0.15, 0.8, 0.65, 0.12, 0.45
    figure = new_figure(left + right + columns * panel_width + (columns - 1) * wspace,
                        bottom + top + lines * panel_height + (lines - 1) * hspace,
                        left, right, bottom, top, wspace, hspace, columns, lines)
    axes = figure.subplots(lines, columns, squeeze=False, sharex=True, sharey=True)
    for j, ax in enumerate(axes.flat):
        if j >= len(times):
            ax.set_visible(False)
            continue
        _snapshot_axes(ax, scene, result, rows, times[j], limits)
        if j % columns == 0:
            ax.set_ylabel("z [m]")
        if j // columns == lines - 1 or j + columns >= len(times):
            ax.set_xlabel("x [m]")
            ax.xaxis.set_tick_params(labelbottom=True)
    handles = [Line2D([], [], color=_cable_color(i), marker="o", markersize=3, label=f"cable {i + 1}")
               for i in range(len(result.nodes))]
    handles += [Line2D([], [], label="reference", **_REFERENCE_STYLE),
                Line2D([], [], color="black", linewidth=1.0, label="platform path"),
                Line2D([], [], color="0.4", linestyle=":", label="straight chord of the free span")]
    figure.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False,
                  bbox_to_anchor=(0.5, 0.0))
    title = f"{scene.name}: robot at several instants ({result.controller})"
    note = _status_note(result)
    figure.suptitle(textwrap.fill(title + (f" — {note}" if note else ""), width=110), fontsize=11,
                    y=1.0 - 0.12 / figure.get_figheight(),
                    va="top")
    return save_figure(figure, path)


def _one_panel(draw, path: str | Path, scene: Scene | None, result: Result, *size, **margins) -> Path:
    figure = new_figure(*size, **margins)
    draw(figure.add_subplot(), scene, result)
    return save_figure(figure, path)


def plot_path(scene: Scene, result: Result, path: str | Path) -> Path:
    """Reference and actual path of the platform centre in the x-z plane (Fig. 7a)."""
    return _one_panel(_path_axes, path, scene, result, 5.5, 5.6, left=0.8, bottom=1.0)


def plot_rotation(result: Result, path: str | Path, scene: Scene | None = None) -> Path:
    """Platform rotation [deg] over time (Fig. 7b); over the ``scene``'s end time if given."""
    return _one_panel(_rotation_axes, path, scene, result, 6.0, 3.8)


def plot_errors(result: Result, path: str | Path, scene: Scene | None = None) -> Path:
    """x and z error of the platform centre [cm] over time (Fig. 7c)."""
    return _one_panel(_errors_axes, path, scene, result, 6.0, 3.8)


def plot_tensions(scene: Scene, result: Result, path: str | Path) -> Path:
    """Cable tensions [N] over time, one panel per cable: platform end, winch end, all elements' range."""
    m = len(result.tensions)
    lines = max(1, m)
    figure = new_figure(6.5, 0.95 + 2.3 * lines + 0.4 * (lines - 1), top=0.35, hspace=0.4, lines=lines)
    axes = figure.subplots(lines, 1, sharex=True, squeeze=False)[:, 0]
    rows = _valid_rows(result)
    time = np.asarray(result.time, dtype=float)[rows]
    for i, ax in enumerate(axes):
        if i >= m:
            break
        tension = np.asarray(result.tensions[i], dtype=float)[rows]
        color = _cable_color(i)
        if tension.size:
            with np.errstate(all="ignore"):
                low, high = np.nanmin(tension, axis=1), np.nanmax(tension, axis=1)
            ax.fill_between(time, low, high, color=color, alpha=0.15, linewidth=0, label="all elements")
            ax.plot(time, tension[:, -1], color=color, linewidth=1.4, label="platform end")
            ax.plot(time, tension[:, 0], color=color, linewidth=1.0, linestyle="--", label="winch end")
        else:
            _no_data(ax, "no data")
        ax.axhline(0.0, color="0.3", linewidth=0.8)
        _time_axis(ax, scene, result)
        ax.set_xlabel("")
        ax.set_ylabel("tension [N]")
        ax.set_title(f"Cable {i + 1}", fontsize=10)
        _legend(ax, fontsize=8, loc="upper right", ncol=3)
        _mark_end(ax, result)
    axes[-1].set_xlabel("time t [s]")
    return save_figure(figure, path)


def plot_overview(scene: Scene, result: Result, folder: str | Path, times: Iterable[float] | None = None,
                  after: float = 1.0) -> list[Path]:
    """The figures of one run into ``folder``, its space's (:data:`OVERVIEWS`); returns the files written."""
    return OVERVIEWS[result.space](scene, result, Path(folder), times, after)


def plot_planar_overview(scene: Scene, result: Result, folder: str | Path,
                         times: Iterable[float] | None = None, after: float = 1.0) -> list[Path]:  # noqa: ARG001
    """All figures of one planar run into ``folder`` (:data:`OVERVIEW_FILES`); snapshots at ``times`` [s]."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if times is None:
        times = np.linspace(0.0, float(scene.solver.end_time), 6)
    times = [round(float(t), 6) for t in times]
    paths = [
        plot_snapshots(scene, result, folder / OVERVIEW_FILES["snapshots"], times=times),
        plot_path(scene, result, folder / OVERVIEW_FILES["path"]),
        plot_rotation(result, folder / OVERVIEW_FILES["rotation"], scene=scene),
        plot_errors(result, folder / OVERVIEW_FILES["errors"], scene=scene),
        plot_tensions(scene, result, folder / OVERVIEW_FILES["tensions"]),
    ]
    figure = new_figure(11.0, 9.0, left=0.8, right=0.25, bottom=0.6, top=0.65, wspace=0.95, hspace=1.15,
                        columns=2, lines=2)
    axes = figure.subplots(2, 2)
    _path_axes(axes[0, 0], scene, result)
    _rotation_axes(axes[0, 1], scene, result)
    _errors_axes(axes[1, 1], scene, result)
    rows = _valid_rows(result)
    _fading_snapshot_axes(axes[1, 0], scene, result, times, _robot_limits(scene, result, rows))
    note = _status_note(result)
    title = f"{scene.name} ({result.controller})" + (f" — {note}" if note else "")
    figure.suptitle(textwrap.fill(title, width=int(11.0 * 72 / 12 * 1.6)), fontsize=12,
                    y=1.0 - 0.12 / figure.get_figheight(), va="top")
    paths.append(save_figure(figure, folder / OVERVIEW_FILES["overview"]))
    return paths


def plot_comparison(scene: Scene, results: Mapping[str, Result], folder: str | Path) -> list[Path]:
    """Compare runs of one scene by label, one colour each: ``comparison_paths.png`` (the paths against the
    reference) and ``comparison_errors.png`` (position error norm [cm] over time)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    colors = [f"C{j % 10}" for j in range(len(results))]

    figure = new_figure(5.5, 5.6, left=0.8, bottom=1.0 + 0.2 * ((len(results) + 1) // 4))
    ax = figure.add_subplot()
    reference = _reference_path(scene, None)
    ax.plot(reference[:, 0], reference[:, 1], label="reference", **_REFERENCE_STYLE)
    for color, (label, result) in zip(colors, results.items()):
        rows = _valid_rows(result)
        pose = np.asarray(result.pose, dtype=float)[rows]
        note = " (failed)" if _status_note(result) else ""
        ax.plot(pose[:, 0], pose[:, 1], color=color, linewidth=1.3, label=label + note)
        if note and len(pose):
            ax.plot(pose[-1, 0], pose[-1, 1], "x", color=color, markersize=7, markeredgewidth=2)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(f"{scene.name}: path of the platform centre", fontsize=10)
    ax.grid(True, linewidth=0.4, alpha=0.6)
    _legend_below(ax)
    paths = [save_figure(figure, folder / "comparison_paths.png")]

    figure = new_figure(6.5, 3.8)
    ax = figure.add_subplot()
    for color, (label, result) in zip(colors, results.items()):
        rows = _valid_rows(result)
        error = (np.asarray(result.pose, dtype=float)[rows, :2]
                 - np.asarray(result.reference, dtype=float)[rows, :2])
        norm = 100.0 * np.linalg.norm(error, axis=1)
        ax.plot(np.asarray(result.time, dtype=float)[rows], norm, color=color, linewidth=1.3, label=label)
        if _status_note(result) and len(rows):
            ax.plot(result.time[rows[-1]], norm[-1], "x", color=color, markersize=7, markeredgewidth=2)
    ax.set_xlim(0.0, float(scene.solver.end_time))
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("position error |actual − reference| [cm]")
    ax.set_title(f"{scene.name}: position error of the platform centre", fontsize=10)
    ax.grid(True, linewidth=0.4, alpha=0.6)
    _legend(ax, fontsize=8, loc="best")
    paths.append(save_figure(figure, folder / "comparison_errors.png"))
    return paths


def plot_rest(rest: Rest, path: str | Path) -> Path:
    """Figure of a scene at rest, its space's (:data:`REST_FIGURES`); writes a PNG and returns its path."""
    return REST_FIGURES[rest.space](rest, path)


def _planar_rest(rest: Rest, path: str | Path) -> Path:
    """The rest profile: nodes, pulleys, leave points and the platform."""
    scene = rest.scene
    figure = Figure(figsize=(7.0, 5.0))
    FigureCanvasAgg(figure)
    ax = figure.add_subplot(1, 1, 1)
    colors = ("tab:blue", "tab:red", "tab:green", "tab:purple")
    for pulley in scene.exits:
        if pulley.wraps:
            ax.add_patch(Circle(pulley.point, pulley.radius, facecolor="0.92", edgecolor="0.55", zorder=1))
        ax.plot(*pulley.point, marker="+", color="0.55", zorder=1)
    for i, nodes in enumerate(rest.nodes):
        color = colors[i % len(colors)]
        ax.plot(nodes[:, 0], nodes[:, 1], "-o", color=color, markersize=3, linewidth=1.0, zorder=3,
                label=f"cable {i + 1}: free span {rest.cable_stretched_length_m[i]:.4f} m, "
                      f"upper force |F| = {np.hypot(*rest.upper_forces_N[i]):.2f} N")
        ax.plot(*rest.upper_points_m[i], marker="x", color=color, markersize=8, zorder=4)
    x, z = rest.position
    ax.plot(x, z, marker="s", color="0.2", markersize=7, zorder=5,
            label=f"platform ({x:.4f}, {z:.4f}) m, {float(np.degrees(rest.rotation)):.2f} deg")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.grid(True, linewidth=0.4, alpha=0.5)
    ax.legend(loc="upper center", fontsize=7, framealpha=0.9)
    ax.set_title(f"{scene.name} at rest ({rest.method}; x: leave points)", fontsize=9)
    return save_figure(figure, path)


#: Points per catenary curve in a spatial rest's figure.
CURVE_SAMPLES = 60


def _spatial_rest(rest: Rest, path: str | Path) -> Path:
    """Figure of the robot at rest, in 3-D and from above: lumped cables (dots), catenaries (dashed), platform."""
    figure = Figure(figsize=(11.0, 5.2))
    FigureCanvasAgg(figure)
    ax = figure.add_subplot(1, 2, 1, projection="3d")
    top = figure.add_subplot(1, 2, 2)
    figure.subplots_adjust(wspace=0.35)
    colors = ("tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:pink", "tab:olive")
    anchors = rest.position + np.asarray(rest.scene.platform.anchors) @ rest.rotation_matrix.T
    outline = np.vstack([anchors, anchors[:1]])
    exits = rest.scene.exit_points
    for i, (nodes, cable) in enumerate(zip(rest.nodes, rest.catenary.cables)):
        color = colors[i % len(colors)]
        curve = cable.points(np.linspace(0.0, cable.unstrained_length, CURVE_SAMPLES))
        label = f"cable {i + 1}: {rest.anchor_tensions[i]:.1f} N at the anchor"
        ax.plot(nodes[:, 0], nodes[:, 1], nodes[:, 2], "o-", color=color, markersize=2, linewidth=1.0, label=label)
        ax.plot(curve[:, 0], curve[:, 1], curve[:, 2], "--", color="0.3", linewidth=0.7)
        top.plot(nodes[:, 0], nodes[:, 1], "o-", color=color, markersize=2, linewidth=1.0)
        top.annotate(f"{i + 1}", exits[i, :2], textcoords="offset points", xytext=(4, 4), fontsize=8, color=color)
    for axes, coordinates in ((ax, (outline[:, 0], outline[:, 1], outline[:, 2])), (top, (outline[:, 0], outline[:, 1]))):
        axes.plot(*coordinates, "k-", linewidth=1.5)
    ax.plot(*rest.position, "ks", markersize=4)
    ax.plot(exits[:, 0], exits[:, 1], exits[:, 2], "k^", markersize=5)
    top.plot(exits[:, 0], exits[:, 1], "k^", markersize=5)
    top.plot(*rest.position[:2], "ks", markersize=4)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    top.set_xlabel("x [m]")
    top.set_ylabel("y [m]")
    top.set_aspect("equal")
    top.grid(True, linewidth=0.3)
    top.set_title("from above (exits: triangles)", fontsize=9)
    x, y, z = rest.position
    roll, pitch, yaw = rotation_angles_deg(rest.rotation_matrix)
    figure.suptitle(f"{rest.scene.name} at rest: platform at ({x:.4f}, {y:.4f}, {z:.4f}) m, roll {roll:.2f}, "
                    f"pitch {pitch:.2f}, yaw {yaw:.2f} deg\nlumped cables (dots) and elastic catenaries (dashed)",
                    fontsize=9)
    ax.legend(fontsize=7, loc="upper left")
    span = np.vstack([exits, *rest.nodes])
    centre, half = span.mean(axis=0), 0.55 * np.ptp(span, axis=0).max()
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    path = Path(path)
    figure.savefig(path, dpi=110, format="png")
    return path


def plot_spatial_run(result: Result, path: str | Path, after: float = 1.0) -> Path:
    """A spatial run's overview: its path from above and from the side, position error and lowest tensions."""
    figure = Figure(figsize=(11.0, 8.0))
    FigureCanvasAgg(figure)
    axes = figure.subplots(2, 2)
    top, side, error, tension = axes[0, 0], axes[0, 1], axes[1, 0], axes[1, 1]
    for ax, (a, b), names in ((top, (0, 1), ("x [m]", "y [m]")), (side, (0, 2), ("x [m]", "z [m]"))):
        ax.plot(result.reference[:, a], result.reference[:, b], "k--", linewidth=1.0, label="reference")
        ax.plot(result.pose[:, a], result.pose[:, b], "tab:blue", linewidth=1.2, label="platform")
        ax.set_xlabel(names[0])
        ax.set_ylabel(names[1])
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, linewidth=0.3)
        ax.legend(fontsize=8)
    top.set_title("path from above", fontsize=9)
    side.set_title("path from the side", fontsize=9)
    for k, name in enumerate("xyz"):
        error.plot(result.time, 1000.0 * result.position_error[:, k], label=f"error {name}")
    error.axvline(after, color="0.6", linewidth=0.8, linestyle=":")
    for i, series in enumerate(result.tensions):
        tension.plot(result.time, series.min(axis=1), label=f"cable {i + 1}")
    tension.axhline(0.0, color="k", linewidth=0.8)
    for ax, label, legend in ((error, "actual - reference [mm]", {"fontsize": 8}),
                              (tension, "lowest element tension [N]", {"fontsize": 7, "ncol": 2})):
        ax.set_xlabel("t [s]")
        ax.set_ylabel(label)
        ax.grid(True, linewidth=0.3)
        ax.legend(**legend)
    summary = result.summary(after)
    worst = summary["max_position_error_m"]
    figure.suptitle(f"{result.scene_name} under {result.controller}: max position error after {after:g} s "
                    f"{'n/a' if worst is None else f'{1000 * worst:.2f} mm'} ({result.status})", fontsize=10)
    figure.tight_layout()
    path = Path(path)
    figure.savefig(path, dpi=100, format="png")
    return path


def _spatial_overview(scene: Scene, result: Result, folder: Path, times, after: float) -> list[Path]:  # noqa: ARG001
    folder.mkdir(parents=True, exist_ok=True)
    return [plot_spatial_run(result, folder / OVERVIEW_FILES["overview"], after)]


#: The overview figures of a run, by its space (:func:`plot_overview`).
OVERVIEWS = {PLANE: plot_planar_overview, SPACE: _spatial_overview}
#: The figure of a rest, by its space (:func:`plot_rest`).
REST_FIGURES = {PLANE: _planar_rest, SPACE: _spatial_rest}
