"""The position loop of :class:`~controllers.feedback.FilteredPositionPI`, linearised: margins, poles, gains.

The loop measures the platform's position (with ``rotation`` also its rotation) one solver step h late
and commands dlambda = U (k_p + k_i / s) F(s) e, F the Butterworth filter, U the ideal Jacobian of the
controllers' model at the reference pose. The plant (:func:`linearise`) is the simulator's own lumped
cables and the rigid platform, at the equilibrium of the chain statics
(:mod:`cdpr_exu.statics.chain_statics`) holding the reference pose under the weight and the inertial
load -M a:

    M q'' + C q' + K q = B0 dlambda + B1 dlambda',

q the interior nodes and the platform's pose (in space its small rotation about the world axes); C the
axial and bending dampers; B0, B1 the winches. Written once where the concept is the same (the loop, its
margins, the design); per Space (:data:`_PLANTS`) where it is not: in the plane K = -dQ/dq by central
differences of :func:`~cdpr_exu.statics.chain_statics.chain_forces` and the winch moves node 0 along its
line; in space, at point exits, K the chain statics' Hessian and the winch changes every element's rest
length. The cables' transverse modes are in it (the paper robot's first near 2 Hz, CoGiRo's near 2.4 Hz,
inside the loops' bands); slack, velocity terms, the fade-in and the contact's damping are not. Margins
(:func:`loop_margins`, python-control): loop-at-a-time gain and phase margins of L = G U K (the delay
exact; each loop with the others closed), the balanced disk margin of the unstructured sensitivity
(conservative: the structured one needs slycot), and the closed-loop poles (the delay a Pade
approximant of order 3: below 1e-6 rad of phase error at 10 Hz and 2 ms).
"""

from __future__ import annotations

import itertools
from collections import namedtuple
from dataclasses import dataclass

import numpy as np

from cdpr_exu.core.errors import CdprWarning, SceneError
from cdpr_exu.core.validation import shown
from cdpr_exu.space import PLANE, SPACE

#: Step of the central differences, relative to the shortest element [-].
DIFFERENCE_STEP = 1e-7

#: Frequencies the margins are evaluated at [rad/s], 120 per decade (3000 points agree to 1e-8 dB and deg).
MARGIN_FREQUENCIES = np.logspace(-2, np.log10(2000.0), 633)

#: Damping ratio of the position loop's error filter (Butterworth).
FILTER_DAMPING = float(np.sqrt(0.5))

#: The margins a loop must keep on its model before a run [dB, deg].
REQUIRED_MARGINS = (6.0, 30.0)

#: Above this many coordinates the frequency response solves sparse (a spatial robot's 462: 0.7 s of CPU for
#: :data:`MARGIN_FREQUENCIES` against 11 s dense, the same to 2e-10); a planar robot's few dozen stay dense.
DENSE_SIZE = 200

#: Reference poses a loop is checked at before a run, evenly over the run (about 1.5 s each).
CHECK_POSES = 4


class PoorMarginsWarning(CdprWarning):
    """A position loop keeps less than :data:`REQUIRED_MARGINS` on its model: the run goes on without it."""


def ideal_jacobian(scene, pose, size: int | None = None) -> np.ndarray:
    """U = d(lambda)/d(error) of ``scene``'s ideal cables at ``pose``, shape (m, size) [m/m, m/rad] (the loop's:
    the first ``size`` columns of :func:`~cdpr_exu.statics.kinematics.length_jacobian`, default the position's)."""
    from cdpr_exu.statics.kinematics import length_jacobian

    return length_jacobian(scene, np.asarray(pose, dtype=float))[:, :scene.space.position_size if size is None else size]


