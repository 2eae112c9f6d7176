"""``cdpr import caspr`` (cdpr_exu.scenes.caspr): scenes from CASPR's model files.

tests/data/caspr/ holds CASPR's CoGiRo and IPAnema 1 models in CASPR's own schema (each file
cites the commit of darwinlau/CASPR it copies). Imported, they are the shipped spatial-cogiro
and spatial-ipanema robots, which were transcribed from those files by hand; what CASPR says
that a scene cannot express is refused, naming the element, with nothing written.
"""

import re
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cdpr_exu.cli import main
from cdpr_exu.run.rest import solve_rest
from cdpr_exu.scenes.caspr import caspr_scene
from cdpr_exu.scenes.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data" / "caspr"


def _import(tmp_path, robot: str, *options: str):
    """The scene ``cdpr import caspr`` writes from ``robot``'s two files, loaded back."""
    out = tmp_path / f"{robot}.toml"
    assert main(["import", "caspr", str(DATA / f"{robot}_bodies.xml"), str(DATA / f"{robot}_cables.xml"),
                 "--out", str(out), *options]) == 0
    return load_scene(out)


def test_the_imported_cogiro_is_the_shipped_scene_with_caspr_s_tension_limits(tmp_path):
    imported, shipped = _import(tmp_path, "CoGiRo"), load_scene("spatial-cogiro")
    # exits, anchors moved from CASPR's reference point to the centre of mass, mass, the inertia's diagonal,
    # the cables and the unstrained lengths (the ideal ones at CASPR's initial pose less their stretch),
    # effects, winch and solver: equal to the digits the shipped scene gives (its TOML was made from the
    # same numbers, the anchors to CASPR's 4 decimals, the lengths to 5)
    assert replace(imported, name=shipped.name, description=shipped.description, trajectory=shipped.trajectory,
                   cables=tuple(replace(c, min_tension=None, max_tension=None) for c in imported.cables)) == shipped
    np.testing.assert_array_equal(imported.tension_limits, [[100.0, 5000.0]] * 8)  # CASPR's force_min, force_max
    # the initial pose, q_initial's reference point at (0, 0, 2) m plus the centre of mass, held
    np.testing.assert_allclose(imported.trajectory.pose(3.0), [-0.034, -0.013, 2.264, 0.0, 0.0, 0.0], atol=1e-12)
    assert imported.name == "CoGiRo" and imported.platform.inertia == (36.598, 35.982, 25.439)


def test_the_imported_ipanema_is_the_shipped_geometry_and_settles_near_caspr_s_initial_pose(tmp_path):
    imported = _import(tmp_path, "IPAnema_1", "--cable-set", "IROS_CASPR_2016", "--n-elements", "10")
    shipped = load_scene("spatial-ipanema")
    np.testing.assert_array_equal(imported.exit_points, shipped.exit_points)
    assert imported.platform == shipped.platform  # mass, inertia and anchors (CASPR's centre of mass is its joint)
    np.testing.assert_array_equal(imported.tension_limits[:, 0], 0.0)
    np.testing.assert_array_equal(imported.tension_limits[:, 1], [720.0] * 5 + [200.0] + [720.0] * 2)
    assert {c.n_elements for c in imported.cables} == {10}
    rest = solve_rest(imported)
    # The lengths hold the platform at CASPR's initial pose (0, 0, 1) m on straight cables; sag of the
    # default 0.14 kg/m steel at 140-330 N moves it by 0.28 mm (measured). 1 mm bounds that, while a
    # wrong anchor or exit moves it by decimetres.
    np.testing.assert_allclose(rest.position, [0.0, 0.0, 1.0], atol=1e-3)
    assert np.linalg.norm(rest.rotation) < 1e-3 and np.all(rest.anchor_tensions > 0.0)


