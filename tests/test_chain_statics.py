"""Chain statics: the simulator's own lumped cables at rest, in the plane and in space, against Exudyn,
closed forms and the catenaries."""

from dataclasses import replace

import exudyn as exu
import numpy as np
import pytest

from cdpr_exu.builder.model import initial_nodes
from cdpr_exu.builder.robot_3d import build_spatial_robot, scene_chain_spec, swivel_angles
from cdpr_exu.run.settle import chain_statics_robot, set_configuration, solve_static
from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.run.rest import PENALTY, solve_rest
from cdpr_exu.scenes.scene import Effects, PlatformSpec, load_scene
from cdpr_exu.statics import chain_statics, statics
from cdpr_exu.statics.chain_kernels import SpatialChains
from cdpr_exu.statics.chain_statics import (ChainRobot, cable_paid_out, chain_forces, chain_rest, chain_robot,
                                            robot_paid_out, solve_chain_statics, solve_inverse_chain_statics)
from cdpr_exu.statics.statics import catenary_platform, solve_statics

PAPER = load_scene("paper-circle")
FOUR = load_scene("spatial-four-cable")


def _solve(scene, position, **kwargs):
    """Planar chain statics of ``scene`` at ``position``, started from its catenary statics."""
    start = statics.solve_inverse_statics(catenary_platform(scene), position)
    return solve_inverse_chain_statics(chain_robot(scene), (*position, start.rotation),
                                       tension_guess=[c.tension_at_anchor for c in start.cables], **kwargs)


def _scene(n_elements, bending=True, point_mass=False):
    """spatial-four-cable with ``n_elements`` per cable, bending on or off, a rigid or point-mass platform."""
    effects = FOUR.effects if bending else replace(FOUR.effects, bending=False, bending_damping=False)
    platform = replace(FOUR.platform, anchors=((0.0, 0.0, 0.0),) * 4) if point_mass else FOUR.platform
    return FOUR.with_changes(cables=tuple(replace(c, n_elements=n_elements) for c in FOUR.cables),
                             effects=effects, platform=platform)


def _catenary_scene(n_elements, lumping="consistent"):
    """The paper's cable between fixed exit points, no bending: the catenary's own model."""
    scene = load_scene("paper-catenary-fixed")
    cables = tuple(replace(c, n_elements=n_elements, mass_lumping=lumping) for c in scene.cables)
    return scene.with_changes(cables=cables, effects=Effects.from_preset("catenary", pulley_contact=False))


# ---------------------------------------------------------------------------
# both dimensions
# ---------------------------------------------------------------------------
def _equilibrium(dimension):
    """A scene, its chain robot and an equilibrium: the paper's robot held at (0.25, -1.7) m (plane), the
    four-cable robot at rest on 10 elements per cable (space)."""
    if dimension == 2:
        return PAPER, chain_robot(PAPER), _solve(PAPER, (0.25, -1.7))
    scene = _scene(10)
    return scene, chain_robot(scene), chain_rest(scene)


def _node_forces(robot, equilibrium):
    """Net force on every node between the held ends [N], from the potential's gradient (space) or the
    nodal forces (plane), and the platform's wrench."""
    if robot.space.dimension == 2:
        return chain_forces(robot, equilibrium.nodes, equilibrium.position, equilibrium.rotation)
    model = SpatialChains(robot)
    p = np.concatenate(equilibrium.nodes)
    G = model.point_derivatives(p, np.zeros(0))[0]
    return -G.reshape(-1, 3)[model.free], None


@pytest.mark.parametrize("dimension", [2, 3])
def test_the_equilibrium_balances_every_node_and_the_platform(dimension):
    scene, robot, equilibrium = _equilibrium(dimension)
    space = robot.space
    node_forces, platform_wrench = _node_forces(robot, equilibrium)
    # Forces of order 10 N; 1e-7 N is the planar solver's tolerance (the spatial one's 1e-9 N), far above
    # rounding (1e-10 N).
    assert np.abs(node_forces).max() < 1e-6
    if platform_wrench is not None:
        assert np.abs(platform_wrench).max() < 1e-6
    # the platform: the cables' forces on it carry its weight and their moments cancel (forces ~10-40 N)
    weight = np.zeros(space.dimension)
    weight[space.vertical] = -scene.platform.mass * scene.gravity
    rotation = space.rotation_matrix(equilibrium.pose[space.position_size:])
    arms = np.asarray(scene.platform.anchors) @ rotation.T
    balance = {2: 1e-6, 3: 1e-8}[dimension]  # ten times the solver's tolerance: 1e-7 N (plane), 1e-9 N (space)
    assert np.abs(equilibrium.forces_on_platform.sum(axis=0) + weight).max() < balance
    in_3d = ((0, 0), (0, 3 - dimension))
    moments = np.cross(np.pad(arms, in_3d), np.pad(equilibrium.forces_on_platform, in_3d))
    assert np.abs(moments.sum(axis=0)).max() < balance
    assert np.all(equilibrium.anchor_tensions > 5.0)  # a 2.5 kg (5 kg) platform on two (four) cables
    # the anchors sit where the pose puts them (exact joints)
    anchors = np.array([n[-1] for n in equilibrium.nodes])
    assert np.abs(anchors - (equilibrium.position + arms)).max() < 1e-12


