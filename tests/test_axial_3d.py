"""Tension-only axial elements of spatial cables (cdpr_exu.physics.axial_3d, chain_3d, spatial_robot).

Kernels against finite differences, Exudyn's spring-damper and the planar kernels; the
spatial robot in Exudyn (real solver) statically and while a winch pays out cable fast.
"""

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np
import pytest

from cdpr_exu.physics.sparse_blocks import block_pattern
from cdpr_exu.physics.axial import TAUT_BAND, cable_elements, slack_axial_force
from cdpr_exu.core.errors import SceneError, SolverFailure
from cdpr_exu.physics import axial_3d
from cdpr_exu.builder.chain_3d import add_spatial_chain
from cdpr_exu.builder.robot_3d import ChainSpec3D, anchor_forces, build_spatial_robot, element_forces, robot_energy
from cdpr_exu.run.settle import dynamic_settings, solve_static
from conftest import ASYMMETRIC_LENGTHS, PAPER_CATENARY_CABLE, PENALTY, four_cable_robot

# The paper's cable, and the four-cable robot of tests/conftest.py.
EA = PAPER_CATENARY_CABLE.axial_stiffness


# ---------------------------------------------------------------------------
# kernels
# ---------------------------------------------------------------------------
def _chain(strains, seed=0):
    """A zig-zag chain of len(strains) elements of about 0.5 m whose strains (l - l0) / l0 are given,
    random velocities; stiffness 1e4..4e4 N/m, damping 1..20 N s/m."""
    rng = np.random.default_rng(seed)
    n = len(strains) + 1
    points = np.cumsum(rng.normal(0.0, 0.2, size=(n, 3)) + [0.4, 0.1, -0.2], axis=0)
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    rest = lengths / (1.0 + np.asarray(strains, dtype=float))
    stiffness = rng.uniform(1e4, 4e4, size=n - 1)
    damping = rng.uniform(1.0, 20.0, size=n - 1)
    return points.ravel(), rng.normal(0.0, 0.05, size=3 * n), cable_elements([n]), rest, stiffness, damping


def _force(p, v, elements, rest, k, c):
    return axial_3d.tension_only_force(p, v, elements, rest, k, c, np.zeros(len(elements)), np.zeros(p.size))


def _dense(p, v, elements, rest, k, c, f_q, f_q_t, cut_slopes=False):
    rows, columns = block_pattern(elements, 3)
    values = axial_3d.tension_only_triplet_values(p, v, elements, rest, k, c, np.zeros(len(elements)), f_q, f_q_t,
                                                  np.zeros(rows.size), cut_slopes)
    matrix = np.zeros((p.size, p.size))
    np.add.at(matrix, (rows, columns), values)
    return matrix


# Strains: taut (1e-2, 1e-3), slack (-1e-2), and inside the taut band (half of it).
STRAINS = [1e-2, 1e-3, -1e-2, 0.5 * TAUT_BAND]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sparse_jacobians_match_central_differences_of_the_force_in_positions_and_velocities(seed):
    p, v, elements, rest, k, c = _chain(STRAINS, seed)
    stiffness = _dense(p, v, elements, rest, k, c, 1.0, 0.0)
    damping = _dense(p, v, elements, rest, k, c, 0.0, 1.0)
    # f_q K + f_q_t D is linear in the factors (Exudyn's convention, K = -df/dq, D = -df/dv)
    np.testing.assert_allclose(_dense(p, v, elements, rest, k, c, 0.7, 0.3), 0.7 * stiffness + 0.3 * damping,
                               rtol=1e-14, atol=1e-12)
    # Position step 1e-9 m: the in-band element's force is a quartic on the band's scale
    # b = 1e-5 l0 = 5e-6 m, truncation ~ 4 (h / b)^2 = 2e-7; rounding ~ 1e-16 |f| / h. Velocity
    # step 1e-6 m/s: the force is linear in the velocities (no truncation) while k s + c ds/dt > 0,
    # rounding 1e-16 x 400 N / 1e-6 m/s = 4e-8 N s/m of D ~ 10 N s/m.
    h, h_v = 1e-9, 1e-6
    numeric_k, numeric_d = np.zeros_like(stiffness), np.zeros_like(damping)
    for j in range(p.size):
        e = np.zeros(p.size)
        e[j] = h
        numeric_k[:, j] = -(_force(p + e, v, elements, rest, k, c) - _force(p - e, v, elements, rest, k, c)) / (2 * h)
        e_v = e * (h_v / h)
        numeric_d[:, j] = -(_force(p, v + e_v, elements, rest, k, c) - _force(p, v - e_v, elements, rest, k, c)) / (
            2 * h_v)
    errors = (np.abs(stiffness - numeric_k).max() / np.abs(stiffness).max(),
              np.abs(damping - numeric_d).max() / np.abs(damping).max())
    print(f"relative Jacobian errors: K {errors[0]:.1e}, D {errors[1]:.1e}")
    assert errors[0] < 1e-6 and errors[1] < 1e-6
    # each element's own block, not just the largest (the band's switch slope makes one block 20 times larger)
    for a, b in elements:
        block = np.r_[3 * a:3 * a + 3, 3 * b:3 * b + 3]
        scale = np.abs(stiffness[np.ix_(block, block)]).max()
        if scale > 0.0:
            assert np.abs((stiffness - numeric_k)[np.ix_(block, block)]).max() < 1e-6 * scale


