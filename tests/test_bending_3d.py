"""Exact-angle bending of spatial cables (cdpr_exu.physics.bending_3d) and a spatial chain in Exudyn."""

import exudyn as exu
import numpy as np
import pytest

import exudyn.itemInterface as eii

from cdpr_exu.physics.sparse_blocks import block_pattern
from cdpr_exu.physics.bending import BendingSpringDamper, bending_force_kernel, cable_joints
from cdpr_exu.physics.bending_3d import (ISOTROPIC_BEND, SERIES_BELOW, add_spatial_bending_damping_force,
                                         add_spatial_bending_damping_jacobian, angle_factor,
                                         bending_damping_dissipation,
                                         spatial_bending_energy, spatial_bending_force,
                                         spatial_bending_stiffness)
from cdpr_exu.builder.cable import add_cable, add_cable_forces
from cdpr_exu.builder.chain_3d import add_spatial_chain, chain_energy
from cdpr_exu.scenes.scene import CableSpec, Effects


def _curve(seed, nodes=7):
    rng = np.random.default_rng(seed)
    return np.cumsum(rng.normal(0.0, 0.1, (nodes, 3)) + [0.3, 0.1, -0.05], axis=0).ravel()


def _force(p, joints, k):
    return spatial_bending_force(p, joints, k, np.zeros(p.size))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_force_is_minus_the_gradient_of_the_energy(seed):
    p = _curve(seed)
    joints = cable_joints([p.size // 3])
    k = np.full(len(joints), 1.96)
    h = 1e-7
    numeric = np.array([-(spatial_bending_energy(p + h * e, joints, k) - spatial_bending_energy(p - h * e, joints, k))
                        / (2 * h) for e in np.eye(p.size)])
    # central differences of an energy of order 1e-1 J: 1e-7 relative to the largest force
    np.testing.assert_allclose(_force(p, joints, k), numeric, atol=1e-7 * np.abs(numeric).max())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sparse_stiffness_matches_central_differences_of_the_force(seed):
    p = _curve(seed)
    n = p.size
    joints = cable_joints([n // 3])
    k = np.full(len(joints), 1.96)
    rows, columns = block_pattern(joints, 3)
    stiffness = np.zeros((n, n))
    np.add.at(stiffness, (rows, columns), spatial_bending_stiffness(p, joints, k, 1.0, np.zeros(rows.size)))
    h = 1e-7
    numeric = np.column_stack([-(_force(p + h * e, joints, k) - _force(p - h * e, joints, k)) / (2 * h)
                               for e in np.eye(n)])
    # measured 4e-10 of the largest entry; bound 1e-7
    np.testing.assert_allclose(stiffness, numeric, atol=1e-7 * np.abs(numeric).max())


def test_a_cable_bent_in_a_vertical_plane_feels_the_planar_models_force():
    rng = np.random.default_rng(1)
    planar = np.cumsum(rng.normal(0.0, 0.1, (7, 2)) + [0.3, -0.05], axis=0)
    spatial = np.column_stack([planar[:, 0], np.zeros(7), planar[:, 1]]).ravel()  # (x, z) -> (x, 0, z)
    k = np.full(5, 1.96)
    force_2d = bending_force_kernel(planar.ravel(), np.zeros(14), cable_joints([7]), k, np.zeros(5), np.zeros(14))
    force_3d = _force(spatial, cable_joints([7]), k).reshape(-1, 3)
    np.testing.assert_allclose(force_3d[:, [0, 2]], force_2d.reshape(-1, 2), atol=1e-12)
    assert np.all(force_3d[:, 1] == 0.0)


def test_the_force_is_linear_in_the_angle_and_smooth_at_a_straight_cable():
    """k theta at the joint: a tip displaced by eps (theta ~ eps) feels k eps / l^2 = eps (k = l = 1)."""
    for eps in (1e-3, 1e-6, 1e-9):
        p = np.array([0.0, 0, 0, 1, 0, 0, 2, eps, 0])
        assert _force(p, cable_joints([3]), np.array([1.0]))[7] == pytest.approx(-eps, rel=1e-5)
    assert np.all(_force(np.array([0.0, 0, 0, 1, 0, 0, 2, 0, 0]), cable_joints([3]), np.array([1.0])) == 0.0)
    x = SERIES_BELOW  # the series and the closed form meet there
    series, closed = angle_factor(1.0 - x * (1 - 1e-9)), angle_factor(1.0 - x * (1 + 1e-9))
    assert series[0] == pytest.approx(closed[0], rel=1e-9) and series[1] == pytest.approx(closed[1], rel=1e-5)


def test_a_rigid_rotation_rotates_the_force_and_keeps_the_energy():
    p = _curve(3)
    joints = cable_joints([p.size // 3])
    k = np.full(len(joints), 1.0)
    angle = 0.7
    rotation = np.array([[1, 0, 0], [0, np.cos(angle), -np.sin(angle)], [0, np.sin(angle), np.cos(angle)]])
    turned = (p.reshape(-1, 3) @ rotation.T).ravel()
    np.testing.assert_allclose(_force(turned, joints, k).reshape(-1, 3), _force(p, joints, k).reshape(-1, 3) @ rotation.T,
                               atol=1e-12)
    assert spatial_bending_energy(turned, joints, k) == pytest.approx(spatial_bending_energy(p, joints, k), rel=1e-12)


def _swing(step, end=1.0, bending=0.5, bending_damping=0.0):
    """Energy history of a 9-node chain, held at one end, released from a 3-D curve (no axial damping);
    also the bending dampers' power 2 R [W] after each step."""
    container = exu.SystemContainer()
    mbs = container.AddSystem()
    s = np.linspace(0.0, 1.0, 9)
    positions = np.column_stack([s, 0.3 * np.sin(2 * s), -0.2 * s**2])
    masses = np.full(9, 0.1)
    items = add_spatial_chain(mbs, positions, masses, 1e4, 0.0, bending, bending_damping=bending_damping)
    mbs.Assemble()
    settings = exu.SimulationSettings()
    settings.timeIntegration.numberOfSteps = int(round(end / step))
    settings.timeIntegration.endTime = end
    settings.timeIntegration.generalizedAlpha.spectralRadius = 1.0  # no numerical dissipation
    settings.timeIntegration.newton.relativeTolerance = 1e-10
    settings.timeIntegration.verboseMode = 0
    settings.solution.file.write = False  # else Exudyn writes solution/ into the working folder
    settings.linearSolver.solverType = exu.LinearSolverType.EigenSparse
    energies, heights, powers = [], [], []

    def record(mbs_, t):
        q = np.asarray(mbs_.systemData.GetODE2Coordinates())[:27]
        v = np.asarray(mbs_.systemData.GetODE2Coordinates_t())[:27]
        energies.append(chain_energy(items, masses, q, v, 1e4, bending))
        heights.append(q[-1])
        if items.bending_damping is not None:
            powers.append(bending_damping_dissipation(items.reference + q, v, items.joints, items.bending_damping,
                                                      ISOTROPIC_BEND))
        return True

    mbs.SetPostStepUserFunction(record)
    mbs.SolveDynamic(settings)
    if bending_damping:
        return np.array(energies), np.array(heights), np.array(powers)
    return np.array(energies), np.array(heights)


def test_a_spatial_chain_conserves_energy_to_second_order_in_the_step():
    """Measured drifts 5.7e-4, 1.4e-4, 3.5e-5 J (ratios 4.0) while the tip falls by decimetres."""
    drifts = []
    for step in (2e-3, 1e-3, 5e-4):
        energy, heights = _swing(step)
        drifts.append(np.abs(energy - energy[0]).max())
        assert heights.min() < -0.1  # the chain swings: its tip drops more than 10 cm
    orders = np.log2(np.array(drifts[:-1]) / np.array(drifts[1:]))
    assert np.all((orders > 1.8) & (orders < 2.2)), drifts
    assert drifts[0] < 2e-3


# --------------------------------------------------------------------------- bending dampers

def _damper_force(p, v, joints, c, bend):
    return add_spatial_bending_damping_force(p, v, joints, c, bend, np.zeros(p.size))


def _damper_matrices(p, v, joints, c, bend):
    """K = -df/dq and D = -df/dv as dense matrices, from the sparse triplets."""
    rows, columns = block_pattern(joints, 3)
    matrices = []
    for factors in ((1.0, 0.0), (0.0, 1.0)):
        matrix = np.zeros((p.size, p.size))
        np.add.at(matrix, (rows, columns),
                  add_spatial_bending_damping_jacobian(p, v, joints, c, bend, *factors, np.zeros(rows.size)))
        matrices.append(matrix)
    return matrices


def _bent_joint(theta):
    """A joint bent by theta in the x-y plane, segments of 1 and 0.8 m, flat (3 nodes x 3)."""
    return np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0 + 0.8 * np.cos(theta), 0.8 * np.sin(theta), 0.0])


@pytest.mark.parametrize("bend", [np.inf, ISOTROPIC_BEND])
@pytest.mark.parametrize("seed", [0, 1])
def test_the_bending_damper_force_is_minus_the_velocity_gradient_of_its_rayleigh_function(seed, bend):
    p = _curve(seed)
    v = np.random.default_rng(10 + seed).normal(0.0, 1.0, p.size)
    joints = cable_joints([p.size // 3])
    c = np.full(len(joints), 1.96)
    h = 1e-3  # R is quadratic in v: central differences are exact up to round-off
    numeric = np.array([-(bending_damping_dissipation(p, v + h * e, joints, c, bend)
                          - bending_damping_dissipation(p, v - h * e, joints, c, bend)) / (4 * h) for e in np.eye(p.size)])
    np.testing.assert_allclose(_damper_force(p, v, joints, c, bend), numeric, atol=1e-9 * np.abs(numeric).max())
    assert bending_damping_dissipation(p, v, joints, c, bend) > 0.0


@pytest.mark.parametrize("bend", [np.inf, ISOTROPIC_BEND, 0.3])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_bending_damper_jacobians_match_central_differences_in_positions_and_velocities(seed, bend):
    p = _curve(seed)
    v = np.random.default_rng(20 + seed).normal(0.0, 1.0, p.size)
    joints = cable_joints([p.size // 3])
    c = np.full(len(joints), 1.96)
    stiffness, damping = _damper_matrices(p, v, joints, c, bend)
    h = 1e-7
    numeric_q = np.column_stack([-(_damper_force(p + h * e, v, joints, c, bend) - _damper_force(p - h * e, v, joints, c, bend))
                                 / (2 * h) for e in np.eye(p.size)])
    numeric_v = np.column_stack([-(_damper_force(p, v + e, joints, c, bend) - _damper_force(p, v - e, joints, c, bend)) / 2
                                 for e in np.eye(p.size)])  # linear in v: exact
    # measured 3e-10 to 5e-10 of the largest entry (positions), 1e-15 (velocities); bounds 1e-7 and 1e-12
    np.testing.assert_allclose(stiffness, numeric_q, atol=1e-7 * np.abs(numeric_q).max())
    np.testing.assert_allclose(damping, numeric_v, atol=1e-12 * np.abs(numeric_v).max())
    assert np.linalg.eigvalsh(0.5 * (damping + damping.T)).min() > -1e-12 * np.abs(damping).max()  # D >= 0
    np.testing.assert_allclose(damping, damping.T, atol=1e-14 * np.abs(damping).max())


@pytest.mark.parametrize("theta_deg", [10.0, 30.0, 60.0])
def test_the_bending_damper_ignores_translation_and_turning_about_the_joint_normal(theta_deg):
    p = _bent_joint(np.radians(theta_deg))
    joints, c = cable_joints([3]), np.array([2.0])
    points = p.reshape(-1, 3)
    for velocity in (np.tile([0.3, -1.2, 0.7], 3), np.cross([0.0, 0.0, 1.5], points - [0.4, 0.2, 0.0]).ravel()):
        for bend in (np.inf, ISOTROPIC_BEND):
            assert np.abs(_damper_force(p, velocity, joints, c, bend)).max() < 1e-13
            assert abs(bending_damping_dissipation(p, velocity, joints, c, bend)) < 1e-13


@pytest.mark.parametrize("theta_deg", [10.0, 30.0, 60.0])
def test_turning_a_bent_joint_about_an_axis_in_its_plane_is_damped_eps_squared_over_sin_squared_less(theta_deg):
    """The spurious dissipation of a rigid rotation Omega about an in-plane axis: c Omega^2 sin^2(theta)
    on the relative angular velocity alone (|w2 - w1| = Omega sin(theta)), and
    c Omega^2 sin^2(theta) eps^2 / (sin^2(theta) + eps^2) with the isotropic bend eps."""
    theta = np.radians(theta_deg)
    p = _bent_joint(theta)
    joints, c, omega = cable_joints([3]), np.array([2.0]), 1.5
    for axis in ([1.0, 0.0, 0.0], [np.cos(theta), np.sin(theta), 0.0], [0.0, 1.0, 0.0]):
        velocity = np.cross(omega * np.asarray(axis), p.reshape(-1, 3)).ravel()
        e1, e2, v = p[3:6] - p[:3], p[6:] - p[3:6], velocity.reshape(-1, 3)  # w_i = e_i x de_i/dt / |e_i|^2
        relative = np.cross(e2, v[2] - v[1]) / (e2 @ e2) - np.cross(e1, v[1] - v[0]) / (e1 @ e1)
        assert np.linalg.norm(relative) == pytest.approx(omega * np.sin(theta), rel=1e-12)
        spurious = c[0] * omega**2 * np.sin(theta) ** 2
        assert bending_damping_dissipation(p, velocity, joints, c, np.inf) == pytest.approx(spurious, rel=1e-12)
        eps2 = ISOTROPIC_BEND**2
        assert bending_damping_dissipation(p, velocity, joints, c, ISOTROPIC_BEND) == pytest.approx(
            spurious * eps2 / (np.sin(theta) ** 2 + eps2), rel=1e-12)


@pytest.mark.parametrize("bend", [np.inf, ISOTROPIC_BEND])
def test_a_cable_moving_in_a_vertical_plane_feels_the_planar_bending_damper(bend):
    """Force and the in-plane blocks of K and D equal the planar model's damper (bending.py,
    moment c dtheta/dt) to round-off; nothing leaves the plane."""
    rng = np.random.default_rng(4)
    planar = np.cumsum(rng.normal(0.0, 0.1, (7, 2)) + [0.3, -0.05], axis=0)
    velocity_2d = rng.normal(0.0, 1.0, (7, 2))
    spatial = np.column_stack([planar[:, 0], np.zeros(7), planar[:, 1]]).ravel()  # (x, z) -> (x, 0, z)
    velocity = np.column_stack([velocity_2d[:, 0], np.zeros(7), velocity_2d[:, 1]]).ravel()
    c = np.full(5, 1.96)
    force_2d = bending_force_kernel(planar.ravel(), velocity_2d.ravel(), cable_joints([7]), np.zeros(5), c,
                                    np.zeros(14))
    force_3d = _damper_force(spatial, velocity, cable_joints([7]), c, bend).reshape(-1, 3)
    np.testing.assert_allclose(force_3d[:, [0, 2]], force_2d.reshape(-1, 2), atol=1e-12 * np.abs(force_2d).max())
    assert np.abs(force_3d[:, 1]).max() < 1e-14 * np.abs(force_2d).max()
    planar_dampers = BendingSpringDamper(7, cable_joints([7]), np.zeros(5), c)
    k_2d, d_2d = planar_dampers.jacobian(planar.ravel(), velocity_2d.ravel())
    k_3d, d_3d = _damper_matrices(spatial, velocity, cable_joints([7]), c, bend)
    in_plane = np.ravel(np.column_stack([np.arange(0, 21, 3), np.arange(2, 21, 3)]))  # x0, z0, x1, z1, ...
    np.testing.assert_allclose(k_3d[np.ix_(in_plane, in_plane)], k_2d, atol=1e-11 * np.abs(k_2d).max())
    np.testing.assert_allclose(d_3d[np.ix_(in_plane, in_plane)], d_2d, atol=1e-12 * np.abs(d_2d).max())


def test_the_bending_damper_is_smooth_at_a_straight_cable():
    """Force and Jacobians of a joint bent by delta (in either plane) tend to the straight joint's
    linearly in delta: no kink where the bending plane is undefined. With the isotropic bend eps
    the slope of K is about 1 / eps^2 times larger (measured 1.3e4 against 20 here)."""
    joints, c = cable_joints([3]), np.array([2.0])
    velocity = np.array([0.1, -0.4, 0.3, 0.2, 0.5, -0.1, -0.3, 0.2, 0.6])
    straight = _bent_joint(0.0)
    at = {bend: (_damper_force(straight, velocity, joints, c, bend), *_damper_matrices(straight, velocity, joints, c, bend))
          for bend in (np.inf, ISOTROPIC_BEND)}
    for bend, values in at.items():
        for direction in ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]):
            changes = []
            for delta in (1e-8, 1e-10):
                bent = straight + delta * np.concatenate([np.zeros(6), direction])
                near = (_damper_force(bent, velocity, joints, c, bend), *_damper_matrices(bent, velocity, joints, c, bend))
                changes.append([np.abs(x - y).max() for x, y in zip(near, values)])
            changes = np.array(changes)
            assert np.all(changes[0] < 1e-3)
            # linear in delta: 100 times smaller at a 100 times smaller bend (round-off floor 1e-14)
            np.testing.assert_allclose(changes[1], changes[0] / 100.0, rtol=1e-2, atol=1e-14)


def test_a_swinging_chain_with_bending_dampers_loses_energy_every_step_as_they_dissipate_it():
    """Spectral radius 1 (no numerical dissipation): the energy falls every step, and the loss is
    the integral of the dampers' power 2 R (trapezoidal rule) to second order in the step."""
    mismatches = []
    for step in (2e-3, 1e-3):
        energy, heights, power = _swing(step, end=0.5, bending_damping=0.05)
        assert heights.min() < -0.05
        assert np.all(np.diff(energy) < 0.0)
        dissipated = np.concatenate([[0.0], np.cumsum(0.5 * step * (power[1:] + power[:-1]))])
        loss = energy[0] - energy
        assert loss[-1] > 0.05 * energy.std() + 1e-3  # the dampers take out a visible share
        mismatches.append(np.abs(loss - dissipated).max())
    assert mismatches[1] < 0.35 * mismatches[0], mismatches  # about 1/4: second order


def _planar_and_spatial_swing(bending_damping, step=1e-3, end=0.3):
    """Node paths (steps, nodes, 2) [m] of the same held chain released from an arc in the x-z
    plane, built by the planar builder (builder/cable.py) and as a spatial chain (chain_3d)."""
    cable = CableSpec(unstrained_length=2.0, radius=0.005, linear_density=0.35, youngs_modulus=1e9,
                      damping_constant=1e9, n_elements=8)
    angles = np.linspace(0.2, -0.9, cable.n_elements)
    nodes_xz = np.vstack([[0.0, 0.0], np.cumsum(cable.element_length * np.column_stack([np.cos(angles),
                                                                                         np.sin(angles)]), axis=0)])
    effects = Effects.from_preset("full", slack=False, pulley_contact=False, bending_damping=bending_damping)
    paths = []
    for dimension in (2, 3):
        container = exu.SystemContainer()
        mbs = container.AddSystem()
        if dimension == 2:
            items = add_cable(mbs, cable, nodes_xz, effects, 9.81)
            add_cable_forces(mbs, [cable], [items], effects)
            ground = mbs.AddNode(eii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
            ground_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
            for coordinate in range(2):
                held = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=items.nodes[0], coordinate=coordinate))
                mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[ground_marker, held]))
        else:
            positions = np.column_stack([nodes_xz[:, 0], np.zeros(len(nodes_xz)), nodes_xz[:, 1]])
            add_spatial_chain(mbs, positions, cable.node_masses(), cable.axial_stiffness, cable.axial_damping,
                              cable.bending_stiffness, gravity=9.81,
                              bending_damping=cable.bending_damping if bending_damping else 0.0)
        mbs.Assemble()
        settings = exu.SimulationSettings()
        settings.timeIntegration.numberOfSteps = int(round(end / step))
        settings.timeIntegration.endTime = end
        settings.timeIntegration.newton.relativeTolerance = 1e-10
        settings.timeIntegration.verboseMode = 0
        settings.solution.file.write = False
        path = []

        def record(mbs_, t, dimension=dimension, path=path):
            q = np.asarray(mbs_.systemData.GetODE2Coordinates())[:dimension * len(nodes_xz)].reshape(-1, dimension)
            path.append(q[:, [0, -1]] if dimension == 3 else q.copy())
            if dimension == 3:
                assert np.abs(q[:, 1]).max() < 1e-12  # nothing leaves the plane
            return True

        mbs.SetPostStepUserFunction(record)
        mbs.SolveDynamic(settings)
        paths.append(np.array(path) + nodes_xz)
    return paths


def test_a_spatial_chain_in_a_vertical_plane_swings_along_the_planar_chains_path_with_bending_dampers():
    """The same discrete model in two builders: measured 3e-15 m apart over 0.3 s (6e-13 m
    without the dampers) while the tip falls 0.45 m; the dampers (the paper's d_n) move the
    nodes by up to 0.30 m."""
    planar, spatial = _planar_and_spatial_swing(True)
    assert np.abs(planar - spatial).max() < 1e-9  # Newton's relative tolerance 1e-10 on metre-sized coordinates
    undamped, _ = _planar_and_spatial_swing(False)
    assert np.abs(undamped - planar).max() > 0.1
