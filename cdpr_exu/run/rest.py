"""The static mode: a scene brought to rest, in either space, and what the cables look like there.

:func:`solve_rest` brings a scene to rest with the winches holding their initial lengths (the
trajectory is not followed) by its space's method (:data:`REST_METHODS`) and returns one :class:`Rest`.
Units SI; z up, gravity along -z.

**In the plane** (dynamic relaxation of the lumped :class:`~cdpr_exu.builder.model.Model`): the scene
is integrated with its own damping and solver settings, in chunks, until the largest node speed falls
below a tolerance; then Exudyn's static solver polishes the state. For each cable the rest holds the
length and end forces of its *free span*, the part the elastic catenary
(:mod:`cdpr_exu.physics.catenary`) describes:

* with a point exit, or over a pulley no node touches, the whole cable, from node 0 (held by the
  winch constraints) to the platform anchor (node n);
* over a pulley, from the *leave point* to the anchor: with node c the last node in contact with the
  rim, the point of the rim where the tangent from node c + 1 touches it (nearer node c), then the
  elements from node c + 1 on (the catenary's suspended part). The wrapped part is left out: the
  lumped model wraps the pulley with chords, shorter than the arc (``examples/catenary_validation.py``).

End forces are those the cable *exerts on* its supports, as the catenary's ``force_on_a`` (platform)
and ``force_on_b`` (upper end): ``platform_force + upper_force = (0, -W)`` at rest, W the span's
weight. At the platform: the reaction of the revolute joint that pins the anchor node (exact: with the
bending shear and the anchor node's weight); at a point exit: the reactions of the winch node's two
coordinate constraints; over a pulley: the cable's internal force at the cut through element
(c, c + 1), its axial force plus the shear of the two bending joints that straddle the cut (3.8 N
beside 14 N on the paper's scene).

The static polish converges in one Newton iteration from the settled state and makes it an exact
equilibrium (a free span's force balance from 2e-7 N to 1e-11 N on the paper's scenes). Without bending
damping the swinging modes are all but undamped: such a scene is settled with the paper's bending on,
and the static solver finds its own model's rest from there. ``Rest.method`` says which path was taken.

**In space** two independent methods solve the scene: the **catenary statics**
(:func:`cdpr_exu.statics.statics.solve_statics`: elastic catenaries, no bending), and Exudyn's static
solver on the lumped robot with the scene's effects, started on the catenary solution (over swivel
pulleys on the chain statics', :func:`cdpr_exu.run.settle.start_at_rest`). The rest says how far the
two lie apart (the discretisation error, about n^-2, plus bending). A rigid platform's cable ends are
held by stiff penalty joints (Exudyn's static solver diverges on ``ObjectJointSpherical`` when the body
must turn), adding 1 / (:data:`PENALTY` n) of a cable's compliance. Tension-only cables are solved
with spring elements (a slack start fails); a compressed element is reported.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.builder.cable import arm_first_step_kink, element_tensions
from cdpr_exu.builder.model import Model, build_model
from cdpr_exu.builder.robot_3d import build_spatial_robot, chain_positions, element_forces, scene_chain_spec, \
    swivel_angles
from cdpr_exu.core.errors import SceneError, SolverFailure
from cdpr_exu.core.geometry import penetration, rotation_angles_deg
from cdpr_exu.core.output import fixed, write_npz, write_summary
from cdpr_exu.run.settle import solve_static, start_at_rest, static_settings
from cdpr_exu.physics import bending
from cdpr_exu.results.result import provenance
from cdpr_exu.run.solver import likely_cause, quiet_exudyn, solver_report, solver_settings
from cdpr_exu.scenes.scene import Scene
from cdpr_exu.space import PLANE, SPACE
from cdpr_exu.statics.statics import catenary_platform, solve_statics

#: Default tolerance on the largest node speed at rest [m/s].
DEFAULT_TOLERANCE = 1.0e-6
#: Default longest simulated time before giving up [s].
DEFAULT_MAX_TIME = 60.0
#: Default length of each extension of the run after the scene's end time [s].
DEFAULT_CHUNK_TIME = 2.0
#: The node speed of a chunk is its largest over this final part of it [s] (not at a turning point).
SPEED_WINDOW = 0.5
#: The static polish is kept only if it moves no node farther than this [m]: a state at rest to
#: 1e-6 m/s lies about v * 1 s from its equilibrium; a larger jump found another equilibrium branch.
POLISH_MAX_SHIFT = 1.0e-3
#: Simulated time [s] of the check run of ``max_node_speed_m_s`` after a bending continuation.
CHECK_TIME = 0.2
#: Name of the path taken by the planar relaxation, by case.
METHODS = {
    "dynamic": "dynamics with the scene's damping",
    "dynamic+static": "dynamics with the scene's damping, polished by Exudyn's static solver",
    "bending-continuation+static": "settled with the paper's bending on, then Exudyn's static solver "
                                   "on the scene's own model from there",
}
#: Stiffness of the penalty spherical joints of a rigid platform in space, in element axial stiffnesses
#: (3e-7 m at n = 40 on the four-cable robot, tests/test_spatial_robot.py).
PENALTY = 100.0
#: A spatial answer farther than this fraction of the shortest cable from its elastic catenaries'
#: is flagged (``warnings``): the shipped swivel robot rests 0.9 % away (22 mm, its bending around
#: 0.1 m pulleys; measured), at E = 1e10 Pa 5.5 %, where bending more than hanging sets the answer.
FAR_FROM_CATENARY = 0.05

#: Definitions written into a planar rest's ``summary.json``.
DEFINITIONS = {
    "free_span": "the cable from its upper point to the platform anchor: the whole cable for a point exit; over a "
                 "pulley, from the point where it leaves the rim (tangent from the first free node) to the anchor",
    "cable_stretched_length_m": "length of the free span at rest (sum of element lengths, plus the straight piece "
                                "from the leave point to the first free node) [m]",
    "cable_unstrained_length_m": "unstrained length of the free span [m]",
    "platform_forces_N": "force (x, z) each cable exerts on the platform at its anchor (revolute-joint reaction) [N]",
    "upper_forces_N": "force (x, z) each cable's free span exerts on its upper support: winch constraints for a "
                      "point exit, the rest of the cable at the leave point for a pulley [N]",
    "span_weights_N": "weight of the nodes of each free span; platform_force + upper_force = (0, -weight) at rest [N]",
    "anchor_tensions_N": "axial force of the element at the anchor [N]",
    "max_node_speed_m_s": "largest node speed (cable nodes and platform) over the last 0.5 s of the dynamics "
                          "(or of the check run after a bending continuation) [m/s]",
}


@dataclass(frozen=True, eq=False)
class Rest:
    """A scene at rest, in its space (d = 2: (x, z) in the paper's plane; d = 3), m cables. Units SI.

    Attributes
    ----------
    position : ndarray, shape (d,) [m]
        Platform centre of mass.
    rotation : float or ndarray, shape (3,) [rad]
        The counter-clockwise angle in the plane, the rotation vector in space.
    rotation_matrix : ndarray, shape (d, d)
        Platform frame to world frame.
    nodes, tensions : tuple of ndarray, shapes (n_i + 1, d) [m] and (n_i,) [N]
        Node positions of each cable (upper end first) and each element's axial force (negative:
        compressed, which a real cable cannot be).
    anchor_tensions : ndarray, shape (m,) [N]; platform_forces : ndarray, shape (m, d) [N]
        Each cable's axial force at its anchor and the force it exerts on the platform there.
    method : str
        A key of :data:`METHODS` in the plane, a description in space.
    warnings, notes : tuple of str
        What makes this answer suspect; what the solver tried and refused.

    Planar only (None in space; :data:`DEFINITIONS`): ``cable_stretched_length_m``,
    ``cable_unstrained_length_m``, ``first_free_node`` (0, or c + 1 over a pulley), ``upper_points_m``,
    ``upper_forces_N``, ``span_weights_N``, ``max_node_speed_m_s`` (over the last :data:`SPEED_WINDOW`),
    ``time_s`` (simulated), ``static_shift_m`` (the static solver's largest node shift; None: not used).
    Spatial only (None in the plane): ``catenary`` (the elastic-catenary statics' PlatformEquilibrium),
    ``anchor_joint`` (how the cable ends are held), ``swivel_angles`` (m,) [rad] (None: no swivels).
    """

    scene: Scene
    position: np.ndarray
    rotation: Any
    rotation_matrix: np.ndarray
    nodes: tuple
    tensions: tuple
    anchor_tensions: np.ndarray
    platform_forces: np.ndarray
    method: str
    wall_time_s: float = 0.0
    warnings: tuple = ()
    notes: tuple = ()
    cable_stretched_length_m: np.ndarray | None = None
    cable_unstrained_length_m: np.ndarray | None = None
    first_free_node: np.ndarray | None = None
    upper_points_m: np.ndarray | None = None
    upper_forces_N: np.ndarray | None = None
    span_weights_N: np.ndarray | None = None
    max_node_speed_m_s: float | None = None
    time_s: float | None = None
    static_shift_m: float | None = None
    catenary: Any = None
    anchor_joint: str | None = None
    swivel_angles: np.ndarray | None = None

    @property
    def space(self):
        return self.scene.space

    @property
    def lowest_element_tension(self) -> float:
        """The lowest axial force of all elements [N] (negative: compressed)."""
        return float(min(t.min() for t in self.tensions))

    @property
    def catenary_distance(self) -> float | None:
        """Distance [m] from the platform position to its elastic catenaries' answer (None: not computed)."""
        return None if self.catenary is None else float(np.linalg.norm(self.position - self.catenary.position))

    def force_balance_residual(self) -> np.ndarray:
        """``platform_force + upper_force + (0, W)`` of each planar free span, shape (m, 2) [N]: 0 at rest."""
        weight = np.column_stack([np.zeros_like(self.span_weights_N), self.span_weights_N])
        return self.platform_forces + self.upper_forces_N + weight

    def summary(self) -> dict[str, Any]:
        """Plain data for ``summary.json`` (SI units in the key names)."""
        return REST_METHODS[self.space].summary(self)

    def summary_lines(self) -> list[str]:
        """The rest in a few lines of text (the CLI prints them)."""
        return REST_METHODS[self.space].lines(self)

    def save(self, folder: str | Path) -> dict[str, Path]:
        """Write ``summary.json`` and, in the plane, ``rest.npz`` into ``folder``; returns the paths."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        paths = {"summary": write_summary(folder, {**self.summary(), **provenance()})}
        arrays = REST_METHODS[self.space].arrays(self)
        if arrays:
            paths["npz"] = write_npz(folder / "rest.npz", **arrays)
        return paths


def solve_rest(scene: Scene, **options) -> Rest:
    """Bring ``scene`` to rest, the winches holding their initial lengths, by its space's method
    (:data:`REST_METHODS`). ``options`` are the planar relaxation's (:func:`_relax`); a spatial static
    solve ignores them.

    Raises
    ------
    SceneError
        A scene the method cannot bring to rest (massless planar cables, an explicit integrator, a
        bad option), naming the field.
    UnreachableError, SolverFailure
        No equilibrium of the catenary statics; the solver fails, the planar scene is not at rest after
        ``max_time``, or the spatial equilibrium holds the platform above its exits.
    """
    return REST_METHODS[scene.space].solve(scene, **options)


def bending_text(scene: Scene, catenary, what: str) -> str:
    """A sentence: ``what`` is the cables' bending E J [N m^2], its bending length sqrt(E J / T) at the
    catenaries' largest tension T against the smallest swivel radius (or the shortest cable)."""
    cable = scene.cables[0]
    if not scene.effects.bending:
        return "the cables have no bending (effects.bending = false)"
    stiffness = cable.youngs_modulus * cable.second_moment
    tension = float(np.max(catenary.tensions_at_anchor))
    length = math.sqrt(stiffness / tension) if tension > 0.0 else math.inf
    radii = np.array([exit_.radius for exit_ in scene.exits if exit_.wraps])
    scale, name = ((float(radii.min()), "the pulleys' radius") if radii.size
                   else (float(scene.unstrained_lengths.min()), "the shortest cable"))
    return (f"{what} is the cables' bending: E J = {stiffness:.3g} N m^2 (cables[0].youngs_modulus = "
            f"{cable.youngs_modulus:.3g} Pa on the solid section pi r^4 / 4) has a bending length sqrt(E J / T) = "
            f"{length:.3g} m at the catenaries' tension T = {tension:.4g} N, {length / scale:.2g} times {name} "
            f"({scale:.4g} m)")


def rest_above_exits(scene: Scene, position, rotation, lowest_tension: float, catenary) -> str | None:
    """Why a rest of the lumped robot at ``position`` (3,) [m], ``rotation`` (3, 3) is no cable robot's
    rest, or None: every anchor above its exit (:meth:`Scene.above_exits`) is held by elements that push
    (``lowest_tension`` [N] < 0) or by bending, not by hanging cables (cables whose bending length is
    many times their pulleys' radius stand up like rods). ``catenary``: the scene's catenary statics."""
    above = scene.above_exits(position, rotation)
    if above is None:
        return None
    return (f"the lumped robot's equilibrium holds the platform at z = {float(position[2]):.4g} m (its elastic "
            f"catenaries hang it at z = {float(catenary.position[2]):.4g} m, {1000 * float(np.linalg.norm(np.asarray(position) - catenary.position)):.0f} mm away) and {above}; "
            + bending_text(scene, catenary, "what holds it up")
            + f", and its lowest element force is {lowest_tension:.3g} N. Give the cables a smaller "
            "youngs_modulus or radius (a wire rope bends far more easily than a solid rod of its modulus)")


def _relax(scene: Scene, *, tolerance: float = DEFAULT_TOLERANCE, max_time: float = DEFAULT_MAX_TIME,
           chunk_time: float = DEFAULT_CHUNK_TIME, polish: bool = True) -> Rest:
    """Bring a planar ``scene`` (massive cables, implicit solver) to rest by dynamic relaxation.

    Integrates up to its end time, then in chunks of ``chunk_time`` [s] until the largest node speed
    over the last :data:`SPEED_WINDOW` of a chunk is below ``tolerance`` [m/s] (giving up after
    ``max_time`` [s]); then (``polish``) keeps Exudyn's static solution from there if it converged
    within :data:`POLISH_MAX_SHIFT`. See the module notes for a scene without bending damping.
    """
    for name, value in (("tolerance", tolerance), ("max_time", max_time), ("chunk_time", chunk_time)):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise SceneError(f"{name} must be a positive number, got {value!r}")
    if not scene.effects.cable_mass:
        raise SceneError("effects.cable_mass = false: the static mode needs cable nodes (massless ropes are "
                         "straight; their statics is cdpr_exu.statics.statics with zero weight)")
    if scene.solver.integrator != "generalized_alpha":
        raise SceneError(f"solver.integrator = {scene.solver.integrator!r}: the static mode runs the implicit "
                         "solver ('generalized_alpha'); the rest state does not depend on the integrator")
    start = _time.perf_counter()
    notes: list[str] = []
    if scene.effects.bending_damping:
        model = _build(scene)
        elapsed, speed = _integrate_until_rest(model, scene, tolerance, max_time, chunk_time)
        method, shift = "dynamic", None
        if polish:
            shift = _static_solve(model, POLISH_MAX_SHIFT)
            if shift is None:
                notes.append("static polish refused: Exudyn's static solver did not converge within "
                             f"{POLISH_MAX_SHIFT * 1000:g} mm of the settled state; the dynamic rest state is kept")
            else:
                method = "dynamic+static"
    else:
        helper = scene.with_changes(effects=replace(scene.effects, bending=True, bending_damping=True,
                                                    bending_model="exact"))
        helper_model = _build(helper)
        elapsed, _ = _integrate_until_rest(helper_model, helper, tolerance, max_time, chunk_time)
        model = _build(scene)
        _copy_state(helper_model, model)
        shift = _static_solve(model, max_shift=None)
        if shift is None:
            raise SolverFailure(
                f"scene {scene.name!r} has no bending damping, so its swinging is all but undamped; it was settled "
                "with the paper's bending on, but Exudyn's static solver did not converge from there for the "
                "scene's own effects", time=elapsed)
        tensions = [element_tensions(c, n, np.zeros_like(n), scene.effects)
                    for c, n in zip(scene.cables, _cable_positions(model))]
        if min(t.min() for t in tensions) <= 0.0:
            raise SolverFailure(
                f"the static solution of scene {scene.name!r} has pushing elements (smallest axial force "
                f"{min(t.min() for t in tensions):.3g} N): an equilibrium no hanging cable reaches", time=elapsed)
        speed = _check_run(model, scene)
        method = "bending-continuation+static"
    reaction_sign = -1.0 if method.endswith("static") else 1.0  # see _rest_state
    state = _rest_state(model, scene, speed, elapsed, method, shift, tuple(notes), reaction_sign)
    return replace(state, wall_time_s=_time.perf_counter() - start)


def _build(scene: Scene) -> Model:
    """The scene's model; a point-mass platform's rotation (which feels no moment) is locked."""
    model = build_model(scene)
    if scene.platform.is_point_mass:
        mbs = model.mbs
        ground = mbs.AddNode(eii.NodePointGround(referenceCoordinates=[0.0, 0.0, 0.0]))
        ground_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=ground, coordinate=0))
        rotation_marker = mbs.AddMarker(eii.MarkerNodeCoordinate(nodeNumber=model.platform.node, coordinate=2))
        mbs.AddObject(eii.ObjectConnectorCoordinate(markerNumbers=[ground_marker, rotation_marker]))
        mbs.Assemble()
    return model


