"""Spatial chain statics: the lumped spatial cables at rest, against Exudyn's static solve and the catenaries."""

from dataclasses import replace

import exudyn as exu
import numpy as np
import pytest

from cdpr_exu.builder.spatial_robot import build_spatial_robot
from cdpr_exu.core.errors import SceneError
from cdpr_exu.physics.spatial_statics import solve_spatial_statics
from cdpr_exu.run.spatial_rest import PENALTY, solve_spatial_rest
from cdpr_exu.scenes.spatial_scene import load_spatial_scene
from cdpr_exu.statics.spatial_chain_statics import spatial_chain_robot, spatial_chain_statics

FOUR = load_spatial_scene("spatial-four-cable")


def _scene(n_elements, bending=True, point_mass=False):
    """spatial-four-cable with ``n_elements`` per cable, bending on or off, a rigid or point-mass platform."""
    effects = FOUR.effects if bending else replace(FOUR.effects, bending=False, bending_damping=False)
    platform = replace(FOUR.platform, anchors=((0.0, 0.0, 0.0),) * 4) if point_mass else FOUR.platform
    return FOUR.with_changes(cables=tuple(replace(c, n_elements=n_elements) for c in FOUR.cables),
                             effects=effects, platform=platform)


@pytest.mark.parametrize("bending, point_mass", [(True, False), (False, False), (True, True)])
def test_the_chain_statics_reproduce_exudyns_static_solution(bending, point_mass):
    scene = _scene(10, bending, point_mass)
    exudyn = solve_spatial_rest(scene)  # penalty joints on a rigid platform, exact ones on a point mass
    factor = None if point_mass else PENALTY
    chain = spatial_chain_statics(scene, factor)
    # The same discrete model: Exudyn's Newton stops at a residual of 1e-9, ours at 1e-9 N; with element
    # stiffnesses ~3e5 N/m that is 1e-14 m. Measured: 2e-14 m and 1e-12 rad (bending), 1e-15 m (none).
    # 1e-10 m is 4 orders below the penalty joints' compliance (below) and 6 below the bending's effect.
    assert np.abs(chain.position - exudyn.position).max() < 1e-10
    assert np.abs(chain.rotation_vector - exudyn.rotation_vector).max() < 1e-10
    assert max(np.abs(a - b).max() for a, b in zip(chain.nodes, exudyn.nodes)) < 1e-10
    # element forces ~10-40 N: measured 7e-11 N apart
    assert max(np.abs(a - b).max() for a, b in zip(chain.tensions, exudyn.element_tensions)) < 1e-8
    # the anchor forces: Exudyn reads the penalty spring's force, 3e7 N/m x 1e-13 m -> measured 3e-6 N
    assert np.abs(chain.forces_on_platform - exudyn.forces_on_platform).max() < 1e-4
    assert chain.tensions[0].min() > 0.0  # all taut: the tension-only law and the static mode's springs agree


def test_the_penalty_joints_move_the_rigid_platform_by_their_compliance():
    scene = _scene(10)
    exact, penalty = spatial_chain_statics(scene), spatial_chain_statics(scene, PENALTY)
    robot = spatial_chain_robot(scene, PENALTY)
    # each penalty spring gives by T / (f k): 1.2e-6 m at 40 N; measured 1.9e-6 m of platform motion
    give = max(t / (PENALTY * c.axial_stiffness) for t, c in zip(penalty.tensions_at_anchor, robot.cables))
    shift = np.abs(exact.position - penalty.position).max()
    assert 0.1 * give < shift < 3.0 * give


def test_the_equilibrium_balances_the_platform():
    scene = _scene(10)
    chain = spatial_chain_statics(scene)
    weight = np.array([0.0, 0.0, -scene.platform.mass * scene.gravity])
    arms = np.array(scene.platform.anchors) @ chain.rotation.T
    # forces ~40 N, weight 49 N; the solver's tolerance 1e-9 N
    assert np.abs(chain.forces_on_platform.sum(axis=0) + weight).max() < 1e-8
    assert np.abs(np.cross(arms, chain.forces_on_platform).sum(axis=0)).max() < 1e-8
    # the last node sits on its anchor (exact joints)
    assert np.abs(np.array([n[-1] for n in chain.nodes]) - (chain.position + arms)).max() < 1e-12


def test_the_model_is_the_builders():
    scene = _scene(10)
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, scene.catenary_platform(), scene.unstrained_lengths, scene.chain_spec())
    robot = spatial_chain_robot(scene)
    for cable, masses, k, k_theta in zip(robot.cables, items.node_masses, items.axial_stiffnesses,
                                         items.bending_stiffnesses):
        assert np.array_equal(cable.node_masses, masses)  # the same lumping, to the last bit
        assert cable.axial_stiffness == k and cable.bending_stiffness == k_theta


def test_without_bending_the_chains_converge_to_the_catenaries_as_n_squared():
    errors = []
    for n in (10, 20, 40):
        chain = spatial_chain_statics(_scene(n, bending=False))
        catenary = solve_spatial_statics(FOUR.catenary_platform(), FOUR.unstrained_lengths)
        errors.append((np.linalg.norm(chain.position - catenary.position),
                       np.linalg.norm(chain.rotation_vector - catenary.rotation_vector),
                       np.abs(chain.tensions_at_anchor - catenary.tensions_at_anchor).max()))
    errors = np.array(errors)
    # measured 7.3e-5, 1.8e-5, 4.6e-6 m: ratios 3.995 and 3.999 (and 4.02, 4.00 in rotation and tension)
    assert errors[0, 0] < 1e-4
    ratios = errors[:-1] / errors[1:]
    assert np.all((ratios > 3.8) & (ratios < 4.2))


