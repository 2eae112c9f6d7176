"""Tests of cdpr_exu.statics.feasibility: whether massless and catenary cables hold the platform within
[t_min, t_max], where an answer is known. Pure maths, no Exudyn."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError, UnreachableError
from cdpr_exu.exits import PointExit
from cdpr_exu.scenes.caspr import caspr_scene
from cdpr_exu.scenes.scene import CableSpec, PlatformSpec, Scene, WinchSpec, load_scene
from cdpr_exu.statics.feasibility import catenary_holding, massless_holding, tension_bounds
from cdpr_exu.statics.statics import catenary_platform, solve_statics
from cdpr_exu.statics.tension_distribution import tensions

COGIRO = load_scene("spatial-cogiro")
#: CASPR's CoGiRo bounds (force_min, force_max: tests/data/caspr/, read by cdpr import caspr) [N].
CASPR_COGIRO, _ = caspr_scene(*(Path(__file__).parent / "data" / "caspr" / f"CoGiRo_{part}.xml"
                                for part in ("bodies", "cables")))
COGIRO_LIMITS = tension_bounds(COGIRO, *CASPR_COGIRO.tension_limits[0])
GRAVITY = 9.81


def point_mass(exits, mass=2.5, limits=(5.0, 40.0), density=0.35) -> Scene:
    """A planar point mass on cables from ``exits`` (x, z) [m], each cable within ``limits`` [N]."""
    cable = CableSpec(linear_density=density, min_tension=limits[0], max_tension=limits[1])
    return Scene(cables=(cable,) * len(exits), exits=tuple(PointExit(p) for p in exits),
                 platform=PlatformSpec(mass=mass, anchors=((0.0, 0.0),) * len(exits)), winch=WinchSpec(kind="fixed"))


TWO = point_mass([(-1.75, 0.0), (1.75, 0.0)])
FOUR = point_mass([(-1.75, 0.0), (1.75, 0.0), (-1.75, -4.0), (1.75, -4.0)], mass=2.5, limits=(1.0, 60.0))


def two_cable_tensions(x, z, mass=2.5):
    """Closed form: a point mass at (x, z) on two cables from (-+1.75, 0): [u1 u2] f = (0, M g) by Cramer's rule."""
    u1, u2 = (np.array([-1.75 - x, -z]), np.array([1.75 - x, -z]))
    u1, u2 = u1 / np.linalg.norm(u1), u2 / np.linalg.norm(u2)
    det = u1[0] * u2[1] - u1[1] * u2[0]
    return np.array([-mass * GRAVITY * u2[0] / det, mass * GRAVITY * u1[0] / det])


def test_the_massless_two_cable_workspace_is_the_closed_form_one():
    """Each tension from the 2 x 2 structure matrix; the boundary is where one reaches 5 or 40 N. Every grid
    point is classified as the closed form says, with the closed form's tensions (round-off: 1e-9 relative)."""
    xs, zs = np.linspace(-1.6, 1.6, 33), np.linspace(-3.0, -0.1, 30)
    held = 0
    for x in xs:
        for z in zs:
            closed = two_cable_tensions(x, z)
            expected = bool(np.all((closed >= 5.0) & (closed <= 40.0)))
            result = massless_holding(TWO, np.array([x, z, 0.0]), tension_bounds(TWO))
            assert result.held == expected, (x, z, closed)
            if expected:
                held += 1
                np.testing.assert_allclose(result.anchor_tensions, closed, rtol=1e-9)
    assert 0 < held < xs.size * zs.size  # the boundary crosses the grid


def test_the_massless_model_on_four_cables_is_the_tension_distribution_point_by_point():
    for x in np.linspace(-1.5, 1.5, 9):
        for z in np.linspace(-3.8, -0.2, 9):
            pose = np.array([x, z, 0.0])
            result = massless_holding(FOUR, pose, tension_bounds(FOUR))
            try:
                direct = tensions(FOUR, pose)
            except UnreachableError:
                assert result.status == "outside_limits"
                continue
            assert result.held
            np.testing.assert_array_equal(result.anchor_tensions, direct)


@pytest.mark.parametrize("scene, limits, poses", [
    (FOUR, None, [[0.0, -2.0, 0.0], [0.8, -1.0, 0.0], [-1.2, -3.0, 0.0], [1.5, -0.3, 0.0]]),
    (COGIRO, COGIRO_LIMITS, [[0.0, 0.0, 2.0, 0.0, 0.0, 0.0], [-3.0, -1.0, 2.0, 0.0, 0.0, 0.0],
                             [5.0, 3.0, 4.5, 0.0, 0.0, 0.0], [6.5, 4.5, 1.0, 0.0, 0.0, 0.0]]),
], ids=["planar point mass, 4 cables", "spatial-cogiro"])
def test_the_catenary_model_tends_to_the_massless_one_as_the_cables_lose_their_weight(scene, limits, poses):
    """At 1e-9 kg/m a cable of at most 10 m weighs w L < 1e-7 N: the tensions move by that times the
    structure matrix's conditioning (< 1e3 here), so by less than 1e-4 N, and the unstrained length is the
    straight one less its stretch T L / EA (to the catenary's 1e-12 and the 1e-9 convergence of T)."""
    light = replace(scene, cables=tuple(replace(c, linear_density=1e-9) for c in scene.cables))
    limits = tension_bounds(light) if limits is None else limits
    held = 0
    for pose in np.array(poses):
        massless = massless_holding(light, pose, limits)
        catenary = catenary_holding(light, pose, limits, massless.anchor_tensions)
        assert catenary.status == massless.status
        if massless.held:
            held += 1
            np.testing.assert_allclose(catenary.anchor_tensions, massless.anchor_tensions, atol=1e-4)
            stiffness = np.array([c.axial_rigidity for c in light.cables])
            stretched = catenary.lengths * (1.0 + catenary.anchor_tensions / stiffness)
            np.testing.assert_allclose(stretched, massless.lengths, rtol=1e-9)
            assert np.all(catenary.sags < 1e-6)
    assert held >= 2


