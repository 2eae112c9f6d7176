"""Replay a finished run: Exudyn's SolutionViewer, or a headless GIF/MP4 animation.

A run folder of ``cdpr run SCENE --out DIR`` holds ``scene.toml`` and ``solution.sol`` (Exudyn's
binary solution file). The scene rebuilds the identical Exudyn system
(:func:`cdpr_exu.builder.model.build_model`), each row of the solution file is loaded into it
(:func:`exudyn.utilities.SetSolutionState`) and drawn: interactively (:func:`view_solution`, ``cdpr view``,
which needs a display) or by Exudyn's software raytracer into a GIF or MP4 (:func:`render_animation`,
``cdpr animate``; a spatial run is drawn from its ``result.npz`` with matplotlib's 3-D axes).

Planar replays get drawing-only items (:func:`decorate_model`: pulleys, platform rectangle, reference
path): ground and body graphics only, so the columns of the solution file are unchanged (checked on
every load). Exudyn's x-y plane is the paper's x-z plane.
"""

from __future__ import annotations

import json
import os
import sys
import time as _time
from dataclasses import dataclass
from pathlib import Path

import exudyn as exu
import exudyn.graphics as graphics
import numpy as np
from exudyn.rigidBodyUtilities import RotationMatrixX, RotationMatrixZ
from exudyn.utilities import LoadSolutionFile, SetSolutionState

from cdpr_exu.builder.robot_3d import Model3D, platform_pose
from cdpr_exu.builder.model import Model, build_model
from cdpr_exu.core.errors import CdprError
from cdpr_exu.core.geometry import rotation_vector
from cdpr_exu.core.output import check_output_folder, clear_outputs
from cdpr_exu.scenes.scene import Scene, load_scene
from cdpr_exu.results.result import Result
from cdpr_exu.space import PLANE, SPACE, Space

#: File names inside a run folder (written by ``cdpr run --out``).
SCENE_FILE = "scene.toml"
SOLUTION_FILE = "solution.sol"

#: Default image size of ``cdpr animate`` [pixels] (width, height).
DEFAULT_SIZE = (640, 480)
#: Default frame rate of ``cdpr animate`` [frames per second].
DEFAULT_FPS = 25.0
#: Highest frame rate a GIF can store (frame times in hundredths of a second) [frames per second].
MAX_GIF_FPS = 100.0
#: Share of the scene's extent left free around it in an animation frame.
FRAME_MARGIN = 0.06
#: Height of the caption band at the top of an animation frame, as a share of its height.
CAPTION_BAND = 0.07

# Colours, RGBA in [0, 1].
PULLEY_COLOR = [0.72, 0.72, 0.75, 1.0]
PULLEY_RIM_COLOR = [0.35, 0.35, 0.38, 1.0]
REFERENCE_COLOR = [0.85, 0.12, 0.12, 1.0]
PLATFORM_COLOR = [0.55, 0.70, 0.95, 1.0]
CABLE_COLOR = [0.10, 0.10, 0.25, 1.0]
NODE_COLOR = [0.10, 0.15, 0.55, 1.0]
#: Colour of the platform's travelled path in animation frames (RGB, 0-255).
TRAIL_RGB = (40, 110, 210)

#: Exudyn items that only clutter a replay (constraint symbols, contact helpers).
_HIDDEN_OBJECT_TYPES = ("ConnectorCoordinate", "JointRevolute2D", "ContactSphereSphere", "GenericODE2")
_HIDDEN_NODE_TYPES = ("PointGround", "RigidBody2D")


class RunFolderError(CdprError, FileNotFoundError):
    """A run folder or one of its files is missing or unreadable; the message names it."""


class SolutionMismatchError(CdprError, ValueError):
    """The solution file does not fit the model rebuilt from the folder's scene."""


class NoDisplayError(CdprError, RuntimeError):
    """No window can be opened here (no display, or Exudyn's windows are switched off)."""


