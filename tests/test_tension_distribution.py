"""Tests of cdpr_exu.statics.tension_distribution: cable tensions within their bounds that hold a platform.

One tension distribution for both dimensions: CoGiRo (CASPR's published robot, the shipped
``spatial-cogiro`` with CASPR's 100-5000 N bounds, over point exits and over swivel pulleys) and
planar point masses on three and four cables. Pure maths, no Exudyn.
"""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog, minimize

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.exits import PointExit, Swivel
from cdpr_exu.scenes.caspr import caspr_scene
from cdpr_exu.scenes.scene import CableSpec, PlatformSpec, Scene, WinchSpec, load_scene
from cdpr_exu.statics.kinematics import structure_matrix
from cdpr_exu.statics.tension_distribution import tension_distribution, tensions, weight_wrench


def with_limits(scene: Scene, min_tension: float, max_tension: float) -> Scene:
    return replace(scene, cables=tuple(replace(c, min_tension=min_tension, max_tension=max_tension)
                                       for c in scene.cables))


#: CoGiRo as CASPR publishes it (tests/data/caspr/, read by cdpr import caspr), and its bounds (force_min, force_max).
CASPR_COGIRO, _ = caspr_scene(*(Path(__file__).parent / "data" / "caspr" / f"CoGiRo_{part}.xml"
                                for part in ("bodies", "cables")))
MIN_TENSION, MAX_TENSION = CASPR_COGIRO.tension_limits[0]
#: CoGiRo within CASPR's bounds, over its point exits and over swivel pulleys of 0.1 m there (elements <= 5 cm).
COGIRO = with_limits(load_scene("spatial-cogiro"), MIN_TENSION, MAX_TENSION)
COGIRO_SWIVEL = replace(COGIRO, exits=tuple(Swivel(e.point, 0.1) for e in COGIRO.exits),
                        cables=tuple(replace(c, n_elements=200) for c in COGIRO.cables))
#: Centre-of-mass poses at the positions of CASPR's CoGiRo_trajectories.xml ("long_stable"), with and without rotation.
COGIRO_POSES = np.array([
    [0.0, 0.0, 2.0, 0.0, 0.0, 0.0],
    [-3.0, -1.0, 2.0, 0.0, 0.0, 0.0],
    [2.0, -3.0, 0.0, 0.0, 0.0, 0.0],
    [2.0, 0.0, 2.0, 0.0, 0.0, 0.0],
    [-4.0, 1.0, 0.0, 0.0, 0.0, 0.0],
    [2.0, -3.0, 4.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 2.0, 0.1, -0.05, 0.2],
    [-2.0, 2.0, 2.0, -0.1, 0.05, -0.3],
])
ROBOTS = pytest.mark.parametrize("robot", [COGIRO, COGIRO_SWIVEL], ids=["point exits", "swivel pulleys"])


def symmetric_robot(point_mass=False) -> Scene:
    """8 cables (4 on a point mass), mirror-symmetric in x and in y, frame 15 x 11 x 5.5 m, 91 kg, 100-5000 N."""
    exits, anchors = [], []
    for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1)):
        exits.append(PointExit((sx * 7.5, sy * 5.2, 5.5)))
        anchors.append((0.0, 0.0, 0.0) if point_mass else (sx * 0.5, sy * 0.5, -0.5))
        if not point_mass:
            exits.append(PointExit((sx * 7.2, sy * 5.5, 5.5)))
            anchors.append((sx * 0.5, sy * 0.35, 0.5))
    return with_limits(replace(COGIRO, exits=tuple(exits), cables=COGIRO.cables[:len(exits)],
                               platform=PlatformSpec(mass=91.0, inertia=None if point_mass else (30.0, 30.0, 20.0),
                                                     anchors=tuple(anchors))), 100.0, 5000.0)


def planar_point_mass(n_cables: int = 4, mass: float = 2.5, limits=(1.0, 100.0)) -> Scene:
    """Cables from the corners of a 3.5 x 4 m frame (the top two, and one or two at the bottom) to a point mass."""
    points = [(-1.75, 0.0), (1.75, 0.0), (-1.75, -4.0), (1.75, -4.0)][:n_cables]
    scene = Scene(cables=(CableSpec(),) * n_cables, exits=tuple(PointExit(p) for p in points),
                  platform=PlatformSpec(mass=mass, anchors=((0.0, 0.0),) * n_cables), winch=WinchSpec(kind="fixed"))
    return with_limits(scene, *limits)