def _catenary_errors(dimension, n):
    """How far the chains of ``n`` elements without bending are from the catenaries. Plane: the chain's free
    span, from its winch node to the anchor, against the catenary hung between the same two points (the
    catenary needs the chain's unstrained length: its length error [m]). Space: the four-cable robot's rest
    against its catenary statics (position [m], rotation [rad], anchor tensions [N])."""
    if dimension == 2:
        position = (0.2, -1.6)
        scene = _catenary_scene(n)
        chain = _solve(scene, position)
        platform = catenary_platform(scene)
        hung = statics.SuspendedPlatform(
            tuple(replace(c, exit_point=tuple(nodes[0])) for c, nodes in zip(platform.cables, chain.nodes)),
            platform.mass, platform.gravity, platform.inertia)
        catenary = statics.solve_inverse_statics(hung, position)
        error = np.abs(catenary.unstrained_lengths - scene.cables[0].unstrained_length).max()
        assert catenary.rotation == pytest.approx(chain.rotation, abs=10 * error)
        return [error]
    chain = chain_rest(_scene(n, bending=False))
    catenary = solve_statics(catenary_platform(FOUR), FOUR.unstrained_lengths)
    return [np.linalg.norm(chain.position - catenary.position),
            np.linalg.norm(chain.rotation_vector - catenary.rotation),
            np.abs(chain.tensions_at_anchor - catenary.tensions_at_anchor).max()]


@pytest.mark.parametrize("dimension", [2, 3])
def test_without_bending_the_chains_converge_to_the_catenaries_at_second_order(dimension):
    errors = np.array([_catenary_errors(dimension, n) for n in (10, 20, 40)])
    orders = np.log2(errors[:-1] / errors[1:])
    # consistent lumping: the chain is a second-order discretisation of the catenary
    assert np.all(orders > 1.8), (errors, orders)
    assert errors[-1 if dimension == 2 else 0, 0] < 1e-4
    if dimension == 3:
        # measured 7.3e-5, 1.8e-5, 4.6e-6 m: ratios 3.995 and 3.999 (and 4.02, 4.00 in rotation and tension)
        ratios = errors[:-1] / errors[1:]
        assert np.all((ratios > 3.8) & (ratios < 4.2))


@pytest.mark.parametrize("dimension", [2, 3])
def test_the_inverse_at_an_equilibriums_pose_gives_back_its_lengths(dimension):
    """The planar inverse is the plane's chain statics; in space the inverse at the rest pose, started 0.3 mm
    off, finds the lengths the robot rests on."""
    scene, robot, equilibrium = _equilibrium(dimension)
    again = solve_inverse_chain_statics(robot, equilibrium.pose,
                                        guess=replace(equilibrium, paid_out=equilibrium.paid_out + 3e-4))
    # both converge to their solvers' tolerance: 1e-7 N (plane) and 1e-9 relative (space) on ~3e5 N/m elements
    assert np.abs(again.paid_out - equilibrium.paid_out).max() < 1e-8
    assert np.abs(again.tensions_at_anchor - equilibrium.tensions_at_anchor).max() < 1e-5


