"""The static mode: a scene brought to rest, and what the cables look like there.

:func:`solve_rest` integrates a scene with its own damping and solver settings, in
chunks, until the largest node speed falls below a tolerance, then polishes the state
with Exudyn's static solver (``mbs.SolveStatic``). The winches hold their initial
lengths: the scene's trajectory is not followed. The answer, a :class:`RestState`,
holds the platform pose, every node, every element's axial force, and for each cable
the length and end forces of its *free span*, the part that the elastic catenary
(:mod:`cdpr_exu.physics.catenary`) describes:

* with a point exit (the cable does not wrap its exit), or over a pulley that no node
  touches, the whole cable, from its upper end (node 0, held by the winch
  constraints) to the platform anchor (node n);
* over a pulley, the cable from the point where it leaves the rim to the anchor. Let
  node c be the last node (counting from the winch) in contact with the rim. The
  cable leaves the pulley on element (c, c + 1); its *leave point* is the point of the
  rim where the tangent from node c + 1 touches it (the tangent nearer node c). The
  free span is the straight piece from the leave point to node c + 1 plus the
  elements from node c + 1 to the anchor. This is the lumped counterpart of the
  catenary's suspended part (anchor to tangent point, ``CableEquilibrium.catenary``).
  The wrapped part is left out on purpose: the lumped model wraps the pulley with
  straight chords, shorter than the arc by about a centimetre per element for 0.25 m
  elements on a 0.25 m pulley (26 mm over the paper's wrap), a property of the
  discretisation, not of the cable. Where such a coarse polygon leaves the rim is
  itself uncertain by a good part of an element (about 2 cm along the rim on the
  paper's scene, see ``examples/catenary_validation.py``); with elements short
  against the pulley radius both effects vanish.

End forces are the forces the cable *exerts on* its supports, as the catenary's
``force_on_a`` (platform) and ``force_on_b`` (upper end); with the span's weight W,
``platform_force + upper_force = (0, -W)`` at rest:

* at the platform: the reaction of the revolute joint that pins the anchor node to the
  platform (exact: it includes the bending shear and the anchor node's weight; the
  axial force of the anchor element is given as well, ``anchor_tensions_N``);
* at a point exit: the reactions (Lagrange multipliers) of the winch node's two
  coordinate constraints (node 0 and its weight belong to the span);
* over a pulley: the internal force of the cable at the cut through element
  (c, c + 1): that element's axial force along it, plus, with bending, the shear of the
  two bending joints that straddle the cut (3.8 N beside an axial force of 14 N on the
  paper's scene, so it cannot be left out). Node c + 1 touches nothing.

Static solver notes (measured on the paper's scenes, settled for 8 s to 3e-7 m/s): from
the settled state the static solver converges in one Newton iteration, in milliseconds;
it moves the nodes by 2e-7 m and the element forces by 1e-6 N, and brings the force
balance of a free span from 2e-7 N (the inertia of the residual creep) to 1e-11 N. So
it changes nothing that matters here, but it is cheap and makes the state an exact
equilibrium. It needs the rotation of a point-mass platform locked
(:data:`ROTATION_LOCK`): nothing resists that rotation, so the static Jacobian is
singular (the cause of the failures "from the straight start"; with the lock and 20
load steps it converges from there too, with bending). Without bending
damping (``effects.bending_damping`` off, eg the "catenary" preset) the cable's
swinging modes are all but undamped (still 0.5 to 0.9 m/s after 60 s on the paper's
scene): there the scene is settled with the paper's bending stiffness and damping
switched on, and the static solver then finds the rest of the scene's own model from
that state (a continuation in the bending stiffness; from the straight start it finds
equilibria of pushing elements instead). ``RestState.method`` says which path was taken.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import exudyn as exu
import exudyn.itemInterface as eii
import numpy as np

from cdpr_exu.builder.cable import arm_first_step_kink, element_tensions
from cdpr_exu.core.errors import SceneError, SolverFailure
from cdpr_exu.builder.model import Model, build_model
from cdpr_exu.core.geometry import penetration
from cdpr_exu.core.output import write_npz, write_summary
from cdpr_exu.run.settle import static_settings
from cdpr_exu.physics import bending
from cdpr_exu.results.result import provenance
from cdpr_exu.run.simulate import likely_cause
from cdpr_exu.run.solver import quiet_exudyn, solver_report, solver_settings
from cdpr_exu.scenes.scene import Scene

#: Default tolerance on the largest node speed at rest [m/s].
DEFAULT_TOLERANCE = 1.0e-6
#: Default longest simulated time before giving up [s].
DEFAULT_MAX_TIME = 60.0
#: Default length of each extension of the run after the scene's end time [s].
DEFAULT_CHUNK_TIME = 2.0
#: The node speed of a chunk is its largest over this final part of the chunk [s]
#: (not only at its last step, which a swinging mode may pass at a turning point).
SPEED_WINDOW = 0.5
#: The static polish is kept only if it moves no node farther than this [m]. A state at
#: rest to 1e-6 m/s is within about v * tau (tau ~ 1 s: the Kelvin-Voigt time constant
#: c_i / k_i, and the swinging periods) of its equilibrium, so 1 mm is three orders of
#: magnitude of margin; a larger jump means another equilibrium branch was found.
POLISH_MAX_SHIFT = 1.0e-3
#: Simulated time of the check run from a static solution of a scene without bending
#: damping [s]: its largest node speed is reported as ``max_node_speed_m_s``.
CHECK_TIME = 0.2
#: Name of the path taken by :func:`solve_rest`, by case.
METHODS = {
    "dynamic": "dynamics with the scene's damping",
    "dynamic+static": "dynamics with the scene's damping, polished by Exudyn's static solver",
    "bending-continuation+static": "settled with the paper's bending on, then Exudyn's static solver "
                                   "on the scene's own model from there",
}
#: Whether a point-mass platform's rotation is locked by a coordinate constraint. The
#: rotation of a point mass feels no moment (its anchors are at its centre of mass),
#: so locking it changes no answer; it makes the static Jacobian regular.
ROTATION_LOCK = True

#: Definitions written into ``summary.json``.
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


# --------------------------------------------------------------------------- result


@dataclass(frozen=True, eq=False)
class RestState:
    """A scene at rest. Units SI, positions (x, z) in the paper's plane, m cables.

    Attributes
    ----------
    scene_name : str
    platform_position_m : ndarray, shape (2,) [m]
        Centre of mass (x, z).
    platform_rotation_deg : float [deg]
        Counter-clockwise.
    nodes : tuple of ndarray, each shape (n_i + 1, 2) [m]
        Node positions of each cable, winch end first.
    tensions : tuple of ndarray, each shape (n_i,) [N]
        Axial force of each element (tension positive), as the spring-dampers compute it.
    cable_stretched_length_m : ndarray, shape (m,) [m]
        Length of each cable's free span (see the module notes).
    cable_unstrained_length_m : ndarray, shape (m,) [m]
        Unstrained length of the free span.
    first_free_node : ndarray of int, shape (m,)
        First node of the free span: 0 for a point exit, c + 1 over a pulley.
    upper_points_m : ndarray, shape (m, 2) [m]
        Upper end of the free span: node 0, or the leave point on the rim.
    upper_forces_N : ndarray, shape (m, 2) [N]
        Force each free span exerts on its upper support.
    platform_forces_N : ndarray, shape (m, 2) [N]
        Force each cable exerts on the platform at its anchor.
    anchor_tensions_N : ndarray, shape (m,) [N]
        Axial force of the anchor element.
    span_weights_N : ndarray, shape (m,) [N]
        Weight of the nodes of each free span.
    max_node_speed_m_s : float [m/s]
        Largest node speed over the last :data:`SPEED_WINDOW` of the dynamics.
    time_s : float [s]
        Simulated time of the dynamics.
    method : str
        Key of :data:`METHODS`.
    static_shift_m : float or None [m]
        How far the static solver moved the farthest node (None: not used or refused).
    wall_time_s : float [s]
    notes : tuple of str
        What the solver tried and refused (eg a static polish that did not converge).
    """

    scene_name: str
    platform_position_m: np.ndarray
    platform_rotation_deg: float
    nodes: tuple
    tensions: tuple
    cable_stretched_length_m: np.ndarray
    cable_unstrained_length_m: np.ndarray
    first_free_node: np.ndarray
    upper_points_m: np.ndarray
    upper_forces_N: np.ndarray
    platform_forces_N: np.ndarray
    anchor_tensions_N: np.ndarray
    span_weights_N: np.ndarray
    max_node_speed_m_s: float
    time_s: float
    method: str
    static_shift_m: float | None = None
    wall_time_s: float = 0.0
    notes: tuple = field(default=())

    def force_balance_residual(self) -> np.ndarray:
        """``platform_force + upper_force + (0, W)`` of each free span, shape (m, 2) [N]: 0 at rest."""
        weight = np.column_stack([np.zeros_like(self.span_weights_N), self.span_weights_N])
        return self.platform_forces_N + self.upper_forces_N + weight

    def summary(self) -> dict[str, Any]:
        """Plain-data summary (JSON-ready) of the rest state, with the definitions used."""
        return {
            "scene": self.scene_name,
            "method": self.method,
            "method_description": METHODS[self.method],
            "platform_position_m": self.platform_position_m.tolist(),
            "platform_rotation_deg": self.platform_rotation_deg,
            "cable_stretched_length_m": self.cable_stretched_length_m.tolist(),
            "cable_unstrained_length_m": self.cable_unstrained_length_m.tolist(),
            "first_free_node": self.first_free_node.tolist(),
            "upper_points_m": self.upper_points_m.tolist(),
            "upper_forces_N": self.upper_forces_N.tolist(),
            "platform_forces_N": self.platform_forces_N.tolist(),
            "anchor_tensions_N": self.anchor_tensions_N.tolist(),
            "span_weights_N": self.span_weights_N.tolist(),
            "force_balance_residual_N": self.force_balance_residual().tolist(),
            "max_node_speed_m_s": self.max_node_speed_m_s,
            "simulated_time_s": self.time_s,
            "static_shift_m": self.static_shift_m,
            "wall_time_s": self.wall_time_s,
            "notes": list(self.notes),
            "nodes_m": [n.tolist() for n in self.nodes],
            "element_tensions_N": [t.tolist() for t in self.tensions],
            "definitions": DEFINITIONS,
        }

    def save(self, folder: str | Path) -> dict[str, Path]:
        """Write ``summary.json`` (with provenance) and ``rest.npz`` into ``folder``."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        summary = {**self.summary(), **provenance()}
        write_summary(folder, summary)
        arrays = {
            "platform_position_m": self.platform_position_m,
            "platform_rotation_deg": np.array(self.platform_rotation_deg),
            "cable_stretched_length_m": self.cable_stretched_length_m,
            "cable_unstrained_length_m": self.cable_unstrained_length_m,
            "first_free_node": self.first_free_node,
            "upper_points_m": self.upper_points_m,
            "upper_forces_N": self.upper_forces_N,
            "platform_forces_N": self.platform_forces_N,
            "anchor_tensions_N": self.anchor_tensions_N,
            "span_weights_N": self.span_weights_N,
            "max_node_speed_m_s": np.array(self.max_node_speed_m_s),
        }
        for i, (nodes, tensions) in enumerate(zip(self.nodes, self.tensions)):
            arrays[f"nodes_{i}"] = nodes
            arrays[f"tensions_{i}"] = tensions
        write_npz(folder / "rest.npz", **arrays)
        return {"summary": folder / "summary.json", "npz": folder / "rest.npz"}