def test_the_elastic_force_is_minus_the_gradient_of_the_energy_inside_and_above_the_band():
    p, v, elements, rest, k, _ = _chain(STRAINS, 3)
    no_damping = np.zeros_like(k)
    force = _force(p, np.zeros_like(v), elements, rest, k, no_damping)
    h = 1e-9
    gradient = np.array([(axial_3d.tension_only_energy(p + h * e, elements, rest, k)
                          - axial_3d.tension_only_energy(p - h * e, elements, rest, k)) / (2 * h)
                         for e in np.eye(p.size)])
    # energies ~ k s^2 / 2 = 1 J differenced over 2e-9 m: rounding 1e-16 J / 1e-9 m = 1e-7 N of ~300 N
    np.testing.assert_allclose(force, -gradient, rtol=0, atol=1e-6 * np.abs(force).max())


def test_a_taut_element_is_exudyns_spring_damper_to_round_off():
    """Exudyn's ObjectConnectorSpringDamper reports k (l - l0) + c dl/dt along the element as
    its Force; a chain of taut elements (strains 1e-4 to 1e-2) pulls its nodes with the same."""
    p, v, elements, rest, k, c = _chain([1e-2, 3e-3, 1e-4, 5e-3], 4)
    v *= 0.01  # slowly opening or closing, so that k s + c ds/dt stays positive
    mbs = exu.SystemContainer().AddSystem()
    points, velocities = p.reshape(-1, 3), v.reshape(-1, 3)
    markers = []
    for point, velocity in zip(points, velocities):
        node = mbs.AddNode(eii.NodePoint(referenceCoordinates=list(point), initialVelocities=list(velocity)))
        mbs.AddObject(eii.ObjectMassPoint(mass=1.0, nodeNumber=node))
        markers.append(mbs.AddMarker(eii.MarkerNodePosition(nodeNumber=node)))
    springs = [mbs.AddObject(eii.ObjectConnectorSpringDamper(
        markerNumbers=[markers[a], markers[b]], stiffness=float(k[e]), damping=float(c[e]),
        referenceLength=float(rest[e]))) for e, (a, b) in enumerate(elements)]
    mbs.Assemble()
    exudyn_forces = np.array([mbs.GetObjectOutput(s, exu.OutputVariableType.Force) for s in springs])
    tensions = axial_3d.tension_only_tensions(p, v, elements, rest, k, c, np.zeros(len(elements)), np.zeros(len(elements)))
    directions = np.diff(points, axis=0) / np.linalg.norm(np.diff(points, axis=0), axis=1)[:, None]
    assert np.all(tensions > 0.0)
    # forces 5 to 400 N computed in doubles along the same formula: 1e-13 relative is round-off
    np.testing.assert_allclose(tensions[:, None] * directions, exudyn_forces, rtol=1e-13,
                               atol=1e-13 * np.abs(exudyn_forces).max())
    # the node forces: element force pulls node a towards b and b towards a
    expected = np.zeros(p.size)
    for (a, b), force in zip(elements, exudyn_forces):
        expected[3 * a:3 * a + 3] += force
        expected[3 * b:3 * b + 3] -= force
    np.testing.assert_allclose(_force(p, v, elements, rest, k, c), expected, rtol=0,
                               atol=1e-13 * np.abs(exudyn_forces).max())


