"""Pulley contact on element segments (cdpr_exu.physics.segment_contact, Effects.pulley_contact_model).

The kernels against finite differences and closed-form forces; the scene field; which
Exudyn items each contact model adds; and the paper's circle on the real Exudyn solver
with segment contact, also with cables that node contact refuses as too coarse.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import replace
from functools import lru_cache

import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError, SolverFailure
from cdpr_exu.builder.model import build_model, contact_candidates
from cdpr_exu.core.geometry import segment_penetration
from cdpr_exu.scenes.scene import Effects, load_scene, save_scene, scene_from_dict
from cdpr_exu.physics.segment_contact import SegmentPulleyContact, contact_segments
from cdpr_exu.run.simulate import simulate

PAPER = load_scene("paper-circle")
CENTER = np.array([0.1, -0.2])  # [m]
RADIUS = 0.25  # [m]
STIFFNESS = 1.0e7  # [N/m], the paper's k_p
DAMPING = 10.0  # [N s/m]


def segment_scene(n_elements: int = 15, end_time: float = 1.0, **effects):
    """The paper's circle with segment contact, ``n_elements`` per cable, a short run."""
    return PAPER.with_changes(
        effects=Effects.from_preset("full", pulley_contact_model="segment", **effects),
        cables=tuple(replace(c, n_elements=n_elements) for c in PAPER.cables),
        solver=replace(PAPER.solver, end_time=end_time, output_period=0.01))


@lru_cache(maxsize=None)
def segment_run(n_elements: int):
    scene = segment_scene(n_elements)
    return scene, simulate(scene)


def object_types(model) -> Counter:
    mbs = model.mbs
    return Counter(mbs.GetObject(i)["objectType"] for i in range(mbs.systemData.NumberOfObjects()))


# ============================================================================ kernels