def _balance(robot, pose, result):
    """The residual ``A f + w`` of the platform's weight held by ``result`` at ``pose``, and the weight."""
    wrench = weight_wrench(robot)
    return structure_matrix(robot, pose) @ result + wrench, wrench


# ----------------------------------------------------------------------------------
# both dimensions
# ----------------------------------------------------------------------------------
@pytest.mark.parametrize("n_cables", [3, 4])
def test_a_planar_point_mass_on_three_or_four_cables_is_held_within_the_limits(n_cables):
    robot = planar_point_mass(n_cables)
    for pose in ([0.0, -2.0, 0.0], [0.8, -1.0, 0.0], [-1.2, -3.0, 0.0]):
        held = tensions(robot, pose)
        residual, weight = _balance(robot, pose, held)
        # the balance holds by construction: round-off of tensions of ~10 N, ~1e-15 relative
        assert np.linalg.norm(residual) <= 1e-12 * np.linalg.norm(weight)
        assert np.all((held >= 1.0) & (held <= 100.0))


def test_a_planar_point_mass_is_refused_outside_its_wrench_feasible_set_naming_the_pose():
    # 1 N at least in every cable: above the top exits all four pull it down
    with pytest.raises(UnreachableError, match=r"pose \[0\.0, 0\.5, 0\.0\] is outside the wrench-feasible "
                                               r"workspace: no cable tensions within \[1, 100\] N balance"):
        tensions(planar_point_mass(), [0.0, 0.5, 0.0])
    # 50 kg: the top cables would need about 350 N each
    with pytest.raises(UnreachableError, match="outside the wrench-feasible workspace"):
        tensions(planar_point_mass(mass=50.0), [0.0, -2.0, 0.0])
    with pytest.raises(UnreachableError, match=r"poses\[2\]: pose \[0\.0, 0\.5, 0\.0\] is outside"):
        tensions(planar_point_mass(), [[0.0, -2.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.5, 0.0]])


@pytest.mark.parametrize("point_mass", [False, True], ids=["8 cables, rigid", "4 cables, point mass"])
def test_symmetric_robot_at_its_centre_gets_symmetric_tensions(point_mass):
    robot = symmetric_robot(point_mass)
    centre = np.array([0.0, 0.0, 2.5, 0.0, 0.0, 0.0])
    held = tensions(robot, centre)
    per_corner = held.reshape(4, -1)  # each row one corner, in the same cable order
    # the QP's unique minimiser inherits the mirror symmetry; round-off of tensions of ~300 N: 1e-9 relative
    np.testing.assert_allclose(per_corner, np.broadcast_to(per_corner[0], per_corner.shape), rtol=1e-9)
    residual, weight = _balance(robot, centre, held)
    assert np.linalg.norm(residual) <= 1e-9 * np.linalg.norm(weight)


# ----------------------------------------------------------------------------------
# CoGiRo
# ----------------------------------------------------------------------------------
def test_cogiro_data_is_caspr_s_frame_and_platform():
    span = np.ptp(CASPR_COGIRO.exit_points, axis=0)
    assert 14.9 < span[0] < 15.1 and 10.9 < span[1] < 11.1
    assert np.all((CASPR_COGIRO.exit_points[:, 2] > 5.38) & (CASPR_COGIRO.exit_points[:, 2] < 5.43))
    assert CASPR_COGIRO.platform.mass == 91.058 and (MIN_TENSION, MAX_TENSION) == (100.0, 5000.0)
    np.testing.assert_allclose(COGIRO.exit_points, CASPR_COGIRO.exit_points, atol=1e-12)  # CASPR gives 0.1 mm, as the scene


