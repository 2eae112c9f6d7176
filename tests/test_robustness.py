"""The robustness study (cdpr_exu/studies/robustness.py): plants off their model, rows that resume."""

from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.studies import robustness


def test_a_perturbed_plant_is_the_shipped_mismatch_and_hands_its_controllers_the_model():
    """spatial-cogiro with the platform +10 % and the cables' density -10 % is spatial-cogiro-mismatch: the same
    plant, and the same model behind it (its [controller_model])."""
    model, shipped = load_scene("spatial-cogiro"), load_scene("spatial-cogiro-mismatch")
    plant = robustness.perturbed(model, platform_mass=0.1, cable_density=-0.1)
    # 1e-6: the shipped file writes them to 7 digits (100.1638 kg, 40.2578 kg m^2)
    np.testing.assert_allclose([plant.platform.mass, *plant.platform.inertia, plant.cables[0].linear_density],
                               [shipped.platform.mass, *shipped.platform.inertia, shipped.cables[0].linear_density],
                               rtol=1e-6)
    believed = plant.controller_scene()
    assert (believed.platform, believed.cables) == (model.platform, model.cables)
    with pytest.raises(SceneError, match="cable_density must be a relative error above -1"):
        robustness.perturbed(model, cable_density=-1.0)


def test_a_corner_with_stiffer_cables_and_pulleys_3_mm_further_out_is_a_plant_its_controllers_do_not_see():
    """The grid's other axes (issue 27, item 1), one corner: Young's modulus +20 % and each pulley 3 mm further
    out. The controllers get the model back (exits and cables); the plant's pulleys are 3.506 m apart. The run
    starts at rest on the plant at the reference pose (its own equilibrium), so ideal IK's length changes are
    off only in their direction, by about 3 mm / 2.5 m = 1.2e-3 rad: over a short run the path moves by far less
    than a millimetre from the nominal plant's, but it moves."""
    from cdpr_exu.run.simulate import simulate
    from controllers.ideal_ik import IdealIKController

    model = load_scene("paper-circle")
    model = model.with_changes(solver=replace(model.solver, end_time=0.2, output_period=0.01))
    plant = robustness.perturbed(model, cable_stiffness=0.2, exit_offset=0.003)
    assert [e.center for e in plant.exits] == [(-1.753, 0.0), (1.753, 0.0)]
    assert plant.cables[0].youngs_modulus == pytest.approx(1.2 * model.cables[0].youngs_modulus, rel=1e-12)
    believed = plant.controller_scene()
    assert (believed.exits, believed.cables) == (model.exits, model.cables)
    assert [e.center[0] for e in robustness.perturbed(model, exit_offset=-0.003).exits] == [-1.747, 1.747]
    nominal, corner = simulate(model, IdealIKController()), simulate(plant, IdealIKController())
    assert corner.status == "completed"
    moved = np.abs(corner.pose[:, :2] - nominal.pose[:, :2]).max()
    assert 0.0 < moved < 1e-3
    with pytest.raises(SceneError, match="exit_offset moves pulleys"):
        robustness.perturbed(load_scene("spatial-four-cable"), exit_offset=0.003)


def test_a_study_writes_each_row_as_it_ends_and_resumes_without_running_it_again(tmp_path):
    scene = load_scene("paper-circle")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=0.1, output_period=0.01))
    grid = robustness.error_grid((0.0, 0.2), (0.0,))
    controllers = {"tension_aware_relative": ("tension_aware", {"start": "relative"})}
    with ThreadPoolExecutor(1) as pool:
        rows = robustness.run_robustness(scene, controllers, grid, tmp_path, after=0.0, executor=pool, progress=False)
    assert [(r["platform_mass"], r["controller"], r["status"]) for r in rows] == [
        (m, c, "completed") for m in (0.0, 0.2) for c in ("ideal_ik", "tension_aware_relative")]
    assert all(r["max_error_vs_ideal_ik"] > 0 for r in rows)
    journal = (tmp_path / "rows.jsonl").read_text()
    assert len(journal.splitlines()) == 4

    class Refuses:
        def submit(self, *args, **kwargs):
            raise AssertionError("a finished row was run again")

    again = robustness.run_robustness(scene, controllers, grid, tmp_path, after=0.0, executor=Refuses(), progress=False)
    assert again == rows and (tmp_path / "rows.jsonl").read_text() == journal
    assert "| tension_aware_relative | 2/2 |" in (tmp_path / "robustness.md").read_text()
    assert (tmp_path / "robustness_tension_aware_relative.png").is_file()