def _speed_indices(model: Model) -> np.ndarray:
    """ODE2 indices of every (x, z) pair whose speed counts: cable nodes and the platform, shape (k, 2)."""
    indices = model.coordinate_indices()
    pairs = [indices["platform"][:2][None, :]]
    pairs += [indices[f"cable_{i}"] for i in range(len(model.cables))]
    return np.concatenate(pairs)


def _integrate_until_rest(model: Model, scene: Scene, tolerance: float, max_time: float,
                          chunk_time: float) -> tuple[float, float]:
    """Integrate from the model's initial state until at rest; returns (time, speed) [s, m/s]."""
    mbs = model.mbs
    data = mbs.systemData
    settings = solver_settings(scene)
    step = scene.solver.step_size
    pairs = _speed_indices(model)
    window = {"from": 0.0, "speed": 0.0}

    kink = arm_first_step_kink(model.cable_forces)

    def post_step(mbs_, t):
        kink[0] = 0.0  # past the first step: Newton sees the tension-only law as it is
        if t >= window["from"]:
            v = np.asarray(data.GetODE2Coordinates_t())[pairs]
            window["speed"] = max(window["speed"], float(np.sqrt((v**2).sum(axis=1)).max()))
        return True

    mbs.SetPostStepUserFunction(post_step)
    t, end = 0.0, min(scene.solver.end_time, max_time)
    try:
        while True:
            settings.timeIntegration.startTime = t
            settings.timeIntegration.endTime = end
            settings.timeIntegration.numberOfSteps = max(1, int(round((end - t) / step)))
            window.update({"from": end - min(SPEED_WINDOW, end - t), "speed": 0.0})
            try:
                with quiet_exudyn():
                    mbs.SolveDynamic(settings)
            except (exu.SolverError, RuntimeError, SystemError) as err:
                cause = solver_report(mbs, " ".join(str(err).split()))
                reached = float(mbs.sys["dynamicSolver"].it.currentTime) if "dynamicSolver" in mbs.sys else t
                raise SolverFailure(f"the run of scene {scene.name!r} to rest failed at t = {reached:.4f} s "
                                    f"(between {t:.3f} s and {end:.3f} s): {cause}. {likely_cause(scene, cause, reached)}",
                                    time=reached, partial_result=_last_state(model)) from None
            t = end
            speed = window["speed"]
            if not math.isfinite(speed) or not np.all(np.isfinite(data.GetODE2Coordinates())):
                raise SolverFailure(f"the run of scene {scene.name!r} to rest diverged before t = {t:.3f} s", time=t)
            if speed < tolerance:
                return t, speed
            if t >= max_time - 1e-9:
                raise SolverFailure(
                    f"scene {scene.name!r} is not at rest after {t:.3g} s of simulated time: the largest node "
                    f"speed over the last {SPEED_WINDOW} s is {speed:.3g} m/s, above the tolerance {tolerance:g} m/s. "
                    "Raise max_time, or check the damping (effects.axial_damping, effects.bending_damping)", time=t,
                    partial_result=_last_state(model))
            data.SetSystemState(data.GetSystemState(), configuration=exu.ConfigurationType.Initial)
            end = min(t + chunk_time, max_time)
    finally:
        mbs.SetPostStepUserFunction(0)