def test_a_slack_element_gives_exactly_zero_force_and_jacobian_whatever_its_velocity():
    p, v, elements, rest, k, c = _chain([-1e-2, -1e-9, -0.3], 5)
    for velocities in (v, 100.0 * v, -100.0 * v):  # opening fast, closing fast
        assert np.all(_force(p, velocities, elements, rest, k, c) == 0.0)
        assert np.all(axial_3d.tension_only_tensions(p, velocities, elements, rest, k, c, np.zeros(3), np.ones(3)) == 0.0)
        assert np.all(_dense(p, velocities, elements, rest, k, c, 1.0, 1.0) == 0.0)
    assert axial_3d.tension_only_energy(p, elements, rest, k) == 0.0


def test_a_damper_cut_element_gives_newton_its_taut_slopes_only_when_asked_and_no_force():
    """Stretched by 1e-3 and closing fast (velocities x 1000: k s + c ds/dt < 0 for every
    element): no force, the law's zero Jacobian; with ``cut_slopes`` (a step's first Newton
    iterations, :class:`cdpr_exu.physics.axial.CutSlopes`) each element's taut block
    [[G, -G], [-G, G]] with G = f_q (k u u^T + c u w^T) + f_q_t c u u^T and no force term."""
    p, v, elements, rest, k, c = _chain([1e-3, 1e-3, 1e-3], 3)
    points, velocities = p.reshape(-1, 3), np.zeros_like(p)
    u = np.diff(points, axis=0) / np.linalg.norm(np.diff(points, axis=0), axis=1)[:, None]
    for e in range(3):  # node e + 1 runs back along the element at 10 m/s: every element closes fast
        velocities[3 * (e + 1):3 * (e + 2)] -= 10.0 * u[e] * (e + 1)
    assert np.all(_force(p, velocities, elements, rest, k, c) == 0.0)
    assert not _dense(p, velocities, elements, rest, k, c, 1.0, 1.0).any()
    expected = np.zeros((p.size, p.size))
    for e, (a, b) in enumerate(elements):
        length = np.linalg.norm(points[b] - points[a])
        dv = velocities[3 * b:3 * b + 3] - velocities[3 * a:3 * a + 3]
        w = (dv - u[e] * (u[e] @ dv)) / length
        g = 0.7 * (k[e] * np.outer(u[e], u[e]) + c[e] * np.outer(u[e], w)) + 0.003 * c[e] * np.outer(u[e], u[e])
        for (i, j), sign in (((a, a), 1), ((b, b), 1), ((a, b), -1), ((b, a), -1)):
            expected[3 * i:3 * i + 3, 3 * j:3 * j + 3] += sign * g
    np.testing.assert_allclose(_dense(p, velocities, elements, rest, k, c, 0.7, 0.003, True), expected,
                               rtol=0, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("azimuth_deg", [0.0, 30.0])
def test_a_chain_in_a_vertical_plane_gives_the_planar_kernels_force_with_no_out_of_plane_component(azimuth_deg):
    rng = np.random.default_rng(6)
    n = 6
    planar = np.cumsum(rng.normal(0.0, 0.2, size=(n, 2)) + [0.4, -0.1], axis=0)  # (horizontal, z)
    planar_v = rng.normal(0.0, 0.05, size=(n, 2))
    elements = cable_elements([n])
    lengths = np.linalg.norm(np.diff(planar, axis=0), axis=1)
    rest = lengths / (1.0 + np.array([1e-2, -1e-3, 0.3 * TAUT_BAND, 2e-3, -0.2]))  # taut, slack, in band
    k, c = np.full(n - 1, 2e4), np.full(n - 1, 5.0)
    expected = slack_axial_force(planar.ravel(), planar_v.ravel(), elements, rest, k, c, np.zeros(2 * n))
    expected = expected.reshape(-1, 2)
    angle = np.radians(azimuth_deg)
    horizontal, normal = np.array([np.cos(angle), np.sin(angle), 0.0]), np.array([-np.sin(angle), np.cos(angle), 0.0])
    offset = np.array([0.2, 0.7, 1.0])  # the plane through (0.2, 0.7, z), normal `normal`
    to_space = lambda xz: np.outer(xz[:, 0], horizontal) + np.outer(xz[:, 1], [0.0, 0.0, 1.0])  # noqa: E731
    force = _force((offset + to_space(planar)).ravel(), to_space(planar_v).ravel(), elements, rest, k, c)
    force = force.reshape(-1, 3)
    scale = np.abs(expected).max()
    assert scale > 10.0 and np.any(expected == 0.0)  # some taut, some slack
    # round-off: moved to (0.2, 0.7, 1.0), the positions round by 1e-16 m, which the in-band
    # element's extension (1e-6 m) and the switch's slope turn into ~1e-10 of its force
    # (measured 2.5e-13 of the largest force)
    np.testing.assert_allclose(force @ horizontal, expected[:, 0], rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(force[:, 2], expected[:, 1], rtol=0, atol=1e-10 * scale)
    # out of plane: exactly zero in the plane y = 0.7, rounding of the rotation otherwise
    out_of_plane = np.abs(force @ normal).max()
    assert out_of_plane == 0.0 if azimuth_deg == 0.0 else out_of_plane < 1e-14 * scale


# ---------------------------------------------------------------------------
# the chain in Exudyn
# ---------------------------------------------------------------------------
def test_a_tension_only_chain_has_no_springs_one_generic_object_and_live_parameter_arrays():
    mbs = exu.SystemContainer().AddSystem()
    positions = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [1.0, 0.0, 0.0]])
    items = add_spatial_chain(mbs, positions, np.full(3, 0.1), 1e4, 2.0, 0.0, tension_only=True)
    assert items.springs == [] and items.bending is None and items.generic is not None
    assert items.tension_only
    np.testing.assert_array_equal(items.axial_rest_length, [0.5, 0.5])
    np.testing.assert_array_equal(items.axial_stiffness, [1e4, 1e4])
    np.testing.assert_array_equal(items.axial_damping, [2.0, 2.0])
    mbs.Assemble()
    force_function = items.forces.user_functions[0]
    q = np.zeros(9)
    weight = np.tile([0.0, 0.0, -0.1 * 9.81], 3)  # the node masses' weight is the generic object's too
    np.testing.assert_array_equal(force_function(mbs, 0.0, items.generic, q, q), weight)  # at the rest length
    items.axial_rest_length[:] *= 0.9  # reeled in by 5 cm per element, in place
    force = np.array(force_function(mbs, 0.0, items.generic, q, q))
    np.testing.assert_allclose(force[[0, 3, 6]], [500.0, 0.0, -500.0], rtol=1e-12)  # 1e4 N/m x 0.05 m
    # without the option: Exudyn's spring-dampers, the generic object carries the masses and their weight
    plain = add_spatial_chain(exu.SystemContainer().AddSystem(), positions, np.full(3, 0.1), 1e4, 2.0, 0.0)
    assert len(plain.springs) == 2 and plain.generic is not None and not plain.tension_only