@dataclass
class Replay:
    """A run folder loaded for replay: its scene, the model rebuilt from it and the solution
    (:func:`exudyn.utilities.LoadSolutionFile`'s dict; ``solution["data"]``: a row per output, time first)."""

    run_dir: Path
    scene: Scene
    model: Model | Model3D
    solution: dict

    @property
    def n_rows(self) -> int:
        return int(self.solution["nRows"])

    @property
    def times(self) -> np.ndarray:
        """Time of each row, shape (n_rows,) [s]."""
        return np.asarray(self.solution["data"][:, 0], dtype=float)

    def positions(self) -> dict[str, np.ndarray]:
        """Planar positions in each row: ``"platform"`` (n_rows, 3) (x, z, rotation) [m, rad] and
        ``"cable_i"`` (n_rows, n_i + 1, 2) [m], winch end first."""
        mbs = self.model.mbs
        reference = mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Reference)
        n_ode2 = int(self.solution["columnsExported"][0])
        q = reference + self.solution["data"][:, 1:1 + n_ode2]
        return {name: q[:, index] for name, index in self.model.coordinate_indices().items()}

    def platform_pose(self) -> np.ndarray:
        """The platform's pose in each row, shape (n_rows, pose size) [m, rad] (:data:`VIEWS`)."""
        return VIEWS[self.scene.space].poses(self)


def _require_file(path: Path, what: str) -> Path:
    if not path.is_file():
        raise RunFolderError(f"{what} {str(path)!r} not found; a run folder is written by "
                             f"`cdpr run SCENE --out DIR` and holds {SCENE_FILE} and {SOLUTION_FILE}")
    return path


def _run_folder(run_dir: str | Path) -> Path:
    """``run_dir`` as a Path; RunFolderError if it is no folder."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise RunFolderError(f"run folder {str(run_dir)!r} does not exist; write one with "
                             f"`cdpr run SCENE --out {run_dir}`")
    return run_dir


def run_files(run_dir: str | Path) -> tuple[Path, Path]:
    """Paths of the scene and solution files of a run folder; RunFolderError names what is missing."""
    run_dir = _run_folder(run_dir)
    return (_require_file(run_dir / SCENE_FILE, "scene file"),
            _require_file(run_dir / SOLUTION_FILE, "solution file"))


def load_solution(path: str | Path) -> dict:
    """Read an Exudyn solution file (text or binary); RunFolderError if it is missing, unreadable or empty."""
    path = Path(path)
    _require_file(path, "solution file")
    try:
        solution = LoadSolutionFile(str(path), verbose=False)
    except Exception as err:  # Exudyn raises plain exceptions of several kinds here
        raise RunFolderError(f"solution file {str(path)!r} cannot be read: {err}") from None
    if int(solution["nRows"]) == 0:
        raise RunFolderError(f"solution file {str(path)!r} holds no time step (did the run fail at once?)")
    return solution


def check_solution_fits(model, solution: dict, source: str) -> None:
    """SolutionMismatchError if the solution's exported coordinate sizes differ from ``model``'s system."""
    data = model.mbs.systemData
    n_ode2, n_vel2, n_acc2, n_ode1, n_vel1, n_algebraic, n_data = (int(n) for n in solution["columnsExported"])
    expected = {"ODE2 coordinates": (n_ode2, data.ODE2Size()), "ODE1 coordinates": (n_ode1, data.ODE1Size()),
                "algebraic coordinates": (n_algebraic, data.AEsize()), "data coordinates": (n_data, data.DataSize())}
    for name, count in (("velocities", n_vel2), ("accelerations", n_acc2)):
        if count not in (0, data.ODE2Size()):
            expected[f"ODE2 {name}"] = (count, data.ODE2Size())
    if n_vel1 not in (0, data.ODE1Size()):
        expected["ODE1 velocities"] = (n_vel1, data.ODE1Size())
    wrong = [f"{name}: file {found}, model {want}" for name, (found, want) in expected.items() if found != want]
    if wrong:
        raise SolutionMismatchError(
            f"{source} does not fit the model rebuilt from the scene ({'; '.join(wrong)}); was scene.toml "
            "edited, or the package changed, after the run? Run the scene again with `cdpr run`")


def load_replay(run_dir: str | Path, *, decorate: bool = True) -> Replay:
    """Load a run folder of ``cdpr run SCENE --out DIR``, planar or spatial, with the drawing-only items
    of its view if ``decorate`` (:data:`VIEWS`). Raises RunFolderError, SolutionMismatchError, SceneError."""
    scene_file, solution_file = run_files(run_dir)
    scene = load_scene(scene_file)
    solution = load_solution(solution_file)
    replay = Replay(Path(run_dir), scene, build_model(scene), solution)
    if decorate:
        VIEWS[scene.space].decorate(replay)
    check_solution_fits(replay.model, solution, f"solution file {str(solution_file)!r}")
    return replay


def reference_path(scene: Scene, times: np.ndarray) -> np.ndarray:
    """Reference position of the platform at ``times``, shape (N, 2) [m]; (0, 2) without a trajectory."""
    if scene.trajectory is None or len(times) == 0:
        return np.zeros((0, 2))
    return np.atleast_2d(scene.trajectory.pose(np.asarray(times, dtype=float)))[:, :2]


def thin_polyline(points: np.ndarray, min_segment: float) -> np.ndarray:
    """The points (N, 2) [m] of a polyline less those closer than ``min_segment`` [m] to the last kept one
    (the last point always kept): Exudyn's raytracer leaves out segments shorter than about a pixel."""
    points = np.asarray(points, dtype=float)
    points = points[np.all(np.isfinite(points), axis=1)]
    if len(points) < 2:
        return points
    kept = [points[0]]
    for point in points[1:]:
        if np.linalg.norm(point - kept[-1]) >= min_segment:
            kept.append(point)
    if np.linalg.norm(points[-1] - kept[-1]) > 0.0:
        if len(kept) > 1 and np.linalg.norm(points[-1] - kept[-1]) < min_segment:
            kept[-1] = points[-1]
        else:
            kept.append(points[-1])
    return np.array(kept)