def _last_state(model: Model) -> dict[str, Any]:
    """The platform pose and node positions where a failed run to rest stopped (finite values only)."""
    pose = _coordinates(model, "platform")
    return {"platform_pose": pose.tolist() if np.all(np.isfinite(pose)) else None,
            "nodes_m": [n.tolist() if np.all(np.isfinite(n)) else None for n in _cable_positions(model)]}


def _static_solve(model: Model, max_shift: float | None) -> float | None:
    """Exudyn's static solver from the model's current state, velocities zeroed: the largest node shift
    [m] if it converged and moved no node farther than ``max_shift``; else None, the state restored."""
    mbs = model.mbs
    data = mbs.systemData
    saved = data.GetSystemState()
    before = np.concatenate(_cable_positions(model))
    state = list(saved)
    state[1] = np.zeros_like(np.asarray(state[1]))
    data.SetSystemState(state, configuration=exu.ConfigurationType.Initial)
    try:
        with quiet_exudyn():  # a failed static solve prints a page of hints
            converged = bool(mbs.SolveStatic(static_settings(1e-10), showHints=False, showCausingItems=False))
    except (exu.SolverError, RuntimeError, SystemError):
        converged = False
    after = np.concatenate(_cable_positions(model)) if converged else before
    shift = float(np.linalg.norm(after - before, axis=1).max()) if converged else math.inf
    if not converged or not np.isfinite(shift) or (max_shift is not None and shift > max_shift):
        data.SetSystemState(saved, configuration=exu.ConfigurationType.Current)
        return None
    state = data.GetSystemState()
    state[1] = np.zeros_like(np.asarray(state[1]))
    data.SetSystemState(state, configuration=exu.ConfigurationType.Current)
    return shift