@dataclass(frozen=True)
class LinearRobot:
    """The robot linearised at one pose: M, C, K (n, n) [kg, N s/m, N/m], B0, B1 (n, m) [N/m, N s/m] (force
    per metre and per metre per second paid out); ``platform``: the row of q where the platform's pose
    starts (position, then the small rotation: about the world axes in space); ``outputs``: how many of
    its coordinates the loop measures."""

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    input_stiffness: np.ndarray
    input_damping: np.ndarray
    platform: int
    outputs: int = 2

    def response(self, omega) -> np.ndarray:
        """G(j omega): the measured platform coordinates per paid-out length, shape (F, outputs, m) [m/m, rad/m]."""
        import scipy.sparse as sparse
        from scipy.sparse.linalg import splu

        rows = self.platform + np.arange(self.outputs)
        dense = self.mass.shape[0] <= DENSE_SIZE
        K, M, C = (a if dense else sparse.csc_matrix(a) for a in (self.stiffness, self.mass, self.damping))
        solve = np.linalg.solve if dense else (lambda matrix, rhs: splu(matrix.tocsc()).solve(rhs))
        return np.stack([solve(K - w * w * M + 1j * w * C, self.input_stiffness + 1j * w * self.input_damping)[rows]
                         for w in np.asarray(omega, dtype=float)])

    def system(self):
        """G as a python-control state space: states (q, M q' - B1 dlambda), input dlambda, output the measured
        platform coordinates."""
        import control as ct

        n = self.mass.shape[0]
        inverse = np.linalg.inv(self.mass)
        A = np.block([[np.zeros((n, n)), inverse], [-self.stiffness, -self.damping @ inverse]])
        B = np.vstack([inverse @ self.input_damping, self.input_stiffness - self.damping @ inverse @ self.input_damping])
        C = np.zeros((self.outputs, 2 * n))
        C[np.arange(self.outputs), self.platform + np.arange(self.outputs)] = 1.0
        return ct.ss(A, B, C, 0.0)


def models(scene) -> bool:
    """Whether :func:`linearise` models ``scene``'s robot: :data:`_PLANTS`' rule for its Space."""
    return _PLANTS[scene.space].models(scene)


def linearise(scene, pose, acceleration=None, rotation: bool = False) -> LinearRobot:
    """Linearise ``scene``'s robot about the equilibrium holding its platform at ``pose`` [m, rad] under the
    weight and the load -M ``acceleration`` [m/s^2] (of its centre; the angular one left out); the loop
    measures its position, with ``rotation`` (a rigid platform) its rotation too. In the plane the
    centre is held at ``pose[:2]``, the rotation the balance's.

    Raises
    ------
    SceneError
        For a robot :func:`models` says no to.
    UnreachableError
        If the cables cannot hold the pose.
    """
    plant = _PLANTS[scene.space]
    if not plant.models(scene):
        raise SceneError(f"the loop design handles {plant.handles}, got scene {scene.name!r} ({scene.space.name}, "
                         f"{scene.n_cables} cables)")
    space, rigid = scene.space, not scene.platform.is_point_mass
    acceleration = np.zeros(space.position_size) if acceleration is None else np.asarray(acceleration, dtype=float)
    outputs = space.position_size + (space.rotation_size if rotation and rigid else 0)
    return plant.linearise(scene, np.asarray(pose, dtype=float), -scene.platform.mass * acceleration[:space.position_size],
                           outputs)


def _planar_robot(scene, pose, force, outputs) -> LinearRobot:
    """:func:`linearise` in the plane: the interior nodes (x, z) and the platform's (x, z, rotation); K = -dQ/dq
    by central differences of :func:`~cdpr_exu.statics.chain_statics.chain_forces`; the winch moves node 0."""
    from cdpr_exu.statics import chain_statics, statics
    from cdpr_exu.statics.chain_statics import chain_forces

    wrench = np.array([*force, 0.0])
    chain = chain_statics.chain_robot(scene)
    start = statics.solve_inverse_statics(statics.catenary_platform(scene), pose[:2], external_wrench=wrench)
    equilibrium = chain_statics.solve_inverse_chain_statics(chain, (*pose[:2], start.rotation), external_wrench=wrench,
                                                            tension_guess=[c.tension_at_anchor for c in start.cables])
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
    return LinearRobot(M, T.T @ CX @ T, K, B0, -T.T @ CX @ S, platform, outputs)


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