def _refusals():
    planar, spatial = chain_robot(PAPER), chain_robot(_scene(4))
    p, s = planar.cables[0], spatial.cables[0]
    return [
        (2, lambda: solve_inverse_chain_statics(planar, (np.nan, -1.8), tension_guess=[10.0, 10.0]), "position"),
        (2, lambda: solve_inverse_chain_statics(planar, (0.0, -1.8), tension_guess=[10.0, -1.0]), "tension_guess"),
        (2, lambda: solve_inverse_chain_statics(planar, (0.0, -1.8)), "guess or tension_guess"),
        (2, lambda: solve_inverse_chain_statics(planar, (0.0, -1.8), free_rotation=False, tension_guess=[10.0, 10.0]),
         "as many cables as platform equations"),
        (2, lambda: solve_inverse_chain_statics(planar, (0.0, -1.8, 0.0, 0.0)), "pose"),
        (2, lambda: solve_inverse_chain_statics(planar, (0.0, -1.8), lengths=[1.0, 1.0]), "lengths"),
        (2, lambda: replace(p, node_masses=(0.1, -0.1, 0.1)), "node_masses"),
        (2, lambda: replace(p, pulley=(0.0, 0.0)), "pulley"),
        (2, lambda: replace(p, exit_point=(0.0, 0.0, 0.0)), "exit_point"),
        (2, lambda: chain_robot(PAPER.with_changes(effects=Effects.from_preset("elastic"))), "cable_mass"),
        (2, lambda: chain_robot(PAPER.with_changes(effects=Effects.from_preset("full", bending_model="linear"))),
         "bending_model"),
        (2, lambda: chain_robot(PAPER, anchor_spring_factor=1e3), "anchor_spring_factor"),
        (2, lambda: chain_robot(PAPER.with_changes(effects=Effects.from_preset("full", pulley_contact_model="segment"))),
         "pulley_contact_model"),
        (2, lambda: chain_robot(PAPER.with_changes(effects=Effects.from_preset("full", pulley_contact_model="node_smooth"))),
         "pulley_contact_model"),
        (2, lambda: solve_chain_statics(planar, [], (0.0, -1.8)), "solve_inverse_chain_statics"),
        (2, lambda: ChainRobot((p, s), 1.0, 9.81), "cables must all be planar or all spatial"),
        (3, lambda: solve_inverse_chain_statics(spatial, np.zeros(6), [10.0] * 4), "lengths and nodes"),
        (3, lambda: solve_inverse_chain_statics(spatial, np.zeros(5), [10.0] * 4, lengths=[1.0] * 4,
                                                nodes=[np.zeros((5, 3))] * 4), "pose"),
        (3, lambda: solve_inverse_chain_statics(spatial, np.zeros(6), [10.0, -1.0, 10.0, 10.0], lengths=[1.0] * 4,
                                                nodes=[np.zeros((5, 3))] * 4), "tension_guess"),
        (3, lambda: solve_inverse_chain_statics(spatial, np.zeros(6), [10.0] * 4, free_rotation=True), "free_rotation"),
        (3, lambda: solve_chain_statics(spatial, [np.zeros((5, 3))] * 3, np.zeros(3)), "nodes"),
        (3, lambda: solve_chain_statics(spatial, [np.zeros((5, 3))] * 4, (np.nan, 0.0, 0.0)), "position"),
        (3, lambda: replace(s, node_masses=(0.1, -0.1, 0.1, 0.1, 0.1)), "node_masses"),
        (3, lambda: replace(s, exit_point=None), "exit_point"),
        (3, lambda: replace(s, pulley=PAPER.exits[0]), "pulley"),
        (3, lambda: replace(s, winch_travel=0.1), "winch_travel"),
        (3, lambda: replace(spatial, anchor_spring_factor=-1.0), "anchor_spring_factor"),
        (3, lambda: cable_paid_out(s, -1.0), "length"),
        (3, lambda: robot_paid_out(spatial, [1.0] * 3), "lengths"),
        (3, lambda: chain_robot(FOUR.with_changes(effects=Effects.from_preset("full", bending_model="linear"))),
         "bending_model"),
    ]


@pytest.mark.parametrize("dimension", [2, 3])
def test_bad_input_is_refused_with_the_parameter_named(dimension):
    cases = [(call, match) for d, call, match in _refusals() if d == dimension]
    assert cases
    for call, match in cases:
        with pytest.raises(SceneError, match=match):
            call()


# ---------------------------------------------------------------------------
# the plane
# ---------------------------------------------------------------------------
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
    solution = _solve(scene, rest.position)
    # Exudyn's rest is an equilibrium to ~1e-11 N and its nodes to ~1e-7 m (rest.py notes);
    # an axial stiffness of 3e5 N/m turns 1e-6 m of node error into 0.3 N, so lengths
    # and nodes are compared at the micrometre.
    assert np.abs(solution.paid_out - held).max() < 5e-6
    assert solution.rotation == pytest.approx(rest.rotation, abs=1e-5)
    for ours, exudyn in zip(solution.nodes, rest.nodes):
        assert np.abs(ours - exudyn).max() < 5e-6
    assert np.allclose(solution.anchor_tensions, rest.anchor_tensions, rtol=1e-4)


def test_massless_straight_cables_give_hookes_law():
    scene = _catenary_scene(8)
    robot = chain_robot(scene)
    robot = ChainRobot(tuple(replace(c, node_masses=(0.0,) * len(c.node_masses)) for c in robot.cables),
                       robot.mass, robot.gravity)
    position = np.array([0.2, -1.6])
    solution = solve_inverse_chain_statics(robot, position, tension_guess=[10.0, 10.0])
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
    continued = solve_inverse_chain_statics(chain_robot(PAPER), (0.12, -1.88), guess=first)
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


def test_a_pose_the_cables_cannot_hold_is_refused():
    # above the pulleys' line the cables would have to push the platform up
    robot = chain_robot(PAPER)
    with pytest.raises(UnreachableError):
        solve_inverse_chain_statics(robot, (0.0, 0.3), tension_guess=[10.0, 10.0])


def test_point_mass_platform_needs_no_rotation():
    scene = _catenary_scene(10).with_changes(
        platform=PlatformSpec(mass=1.0, inertia=0.01, anchors=((0.0, 0.0), (0.0, 0.0)), initial_pose=(0.0, -1.7, 0.0)))
    robot = chain_robot(scene)
    assert robot.is_point_mass
    solution = solve_inverse_chain_statics(robot, (0.3, -1.5), tension_guess=[8.0, 8.0])
    assert solution.rotation == 0.0
    _, wrench = chain_forces(robot, solution.nodes, solution.position)
    assert np.abs(wrench[:2]).max() < 1e-6