@ROBOTS
def test_tension_distribution_balances_the_cogiro_weight_within_the_bounds(robot):
    held = tensions(robot, COGIRO_POSES)
    for pose, result in zip(COGIRO_POSES, held):
        residual, weight = _balance(robot, pose, result)
        # the balance holds by construction (f = f_p + N lambda): round-off of tensions of 1e3 N, ~1e-13 relative
        assert np.linalg.norm(residual) <= 1e-9 * np.linalg.norm(weight)
    assert np.all(held >= MIN_TENSION) and np.all(held <= MAX_TENSION)


def test_tension_distribution_is_the_minimiser_of_the_distance_to_the_mid_tensions():
    # at a pose where two cables sit at their lower bound (measured), compare with SciPy's SLSQP on the full QP
    pose = COGIRO_POSES[2]
    matrix, wrench = structure_matrix(COGIRO, pose), weight_wrench(COGIRO)
    held = tensions(COGIRO, pose)
    assert np.sum(np.isclose(held, MIN_TENSION, rtol=0, atol=1e-9)) >= 1  # a bound is active here
    middle = 0.5 * (MIN_TENSION + MAX_TENSION)
    reference = minimize(lambda f: np.sum((f - middle) ** 2) / middle**2, np.full(8, middle), method="SLSQP",
                         jac=lambda f: 2.0 * (f - middle) / middle**2,
                         bounds=[(MIN_TENSION, MAX_TENSION)] * 8,
                         constraints={"type": "eq", "fun": lambda f: (matrix @ f + wrench) / 1e3,
                                      "jac": lambda f: matrix / 1e3},
                         options={"ftol": 1e-14, "maxiter": 500})
    assert reference.success
    # SLSQP stops at its own tolerance: 1e-6 of the tension range (5 mN) covers it
    np.testing.assert_allclose(held, reference.x, rtol=0, atol=1e-6 * 4900.0)
    assert np.sum((held - middle) ** 2) <= np.sum((reference.x - middle) ** 2) * (1 + 1e-9)


def test_tension_distribution_is_the_closed_form_one_where_no_bound_is_active():
    pose = COGIRO_POSES[0]
    matrix, wrench = structure_matrix(COGIRO, pose), weight_wrench(COGIRO)
    middle = np.full(8, 0.5 * (MIN_TENSION + MAX_TENSION))
    closed_form = middle - np.linalg.pinv(matrix) @ (wrench + matrix @ middle)
    assert np.all((closed_form > MIN_TENSION) & (closed_form < MAX_TENSION))
    # tensions of hundreds of newtons: round-off of the SVD and the pseudo-inverse, ~1e-12 N
    np.testing.assert_allclose(tensions(COGIRO, pose), closed_form, rtol=0, atol=1e-9)


def test_pose_above_the_exits_is_outside_the_wrench_feasible_workspace():
    with pytest.raises(UnreachableError, match=r"pose \[0\.0, 0\.0, 7\.0, 0\.0, 0\.0, 0\.0\] is outside the "
                                               r"wrench-feasible workspace"):
        tensions(COGIRO_SWIVEL, [0.0, 0.0, 7.0, 0.0, 0.0, 0.0])
    heavy = replace(COGIRO, platform=replace(COGIRO.platform, mass=1e5))  # too heavy for 5000 N cables
    with pytest.raises(UnreachableError, match="outside the wrench-feasible workspace"):
        tensions(heavy, COGIRO_POSES[0])


def test_tensions_along_poses_name_the_first_infeasible_one():
    heights = np.linspace(2.0, 7.0, 51)
    poses = np.column_stack([np.zeros((51, 2)), heights, np.zeros((51, 3))])
    with pytest.raises(UnreachableError, match=r"poses\[(\d+)\]: pose .* outside the wrench-feasible workspace") as err:
        tensions(COGIRO, poses)
    index = int(str(err.value).split("]")[0].split("[")[1])
    assert 0 < index < 51 and f"pose [0.0, 0.0, {heights[index]}" in str(err.value)
    tensions(COGIRO, poses[index - 1])  # the one before is inside
    assert tensions(COGIRO, COGIRO_POSES).shape == (len(COGIRO_POSES), 8)