def spatial_equilibrium(scene, pose, force):
    """The spatial chain statics' equilibrium holding ``scene``'s platform at ``pose`` (6,) [m, rad] under
    ``force`` (3,) [N] on its centre, the tensions nearest the rest's (the catenary's statics start it)."""
    from cdpr_exu.statics import chain_statics, statics

    platform = statics.catenary_platform(scene)
    rest = statics.solve_statics(platform, scene.unstrained_lengths)
    wrench = np.concatenate([force, np.zeros(3)])
    start = statics.solve_inverse_statics(platform, pose, wrench,
                                          initial_guess=np.array([c.catenary.horizontal_tension for c in rest.cables]))
    robot = chain_statics.chain_robot(scene)
    nodes = []
    for cable, state in zip(robot.cables, start.cables):
        length = state.unstrained_length
        points = state.points(length - np.linspace(0.0, length, cable.n_elements + 1))
        points[0] = cable.exit_point
        nodes.append(points)
    return robot, chain_statics.solve_inverse_chain_statics(
        robot, pose, [c.tension_at_anchor for c in start.cables], lengths=start.unstrained_lengths, nodes=nodes,
        external_wrench=wrench)


def _spatial_robot(scene, pose, force, outputs) -> LinearRobot:
    """:func:`linearise` in space, at point exits: the interior nodes (x, y, z), the platform's position and
    (rigid) small rotation about the world axes; K the chain statics' Hessian
    (:meth:`~cdpr_exu.statics.chain_kernels.SpatialChains.derivatives`). A winch at a point exit pays out
    by changing every element's rest length lambda / n (and with it k, the node weights and the bending
    stiffness: B0 by central differences), and the dampers act on d(l - lambda / n)/dt (B1)."""
    from cdpr_exu.physics import bending_3d
    from cdpr_exu.physics.sparse_blocks import block_pattern
    from cdpr_exu.statics.chain_kernels import SpatialChains
    from cdpr_exu.statics.chain_statics import robot_paid_out

    chain, equilibrium = spatial_equilibrium(scene, pose, force)
    lengths = np.asarray(equilibrium.paid_out, dtype=float)

    def model(paid_out):
        held = SpatialChains(robot_paid_out(chain, paid_out))
        held.external_force = force
        return held

    held = model(lengths)
    points = np.concatenate(equilibrium.nodes)
    state = (points[held.free].ravel(), np.asarray(equilibrium.position, float), equilibrium.rotation, np.zeros(0))
    K = held.derivatives(*state)[1].toarray()
    step = DIFFERENCE_STEP * float(held.l0.min())
    B0 = np.column_stack([-(model(lengths + step * e).derivatives(*state)[0]
                            - model(lengths - step * e).derivatives(*state)[0]) / (2 * step)
                          for e in np.eye(len(lengths))])
    T = held._map(equilibrium.rotation).toarray()
    platform = held.n_free
    M = np.diag(np.concatenate([np.repeat(held.masses[held.free], 3), np.zeros(K.shape[0] - platform)]))
    body = np.array([j for j, _ in held.body])
    for j in body:
        anchor = T[3 * j:3 * j + 3, platform:]
        M[platform:, platform:] += held.masses[j] * anchor.T @ anchor
    M[platform:platform + 3, platform:platform + 3] += scene.platform.mass * np.eye(3)
    if held.rigid:
        R = equilibrium.rotation
        M[platform + 3:, platform + 3:] += R @ np.diag(scene.platform.inertia) @ R.T
    # the dampers in the points' coordinates: CX = -dF/dv, SX = dF/d(lambda')
    effects, n = scene.effects, held.counts[0] - 1
    size = 3 * held.n_points
    CX, SX = np.zeros((size, size)), np.zeros((size, len(lengths)))
    if effects.axial_damping:
        a, b = held.elements[:, 0], held.elements[:, 1]
        t = (points[b] - points[a]) / np.linalg.norm(points[b] - points[a], axis=1)[:, None]
        c = np.array([cable.damping_constant * cable.area * n / lengths[i] for i, cable in
                      ((i, scene.cables[i]) for i in held.element_cable)])
        block = c[:, None, None] * t[:, :, None] * t[:, None, :]
        for r, s, sign in ((a, a, 1), (b, b, 1), (a, b, -1), (b, a, -1)):
            np.add.at(CX, (3 * r[:, None, None] + np.arange(3)[:, None], 3 * s[:, None, None] + np.arange(3)),
                      sign * block)
        np.add.at(SX, (3 * a[:, None] + np.arange(3), held.element_cable[:, None]), -(c / n)[:, None] * t)
        np.add.at(SX, (3 * b[:, None] + np.arange(3), held.element_cable[:, None]), (c / n)[:, None] * t)
    if effects.bending and effects.bending_damping:
        joints = held.joints
        cable_of = np.repeat(np.arange(len(lengths)), held.counts)[joints[:, 1]]
        damping = np.array([scene.cables[i].damping_constant * scene.cables[i].second_moment * n / lengths[i]
                            for i in cable_of])
        values = np.zeros(81 * len(joints))
        bending_3d.add_spatial_bending_damping_jacobian(points.ravel(), np.zeros(size), joints, damping,
                                                        bending_3d.ISOTROPIC_BEND, 0.0, 1.0, values)
        rows, columns = block_pattern(joints, 3)
        np.add.at(CX, (rows, columns), values)
    T = T[:size]
    return LinearRobot(M, T.T @ CX @ T, K, B0, T.T @ SX, platform, outputs)