def scene_extent(scene: Scene) -> float:
    """Size of the robot: the larger side of the box around pulleys and start pose [m]."""
    centers = np.vstack([scene.exit_points, [scene.platform.initial_pose[:2]]])
    radius = max(exit_.radius for exit_ in scene.exits)
    return float(np.max(np.ptp(centers, axis=0)) + 2.0 * radius) or 1.0


def decorate_model(model: Model, reference_xz: np.ndarray | None = None) -> int:
    """Add drawing-only items (no node, no coordinate) to an assembled planar model and assemble it again;
    returns the new ground object's index: pulleys, the reference path ``reference_xz`` (N, 2) [m], the
    platform's rectangle and anchors, cables as lines, no constraint or contact symbols."""
    scene, mbs = model.scene, model.mbs
    extent = scene_extent(scene)
    items = []
    for pulley in scene.exits:
        x, z = pulley.point
        if pulley.wraps:
            items.append(graphics.Cylinder(pAxis=[x, z, -0.02], vAxis=[0.0, 0.0, 0.01], radius=pulley.radius,
                                           color=PULLEY_COLOR, nTiles=64))
            items.append(graphics.Circle([x, z, 0.0], pulley.radius, color=PULLEY_RIM_COLOR))
        items.append(graphics.Circle([x, z, 0.0], 0.008 * extent, color=PULLEY_RIM_COLOR))
    if reference_xz is not None and len(reference_xz):
        path = thin_polyline(reference_xz, extent / 300.0)
        if len(path) >= 2:
            items.append(graphics.Lines([[x, z, -0.005] for x, z in path], color=REFERENCE_COLOR))
        elif len(path) == 1:  # a fixed reference: mark the point
            items.append(graphics.Circle([path[0, 0], path[0, 1], 0.0], 0.015 * extent, color=REFERENCE_COLOR))
    ground = mbs.CreateGround(graphicsDataList=items)

    width, height = scene.platform.size
    body = []
    if width > 0.0 and height > 0.0:
        body.append(graphics.Brick(size=[width, height, 0.004], color=PLATFORM_COLOR, addEdges=True))
    else:
        body.append(graphics.Circle([0.0, 0.0, 0.0], 0.02 * extent, color=CABLE_COLOR))
    for bx, bz in scene.platform.anchors:
        body.append(graphics.Circle([bx, bz, 0.003], 0.004 * extent, color=CABLE_COLOR))
    mbs.SetObjectParameter(model.platform.body, "VgraphicsData", body)

    for index in range(mbs.systemData.NumberOfObjects()):
        kind = mbs.GetObject(index)["objectType"]
        if kind in _HIDDEN_OBJECT_TYPES:
            mbs.SetObjectParameter(index, "Vshow", False)
        elif kind == "ConnectorSpringDamper":  # a cable element: a straight line, not a coil
            mbs.SetObjectParameter(index, "VdrawSize", 1e-6)
            mbs.SetObjectParameter(index, "Vcolor", CABLE_COLOR)
    for index in range(mbs.systemData.NumberOfNodes()):
        if mbs.GetNode(index)["nodeType"] in _HIDDEN_NODE_TYPES:
            mbs.SetNodeParameter(index, "Vshow", False)
    mbs.Assemble()
    return ground


