"""The committed ``results/`` are as new as the code: re-running the README's command leaves them unchanged.

Issue 11.12: ``cdpr run paper-circle --out results/paper_circle`` rewrote tracked files
whose committed versions lacked fields the code now writes. These checks need no
simulation: a scene file that the code would write differently, or a committed JSON, CSV
or Markdown table that holds a wall time, a real-time factor or a date at any depth (which
belong in the untracked ``timing.json``, issue 23.18), fails here.
"""

import csv
import json
from pathlib import Path

import pytest

from cdpr_exu.core.output import TIMING_KEYS
from cdpr_exu.scenes.scene import load_scene, save_scene

RESULTS = Path(__file__).resolve().parents[1] / "results"
SCENES = sorted(RESULTS.glob("**/*scene.toml"))
JSONS = sorted(p for p in RESULTS.glob("**/*.json") if not p.name.endswith("timing.json"))
CSVS = sorted(RESULTS.glob("**/*.csv"))
MARKDOWNS = sorted(RESULTS.glob("**/*.md"))

#: Files whose measured cost is their subject (error against CPU time), by path under results/, and the
#: keys or header words they keep: they change with every rerun, as the README says ("Outputs").
MEASURED_COST = {
    "accuracy/paper_catenary/accuracy.json": {"cpu_time_s", "wall_time_s", "real_time_factor"},
    "accuracy/paper_circle/accuracy.json": {"cpu_time_s", "wall_time_s", "real_time_factor"},
    "accuracy/paper_catenary/accuracy.csv": {"cpu_time_s", "wall_time_s", "real_time_factor"},
    "accuracy/paper_circle/accuracy.csv": {"cpu_time_s", "wall_time_s", "real_time_factor"},
    "accuracy/paper_catenary/tables.md": {"real time"},
    "accuracy/paper_circle/tables.md": {"real time"},
    "contact_models/summary.json": {"cpu_time_s"},
}


def _name(path: Path) -> str:
    return str(path.relative_to(RESULTS))


def _cases(paths):
    return [pytest.param(p, id=_name(p)) for p in paths]


def _is_timing(key: str) -> bool:
    """A wall-clock or CPU-time figure (or a date): TIMING_KEYS, and the examples' own variants of them."""
    return key in TIMING_KEYS or "wall_time" in key or "cpu_time" in key or key.endswith("_wall_s")


@pytest.mark.parametrize("path", SCENES, ids=[_name(p) for p in SCENES])
def test_committed_scene_files_are_what_the_code_writes(path, tmp_path):
    rewritten = save_scene(load_scene(path), tmp_path / "scene.toml")
    assert rewritten.read_text() == path.read_text(), "regenerate this result folder with its script"


@pytest.mark.parametrize("path", _cases(JSONS))
def test_committed_json_is_strict_and_holds_no_wall_time_or_date_at_any_depth(path):
    data = json.loads(path.read_text(), parse_constant=lambda token: pytest.fail(f"bare {token} in {path}"))
    found = set()

    def walk(value):
        if isinstance(value, dict):
            found.update(k for k in value if _is_timing(k))
            for v in value.values():
                walk(v)
        elif isinstance(value, list):
            for v in value:
                walk(v)

    walk(data)
    assert not found - MEASURED_COST.get(_name(path), set()), "wall-clock figures belong in timing.json"


@pytest.mark.parametrize("path", _cases(CSVS))
def test_committed_csv_has_no_wall_time_column(path):
    with open(path, newline="") as handle:
        header = next(csv.reader(handle))
    assert not {c for c in header if _is_timing(c) or c == "real_time_factor"} - MEASURED_COST.get(_name(path), set())


@pytest.mark.parametrize("path", _cases(MARKDOWNS))
def test_committed_markdown_tables_have_no_wall_time_column(path):
    allowed = MEASURED_COST.get(_name(path), set())
    headers = [line for line, following in zip(path.read_text().splitlines(), path.read_text().splitlines()[1:])
               if line.startswith("|") and following.startswith("|---")]
    for header in headers:
        cells = [cell.strip().lower() for cell in header.strip("|").split("|")]
        assert not [c for c in cells if ("wall" in c or "real time" in c) and not any(a in c for a in allowed)], header


def test_the_readme_command_result_folder_is_complete():
    folder = RESULTS / "paper_circle"
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["scene"] == "paper-circle" and summary["status"] == "completed"
    for name in ("result.npz", "pose.csv", "solution.sol", "scene.toml", "overview.png"):
        assert (folder / name).is_file(), name