# ---------------------------------------------------------------------------
# space
# ---------------------------------------------------------------------------
@pytest.mark.parametrize("bending, point_mass", [(True, False), (False, False), (True, True)])
def test_the_chain_statics_reproduce_exudyns_static_solution(bending, point_mass):
    scene = _scene(10, bending, point_mass)
    exudyn = solve_rest(scene)  # penalty joints on a rigid platform, exact ones on a point mass
    factor = None if point_mass else PENALTY
    chain = chain_rest(scene, factor)
    # The same discrete model: Exudyn's Newton stops at a residual of 1e-9, ours at 1e-9 N; with element
    # stiffnesses ~3e5 N/m that is 1e-14 m. Measured: 2e-14 m and 1e-12 rad (bending), 1e-15 m (none).
    # 1e-10 m is 4 orders below the penalty joints' compliance (below) and 6 below the bending's effect.
    assert np.abs(chain.position - exudyn.position).max() < 1e-10
    assert np.abs(chain.rotation_vector - exudyn.rotation).max() < 1e-10
    assert max(np.abs(a - b).max() for a, b in zip(chain.nodes, exudyn.nodes)) < 1e-10
    # element forces ~10-40 N: measured 7e-11 N apart
    assert max(np.abs(a - b).max() for a, b in zip(chain.tensions, exudyn.tensions)) < 1e-8
    # the anchor forces: Exudyn reads the penalty spring's force, 3e7 N/m x 1e-13 m -> measured 3e-6 N
    assert np.abs(chain.forces_on_platform - exudyn.platform_forces).max() < 1e-4
    assert chain.tensions[0].min() > 0.0  # all taut: the tension-only law and the static mode's springs agree


def test_the_penalty_joints_move_the_rigid_platform_by_their_compliance():
    scene = _scene(10)
    exact, penalty = chain_rest(scene), chain_rest(scene, PENALTY)
    robot = chain_robot(scene, PENALTY)
    # each penalty spring gives by T / (f k): 1.2e-6 m at 40 N; measured 1.9e-6 m of platform motion
    give = max(t / (PENALTY * c.axial_stiffness) for t, c in zip(penalty.tensions_at_anchor, robot.cables))
    shift = np.abs(exact.position - penalty.position).max()
    assert 0.1 * give < shift < 3.0 * give


def test_the_model_is_the_builders():
    scene = _scene(10)
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, catenary_platform(scene), scene.unstrained_lengths, scene_chain_spec(scene))
    robot = chain_robot(scene)
    for cable, masses, k, k_theta in zip(robot.cables, items.node_masses, items.axial_stiffnesses,
                                         items.bending_stiffnesses):
        assert np.array_equal(cable.node_masses, masses)  # the same lumping, to the last bit
        assert cable.axial_stiffness == k and cable.bending_stiffness == k_theta


# ---------------------------------------------------------------------------
# over swivel pulleys
# ---------------------------------------------------------------------------
SWIVEL = load_scene("spatial-four-cable-swivel")


def _swivel_scene(asymmetric=True, rigid=False):
    """spatial-four-cable-swivel (bending on), with unequal lengths and/or spatial-four-cable's rigid platform."""
    scene = SWIVEL
    if asymmetric:
        lengths = (2.40, 2.36, 2.33, 2.38)  # no longer than 2.40: elements stay within half the pulley radius
        scene = scene.with_changes(cables=tuple(replace(c, unstrained_length=length)
                                                for c, length in zip(scene.cables, lengths)))
    if rigid:
        scene = scene.with_changes(platform=FOUR.platform)
    return scene


def _exudyn_robot(scene, anchor_spring_factor=None, tension_only=False):
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, catenary_platform(scene), scene.unstrained_lengths,
                                scene_chain_spec(scene, anchor_spring_factor, tension_only), exits=scene.exits)
    mbs.Assemble()
    return mbs, items


@pytest.mark.parametrize("rigid, tension_only", [(False, False), (False, True), (True, False)])
def test_over_swivel_pulleys_exudyns_static_solver_accepts_the_chain_statics_equilibrium(rigid, tension_only):
    # Exudyn's static solver diverges from the catenary start over a swivel pulley (its first
    # Newton step raised the residual 300-fold, docs/spatial.md). Started on the chain statics'
    # equilibrium of the same model, it converges and moves nothing: the two agree to its
    # tolerance. Measured: no coordinate moves by more than 1e-15 m (point mass, springs or
    # tension-only elements; penalty joints on a rigid platform), the anchor forces agree to
    # 4e-8 N (penalty springs of 1.6e8 N/m read at positions rounded to 1e-16 m).
    scene = _swivel_scene(rigid=rigid)
    factor = PENALTY if rigid else None
    chain = chain_rest(scene, factor, tension_only)
    mbs, items = _exudyn_robot(scene, factor, tension_only)
    set_configuration(mbs, items, chain)
    before = np.array(mbs.systemData.GetODE2Coordinates())
    exudyn = solve_static(mbs, items)
    after = np.array(mbs.systemData.GetODE2Coordinates())
    # 1e-12 m: a thousand times the measured shift; a term the two models did not share (a held node
    # elsewhere, a contact or bending force left out) would move the state by its force over a stiffness
    # of 1e6 N/m, micrometres to millimetres
    assert np.abs(after - before).max() < 1e-12
    assert np.abs(swivel_angles(mbs, items) - chain.swivel_angles).max() < 1e-12
    assert np.abs(exudyn.forces_on_platform - chain.forces_on_platform).max() < 1e-6
    if rigid:  # the platform turns: the rotation is solved too
        assert np.linalg.norm(chain.rotation_vector) > 0.01
    # the wraps are on the discs: each pulley turned within 2 degrees of its anchor's azimuth
    azimuths = [np.arctan2(*(a - s.inlet)[1::-1]) for a, s in
                zip(chain.position + np.asarray(scene.platform.anchors) @ chain.rotation.T, scene.exits)]
    assert np.degrees(np.abs(chain.swivel_angles - azimuths)).max() < 2.0


