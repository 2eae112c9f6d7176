"""The linearised position loop (controllers/loop_design.py): a closed-form plant, and margins that the runs bear out."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.scenes.scene import Effects, load_scene
from controllers import loop_design


def test_the_linearised_robot_has_the_spring_mass_pole_of_a_massless_elastic_v():
    """Two straight elastic cables from fixed points (+-1.75, 0) m to a 1 kg point platform at (0, -1.75) m:
    at 45 degrees each cable is a spring k = EA / L_u along it plus the geometric stiffness T / l across, so
    both translations have k_x = k_z = k + T / l and the pole omega^2 = (k + T / l) / M."""
    fixed = load_scene("paper-catenary-fixed")
    scene = fixed.with_changes(cables=tuple(replace(c, linear_density=1e-4) for c in fixed.cables),
                               effects=Effects.from_preset("full", bending=False, bending_damping=False,
                                                                 axial_damping=False))
    robot = loop_design.linearise(scene, (0.0, -1.75))
    cable = scene.cables[0]
    length = 1.75 * np.sqrt(2.0)
    tension = scene.platform.mass * scene.gravity / np.sqrt(2.0)
    stiffness = cable.axial_rigidity / (length / (1.0 + tension / cable.axial_rigidity))
    expected = (stiffness + tension / length) / scene.platform.mass
    squared = np.sort(np.linalg.eigvals(np.linalg.solve(robot.mass, robot.stiffness)).real)
    nearest = squared[np.argsort(np.abs(squared - expected))[:2]]
    # the two translations; 1e-3: the cables' 5e-4 kg against the 1 kg platform (their own
    # modes are 300 times higher), and the central differences' 1e-7 relative step
    np.testing.assert_allclose(nearest, expected, rtol=1e-3)


def test_the_loop_design_refuses_what_it_does_not_model_naming_it():
    with pytest.raises(SceneError, match="planar two-cable"):
        loop_design.linearise(load_scene("spatial-four-cable"), (0.0, 0.0, 1.0))
    with pytest.raises(SceneError, match="cutoff must be positive"):
        loop_design.LoopGains(cutoff=0.0)
    with pytest.raises(SceneError, match="integral_gain must be zero or positive"):
        loop_design.LoopGains(integral_gain=-1.0)
