"""Figures of the studies: a parameter sweep's (:func:`plot_study`), a robustness study's heat maps
(:func:`plot_robustness`) and the accuracy study's Pareto plot (:func:`plot_pareto`), from their rows
(plain data) or the :class:`~cdpr_exu.studies.accuracy.AccuracyStudy`; each writes PNGs and returns
their paths.
"""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Mapping, Sequence

import matplotlib
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.ticker import NullFormatter

from cdpr_exu.core.output import finite_number, value_text
from cdpr_exu.post.plots import DPI, new_figure, save_figure


def _file_stem(path: str) -> str:
    return re.sub(r"[^A-Za-z0-9_]+", "_", path).strip("_")


def _is_numeric(values: Sequence[Any]) -> bool:
    return all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values)


def plot_study(rows: Sequence[Mapping[str, Any]], variations: Sequence[Any], out: str | Path,
               mode: str = "grid") -> dict[str, Path]:
    """Summary figures of a study (``rows`` and ``variations`` of :func:`~cdpr_exu.studies.study.run_study`),
    by name: for each varied parameter ``vs_<path>.png``, the max position error and the Newton
    iterations (a cost the same from run to run) against it, one line per combination of the others;
    ``heatmap.png`` for a 2-parameter grid. Failed and refused runs: red crosses at the foot of the axes.
    """
    out = Path(out)
    written: dict[str, Path] = {}
    for variation in variations:
        others = [v for v in variations if v.path != variation.path] if mode == "grid" else []
        figure = new_figure(10.0, 4.0, left=0.9, right=0.25, bottom=0.8, top=0.5, wspace=0.9, columns=2)
        axes = figure.subplots(1, 2)
        numeric = _is_numeric(variation.values)
        position = {v: (v if numeric else i) for i, v in enumerate(variation.values)}
        groups: dict[tuple, list[Mapping[str, Any]]] = {}
        for row in rows:
            groups.setdefault(tuple(row[o.path] for o in others), []).append(row)
        for quantity, axis, scale, label in (("max_position_error_m", axes[0], 1000.0, "max position error [mm]"),
                                             ("newton_iterations", axes[1], 1.0, "Newton iterations")):
            failed_label = "failed / refused"
            for key, members in groups.items():
                members = sorted(members, key=lambda r: position[r[variation.path]])
                name = ", ".join(f"{o.path} = {value_text(v)}" for o, v in zip(others, key)) or None
                ok = [r for r in members if r["status"] == "completed" and finite_number(r.get(quantity))]
                bad = [r for r in members if r["status"] != "completed"]
                if ok:
                    axis.plot([position[r[variation.path]] for r in ok], [scale * r[quantity] for r in ok],
                              marker="o", label=name)
                elif name:
                    failed_label = None
                if bad:  # at the foot of the axes: their figures are partial or missing
                    label_bad = failed_label if ok or not name else f"{name}: failed / refused"
                    axis.plot([position[r[variation.path]] for r in bad], [0.03] * len(bad), linestyle="none",
                              marker="x", color="tab:red", markersize=9, markeredgewidth=2,
                              transform=axis.get_xaxis_transform(), label=label_bad, clip_on=False)
                    if ok or not name:
                        failed_label = None
            axis.set_xlabel(variation.path)
            axis.set_ylabel(label)
            axis.grid(True, alpha=0.3)
            if not numeric:
                axis.set_xticks(range(len(variation.values)), [value_text(v) for v in variation.values])
            if others or failed_label is None:
                axis.legend(fontsize=7)
        after = next((r["errors_measured_after_s"] for r in rows if finite_number(r.get("errors_measured_after_s"))), None)
        figure.suptitle(f"study over {variation.path}" + (f" (errors after {after:g} s)" if finite_number(after) else ""),
                        fontsize=10)
        path = out / f"vs_{_file_stem(variation.path)}.png"
        figure.savefig(path, dpi=DPI, format="png")
        written[f"vs_{variation.path}"] = path
    if mode == "grid" and len(variations) == 2:
        written["heatmap"] = _plot_heatmap(rows, variations, out / "heatmap.png")
    return written


