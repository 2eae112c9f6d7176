"""The README says what the code does: its links, its example and its claims are checked here."""

import json
import re
from dataclasses import replace
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text()
DOCS = {path.name: path.read_text() for path in (ROOT / "docs").glob("*.md")}


def _python_example() -> str:
    """The first ```python block of the README."""
    return re.search(r"```python\n(.*?)```", README, re.S).group(1)


def test_readme_and_docs_never_point_outside_the_repository():
    for name, text in {"README.md": README, **DOCS}.items():
        assert "shared/" not in text, name


def test_no_image_tag_points_at_a_markdown_file():
    for name, text in {"README.md": README, **DOCS}.items():
        assert not re.search(r"!\[[^\]]*\]\([^)]*\.md\)", text), name


def test_every_relative_link_of_the_readme_exists():
    for target in re.findall(r"\]\(((?!https?:)[^)#]+)\)", README):
        assert (ROOT / target).exists(), target


def test_the_paper_is_described_and_its_parameters_are_in_docs():
    assert "bond graph" in README and "20-sim" in README
    paper = DOCS["paper.md"]
    for value in ("0.35 kg/m", "1e9 N/m^2", "1e7 N/m", "0.0271 kg m^2", "(0, -2) m"):
        assert value in paper, value


def test_scene_reference_says_point_to_point_poses_are_x_z_rotation():
    assert re.search(r"point_to_point.*x \[m\], z \[m\], rotation \[rad\]", README)


def test_controllers_table_says_how_the_closed_loop_is_built():
    from cdpr_exu.scenes.scene import load_scene
    from controllers.registry import CONTROLLERS

    controller = CONTROLLERS["closed_loop_tension_aware"](load_scene("paper-circle"))
    row = next(line for line in README.splitlines() if line.startswith("| `closed_loop_tension_aware`"))
    assert "tension_aware_dynamic_chordal" in row
    assert controller.dynamic and controller.chordal_correction


@pytest.mark.slow
def test_bending_free_claim_matches_the_run():
    """The README says the bending-free run at spectral radius 0.5 with the paper's springs
    stops at 0.37 s, the platform above the pulleys; with tension-only elements it is
    flung decimetres off its path (10 s), its cables slack for seconds. That motion is
    chaotic: changes of Newton's Jacobian that move no converged state gave 0.71, 0.14 and
    0.69 m, the node contact moved into the numba object (round-off: 0.27 s -> 0.37 s) 0.61 m,
    and Newton tolerances of 1e-6 / 1e-7 / 1e-8 give 0.69 / 0.34 / 0.62 m, so the
    test asserts what every run shares: 0.1 to 1 m, more than a second slack per cable, no
    element pushing, and the README's figure for the default tolerance."""
    from cdpr_exu import SolverFailure, load_scene, simulate
    from cdpr_exu.scenes.scene import Effects

    scene = load_scene("paper-circle")
    solver = replace(scene.solver, spectral_radius=0.5, end_time=1.5)
    springs = scene.with_changes(effects=Effects.from_preset("catenary", slack=False), solver=solver)
    with pytest.raises(SolverFailure, match="rose above the pulleys") as failure:
        simulate(springs)
    assert failure.value.time == pytest.approx(0.37, abs=0.005)
    assert "rises above the" in README and "stopped at 0.37 s" in README
    tension_only = scene.with_changes(effects=Effects.from_preset("catenary"),
                                      solver=replace(solver, end_time=10.0))
    summary = simulate(tension_only).summary()
    assert summary["status"] == "completed" and 0.1 < summary["max_position_error_m"] < 1.0
    assert min(summary["slack_time_per_cable_s"]) > 1.0 and not summary["elements_pushed"]
    assert "decimetres off its path" in README and f"{summary['max_position_error_m']:.2f}" in README


@pytest.mark.slow
def test_python_example_prints_the_controllers_table_figure(tmp_path, monkeypatch, capsys):
    """The README's example, run as written, prints the max error that the README's table shows."""
    monkeypatch.chdir(tmp_path)
    exec(compile(_python_example().replace("progress=True", "progress=False"), "README example", "exec"), {})
    printed = float(capsys.readouterr().out.split()[0])
    table = json.loads((ROOT / "results" / "controllers" / "summary.json").read_text())
    expected = 1000 * table["controllers"]["closed_loop_tension_aware"]["max_position_error_m"]
    assert printed == pytest.approx(expected, abs=0.006)  # printed to 0.01 mm
    row = next(line for line in README.splitlines() if line.startswith("| closed_loop_tension_aware |"))
    assert f"{expected:.2f}" == row.split("|")[2].strip()
    assert (tmp_path / "out" / "run" / "summary.json").is_file()


def _layout_section() -> str:
    """The README's "Layout" section: from its heading to the next heading."""
    return README.split("\n## Layout\n", 1)[1].split("\n## ", 1)[0]


