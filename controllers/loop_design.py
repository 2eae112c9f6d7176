"""The position loop of :class:`~controllers.feedback.FilteredPositionPI`, linearised: margins, poles, gains.

The loop measures the position r (x, z) one solver step h late and commands
dlambda = U (k_p + k_i / s) F(s) e, F the Butterworth filter, U the ideal Jacobian of the
controllers' model at the reference pose. The plant (:func:`linearise`) is the simulator's
own lumped cables (:mod:`cdpr_exu.statics.chain_statics`) and the rigid platform, at the
equilibrium holding the reference pose under the weight and the inertial load -M a:

    M q'' + C q' + K q = B0 dlambda + B1 dlambda',

q the interior nodes and the platform pose; K = -dQ/dq by central differences of
:func:`~cdpr_exu.statics.chain_statics.chain_forces`; C the axial and bending dampers; B0, B1
the winches. The cables' transverse modes are in it (the paper robot's first near 2 Hz,
inside the loop's band); slack, velocity terms, the fade-in and the contact's damping are
not. Margins (:func:`loop_margins`, python-control): loop-at-a-time gain and phase margins
of L = G U K (the delay exact), the balanced disk margin of the unstructured sensitivity
(conservative: the structured one needs slycot), and the closed-loop poles (the delay a Pade
approximant of order 3: below 1e-6 rad of phase error at 10 Hz and 2 ms).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from cdpr_exu.core.errors import CdprWarning, SceneError
from cdpr_exu.core.validation import shown

#: Step of the central differences, relative to the shortest element [-].
DIFFERENCE_STEP = 1e-7

#: Frequencies the margins are evaluated at [rad/s], 120 per decade (3000 points agree to 1e-8 dB and deg).
MARGIN_FREQUENCIES = np.logspace(-2, np.log10(2000.0), 633)

#: Damping ratio of the position loop's error filter (Butterworth).
FILTER_DAMPING = float(np.sqrt(0.5))

#: The margins a loop must keep on its model before a run [dB, deg].
REQUIRED_MARGINS = (6.0, 30.0)

#: Reference poses a loop is checked at before a run, evenly over the run (about 1.5 s each).
CHECK_POSES = 4


class PoorMarginsWarning(CdprWarning):
    """A position loop keeps less than :data:`REQUIRED_MARGINS` on its model: the run goes on without it."""


def _equilibrium(scene, pose, wrench):
    """(chain robot, chain-statics equilibrium) holding ``scene``'s platform centre at ``pose[:2]`` under ``wrench``."""
    from cdpr_exu.statics import chain_statics, statics

    chain = chain_statics.chain_robot(scene)
    start = statics.solve_inverse_statics(statics.catenary_platform(scene), pose[:2], external_wrench=wrench)
    return chain, chain_statics.solve_inverse_chain_statics(chain, (*pose[:2], start.rotation), external_wrench=wrench,
                                                            tension_guess=[c.tension_at_anchor for c in start.cables])


def ideal_jacobian(scene, pose) -> np.ndarray:
    """U = d(lambda)/d(position) of ``scene``'s ideal cables at ``pose``, shape (m, 2) [m/m] (the loop's)."""
    from cdpr_exu.statics.kinematics import cable_exits

    return np.stack([exit_.unit_vector for exit_ in cable_exits(scene, np.asarray(pose, dtype=float))], axis=-2)


@dataclass(frozen=True)
class LinearRobot:
    """The robot linearised at one pose: M, C, K (n, n) [kg, N s/m, N/m], B0, B1 (n, m) [N/m, N s/m] (force
    per metre and per metre per second paid out); ``platform``: the row of q where (x, z, rotation) start."""

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    input_stiffness: np.ndarray
    input_damping: np.ndarray
    platform: int

    def response(self, omega) -> np.ndarray:
        """G(j omega): the platform position (x, z) per paid-out length, shape (F, 2, m) [m/m]."""
        rows = [self.platform, self.platform + 1]
        return np.stack([np.linalg.solve(self.stiffness - w * w * self.mass + 1j * w * self.damping,
                                         self.input_stiffness + 1j * w * self.input_damping)[rows]
                         for w in np.asarray(omega, dtype=float)])

    def system(self):
        """G as a python-control state space: states (q, M q' - B1 dlambda), input dlambda, output (x, z)."""
        import control as ct

        n = self.mass.shape[0]
        inverse = np.linalg.inv(self.mass)
        A = np.block([[np.zeros((n, n)), inverse], [-self.stiffness, -self.damping @ inverse]])
        B = np.vstack([inverse @ self.input_damping, self.input_stiffness - self.damping @ inverse @ self.input_damping])
        C = np.zeros((2, 2 * n))
        C[[0, 1], [self.platform, self.platform + 1]] = 1.0
        return ct.ss(A, B, C, 0.0)


