"""Chain statics: the simulator's own lumped cables at rest, against Exudyn and closed forms."""

from dataclasses import replace

import numpy as np
import pytest

from cdpr_exu.statics import statics
from cdpr_exu.statics.chain_statics import ChainRobot, chain_forces, chain_robot, solve_chain_statics
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.builder.model import initial_nodes
from cdpr_exu.scenes.scene import Effects, PlatformSpec, load_scene
from cdpr_exu.statics.statics import catenary_platform

PAPER = load_scene("paper-circle")


def _solve(scene, position, **kwargs):
    """Chain statics of ``scene`` at ``position``, started from its catenary statics."""
    start = statics.solve_inverse_statics(catenary_platform(scene), position)
    return solve_chain_statics(chain_robot(scene), position, start.rotation,
                               tension_guess=[c.tension_at_anchor for c in start.cables], **kwargs)


def test_the_equilibrium_balances_every_node_and_the_platform():
    solution = _solve(PAPER, (0.25, -1.7))
    node_forces, platform_wrench = chain_forces(chain_robot(PAPER), solution.nodes, solution.position,
                                                solution.rotation)
    # Forces of order 10 N; 1e-7 N is the solver's tolerance, far above rounding (1e-10 N).
    assert np.abs(node_forces).max() < 1e-6
    assert np.abs(platform_wrench).max() < 1e-6
    assert np.all(solution.anchor_tensions > 5.0)  # a 2.5 kg platform on two cables
    # the anchors sit where the pose puts them
    anchors = np.array([n[-1] for n in solution.nodes])
    c, s = np.cos(solution.rotation), np.sin(solution.rotation)
    expected = solution.position + np.asarray(PAPER.platform.anchors) @ np.array([[c, s], [-s, c]])
    assert np.allclose(anchors, expected, atol=1e-12)


@pytest.mark.slow
def test_it_finds_the_rest_that_exudyn_finds_with_the_same_winch_lengths():
    """Independent check: the scene settled by the real solver (dynamics, then Exudyn's
    static solver) with the winches held; chain statics at that platform position must
    give back the winches' lengths, the rotation and every node."""
    from cdpr_exu.run.rest import solve_rest

    scene = PAPER.with_changes(platform=replace(PAPER.platform, initial_pose=(0.3, -1.8, 0.0)))
    rest = solve_rest(scene)
    held = np.array([scene.cables[i].unstrained_length - (scene.exits[i].center[1] - initial_nodes(scene, i)[0, 1])
                     for i in range(2)])
    solution = _solve(scene, rest.platform_position_m)
    # Exudyn's rest is an equilibrium to ~1e-11 N and its nodes to ~1e-7 m (rest.py notes);
    # an axial stiffness of 3e5 N/m turns 1e-6 m of node error into 0.3 N, so lengths
    # and nodes are compared at the micrometre.
    assert np.abs(solution.paid_out - held).max() < 5e-6
    assert solution.rotation == pytest.approx(np.radians(rest.platform_rotation_deg), abs=1e-5)
    for ours, exudyn in zip(solution.nodes, rest.nodes):
        assert np.abs(ours - exudyn).max() < 5e-6
    assert np.allclose(solution.anchor_tensions, rest.anchor_tensions_N, rtol=1e-4)


def _catenary_scene(n_elements, lumping="consistent"):
    """The paper's cable between fixed exit points, no bending: the catenary's own model."""
    scene = load_scene("paper-catenary-fixed")
    cables = tuple(replace(c, n_elements=n_elements, mass_lumping=lumping) for c in scene.cables)
    return scene.with_changes(cables=cables, effects=Effects.from_preset("catenary", pulley_contact=False))


def test_without_bending_it_converges_to_the_elastic_catenary_at_second_order():
    """The chain's free span, from its winch node to the anchor, against the catenary
    hung between the same two points: the catenary needs the chain's unstrained length."""
    position = (0.2, -1.6)
    errors = []
    for n in (10, 20, 40):
        scene = _catenary_scene(n)
        chain = _solve(scene, position)
        platform = catenary_platform(scene)
        hung = statics.SuspendedPlatform(
            tuple(replace(c, exit_point=tuple(nodes[0])) for c, nodes in zip(platform.cables, chain.nodes)),
            platform.mass, platform.gravity, platform.inertia)
        catenary = statics.solve_inverse_statics(hung, position)
        length = scene.cables[0].unstrained_length
        errors.append(np.abs(catenary.unstrained_lengths - length).max())
        assert catenary.rotation == pytest.approx(chain.rotation, abs=10 * errors[-1])
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    # consistent lumping: the chain is a second-order discretisation of the catenary
    assert np.all(orders > 1.8), (errors, orders)
    assert errors[-1] < 1e-4