def test_the_layout_section_names_every_module_example_and_benchmark():
    """Issue 23.19: the layout had drifted (feedback.py, ilc.py, spatial_feedback.py, three
    examples and the benchmarks were missing). Every .py file of the four source folders but
    the packages' __init__.py is named there, as a whole file name (``bending.py`` does not
    count as named by ``bench_bending.py``)."""
    layout = _layout_section()
    missing = [str(path.relative_to(ROOT))
               for folder in ("cdpr_exu", "controllers", "examples", "benchmarks")
               for path in sorted((ROOT / folder).rglob("*.py"))
               if path.name != "__init__.py" and not re.search(r"(?<![\w/.])" + re.escape(path.name), layout)]
    assert missing == [], f"name these in the README's Layout section: {missing}"


def test_virtual_environments_are_ignored_by_git():
    """Issue 23.19: a `.venv/` made in the clone (as the quick start invites) showed up in `git status`."""
    import subprocess

    for name in (".venv", "venv"):
        done = subprocess.run(["git", "check-ignore", "-q", f"{name}/bin/python"], cwd=ROOT)
        assert done.returncode == 0, f"{name}/ is not in .gitignore"


def _refresh_module():
    """examples/refresh_readme.py, imported from its path (examples/ is not a package)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("refresh_readme", ROOT / "examples" / "refresh_readme.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_refreshing_the_readme_and_docs_changes_nothing():
    """Issue 23.17: figures typed by hand drifted from the files that produced them. Every table
    and figure of README.md and docs/*.md marked with its source is what
    ``python examples/refresh_readme.py`` writes from that source now, so a regenerated result
    whose document was not refreshed fails here."""
    refresh = _refresh_module()
    stale = [str(path.relative_to(ROOT)) for path in refresh.documents(ROOT)
             if refresh.refreshed(path.read_text(), ROOT)[0] != path.read_text()]
    assert stale == [], f"run python examples/refresh_readme.py: {stale} differ from their sources"


def test_every_figure_marker_names_a_number_in_an_existing_file():
    refresh = _refresh_module()
    count = 0
    for path in refresh.documents(ROOT):
        for marker in refresh.markers(path.read_text()):
            source = ROOT / marker.group("path")
            assert source.is_file(), f"{path.name}: {marker.group(0)}"
            value = refresh.value_at(marker.group("path"), marker.group("keys"), ROOT)
            assert isinstance(value, (int, float)) and not isinstance(value, bool), marker.group(0)
            refresh.formatted(value, marker.group("spec"))
            count += 1
    assert count >= 20  # the README's measured figures are markers (issue 23.17)


def test_a_figure_marker_is_filled_from_its_source(tmp_path):
    """The marker syntax of examples/refresh_readme.py: keys, list filters (a quoted value may
    hold commas), units, a flipped sign and formats, from JSON, CSV and Markdown tables."""
    refresh = _refresh_module()
    (tmp_path / "r.json").write_text(json.dumps({"a": {"b": 0.018032, "d": -0.00325}, "rows": [
        {"n": 15, "step": 0.002, "e": 0.015332, "name": "full, step 2e-3 s"},
        {"n": 15, "step": 0.01, "e": 0.0153, "name": "full"}, {"n": 30, "step": 0.01, "e": 2.5}]}))
    (tmp_path / "t.csv").write_text("case,step_s\npaper,0.05\ncircle x4,0.02\n")
    (tmp_path / "t.md").write_text("# title\n\n| case | x real time |\n|---|---|\n| shipped (full, 0.01 s) | 2.50 |\n")
    text = ("x <!-- value: r.json#a.b | mm:1 -->?<!-- /value --> and "
            "<!-- value: r.json#rows.[n=15,step=2e-3].e | mm:.3g -->old<!-- /value -->, "
            "<!-- value: r.json#rows.-1.e | 1:.0e -->1<!-- /value --> <!-- value: r.json#rows.1.n | 1:0 --><!-- /value -->\n"
            '<!-- value: r.json#rows.[name="full, step 2e-3 s"].n | 1:0 -->?<!-- /value --> '
            "<!-- value: r.json#a.d | -mm:2 -->?<!-- /value --> "
            "<!-- value: t.csv#[case=circle x4].step_s | 1:2 -->?<!-- /value --> "
            '<!-- value: t.md#1.[0="shipped (full, 0.01 s)"].x real time | 1:1 -->?<!-- /value -->\n')
    new, tables, figures = refresh.refreshed(text, tmp_path)
    assert (tables, figures) == (0, 8)
    assert [m.group("body") for m in refresh.markers(new)] == ["18.0", "15.3", "2e+00", "15", "15", "3.25", "0.02",
                                                                "2.5"]
    assert refresh.refreshed(new, tmp_path)[0] == new
    with pytest.raises(KeyError, match="matches 2 elements"):
        refresh.value_at("r.json", "rows.[n=15].e", tmp_path)
    with pytest.raises(ValueError, match="not a number"):
        refresh.formatted("full", "1:0")