def _copy_state(source: Model, target: Model) -> None:
    """Copy the positions (and contact data) of one model of a scene into another of the same nodes."""
    source_data, target_data = source.mbs.systemData, target.mbs.systemData
    src_idx, dst_idx = source.coordinate_indices(), target.coordinate_indices()
    q_source = np.asarray(source_data.GetODE2Coordinates())
    state = target_data.GetSystemState(exu.ConfigurationType.Initial)
    q = np.asarray(state[0]).copy()
    for key, index in src_idx.items():
        q[dst_idx[key]] = q_source[index]
    state[0] = q
    state[1] = np.zeros_like(np.asarray(state[1]))
    source_state = source_data.GetSystemState()
    if len(source_state[4]) == len(state[4]):  # contact gaps: the same contact items
        state[4] = source_state[4]
    for configuration in (exu.ConfigurationType.Initial, exu.ConfigurationType.Current):
        target_data.SetSystemState(state, configuration=configuration)


def _check_run(model: Model, scene: Scene) -> float:
    """Largest node speed of a short run (:data:`CHECK_TIME`) from the current state [m/s]."""
    data = model.mbs.systemData
    data.SetSystemState(data.GetSystemState(), configuration=exu.ConfigurationType.Initial)
    check = scene.with_changes(solver=replace(scene.solver, end_time=CHECK_TIME,
                                              output_period=min(scene.solver.output_period, CHECK_TIME)))
    saved = data.GetSystemState()
    _, speed = _integrate_until_rest(model, check, math.inf, CHECK_TIME, CHECK_TIME)
    data.SetSystemState(saved, configuration=exu.ConfigurationType.Current)
    return speed