def test_exudyns_system_jacobian_with_tension_only_elements_is_the_one_with_its_own_spring_dampers():
    """The sign convention: Exudyn's Newton matrix of a free, taut, moving chain (bending on), its
    ODE2 right-hand side differentiated in positions and in velocities, is the same whether the
    axial elements are ObjectConnectorSpringDamper or tension-only in the ObjectGenericODE2."""
    rng = np.random.default_rng(7)
    n = 5
    points = np.cumsum(rng.normal(0.0, 0.1, size=(n, 3)) + [0.5, 0.0, 0.0], axis=0)
    displacements = np.vstack([np.zeros(3), np.cumsum(0.01 * np.diff(points, axis=0), axis=0)])  # 1 % strain
    velocities = rng.normal(0.0, 0.01, size=(n, 3))
    matrices = []
    for tension_only in (False, True):
        mbs = exu.SystemContainer().AddSystem()
        items = add_spatial_chain(mbs, points, np.full(n, 0.1), 1e4, 5.0, 0.3, gravity=0.0, hold_first=False,
                                  tension_only=tension_only)
        for node, q, v in zip(items.nodes, displacements, velocities):
            mbs.SetNodeParameter(node, "initialCoordinates", list(q))
            mbs.SetNodeParameter(node, "initialVelocities", list(v))
        mbs.Assemble()
        solver = exu.MainSolverImplicitSecondOrder()
        solver.InitializeSolver(mbs, dynamic_settings(1e-3, 1e-3))
        solver.ComputeJacobianODE2RHS(mbs, 1.0, 0.0)
        stiffness = np.array(solver.GetSystemJacobian())
        solver.ComputeJacobianODE2RHS(mbs, 0.0, 1.0)
        matrices.append((stiffness, np.array(solver.GetSystemJacobian())))
    for exudyn_springs, tension_only in zip(*matrices):
        # measured 1e-16 of the largest entry (2e4 N/m, 10 N s/m): both analytic
        np.testing.assert_allclose(tension_only, exudyn_springs, rtol=0, atol=1e-12 * np.abs(exudyn_springs).max())