def test_a_rigid_platform_on_exact_joints_over_swivel_pulleys_starts_at_rest_and_stays_there():
    import warnings

    from cdpr_exu.builder.robot_3d import platform_pose
    from cdpr_exu.run.settle import start_at_rest
    from cdpr_exu.run.dynamics import run_dynamic

    # Exudyn's static solver diverges on exact spherical joints holding a turning rigid body
    # (builder/robot_3d.py), so it cannot check this start; its dynamic solver can: started
    # at rest on the chain statics' equilibrium, the platform stays put. Measured over 0.05 s:
    # 1e-15 m and 3e-15 rad (the platform turned by 0.02 rad at rest)
    scene = _swivel_scene(rigid=True)
    mbs, items = _exudyn_robot(scene, tension_only=True)  # as cdpr run builds it
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # neither the fallback nor a failed polish
        start = start_at_rest(mbs, items)
    assert start.method == "chain statics" and start.polish_shift is None
    assert np.linalg.norm(start.statics.rotation_vector) > 0.01
    position = platform_pose(mbs, items)[0]
    run = run_dynamic(mbs, items, 0.05, 1e-3, spectral_radius=0.5)
    # 1e-9: six orders below how far a start off equilibrium moves (the settle's creep left 8.6 mm)
    assert np.abs(run.position - position).max() < 1e-9
    assert np.abs(run.rotation_vector - start.statics.rotation_vector).max() < 1e-9


def test_over_swivel_pulleys_the_model_is_the_builders():
    scene = _swivel_scene()
    mbs, items = _exudyn_robot(scene, tension_only=True)
    built, from_scene = chain_statics_robot(mbs, items), chain_robot(scene)
    for a, b in zip(built.cables, from_scene.cables):
        # the same lumping, stiffnesses, pulley and winch line; the winch end held where the builder holds it
        assert a.node_masses == b.node_masses and a.pulley == b.pulley and a.winch_elements == b.winch_elements > 0
        assert a.axial_stiffness == b.axial_stiffness and a.bending_stiffness == b.bending_stiffness > 0
        assert a.slack and b.slack
        assert np.abs(np.subtract(a.exit_point, b.exit_point)).max() < 1e-15


def test_a_symmetric_robot_over_swivel_pulleys_hangs_symmetric_in_the_chain_statics():
    scene = _swivel_scene(asymmetric=False)
    chain = chain_rest(scene)
    # four equal cables from the corners of a square, with bending: on the axis to round-off
    # (measured 2e-17 m), equal tensions, each pulley turned to its anchor (-135, -45, 45, 135 deg)
    assert np.abs(chain.position[:2]).max() < 1e-12
    assert np.ptp(chain.tensions_at_anchor) < 1e-9 * chain.tensions_at_anchor.max()
    assert chain.swivel_angles == pytest.approx(np.radians([-135.0, -45.0, 45.0, 135.0]), abs=1e-12)
    weight = scene.platform.mass * scene.gravity
    assert chain.forces_on_platform.sum(axis=0) == pytest.approx([0.0, 0.0, weight], abs=1e-8 * weight)
    # each cable's nodes mirror the next one's under a quarter turn about the vertical axis
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert np.abs(chain.nodes[0] @ quarter.T - chain.nodes[1]).max() < 1e-12