def models(scene) -> bool:
    """Whether :func:`linearise` models ``scene``'s robot: planar, with two cables."""
    return scene.dimension == 2 and scene.n_cables == 2


def linearise(scene, pose, acceleration=None) -> LinearRobot:
    """Linearise a planar two-cable robot about the equilibrium holding its centre at ``pose[:2]`` [m] (the
    rotation the balance's) under the weight and the load -M ``acceleration`` [m/s^2].

    Raises
    ------
    SceneError
        For a spatial scene or one without two cables.
    UnreachableError
        If the cables cannot hold the pose.
    """
    from cdpr_exu.statics.chain_statics import chain_forces

    if not models(scene):
        raise SceneError(f"the loop design handles planar two-cable robots, got dimension {scene.dimension} "
                         f"with {scene.n_cables} cables")
    pose = np.asarray(pose, dtype=float)
    acceleration = np.zeros(2) if acceleration is None else np.asarray(acceleration, dtype=float)
    wrench = np.array([*(-scene.platform.mass * acceleration[:2]), 0.0])
    chain, equilibrium = _equilibrium(scene, pose, wrench)
    nodes = [np.array(n, dtype=float) for n in equilibrium.nodes]
    position, rotation = np.asarray(equilibrium.position, dtype=float), float(equilibrium.rotation)
    interior = sum(len(n) - 2 for n in nodes)
    n, platform = 2 * interior + 3, 2 * interior

    def forces(q, lengths):
        """Q(q, lambda): the interior nodes' forces and the platform's wrench, flat (n,)."""
        moved, offset = [], 0
        x, z, phi = q[platform:]
        turn = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
        for cable, base, length in zip(chain.cables, nodes, lengths):
            k = len(base) - 2
            current = base.copy()
            current[1:-1] = q[offset:offset + 2 * k].reshape(k, 2)
            current[0], current[-1] = cable.winch_node(length), np.array([x, z]) + turn @ np.asarray(cable.anchor)
            moved.append(current)
            offset += 2 * k
        node_forces, platform_wrench = chain_forces(chain, moved, (x, z), phi, wrench)
        return np.concatenate([node_forces.ravel(), platform_wrench])

    q0 = np.concatenate([*(nd[1:-1].ravel() for nd in nodes), position, [rotation]])
    lengths0 = np.asarray(equilibrium.paid_out, dtype=float)
    step = DIFFERENCE_STEP * min(c.element_length for c in chain.cables)
    K = np.column_stack([-(forces(q0 + step * e, lengths0) - forces(q0 - step * e, lengths0)) / (2 * step)
                         for e in np.eye(n)])
    B0 = np.column_stack([(forces(q0, lengths0 + step * e) - forces(q0, lengths0 - step * e)) / (2 * step)
                          for e in np.eye(2)])
    # dX/dq (interior nodes one to one, anchors with the platform) and dX/dlambda (the winch nodes)
    counts = [len(nd) for nd in nodes]
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)
    T, S = np.zeros((2 * sum(counts), n)), np.zeros((2 * sum(counts), 2))
    M = np.zeros((n, n))
    offset = 0
    for i, (cable, f, count) in enumerate(zip(chain.cables, first, counts)):
        for k in range(1, count - 1):
            T[2 * (f + k):2 * (f + k) + 2, offset:offset + 2] = np.eye(2)
            M[offset:offset + 2, offset:offset + 2] = cable.node_masses[k] * np.eye(2)
            offset += 2
        arm = nodes[i][-1] - position
        anchor = np.array([[1.0, 0.0, -arm[1]], [0.0, 1.0, arm[0]]])  # d anchor / d (x, z, rotation)
        T[2 * (f + count - 1):2 * (f + count), platform:] = anchor
        M[platform:, platform:] += cable.node_masses[-1] * anchor.T @ anchor
        S[2 * f:2 * f + 2, i] = (cable.winch_node(lengths0[i] + step) - cable.winch_node(lengths0[i] - step)) / (2 * step)
    M[platform:, platform:] += np.diag([scene.platform.mass, scene.platform.mass, scene.platform.inertia])
    CX = _node_damping(scene, np.concatenate(nodes), counts)
    return LinearRobot(M, T.T @ CX @ T, K, B0, -T.T @ CX @ S, platform)


