"""Files that programs read: strict JSON, CSV cells, stable archives, and output folders.

Every JSON file the project writes goes through :func:`write_json`: ``NaN`` and
infinities become ``null`` (strict parsers reject the bare tokens), NumPy scalars and
arrays become plain numbers and lists. CSV cells for "not applicable" are empty, never
``nan``. Wall-clock figures go into ``timing.json`` beside ``summary.json``, so that
everything else a run writes is identical from one run to the next.
"""

from __future__ import annotations

import json
import math
import re
import zipfile
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np

from cdpr_exu.core.errors import OutputError

#: Keys of a summary that change from run to run on the same machine (wall clock).
TIMING_KEYS: tuple[str, ...] = ("wall_time_s", "real_time_factor", "date", "cpu_time_s",
                                "companion_wall_time_s", "companion_cpu_time_s")


def strict(value: Any) -> Any:
    """``value`` with NaN/inf as None and NumPy types as plain Python (recursively)."""
    if isinstance(value, Mapping):
        return {str(k): strict(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [strict(v) for v in value]
    if isinstance(value, np.ndarray):
        return strict(value.tolist())
    if isinstance(value, (np.bool_, bool)):
        return bool(value)
    if isinstance(value, (np.integer, int)):
        return int(value)
    if isinstance(value, (np.floating, float)):
        value = float(value)
        return value if math.isfinite(value) else None
    if value is None or isinstance(value, str):
        return value
    if isinstance(value, Path):
        return str(value)
    return str(value)


def json_text(value: Any) -> str:
    """Strict JSON (RFC 8259: no NaN or Infinity tokens) of ``value``, indented, ending in a newline."""
    return json.dumps(strict(value), indent=2, allow_nan=False) + "\n"


def write_json(path: str | Path, value: Any) -> Path:
    """Write ``value`` as strict JSON to ``path``; returns the path."""
    path = Path(path)
    path.write_text(json_text(value))
    return path


def csv_cell(value: Any) -> str:
    """A CSV cell: empty for None and NaN ("not applicable"), JSON for lists, text otherwise."""
    if value is None:
        return ""
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.9g}" if math.isfinite(value) else ""
    if isinstance(value, (list, tuple, dict)):
        return json.dumps(strict(value))
    return str(value)


def value_text(value: Any) -> str:
    """A value as a study's table, CSV and figures show it: ``true``/``false``, a float with all its
    digits (empty when not finite: "not applicable", never "nan"), empty for None, else ``str``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ""  # empty: "not applicable", never "nan"
    return "" if value is None else str(value)


def finite_number(value: Any) -> bool:
    """True for an int or a float that is finite (a study's figure that exists; None and NaN do not)."""
    return isinstance(value, (int, float)) and math.isfinite(value)


def fixed(value: float, digits: int = 2) -> str:
    """``value`` with ``digits`` decimals, never printed as ``-0.00``."""
    text = f"{value:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def length_text(metres: float | None) -> str:
    """A length [m] as printed: millimetres with two decimals from 0.1 mm on, micrometres to three
    significant digits below (never "0.00 mm" for a micrometre); "n/a" for None."""
    if metres is None:
        return "n/a"
    if abs(metres) >= 1e-4:
        return f"{fixed(1000.0 * metres, 2)} mm"
    return f"{1e6 * metres:.3g} um".replace("-0 um", "0 um")


def split_timing(summary: Any, keep: Sequence[str] = ()) -> tuple[Any, Any]:
    """Split a summary into (stable figures, timing figures that change from run to run).

    The :data:`TIMING_KEYS` go to the timing part at any depth, under the same keys and list
    positions (a comparison's ``controllers.ideal_ik.wall_time_s``, a study's
    ``rows[3].real_time_factor``), so that no wall-clock figure hides in a nested table.
    ``keep`` names timing keys that stay in the stable part because they are what the
    file is about (the accuracy study's cost columns). The timing part is empty where
    there is none.
    """
    if isinstance(summary, Mapping):
        stable, timing = {}, {}
        for key, value in summary.items():
            if key in TIMING_KEYS and key not in keep:
                timing[key] = value
                continue
            stable[key], nested = split_timing(value, keep)
            if nested:
                timing[key] = nested
        return stable, timing
    if isinstance(summary, (list, tuple)):
        parts = [split_timing(value, keep) for value in summary]
        timing = [nested or {} for _, nested in parts]
        return [stable for stable, _ in parts], (timing if any(timing) else {})
    return summary, {}


def write_summary(folder: str | Path, summary: Mapping[str, Any], name: str = "summary.json", *,
                  timing_name: str = "timing.json", keep: Sequence[str] = ()) -> Path:
    """Write ``summary`` into ``folder``: the stable part as ``name``, wall-clock figures (at any depth,
    :func:`split_timing`) as ``timing_name`` (git-ignored under results/); ``keep``: timing keys the stable
    file keeps because they are its subject."""
    folder = Path(folder)
    stable, timing = split_timing(summary, keep)
    if timing:
        write_json(folder / timing_name, timing)
    return write_json(folder / name, stable)


#: Date written into every zip member, so that archives of the same data are identical.
ZIP_DATE = (2020, 1, 1, 0, 0, 0)


def write_npz(path: str | Path, **arrays: Any) -> Path:
    """``numpy.savez_compressed`` with a fixed member date: the same data gives the same bytes."""
    path = Path(path)
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name, value in arrays.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            with archive.open(info, "w") as member:
                np.lib.format.write_array(member, np.asanyarray(value), allow_pickle=False)
    return path


#: Pose columns of a planar run's ``pose.csv`` (after ``time_s``; the reference's follow, ``x_ref_m``, ...).
PLANAR_POSE_COLUMNS: tuple[str, ...] = ("x_m", "z_m", "rotation_rad")
#: Pose columns of a spatial run's ``pose.csv``: the centre of mass and the rotation vector.
SPATIAL_POSE_COLUMNS: tuple[str, ...] = ("x_m", "y_m", "z_m", "rotation_x_rad", "rotation_y_rad", "rotation_z_rad")


def write_pose_csv(path: str | Path, time: Any, pose: Any, reference: Any, columns: Sequence[str]) -> Path:
    """Write a run's platform path as CSV: time, the pose, the reference pose, units in the header.

    Parameters
    ----------
    path : path
    time : array_like, shape (N,) [s]
    pose, reference : array_like, shape (N, len(columns))
    columns : names of the pose columns with their unit last (:data:`PLANAR_POSE_COLUMNS`,
        :data:`SPATIAL_POSE_COLUMNS`); the reference's are the same with ``_ref`` before the unit.
    """
    path = Path(path)
    references = [f"{name.rsplit('_', 1)[0]}_ref_{name.rsplit('_', 1)[1]}" for name in columns]
    header = ",".join(["time_s", *columns, *references])
    table = np.column_stack([np.asarray(time, dtype=float), np.asarray(pose, dtype=float),
                             np.asarray(reference, dtype=float)])
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.9g")
    return path


def undate_solution_file(path: str | Path) -> None:
    """Blank the date in the header of Exudyn's solution file, so it is stable from run to run.

    The binary header and footer hold the start and end times as ``YYYY-MM-DD,HH:MM:SS``;
    they are overwritten in place with zeros of the same length (the file stays readable
    by SolutionViewer).
    """
    path = Path(path)
    data = bytearray(path.read_bytes())
    pattern = re.compile(rb"\d{4}-\d{2}-\d{2},\d{2}:\d{2}:\d{2}")
    for offset in (0, max(0, len(data) - 256)):
        for match in pattern.finditer(bytes(data[offset:offset + 1024])):
            data[offset + match.start():offset + match.end()] = b"0000-00-00,00:00:00"
    path.write_bytes(bytes(data))


#: What each command writes into its output folder: file names and ``glob`` patterns. Before it
#: writes, a command removes these (:func:`clear_outputs`), so that no file of the run it replaces
#: stays beside its own (a spatial run into a planar run's folder kept that run's scene.toml,
#: solution.sol and figures, and `cdpr view` replayed the old run); every other file is left alone
#: (results/paper_circle/variants.* of examples/paper_reproduction.py, a user's notes).
COMMAND_OUTPUTS: dict[str, tuple[str, ...]] = {
    "run": ("scene.toml", "result.npz", "pose.csv", "summary.json", "timing.json", "solution.sol",
            "overview.png", "snapshots.png", "path.png", "rotation.png", "errors.png", "tensions.png",
            "animation.gif", "animation.mp4"),  # `cdpr animate`'s default files show the run they were made of
    "compare": ("scene.toml", "summary.json", "timing.json", "comparison.md", "pose_*.csv",
                "comparison_paths.png", "comparison_errors.png", "overview_*.png"),
    "static": ("scene.toml", "summary.json", "timing.json", "rest.npz", "rest_profile.png"),
    "study sweep": ("base_scene.toml", "study.csv", "study.json", "timing.json", "vs_*.png", "heatmap.png"),
    "study accuracy": ("base_scene.toml", "accuracy.csv", "accuracy.json", "timing.json", "tables.md", "pareto.png",
                       "reference.npz"),
    "animate --frames-dir": ("frame_*.png",),
    "workspace": ("workspace.csv", "summary.json", "summary.md", "slices.png", "view3d.png"),  # resumes: keeps points.jsonl
}
#: Files that only one command writes: a folder holding one of them holds that command's output.
COMMAND_MARKERS: dict[str, tuple[str, ...]] = {
    "run": ("result.npz", "solution.sol"),
    "compare": ("comparison.md",),
    "static": ("rest.npz", "rest_profile.png"),
    "study sweep": ("study.json", "study.csv"),
    "study accuracy": ("accuracy.json", "accuracy.csv"),
    "workspace": ("points.jsonl", "workspace.csv"),
}


def check_output_folder(path: str | Path | None, option: str = "--out", command: str | None = None) -> Path | None:
    """Make sure ``path`` can be the output folder, before any work starts; create it.

    With ``command`` (a key of :data:`COMMAND_OUTPUTS`), a folder that holds another
    command's output (one of its :data:`COMMAND_MARKERS`) is refused: the two commands'
    files would lie side by side, and what reads the folder (``cdpr view``, a reader of
    summary.json) would mix them. A folder of the same command's earlier output is
    accepted; the command clears those files before it writes (:func:`clear_outputs`).

    Raises
    ------
    OutputError
        If ``path`` (or one of its parents) is an existing file, cannot be created, or holds
        another command's output.
    """
    if path is None:
        return None
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"{option} {path}: is an existing file, not a folder; give a folder name")
    for parent in path.parents:
        if parent.exists() and not parent.is_dir():
            raise OutputError(f"{option} {path}: {parent} is a file, so no folder can be made inside it")
    if command is not None and path.is_dir():
        for other, markers in COMMAND_MARKERS.items():
            found = [name for name in markers if (path / name).is_file()]
            if other != command and found:
                raise OutputError(f"{option} {path}: holds the output of `cdpr {other}` ({', '.join(found)}); "
                                  f"`cdpr {command}` there would leave the two side by side. Give another folder, "
                                  "or remove that output first")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(f"{option} {path}: cannot create the folder ({err.strerror or err})") from err
    return path


def clear_outputs(folder: str | Path, command: str) -> list[Path]:
    """Remove the files ``command`` writes (:data:`COMMAND_OUTPUTS`) from ``folder``; returns them.

    Called by each command just before it writes its first file, so that a new run leaves
    none of the run it replaces (a figure that the new run does not draw, a
    ``pose_<controller>.csv`` of a controller it did not run). Other files, and folders,
    are left alone.
    """
    folder = Path(folder)
    removed = []
    for pattern in COMMAND_OUTPUTS[command]:
        for path in sorted(folder.glob(pattern)):
            if path.is_file():
                path.unlink()
                removed.append(path)
    return removed
