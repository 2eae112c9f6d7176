"""Files that programs read: strict JSON (NaN and infinities as ``null``), CSV cells ("not applicable"
empty, never ``nan``), stable archives, and output folders. Wall-clock figures go into ``timing.json``,
so that everything else a run writes is identical from one run to the next.
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
    digits, empty for None or not finite, else ``str``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ""  # empty: "not applicable", never "nan"
    return "" if value is None else str(value)


def finite_number(value: Any) -> bool:
    """True for a finite int or float (None and NaN are not)."""
    return isinstance(value, (int, float)) and math.isfinite(value)


def fixed(value: float, digits: int = 2) -> str:
    """``value`` with ``digits`` decimals, never printed as ``-0.00``."""
    text = f"{value:.{digits}f}"
    return text[1:] if text.startswith("-") and float(text) == 0.0 else text


def length_text(metres: float | None) -> str:
    """A length [m] as printed: mm with two decimals from 0.1 mm on, um to three digits below; None "n/a"."""
    if metres is None:
        return "n/a"
    if abs(metres) >= 1e-4:
        return f"{fixed(1000.0 * metres, 2)} mm"
    return f"{1e6 * metres:.3g} um".replace("-0 um", "0 um")


def split_timing(summary: Any, keep: Sequence[str] = ()) -> tuple[Any, Any]:
    """Split a summary into (stable figures, the :data:`TIMING_KEYS` at any depth, under the same keys and
    list positions); ``keep``: timing keys that stay because they are the file's subject."""
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
    """Write ``summary`` into ``folder``: the stable part as ``name``, the wall-clock figures
    (:func:`split_timing`) as ``timing_name`` (git-ignored under results/)."""
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


def write_pose_csv(path: str | Path, time: Any, pose: Any, reference: Any, columns: Sequence[str]) -> Path:
    """Write a run's platform path as CSV: ``time`` (N,) [s], ``pose`` and ``reference`` (N, len(columns)),
    under ``columns`` (unit last; the reference's with ``_ref`` before the unit)."""
    path = Path(path)
    references = [f"{name.rsplit('_', 1)[0]}_ref_{name.rsplit('_', 1)[1]}" for name in columns]
    header = ",".join(["time_s", *columns, *references])
    table = np.column_stack([np.asarray(time, dtype=float), np.asarray(pose, dtype=float),
                             np.asarray(reference, dtype=float)])
    np.savetxt(path, table, delimiter=",", header=header, comments="", fmt="%.9g")
    return path


def undate_solution_file(path: str | Path) -> None:
    """Blank the ``YYYY-MM-DD,HH:MM:SS`` dates in the header and footer of Exudyn's solution file (zeros of
    the same length: SolutionViewer still reads it), so it is stable from run to run."""
    path = Path(path)
    data = bytearray(path.read_bytes())
    pattern = re.compile(rb"\d{4}-\d{2}-\d{2},\d{2}:\d{2}:\d{2}")
    for offset in (0, max(0, len(data) - 256)):
        for match in pattern.finditer(bytes(data[offset:offset + 1024])):
            data[offset + match.start():offset + match.end()] = b"0000-00-00,00:00:00"
    path.write_bytes(bytes(data))


#: What each command writes into its output folder (names and ``glob`` patterns), removed before it writes
#: (:func:`clear_outputs`) so that no file of the run it replaces stays; other files are left alone.
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

    OutputError if ``path`` (or a parent) is a file, cannot be created, or, with ``command``,
    holds another command's output (:data:`COMMAND_MARKERS`: the two would be mixed).
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
    """Remove the files ``command`` writes (:data:`COMMAND_OUTPUTS`) from ``folder``; returns them."""
    folder = Path(folder)
    removed = []
    for pattern in COMMAND_OUTPUTS[command]:
        for path in sorted(folder.glob(pattern)):
            if path.is_file():
                path.unlink()
                removed.append(path)
    return removed