#: What :func:`_plot_heatmap` shows by default: (row key, scale, label) per panel.
HEATMAP_QUANTITIES = (("max_position_error_m", 1000.0, "max position error [mm]"),
                      ("newton_iterations", 1.0, "Newton iterations"))


def _plot_heatmap(rows: Sequence[Mapping[str, Any]], variations: Sequence[Any], path: Path,
                  quantities=HEATMAP_QUANTITIES, title: str = "study grid") -> Path:
    """``quantities`` (two panels) over a 2-parameter grid, failed cells marked."""
    first, second = variations
    figure = new_figure(11.0, 4.5, left=1.0, right=0.3, bottom=0.8, top=0.5, wspace=1.6, columns=2)
    axes = figure.subplots(1, 2)
    index = {(row[first.path], row[second.path]): row for row in rows}
    for axis, (quantity, scale, label) in zip(axes, quantities):
        grid = np.full((len(first.values), len(second.values)), np.nan)
        for i, a in enumerate(first.values):
            for j, b in enumerate(second.values):
                row = index.get((a, b))
                if row is not None and row["status"] == "completed" and finite_number(row.get(quantity)):
                    grid[i, j] = scale * row[quantity]
        colormap = matplotlib.colormaps["viridis"].with_extremes(bad="0.85")
        image = axis.imshow(grid, origin="lower", aspect="auto", cmap=colormap)
        figure.colorbar(image, ax=axis, label=label)
        finite = grid[np.isfinite(grid)]
        middle = 0.5 * (finite.min() + finite.max()) if finite.size else 0.0
        for i, a in enumerate(first.values):
            for j, b in enumerate(second.values):
                row = index.get((a, b))
                if row is None:
                    continue
                if row["status"] != "completed":
                    text, color = row["status"].split(":")[0], "tab:red"
                else:
                    text, color = f"{grid[i, j]:.3g}", ("black" if grid[i, j] > middle else "white")
                axis.text(j, i, text, ha="center", va="center", fontsize=8, color=color)
        axis.set_xticks(range(len(second.values)), [value_text(v) for v in second.values])
        axis.set_yticks(range(len(first.values)), [value_text(v) for v in first.values])
        axis.set_xlabel(second.path)
        axis.set_ylabel(first.path)
    figure.suptitle(f"{title} (grey, red text: failed or refused run)", fontsize=10)
    figure.savefig(path, dpi=DPI, format="png")
    return path


def plot_robustness(rows: Sequence[Mapping[str, Any]], out: str | Path) -> dict[str, Path]:
    """``robustness_<controller>.png`` by name: a robustness study's max position error (and its ratio to
    ideal IK's) over the platform mass and cable density errors, at the nominal stiffness and exits."""
    axes = [SimpleNamespace(path=name, values=tuple(sorted({row[name] for row in rows})))  # as a study's Variation
            for name in ("platform_mass", "cable_density")]
    quantities = (("max_position_error_m", 1000.0, "max position error [mm]"),
                  ("max_error_vs_ideal_ik", 1.0, "ideal IK's max error / this one's"))
    written = {}
    for name in dict.fromkeys(row["controller"] for row in rows):
        mine = [row for row in rows if row["controller"] == name
                and not (row.get("cable_stiffness") or row.get("exit_offset"))]
        written[f"robustness_{name}"] = _plot_heatmap(mine, axes, Path(out) / f"robustness_{name}.png", quantities,
                                                      f"{name} on plants off its model")
    return written


#: Colours of the ladder's models; other models take the spare colours in turn.
_MODEL_COLORS = {"ideal": "tab:gray", "elastic": "tab:green", "catenary": "tab:orange", "full": "tab:blue",
                 "full, linear bending": "tab:purple"}  # model_name("full", LINEAR_BENDING) of the accuracy study
