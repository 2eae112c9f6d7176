"""A headless 3-D animation of a spatial run: the cables, the platform and its path.

Reads the run folder that ``cdpr run SPATIAL-SCENE --out DIR`` writes (``result.npz``:
time, pose, reference and the cables' nodes) and draws each frame with matplotlib's 3-D
axes (no display, no Exudyn renderer). ``cdpr animate DIR`` renders it through
:func:`cdpr_exu.post.viewer.render_animation` (or
:func:`cdpr_exu.post.viewer.render_spatial_animation`), as planar runs: the same option checks,
``--frames-dir`` and GIF or MP4 writer. Units SI.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from cdpr_exu.core.errors import OutputError
from cdpr_exu.results.result import Result
from cdpr_exu.space import SPACE, Space

__all__ = ["run_space", "SpatialFrames"]


def run_space(run_dir: str | Path) -> Space | None:
    """The :class:`~cdpr_exu.space.Space` of the run a ``cdpr run`` folder holds (its result.npz's
    :class:`Result`), or None for a folder without one."""
    path = Path(run_dir) / "result.npz"
    return Result.load(path).space if path.is_file() else None


class SpatialFrames:
    """The frames of a spatial run folder, each a PIL RGB image of ``size`` pixels.

    Attributes
    ----------
    name : str
        The scene's name (from summary.json), else the folder's.
    times : ndarray, shape (N,) [s]
        Time of each stored sample; :meth:`frame` takes its index.

    Raises
    ------
    OutputError
        If the folder holds no spatial run.
    """

    def __init__(self, run_dir: str | Path, size: tuple[int, int]):
        run_dir = Path(run_dir)
        if run_space(run_dir) is not SPACE:
            raise OutputError(f"{run_dir} holds no spatial run (result.npz with 6-DOF poses); "
                              "write one with `cdpr run SPATIAL-SCENE --out DIR`")
        result = Result.load(run_dir)
        self.times, self.pose, self.reference, self.nodes = result.time, result.pose, result.reference, result.nodes
        summary = run_dir / "summary.json"
        self.name = json.loads(summary.read_text()).get("scene", run_dir.name) if summary.is_file() else run_dir.name
        self.size = (int(size[0]), int(size[1]))
        self.figure = figure = Figure(figsize=(self.size[0] / 100.0, self.size[1] / 100.0), dpi=100)
        self.canvas = FigureCanvasAgg(figure)
        ax = figure.add_subplot(1, 1, 1, projection="3d")
        span = np.vstack([n.reshape(-1, 3) for n in self.nodes])
        low, high = span.min(axis=0), span.max(axis=0)
        centre, half = (low + high) / 2.0, 0.55 * float((high - low).max())
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        ax.plot(self.reference[:, 0], self.reference[:, 1], self.reference[:, 2], "k--", linewidth=0.8)
        self.lines = [ax.plot([], [], [], "-", linewidth=1.0)[0] for _ in self.nodes]
        self.trace, = ax.plot([], [], [], "tab:blue", linewidth=1.2)
        self.platform, = ax.plot([], [], [], "ks", markersize=4)
        self.title = ax.set_title("", fontsize=9)

    def frame(self, k: int):
        """Sample ``k`` drawn as a PIL RGB image."""
        from PIL import Image

        pose = self.pose
        for line, cable in zip(self.lines, self.nodes):
            line.set_data_3d(cable[k, :, 0], cable[k, :, 1], cable[k, :, 2])
        self.trace.set_data_3d(pose[:k + 1, 0], pose[:k + 1, 1], pose[:k + 1, 2])
        self.platform.set_data_3d([pose[k, 0]], [pose[k, 1]], [pose[k, 2]])
        error = 1000.0 * float(np.linalg.norm(pose[k, :3] - self.reference[k, :3]))
        self.title.set_text(f"{self.name}: t = {self.times[k]:.2f} s, position error {error:.2f} mm")
        self.canvas.draw()
        image = Image.fromarray(np.asarray(self.canvas.buffer_rgba())[:, :, :3].copy())
        return image if image.size == self.size else image.resize(self.size)