def test_massless_straight_cables_give_hookes_law():
    scene = _catenary_scene(8)
    robot = chain_robot(scene)
    robot = ChainRobot(tuple(replace(c, node_masses=(0.0,) * len(c.node_masses)) for c in robot.cables),
                       robot.mass, robot.gravity)
    position = np.array([0.2, -1.6])
    solution = solve_chain_statics(robot, position, tension_guess=[10.0, 10.0])
    for cable, nodes, tensions, paid in zip(robot.cables, solution.nodes, solution.tensions, solution.paid_out):
        span = np.linalg.norm(position - np.asarray(cable.pulley.point))
        ea = cable.axial_stiffness * cable.element_length
        assert np.ptp(tensions) < 1e-9 * tensions.max()  # no weight: one tension along the cable
        # node 0 sits on the vertical through the exit point, lambda - L0 above it
        assert nodes[0] == pytest.approx(np.asarray(cable.pulley.point) + [0.0, paid - cable.unstrained_length],
                                         abs=1e-12)
        straight = np.linalg.norm(nodes[-1] - nodes[0])
        assert straight / (1.0 + tensions[0] / ea) == pytest.approx(cable.unstrained_length, rel=1e-9)
        assert span > 0


def test_a_continued_solution_equals_a_fresh_one():
    first = _solve(PAPER, (0.10, -1.9))
    continued = solve_chain_statics(chain_robot(PAPER), (0.12, -1.88), guess=first)
    fresh = _solve(PAPER, (0.12, -1.88))
    assert np.abs(continued.paid_out - fresh.paid_out).max() < 1e-8
    assert continued.rotation == pytest.approx(fresh.rotation, abs=1e-8)


def test_an_inertial_load_changes_the_lengths_as_the_static_load_would():
    """d'Alembert: -M a along x is the same load as a horizontal external force."""
    platform = catenary_platform(PAPER)
    wrench = statics.inertial_wrench(platform, np.array([0.5, 0.0]), 0.0)
    with_load = _solve(PAPER, (0.0, -1.8), external_wrench=wrench)
    without = _solve(PAPER, (0.0, -1.8))
    assert wrench[0] == pytest.approx(-0.5 * PAPER.platform.mass)
    # pushed to -x, the platform needs more cable on the left winch side... the
    # lengths must move apart in opposite directions by millimetres
    change = with_load.paid_out - without.paid_out
    assert change[0] * change[1] < 0
    assert 1e-4 < np.abs(change).max() < 0.05


def test_bad_input_is_refused_with_the_parameter_named():
    robot = chain_robot(PAPER)
    with pytest.raises(SceneError, match="position"):
        solve_chain_statics(robot, (np.nan, -1.8), tension_guess=[10.0, 10.0])
    with pytest.raises(SceneError, match="tension_guess"):
        solve_chain_statics(robot, (0.0, -1.8), tension_guess=[10.0, -1.0])
    with pytest.raises(SceneError, match="guess or tension_guess"):
        solve_chain_statics(robot, (0.0, -1.8))
    with pytest.raises(SceneError, match="as many cables as platform equations"):
        solve_chain_statics(robot, (0.0, -1.8), free_rotation=False, tension_guess=[10.0, 10.0])
    with pytest.raises(SceneError, match="node_masses"):
        replace(robot.cables[0], node_masses=(0.1, -0.1, 0.1))
    with pytest.raises(SceneError, match="pulley"):
        replace(robot.cables[0], pulley=(0.0, 0.0))
    with pytest.raises(SceneError, match="cable_mass"):
        chain_robot(PAPER.with_changes(effects=Effects.from_preset("elastic")))
    with pytest.raises(SceneError, match="bending_model"):
        chain_robot(PAPER.with_changes(effects=Effects.from_preset("full", bending_model="linear")))


def test_a_pose_the_cables_cannot_hold_is_refused():
    # above the pulleys' line the cables would have to push the platform up
    robot = chain_robot(PAPER)
    with pytest.raises(UnreachableError):
        solve_chain_statics(robot, (0.0, 0.3), tension_guess=[10.0, 10.0])


def test_point_mass_platform_needs_no_rotation():
    scene = _catenary_scene(10).with_changes(
        platform=PlatformSpec(mass=1.0, inertia=0.01, anchors=((0.0, 0.0), (0.0, 0.0)), initial_pose=(0.0, -1.7, 0.0)))
    robot = chain_robot(scene)
    assert robot.is_point_mass
    solution = solve_chain_statics(robot, (0.3, -1.5), tension_guess=[8.0, 8.0])
    assert solution.rotation == 0.0
    _, wrench = chain_forces(robot, solution.nodes, solution.position)
    assert np.abs(wrench[:2]).max() < 1e-6