def segment_contact_force(positions, velocities, segments, centers, radii, stiffness, damping):
    """The contact force (2N,) [N] of :class:`SegmentPulleyContact` over N = positions.size / 2 nodes."""
    contact = SegmentPulleyContact(positions.size // 2, segments, centers, radii, stiffness, damping)
    return contact.add_force(positions, velocities, np.zeros(positions.size))


def segment_contact_jacobian(positions, velocities, segments, centers, radii, stiffness, damping):
    """``(K, D)`` = (-df/dq, -df/dv) of :func:`segment_contact_force`, each (2N, 2N)."""
    contact = SegmentPulleyContact(positions.size // 2, segments, centers, radii, stiffness, damping)
    n = positions.size
    return (contact.add_jacobian(positions, velocities, 1.0, 0.0, np.zeros((n, n))),
            contact.add_jacobian(positions, velocities, 0.0, 1.0, np.zeros((n, n))))

def wrapped_chain(seed: int = 1):
    """Five nodes about the pulley rim (chords cut the disc by ~1-2 cm), random velocities."""
    rng = np.random.default_rng(seed)
    angles = np.linspace(0.3, 2.5, 5)
    positions = np.column_stack([CENTER[0] + 0.24 * np.cos(angles), CENTER[1] + 0.24 * np.sin(angles)]).ravel()
    positions += rng.normal(0.0, 0.01, positions.size)
    velocities = rng.normal(0.0, 0.3, positions.size)
    return positions, velocities, np.array([[0, 1], [1, 2], [2, 3], [3, 4]])


def corner_into_the_disc():
    """A V-shaped cable whose corner node 1 points into the disc: both segments clamp to it."""
    tip = CENTER + np.array([0.0, RADIUS - 2e-3])
    positions = np.concatenate([tip + [-0.2, 0.1], tip, tip + [0.2, 0.1]])
    velocities = np.array([0.0, 0.0, 0.05, -0.02, 0.0, 0.0])
    return positions, velocities, np.array([[0, 1], [1, 2]])


def finite_difference_jacobians(positions, velocities, segments, damping):
    args = (segments, CENTER, RADIUS, STIFFNESS, damping)
    n = positions.size
    k_fd, d_fd = np.zeros((n, n)), np.zeros((n, n))
    h_q, h_v = 1e-7, 1e-3  # the force is linear in v (no contact switches within 1e-3 m/s here)
    for j in range(n):
        e = np.zeros(n)
        e[j] = h_q
        k_fd[:, j] = -(segment_contact_force(positions + e, velocities, *args)
                       - segment_contact_force(positions - e, velocities, *args)) / (2 * h_q)
        e[j] = h_v
        d_fd[:, j] = -(segment_contact_force(positions, velocities + e, *args)
                       - segment_contact_force(positions, velocities - e, *args)) / (2 * h_v)
    return k_fd, d_fd


@pytest.mark.parametrize("make", [wrapped_chain, corner_into_the_disc], ids=["wrapped-chain", "corner"])
def test_analytic_jacobian_matches_finite_differences_of_the_force(make):
    positions, velocities, segments = make()
    k_matrix, d_matrix = segment_contact_jacobian(positions, velocities, segments, CENTER, RADIUS, STIFFNESS, DAMPING)
    k_fd, d_fd = finite_difference_jacobians(positions, velocities, segments, DAMPING)
    assert np.abs(k_matrix).max() > 1e6  # the contacts are active
    # Central differences with h = 1e-7 m: truncation ~ h^2 |f'''| and round-off
    # ~ 1e-16 |f| / h, both near 1e-9 of |K| here; 1e-6 leaves a wide margin.
    assert np.abs(k_matrix - k_fd).max() < 1e-6 * np.abs(k_matrix).max()
    assert np.abs(d_matrix - d_fd).max() < 1e-6 * np.abs(d_matrix).max()


def test_stiffness_is_symmetric_without_damping_because_the_force_has_a_potential():
    positions, velocities, segments = wrapped_chain()
    k_matrix, d_matrix = segment_contact_jacobian(positions, velocities, segments, CENTER, RADIUS, STIFFNESS, 0.0)
    assert np.abs(k_matrix - k_matrix.T).max() < 1e-12 * np.abs(k_matrix).max()
    assert not d_matrix.any()


def test_a_segment_pressed_on_the_pulley_gets_k_p_times_its_penetration_shared_by_the_lever_rule():
    depth = 1.0e-3  # [m]
    height = CENTER[1] + RADIUS - depth
    positions = np.array([CENTER[0] - 0.3, height, CENTER[0] + 0.5, height])  # closest point above the centre
    force = segment_contact_force(positions, np.zeros(4), [[0, 1]], CENTER, RADIUS, STIFFNESS, DAMPING)
    t = 0.3 / 0.8
    expected = STIFFNESS * depth  # 1e4 N, straight up
    # 1e-9: the force is a handful of floating-point operations on numbers of order 1
    np.testing.assert_allclose(force[[1, 3]], [(1 - t) * expected, t * expected], rtol=1e-9)
    assert np.abs(force[[0, 2]]).max() < 1e-9 * expected


def test_a_segment_outside_the_disc_feels_nothing():
    height = CENTER[1] + RADIUS + 1e-6
    positions = np.array([CENTER[0] - 0.3, height, CENTER[0] + 0.5, height])
    assert not segment_contact_force(positions, np.ones(4), [[0, 1]], CENTER, RADIUS, STIFFNESS, DAMPING).any()


def test_damping_resists_penetration_but_never_pulls_the_segment_into_the_pulley():
    depth = 1.0e-4  # [m]: spring force 1000 N
    height = CENTER[1] + RADIUS - depth
    positions = np.array([CENTER[0] - 0.4, height, CENTER[0] + 0.4, height])  # t = 1/2
    approaching = segment_contact_force(positions, np.array([0.0, -1.0, 0.0, -1.0]), [[0, 1]], CENTER, RADIUS,
                                        STIFFNESS, DAMPING)
    np.testing.assert_allclose(approaching[[1, 3]].sum(), STIFFNESS * depth + DAMPING * 1.0, rtol=1e-9)
    # Leaving at 200 m/s: k_p depth - c_p v_n = 1000 - 2000 < 0, so no force at all (Exudyn's
    # contact also acts only in compression), and no stiffness either.
    leaving = np.array([0.0, 200.0, 0.0, 200.0])
    assert not segment_contact_force(positions, leaving, [[0, 1]], CENTER, RADIUS, STIFFNESS, DAMPING).any()
    k_matrix, d_matrix = segment_contact_jacobian(positions, leaving, [[0, 1]], CENTER, RADIUS, STIFFNESS, DAMPING)
    assert not k_matrix.any() and not d_matrix.any()


def test_a_corner_pointing_into_the_disc_is_pushed_by_both_its_segments():
    """The documented endpoint choice: each segment counts its closest point, even a shared node."""
    positions, _, segments = corner_into_the_disc()
    force = segment_contact_force(positions, np.zeros(6), segments, CENTER, RADIUS, STIFFNESS, 0.0)
    np.testing.assert_allclose(force[3], 2 * STIFFNESS * 2e-3, rtol=1e-9)
    assert np.abs(force[[0, 1, 4, 5]]).max() == 0.0  # t = 1 and t = 0: the outer nodes get nothing


def test_validation_names_the_bad_argument():
    positions, velocities, segments = wrapped_chain()
    with pytest.raises(SceneError, match="segments refer to nodes outside"):
        segment_contact_force(positions, velocities, [[0, 5]], CENTER, RADIUS, STIFFNESS, DAMPING)
    with pytest.raises(SceneError, match="radii"):
        SegmentPulleyContact(5, segments, CENTER, 0.0, STIFFNESS, DAMPING)
    with pytest.raises(SceneError, match="velocities"):
        segment_contact_force(positions, velocities[:-2], segments, CENTER, RADIUS, STIFFNESS, DAMPING)


def test_contact_segments_are_the_elements_touching_a_candidate_node():
    np.testing.assert_array_equal(contact_segments([3, 4, 5], 15), [2, 3, 4, 5])
    np.testing.assert_array_equal(contact_segments([14, 15], 15), [13, 14])  # no element beyond the last node


# ============================================================================ scene field


def test_the_accuracy_study_compares_segment_contact_as_an_effect_variant():
    from cdpr_exu.studies.accuracy import EFFECT_VARIANTS, FULL_GRID, Configuration, model_name

    variant = (("effects.pulley_contact_model", "segment"),)
    assert variant in EFFECT_VARIANTS
    assert model_name("full", variant) == "full, segment contact"
    configuration = Configuration("full", 30, 1e-3, variant)
    assert configuration in FULL_GRID.configurations()
    scene = scene_from_dict(configuration.scene_data(PAPER.to_dict()))
    assert scene.effects.pulley_contact_model == "segment" and scene.cables[0].n_elements == 30


def test_pulley_contact_model_survives_a_toml_round_trip(tmp_path):
    scene = segment_scene()
    again = load_scene(save_scene(scene, tmp_path / "scene.toml"))
    assert again == scene and again.effects.pulley_contact_model == "segment"
    assert PAPER.effects.pulley_contact_model == "node"  # the default


def test_an_unknown_pulley_contact_model_is_refused_by_name():
    data = PAPER.to_dict()
    data["effects"] = {"preset": "full", "pulley_contact_model": "edge"}
    with pytest.raises(SceneError, match=r"effects\.pulley_contact_model .*'edge'"):
        scene_from_dict(data)


# ============================================================================ items


def test_segment_contact_adds_no_exudyn_contact_items_and_lists_the_candidate_elements():
    model = build_model(segment_scene())
    types = object_types(model)
    assert types["ContactSphereSphere"] == 0
    assert types["Ground"] == 0  # no pulley ground markers either
    assert types["GenericODE2"] == 1  # the contacts live in the cables' one generic object
    counts = model.item_counts()
    assert counts["pulley_contacts"] == 0
    for i, elements in enumerate(model.contact_elements):
        np.testing.assert_array_equal(elements, contact_segments(contact_candidates(model.scene, i), 15))
    assert counts["contact_segments"] == len(model.cable_forces.contact_segments) > 0


def test_node_contact_lives_in_the_generic_object_too():
    scene = PAPER.with_changes(solver=replace(PAPER.solver, end_time=1.0))
    model = build_model(scene)
    types = object_types(model)
    candidates = sum(len(contact_candidates(scene, i)) for i in range(2))
    assert model.item_counts()["pulley_contacts"] == model.cable_forces.node_contact.nodes.size == candidates
    assert types["ContactSphereSphere"] == types["Ground"] == 0  # Exudyn's law, frozen in Newton, in numba
    assert model.item_counts()["contact_segments"] == 0
    assert model.cable_forces.contact is None  # no segment-contact cost at all


def test_segment_contact_without_bending_or_slack_still_gets_its_generic_object():
    model = build_model(segment_scene(bending=False, bending_damping=False, slack=False))
    counts = model.item_counts()
    assert counts["bending_joints"] == 0 and counts["slack_elements"] == 0
    assert counts["cable_force_objects"] == 1 and counts["contact_segments"] > 0
    assert object_types(model)["ContactSphereSphere"] == 0


def test_segment_contact_with_linear_bending_keeps_a_force_function():
    model = build_model(segment_scene(bending_model="linear"))
    assert model.mbs.GetObject(model.cable_forces.object)["forceUserFunction"] != 0


# ============================================================================ runs


def test_paper_circle_with_segment_contact_keeps_every_element_out_of_the_pulley():
    """One second of the paper's circle, 15 elements: segments stay outside the disc to < 1 mm.

    A wrapped element spanning the angle l0i / r_p = 1 rad is pressed on the rim with
    about 2 T sin(1/2) ~ T; end tensions reach some 60 N in the start-up jolt, so the
    penetration should be of order T / k_p = 6e-6 m. Measured: 8 um; the bound 1 mm
    leaves room for impacts of elements landing on the rim, and is 30 times less than
    the 30 mm chords of node contact cut into the disc.
    """
    scene, result = segment_run(15)
    assert result.status == "completed"
    worst = max(segment_penetration(p, x).max() for p, nodes in zip(scene.exits, result.nodes) for x in nodes)
    assert worst < 1.0e-3
    # Free span: elements below the pulleys, on the platform's side of the pulley centre.
    # They hang the 2.5 kg platform (about 12 N each at rest); at t = 0 every element is
    # unstrained (zero tension), so from the first output time on.
    later = result.time > 0.0
    for i, (pulley, nodes, tensions) in enumerate(zip(scene.exits, result.nodes, result.tensions)):
        a, b = nodes[later, :-1], nodes[later, 1:]
        free = (np.maximum(a[..., 1], b[..., 1]) < pulley.center[1]) & (
            (0.5 * (a[..., 0] + b[..., 0]) - pulley.center[0]) * pulley.side < 0)
        assert free.sum(axis=1).min() >= 5  # at least 1.25 m of free span at all times
        assert tensions[later][free].min() > 0.0, f"cable {i}"


@pytest.mark.parametrize("n_elements", [7, 8])
def test_cables_node_contact_refuses_as_too_coarse_run_with_segment_contact(n_elements):
    """7 and 8 elements (0.54 m and 0.47 m on a 0.25 m pulley) cut the disc as chords under
    node contact, which refuses them; 7 is the coarsest the circle's reach allows at all
    (6 leave no element on the winch side). Under segment contact they run, with
    segments outside the disc to 0.05 mm (measured; bound 1 mm as above)."""
    node = PAPER.with_changes(cables=tuple(replace(c, n_elements=n_elements) for c in PAPER.cables),
                              solver=replace(PAPER.solver, end_time=1.0))
    with pytest.raises(SceneError, match=rf"n_elements = {n_elements} is too coarse"):
        build_model(node)
    scene, result = segment_run(n_elements)
    assert result.status == "completed"
    worst = max(segment_penetration(p, x).max() for p, nodes in zip(scene.exits, result.nodes) for x in nodes)
    assert worst < 1.0e-3
    assert np.abs(result.error[:, :2]).max() < 0.2  # on the circle, not thrown off it


def test_the_monitor_still_stops_a_cable_slipping_through_a_soft_segment_contact():
    """k_p = 100 N/m cannot carry tensions of ~20 N: the cable sinks into the pulley and the
    run is stopped once an element cuts half a radius deep."""
    scene = segment_scene().with_changes(exits=tuple(replace(p, contact_stiffness=100.0) for p in PAPER.exits))
    with pytest.raises(SolverFailure, match=r"cuts \d+ mm deep into pulley .*contact_stiffness"):
        simulate(scene)