def _coordinates(model: Model, key: str) -> np.ndarray:
    """The current absolute coordinates (reference + displacement) of ``key``'s ODE2 indices."""
    data = model.mbs.systemData
    index = model.coordinate_indices()[key]
    return np.asarray(data.GetODE2Coordinates(exu.ConfigurationType.Reference))[index] \
        + np.asarray(data.GetODE2Coordinates())[index]


def _cable_positions(model: Model) -> list[np.ndarray]:
    return [_coordinates(model, f"cable_{i}") for i in range(len(model.cables))]


def _cable_velocities(model: Model) -> list[np.ndarray]:
    v = np.asarray(model.mbs.systemData.GetODE2Coordinates_t())
    indices = model.coordinate_indices()
    return [v[indices[f"cable_{i}"]] for i in range(len(model.cables))]


def leave_point(center: np.ndarray, radius: float, outside: np.ndarray, near: np.ndarray) -> np.ndarray:
    """The point (2,) [m] of a pulley rim (``center`` (2,) [m], ``radius`` [m]) where the tangent from
    ``outside`` (2,) [m] touches it, of the two the one nearer ``near`` (2,) [m] (the last node in contact)."""
    delta = np.asarray(outside, float) - center
    distance = float(np.hypot(*delta))
    beta = math.atan2(delta[1], delta[0])
    alpha = math.acos(min(1.0, radius / distance))
    candidates = [center + radius * np.array([math.cos(beta + s * alpha), math.sin(beta + s * alpha)])
                  for s in (-1.0, 1.0)]
    return min(candidates, key=lambda p: float(np.hypot(*(p - near))))


