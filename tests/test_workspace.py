"""The workspace check: a reference the cables cannot reach or hold is refused before any run."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.studies.learning import learners
from controllers.registry import CONTROLLERS
from cdpr_exu.core.errors import UnreachableError
from cdpr_exu.exits import Pulley
from cdpr_exu.scenes.scene import CableSpec, Effects, PlatformSpec, Scene, SolverSpec, load_scene
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.trajectories import CircleTrajectory, PointToPointTrajectory
from cdpr_exu.statics.workspace import check_reference, reference_samples

PAPER = load_scene("paper-circle")


def _moving_to(end, **changes):
    trajectory = PointToPointTrajectory(start=(0.0, -2.0, 0.0), end=end, duration=2.0)
    return PAPER.with_changes(trajectory=trajectory, solver=replace(PAPER.solver, end_time=3.0), **changes)


@pytest.mark.parametrize("controller", sorted(CONTROLLERS))
def test_a_reference_above_the_pulleys_is_refused_before_the_run_for_every_controller(controller):
    scene = _moving_to((0.0, 1.0, 0.0))
    with pytest.raises(UnreachableError, match=r"at t = \d+\.\d+ s .*cannot hold the platform's weight") as err:
        options = {"learner": learners(scene)} if CONTROLLERS[controller].learns else {}
        simulate(scene, CONTROLLERS[controller](scene, **options))
    assert "platform.mass" in str(err.value) and "(x [m], z [m], rotation [rad])" in str(err.value)


def test_the_first_pose_refused_is_where_the_anchors_rise_to_the_pulley_tops():
    """Cables pull along the line to where they leave the rim; above the rim top they pull down only."""
    times, poses = reference_samples(_moving_to((0.0, 1.0, 0.0)))
    with pytest.raises(UnreachableError) as err:
        check_reference(_moving_to((0.0, 1.0, 0.0)))
    z = float(str(err.value).split("[")[1].split(",")[1])
    anchor_height = z + 0.1  # anchors sit h_p / 2 = 0.1 m above the platform centre
    # The pulley top is at z = +0.25; the first refused sample lies within one sample spacing above it.
    spacing = np.max(np.abs(np.diff(poses[:, 1])))
    assert 0.0 < anchor_height - 0.25 <= spacing + 1e-9


def test_an_anchor_inside_a_pulley_names_the_conflicting_fields_then_the_values():
    scene = _moving_to((-1.6, -0.3, 0.0))
    with pytest.raises(UnreachableError) as err:
        check_reference(scene)
    message = str(err.value)
    for field in ("platform.anchors[0]", "pulleys[0].center", "pulleys[0].radius", "t = "):
        assert field in message, field


def test_a_reference_needing_more_cable_than_there_is_names_the_cable_length():
    with pytest.raises(UnreachableError, match=r"cables\[\d\]\.unstrained_length"):
        check_reference(_moving_to((0.0, -4.5, 0.0)))


@pytest.mark.parametrize("preset", ["elastic", "ideal"])
def test_massless_ropes_reach_the_same_poses_whatever_n_elements_says(preset):
    """A massless rope has no elements: a pose needing about 3.5 of its 3.75 m is reachable at n = 4 and n = 80."""
    low = _moving_to((0.0, -2.6, 0.0), effects=Effects.from_preset(preset))
    verdicts = []
    for n in (4, 80):
        scene = low.with_changes(cables=tuple(replace(c, n_elements=n) for c in low.cables))
        check_reference(scene)  # must not raise
        verdicts.append(True)
    assert verdicts == [True, True]
    lumped = low.with_changes(effects=Effects.from_preset("full"),
                              cables=tuple(replace(c, n_elements=4) for c in low.cables))
    with pytest.raises(UnreachableError, match="one element"):  # a lumped cable keeps one element
        check_reference(lumped)


def test_the_circle_is_checked_at_its_extreme_poses_exactly():
    scene = PAPER.with_changes(trajectory=CircleTrajectory((0.0, -1.6), angular_rate=1.5))
    times, poses = reference_samples(scene)
    quarter = np.pi / 2 / 1.5
    for k in range(1, 4):
        assert np.min(np.abs(times - k * quarter)) < 1e-12
    assert poses[:, 1].max() == pytest.approx(-1.2, abs=1e-12)  # the top of the circle, sampled exactly


def test_the_shipped_scenes_pass_the_check():
    """Planar and spatial: one check (a spatial scene without a trajectory has nothing to follow)."""
    from cdpr_exu.scenes.scene import shipped_scenes

    for scene in map(load_scene, shipped_scenes()):
        check_reference(scene)


def _four_cables(end_rotation: float, duration: float):
    """A rigid planar platform on four cables (two pulleys above, two below, 1-60 N each) turning on the spot."""
    exits = (Pulley((-1.75, 0.0), 0.25, -1), Pulley((1.75, 0.0), 0.25, 1), Pulley((-1.75, -4.0), 0.25, -1),
             Pulley((1.75, -4.0), 0.25, 1))
    return Scene(cables=(CableSpec(min_tension=1.0, max_tension=60.0),) * 4, exits=exits,
                 platform=PlatformSpec(anchors=((-0.15, 0.1), (0.15, 0.1), (-0.15, -0.1), (0.15, -0.1))),
                 trajectory=PointToPointTrajectory(start=(0.0, -2.0, 0.0), end=(0.0, -2.0, end_rotation),
                                                   duration=duration),
                 solver=SolverSpec(end_time=duration + 0.5))


def test_a_planar_platform_on_three_cables_or_more_must_get_the_moment_its_rotation_needs():
    """One rule for both dimensions: a rigid platform with as many cables as its wrench has entries (3 in the
    plane, 6 in space) is asked the whole wrench (within tension limits, the moment its rotation needs). Turning 0.1 rad in 2 s is held within 1-60 N; in 50 ms it
    needs J phi'' of several N m (J = 0.0271 kg m^2), more than 60 N on 0.15 m arms can give."""
    check_reference(_four_cables(0.1, 2.0))
    with pytest.raises(UnreachableError, match=r"\(x \[m\], z \[m\], rotation \[rad\]\) at t = 0\.\d{3} s is "
                                               r"outside the workspace: .*moment about its centre of mass") as err:
        check_reference(_four_cables(0.1, 0.05))
    assert "platform.inertia = 0.0271 kg m^2" in str(err.value) and "max_tension = 60 N" in str(err.value)
    # without tension limits the cables must hold it at rest at each pose; the turn's dynamics is the run's
    unlimited = _four_cables(0.1, 0.05)
    check_reference(unlimited.with_changes(cables=tuple(replace(c, min_tension=None, max_tension=None)
                                                        for c in unlimited.cables)))
    # the paper's two cables cannot turn the platform: it turns to balance the moment, only the force is asked
    fast_turn = PointToPointTrajectory(start=(0.0, -2.0, 0.0), end=(0.0, -2.0, 0.1), duration=0.05)
    check_reference(PAPER.with_changes(trajectory=fast_turn, solver=replace(PAPER.solver, end_time=0.55)))


@pytest.mark.parametrize("preset", ["elastic", "ideal"])
def test_massless_ropes_run_to_the_same_path_whatever_n_elements_says(preset):
    """Issue 12.3 end to end: the same massless scene was refused at n_elements = 4 and ran at
    80. Both run now (a pose needing about 3.5 m of the 3.75 m ropes), to the same path: a
    massless rope has no elements, so n_elements changes nothing (measured: bit-identical)."""
    low = _moving_to((0.0, -2.6, 0.0), effects=Effects.from_preset(preset))
    paths = []
    for n in (4, 80):
        scene = low.with_changes(cables=tuple(replace(c, n_elements=n) for c in low.cables))
        result = simulate(scene)
        assert result.status == "completed" and result.time[-1] == pytest.approx(3.0)
        paths.append(result.pose)
    np.testing.assert_allclose(paths[0], paths[1], rtol=0.0, atol=1e-12)
    assert paths[0][-1, 1] == pytest.approx(-2.6, abs=2e-3)  # it got there (elastic ropes stretch 0.8 mm)