#: Each Space's plant: which robots it models (and how it says so), and its :func:`linearise`.
_Plant = namedtuple("_Plant", "models handles linearise")
_PLANTS = {PLANE: _Plant(lambda scene: scene.n_cables == 2, "planar two-cable robots", _planar_robot),
           SPACE: _Plant(lambda scene: not any(e.wraps for e in scene.exits) and (
               scene.platform.is_point_mass or scene.n_cables >= 6), "spatial robots at point exits (a point mass, or "
               "a rigid platform on six cables or more)", _spatial_robot)}


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
        """The controller as a python-control state space: error (e) -> dlambda (m), U (m, e) the ``jacobian``,
        the delay a Pade (3)."""
        import control as ct

        wc = 2 * np.pi * self.cutoff
        law = (ct.tf([self.proportional_gain, self.integral_gain], [1.0, 0.0])
               * ct.tf([wc**2], [1.0, 2 * FILTER_DAMPING * wc, wc**2]) * ct.tf(*ct.pade(delay, 3)))
        per_axis = ct.append(*[ct.ss(law)] * np.shape(jacobian)[1])
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
    """(gain margin [dB], phase margin [deg]) of a SISO loop's frequency response, the smallest of each.

    The phase margin of a gain crossover is the smallest phase change, lag or lead, that puts the loop
    on -1: python-control gives a crossover at phase p as p + 180 wrapped into (-180, 180], negative for
    a lead (a lightly damped cable mode's resonance crossing unity at +112 deg: -67.8, 67.8 deg from -1).
    Whether the closed loop is stable is checked apart, on its poles (:func:`loop_margins`)."""
    import control as ct

    gm, pm, _, _, _, _ = ct.stability_margins(ct.frd(response, omega), returnall=True)
    gm, pm = np.atleast_1d(np.asarray(gm, dtype=float)), np.abs(np.atleast_1d(np.asarray(pm, dtype=float)))
    gm = np.abs(20 * np.log10(gm[np.isfinite(gm) & (gm > 0)]))
    return (float(gm.min()) if gm.size else float("inf")), (float(pm.min()) if pm.size else float("inf"))


def _disk_margin(L) -> float:
    """Balanced disk margin alpha = 1 / max sigma_max(S - I/2) of L (F, e, e)."""
    eye = np.eye(L.shape[-1])[None]
    return 1.0 / float(np.linalg.svd(np.linalg.inv(eye + L) - 0.5 * eye, compute_uv=False)[:, 0].max())


def _with_others_closed(L, i) -> np.ndarray:
    """Loop i's response (F,) with every other loop of L (F, e, e) closed, closed one at a time."""
    while L.shape[-1] > 1:
        other = int(i == 0)
        rest = [j for j in range(L.shape[-1]) if j != other]
        L = (L[:, rest][:, :, rest]
             - L[:, rest, other][:, :, None] * L[:, other, rest][:, None, :] / (1.0 + L[:, other, other])[:, None, None])
        i -= int(other < i)
    return L[:, 0, 0]


def _loop_at_a_time(L, omega) -> tuple[float, float]:
    """The smallest gain [dB] and phase [deg] margins of the loops of L (F, e, e), each with the others closed."""
    margins = [_siso_margins(_with_others_closed(L, i), omega) for i in range(L.shape[-1])]
    return min(g for g, _ in margins), min(p for _, p in margins)


