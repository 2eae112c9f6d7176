"""Scenes: TOML round trips, the paper's derived parameters, and refusal of bad input."""

import math
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.exits import Pulley
from cdpr_exu.scenes.scene import (
    CableSpec, Effects, PlatformSpec, Scene, SolverSpec, load_scene, save_scene,
    scene_from_dict, shipped_scenes,
)
from cdpr_exu.scenes.trajectories import CircleTrajectory


def test_paper_circle_is_shipped_and_has_table_2_parameters():
    scene = load_scene("paper-circle")
    cable = scene.cables[0]
    # Table 2 of the paper, printed to three significant figures there.
    assert cable.axial_stiffness == pytest.approx(3.14e5, rel=2e-3)
    assert cable.axial_damping == pytest.approx(3.14e5, rel=2e-3)
    assert cable.bending_stiffness == pytest.approx(1.96, rel=3e-3)
    assert cable.bending_damping == pytest.approx(1.96, rel=3e-3)
    assert cable.element_mass == pytest.approx(0.0875, rel=1e-12)
    assert scene.platform.mass == 2.5 and scene.platform.inertia == 0.0271
    assert scene.exits[0].center == (-1.75, 0.0) and scene.exits[1].center == (1.75, 0.0)
    assert isinstance(scene.trajectory, CircleTrajectory)
    np.testing.assert_allclose(scene.trajectory.pose(0.0), [0.0, -2.0, 0.0], atol=1e-15)
    assert "paper-circle" in shipped_scenes()


def test_scene_survives_a_toml_round_trip(tmp_path):
    scene = load_scene("paper-circle")
    again = load_scene(save_scene(scene, tmp_path / "scene.toml"))
    assert again == scene


@pytest.mark.parametrize("lumping", ["consistent", "paper"])
def test_node_masses_add_up_to_the_cable_mass_or_one_half_element_more(lumping):
    cable = CableSpec(n_elements=15, mass_lumping=lumping)
    masses = cable.node_masses()
    assert masses.shape == (16,)
    # Consistent lumping conserves the mass exactly; the paper's lumping puts a whole
    # element on every node but the winch node, which gets half an element as well.
    expected = cable.mass if lumping == "consistent" else cable.mass + cable.element_mass / 2
    assert masses.sum() == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize(
    "make, field",
    [
        (lambda: CableSpec(radius=-0.005), "cable.radius"),
        (lambda: CableSpec(unstrained_length=0.0), "cable.unstrained_length"),
        (lambda: CableSpec(linear_density=float("nan")), "cable.linear_density"),
        (lambda: CableSpec(youngs_modulus=-1.0), "cable.youngs_modulus"),
        (lambda: CableSpec(n_elements=1), "cable.n_elements"),
        (lambda: CableSpec(n_elements=0), "cable.n_elements"),
        (lambda: CableSpec(n_elements=2.5), "cable.n_elements"),
        (lambda: CableSpec(mass_lumping="lumpy"), "cable.mass_lumping"),
        (lambda: Pulley(radius=0.0), "pulley.radius"),
        (lambda: Pulley(contact_stiffness=-1e7), "pulley.contact_stiffness"),
        (lambda: Pulley(side=0), "pulley.side"),
        (lambda: Pulley(center=(0.0,)), "pulley.center"),
        (lambda: PlatformSpec(mass=-2.5), "platform.mass"),
        (lambda: PlatformSpec(mass=0.0), "platform.mass"),
        (lambda: PlatformSpec(inertia=float("inf")), "platform.inertia"),
        (lambda: PlatformSpec(anchors=((0.1, 0.2, 0.3, 0.4),)), "platform.anchors"),
        (lambda: Scene(platform=PlatformSpec(anchors=((0.1, 0.2, 0.3),) * 2, inertia=(1.0, 1.0, 1.0))),
         "platform.anchors"),  # a spatial platform in a planar scene
        (lambda: PlatformSpec(anchors=(0.1, 0.2)), "platform.anchors"),
        (lambda: PlatformSpec(initial_pose=(0.0, float("nan"), 0.0)), "platform.initial_pose"),
        (lambda: SolverSpec(step_size=0.0), "solver.step_size"),
        (lambda: SolverSpec(spectral_radius=1.5), "solver.spectral_radius"),
        (lambda: Effects(bending=False, bending_damping=True), "effects.bending_damping"),
        (lambda: Effects.from_preset("nonsense"), "effects.preset"),
    ],
)
def test_bad_fields_are_refused_with_their_name(make, field):
    with pytest.raises(SceneError, match=field.replace(".", r"\.")):
        make()