def test_over_swivel_pulleys_the_gradient_and_hessian_are_the_energys_derivatives():

    scene = _swivel_scene()  # bending, tension-only elements
    robot, equilibrium = chain_robot(scene), chain_rest(scene)
    model = SpatialChains(robot)
    p = np.concatenate([n for n in equilibrium.nodes])
    rng = np.random.default_rng(3)
    # off the equilibrium, and the swivels turned, so that every term has a gradient: the groove's
    # sideways slope, the contact's torque on psi
    free = p[model.free].ravel() + rng.normal(0.0, 2e-4, model.n_free)
    state = (free, equilibrium.position + [1e-3, 2e-3, 0.0], np.eye(3), equilibrium.swivel_angles + [0.02, -0.03, 0.01, 0.0])
    contact = model.contacts[0]
    pulley, nodes = contact[1], contact[4]
    positions = model.points(*state[:3])[contact[2]:contact[2] + contact[3]].ravel().copy()
    assert sp_energy(positions, state[3][0], nodes, pulley) > 0.0  # the contact is engaged
    gradient, hessian = model.derivatives(*state)[:2]
    hessian = hessian.toarray()
    # the columns of the swivel angles, the platform and the first cable's nodes up the winch line and over
    # the wrap (its first 20 free nodes; the rest of the chain is the point-exit model's, tested above)
    columns = [*range(model.psi0, model.n_unknowns), *range(model.n_free, model.n_free + 3), *range(3 * 20)]
    h = 1e-7
    numeric = np.zeros(len(columns))
    numeric_hessian = np.zeros((model.n_unknowns, len(columns)))
    for c, i in enumerate(columns):
        delta = np.zeros(model.n_unknowns)
        delta[i] = h
        plus, minus = model.step(*state, delta), model.step(*state, -delta)
        numeric[c] = (model.energy(*plus) - model.energy(*minus)) / (2 * h)
        numeric_hessian[:, c] = (model.derivatives(*plus)[0] - model.derivatives(*minus)[0]) / (2 * h)
    # central differences: O(h^2) truncation and the energy's rounding (1e-16 of ~100 J over 1e-7 m).
    # Measured, relative to the largest entry: gradient 2e-10 (psi entries 2e-9), Hessian 3e-10 (psi
    # columns 6e-9); 1e-7 leaves room for rounding and is far below a wrong term (order 1)
    assert np.abs(numeric - gradient[columns]).max() < 1e-7 * np.abs(gradient).max()
    psi = slice(0, model.n_psi)
    assert np.abs(numeric[psi] - gradient[model.psi0:]).max() < 1e-7 * np.abs(gradient[model.psi0:]).max()
    assert np.abs(numeric_hessian - hessian[:, columns]).max() < 1e-7 * np.abs(hessian).max()
    psi_columns = hessian[:, model.psi0:]
    assert np.abs(psi_columns).max() > 0.0  # psi has stiffness from the groove
    assert np.abs(numeric_hessian[:, psi] - psi_columns).max() < 1e-7 * np.abs(psi_columns).max()


def sp_energy(positions, psi, nodes, pulley):
    from cdpr_exu.physics.swivel_pulley import swivel_contact_energy

    return swivel_contact_energy(positions, psi, nodes, pulley.inlet_array, pulley.radius, pulley.groove_radius,
                                 pulley.flange_height, pulley.contact_stiffness, pulley.onset_band)


# --- the inverse: lengths whose chains hold a pose -------------------------------------------------

IPANEMA = load_scene("spatial-ipanema")


def _ipanema(n_elements=10):
    """spatial-ipanema (8 taut cables, bending on) with ``n_elements`` per cable."""
    return IPANEMA.with_changes(cables=tuple(replace(c, n_elements=n_elements) for c in IPANEMA.cables))


def _catenary_start(scene, robot, pose):
    """Lengths and nodes of the catenary inverse at ``pose``: the start the controller takes."""
    from cdpr_exu.core.geometry import rotation_from_vector
    from cdpr_exu.statics.statics import forward_cable, solve_inverse_statics

    platform = catenary_platform(scene)
    rest = solve_statics(platform, scene.unstrained_lengths)
    inverse = solve_inverse_statics(platform, pose, initial_guess=rest.horizontal_tensions)
    points = pose[:3] + np.array(platform.anchors) @ rotation_from_vector(pose[3:6]).T
    nodes = [forward_cable(c, length, point)[0].points(length - np.linspace(0.0, length, chain.n_elements + 1))
             for c, chain, length, point in zip(platform.cables, robot.cables, inverse.unstrained_lengths, points)]
    return inverse.unstrained_lengths, nodes


def test_the_inverse_chain_statics_at_the_rest_pose_give_back_the_lengths_it_rests_on():

    scene = _ipanema()
    robot = chain_robot(scene)
    rest = chain_rest(scene)
    pose = np.concatenate([rest.position, rest.rotation_vector])
    lengths, nodes = _catenary_start(scene, robot, pose)
    inverse = solve_inverse_chain_statics(robot, pose, rest.tensions_at_anchor, lengths=lengths, nodes=nodes)
    # Eight lengths hold six equations: with the rest tensions as the target, the answer is the
    # lengths the robot rests on. Measured 4e-15 m apart after one iteration from the catenary start
    # (3e-9 m off), tensions to 2e-8 N (the rest's tolerance, 1e-9 N on 2e6 N/m elements, is 1e-15 m).
    assert np.abs(inverse.paid_out - scene.unstrained_lengths).max() < 1e-12
    assert np.abs(inverse.tensions_at_anchor - rest.tensions_at_anchor).max() < 1e-6