def _bending_cut_force(scene: Scene, cable_index: int, positions: np.ndarray, velocities: np.ndarray,
                       cut: int) -> np.ndarray:
    """Force (x, z) [N] the bending joints straddling element (cut, cut + 1) exert on nodes > cut."""
    effects, cable = scene.effects, scene.cables[cable_index]
    n = len(positions) - 1
    joints = np.array([[b - 1, b, b + 1] for b in (cut, cut + 1) if 1 <= b <= n - 1], dtype=np.int64)
    if not effects.bending or len(joints) == 0:
        return np.zeros(2)
    damping = cable.bending_damping if effects.bending_damping else 0.0
    flat_p, flat_v = positions.ravel(), velocities.ravel()
    if effects.bending_model == "linear":
        stiffness = bending.curvature_stiffness_matrix(n + 1, joints, cable.bending_stiffness, cable.element_length)
        force = -stiffness @ flat_p - (damping / cable.bending_stiffness) * stiffness @ flat_v
    else:
        spring = bending.BendingSpringDamper(n + 1, joints, cable.bending_stiffness, damping)
        force = np.array(spring.force(flat_p, flat_v))
    return force.reshape(-1, 2)[cut + 1:].sum(axis=0)


def _rest_state(model: Model, scene: Scene, speed: float, elapsed: float, method: str,
                shift: float | None, notes: tuple, reaction_sign: float = 1.0) -> Rest:
    """Read the rest state off the model. ``reaction_sign`` is -1 for a state of Exudyn's static solver,
    whose constraint reactions have the opposite sign of the dynamic solver's (``tests/test_model.py``)."""
    mbs = model.mbs
    pose = _coordinates(model, "platform")
    force = exu.OutputVariableType.Force
    positions, velocities = _cable_positions(model), _cable_velocities(model)
    tensions, platform_forces, spans = [], [], []  # spans: the free spans' columns of the Rest
    for i, (cable, nodes, v) in enumerate(zip(scene.cables, positions, velocities)):
        tension = element_tensions(cable, nodes, v, scene.effects)
        tensions.append(tension)
        node_weights = scene.gravity * cable.node_masses() if scene.effects.gravity else np.zeros(len(nodes))
        elements = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
        platform_forces.append(reaction_sign * np.asarray(mbs.GetObjectOutput(model.platform.joints[i], force))[:2])
        pulley = scene.exits[i]
        touching = np.flatnonzero(penetration(pulley, nodes) > 0.0) if pulley.wraps else []
        if len(touching) == 0 or touching[-1] >= len(nodes) - 1:
            winch = model.winches[i]
            if int(winch.horizontal) >= 0 and int(winch.vertical) >= 0:
                upper = reaction_sign * np.array([mbs.GetObjectOutput(winch.horizontal, force),
                                                  mbs.GetObjectOutput(winch.vertical, force)], dtype=float)
            else:  # no constraint reaction to read: the balance of node 0 instead
                # what node 0 passes on to its support: its element's pull, the bending
                # force on it (minus the joint's force on the nodes beyond it), its weight
                pull = tension[0] * (nodes[1] - nodes[0]) / elements[0]
                upper = pull - _bending_cut_force(scene, i, nodes, v, 0) - np.array([0.0, node_weights[0]])
            spans.append((0, nodes[0], upper, float(elements.sum()), cable.unstrained_length,
                          float(node_weights.sum())))
            continue
        c = int(touching[-1])
        point = leave_point(np.asarray(pulley.point), pulley.radius, nodes[c + 1], nodes[c])
        piece = float(np.hypot(*(nodes[c + 1] - point)))
        on_span = tension[c] * (nodes[c] - nodes[c + 1]) / elements[c] + _bending_cut_force(scene, i, nodes, v, c)
        strain = tension[c] / cable.axial_rigidity
        spans.append((c + 1, point, -on_span, piece + float(elements[c + 1:].sum()),
                      piece / (1.0 + strain) + (len(elements) - c - 1) * cable.element_length,
                      float(node_weights[c + 1:].sum())))
    first, upper_points, upper_forces, lengths, unstrained, weights = (list(column) for column in zip(*spans))
    return Rest(
        scene=scene, position=pose[:2].copy(), rotation=float(pose[2]), rotation_matrix=PLANE.rotation_matrix(pose[2]),
        nodes=tuple(positions), tensions=tuple(tensions), anchor_tensions=np.array([t[-1] for t in tensions]),
        platform_forces=np.array(platform_forces), method=method, notes=notes,
        cable_stretched_length_m=np.array(lengths), cable_unstrained_length_m=np.array(unstrained),
        first_free_node=np.array(first, dtype=int), upper_points_m=np.array(upper_points),
        upper_forces_N=np.array(upper_forces), span_weights_N=np.array(weights),
        max_node_speed_m_s=float(speed), time_s=float(elapsed), static_shift_m=shift,
    )