def _style_settings(settings, extent: float) -> None:
    """Visualization settings of every replay, for a scene ``extent`` [m] across."""
    settings.loads.show = False
    settings.markers.show = False
    settings.connectors.springNumberOfWindings = 1
    settings.nodes.drawNodesAsPoint = False
    settings.nodes.defaultSize = 0.006 * extent
    settings.nodes.defaultColor = NODE_COLOR
    settings.nodes.tiling = 8
    settings.general.autoFitScene = False


def _style(model: Model) -> None:
    """A planar replay's settings, without the coordinate system."""
    settings = model.system_container.visualizationSettings
    _style_settings(settings, scene_extent(model.scene))
    settings.view0.scene.drawCoordinateSystem = 0


def _spatial_poses(replay: Replay) -> np.ndarray:
    """A spatial replay's platform pose (centre [m], rotation vector [rad]) in each row, shape (n_rows, 6)."""
    mbs, items = replay.model.mbs, replay.model.items
    poses = []
    for row in range(replay.n_rows):
        SetSolutionState(mbs, replay.solution, row, exu.ConfigurationType.Current)
        position, rotation = platform_pose(mbs, items)
        poses.append(np.concatenate([position, rotation_vector(rotation)]))
    return np.asarray(poses)


def _style_spatial(replay: Replay, size: tuple[int, int] = (1024, 768)) -> None:
    """A spatial replay's settings and a side view onto the exits and the platform's path."""
    settings = replay.model.system_container.visualizationSettings
    points = np.vstack([replay.scene.exit_points, _spatial_poses(replay)[:, :3]])
    low, high = points.min(axis=0), points.max(axis=0)
    extent = float((high - low).max()) or 1.0
    _style_settings(settings, extent)
    settings.view0.window.renderWindowSize = [int(size[0]), int(size[1])]
    advanced = settings.openGL.advanced
    advanced.initialCenterPoint = [float(x) for x in (low + high) / 2.0]
    advanced.initialZoom = 0.7 * extent
    advanced.initialMaxSceneSize = 4.0 * extent
    # Exudyn takes the transpose of the view's rotation: this one shows z up, x to the right, seen from -y.
    advanced.initialModelRotation = (RotationMatrixX(-0.5 * np.pi) @ RotationMatrixZ(-0.15 * np.pi)).T.tolist()


def _decorate_planar(replay: Replay) -> None:
    decorate_model(replay.model, reference_path(replay.scene, replay.times))


def _view_planar(replay: Replay) -> None:
    """A planar replay's look in SolutionViewer: its style and a camera fitted to the x-z plane."""
    _style(replay.model)
    fit_camera(_view_points(replay), (1024, 768), caption_band=0.12).apply(replay.model)


@dataclass(frozen=True)
class View:
    """How a replay of one space is read and drawn: ``poses(replay)`` the platform's pose in each row,
    ``decorate(replay)`` adds drawing-only items, ``style(replay)`` sets SolutionViewer's look and camera."""

    poses: object
    decorate: object
    style: object


