"""Spatial scenes in TOML (cdpr_exu.scenes.scene with dimension = 3), real solver (their static mode:
tests/test_rest.py)."""

import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.scene import load_scene, scene_from_dict, shipped_scenes

#: The paper's catenary scene with fixed cable ends, written as a spatial scene in the
#: vertical x-z plane (y = 0): the same cables, elements, masses and bending.
PLANAR_AS_SPATIAL = {
    "name": "paper-catenary-fixed-3d", "dimension": 3, "gravity": 9.8,
    "cable": {"unstrained_length": 2.4748737341529163, "radius": 0.005, "linear_density": 0.35,
              "youngs_modulus": 1.0e9, "damping_constant": 1.0e9, "n_elements": 15},
    "cables": [{}, {}],
    "exits": [{"point": [-1.75, 0.0, 0.0]}, {"point": [1.75, 0.0, 0.0]}],
    "platform": {"mass": 1.0, "anchors": [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]},
}


def _cdpr(*args):
    return subprocess.run([sys.executable, "-m", "cdpr_exu.cli", *args], capture_output=True, text=True, timeout=300)


def test_the_one_loader_loads_the_shipped_spatial_scenes_beside_the_planar_ones():
    assert "spatial-four-cable" in shipped_scenes() and "paper-circle" in shipped_scenes()
    scene = load_scene("spatial-four-cable")
    assert scene.dimension == 3 and scene.n_cables == 4 and not scene.platform.is_point_mass
    assert scene.space.pose_size == 6 and load_scene("paper-circle").space.pose_size == 3


def test_run_and_the_accuracy_study_need_a_trajectory_on_a_spatial_scene(tmp_path):
    done = _cdpr("study", "accuracy", "spatial-four-cable", "--out", str(tmp_path / "study"))
    assert done.returncode == 2
    assert "no [trajectory]" in done.stderr and "cdpr static" in done.stderr
    assert not (tmp_path / "study").exists()  # refused before any run
    done = _cdpr("run", "spatial-four-cable")  # a static scene: no reference to follow
    assert done.returncode == 2 and "no [trajectory]" in done.stderr


@pytest.mark.parametrize("change, field", [
    (lambda d: d.update(exits=d["exits"][:1]), "exits"),
    (lambda d: d.update(effects={"preset": "ideal"}), "effects.preset"),
    (lambda d: d.update(cables=[{}, {"n_elements": 20}]), "cables\\[1\\].n_elements"),
    (lambda d: d.update(dimension=4), "dimension"),
    (lambda d: d.pop("exits"), "exits"),
    (lambda d: d.update(exits=[{"point": [0.0, 0.0, 0.0]}, {"point": [0.0, 0.0, 0.0]}]), "exit_point"),
    (lambda d: d.update(exits=[{"kind": "pulley", "center": [0.0, 0.0]}] * 2), "no such exit in a spatial scene"),
    (lambda d: d["platform"].update(initial_pose=[0.0] * 6), "platform.initial_pose"),
    (lambda d: d["platform"].update(anchors=[[0.0, 0.0, 0.0], [0.0, float("nan"), 0.0]]), "platform.anchors\\[1\\]"),
    (lambda d: d["platform"].update(mass=-1.0), "platform.mass"),
    (lambda d: d["cable"].update(radius=-0.005), "cables\\[0\\].radius"),
])
def test_a_bad_spatial_scene_is_refused_naming_the_field(change, field):
    data = json.loads(json.dumps(PLANAR_AS_SPATIAL))
    change(data)
    with pytest.raises(SceneError, match=field):
        scene_from_dict(data)


def test_a_spatial_scene_gets_the_planar_bending_damping_constant_only_with_effects_bending_damping():
    """c_theta = d_n J / l_e on every joint (the planar CableSpec.bending_damping); without
    effects.bending_damping the chains have no dampers (and no cost for them)."""
    import exudyn as exu

    from cdpr_exu.builder.robot_3d import build_spatial_robot, scene_chain_spec
    from cdpr_exu.statics.statics import catenary_platform

    scene = load_scene("spatial-four-cable")
    for damped in (True, False):
        changed = replace(scene, effects=replace(scene.effects, bending_damping=damped))
        mbs = exu.SystemContainer().AddSystem()
        items = build_spatial_robot(mbs, catenary_platform(changed), changed.unstrained_lengths, scene_chain_spec(changed))
        for cable, chain in zip(changed.cables, items.chains):
            if damped:
                assert chain.bending_damping == pytest.approx(np.full(len(chain.joints), cable.bending_damping),
                                                              rel=1e-12)
            else:
                assert chain.bending_damping is None and chain.bending_stiffness is not None


def test_a_misspelt_scene_name_lists_every_shipped_scene_and_the_likeliest_first(capsys):
    """Issue 23.7: `cdpr run spatial-cogiroo` listed only the planar scenes as alternatives."""
    from cdpr_exu.cli import main
    from cdpr_exu.scenes.scene import shipped_scenes

    assert main(["run", "spatial-cogiroo"]) == 2
    message = capsys.readouterr().err
    assert "no scene named 'spatial-cogiroo'; did you mean 'spatial-cogiro'? shipped scenes:" in message, message
    for name in shipped_scenes():
        assert name in message, name
    for misspelt, meant in (("paper-circel", "'paper-circle' or 'paper-circle-slow'"), ("ipanema", "'spatial-ipanema'")):
        with pytest.raises(SceneError, match=f"did you mean {meant}\\?"):
            load_scene(misspelt)
    with pytest.raises(SceneError, match="did you mean 'spatial-four-cable' or 'spatial-four-cable-swivel'"):
        load_scene("spatial-four")