def _planar_arrays(rest: Rest) -> dict[str, np.ndarray]:
    """The arrays of ``rest.npz``; the first ten are in ``summary.json`` too."""
    arrays = {
        "platform_position_m": rest.position, "platform_rotation_deg": np.array(float(np.degrees(rest.rotation))),
        "cable_stretched_length_m": rest.cable_stretched_length_m,
        "cable_unstrained_length_m": rest.cable_unstrained_length_m, "first_free_node": rest.first_free_node,
        "upper_points_m": rest.upper_points_m, "upper_forces_N": rest.upper_forces_N,
        "platform_forces_N": rest.platform_forces, "anchor_tensions_N": rest.anchor_tensions,
        "span_weights_N": rest.span_weights_N, "max_node_speed_m_s": np.array(rest.max_node_speed_m_s),
    }
    for i, (nodes, tensions) in enumerate(zip(rest.nodes, rest.tensions)):
        arrays[f"nodes_{i}"] = nodes
        arrays[f"tensions_{i}"] = tensions
    return arrays


def _planar_summary(rest: Rest) -> dict[str, Any]:
    arrays = list(_planar_arrays(rest).items())[:10]
    return {
        "scene": rest.scene.name, "method": rest.method, "method_description": METHODS[rest.method],
        **{key: value.tolist() for key, value in arrays},
        "force_balance_residual_N": rest.force_balance_residual().tolist(),
        "max_node_speed_m_s": rest.max_node_speed_m_s, "simulated_time_s": rest.time_s,
        "static_shift_m": rest.static_shift_m, "wall_time_s": rest.wall_time_s, "notes": list(rest.notes),
        "nodes_m": [n.tolist() for n in rest.nodes], "element_tensions_N": [t.tolist() for t in rest.tensions],
        "definitions": DEFINITIONS,
    }


def _planar_lines(rest: Rest) -> list[str]:
    x, z = rest.position
    lines = [f"{rest.scene.name} at rest after {rest.time_s:.2f} s simulated ({rest.method}), "
             f"largest node speed {rest.max_node_speed_m_s:.2g} m/s",
             f"  platform at x = {fixed(x, 6)} m, z = {fixed(z, 6)} m, rotation {fixed(np.degrees(rest.rotation), 4)} deg"]
    lines += [f"  cable {i + 1}: free span {rest.cable_stretched_length_m[i]:.6f} m "
              f"(unstrained {rest.cable_unstrained_length_m[i]:.6f} m), force on platform "
              f"{np.round(rest.platform_forces[i], 4).tolist()} N, on upper support "
              f"{np.round(rest.upper_forces_N[i], 4).tolist()} N" for i in range(len(rest.nodes))]
    return lines + [f"  note: {note}" for note in rest.notes]


def _solve_from_catenaries(scene: Scene, **relaxation) -> Rest:
    """Bring a spatial ``scene`` to rest (the module notes); the planar ``relaxation`` does not apply."""
    start = _time.perf_counter()
    platform = catenary_platform(scene)
    lengths = scene.unstrained_lengths
    catenary = solve_statics(platform, lengths)
    rigid = not platform.is_point_mass
    chain = scene_chain_spec(scene, anchor_spring_factor=PENALTY if rigid else None, tension_only=False)
    mbs = exu.SystemContainer().AddSystem()
    swivels = any(exit_.wraps for exit_ in scene.exits)
    items = build_spatial_robot(mbs, platform, lengths, chain, initial=catenary, exits=scene.exits)
    mbs.Assemble()
    if swivels:
        start_at_rest(mbs, items)  # Exudyn's static solver does not converge from the catenary start over a swivel pulley
    static = solve_static(mbs, items)
    nodes = tuple(chain_positions(mbs, items, i) for i in range(scene.n_cables))
    tensions = tuple(element_forces(mbs, items, i) for i in range(scene.n_cables))
    joint = f"penalty spherical joints of {PENALTY:g} element stiffnesses" if rigid else "exact spherical joints"
    method = (f"Exudyn static solver on the lumped robot ({scene.cables[0].n_elements} elements per cable, {joint}), "
              "started on the elastic-catenary statics"
              + (" and, over swivel pulleys, on the chain statics' equilibrium from there" if swivels else ""))
    rest = Rest(scene, static.position, static.rotation_vector, static.rotation, nodes, tensions,
                static.tensions_at_anchor, static.forces_on_platform, method, catenary=catenary, anchor_joint=joint,
                swivel_angles=swivel_angles(mbs, items) if swivels else None)
    rest = replace(rest, warnings=_spatial_warnings(rest), wall_time_s=_time.perf_counter() - start)
    above = rest_above_exits(scene, rest.position, rest.rotation_matrix, rest.lowest_element_tension, catenary)
    if above is not None:
        raise SolverFailure(f"no rest of a cable robot: {above}", partial_result=rest.summary())
    return rest