@dataclass(frozen=True)
class Camera:
    """An orthographic view of the x-z plane (Exudyn x-y): ``center`` (x, z) [m] at the image centre,
    ``zoom`` [m] half the visible height (Exudyn's), ``size`` (width, height) [pixels]."""

    center: tuple[float, float]
    zoom: float
    size: tuple[int, int]

    @property
    def scale(self) -> float:
        """Pixels per metre."""
        return self.size[1] / (2.0 * self.zoom)

    def to_pixels(self, points: np.ndarray) -> np.ndarray:
        """Image coordinates (column, row) of world points, shape (..., 2) [pixels]."""
        points = np.asarray(points, dtype=float)
        column = self.size[0] / 2.0 + (points[..., 0] - self.center[0]) * self.scale
        row = self.size[1] / 2.0 - (points[..., 1] - self.center[1]) * self.scale
        return np.stack([column, row], axis=-1)

    def apply(self, model: Model) -> None:
        """Make this the initial view of the model's renderer."""
        settings = model.system_container.visualizationSettings
        settings.view0.window.renderWindowSize = [int(self.size[0]), int(self.size[1])]
        advanced = settings.openGL.advanced
        advanced.initialCenterPoint = [float(self.center[0]), float(self.center[1]), 0.0]
        advanced.initialZoom = float(self.zoom)
        advanced.initialMaxSceneSize = float(4.0 * self.zoom)
        advanced.initialModelRotation = np.eye(3).tolist()