@pytest.mark.parametrize("point_mass", [False, True])
def test_the_forward_chain_statics_of_the_inverse_lengths_put_the_platform_back_on_the_pose(point_mass):
    from cdpr_exu.core.geometry import rotation_from_vector

    scene = _scene(10, point_mass=True) if point_mass else _ipanema()  # 4 cables on a point mass; IPAnema's 8
    robot = chain_robot(scene)
    rest = chain_rest(scene)
    # 0.1 m and 0.02 rad off the rest, with the d'Alembert force of the platform accelerating at (2, -1, 0) m/s^2
    pose = np.concatenate([rest.position + [0.1, -0.05, 0.05], rest.rotation_vector + [0.0, 0.0, 0.02]])
    if point_mass:
        pose[3:] = 0.0
    inertial = -scene.platform.mass * np.array([2.0, -1.0, 0.0])
    lengths, nodes = _catenary_start(scene, robot, pose)
    inverse = solve_inverse_chain_statics(robot, pose, rest.tensions_at_anchor, lengths=lengths, nodes=nodes,
                                          external_wrench=np.concatenate([inertial, np.zeros(3)]))
    assert np.all(inverse.tensions_at_anchor > 0.0)
    # the forward statics of these lengths, started 1 mm and 1 mrad away, find the pose again
    forward = solve_chain_statics(robot_paid_out(robot, inverse.paid_out), inverse.nodes,
                                  pose[:3] + 1e-3, rotation_from_vector(pose[3:] + 1e-3), external_force=inertial)
    assert forward.iterations >= 2
    # The inverse balances the platform to 1e-9 of its largest force and its chains to their rounding
    # floor (4e-8 N on IPAnema's 2e6 N/m elements), as does the forward solve.
    # Measured: 2e-15 m and 2e-15 rad (IPAnema), 2.3e-11 m (four cables on a point mass); a pose
    # off by 1e-9 m would leave about 2e-3 N on IPAnema's cables.
    assert np.abs(forward.position - pose[:3]).max() < 1e-9
    assert np.abs(forward.rotation_vector - (0.0 if point_mass else pose[3:])).max() < 1e-9


def test_over_swivel_pulleys_the_held_chains_force_rate_is_the_derivative_of_paying_out_as_the_run_does():

    scene = _swivel_scene()
    robot, rest = chain_robot(scene), chain_rest(scene)
    cable, length = robot.cables[1], scene.unstrained_lengths[1]
    # the run's swivel winch keeps the elements and moves the held winch end up the axis by the change
    # of the paid-out length (run_3d._SpatialWinches)
    longer = cable_paid_out(cable, length + 2e-3)
    assert longer.paid_out_length == pytest.approx(length + 2e-3, abs=1e-15)
    assert longer.held_point - cable.held_point == pytest.approx([0.0, 0.0, 2e-3], abs=1e-15)
    assert (longer.element_length, longer.node_masses, longer.axial_stiffness) == (
        cable.element_length, cable.node_masses, cable.axial_stiffness)
    anchor = rest.position + [0.01, -0.005, 0.003]

    def held(paid_out):
        return chain_statics.solve_held_chain(cable_paid_out(cable, paid_out), robot.gravity, anchor, rest.nodes[1])

    chain, h = held(length), 1e-5
    # the rate (implicit function theorem on the nodes' and psi's balance) against central differences of
    # re-solved chains: measured 1.8e-7 relative (the O(h^2) truncation); a rate that scaled the elements as
    # at a point exit, or left psi fixed, would be off by order 1
    numeric = (held(length + h).force - held(length - h).force) / (2.0 * h)
    assert np.abs(chain.force_rate - numeric).max() < 1e-4 * np.abs(numeric).max()
    # the chain hangs in the vertical plane through the axis and the anchor, and the disc turns into it
    # (measured to 1e-16 rad)
    azimuth = np.arctan2(*(anchor - scene.exits[1].inlet)[1::-1])
    assert abs(chain.swivel_angle - azimuth) < 1e-9


def test_over_swivel_pulleys_the_inverse_chain_statics_give_back_the_rest_and_the_forward_statics_the_pose():

    scene = _swivel_scene()  # unequal lengths, bending, tension-only elements
    robot, rest = chain_robot(scene), chain_rest(scene)
    # at the rest pose, with the rest tensions as the target and lengths 0.3 mm off: the lengths it rests on
    off = scene.unstrained_lengths + 3e-4 * np.array([1.0, -1.0, 0.5, 0.2])
    inverse = solve_inverse_chain_statics(robot, rest.position, rest.tensions_at_anchor, lengths=off, nodes=rest.nodes)
    # measured 1e-14 m after 3 iterations
    assert np.abs(inverse.paid_out - scene.unstrained_lengths).max() < 1e-10
    assert np.abs(inverse.swivel_angles - rest.swivel_angles).max() < 1e-10
    # 1 cm off the rest, accelerating at (1, -0.5, 0) m/s^2, started from the lengths changed as the straight
    # distances from the inlets (the controller's start)
    pose = rest.position + [0.01, -0.006, 0.004]
    inertial = -scene.platform.mass * np.array([1.0, -0.5, 0.0])
    inlets = np.array([s.inlet for s in scene.exits])
    start = off + np.linalg.norm(inlets - pose, axis=1) - np.linalg.norm(inlets - rest.position, axis=1)
    inverse = solve_inverse_chain_statics(robot, pose, rest.tensions_at_anchor, lengths=start, nodes=rest.nodes,
                                          external_wrench=np.concatenate([inertial, np.zeros(3)]))
    assert np.all(inverse.tensions_at_anchor > 0.0)
    # the forward statics of these lengths (the winch ends moved up the axes as the run moves them),
    # started 1 mm away, find the pose again: measured 1.3e-13 m
    forward = solve_chain_statics(robot_paid_out(robot, inverse.paid_out), inverse.nodes,
                                  pose + 1e-3, swivel_angles=inverse.swivel_angles, external_force=inertial)
    assert forward.iterations >= 2
    assert np.abs(forward.position - pose).max() < 1e-9
    assert np.abs(forward.swivel_angles - inverse.swivel_angles).max() < 1e-9


