"""Node contact with a smooth onset (cdpr_exu.physics.node_contact, Effects.pulley_contact_model = "node_smooth").

The kernels against finite differences and the closed-form law; the sparse triplets
against the dense Jacobian; which Exudyn items the model gets; and the paper's circle on
the real solver, against Exudyn's own node contact.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import replace

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np
import pytest

from cdpr_exu.core.errors import SceneError
from cdpr_exu.builder.cable import add_cable, add_cable_forces
from cdpr_exu.builder.model import build_model, contact_candidates
from cdpr_exu.exits import Pulley
from cdpr_exu.physics.node_contact import CONTACT_ONSET_DEPTH, FrozenNodeContact, NodePulleyContact
from cdpr_exu.scenes.scene import CableSpec, Effects, load_scene
from cdpr_exu.run.simulate import simulate

PAPER = load_scene("paper-circle")
CENTER = np.array([0.1, -0.2])  # [m]
RADIUS = 0.25  # [m]
STIFFNESS = 1.0e7  # [N/m], the paper's k_p
DAMPING = 10.0  # [N s/m], the paper's c_p


def contact(band=CONTACT_ONSET_DEPTH):
    """Contacts on nodes 0 and 2 of a three-node list."""
    return NodePulleyContact(3, [0, 2], CENTER, RADIUS, STIFFNESS, DAMPING, band=band)


def force_of(contact, positions, velocities):
    """The contact forces alone, (2 n_nodes,) [N]."""
    return contact.add_force(np.ascontiguousarray(positions, dtype=np.float64),
                             np.ascontiguousarray(velocities, dtype=np.float64),
                             np.zeros(contact.n_coordinates))


def positions_at(depths, angles=(0.3, 2.0)):
    """Nodes 0 and 2 at the given penetrations [m] and polar angles; node 1 far away."""
    p = np.zeros(6)
    for node, depth, angle in zip((0, 2), depths, angles):
        p[2 * node:2 * node + 2] = CENTER + (RADIUS - depth) * np.array([np.cos(angle), np.sin(angle)])
    p[2:4] = [5.0, 5.0]
    return p


def finite_difference(function, x, h):
    """Central differences of ``function`` (vector valued) at ``x``: shape (len(f), len(x))."""
    columns = []
    for j in range(x.size):
        step = np.zeros_like(x)
        step[j] = h
        columns.append((function(x + step) - function(x - step)) / (2.0 * h))
    return np.column_stack(columns)


@pytest.mark.parametrize("depths", [(0.3e-5, 0.7e-5), (2e-4, 3e-3)], ids=["inside the band", "beyond the band"])
def test_jacobian_matches_finite_differences(depths):
    c = contact()
    p = positions_at(depths)
    v = np.random.default_rng(3).normal(0.0, 1e-3, 6)  # slow enough that the damper never lets go
    k_matrix = c.add_jacobian(p, v, 1.0, 0.0, np.zeros((6, 6)))
    d_matrix = c.add_jacobian(p, v, 0.0, 1.0, np.zeros((6, 6)))
    # h far below the band (1e-5 m), so no difference straddles the switch; relative to
    # k_p = 1e7 N/m, 1e-6 is round-off of a force of ~100 N differenced over 2e-10 m.
    k_fd = -finite_difference(lambda x: force_of(c, x, v), p, 1e-10)
    d_fd = -finite_difference(lambda x: force_of(c, p, x), v, 1e-6)
    assert np.abs(k_matrix - k_fd).max() <= 1e-6 * STIFFNESS
    assert np.abs(d_matrix - d_fd).max() <= 1e-6 * DAMPING


def test_sparse_triplets_hold_the_dense_jacobian():
    c = contact()
    p = positions_at((4e-6, 2e-3))
    v = np.array([1e-3, -2e-3, 0.0, 0.0, 3e-3, 1e-3])
    dense = c.add_jacobian(p, v, 0.7, 0.3, np.zeros((6, 6)))
    rows, columns = c.triplet_pattern()
    values = c.triplet_values(p, v, 0.7, 0.3, np.zeros(rows.size))
    assembled = np.zeros((6, 6))
    np.add.at(assembled, (rows, columns), values)
    np.testing.assert_array_equal(assembled, dense)


def test_beyond_the_band_the_force_is_the_penalty_law_along_the_normal():
    c = contact()
    depth, angle = 2e-3, 0.3  # [m], [rad]
    p = positions_at((depth, 0.0), angles=(angle, 2.0))
    normal = np.array([np.cos(angle), np.sin(angle)])
    v = np.zeros(6)
    v[0:2] = -0.01 * normal  # moving further in at 1 cm/s
    force = force_of(c, p, v)
    expected = (STIFFNESS * depth + DAMPING * 0.01) * normal
    np.testing.assert_allclose(force[0:2], expected, rtol=1e-12)
    np.testing.assert_array_equal(force[2:], 0.0)  # node 1 is not a contact node; node 2 sits on the rim


def test_the_onset_is_continuous_and_smooth():
    c = contact()
    band = CONTACT_ONSET_DEPTH
    v = np.zeros(6)
    normal_force = [np.linalg.norm(force_of(c, positions_at((d, 0.0)), v)[0:2])
                    for d in (0.0, 0.5 * band, band)]
    assert normal_force[0] == 0.0
    # smoothstep at x = 1/2 is 1/2: half the linear law there
    assert normal_force[1] == pytest.approx(0.5 * STIFFNESS * 0.5 * band, rel=1e-9)
    assert normal_force[2] == pytest.approx(STIFFNESS * band, rel=1e-9)
    # C1: the stiffness vanishes at the rim and reaches k_p at the band's end
    radial = lambda d: c.add_jacobian(positions_at((d, 0.0), angles=(0.0, 2.0)), v, 1.0, 0.0, np.zeros((6, 6)))[0, 0]
    assert abs(radial(1e-12)) < 1e-3 * STIFFNESS
    assert radial(band * (1 + 1e-9)) == pytest.approx(STIFFNESS, rel=1e-6)


def test_the_contact_never_pulls_and_band_zero_is_the_sharp_law():
    sharp = contact(band=0.0)
    angle, depth = 0.3, 1e-4
    normal = np.array([np.cos(angle), np.sin(angle)])
    p = positions_at((depth, 0.0), angles=(angle, 2.0))
    leaving = np.zeros(6)
    leaving[0:2] = 1.0 * normal  # leaving at 1 m/s: the damper would pull 10 N, the spring pushes 1000 N
    np.testing.assert_allclose(force_of(sharp, p, leaving)[0:2], (STIFFNESS * depth - DAMPING) * normal,
                               rtol=1e-12)
    leaving[0:2] = 200.0 * normal  # faster than k_p depth / c_p = 100 m/s: it lets go
    np.testing.assert_array_equal(force_of(sharp, p, leaving), 0.0)
    outside = positions_at((-1e-3, -1e-3))
    np.testing.assert_array_equal(force_of(sharp, outside, np.ones(6)), 0.0)


@pytest.mark.parametrize("kwargs, field", [
    ({"band": -1e-5}, "band"), ({"radii": 0.0}, "radii"), ({"stiffness": -1.0}, "stiffness"),
    ({"nodes": [0, 7]}, "nodes"), ({"centers": [[0.0, 0.0]] * 3}, "centers"),
])
def test_bad_arguments_are_refused_by_name(kwargs, field):
    arguments = dict(n_nodes=3, nodes=[0, 2], centers=CENTER, radii=RADIUS, stiffness=STIFFNESS, damping=DAMPING)
    arguments.update(kwargs)
    with pytest.raises(SceneError, match=field):
        NodePulleyContact(**arguments)


def smooth_scene(end_time=1.0, **effects):
    return PAPER.with_changes(effects=Effects.from_preset("full", pulley_contact_model="node_smooth", **effects),
                              solver=replace(PAPER.solver, end_time=end_time))


def test_smooth_node_contact_lives_in_the_cables_generic_object():
    model = build_model(smooth_scene(bending=False, bending_damping=False))
    types = Counter(model.mbs.GetObject(i)["objectType"] for i in range(model.mbs.systemData.NumberOfObjects()))
    assert types["ContactSphereSphere"] == 0
    assert types["GenericODE2"] == 1  # even without bending, the contacts need the generic object
    candidates = [contact_candidates(model.scene, i) for i in range(2)]
    assert model.item_counts()["pulley_contacts"] == sum(len(c) for c in candidates) > 0
    counts = [c.n_elements + 1 for c in PAPER.cables]
    np.testing.assert_array_equal(model.cable_forces.node_contact.nodes,
                                  np.concatenate([candidates[0], counts[0] + candidates[1]]))


@pytest.mark.slow
def test_paper_circle_with_smooth_contact_follows_exudyns_node_contact():
    """The same law, switched on over 1e-5 m instead of in discontinuous iterations: at a
    step of 2.5e-4 s their platform paths agree to within the runs' own step errors there
    (each moves by 0.12 and 0.10 mm at 1.25e-4 s; their difference then is 0.015 mm). Compared
    at the same times: the runs take other steps, so their samples lie up to 1.6e-4 s apart."""
    solver = replace(PAPER.solver, end_time=1.0, step_size=2.5e-4)
    smooth = simulate(smooth_scene().with_changes(solver=solver))
    sharp = simulate(PAPER.with_changes(solver=solver))
    at = np.column_stack([np.interp(smooth.time, sharp.time, sharp.pose[:, k]) for k in range(2)])
    difference = np.linalg.norm(smooth.pose[:, :2] - at, axis=1).max()
    # measured 0.035 mm (0.110 mm row by row, the samples' offset included); bound: the sum of
    # the two step errors, 0.12 + 0.10 mm
    assert difference < 2.2e-4
    assert smooth.pulley_penetration.max() < 1e-3  # no node sinks into the pulley: 1e-3 m is 100 bands


# ============================================================================ frozen node contact ("node")


def test_frozen_contact_jacobian_matches_finite_differences_also_off_the_disc():
    """The frozen law pushes (and may pull) wherever the last switch's gap is negative: here node 0 inside
    the disc and node 2 already 1 mm outside it, both still on."""
    frozen = FrozenNodeContact(3, [0, 2], CENTER, RADIUS, STIFFNESS, DAMPING)
    frozen.gaps = np.array([-1e-4, -1e-5])
    p, v = positions_at((2e-4, -1e-3)), np.array([0.1, -0.2, 0.0, 0.0, 0.3, 0.05])
    force = force_of(frozen, p, v)
    assert force[4:] @ (p[4:] - CENTER) < 0.0  # node 2, outside, is pulled back: Exudyn's law does too
    jacobian = frozen.add_jacobian(p, v, 1.0, 0.0, np.zeros((6, 6)))
    np.testing.assert_allclose(jacobian, -finite_difference(lambda x: force_of(frozen, x, v), p, 1e-9),
                               rtol=1e-5, atol=1e-2)


def test_frozen_contact_follows_exudyns_sphere_contact_items_on_the_solver():
    """A two-element cable dropped onto a pulley and bouncing (its nodes hitting and leaving the rim) with the
    frozen law in the cables' generic object and with Exudyn's ObjectContactSphereSphere on its nodes: the
    same law and switch; only round-off differs (Exudyn's 3-D vectors, its reciprocal of the distance), which
    each impact amplifies (12 switches of the nodes in 0.1 s): measured 4e-9 m after 0.1 s;
    bound 1e-8 m, a millionth of the 10 mm the nodes travel."""
    cable = CableSpec(unstrained_length=0.2, radius=0.005, linear_density=0.35, youngs_modulus=1e9,
                      damping_constant=1e9, n_elements=2)
    pulley = Pulley(center=(0.0, 0.0), radius=RADIUS, contact_stiffness=STIFFNESS, contact_damping=DAMPING)
    start = np.array([[-0.1, RADIUS + 0.002], [0.0, RADIUS + 0.001], [0.1, RADIUS + 0.002]])
    paths = []
    for frozen in (True, False):
        container = exu.SystemContainer()
        mbs = container.AddSystem()
        effects = Effects.from_preset("paper", bending=False, bending_damping=False)
        items = add_cable(mbs, cable, start, effects, 9.81)
        add_cable_forces(mbs, [cable], [items], effects, [pulley], contact_nodes=[np.arange(3)] if frozen else None,
                         frozen_contact=frozen)
        if not frozen:  # Exudyn's own items, as the builder had them
            ground = mbs.AddObject(eii.ObjectGround(referencePosition=[0.0, 0.0, 0.0]))
            center = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground))
            for marker, position in zip(items.markers, start):
                data = mbs.AddNode(eii.NodeGenericData(numberOfDataCoordinates=4, initialCoordinates=[
                    float(np.linalg.norm(position)) - RADIUS - 1e-9, 0.0, 0.0, 0.0]))
                mbs.AddObject(eii.ObjectContactSphereSphere(
                    markerNumbers=[center, marker], nodeNumber=data, spheresRadii=[RADIUS, 1e-9],
                    contactStiffness=STIFFNESS, contactDamping=DAMPING, dynamicFriction=0.0, impactModel=0))
        mbs.Assemble()
        settings = exu.SimulationSettings()
        settings.timeIntegration.numberOfSteps, settings.timeIntegration.endTime = 200, 0.1
        settings.timeIntegration.verboseMode = 0
        settings.timeIntegration.discontinuous.useRecommendedStepSize = False
        settings.solution.file.write = False
        path = []
        mbs.SetPostStepUserFunction(lambda mbs_, t, path=path: path.append(
            np.asarray(mbs_.systemData.GetODE2Coordinates())[:6].copy()) is None)
        mbs.SolveDynamic(settings)
        paths.append(np.array(path))
    assert paths[0].shape == paths[1].shape and paths[0][:, 1::2].min() < -0.01  # the cable drapes over the rim
    assert np.abs(paths[0] - paths[1]).max() < 1e-8