def test_a_bad_tension_only_flag_is_refused_naming_the_field():
    with pytest.raises(SceneError, match="tension_only"):
        ChainSpec3D(tension_only="yes")


# ---------------------------------------------------------------------------
# the robot: statics, and a winch paying out fast
# ---------------------------------------------------------------------------
def _build(platform, lengths, chain):
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, platform, lengths, chain)
    mbs.Assemble()
    return mbs, items


#: Unequal lengths whose catenary start has every element taut (lowest element force 20 N).
#: With tests/test_spatial_robot.py's ASYMMETRIC_LENGTHS two cables hang at 3 to 14 N, and
#: on 10 elements the chords of their catenary are shorter than the arc by (kappa l_e)^2 / 24
#: ~ 3e-3, more than their stretch: some start slack (see the test after this one).
TAUT_LENGTHS = [2.45, 2.5, 2.55, 2.5]


@pytest.mark.parametrize("bending", [0.0, 0.05], ids=["no-bending", "bending"])
@pytest.mark.parametrize("rigid", [pytest.param(False, id="point-mass"), pytest.param(True, id="rigid")])
def test_static_robot_with_tension_only_taut_cables_equals_the_one_with_exudyn_springs(rigid, bending):
    platform = four_cable_robot(rigid)
    results, energies, forces = [], [], []
    for tension_only in (False, True):
        chain = ChainSpec3D(n_elements=10, flexural_rigidity=bending, tension_only=tension_only,
                                 anchor_spring_factor=PENALTY if rigid else None)
        mbs, items = _build(platform, TAUT_LENGTHS, chain)
        results.append(solve_static(mbs, items))
        energies.append(robot_energy(mbs, items))
        forces.append(np.concatenate([element_forces(mbs, items, cable) for cable in range(4)]))
        np.testing.assert_allclose(anchor_forces(mbs, items), results[-1].forces_on_platform)
    springs, tension_only = results
    assert forces[1].min() > 10.0  # every element taut (strain >= 1e-4, ten band widths)
    # Newton stops at 1e-9 of the ~100 N residual; over element stiffnesses ~3e5 N/m that is
    # ~1e-12 m. Measured: positions and rotations equal to 3e-16, forces to 7e-9 N (rigid;
    # 7e-14 N point mass) of 23 to 30 N
    np.testing.assert_allclose(tension_only.position, springs.position, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tension_only.rotation_vector, springs.rotation_vector, rtol=0, atol=1e-12)
    np.testing.assert_allclose(tension_only.forces_on_platform, springs.forces_on_platform, rtol=0, atol=1e-7)
    np.testing.assert_allclose(forces[1], forces[0], rtol=0, atol=1e-7)
    # energy: the smooth law stores 0.15 k b^2 less per element than k s^2 / 2 (b = 1e-5 l0,
    # k = EA / l0): 0.15 EA l0 1e-10 = 3e-7 J for each of the 40 elements
    band_deficit = 40 * 0.15 * EA * max(TAUT_LENGTHS) / 10 * TAUT_BAND**2
    assert 0.0 < energies[0] - energies[1] < 1.01 * band_deficit
    assert energies[0] - energies[1] > 0.99 * band_deficit * min(TAUT_LENGTHS) / max(TAUT_LENGTHS)