def test_toml_errors_name_the_cable_they_come_from():
    data = {
        "name": "x",
        "cable": {"radius": 0.005},
        "cables": [{}, {"radius": -1.0}],
        "pulleys": [{"center": [-1.75, 0.0], "side": -1}, {"center": [1.75, 0.0], "side": 1}],
    }
    with pytest.raises(SceneError, match=r"cables\[1\]\.radius"):
        scene_from_dict(data)


def test_unknown_fields_are_refused():
    with pytest.raises(SceneError, match="unknown field"):
        scene_from_dict({"name": "x", "pulleys": [{"center": [0, 0], "colour": "red"}]})
    with pytest.raises(SceneError, match="unknown field"):
        scene_from_dict({"name": "x", "solver": {"stepsize": 1e-3}})


def test_a_pose_the_cables_cannot_reach_is_refused_before_any_simulation():
    with pytest.raises(SceneError, match=r"cables\[0\]\.unstrained_length"):
        Scene(cables=(CableSpec(unstrained_length=2.0), CableSpec(unstrained_length=2.0)))


def test_anchor_count_must_match_the_cables():
    with pytest.raises(SceneError, match="platform.anchors"):
        Scene(platform=PlatformSpec(anchors=((0.0, 0.0),)))


def test_unknown_scene_name_lists_the_shipped_ones():
    with pytest.raises(SceneError, match="paper-circle"):
        load_scene("no-such-scene")


def test_effects_presets_and_overrides():
    full = Effects.from_preset("full")
    assert full.bending and full.pulley_contact
    catenary = Effects.from_preset("catenary")
    assert catenary.cable_mass and not catenary.bending and not catenary.bending_damping
    assert not Effects.from_preset("full", bending=False, bending_damping=False).bending


def test_element_properties_follow_the_beam_equivalence_formulas():
    cable = CableSpec(radius=0.01, unstrained_length=2.0, n_elements=4, youngs_modulus=2e9, damping_constant=3e8)
    area, second_moment, length = math.pi * 1e-4, math.pi * 1e-8 / 4, 0.5
    assert cable.axial_stiffness == pytest.approx(2e9 * area / length, rel=1e-14)
    assert cable.axial_damping == pytest.approx(3e8 * area / length, rel=1e-14)
    assert cable.bending_stiffness == pytest.approx(2e9 * second_moment / length, rel=1e-14)
    assert cable.bending_damping == pytest.approx(3e8 * second_moment / length, rel=1e-14)


def test_solver_output_period_is_never_finer_than_the_step():
    solver = SolverSpec(step_size=2e-3, output_period=1e-3)
    assert solver.output_period == 2e-3
    assert replace(solver, end_time=1.0).n_steps == 500


def test_an_initial_pose_with_an_anchor_inside_a_pulley_names_the_fields_then_the_values():
    """Issue 12.2: the refusal said only "anchor [-0.15, -1.9] lies inside the pulley disc
    (centre [-1.75, 0.0], radius 2.5 m)"; it names the conflicting fields first now."""
    from cdpr_exu.core.errors import UnreachableError

    data = load_scene("paper-circle").to_dict()
    data["pulleys"][0]["radius"] = 2.5  # the disc reaches the anchor at the initial pose
    with pytest.raises(UnreachableError) as err:
        scene_from_dict(data)
    message = str(err.value)
    assert message.startswith("platform.anchors[0] at platform.initial_pose [0.0, -2.0, 0.0]")
    for field in ("pulleys[0].center [-1.75, 0.0] m", "pulleys[0].radius 2.5 m"):
        assert field in message, field
    assert message.index("pulleys[0].radius") < message.index("lies inside the pulley disc")