# --------------------------------------------------------------------------- solver


def solve_rest(scene: Scene, *, tolerance: float = DEFAULT_TOLERANCE, max_time: float = DEFAULT_MAX_TIME,
               chunk_time: float = DEFAULT_CHUNK_TIME, polish: bool = True) -> RestState:
    """Bring ``scene`` to rest and return its static state.

    Integrates with the scene's solver settings up to its end time, then in chunks of
    ``chunk_time`` until the largest node speed over the last :data:`SPEED_WINDOW` of a
    chunk is below ``tolerance``; then (``polish``) runs Exudyn's static solver from
    there and keeps its answer if it converged within :data:`POLISH_MAX_SHIFT`. A scene
    without bending damping is settled with the paper's bending on and then solved
    statically with its own effects (see the module notes).

    Parameters
    ----------
    scene : Scene
        A scene with massive cables (``effects.cable_mass``) and the implicit solver.
        The winches hold their initial lengths.
    tolerance : float [m/s]
        Largest node speed counted as rest.
    max_time : float [s]
        Longest simulated time before giving up.
    chunk_time : float [s]
        Length of each extension of the run.
    polish : bool
        Polish the settled state with Exudyn's static solver.

    Returns
    -------
    RestState

    Raises
    ------
    SceneError
        If the scene has massless cables or an explicit integrator, or an argument is bad.
    SolverFailure
        If the solver fails, or the scene is not at rest after ``max_time``.
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
            shift, note = _static_polish(model)
            if shift is not None:
                method = "dynamic+static"
            else:
                notes.append(note)
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
    # Exudyn's static solver returns the constraint reactions with the opposite sign of
    # its dynamic solver's (measured: the same state gives negated Lagrange multipliers).
    reaction_sign = -1.0 if method.endswith("static") else 1.0
    state = _rest_state(model, scene, speed, elapsed, method, shift, tuple(notes), reaction_sign)
    return replace(state, wall_time_s=_time.perf_counter() - start)


def _build(scene: Scene) -> Model:
    """The scene's model, with a point-mass platform's rotation locked (see :data:`ROTATION_LOCK`)."""
    model = build_model(scene)
    if ROTATION_LOCK and scene.platform.is_point_mass:
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
    data = model.mbs.systemData
    indices = model.coordinate_indices()
    reference = np.asarray(data.GetODE2Coordinates(exu.ConfigurationType.Reference))
    q = np.asarray(data.GetODE2Coordinates())
    pose = reference[indices["platform"]] + q[indices["platform"]]
    state = {"platform_pose": pose.tolist() if np.all(np.isfinite(pose)) else None}
    nodes = [reference[indices[f"cable_{i}"]] + q[indices[f"cable_{i}"]] for i in range(len(model.cables))]
    state["nodes_m"] = [n.tolist() if np.all(np.isfinite(n)) else None for n in nodes]
    return state


def _static_solve(model: Model, max_shift: float | None) -> float | None:
    """Exudyn's static solver from the model's current state, velocities zeroed.

    Returns the largest node shift [m] if it converged (and moved no node farther than
    ``max_shift``); otherwise restores the state and returns None.
    """
    mbs = model.mbs
    data = mbs.systemData
    saved = data.GetSystemState()
    before = np.concatenate(_cable_positions(model))
    state = list(saved)
    state[1] = np.zeros_like(np.asarray(state[1]))
    data.SetSystemState(state, configuration=exu.ConfigurationType.Initial)
    printing = exu.config.printToConsole
    exu.config.printToConsole = False  # a failed static solve prints a page of hints
    try:
        converged = bool(mbs.SolveStatic(static_settings(1e-10), showHints=False, showCausingItems=False))
    except (exu.SolverError, RuntimeError, SystemError):
        converged = False
    finally:
        exu.config.printToConsole = printing
    after = np.concatenate(_cable_positions(model)) if converged else before
    shift = float(np.linalg.norm(after - before, axis=1).max()) if converged else math.inf
    if not converged or not np.isfinite(shift) or (max_shift is not None and shift > max_shift):
        data.SetSystemState(saved, configuration=exu.ConfigurationType.Current)
        return None
    state = data.GetSystemState()
    state[1] = np.zeros_like(np.asarray(state[1]))
    data.SetSystemState(state, configuration=exu.ConfigurationType.Current)
    return shift


def _static_polish(model: Model) -> tuple[float | None, str]:
    """Polish a settled state statically; returns (shift or None, note on refusal)."""
    shift = _static_solve(model, POLISH_MAX_SHIFT)
    if shift is None:
        return None, ("static polish refused: Exudyn's static solver did not converge within "
                      f"{POLISH_MAX_SHIFT * 1000:g} mm of the settled state; the dynamic rest state is kept")
    return shift, ""


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


# --------------------------------------------------------------------------- the state


def _cable_positions(model: Model) -> list[np.ndarray]:
    data = model.mbs.systemData
    reference = np.asarray(data.GetODE2Coordinates(exu.ConfigurationType.Reference))
    q = np.asarray(data.GetODE2Coordinates())
    indices = model.coordinate_indices()
    return [reference[indices[f"cable_{i}"]] + q[indices[f"cable_{i}"]] for i in range(len(model.cables))]


def _cable_velocities(model: Model) -> list[np.ndarray]:
    v = np.asarray(model.mbs.systemData.GetODE2Coordinates_t())
    indices = model.coordinate_indices()
    return [v[indices[f"cable_{i}"]] for i in range(len(model.cables))]


def leave_point(center: np.ndarray, radius: float, outside: np.ndarray, near: np.ndarray) -> np.ndarray:
    """Point of a pulley rim where the tangent from ``outside`` touches it, on the side of ``near``.

    Parameters
    ----------
    center : ndarray, shape (2,) [m]
    radius : float [m]
    outside : ndarray, shape (2,) [m]
        A point outside the rim (the first free node).
    near : ndarray, shape (2,) [m]
        A point on the rim (the last node in contact) that picks one of the two tangents.

    Returns
    -------
    ndarray, shape (2,) [m]
    """
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
                shift: float | None, notes: tuple, reaction_sign: float = 1.0) -> RestState:
    """Read the rest state off the model (see the module notes for the definitions).

    ``reaction_sign`` is -1 when the state comes from Exudyn's static solver, whose
    constraint reactions have the opposite sign of the dynamic solver's; the conventions
    below are the dynamic solver's, pinned by ``tests/test_model.py``.
    """
    mbs = model.mbs
    data = mbs.systemData
    reference = np.asarray(data.GetODE2Coordinates(exu.ConfigurationType.Reference))
    q = np.asarray(data.GetODE2Coordinates())
    platform = model.coordinate_indices()["platform"]
    pose = reference[platform] + q[platform]
    force = exu.OutputVariableType.Force
    positions, velocities = _cable_positions(model), _cable_velocities(model)
    tensions, lengths, unstrained, first, upper_points, upper_forces = [], [], [], [], [], []
    platform_forces, anchor_tensions, weights = [], [], []
    for i, (cable, nodes, v) in enumerate(zip(scene.cables, positions, velocities)):
        tension = element_tensions(cable, nodes, v, scene.effects)
        tensions.append(tension)
        node_weights = scene.gravity * cable.node_masses() if scene.effects.gravity else np.zeros(len(nodes))
        elements = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
        platform_forces.append(reaction_sign * np.asarray(mbs.GetObjectOutput(model.platform.joints[i], force))[:2])
        anchor_tensions.append(tension[-1])
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
            first.append(0)
            upper_points.append(nodes[0])
            upper_forces.append(upper)
            lengths.append(float(elements.sum()))
            unstrained.append(cable.unstrained_length)
            weights.append(float(node_weights.sum()))
            continue
        c = int(touching[-1])
        point = leave_point(np.asarray(pulley.point), pulley.radius, nodes[c + 1], nodes[c])
        piece = float(np.hypot(*(nodes[c + 1] - point)))
        on_span = tension[c] * (nodes[c] - nodes[c + 1]) / elements[c] + _bending_cut_force(scene, i, nodes, v, c)
        first.append(c + 1)
        upper_points.append(point)
        upper_forces.append(-on_span)
        lengths.append(piece + float(elements[c + 1:].sum()))
        strain = tension[c] / cable.axial_rigidity
        unstrained.append(piece / (1.0 + strain) + (len(elements) - c - 1) * cable.element_length)
        weights.append(float(node_weights[c + 1:].sum()))
    return RestState(
        scene_name=scene.name, platform_position_m=pose[:2].copy(),
        platform_rotation_deg=float(np.degrees(pose[2])), nodes=tuple(positions), tensions=tuple(tensions),
        cable_stretched_length_m=np.array(lengths), cable_unstrained_length_m=np.array(unstrained),
        first_free_node=np.array(first, dtype=int), upper_points_m=np.array(upper_points),
        upper_forces_N=np.array(upper_forces), platform_forces_N=np.array(platform_forces),
        anchor_tensions_N=np.array(anchor_tensions), span_weights_N=np.array(weights),
        max_node_speed_m_s=float(speed), time_s=float(elapsed), method=method, static_shift_m=shift, notes=notes,
    )
