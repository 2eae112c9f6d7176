"""A headless 3-D animation of a spatial run: the cables, the platform and its path, as a GIF.

Reads the run folder that ``cdpr run SPATIAL-SCENE --out DIR`` writes (``result.npz``:
time, pose, reference and the cables' nodes) and draws each frame with matplotlib's 3-D
axes (no display, no Exudyn renderer), then writes an animated GIF with Pillow (which
matplotlib brings). ``cdpr animate DIR`` calls it for a spatial run folder. Units SI.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from cdpr_exu.core.errors import OutputError

__all__ = ["is_spatial_run", "render_spatial_animation"]


def is_spatial_run(run_dir: str | Path) -> bool:
    """True for a folder written by a spatial ``cdpr run`` (a result.npz with 6-DOF poses)."""
    path = Path(run_dir) / "result.npz"
    if not path.is_file():
        return False
    with np.load(path) as data:
        return "pose" in data.files and data["pose"].ndim == 2 and data["pose"].shape[1] == 6


def render_spatial_animation(run_dir: str | Path, out: str | Path | None = None, fps: float = 25.0,
                             every: int | None = None, size: tuple[int, int] = (640, 480)) -> tuple[Path, int]:
    """Render the spatial run in ``run_dir`` to a GIF; returns (the file, the number of frames).

    ``every`` takes every K-th stored row (default: real-time playback at ``fps``).

    Raises
    ------
    OutputError
        If the folder holds no spatial run, or the output is not a .gif file.
    """
    run_dir = Path(run_dir)
    if not is_spatial_run(run_dir):
        raise OutputError(f"{run_dir} holds no spatial run (result.npz with 6-DOF poses); "
                          "write one with `cdpr run SPATIAL-SCENE --out DIR`")
    out = Path(out) if out is not None else run_dir / "animation.gif"
    if out.suffix.lower() != ".gif":
        raise OutputError(f"--out {out}: a spatial run is animated as a .gif")
    with np.load(run_dir / "result.npz") as data:
        time, pose, reference = data["time"], data["pose"], data["reference"]
        cables = sorted((k for k in data.files if k.startswith("nodes_")), key=lambda k: int(k.split("_")[1]))
        nodes = [data[k] for k in cables]
    if every is None:
        period = float(np.median(np.diff(time))) if len(time) > 1 else 1.0
        every = max(1, int(round(1.0 / (fps * period))))
    rows = np.arange(0, len(time), every)
    summary = run_dir / "summary.json"
    name = json.loads(summary.read_text()).get("scene", run_dir.name) if summary.is_file() else run_dir.name
    figure = Figure(figsize=(size[0] / 100.0, size[1] / 100.0), dpi=100)
    FigureCanvasAgg(figure)
    ax = figure.add_subplot(1, 1, 1, projection="3d")
    span = np.vstack([n.reshape(-1, 3) for n in nodes])
    low, high = span.min(axis=0), span.max(axis=0)
    centre, half = (low + high) / 2.0, 0.55 * float((high - low).max())
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.plot(reference[:, 0], reference[:, 1], reference[:, 2], "k--", linewidth=0.8)
    lines = [ax.plot([], [], [], "-", linewidth=1.0)[0] for _ in nodes]
    trace, = ax.plot([], [], [], "tab:blue", linewidth=1.2)
    platform, = ax.plot([], [], [], "ks", markersize=4)
    title = ax.set_title("", fontsize=9)

    def draw(k):
        for line, cable in zip(lines, nodes):
            line.set_data_3d(cable[k, :, 0], cable[k, :, 1], cable[k, :, 2])
        trace.set_data_3d(pose[:k + 1, 0], pose[:k + 1, 1], pose[:k + 1, 2])
        platform.set_data_3d([pose[k, 0]], [pose[k, 1]], [pose[k, 2]])
        error = 1000.0 * float(np.linalg.norm(pose[k, :3] - reference[k, :3]))
        title.set_text(f"{name}: t = {time[k]:.2f} s, position error {error:.2f} mm")
        return [*lines, trace, platform, title]

    animation = FuncAnimation(figure, draw, frames=rows, blit=False)
    out.parent.mkdir(parents=True, exist_ok=True)
    animation.save(out, writer=PillowWriter(fps=fps))
    return out, len(rows)