def test_the_package_exports_what_a_user_needs_and_imports_without_exudyn():
    """Issue 11.13: ``cdpr_exu.load_scene`` raised AttributeError. The names a user needs
    are importable from the package (loaded on first use, so the import stays cheap)."""
    import subprocess
    import sys

    code = ("import sys, cdpr_exu; assert 'exudyn' not in sys.modules, 'import cdpr_exu loaded Exudyn'; "
            "print(cdpr_exu.load_scene.__module__)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and done.stdout.strip() == "cdpr_exu.scenes.scene", done.stderr

    import importlib

    import cdpr_exu
    from controllers import ideal_ik, tension_aware

    errors, result, scene = (importlib.import_module(f"cdpr_exu.{m}")
                             for m in ("core.errors", "results.result", "scenes.scene"))
    # ``cdpr_exu.simulate`` is the function (the module is ``cdpr_exu.run.simulate``).
    assert callable(cdpr_exu.simulate) and "simulate" in cdpr_exu.__all__
    expected = {"load_scene": scene.load_scene, "save_scene": scene.save_scene, "Scene": scene.Scene,
                "Result": result.Result, "CdprError": errors.CdprError,
                "SceneError": errors.SceneError, "UnreachableError": errors.UnreachableError,
                "SolverFailure": errors.SolverFailure, "RunInterrupted": errors.RunInterrupted,
                "OutputError": errors.OutputError, "IdealIKController": ideal_ik.IdealIKController,
                "TensionAwareController": tension_aware.TensionAwareController,
                "ClosedLoopTensionAwareController": tension_aware.ClosedLoopTensionAwareController}
    for name, value in expected.items():
        assert getattr(cdpr_exu, name) is value, name
        assert name in cdpr_exu.__all__ and name in dir(cdpr_exu), name
    for name in cdpr_exu.__all__:  # every advertised name resolves
        assert getattr(cdpr_exu, name) is not None, name
    controller = cdpr_exu.CONTROLLERS["closed_loop_tension_aware"](cdpr_exu.load_scene("paper-circle"))  # the README's form
    assert isinstance(controller, cdpr_exu.ClosedLoopTensionAwareController)
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        cdpr_exu.no_such_name  # noqa: B018


def test_an_initial_pose_above_the_pulleys_is_refused_naming_it_before_any_run():
    """Issue 23.6: a platform started above the pulleys ran, and its failure was blamed on "cable
    slipping through the pulley ... use more elements". Anchors at z = 0.4 m, pulley tops at 0.25 m."""
    from cdpr_exu.core.errors import UnreachableError

    data = load_scene("paper-circle").to_dict()
    data["platform"]["initial_pose"] = [0.0, 0.3, 0.0]
    with pytest.raises(UnreachableError) as err:
        scene_from_dict(data)
    message = str(err.value)
    assert message.startswith("platform.initial_pose [0.0, 0.3, 0.0] (x [m], z [m], rotation [rad]) is above the "
                              "pulleys"), message
    assert "platform.anchors[0] at z = 0.4 m, pulleys[0] up to z = 0.25 m" in message
    assert "cables cannot push" in message
    data["gravity"] = 0.0  # without weight nothing has to hold it up: not this refusal
    assert scene_from_dict(data).platform.initial_pose == (0.0, 0.3, 0.0)


# --------------------------------------------------------------------------- one scene, both dimensions (issue 24)


def test_the_public_load_scene_loads_both_dimensions_into_the_one_scene_class():
    import cdpr_exu
    from cdpr_exu.space import PLANE, SPACE

    planar, spatial = cdpr_exu.load_scene("paper-circle"), cdpr_exu.load_scene("spatial-cogiro")
    assert type(planar) is type(spatial) is cdpr_exu.Scene
    assert (planar.dimension, planar.space, spatial.dimension, spatial.space) == (2, PLANE, 3, SPACE)
    assert {"paper-circle", "spatial-cogiro"} <= set(cdpr_exu.shipped_scenes())
    assert cdpr_exu.shipped_scenes() == sorted(cdpr_exu.shipped_scenes())


@pytest.mark.parametrize("name", shipped_scenes())
def test_every_shipped_scene_saves_in_its_form_and_loads_back_equal(name, tmp_path):
    scene = load_scene(name)
    text = save_scene(scene, tmp_path / "scene.toml").read_text()
    planar_form = scene.dimension == 2  # the shipped planar scenes have all pulleys or all point exits
    assert ("[[pulleys]]" in text, "cable_exit" in text, "[[exits]]" in text) == (planar_form, planar_form,
                                                                                 not planar_form)
    assert load_scene(tmp_path / "scene.toml") == scene


@pytest.mark.parametrize("name, table", [
    ("paper-circle", lambda pulley: {"kind": "pulley", **pulley}),
    ("paper-catenary-fixed", lambda pulley: {"point": pulley["center"]}),  # kind = "point", the default
])
def test_a_planar_scene_in_the_exits_form_is_the_scene_of_its_planar_form(name, table):
    planar = load_scene(name)
    data = planar.to_dict()
    data["exits"] = [table(pulley) for pulley in data.pop("pulleys")]
    del data["cable_exit"]
    assert scene_from_dict(data) == planar
    data["dimension"] = 2
    assert scene_from_dict(data) == planar


def test_a_planar_scene_takes_exits_that_all_wrap_or_all_none():
    from cdpr_exu.exits import PointExit

    scene = load_scene("paper-catenary-fixed")
    assert scene.exits_table == "pulleys"
    # the planar builder lays every cable over its pulley, or every cable from its point, so far
    with pytest.raises(SceneError, match="cable 1 leaves a point while cable 0 wraps"):
        scene.with_changes(exits=(Pulley((-1.75, 0.0), 0.25, -1), PointExit((1.75, 0.0))))


@pytest.mark.parametrize("data, words", [
    ({"dimension": 3, "pulleys": [{"center": [0.0, 0.0]}]}, "scene has unknown field(s) ['pulleys']"),
    ({"dimension": 3, "cable_exit": "point", "exits": []}, "scene has unknown field(s) ['cable_exit']"),
    ({"dimension": 2, "exits": [{"kind": "swivel", "inlet": [0.0, 0.0, 0.0]}]},
     "exits[0].kind = 'swivel': no such exit in a planar scene"),
    ({"dimension": 3, "exits": [{"point": [0.0, 0.0]}]}, "exits[0].point must be a finite 3-vector (x, y, z) [m]"),
    ({"dimension": 2, "exits": [{"point": [0.0, 0.0]}], "cables": [{}], "platform": {}},
     "lacks trajectory: a scene file must give [trajectory]"),
    ({"dimension": 3, "exits": [{"point": [0.0, 0.0, 0.0]}], "platform": {}}, "lacks cables"),
])
def test_each_form_takes_its_own_tables_in_its_dimension(data, words):
    with pytest.raises(SceneError) as caught:
        scene_from_dict({"name": "x", **data})
    assert words in str(caught.value)


def test_a_scene_and_its_platform_are_of_one_dimension():
    spatial = load_scene("spatial-four-cable")
    assert spatial.platform.space is spatial.space and spatial.platform.initial_pose is None
    assert spatial.platform.size is None and len(spatial.platform.inertia) == 3
    with pytest.raises(SceneError, match=r"platform.anchors must be \(x, y, z\) points in a spatial scene"):
        spatial.with_changes(platform=PlatformSpec(mass=5.0, anchors=((0.0, 0.0),) * 4))
    with pytest.raises(SceneError, match=r"platform.anchors must be \(x, z\) points in a planar scene"):
        spatial.with_changes(dimension=2)
    with pytest.raises(SceneError, match=r"exits\[0\] is a 3-D 'point' exit; a planar scene"):
        spatial.with_changes(dimension=2, platform=PlatformSpec(mass=5.0, anchors=((0.0, 0.0),) * 4))
    planar = load_scene("paper-circle")
    assert planar.platform.size == (0.3, 0.2) and planar.exit_points.shape == (2, 2)
    assert spatial.exit_points.shape == (4, 3) and spatial.exit_tops.tolist() == spatial.exit_points[:, 2].tolist()
