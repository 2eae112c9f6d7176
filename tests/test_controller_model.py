"""The controllers' model apart from the plant (scene ``[controller_model]``, issue 13 item 4)."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import ControllerModel, Effects, load_scene, save_scene, scene_from_dict
from cdpr_exu.statics.statics import solve_statics
from controllers.tension_aware import TensionAwareController
from cdpr_exu.statics.statics import catenary_platform

from conftest import v_shaped_scene

MISMATCH = load_scene("paper-circle-mismatch")


def test_the_mismatch_plant_differs_from_what_its_controllers_believe():
    model = MISMATCH.controller_scene()
    assert (MISMATCH.platform.mass, model.platform.mass) == (2.75, 2.5)
    assert MISMATCH.platform.inertia == pytest.approx(1.1 * model.platform.inertia)
    assert [c.linear_density for c in MISMATCH.cables] == [0.315, 0.315]
    assert [c.linear_density for c in model.cables] == [0.35, 0.35]
    # The rest is the plant's: geometry, elasticity, effects, reference, and no model of its own.
    assert model.exits == MISMATCH.exits and model.trajectory == MISMATCH.trajectory
    assert model.effects == MISMATCH.effects and model.effects.slack
    assert [c.youngs_modulus for c in model.cables] == [c.youngs_modulus for c in MISMATCH.cables]
    assert model.controller_model is None
    paper = load_scene("paper-circle")
    assert paper.controller_model is None and paper.controller_scene() is paper


def test_a_controller_model_survives_the_toml_round_trip(tmp_path):
    scene = MISMATCH.with_changes(controller_model=ControllerModel(
        cable={"linear_density": 0.35}, cables=({"youngs_modulus": 0.9e9}, {"n_elements": 10}),
        platform={"mass": 2.5, "anchors": [[-0.16, 0.1], [0.15, 0.1]]}, pulley={"radius": 0.24}, gravity=9.81))
    again = load_scene(save_scene(scene, tmp_path / "scene.toml"))
    assert again == scene
    model = again.controller_scene()
    assert [c.youngs_modulus for c in model.cables] == [0.9e9, 1.0e9]
    assert [c.n_elements for c in model.cables] == [15, 10]
    assert model.platform.anchors[0] == (-0.16, 0.1) and model.gravity == 9.81
    assert {p.radius for p in model.exits} == {0.24}


@pytest.mark.parametrize("table, words", [
    ({"platfrom": {"mass": 2.0}}, r"controller_model has unknown field\(s\) \['platfrom'\]"),
    ({"platform": {"masss": 2.0}}, r"controller_model.platform has unknown .*\['masss'\]"),
    ({"platform": {"initial_pose": [0, -2, 0]}}, r"controller_model.platform .*\['initial_pose'\]"),
    ({"cable": {"max_tension": 100.0}}, r"controller_model.cable .*\['max_tension'\]"),
    ({"cables": [{"radius": 0.004}]}, r"controller_model.cables must list one table per cable \(2\), got 1"),
    ({"platform": {"mass": -2.5}}, r"controller_model.platform.mass"),
    ({"cable": {"n_elements": 1}}, r"controller_model.cables\[0\].n_elements"),
    ({"gravity": -9.8}, r"controller_model.gravity"),
    ({"cables": {"radius": 0.004}}, r"controller_model.cables must be an array of tables"),
])
def test_a_bad_controller_model_is_refused_naming_the_field(table, words):
    data = MISMATCH.to_dict()
    data["controller_model"] = table
    with pytest.raises(SceneError, match=words):
        scene_from_dict(data)


def test_the_run_hands_the_controllers_their_model_not_the_plant():
    """The tension-aware commands on the mismatch plant are those on a plant with the model's
    values, to the last bit; on the plant's own values they differ."""
    short = replace(MISMATCH.solver, end_time=0.05)
    mismatch = MISMATCH.with_changes(solver=short)
    as_model = mismatch.controller_scene()  # a plant that is what the controllers believe
    knows_plant = mismatch.with_changes(controller_model=None)
    runs = [simulate(scene, TensionAwareController(dynamic=True)) for scene in (mismatch, as_model, knows_plant)]
    np.testing.assert_array_equal(runs[0].paid_out, runs[1].paid_out)
    # The heavier platform stretches the cables: knowing it, the controller hauls in less
    # (measured 0.014 mm at 0.05 s, inside the start-up blend; 3.4 mm at 1 s); the plants differ.
    assert np.abs(runs[2].paid_out - runs[0].paid_out).max() > 1e-5
    assert not np.allclose(runs[0].pose, runs[1].pose, atol=1e-7, rtol=0)


def test_the_plant_hangs_where_the_catenary_statics_of_its_own_parameters_put_it():
    """A V of two cables holding a point mass, at rest: the plant (1.1 kg, 0.315 kg/m) sags
    below the controllers' model (1.0 kg, 0.35 kg/m) by what the elastic catenaries predict
    for the two parameter sets (7.02 mm)."""
    plant = v_shaped_scene(platform_mass=1.1, n_elements=12, effects=Effects.from_preset("catenary"))
    plant = plant.with_changes(cables=tuple(replace(c, linear_density=0.315) for c in plant.cables),
                               controller_model=ControllerModel(platform={"mass": 1.0}, cable={"linear_density": 0.35}))
    model = plant.controller_scene()
    lengths = [c.unstrained_length for c in plant.cables]
    predicted = (solve_statics(catenary_platform(plant), lengths).position
                 - solve_statics(catenary_platform(model), lengths).position)
    simulated = simulate(plant).pose[-1, :2] - simulate(model).pose[-1, :2]
    assert predicted[1] < -5e-3  # the plant hangs lower by millimetres
    # The lumped cables miss the catenary's sag by a lumping error that falls as 1/n^2:
    # measured 0.24 mm with 6 elements, 0.061 mm with 12, 0.015 mm with 24.
    np.testing.assert_allclose(simulated, predicted, atol=2e-4)
