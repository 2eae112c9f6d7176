"""Tension-only axial elements (cdpr_exu.physics.axial): forces and their analytic Jacobian."""

import numpy as np
import pytest

from cdpr_exu.physics.axial import cable_elements, slack_axial_force, slack_axial_jacobian


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


# --------------------------------------------------------------------------- the tension law

from cdpr_exu.physics.axial import TAUT_BAND, tension_law  # noqa: E402

K, C, BAND = 3.14e5, 3.14e5, TAUT_BAND * 0.25  # the paper's element, a 0.25 m rest length


def test_a_slack_element_pulled_straight_fast_carries_nothing():
    """Below the rest length there is no force at all, not even from the damper."""
    for extension in (-1e-3, -1e-9, 0.0):
        assert tension_law(extension, 5.0, K, C, BAND) == (0.0, 0.0, 0.0)


def test_above_the_band_the_law_is_kelvin_voigt_and_never_negative():
    tension, slope, damping = tension_law(2e-4, 0.01, K, C, BAND)
    assert tension == pytest.approx(K * 2e-4 + C * 0.01, rel=1e-15) and (slope, damping) == (K, C)
    assert tension_law(2e-4, -1.0, K, C, BAND)[0] == 0.0  # closing faster than it stretches: slack


@pytest.mark.parametrize("rate", [0.0, 0.3])
def test_the_switch_is_continuous_with_a_continuous_slope(rate):
    """C1 at both ends of the band: value and slope match from either side (to the
    central-difference error, 1e-6 of the scale), and the slope is the law's own."""
    for edge in (0.0, BAND):
        # 1e-16 m either side: the slope changes by at most (6 C rate / BAND^2) 1e-16 = 9 N/m there
        below, above = tension_law(edge - 1e-16, rate, K, C, BAND), tension_law(edge + 1e-16, rate, K, C, BAND)
        scale = K * BAND + C * rate
        assert abs(above[0] - below[0]) <= 1e-6 * scale
        assert abs(above[1] - below[1]) <= 1e-4 * max(abs(above[1]), K)
    for extension in np.linspace(0.1 * BAND, 0.9 * BAND, 5):
        h = 1e-6 * BAND
        numeric = (tension_law(extension + h, rate, K, C, BAND)[0] - tension_law(extension - h, rate, K, C, BAND)[0]) / (2 * h)
        assert tension_law(extension, rate, K, C, BAND)[1] == pytest.approx(numeric, rel=1e-6)


def test_jacobian_matches_central_differences_inside_the_taut_band():
    """Elements stretched within the switch band: the smoothstep's slope enters the Jacobian."""
    p = np.array([0.0, 0.0, 1.0 + 0.5 * TAUT_BAND, 0.0, 2.0 + 0.7 * TAUT_BAND, 0.1])
    v = np.array([0.0, 0.0, 0.01, 0.0, 0.02, -0.01])
    elements, rest = cable_elements([3]), np.array([1.0, np.hypot(1.0, 0.1)])  # strains 0.5 and 0.2 bands
    k, c = np.full(2, 3.0e3), np.full(2, 20.0)
    n = p.size
    stiffness = slack_axial_jacobian(p, v, elements, rest, k, c, 1.0, 0.0, np.zeros((n, n)))
    h = 1e-12  # far inside the 1e-5 band
    fd = np.zeros((n, n))
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fd[:, j] = -(_force(p + e, v, elements, rest, k, c) - _force(p - e, v, elements, rest, k, c)) / (2 * h)
    np.testing.assert_allclose(stiffness, fd, atol=1e-3 * np.abs(fd).max())


