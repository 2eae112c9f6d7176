"""Figures of a workspace grid (:mod:`cdpr_exu.studies.workspace_grid`): the positions each model holds.

``slices.png``: the massless and the catenary model side by side, the positions each holds in a slice of
the grid (its first two varied axes; with a third, up to :data:`MAX_SLICES` slices along it), the massless
model's boundary dashed on both. ``view3d.png`` (three varied axes): both models' held positions in 3-D.
"""

from __future__ import annotations

import itertools
import warnings
from pathlib import Path
from typing import Sequence

import numpy as np
from matplotlib.colors import ListedColormap

from cdpr_exu.post.plots import new_figure, save_figure

#: Most slices along the third varied axis in ``slices.png``.
MAX_SLICES = 4
#: Each model's colour.
COLORS = {"massless": "tab:blue", "catenary": "tab:orange"}


def plot_workspace(labels: Sequence[str], values: Sequence[Sequence[float]], held: dict, out, name: str) -> dict:
    """Draw ``slices.png`` (and ``view3d.png``) into ``out``; returns their paths by name (none for a grid
    with fewer than two varied axes).

    ``labels`` and ``values``: each position axis's name and values [m]; ``held``: per model, whether each
    position (every combination of the values, the last axis fastest) is held.
    """
    out, shape = Path(out), tuple(len(v) for v in values)
    varied = [i for i, v in enumerate(values) if len(v) > 1]
    if len(varied) < 2:
        return {}
    grids = {model: np.asarray(flags, dtype=float).reshape(shape) for model, flags in held.items()}
    first, second, third = (varied + [None])[:3]
    levels = [None] if third is None else sorted({round(k) for k in np.linspace(0, shape[third] - 1, MAX_SLICES)})
    figure = new_figure(10.0, 0.9 + 3.6 * len(levels), columns=2, lines=len(levels), wspace=0.8, hspace=0.7, top=0.9)
    figure.suptitle(f"{name}: positions held within the tension limits (dashed: the massless model's boundary)")
    for line, level in zip(figure.subplots(len(levels), 2, squeeze=False), levels):
        index = [0] * len(shape)
        index[first] = index[second] = slice(None)
        if third is not None:
            index[third] = level
        for axis, model in zip(line, COLORS):
            axis.pcolormesh(values[first], values[second], grids[model][tuple(index)].T, shading="nearest",
                            cmap=ListedColormap(["0.93", COLORS[model]]), vmin=0.0, vmax=1.0)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # no boundary in a slice held (or not) everywhere
                axis.contour(values[first], values[second], grids["massless"][tuple(index)].T, levels=[0.5],
                             colors="k", linestyles="--", linewidths=1.0)
            where = "" if third is None else f", {labels[third]} = {values[third][level]:.3g} m"
            axis.set(title=f"{model}{where}", xlabel=f"{labels[first]} [m]", ylabel=f"{labels[second]} [m]",
                     aspect="equal")
    paths = {"slices": save_figure(figure, out / "slices.png")}
    if third is not None:
        figure = new_figure(11.0, 5.0, columns=2, wspace=0.5, left=0.3, bottom=0.3)
        points = np.array(list(itertools.product(*values)))[:, varied[:3]]
        for k, model in enumerate(COLORS):
            axis = figure.add_subplot(1, 2, k + 1, projection="3d")
            chosen = np.asarray(held[model], dtype=bool)
            axis.scatter(*points[chosen].T, s=3, color=COLORS[model], alpha=0.4)
            axis.set(title=f"{model}: {int(chosen.sum())} positions held", xlabel=f"{labels[first]} [m]",
                     ylabel=f"{labels[second]} [m]", zlabel=f"{labels[third]} [m]")
            axis.set_box_aspect(np.ptp(points, axis=0) + 1e-9)
        paths["view3d"] = save_figure(figure, out / "view3d.png")
    return paths