def _node_damping(scene, X, counts) -> np.ndarray:
    """-dF/dv of the axial Kelvin-Voigt and bending dampers in all nodes' coordinates, shape (2N, 2N) [N s/m]."""
    from cdpr_exu.physics import bending

    effects = scene.effects
    CX = np.zeros((X.size, X.size))
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)
    for cable, f, count in zip(scene.cables, first, counts):
        for a in range(f, f + count - 1) if effects.axial_damping else ():
            u = (X[a + 1] - X[a]) / np.linalg.norm(X[a + 1] - X[a])
            block = cable.axial_damping * np.outer(u, u)
            for r, s, sign in ((a, a, 1), (a + 1, a + 1, 1), (a, a + 1, -1), (a + 1, a, -1)):
                CX[2 * r:2 * r + 2, 2 * s:2 * s + 2] += sign * block
    if effects.bending and effects.bending_damping:
        damping = np.concatenate([np.full(c - 2, cable.bending_damping) for cable, c in zip(scene.cables, counts)])
        dampers = bending.BendingSpringDamper(len(X), bending.cable_joints(counts), np.zeros_like(damping), damping)
        CX += dampers.jacobian(X.ravel(), np.zeros(X.size))[1]
    return CX


@dataclass(frozen=True)
class LoopGains:
    """The gains of a :class:`~controllers.feedback.FilteredPositionPI` loop [-, 1/s, Hz]; the defaults are
    :data:`DESIGNED`'s."""

    proportional_gain: float = 3.0
    integral_gain: float = 10.0
    cutoff: float = 5.0

    def __post_init__(self):
        for name, low in (("proportional_gain", 0.0), ("integral_gain", 0.0), ("cutoff", 1e-300)):
            value = getattr(self, name)
            if not np.isfinite(value) or value < low:
                raise SceneError(f"{name} must be {'positive' if low else 'zero or positive'}, got {shown(value)}")

    def law(self, omega, delay: float) -> np.ndarray:
        """(k_p + k_i / s) F(s) exp(-s h) at s = j omega, shape (F,)."""
        s = 1j * np.asarray(omega, dtype=float)
        wc = 2 * np.pi * self.cutoff
        return ((self.proportional_gain + self.integral_gain / s) * wc**2 / (s**2 + 2 * FILTER_DAMPING * wc * s + wc**2)
                * np.exp(-s * delay))

    def system(self, jacobian, delay: float):
        """The controller as a python-control state space: error (2) -> dlambda (m), the delay a Pade (3)."""
        import control as ct

        wc = 2 * np.pi * self.cutoff
        law = (ct.tf([self.proportional_gain, self.integral_gain], [1.0, 0.0])
               * ct.tf([wc**2], [1.0, 2 * FILTER_DAMPING * wc, wc**2]) * ct.tf(*ct.pade(delay, 3)))
        per_axis = ct.append(*[ct.ss(law)] * 2)
        return ct.ss([], [], [], np.asarray(jacobian, dtype=float)) * per_axis


#: The planar loop's default gains (FilteredPositionPI; closed_loop_tension_aware, closed_loop_model_feed_forward):
#: what :func:`design_gains` picks on the robustness study's 13 plants (examples/robustness_study.py, which
#: refuses to write its tables if the design and these defaults part).
DESIGNED = LoopGains()
#: The gains chosen by trial before the loop was designed from its margins (down to 18.6 deg of phase margin).
PREVIOUS = LoopGains(2.0, 40.0, 5.0)