def loop_margins(robot: LinearRobot, jacobian, gains: LoopGains, delay: float,
                 omega=MARGIN_FREQUENCIES, response=None) -> Margins:
    """Margins and closed-loop stability of the position loop on ``robot`` (the plant, which may differ from
    the model whose U (m, e) is ``jacobian``); ``delay`` [s]: the solver step; ``response``: G U if known."""
    import control as ct

    plant = robot.response(omega) @ jacobian if response is None else response
    L = gains.law(omega, delay)[:, None, None] * plant
    gain, phase = _loop_at_a_time(L, omega)
    eye = np.eye(L.shape[-1])
    poles = ct.feedback(robot.system() * gains.system(jacobian, delay), eye).poles()
    slow = poles[np.abs(poles) < 2 * np.pi * 50]
    stable = bool(np.all(poles.real < 0))
    return Margins(gain if stable else 0.0, phase if stable else 0.0,
                   _disk_margin(L), float(np.linalg.svd(np.linalg.inv(eye + L), compute_uv=False)[:, 0].max()),
                   float(np.min(-slow.real / np.abs(slow))), stable)


def loop_cases(model, plants, times, omega=MARGIN_FREQUENCIES, rotation: bool = False) -> list[tuple]:
    """(plant index, time, LinearRobot, U, G U) for each plant linearised at the reference poses of ``times``
    [s] of ``model`` (whose U is the loop's); ``rotation``: the loop feeds a rigid platform's rotation back."""
    cases = []
    for (index, plant), t in itertools.product(enumerate(plants), np.asarray(times, dtype=float)):
        pose = model.trajectory.pose(t)
        robot = linearise(plant, pose, model.trajectory.acceleration(t), rotation)
        jacobian = ideal_jacobian(model, pose, robot.outputs)
        cases.append((index, float(t), robot, jacobian, robot.response(omega) @ jacobian))
    return cases


def design_gains(cases, delay: float, frequency: float, gain_margin_db: float = REQUIRED_MARGINS[0],
                 phase_margin_deg: float = REQUIRED_MARGINS[1],
                 candidates=None, omega=MARGIN_FREQUENCIES, disk_only: bool = False) -> tuple[LoopGains, float]:
    """The gains that meet the margins on every case of :func:`loop_cases` and track best at ``frequency``.

    Of the candidates (default: k_p 0.5-3, k_i 0-40 /s, f_c 1-5 Hz) stable with the margins on
    every case, the one with the smallest worst sensitivity sigma_max(S(j 2 pi f)) at the
    reference's ``frequency`` [Hz]; returns it and that sensitivity. The margins are read from
    the frequency response, the poles checked on the winner. SceneError if none meets them.
    A case meets them through a disk margin that guarantees both, or through each loop's margins
    with the others closed; ``disk_only``: through the disk margin alone, for robots whose cables
    have nearly undamped modes inside the loop's band (the spatial ones: a resonance's loop-at-a-time
    crossovers come and go between sampled poses, the disk margin varies smoothly with the pose).
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
        if disk_only:
            return False
        gain, phase = _loop_at_a_time(L, omega)
        return gain >= gain_margin_db and phase >= phase_margin_deg

    w = np.array([2 * np.pi * frequency])
    at_frequency = [robot.response(w)[0] @ jacobian for _, _, robot, jacobian, _ in cases]
    scored = []
    for gains in candidates:
        law = gains.law(omega, delay)[:, None, None]
        if all(_meets(law * response, omega, disk) for *_, response in cases):
            here = gains.law(w, delay)[0]
            scored.append((max(float(np.linalg.svd(np.linalg.inv(np.eye(len(G)) + here * G), compute_uv=False)[0])
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


def check_loop(scene, gains: LoopGains, poses: int = CHECK_POSES, rotation: bool = False) -> Margins:
    """The worst margins of ``gains``' loop (``rotation``: :func:`loop_cases`) on ``scene``'s robot at ``poses``
    reference poses over its run (one step late); SceneError for a robot :func:`linearise` does not model."""
    end = scene.solver.end_time
    times = end * (np.arange(poses) + 0.5) / poses
    cases = loop_cases(scene, [scene], times, rotation=rotation)
    return worst([loop_margins(robot, jacobian, gains, scene.solver.step_size, response=response)
                  for _, _, robot, jacobian, response in cases])


def meets(margins: Margins, required=REQUIRED_MARGINS) -> bool:
    """Whether ``margins`` are stable with at least the ``required`` (gain [dB], phase [deg]) margins."""
    return margins.stable and margins.gain_margin_db >= required[0] and margins.phase_margin_deg >= required[1]