def test_an_element_on_its_rest_length_gives_newton_the_taut_slopes_but_no_force():
    """At t = 0 a straight cable's elements lie on their rest length to round-off: in the
    run's first step (kink_strain = ROUNDOFF_STRAIN) the Jacobian takes the taut side's
    slopes there (else the first Newton iterate moves every node as a free mass), while
    the force stays zero; later (kink_strain = 0) the slack side's zero slopes again."""
    from cdpr_exu.physics.axial import ROUNDOFF_STRAIN

    k, c = np.array([100.0]), np.array([10.0])
    for strain in (-0.5 * ROUNDOFF_STRAIN, 0.0, 0.5 * ROUNDOFF_STRAIN):
        p = np.array([0.0, 0.0, 1.0 + strain, 0.0])
        # The law's own value: (3 x^2) k s at x = s / band <= 5e-8, below 1e-20 N.
        assert np.abs(_force(p, np.zeros(4), cable_elements([2]), np.array([1.0]), k, c)).max() < 1e-20
        stiffness = slack_axial_jacobian(p, np.zeros(4), cable_elements([2]), np.array([1.0]), k, c, 1.0, 0.0,
                                         np.zeros((4, 4)), ROUNDOFF_STRAIN)
        damping = slack_axial_jacobian(p, np.zeros(4), cable_elements([2]), np.array([1.0]), k, c, 0.0, 1.0,
                                       np.zeros((4, 4)), ROUNDOFF_STRAIN)
        # Along the element (x): k and c exactly, as a taut element's; nothing across it.
        assert stiffness[2, 2] == k[0] and damping[2, 2] == c[0] and stiffness[3, 3] == 0.0
    # A truly slack element (well past round-off) still gives Newton nothing.
    p = np.array([0.0, 0.0, 1.0 - 1e-9, 0.0])
    assert not slack_axial_jacobian(p, np.zeros(4), cable_elements([2]), np.array([1.0]), k, c, 1.0, 1.0,
                                    np.zeros((4, 4)), ROUNDOFF_STRAIN).any()
    # After the first step (kink_strain = 0) only an element exactly on its rest length (a
    # cable section that has only been carried along, bit for bit) keeps the taut slopes;
    # one a round-off off it is slack again.
    p = np.array([0.0, 0.0, 1.0, 0.0])
    exact = slack_axial_jacobian(p, np.zeros(4), cable_elements([2]), np.array([1.0]), k, c, 1.0, 0.0,
                                 np.zeros((4, 4)))
    assert exact[2, 2] == k[0]
    p = np.array([0.0, 0.0, 1.0 - 0.5 * ROUNDOFF_STRAIN, 0.0])
    assert not slack_axial_jacobian(p, np.zeros(4), cable_elements([2]), np.array([1.0]), k, c, 1.0, 1.0,
                                    np.zeros((4, 4))).any()


def test_a_damper_cut_element_gives_newton_its_taut_slopes_only_when_asked_and_no_force():
    """Stretched by 1 % but closing at 1 m/s with c = 10 N s/m: k s + c ds/dt = 1 - 10 < 0, so
    the law cuts its force to zero, and its own slopes there are zero. With ``cut_slopes``
    (a step's first Newton iterations, :class:`cdpr_exu.physics.axial.CutSlopes`) the Jacobian
    takes the taut element's k u u^T and c u u^T (exactly: no geometric term, as the force is
    0, and no w term, as the velocity is along the element); without it, nothing."""
    k, c = np.array([100.0]), np.array([10.0])
    p = np.array([0.0, 0.0, 1.01, 0.0])
    v = np.array([0.0, 0.0, -1.0, 0.0])
    elements, rest = cable_elements([2]), np.array([1.0])
    assert np.all(_force(p, v, elements, rest, k, c) == 0.0)
    stiffness = slack_axial_jacobian(p, v, elements, rest, k, c, 1.0, 0.0, np.zeros((4, 4)), 0.0, True)
    damping = slack_axial_jacobian(p, v, elements, rest, k, c, 0.0, 1.0, np.zeros((4, 4)), 0.0, True)
    u = np.array([1.0, 0.0])
    block = np.outer(u, u)
    np.testing.assert_array_equal(stiffness, np.block([[block, -block], [-block, block]]) * k[0])
    np.testing.assert_array_equal(damping, np.block([[block, -block], [-block, block]]) * c[0])
    assert not slack_axial_jacobian(p, v, elements, rest, k, c, 1.0, 1.0, np.zeros((4, 4))).any()
    # Inside the switch band (1e-5 strain) or shorter than the rest length it stays the law's zero.
    for length in (1.0 + 5e-6, 0.99):
        p = np.array([0.0, 0.0, length, 0.0])
        assert not slack_axial_jacobian(p, v, elements, rest, k, c, 1.0, 1.0, np.zeros((4, 4)), 0.0, True).any()


def test_cut_slopes_hold_for_the_first_newton_iterations_of_each_attempt_at_a_step():
    """Counted as force evaluations at one time: the first CUT_SLOPE_ITERATIONS are active, the
    next is not (Newton then sees the law's own slopes: an element the converged state truly
    cuts would converge only linearly with taut slopes); a new time, a new step or a retried
    shorter one, starts again."""
    from cdpr_exu.physics.axial import CUT_SLOPE_ITERATIONS, CutSlopes

    cut = CutSlopes()
    for _ in range(CUT_SLOPE_ITERATIONS):
        cut.force_evaluated(0.01)
        assert cut.active
    cut.force_evaluated(0.01)
    assert not cut.active
    cut.force_evaluated(0.005)
    assert cut.active