def _spatial_warnings(rest: Rest) -> tuple[str, ...]:
    """An answer far from the catenaries' (:data:`FAR_FROM_CATENARY`) and compressed elements, with figures."""
    found = []
    shortest = float(rest.scene.unstrained_lengths.min())
    if rest.catenary_distance > FAR_FROM_CATENARY * shortest:
        found.append(
            f"the lumped robot rests {1000 * rest.catenary_distance:.0f} mm from its elastic catenaries' answer, "
            f"more than {100 * FAR_FROM_CATENARY:g} % of its shortest cable ({shortest:.4g} m); "
            + bending_text(rest.scene, rest.catenary, "what the catenary leaves out and moves it"))
    lowest = rest.lowest_element_tension
    if lowest < 0.0:
        found.append(f"an element is compressed ({lowest:.3g} N), which a real cable cannot be (the static solve "
                     "uses spring elements): a cable is slack at rest (longer than the catenary the lumped model "
                     "can hang), or the cables' bending holds the platform up")
    return tuple(found)


def _spatial_summary(rest: Rest) -> dict[str, Any]:
    catenary = rest.catenary
    return {
        "scene": rest.scene.name,
        "dimension": 3,
        "method": rest.method,
        "platform_position_m": rest.position.tolist(),
        "platform_rotation_vector_rad": rest.rotation.tolist(),
        "platform_roll_pitch_yaw_deg": rotation_angles_deg(rest.rotation_matrix).tolist(),
        "platform_rotation_matrix": rest.rotation_matrix.tolist(),
        "tension_at_anchor_N": rest.anchor_tensions.tolist(),
        "force_on_platform_N": rest.platform_forces.tolist(),
        "catenary_platform_position_m": catenary.position.tolist(),
        "catenary_platform_rotation_vector_rad": catenary.rotation.tolist(),
        "catenary_tension_at_anchor_N": catenary.tensions_at_anchor.tolist(),
        "min_element_tension_N": rest.lowest_element_tension,
        "elements_pushed": rest.lowest_element_tension < 0.0,
        "lumped_minus_catenary_position_m": rest.catenary_distance,
        "lumped_minus_catenary_rotation_rad": float(np.linalg.norm(rest.rotation - catenary.rotation)),
        "wall_time_s": rest.wall_time_s,
        **({} if rest.swivel_angles is None else {
            "swivel_angle_rad": [None if np.isnan(a) else float(a) for a in rest.swivel_angles],
            "catenary_wrap_angle_rad": [float(c.wrap_angle) for c in catenary.cables]}),
        "warnings": list(rest.warnings),
    }


def _spatial_lines(rest: Rest) -> list[str]:
    x, y, z = rest.position
    roll, pitch, yaw = rotation_angles_deg(rest.rotation_matrix)
    catenary = rest.catenary
    lines = [f"{rest.scene.name} at rest (Exudyn's static solver, {rest.scene.cables[0].n_elements} elements per "
             f"cable, {rest.anchor_joint}; {rest.wall_time_s:.2f} s)",
             f"  platform at x = {x:.6f} m, y = {y:.6f} m, z = {z:.6f} m; rotation vector "
             f"{np.round(rest.rotation, 6).tolist()} rad (roll {roll:.4f}, pitch {pitch:.4f}, yaw {yaw:.4f} deg)"]
    lines += [f"  cable {i + 1}: {tension:.4f} N at the anchor (catenary {catenary.tensions_at_anchor[i]:.4f} N), "
              f"force on platform {np.round(force, 4).tolist()} N"
              for i, (tension, force) in enumerate(zip(rest.anchor_tensions, rest.platform_forces))]
    lines.append(f"  elastic catenaries (no bending): platform at {np.round(catenary.position, 6).tolist()} m, "
                 f"{1000 * np.linalg.norm(rest.position - catenary.position):.3f} mm and "
                 f"{np.degrees(np.linalg.norm(rest.rotation - catenary.rotation)):.4f} deg from the lumped robot")
    for i, psi in enumerate(() if rest.swivel_angles is None else rest.swivel_angles):
        cable = catenary.cables[i]
        if cable.inlet is not None:
            azimuth = np.degrees(np.arctan2(*(cable.anchor_point - cable.inlet)[1::-1]))
            lines.append(f"  swivel pulley {i + 1}: psi = {np.degrees(psi):.4f} deg (anchor azimuth {azimuth:.4f} "
                         f"deg), wrap {np.degrees(cable.wrap_angle):.2f} deg")
    return lines


@dataclass(frozen=True)
class _RestMethod:
    """How a scene of one space is brought to rest and its rest told: solver, summary, ``rest.npz``'s
    arrays (None: no such file) and console lines."""

    solve: Callable[..., Rest]
    summary: Callable[[Rest], dict]
    arrays: Callable[[Rest], dict | None]
    lines: Callable[[Rest], list]


#: The static mode's method by the scene's space: dynamic relaxation of the planar model, Exudyn's
#: static solve of the spatial robot started on its catenaries.
REST_METHODS = {
    PLANE: _RestMethod(_relax, _planar_summary, _planar_arrays, _planar_lines),
    SPACE: _RestMethod(_solve_from_catenaries, _spatial_summary, lambda rest: None, _spatial_lines),
}