_SPARE_COLORS = ("tab:red", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")
_STEP_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*")


def plot_pareto(study, path: str | Path) -> Path:
    """An AccuracyStudy's position and tension errors against CPU time, log-log: a marker per run (colour:
    model, shape: step size), the Pareto front drawn."""
    rows = study.rows
    models = list(dict.fromkeys(r["model"] for r in rows))
    spare = [m for m in models if m not in _MODEL_COLORS]
    colors = {m: _MODEL_COLORS.get(m) or _SPARE_COLORS[spare.index(m) % len(_SPARE_COLORS)] for m in models}
    steps = sorted({r["step_size_s"] for r in rows})
    markers = {h: _STEP_MARKERS[i % len(_STEP_MARKERS)] for i, h in enumerate(steps)}
    figure = new_figure(12.0, 5.2, left=0.8, right=0.2, bottom=1.3, top=0.55, wspace=0.85, columns=2)
    axes = figure.subplots(1, 2)
    quantities = (("position_error_max_m", 1000.0, "max platform position error [mm]" if study.comparison == "path"
                   else "final platform position error [mm]"),
                  ("tension_error_rms_N", 1.0, "RMS error of platform-end tensions [N]" if study.comparison == "path"
                   else "final platform-end tension error [N]"))
    for axis, (quantity, scale, label) in zip(axes, quantities):
        for r in study.compared(quantity):
            if r[quantity] <= 0:
                continue
            axis.plot(r[study.COST], scale * r[quantity], linestyle="none", marker=markers[r["step_size_s"]],
                      color=colors[r["model"]], markersize=6, alpha=0.8, markeredgecolor="black", markeredgewidth=0.4)
        front = [r for r in study.front(quantity) if r[quantity] > 0]
        if front:
            x = [r[study.COST] for r in front]
            y = [scale * r[quantity] for r in front]
            axis.step(x, y, where="post", color="black", linewidth=1.0, alpha=0.7, zorder=0)
            for r, xi, yi in zip(front, x, y):
                axis.annotate(_short_label(r), (xi, yi), fontsize=6, xytext=(3, 3), textcoords="offset points",
                              color="0.25")
        if quantity == "position_error_max_m":
            for tolerance in study.TOLERANCES:
                axis.axhline(1000 * tolerance, color="0.5", linestyle=":", linewidth=0.8)
                axis.annotate(f"{1000 * tolerance:g} mm", (1.0, 1000 * tolerance), xycoords=("axes fraction", "data"),
                              fontsize=7, color="0.4", ha="right", va="bottom")
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.xaxis.set_minor_formatter(NullFormatter())
        axis.yaxis.set_minor_formatter(NullFormatter())
        axis.set_xlabel("CPU time of the run [s] (one core)")
        axis.set_ylabel(label)
        axis.grid(True, which="both", alpha=0.25)
    done = sum(r["status"] == "completed" for r in rows) - 1
    failed = sum(r["status"].startswith("failed") for r in rows)
    refused = sum(r["status"].startswith("refused") for r in rows)
    ref = study.reference_row
    figure.suptitle(f"{study.scene_name}, {study.end_time:g} s: error against the reference ({study.reference.label}, "
                    f"{ref[study.COST]:.0f} s) vs CPU time; {done} runs compared, {failed} failed, "
                    f"{refused} refused (see accuracy.csv); black: Pareto front", fontsize=9)
    handles = [Line2D([], [], linestyle="none", marker="o", color=colors[m], label=m) for m in models]
    handles += [Line2D([], [], linestyle="none", marker=markers[h], color="black", markerfacecolor="none",
                       label=f"h = {h:g} s") for h in steps]
    figure.legend(handles=handles, loc="lower center", ncol=min(len(handles), 6), fontsize=8, frameon=False)
    return save_figure(figure, path)


def _short_label(row: Mapping[str, Any]) -> str:
    """``full 20, 5e-03`` (model, elements, step) for annotations."""
    n = "" if row.get("n_elements") is None else f" {row['n_elements']}"
    return f"{row['model']}{n}, {row['step_size_s']:.0e}"
