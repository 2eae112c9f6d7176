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
import zipfile
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from cdpr_exu.core.errors import OutputError

#: Keys of a summary that change from run to run on the same machine (wall clock).
TIMING_KEYS: tuple[str, ...] = ("wall_time_s", "real_time_factor", "date", "cpu_time_s",
                                "companion_wall_time_s")


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


def split_timing(summary: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, Any]]:
    """Split a summary into (stable figures, timing figures that change from run to run)."""
    stable, timing = {}, {}
    for key, value in summary.items():
        (timing if key in TIMING_KEYS else stable)[key] = value
    return stable, timing


def write_summary(folder: str | Path, summary: Mapping[str, Any], name: str = "summary.json") -> Path:
    """Write ``summary`` into ``folder``: the stable part as ``name``, wall-clock figures as ``timing.json``."""
    folder = Path(folder)
    stable, timing = split_timing(summary)
    if timing:
        write_json(folder / "timing.json", timing)
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


def check_output_folder(path: str | Path | None, option: str = "--out") -> Path | None:
    """Make sure ``path`` can be the output folder, before any work starts; create it.

    Raises
    ------
    OutputError
        If ``path`` (or one of its parents) is an existing file, or cannot be created.
    """
    if path is None:
        return None
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"{option} {path}: is an existing file, not a folder; give a folder name")
    for parent in path.parents:
        if parent.exists() and not parent.is_dir():
            raise OutputError(f"{option} {path}: {parent} is a file, so no folder can be made inside it")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise OutputError(f"{option} {path}: cannot create the folder ({err.strerror or err})") from err
    return path
