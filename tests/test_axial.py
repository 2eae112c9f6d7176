"""Tension-only axial elements (cdpr_exu.axial): forces and their analytic Jacobian."""

import numpy as np
import pytest

from cdpr_exu.axial import cable_elements, slack_axial_force, slack_axial_jacobian


def _chain(rng, n_nodes=5):
    positions = np.cumsum(rng.normal(0.0, 0.3, size=(n_nodes, 2)) + [0.5, 0.0], axis=0).ravel()
    velocities = rng.normal(0.0, 0.5, size=2 * n_nodes)
    elements = cable_elements([n_nodes])
    lengths = np.linalg.norm(np.diff(positions.reshape(-1, 2), axis=0), axis=1)
    # Rest lengths around the current ones: some elements taut, some slack.
    rest = lengths * rng.uniform(0.9, 1.1, size=lengths.size)
    return positions, velocities, elements, rest


def _force(p, v, elements, rest, k, c):
    return slack_axial_force(p, v, elements, rest, k, c, np.zeros(p.size))


def test_a_taut_element_pulls_its_nodes_together_with_hookes_force():
    p = np.array([0.0, 0.0, 1.1, 0.0])
    f = _force(p, np.zeros(4), cable_elements([2]), np.array([1.0]), np.array([100.0]), np.array([0.0]))
    # 100 N/m times 0.1 m stretch; tolerance: floating-point rounding only.
    np.testing.assert_allclose(f, [10.0, 0.0, -10.0, 0.0], atol=1e-12)


def test_a_compressed_or_closing_element_carries_no_force():
    p = np.array([0.0, 0.0, 0.9, 0.0])
    f = _force(p, np.zeros(4), cable_elements([2]), np.array([1.0]), np.array([100.0]), np.array([0.0]))
    assert np.all(f == 0.0)
    # Stretched but closing fast: the damper would push, so the element goes slack.
    p = np.array([0.0, 0.0, 1.01, 0.0])
    v = np.array([0.0, 0.0, -1.0, 0.0])
    f = _force(p, v, cable_elements([2]), np.array([1.0]), np.array([100.0]), np.array([10.0]))
    assert np.all(f == 0.0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_jacobian_matches_central_differences(seed):
    rng = np.random.default_rng(seed)
    p, v, elements, rest = _chain(rng)
    k = np.full(len(elements), 3.0e3)
    c = np.full(len(elements), 20.0)
    n = p.size
    stiffness = slack_axial_jacobian(p, v, elements, rest, k, c, 1.0, 0.0, np.zeros((n, n)))
    damping = slack_axial_jacobian(p, v, elements, rest, k, c, 0.0, 1.0, np.zeros((n, n)))
    h = 1e-7
    fd_k, fd_d = np.zeros((n, n)), np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fd_k[:, j] = -(_force(p + e, v, elements, rest, k, c) - _force(p - e, v, elements, rest, k, c)) / (2 * h)
        fd_d[:, j] = -(_force(p, v + e, elements, rest, k, c) - _force(p, v - e, elements, rest, k, c)) / (2 * h)
    # Central differences with h = 1e-7 on forces of order 1e2..1e3 N: truncation and
    # rounding stay below 1e-6 of the largest entry, away from the slack switch.
    scale = np.abs(fd_k).max()
    np.testing.assert_allclose(stiffness, fd_k, atol=1e-6 * scale)
    np.testing.assert_allclose(damping, fd_d, atol=1e-6 * np.abs(fd_d).max())


def test_internal_forces_sum_to_zero():
    rng = np.random.default_rng(7)
    p, v, elements, rest = _chain(rng, 8)
    f = _force(p, v, elements, rest, np.full(7, 1e4), np.full(7, 5.0)).reshape(-1, 2)
    np.testing.assert_allclose(f.sum(axis=0), 0.0, atol=1e-9)