def fit_camera(points: np.ndarray, size: tuple[int, int], caption_band: float = CAPTION_BAND) -> Camera:
    """The view of ``size`` (width, height) [pixels] that shows all finite ``points`` (N, 2) [m] with a
    margin (:data:`FRAME_MARGIN`) below a caption band (``caption_band``: a share of the image height)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    points = points[np.all(np.isfinite(points), axis=1)]
    if len(points) == 0:
        points = np.zeros((1, 2))
    low, high = points.min(axis=0), points.max(axis=0)
    span = np.maximum(high - low, 1e-3)
    pad = FRAME_MARGIN * max(span)
    low, high = low - pad, high + pad
    width, height = size
    band = caption_band * height
    scale = min(width / (high[0] - low[0]), (height - band) / (high[1] - low[1]))
    middle = (low + high) / 2.0
    center = (float(middle[0]), float(middle[1] + band / (2.0 * scale)))
    return Camera(center, float(height / (2.0 * scale)), (int(width), int(height)))


def _view_points(replay: Replay) -> np.ndarray:
    """Every point an animation must show: pulleys, nodes, platform, reference."""
    scene = replay.scene
    positions = replay.positions()
    parts = [np.array([[p.point[0] + dx * p.radius, p.point[1] + dz * p.radius]
                       for p in scene.exits for dx, dz in ((-1, -1), (1, 1))])]
    parts += [value.reshape(-1, 2) for name, value in positions.items() if name != "platform"]
    platform = positions["platform"][:, :2]
    half_diagonal = 0.5 * float(np.hypot(*scene.platform.size))
    parts += [platform + [dx * half_diagonal, dz * half_diagonal] for dx, dz in ((-1, -1), (1, 1))]
    parts.append(reference_path(scene, replay.times))
    return np.concatenate(parts)


#: How each space's replay is drawn: planar runs decorated and fitted to the x-z plane, spatial runs in
#: Exudyn's own 3-D view fitted to the exits and the platform's path.
VIEWS = {PLANE: View(lambda replay: replay.positions()["platform"], _decorate_planar, _view_planar),
         SPACE: View(_spatial_poses, lambda replay: None, _style_spatial)}


def display_problem() -> str | None:
    """Why no window can be opened here (Exudyn's switch, no display, no tkinter), or None if one can."""
    if getattr(exu.special.userInterface, "suppressSolutionViewer", False):
        return ("Exudyn's windows are switched off in this process (the environment variable "
                "EXUDYN_SUPPRESS_UI_WINDOW_OPEN is set, or exudyn.special.userInterface.suppressSolutionViewer)")
    uses_x11 = sys.platform not in ("win32", "cygwin", "darwin")
    if uses_x11 and not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        return "there is no display (neither DISPLAY nor WAYLAND_DISPLAY is set)"
    try:
        import tkinter
    except ImportError:
        return "tkinter is not installed (Exudyn's SolutionViewer dialog needs it)"
    if uses_x11 and os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        try:  # a stale DISPLAY (e.g. a closed ssh -X session) would end the process inside Exudyn
            root = tkinter.Tk()
            root.destroy()
        except tkinter.TclError as err:
            return f"the display {os.environ['DISPLAY']!r} cannot be opened ({err})"
    return None


def _rows_per_frame(times: np.ndarray, fps: float) -> int:
    """Row step that plays the stored rows in real time at ``fps`` frames per second."""
    if len(times) < 2:
        return 1
    period = float(np.median(np.diff(times)))
    return max(1, int(round(1.0 / (fps * period)))) if period > 0 else 1


def view_solution(run_dir: str | Path, *, every: int | None = None) -> None:
    """Replay a run folder in Exudyn's interactive SolutionViewer, every ``every``-th row (default: about
    real time at 25 frames/s).

    Raises
    ------
    RunFolderError, SolutionMismatchError
    NoDisplayError
        When no window can be opened here, checked before any window is tried (Exudyn ends the whole
        process when it fails to open one); Exudyn's windows are then switched off for the process.
    """
    run_files(run_dir)
    problem = display_problem()
    if problem is not None:
        exu.special.userInterface.SuppressAll(True)
        raise NoDisplayError(
            f"cannot open Exudyn's SolutionViewer: {problem}. Render the run to a file instead with "
            f"`cdpr animate {run_dir}` (GIF or MP4, no display needed), or run `cdpr view {run_dir}` "
            "on a machine with a display")
    from exudyn.interactive import SolutionViewer

    replay = load_replay(run_dir)
    VIEWS[replay.scene.space].style(replay)
    mbs = replay.model.mbs
    if every is None:
        every = _rows_per_frame(replay.times, DEFAULT_FPS)
    SolutionViewer(mbs, replay.solution, rowIncrement=min(int(every), replay.n_rows),
                   timeout=1.0 / DEFAULT_FPS, runOnStart=True, runMode=0,
                   title=f"cdpr view: {replay.scene.name} ({replay.run_dir})")


def parse_size(text: str) -> tuple[int, int]:
    """An image size ``"WIDTHxHEIGHT"`` [pixels], each 32 to 8192; ValueError naming the bad text."""
    try:
        width, height = (int(part) for part in text.lower().split("x"))
    except ValueError:
        raise ValueError(f"size must look like 640x480, got {text!r}") from None
    if not (32 <= width <= 8192 and 32 <= height <= 8192):
        raise ValueError(f"size must be between 32x32 and 8192x8192 pixels, got {text!r}")
    return width, height


class _Caption:
    """Draws the caption, the legend and the platform's travelled path onto a frame."""

    def __init__(self, title: str, camera: Camera, trail: np.ndarray, has_reference: bool):
        from PIL import ImageFont

        self.title, self.camera, self.has_reference = title, camera, has_reference
        self.trail = camera.to_pixels(trail)
        height = camera.size[1]
        try:
            self.font = ImageFont.load_default(size=max(10, round(0.035 * height)))
        except TypeError:  # Pillow without FreeType: the fixed bitmap font
            self.font = ImageFont.load_default()
        self.line = max(1, round(height / 480))
        self.text_height = self.font.getbbox("Ag")[3]

    def draw(self, image, row: int, time: float):
        """Draw onto ``image`` (a PIL image) for stored row ``row`` at ``time`` [s]."""
        from PIL import ImageDraw

        draw = ImageDraw.Draw(image)
        width, height = self.camera.size
        pad = round(0.015 * height)
        trail = self.trail[:row + 1]
        trail = trail[np.all(np.isfinite(trail), axis=1)]
        if len(trail) > 1:
            draw.line([tuple(p) for p in trail], fill=TRAIL_RGB, width=self.line)
        draw.text((pad, pad), f"{self.title}    t = {time:6.2f} s", fill=(0, 0, 0), font=self.font)
        legend = [(TRAIL_RGB, "platform path")]
        if self.has_reference:
            legend.insert(0, (tuple(round(255 * c) for c in REFERENCE_COLOR[:3]), "reference"))
        x, y = pad, height - pad - self.text_height
        middle = y + self.text_height // 2 + 1
        for color, label in legend:
            length = round(0.04 * width)
            draw.line([(x, middle), (x + length, middle)], fill=color, width=2 * self.line)
            x += length + pad // 2
            draw.text((x, y), label, fill=(60, 60, 60), font=self.font)
            x += round(draw.textlength(label, font=self.font)) + 2 * pad
        return image


class _Writer:
    """Collects frames into a GIF (Pillow) or streams them into an MP4 (imageio-ffmpeg)."""

    @staticmethod
    def check(path: Path, size: tuple[int, int], fps: float) -> None:
        """Refuse an animation file this writer cannot make, before any rendering."""
        suffix = path.suffix.lower()
        if suffix not in (".gif", ".mp4"):
            raise CdprError(f"animation file {str(path)!r} must end in .gif or .mp4")
        if suffix == ".gif" and fps > MAX_GIF_FPS:
            raise CdprError(f"--fps {fps:g}: a GIF stores frame times in hundredths of a second, so it plays at "
                            f"most {MAX_GIF_FPS:g} frames/s; lower --fps (and raise --every), or write an .mp4")
        if suffix == ".mp4":
            try:
                import imageio_ffmpeg  # noqa: F401
            except ImportError:
                raise CdprError(f"writing {str(path)!r} needs the optional package imageio-ffmpeg "
                                "(pip install 'cdpr-exu[video]', or pip install imageio-ffmpeg); "
                                "or write a GIF: --out animation.gif") from None
            if size[0] % 2 or size[1] % 2:
                raise CdprError(f"an MP4 needs an even width and height, got --size {size[0]}x{size[1]}")
        if path.parent.exists() and not path.parent.is_dir():
            raise CdprError(f"--out {str(path)!r}: {str(path.parent)!r} is a file, not a folder")
        if not path.parent.is_dir():
            raise CdprError(f"the folder of the animation file {str(path)!r} does not exist")

    def __init__(self, path: Path, fps: float, size: tuple[int, int]):
        self.path, self.fps, self.frames, self.mp4 = path, fps, [], None
        if path.suffix.lower() == ".mp4":
            import imageio_ffmpeg

            self.mp4 = imageio_ffmpeg.write_frames(str(path), size, fps=fps, codec="libx264",
                                                   pix_fmt_out="yuv420p", quality=7, macro_block_size=1,
                                                   ffmpeg_log_level="error")
            self.mp4.send(None)

    def add(self, image) -> None:
        """Append a frame (a PIL RGB image of the writer's size)."""
        if self.mp4 is not None:
            self.mp4.send(np.ascontiguousarray(np.asarray(image)))
        else:  # palette images: a third of the memory of RGB frames
            self.frames.append(image.quantize(colors=96))

    def close(self) -> None:
        """Finish the file."""
        if self.mp4 is not None:
            self.mp4.close()
        elif self.frames:
            self.frames[0].save(self.path, save_all=True, append_images=self.frames[1:],
                                duration=round(1000.0 / self.fps), loop=0)

    def abort(self) -> None:
        """Stop without leaving a partial file."""
        if self.mp4 is not None:
            self.mp4.close()
            self.path.unlink(missing_ok=True)
        self.frames = []


def run_space(run_dir: str | Path) -> Space:
    """The Space of the run in a ``cdpr run`` folder (its result.npz's); planar without one (older runs)."""
    path = Path(run_dir) / "result.npz"
    return Result.load(path).space if path.is_file() else PLANE


class _RaytracedFrames:
    """The frames of a planar run: its solution file's rows in the rebuilt model, drawn by Exudyn's raytracer."""

    @staticmethod
    def check(run_dir: Path) -> None:
        """Refuse a folder without the scene and solution files (:func:`run_files`)."""
        run_files(run_dir)

    def __init__(self, run_dir: Path, size: tuple[int, int]):
        self.replay = replay = load_replay(run_dir)
        model = replay.model
        _style(model)
        settings = model.system_container.visualizationSettings
        settings.raytracer.multiSampling = 2  # samples per pixel: 1 leaves thin lines broken
        settings.raytracer.numberOfThreads = max(1, os.cpu_count() or 1)
        settings.raytracer.advanced.showText = False  # the caption replaces Exudyn's text
        camera = fit_camera(_view_points(replay), size)
        camera.apply(model)
        trail = replay.positions()["platform"][:, :2]
        self.caption = _Caption(replay.scene.name, camera, trail, replay.scene.trajectory is not None)
        self.name, self.times = replay.scene.name, replay.times

    def frame(self, row: int):
        """Row ``row`` as a PIL RGB image."""
        from PIL import Image

        model, solution = self.replay.model, self.replay.solution
        SetSolutionState(model.mbs, solution, row, exu.ConfigurationType.Current)
        SetSolutionState(model.mbs, solution, row, exu.ConfigurationType.Visualization)
        pixels = model.system_container.renderer.RedrawAndGetImage(useRaytracer=True)
        image = Image.fromarray(np.asarray(pixels, dtype=np.uint8)[:, :, :3])
        return self.caption.draw(image, row, float(self.times[row]))


class _AxesFrames:
    """The frames of a spatial run: the samples of its ``result.npz`` drawn with matplotlib's 3-D axes."""

    @staticmethod
    def check(run_dir: Path) -> None:
        """Nothing more to check: :func:`run_space` read the folder's result.npz."""

    def __init__(self, run_dir: Path, size: tuple[int, int]):
        from matplotlib.backends.backend_agg import FigureCanvasAgg  # matplotlib: only where a run is drawn
        from matplotlib.figure import Figure

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


#: The frames source of a run, by its space: each is built as ``source(run_dir, size)``, has ``name``,
#: ``times`` [s] and ``frame(row)`` (a PIL RGB image), and ``check(run_dir)`` refuses a folder it cannot
#: draw before any work.
FRAME_SOURCES = {PLANE: _RaytracedFrames, SPACE: _AxesFrames}


def render_animation(run_dir: str | Path, out_file: str | Path | None = None, *, fps: float = DEFAULT_FPS,
                     every: int | None = None, size: tuple[int, int] = DEFAULT_SIZE,
                     frames_dir: str | Path | None = None, progress: bool = False) -> tuple[Path, int, float]:
    """Render a run folder to ``out_file`` (``.gif``, or ``.mp4`` with imageio-ffmpeg; default
    ``run_dir/animation.gif``) without a display; returns the file, its number of frames and the seconds
    per frame. A planar run's rows are drawn in the rebuilt model by Exudyn's raytracer, with a caption
    and the platform's travelled path; a spatial run's samples with matplotlib's 3-D axes.

    ``fps`` [1/s] (a GIF stores frame times in steps of 10 ms: at most 100), ``every`` the row step
    (default: real-time playback), ``size`` (width, height) [pixels], ``frames_dir`` also gets each frame
    as ``frame_00000.png``, ... (its older frames removed). Every option is checked before any work:
    CdprError names a bad one as the command line spells it; RunFolderError, SolutionMismatchError for
    missing or unfitting files.
    """
    from tqdm import tqdm

    if isinstance(fps, bool) or not isinstance(fps, (int, float, np.integer, np.floating)) \
            or not (np.isfinite(fps) and fps > 0):
        raise CdprError(f"--fps must be a finite number of frames per second > 0, got {fps!r}")
    if every is not None and (isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1):
        raise CdprError(f"--every must be a whole number >= 1, got {every!r}")
    try:
        width, height = (int(n) for n in size)
    except (TypeError, ValueError):
        raise CdprError(f"--size must be (width, height) in pixels, got {size!r}") from None
    if not (32 <= width <= 8192 and 32 <= height <= 8192):
        raise CdprError(f"--size must be between 32x32 and 8192x8192 pixels, got {width}x{height}")
    run_dir = _run_folder(run_dir)
    space = run_space(run_dir)
    FRAME_SOURCES[space].check(run_dir)
    out_file = Path(out_file) if out_file is not None else run_dir / "animation.gif"
    fps, size = float(fps), (width, height)
    _Writer.check(out_file, size, fps)
    if frames_dir is not None:
        frames_dir = check_output_folder(frames_dir, "--frames-dir")
    source = FRAME_SOURCES[space](run_dir, size)
    step = int(every) if every is not None else _rows_per_frame(source.times, fps)
    rows = range(0, len(source.times), step)
    if frames_dir is not None:
        clear_outputs(frames_dir, "animate --frames-dir")  # no frame of a longer, older animation stays

    start = _time.perf_counter()
    writer = _Writer(out_file, fps, size)
    try:
        for frame, row in enumerate(tqdm(rows, unit="frame", desc=f"{source.name} ",
                                         disable=None if progress else True)):
            image = source.frame(row)
            if frames_dir is not None:
                image.save(frames_dir / f"frame_{frame:05d}.png")
            writer.add(image)
    except BaseException:
        writer.abort()
        raise
    writer.close()
    return out_file, len(rows), (_time.perf_counter() - start) / max(1, len(rows))
