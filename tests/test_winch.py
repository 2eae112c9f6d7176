"""Winches: the servo drum's gain design (python-control) and its tracking on the real solver."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.errors import SceneError
from cdpr_exu.scene import WinchSpec, load_scene
from cdpr_exu.simulate import simulate
from cdpr_exu.winch import servo_gains


def _closed_loop_poles(spec):
    a = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    b = np.array([[0.0], [0.0], [1.0 / spec.drum_mass]])
    return np.linalg.eigvals(a - b @ servo_gains(spec)[None, :])


def test_pole_placement_puts_the_servo_poles_where_asked():
    spec = WinchSpec(kind="servo", servo_bandwidth=40.0)
    poles = np.sort(_closed_loop_poles(spec).real)
    np.testing.assert_allclose(poles, [-48.0, -44.0, -40.0], rtol=1e-8)  # -w, -1.1 w, -1.2 w


def test_lqr_servo_is_stable_and_about_as_fast_as_asked():
    spec = WinchSpec(kind="servo", servo_design="lqr", servo_bandwidth=40.0)
    poles = _closed_loop_poles(spec)
    assert np.all(poles.real < 0)
    # Bryson weights aim at the bandwidth: the slowest pole within a factor 2 of it.
    assert 20.0 < np.min(np.abs(poles)) < 80.0


def test_bad_drum_parameters_are_refused():
    with pytest.raises(SceneError, match="winch.drum_radius"):
        WinchSpec(kind="servo", drum_radius=0.0)
    with pytest.raises(SceneError, match="winch.servo_design"):
        WinchSpec(kind="servo", servo_design="pid")


@pytest.mark.slow
def test_servo_winch_tracks_the_command_and_matches_the_kinematic_winch():
    scene = load_scene("paper-circle")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=3.0))
    kinematic = simulate(scene)
    servo = simulate(scene.with_changes(winch=WinchSpec(kind="servo")))
    assert servo.metadata["item_counts"]["servo_drums"] == 2
    # A 60 rad/s servo on a 2 kg equivalent drum: the paid-out length follows the
    # ideal-IK command to a few mm (tension disturbances of ~20 N, rates of 0.6 m/s).
    lag = np.abs(servo.paid_out - kinematic.paid_out)[servo.time > 0.5]
    assert lag.max() < 5e-3
    # ... so the platform moves as with the exact (kinematic) winch, to 5 mm.
    difference = np.linalg.norm(servo.platform_pose[:, :2] - kinematic.platform_pose[:, :2], axis=1)
    assert difference.max() < 5e-3