def _swivel_jump(scene, rest, offset):
    """The pose ``offset`` [m] from the rest of the swivel scene, and the paid-out lengths changed as the straight
    distances from the inlets (the chain controller's start)."""
    pose = rest.position + np.asarray(offset, dtype=float)
    inlets = np.array([s.inlet for s in scene.exits])
    lengths = np.asarray(scene.unstrained_lengths) + np.linalg.norm(inlets - pose, axis=1) \
        - np.linalg.norm(inlets - rest.position, axis=1)
    return pose, lengths


def test_over_a_swivel_pulley_a_held_chain_started_10_cm_away_converges_to_the_chain_solved_in_small_steps(
        monkeypatch):
    from cdpr_exu.core.errors import UnreachableError

    scene = load_scene("spatial-four-cable-swivel")
    robot, rest = chain_robot(scene), chain_rest(scene)
    direction = np.array([1.0, -0.6, 0.4]) / np.linalg.norm([1.0, -0.6, 0.4])  # across and up: the hardest way
    pose, lengths = _swivel_jump(scene, rest, 0.1 * direction)
    cable = cable_paid_out(robot.cables[1], lengths[1])  # paying out 9 cm: slides over the disc
    chain = chain_statics.solve_held_chain(cable, robot.gravity, pose, rest.nodes[1],
                                           swivel_angle=rest.swivel_angles[1])
    # the independent reference: Newton alone (no continuation) in 20 steps of 5 mm along the way, each
    # from the last step's chain, as the controller's samples (2 mm apart) go; and in one jump Newton alone
    # stalls (it did from 2 cm up or 5 cm across)
    monkeypatch.setattr(chain_statics, "CONTINUATION_HALVINGS", 0)
    with pytest.raises(UnreachableError, match="did not converge"):
        chain_statics.solve_held_chain(cable, robot.gravity, pose, rest.nodes[1], swivel_angle=rest.swivel_angles[1])
    nodes, psi = rest.nodes[1], rest.swivel_angles[1]
    for share in np.linspace(0.05, 1.0, 20):
        step_pose, step_lengths = _swivel_jump(scene, rest, share * 0.1 * direction)
        small = chain_statics.solve_held_chain(cable_paid_out(robot.cables[1], step_lengths[1]), robot.gravity,
                                               step_pose, nodes, swivel_angle=psi)
        nodes, psi = small.nodes, small.swivel_angle
    # Both are converged: the force left on every free node and on psi below the solver's 1e-9 N (measured
    # 2.7e-10 N), so they are the same rest shape: the anchor forces agree to 1e-6 relative (measured 1.4e-12,
    # the rounding of 1.6e6 N/m elements' forces), the nodes to 1e-9 m (measured 1e-14 m)
    model = chain_statics._held_model(cable, robot.gravity)
    n = cable.n_elements
    gradient = model.point_derivatives(chain.nodes, np.array([chain.swivel_angle]))[0]
    assert np.abs(np.concatenate([gradient[3:3 * n], gradient[3 * (n + 1):]])).max() < 1e-9
    assert np.abs(chain.force - small.force).max() < 1e-6 * np.linalg.norm(small.force)
    assert np.abs(chain.nodes - small.nodes).max() < 1e-9
    assert abs(chain.swivel_angle - small.swivel_angle) < 1e-9


def test_over_swivel_pulleys_the_inverse_chain_statics_from_the_rest_5_cm_away_hold_that_pose():

    scene = load_scene("spatial-four-cable-swivel")
    robot, rest = chain_robot(scene), chain_rest(scene)
    # 5.2 cm up and across, started from the rest's chains (without continuation a held chain stalled at 157 N)
    pose, lengths = _swivel_jump(scene, rest, [0.03, -0.03, 0.03])
    inverse = solve_inverse_chain_statics(robot, pose, rest.tensions_at_anchor, lengths=lengths, nodes=rest.nodes,
                                          swivel_angles=rest.swivel_angles)
    assert np.all(inverse.tensions_at_anchor > 0.0)
    # the forward statics of these lengths, started 1 mm away, find the pose again (measured 1.4e-12 m; the
    # inverse took 3 Gauss-Newton iterations)
    forward = solve_chain_statics(robot_paid_out(robot, inverse.paid_out), inverse.nodes,
                                  pose + 1e-3, swivel_angles=inverse.swivel_angles)
    assert np.abs(forward.position - pose).max() < 1e-9
    assert np.abs(forward.swivel_angles - inverse.swivel_angles).max() < 1e-9