def test_swivel_exits_are_refused_naming_them():
    with pytest.raises(SceneError, match="swivel"):
        spatial_chain_robot(load_spatial_scene("spatial-four-cable-swivel"))


# --- the inverse: lengths whose chains hold a pose -------------------------------------------------

IPANEMA = load_spatial_scene("spatial-ipanema")


def _ipanema(n_elements=10):
    """spatial-ipanema (8 taut cables, bending on) with ``n_elements`` per cable."""
    return IPANEMA.with_changes(cables=tuple(replace(c, n_elements=n_elements) for c in IPANEMA.cables))


def _catenary_start(scene, robot, pose):
    """Lengths and nodes of the catenary inverse at ``pose``: the start the controller takes."""
    from cdpr_exu.core.geometry import rotation_from_vector
    from cdpr_exu.physics.spatial_statics import solve_cable, solve_inverse_spatial_statics

    platform = scene.catenary_platform()
    rest = solve_spatial_statics(platform, scene.unstrained_lengths)
    inverse = solve_inverse_spatial_statics(platform, pose, [c.catenary.horizontal_tension for c in rest.cables])
    points = pose[:3] + np.array(platform.anchors) @ rotation_from_vector(pose[3:6]).T
    nodes = [solve_cable(c, length, point)[0].points(length - np.linspace(0.0, length, chain.n_elements + 1))
             for c, chain, length, point in zip(platform.cables, robot.cables, inverse.unstrained_lengths, points)]
    return inverse.unstrained_lengths, nodes


def test_the_inverse_chain_statics_at_the_rest_pose_give_back_the_lengths_it_rests_on():
    from cdpr_exu.statics.spatial_chain_statics import solve_inverse_spatial_chain_statics

    scene = _ipanema()
    robot = spatial_chain_robot(scene)
    rest = spatial_chain_statics(scene)
    pose = np.concatenate([rest.position, rest.rotation_vector])
    inverse = solve_inverse_spatial_chain_statics(robot, pose, rest.tensions_at_anchor,
                                                  *_catenary_start(scene, robot, pose))
    # Eight lengths hold six equations: with the rest tensions as the target, the answer is the
    # lengths the robot rests on. Measured 4e-15 m apart after one iteration from the catenary start
    # (3e-9 m off), tensions to 2e-8 N (the rest's tolerance, 1e-9 N on 2e6 N/m elements, is 1e-15 m).
    assert np.abs(inverse.unstrained_lengths - scene.unstrained_lengths).max() < 1e-12
    assert np.abs(inverse.tensions - rest.tensions_at_anchor).max() < 1e-6


@pytest.mark.parametrize("point_mass", [False, True])
def test_the_forward_chain_statics_of_the_inverse_lengths_put_the_platform_back_on_the_pose(point_mass):
    from cdpr_exu.core.geometry import rotation_from_vector
    from cdpr_exu.statics.spatial_chain_statics import (robot_paid_out, solve_inverse_spatial_chain_statics,
                                                        solve_spatial_chain_statics)

    scene = _scene(10, point_mass=True) if point_mass else _ipanema()  # 4 cables on a point mass; IPAnema's 8
    robot = spatial_chain_robot(scene)
    rest = spatial_chain_statics(scene)
    # 0.1 m and 0.02 rad off the rest, with the d'Alembert force of the platform accelerating at (2, -1, 0) m/s^2
    pose = np.concatenate([rest.position + [0.1, -0.05, 0.05], rest.rotation_vector + [0.0, 0.0, 0.02]])
    if point_mass:
        pose[3:] = 0.0
    inertial = -scene.platform.mass * np.array([2.0, -1.0, 0.0])
    lengths, nodes = _catenary_start(scene, robot, pose)
    inverse = solve_inverse_spatial_chain_statics(robot, pose, rest.tensions_at_anchor, lengths, nodes,
                                                  np.concatenate([inertial, np.zeros(3)]))
    assert np.all(inverse.tensions > 0.0)
    # the forward statics of these lengths, started 1 mm and 1 mrad away, find the pose again
    forward = solve_spatial_chain_statics(robot_paid_out(robot, inverse.unstrained_lengths), inverse.nodes,
                                          pose[:3] + 1e-3, rotation_from_vector(pose[3:] + 1e-3),
                                          external_force=inertial)
    assert forward.iterations >= 2
    # The inverse balances the platform to 1e-9 of its largest force and its chains to their rounding
    # floor (4e-8 N on IPAnema's 2e6 N/m elements), as does the forward solve.
    # Measured: 2e-15 m and 2e-15 rad (IPAnema), 2.3e-11 m (four cables on a point mass); a pose
    # off by 1e-9 m would leave about 2e-3 N on IPAnema's cables.
    assert np.abs(forward.position - pose[:3]).max() < 1e-9
    assert np.abs(forward.rotation_vector - (0.0 if point_mass else pose[3:])).max() < 1e-9