def test_refusal_agrees_with_an_lp_feasibility_check_at_random_poses():
    # HiGHS (scipy.optimize.linprog) decides feasibility of A f = -w, bounds, by another method (simplex)
    rng = np.random.default_rng(5)
    verdicts = []
    for robot in (COGIRO, COGIRO_SWIVEL):
        for _ in range(100):
            pose = np.r_[rng.uniform(-7, 7), rng.uniform(-5, 5), rng.uniform(-1, 6), rng.uniform(-0.5, 0.5, 3)]
            matrix, wrench = structure_matrix(robot, pose), weight_wrench(robot)
            lp = linprog(np.zeros(8), A_eq=matrix, b_eq=-wrench, bounds=[(100.0, 5000.0)] * 8, method="highs")
            try:
                tension_distribution(matrix, wrench, 100.0, 5000.0)
                feasible = True
            except UnreachableError:
                feasible = False
            verdicts.append((feasible, lp.status == 0))
    verdicts = np.array(verdicts)
    np.testing.assert_array_equal(verdicts[:, 0], verdicts[:, 1])
    assert 0.2 < verdicts[:, 0].mean() < 0.8  # both verdicts are exercised (measured: about half feasible)


def test_workspace_boundary_is_sharp_and_never_gives_nan():
    # bisect the height where CoGiRo leaves the wrench-feasible workspace on its centre line, then step across it
    lower, upper = 2.0, 7.0
    with np.errstate(all="raise"):  # no division by zero near the boundary, where NNLS's multipliers grow
        for _ in range(60):
            middle = 0.5 * (lower + upper)
            try:
                held = tensions(COGIRO, [0.0, 0.0, middle, 0.0, 0.0, 0.0])
                assert np.all((held >= 100.0) & (held <= 5000.0))  # never NaN
                lower = middle
            except UnreachableError:
                upper = middle
        assert upper - lower < 1e-14 and 4.9 < lower < 5.0  # measured 4.950205 m (the centre of mass)
        for exponent in range(1, 13):
            held = tensions(COGIRO, [0.0, 0.0, lower - 10.0**-exponent, 0.0, 0.0, 0.0])
            assert np.all((held >= 100.0) & (held <= 5000.0))
            with pytest.raises(UnreachableError, match="outside the wrench-feasible workspace"):
                tensions(COGIRO, [0.0, 0.0, upper + 10.0**-exponent, 0.0, 0.0, 0.0])


# ----------------------------------------------------------------------------------
# refusals
# ----------------------------------------------------------------------------------
def test_bad_tension_bounds_are_refused_naming_the_argument():
    matrix, wrench = structure_matrix(COGIRO, COGIRO_POSES[0]), weight_wrench(COGIRO)
    with pytest.raises(SceneError, match="min_tension must not exceed max_tension"):
        tension_distribution(matrix, wrench, 600.0, 500.0)
    with pytest.raises(SceneError, match="min_tension must be finite and zero or positive"):
        tension_distribution(matrix, wrench, -1.0, 500.0)
    with pytest.raises(SceneError, match="max_tension"):
        tension_distribution(matrix, wrench, 100.0, np.nan)


def test_bad_shapes_and_values_are_refused_naming_the_argument():
    matrix, wrench = structure_matrix(COGIRO, COGIRO_POSES[0]), weight_wrench(COGIRO)
    with pytest.raises(SceneError, match="wrench must have shape"):
        tension_distribution(matrix, wrench[:3], 100.0, 5000.0)
    with pytest.raises(SceneError, match="structure_matrix must be finite"):
        tension_distribution(np.where(matrix == matrix[0, 0], np.nan, matrix), wrench, 100.0, 5000.0)
    with pytest.raises(SceneError, match="max_tension must be a scalar or have shape"):
        tension_distribution(matrix, wrench, 100.0, [5000.0] * 7)
    with pytest.raises(SceneError, match="poses must be finite"):
        tensions(COGIRO, [0.0, 0.0, np.nan, 0.0, 0.0, 0.0])
    with pytest.raises(SceneError, match="poses must have trailing shape"):
        tensions(COGIRO, [0.0, 0.0, 2.0])
    with pytest.raises(SceneError, match="external_wrench"):
        tensions(COGIRO, COGIRO_POSES[0], external_wrench=[1.0, 2.0])
