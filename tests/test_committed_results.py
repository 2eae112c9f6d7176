"""The committed ``results/`` are as new as the code: re-running the README's command leaves them unchanged.

Issue 11.12: ``cdpr run paper-circle --out results/paper_circle`` rewrote tracked files
whose committed versions lacked fields the code now writes. These checks need no
simulation: a scene file that the code would write differently, or a committed JSON that
holds a wall time or a date (which belong in the untracked ``timing.json``), fails here.
"""

import json
from pathlib import Path

import pytest

from cdpr_exu.core.output import TIMING_KEYS
from cdpr_exu.scenes.scene import load_scene, save_scene

RESULTS = Path(__file__).resolve().parents[1] / "results"
SCENES = sorted(RESULTS.glob("**/*scene.toml"))
JSONS = sorted(RESULTS.glob("**/*.json"))


@pytest.mark.parametrize("path", SCENES, ids=[str(p.relative_to(RESULTS)) for p in SCENES])
def test_committed_scene_files_are_what_the_code_writes(path, tmp_path):
    rewritten = save_scene(load_scene(path), tmp_path / "scene.toml")
    assert rewritten.read_text() == path.read_text(), "regenerate this result folder with its script"


@pytest.mark.parametrize("path", [p for p in JSONS if p.name != "timing.json"],
                         ids=[str(p.relative_to(RESULTS)) for p in JSONS if p.name != "timing.json"])
def test_committed_json_is_strict_and_holds_no_wall_time_or_date(path):
    data = json.loads(path.read_text(), parse_constant=lambda token: pytest.fail(f"bare {token} in {path}"))
    assert not set(TIMING_KEYS) & set(data), "wall-clock figures belong in timing.json"


def test_the_readme_command_result_folder_is_complete():
    folder = RESULTS / "paper_circle"
    summary = json.loads((folder / "summary.json").read_text())
    assert summary["scene"] == "paper-circle" and summary["status"] == "completed"
    for name in ("result.npz", "pose.csv", "solution.sol", "scene.toml", "overview.png"):
        assert (folder / name).is_file(), name