def test_static_solver_from_a_start_with_slack_elements_and_no_bending_fails():
    """Measured limitation: the catenary start of ASYMMETRIC_LENGTHS has slack elements (their chord
    shorter than their rest length); with tension-only elements and no bending their nodes have no
    stiffness at all, and Exudyn's static solver reports a singular Jacobian (its springs, which
    push, converge). Start from taut cables, or integrate to rest."""
    platform = four_cable_robot(True)
    chain = ChainSpec3D(n_elements=10, tension_only=True, anchor_spring_factor=PENALTY)
    mbs, items = _build(platform, ASYMMETRIC_LENGTHS, chain)
    assert min(element_forces(mbs, items, cable, current=False).min() for cable in range(4)) == 0.0
    with pytest.raises(SolverFailure):
        solve_static(mbs, items)


def _pay_out(tension_only, payout=0.2, duration=0.5, end_time=0.6, step=1e-3, damping=0.0):
    """The four-cable point-mass robot (2.5 m cables, 10 elements) hangs still; from t = 0 every element's
    rest length grows by ``payout`` of itself linearly over ``duration`` (stiffness and damping as
    1 / rest length, a winch paying out 0.5 m per cable, about 1 m/s), in a pre-step function.

    Returns the lowest element force [N] in any cable at any step, the lowest strain (l - l0) / l0, and
    with tension-only elements the lowest element force recovered from the chains' ObjectGenericODE2
    force (what Exudyn integrates, not the law read again)."""
    platform = four_cable_robot(False)
    chain = ChainSpec3D(n_elements=10, tension_only=tension_only, axial_damping_constant=damping)
    mbs, items = _build(platform, [2.5] * 4, chain)
    if tension_only:
        base = [(c.axial_rest_length.copy(), c.axial_stiffness.copy(), c.axial_damping.copy()) for c in items.chains]
    else:
        base = [tuple(np.array([mbs.GetObjectParameter(s, name) for s in c.springs])
                      for name in ("referenceLength", "stiffness", "damping")) for c in items.chains]
    record = {"force": np.inf, "strain": np.inf, "generic": np.inf}

    def pre_step(mbs_, t):
        for cable, (chain_items, (rest, k, c)) in enumerate(zip(items.chains, base)):
            forces = element_forces(mbs_, items, cable)
            record["force"] = min(record["force"], float(forces.min()))
            q = np.concatenate([mbs_.GetNodeOutput(n, exu.OutputVariableType.Coordinates) for n in chain_items.nodes])
            v = np.concatenate([mbs_.GetNodeOutput(n, exu.OutputVariableType.Coordinates_t)
                                for n in chain_items.nodes])
            points = (chain_items.reference + q).reshape(-1, 3)
            lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
            current_rest = chain_items.axial_rest_length if tension_only else np.array(
                [mbs_.GetObjectParameter(s, "referenceLength") for s in chain_items.springs])
            record["strain"] = min(record["strain"], float((lengths / current_rest - 1.0).min()))
            if tension_only:
                # walk from the platform end: node j's force is T_{j-1} (-u_{j-1}) + T_j u_j
                # (the robot's one generic object: this chain's rows, its nodes' weight taken off)
                first = sum(len(other.nodes) for other in items.chains[:cable])
                generic = np.reshape(chain_items.forces.user_functions[0](mbs_, t, chain_items.generic, None, None),
                                     (-1, 3))
                nodal = generic[first:first + len(chain_items.nodes)].copy()
                nodal[:, 2] += chain_items.node_mass * platform.gravity
                directions = np.diff(points, axis=0) / lengths[:, None]
                tension = 0.0
                for e in range(len(lengths) - 1, -1, -1):
                    tension = float((tension * directions[e + 1] if e + 1 < len(lengths) else np.zeros(3))
                                    @ directions[e] - nodal[e + 1] @ directions[e])
                    record["generic"] = min(record["generic"], tension)
        scale = 1.0 + payout * min(t / duration, 1.0)
        for chain_items, (rest, k, c) in zip(items.chains, base):
            if tension_only:  # in place: the arrays the force function reads
                chain_items.axial_rest_length[:] = rest * scale
                chain_items.axial_stiffness[:] = k / scale
                chain_items.axial_damping[:] = c / scale
            else:
                for spring, l0, ki, ci in zip(chain_items.springs, rest, k, c):
                    mbs_.SetObjectParameter(spring, "referenceLength", float(l0 * scale))
                    mbs_.SetObjectParameter(spring, "stiffness", float(ki / scale))
                    mbs_.SetObjectParameter(spring, "damping", float(ci / scale))
        return True

    mbs.SetPreStepUserFunction(pre_step)
    settings = dynamic_settings(end_time, step, spectral_radius=0.8)
    if damping:
        # The damped law max(0, k s + c ds/dt) has a kink where the damper would start to push
        # (continuous force, its slope jumps from (k, c) to 0): at a fixed 1 ms step Newton then
        # failed to converge in 25 (and in 100) iterations during the snaps, with d_n A = 1 and
        # 20 N s. Exudyn's adaptive step halves the step there and goes on.
        settings.timeIntegration.adaptiveStep = True
        settings.timeIntegration.minimumStepSize = 1e-7
    assert mbs.SolveDynamic(settings)
    return record