@dataclass(frozen=True)
class Margins:
    """Stability margins of the 2 x 2 position loop at one pose.

    Attributes
    ----------
    gain_margin_db, phase_margin_deg : float [dB, deg]
        The smaller of the two loops', each with the other closed; inf without a crossing.
    disk_margin : float [-]
        alpha: both loops may change gain within [(2 - alpha)/(2 + alpha), (2 + alpha)/(2 - alpha)]
        and phase by +-2 atan(alpha/2) at once.
    sensitivity_peak, min_damping : float [-]
        Max of sigma_max((I + L)^-1); smallest damping ratio of the poles below 50 Hz.
    """

    gain_margin_db: float
    phase_margin_deg: float
    disk_margin: float
    sensitivity_peak: float
    min_damping: float
    stable: bool

    def to_dict(self) -> dict:
        """Plain data, strict-JSON ready (None for an infinite margin)."""
        return {k: (bool(v) if isinstance(v, (bool, np.bool_)) else (float(v) if np.isfinite(v) else None))
                for k, v in self.__dict__.items()}


def _siso_margins(response, omega) -> tuple[float, float]:
    """(gain margin [dB], phase margin [deg]) of a SISO loop's frequency response, the smallest of each."""
    import control as ct

    gm, pm, _, _, _, _ = ct.stability_margins(ct.frd(response, omega), returnall=True)
    gm, pm = np.atleast_1d(np.asarray(gm, dtype=float)), np.atleast_1d(np.asarray(pm, dtype=float))
    gm = np.abs(20 * np.log10(gm[np.isfinite(gm) & (gm > 0)]))
    return (float(gm.min()) if gm.size else float("inf")), (float(pm.min()) if pm.size else float("inf"))


def _disk_margin(L) -> float:
    """Balanced disk margin alpha = 1 / max sigma_max(S - I/2) of L (F, 2, 2)."""
    eye = np.eye(2)[None]
    return 1.0 / float(np.linalg.svd(np.linalg.inv(eye + L) - 0.5 * eye, compute_uv=False)[:, 0].max())


def _loop_at_a_time(L, omega) -> tuple[float, float]:
    """The smaller gain [dB] and phase [deg] margins of the two loops of L (F, 2, 2), each with the other closed."""
    margins = [_siso_margins(L[:, i, i] - L[:, i, 1 - i] * L[:, 1 - i, i] / (1.0 + L[:, 1 - i, 1 - i]), omega)
               for i in range(2)]
    return min(g for g, _ in margins), min(p for _, p in margins)


def loop_margins(robot: LinearRobot, jacobian, gains: LoopGains, delay: float,
                 omega=MARGIN_FREQUENCIES, response=None) -> Margins:
    """Margins and closed-loop stability of the position loop on ``robot`` (the plant, which may differ from
    the model whose U (m, 2) is ``jacobian``); ``delay`` [s]: the solver step; ``response``: G U if known."""
    import control as ct

    plant = robot.response(omega) @ jacobian if response is None else response
    L = gains.law(omega, delay)[:, None, None] * plant
    gain, phase = _loop_at_a_time(L, omega)
    poles = ct.feedback(robot.system() * gains.system(jacobian, delay), np.eye(2)).poles()
    slow = poles[np.abs(poles) < 2 * np.pi * 50]
    stable = bool(np.all(poles.real < 0))
    return Margins(gain if stable else 0.0, phase if stable else 0.0,
                   _disk_margin(L), float(np.linalg.svd(np.linalg.inv(np.eye(2) + L), compute_uv=False)[:, 0].max()),
                   float(np.min(-slow.real / np.abs(slow))), stable)