@pytest.mark.parametrize("pose", [[0.0, 0.0, 2.0, 0.0, 0.0, 0.0], [-3.0, -1.0, 2.0, 0.0, 0.0, 0.0],
                                  [5.0, 3.0, 4.5, 0.0, 0.0, 0.0]])
@pytest.mark.parametrize("factor", [1.0, 4.0])
def test_the_catenary_lengths_hold_the_platform_at_the_pose_in_the_forward_statics(pose, factor):
    """An independent check of the catenary model on spatial-cogiro: the forward statics (an energy minimum
    over the pose) with the unstrained lengths found puts the platform back at the pose (to 1e-6 m and
    1e-6 rad: the 8 stiff cables pin it) with the tensions found (1e-6 relative), all within 100-5000 N."""
    scene = replace(COGIRO, cables=tuple(replace(c, linear_density=factor * c.linear_density) for c in COGIRO.cables))
    massless = massless_holding(scene, np.array(pose), COGIRO_LIMITS)
    held = catenary_holding(scene, np.array(pose), COGIRO_LIMITS, massless.anchor_tensions)
    assert held.held and held.iterations <= 8
    rest = solve_statics(catenary_platform(scene), held.lengths, initial_pose=pose)
    np.testing.assert_allclose(np.append(rest.position, rest.rotation), pose, atol=1e-6)
    np.testing.assert_allclose([c.tension_at_anchor for c in rest.cables], held.anchor_tensions, rtol=1e-6)
    np.testing.assert_allclose([c.tension_at_exit for c in rest.cables], held.exit_tensions, rtol=1e-6)
    assert np.all((held.anchor_tensions >= 100.0) & (held.exit_tensions <= 5000.0))
    # a heavier cable sags more: 4 times the weight at about the same tension, about 4 times the sag
    assert np.all(held.sags > 0.0)


def test_sagging_cables_hold_a_position_where_massless_ones_would_need_less_than_t_min():
    """spatial-cogiro with 4 times heavier cables at the frame's side: the massless model needs a cable below
    100 N; the catenaries hold the platform (the forward statics of their lengths rests there, 1e-6 m)."""
    scene = replace(COGIRO, cables=tuple(replace(c, linear_density=4.0 * c.linear_density) for c in COGIRO.cables))
    pose = np.array([-7.0, -3.0, 4.5, 0.0, 0.0, 0.0])
    assert massless_holding(scene, pose, COGIRO_LIMITS).status == "outside_limits"
    held = catenary_holding(scene, pose, COGIRO_LIMITS)
    assert held.held and held.anchor_tensions.min() >= 100.0
    rest = solve_statics(catenary_platform(scene), held.lengths, initial_pose=pose)
    np.testing.assert_allclose(np.append(rest.position, rest.rotation), pose, atol=1e-6)


def test_heavier_cables_hold_the_platform_at_fewer_positions():
    """The paper's robot (two 0.35 kg/m cables over pulleys, 2.5 kg) within 1-40 N, over a grid of the plane:
    a catenary's tension at its exit exceeds the anchor's by about its weight (13 N for 3.75 m), so the
    steel cables lose the positions where the massless ones need more than about 27 N; 4 times heavier
    cables weigh 51 N, beyond t_max anywhere (measured: 143, 129 and 0 of 169 positions held)."""
    paper = load_scene("paper-circle")
    limits = tension_bounds(paper, 1.0, 40.0)
    counts = []
    for factor in (1.0, 4.0):
        scene = replace(paper, cables=tuple(replace(c, linear_density=factor * c.linear_density) for c in paper.cables))
        poses = [np.array([x, z, 0.0]) for x in np.linspace(-1.5, 1.5, 13) for z in np.linspace(-3.5, -0.5, 13)]
        flags = [(massless_holding(scene, p, limits), p) for p in poses]
        counts.append([sum(m.held for m, _ in flags),
                       sum(catenary_holding(scene, p, limits, m.anchor_tensions).held for m, p in flags)])
    (massless, steel), (massless_heavy, heavy) = counts
    assert massless == massless_heavy  # the massless model does not see the cables' weight
    assert massless > steel > heavy


def test_a_scene_without_tension_limits_is_refused_naming_the_fields():
    with pytest.raises(SceneError, match=r"cables\[0\]\.min_tension and cables\[0\]\.max_tension must bound"):
        tension_bounds(load_scene("paper-circle"))
    with pytest.raises(SceneError, match=r"cables\[0\]\.min_tension"):
        tension_bounds(load_scene("paper-circle"), 1.0, float("nan"))
    np.testing.assert_array_equal(tension_bounds(FOUR, max_tension=80.0), [[1.0, 80.0]] * 4)