@pytest.mark.parametrize("damping", [0.0, 20.0], ids=["undamped", "damped"])
def test_a_cable_paid_out_fast_never_pushes_with_tension_only_elements_but_does_with_exudyn_springs(damping):
    springs = _pay_out(False, damping=damping)
    tension_only = _pay_out(True, damping=damping)
    print(f"d_n A = {damping} N s, lowest element force: Exudyn springs {springs['force']:.1f} N "
          f"(strain {springs['strain']:.2e}), tension-only {tension_only['force']:.3g} N (from the generic "
          f"object {tension_only['generic']:.3g} N, strain {tension_only['strain']:.2e})")
    # measured, undamped / damped: springs -379 / -356 N at strains -4.8e-3 / -4.6e-3 (the
    # compressed chain is pushed straight and pushes the platform down); tension-only 0 N,
    # the cable as slack as a strain of -0.28 / -0.09 (it sags and whips as it falls)
    assert springs["force"] < -100.0 and springs["strain"] < -1e-3
    assert tension_only["strain"] < -1e-2  # the cable did go slack
    assert tension_only["force"] >= 0.0
    # the tensions recovered from the nodal forces Exudyn gets: rounding of 1e3 N snap peaks
    # (measured -4e-13 N)
    assert tension_only["generic"] > -1e-9


def test_a_cable_paid_out_as_fast_as_it_lengthens_is_not_damped():
    # element 0 -> 1 along x, stretched by 1 mm, its nodes parting at 0.3 m/s while a winch
    # lengthens its rest length at 0.3 m/s: the strain rate is 0, so only k s acts
    p = np.array([0.0, 0.0, 0.0, 1.001, 0.0, 0.0])
    v = np.array([0.0, 0.0, 0.0, 0.3, 0.0, 0.0])
    elements = np.array([[0, 1]])
    rest, k, c = np.array([1.0]), np.array([1.0e5]), np.array([2.0e3])
    paid_out = axial_3d.tension_only_tensions(p, v, elements, rest, k, c, np.array([0.3]), np.zeros(1))
    assert paid_out[0] == pytest.approx(1.0e5 * 1e-3, rel=1e-12)  # 100 N, no 600 N of damping
    held = axial_3d.tension_only_tensions(p, v, elements, rest, k, c, np.zeros(1), np.zeros(1))
    assert held[0] == pytest.approx(100.0 + 2.0e3 * 0.3, rel=1e-12)