def loop_cases(model, plants, times, omega=MARGIN_FREQUENCIES) -> list[tuple]:
    """(plant index, time, LinearRobot, U, G U) for each plant linearised at the reference poses of ``times``
    [s] of ``model`` (whose U is the loop's)."""
    cases = []
    for (index, plant), t in itertools.product(enumerate(plants), np.asarray(times, dtype=float)):
        pose = model.trajectory.pose(t)
        jacobian = ideal_jacobian(model, pose)
        robot = linearise(plant, pose, model.trajectory.acceleration(t))
        cases.append((index, float(t), robot, jacobian, robot.response(omega) @ jacobian))
    return cases


def design_gains(cases, delay: float, frequency: float, gain_margin_db: float = REQUIRED_MARGINS[0],
                 phase_margin_deg: float = REQUIRED_MARGINS[1],
                 candidates=None, omega=MARGIN_FREQUENCIES) -> tuple[LoopGains, float]:
    """The gains that meet the margins on every case of :func:`loop_cases` and track best at ``frequency``.

    Of the candidates (default: k_p 0.5-3, k_i 0-40 /s, f_c 1-5 Hz) stable with the margins on
    every case, the one with the smallest worst sensitivity sigma_max(S(j 2 pi f)) at the
    reference's ``frequency`` [Hz]; returns it and that sensitivity. The margins are read from
    the frequency response, the poles checked on the winner. SceneError if none meets them.
    """
    if candidates is None:
        candidates = [LoopGains(p, i, c) for p, i, c in itertools.product(
            (0.5, 1.0, 1.5, 2.0, 3.0), (0.0, 2.5, 5.0, 10.0, 20.0, 40.0), (1.0, 2.0, 3.0, 5.0))]
    # a disk margin that guarantees both margins in each loop (a one-loop change lies inside the disk)
    disk = max(2 * (10 ** (gain_margin_db / 20) - 1) / (10 ** (gain_margin_db / 20) + 1),
               2 * np.tan(np.radians(phase_margin_deg) / 2))

    def _meets(L, omega, disk):
        if _disk_margin(L) >= disk:
            return True
        gain, phase = _loop_at_a_time(L, omega)
        return gain >= gain_margin_db and phase >= phase_margin_deg

    w = np.array([2 * np.pi * frequency])
    at_frequency = [robot.response(w)[0] @ jacobian for _, _, robot, jacobian, _ in cases]
    scored = []
    for gains in candidates:
        law = gains.law(omega, delay)[:, None, None]
        if all(_meets(law * response, omega, disk) for *_, response in cases):
            here = gains.law(w, delay)[0]
            scored.append((max(float(np.linalg.svd(np.linalg.inv(np.eye(2) + here * G), compute_uv=False)[0])
                               for G in at_frequency), gains))
    for worst, gains in sorted(scored, key=lambda s: s[0]):
        if all(loop_margins(robot, jacobian, gains, delay, omega, response).stable
               for _, _, robot, jacobian, response in cases):
            return gains, worst
    raise SceneError(f"no candidate gains meet {gain_margin_db} dB and {phase_margin_deg} deg on every case")


def worst(margins) -> Margins:
    """The worst of several :class:`Margins` (over poses): each margin's smallest, the peak's largest."""
    return Margins(*(min(getattr(m, k) for m in margins)
                     for k in ("gain_margin_db", "phase_margin_deg", "disk_margin")),
                   max(m.sensitivity_peak for m in margins), min(m.min_damping for m in margins),
                   all(m.stable for m in margins))


def check_loop(scene, gains: LoopGains, poses: int = CHECK_POSES) -> Margins:
    """The worst margins of ``gains``' loop on ``scene``'s robot at ``poses`` reference poses over its run
    (one step late; about 1.5 s per pose); SceneError for a robot :func:`linearise` does not model."""
    end = scene.solver.end_time
    times = end * (np.arange(poses) + 0.5) / poses
    cases = loop_cases(scene, [scene], times)
    return worst([loop_margins(robot, jacobian, gains, scene.solver.step_size, response=response)
                  for _, _, robot, jacobian, response in cases])


def meets(margins: Margins, required=REQUIRED_MARGINS) -> bool:
    """Whether ``margins`` are stable with at least the ``required`` (gain [dB], phase [deg]) margins."""
    return margins.stable and margins.gain_margin_db >= required[0] and margins.phase_margin_deg >= required[1]