def test_a_turned_initial_pose_and_an_inertia_about_the_joint_are_moved_to_the_centre_of_mass(tmp_path):
    mass, com = 91.058, np.array([-0.034, -0.013, 0.264])
    about_com = np.array([[36.598, -0.453, 3.012], [-0.453, 35.982, -1.539], [3.012, -1.539, 25.439]])
    about_joint = about_com + mass * (com @ com * np.eye(3) - np.outer(com, com))  # the parallel-axis rule
    text = (DATA / "CoGiRo_bodies.xml").read_text().replace("0 0 2.0 0 0 0", "0.5 0 2.0 0 0 0.5")
    text = text.replace('ref="com"', 'ref="joint"')
    for name, (i, j) in {"Ixx": (0, 0), "Iyy": (1, 1), "Izz": (2, 2), "Ixy": (0, 1), "Ixz": (0, 2), "Iyz": (1, 2)}.items():
        text = re.sub(f"<{name}>[^<]*</{name}>", f"<{name}>{float(about_joint[i, j])!r}</{name}>", text)
    (tmp_path / "turned_bodies.xml").write_text(text)
    scene, notes = caspr_scene(tmp_path / "turned_bodies.xml", DATA / "CoGiRo_cables.xml")
    # back about the centre of mass: round-off of moments of ~40 kg m^2, 1e-12
    np.testing.assert_allclose(scene.platform.inertia, np.diag(about_com), rtol=0, atol=1e-12)
    assert "[-0.453, 3.012, -1.539] kg m^2 left out" in notes[1]
    # q_initial's XYZ Euler angles (0, 0, 0.5 rad): a turn of 0.5 rad about z, which carries the centre of mass
    turn = np.array([[np.cos(0.5), -np.sin(0.5), 0.0], [np.sin(0.5), np.cos(0.5), 0.0], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(scene.trajectory.pose(0.0), [*([0.5, 0.0, 2.0] + turn @ com), 0.0, 0.0, 0.5],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(scene.platform.anchors[0], np.array([0.5032, -0.4928, 0.0]) - com, atol=1e-12)


def test_the_help_example_writes_a_scene(tmp_path):
    done = subprocess.run([sys.executable, "-m", "cdpr_exu.cli", "import", "caspr", "--help"], capture_output=True,
                          text=True, check=True, cwd=ROOT)
    example = next(line.split() for line in done.stdout.splitlines() if line.startswith("  cdpr import caspr tests/"))
    out = tmp_path / "cogiro.toml"
    assert example[-2:] == ["--out", "cogiro.toml"]
    arguments = [str(ROOT / a) if a.startswith("tests/") else a for a in example[1:-1]]
    assert main([*arguments, str(out)]) == 0 and "exit codes" in done.stdout
    assert load_scene(out).n_cables == 8
    assert "products of inertia about the centre of mass [-0.453, 3.012, -1.539] kg m^2 left out" in out.read_text()


def _edited(tmp_path, name: str, old: str, new: str) -> Path:
    """A copy of the test file ``name`` in ``tmp_path`` with every ``old`` made ``new``."""
    path = tmp_path / name
    path.write_text((DATA / name).read_text().replace(old, new))
    return path


REFUSALS = {
    "not_caspr": ("CoGiRo_cables.xml", "cables", "robot", None,
                  r"is not a CASPR cables file: its root element is <robot>, CASPR's is <cables>"),
    "not_xml": ("CoGiRo_bodies.xml", "<bodies_system>", "<bodies_system", None, r"is not XML \(.*line"),
    "two_links": ("CoGiRo_bodies.xml", "    </links>", "<link_rigid num=\"2\" name=\"arm\"/></links>", None,
                  r"<links> holds \['link_rigid', 'link_rigid'\]: .*multi-link bodies cannot be expressed"),
    "joint": ("CoGiRo_bodies.xml", "SPATIAL_EULER_XYZ", "PLANAR_XY", None,
              r"<link_rigid name='CoGiRo'>: <joint type='PLANAR_XY'> cannot be expressed"),
    "number": ("CoGiRo_bodies.xml", "-0.034 -0.013 0.264", "-0.034 -0.013", None,
               r"<com_location> must give 3 finite number\(s\), got '-0.034 -0.013'"),
    "cable_model": ("CoGiRo_cables.xml", "cable_ideal", "cable_linear_spring", None,
                    r"<cable_linear_spring name='cable 1'>: CASPR's cable model cable_linear_spring cannot"),
    "routing": ("CoGiRo_cables.xml", "</attachments>",
                "<attachment><link>1</link><location>0 0 0</location></attachment></attachments>", None,
                r"<cable_ideal name='cable 1'>: <attachments> on links \['0', '1', '1'\].*routing .* cannot be"),
    "no_limit": ("CoGiRo_cables.xml", "<force_max>5000</force_max>", "", None,
                 r"<cable_ideal name='cable 1'> has no <force_max>"),
    "cable_set": ("CoGiRo_cables.xml", "", "", "IROS_CASPR_2016",
                  r"no <cable_set id='IROS_CASPR_2016'>; it has \['original'\]"),
}


@pytest.mark.parametrize("case", REFUSALS.values(), ids=REFUSALS.keys())
def test_what_a_scene_cannot_express_is_refused_naming_the_element_and_nothing_is_written(tmp_path, capsys, case):
    name, old, new, cable_set, message = case
    files = {part: DATA / f"CoGiRo_{part}.xml" for part in ("bodies", "cables")}
    files[name.split("_")[1][:-4]] = _edited(tmp_path, name, old, new)
    out = tmp_path / "out" / "scene.toml"
    code = main(["import", "caspr", str(files["bodies"]), str(files["cables"]), "--out", str(out)]
                + (["--cable-set", cable_set] if cable_set else []))
    assert code == 2 and re.search(message, capsys.readouterr().err) and not out.parent.exists()


def test_a_missing_file_or_a_bad_material_is_refused_and_nothing_is_written(tmp_path, capsys):
    out = tmp_path / "scene.toml"
    assert main(["import", "caspr", str(tmp_path / "none.xml"), str(DATA / "CoGiRo_cables.xml"), "--out", str(out)]) == 2
    assert re.search(r"none.xml: cannot read the file: No such file", capsys.readouterr().err)
    assert main(["import", "caspr", str(DATA / "CoGiRo_bodies.xml"), str(DATA / "CoGiRo_cables.xml"), "--out", str(out),
                 "--radius", "-0.003"]) == 2
    assert "cable.radius must be positive [m], got -0.003" in capsys.readouterr().err and not out.exists()
