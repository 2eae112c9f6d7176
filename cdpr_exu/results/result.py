"""The result of a run, planar or spatial: time series of the platform, the cables and the winches, and their files.

A :class:`Result` is plain NumPy data (no Exudyn): the platform pose, every cable
node's position, every element's tension, the winch lengths and the reference, at
the output times. Its dimension is data (``dimension``, :attr:`Result.space`): the pose
is the Space's (:mod:`cdpr_exu.space`: ``(x, z, rotation)`` in the paper's plane, ``(x, y,
z, rotation vector)`` in space), and the figures of its summary are named from the
Space's labels. It saves to ``result.npz`` + ``pose.csv`` + ``summary.json`` and loads back
from the ``.npz``.
"""

from __future__ import annotations

import datetime
import json
import platform as _platform
import warnings as _warnings
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np

from cdpr_exu.core.errors import UnphysicalResultWarning
from cdpr_exu.core.output import (PLANAR_POSE_COLUMNS, SPATIAL_POSE_COLUMNS, json_text, write_npz, write_pose_csv,
                                  write_summary)
from cdpr_exu.space import PLANE, SPACE, Space, space_of

#: The pose columns of ``pose.csv``, by space.
POSE_COLUMNS = {PLANE: PLANAR_POSE_COLUMNS, SPACE: SPATIAL_POSE_COLUMNS}

#: Figures a space's summaries leave out. The planar summary.json files (committed in results/, read by
#: the README's tables) keep the layout they had before spatial runs shared the summary: no ``dimension``
#: (absent means 2, as in a scene file) and no ``max_rotation_error_deg`` (their rotation about the one
#: axis is ``max_abs_rotation_deg``; its error is in the figures' rotation panel).
LEFT_OUT = {PLANE: ("dimension", "max_rotation_error_deg"), SPACE: ()}


@dataclass
class Result:
    """Time series of one run, planar or spatial. Units SI.

    Attributes
    ----------
    scene_name : str
    controller : str
    dimension : int
        2 (the paper's x-z plane) or 3: :attr:`space` says what a pose is.
    time : ndarray, shape (N,) [s]
    pose : ndarray, shape (N, pose_size) [m, rad]
        The platform's pose: (x, z, rotation) planar, rotation positive counter-clockwise;
        (x, y, z, rotation vector) spatial, the centre of mass and the platform's rotation vector.
    reference : ndarray, shape (N, pose_size)
        The reference pose at the same times.
    nodes : list of ndarray, each shape (N, n_i + 1, d) [m]
        Node positions of cable i, winch end first (planar) or exit first (spatial).
    tensions : list of ndarray, each shape (N, n_i) [N]
        Axial force of each element (tension positive).
    paid_out : ndarray, shape (N, m) [m]
        Commanded paid-out length of each winch.
    velocity : ndarray, shape (N, pose_size), or None [m/s, rad/s]
        The pose's time derivative, where the run records it (planar runs: (vx, vz, angular
        rate)); None where it does not (spatial runs).
    node_velocities : list of ndarray, each shape (N, n_i + 1, d), or None [m/s]
        Where recorded (planar runs).
    pulley_penetration : ndarray, shape (N, m), or None [m]
        Deepest node penetration into each cable's pulley (0 if none); None where the exits
        have no contact to penetrate (spatial runs).
    wall_time : float [s]
    cpu_time : float [s]
        Process CPU time of the solve (the same span as ``wall_time``).
    steps : int
        Time steps completed.
    newton_iterations : int
    status : str
        "completed", "failed: <cause>" or "interrupted at ...".
    failure_time : float or None [s]
    winch_reservoir : ndarray, shape (N, m), or None [m]
        Slack rope held at each winch drum (tension-only cables under kinematic winches,
        see :func:`cdpr_exu.builder.winch.reservoir_split`); it lengthens each cable's winch
        element (element 0). None where there is no reservoir.
    metadata : dict
    """

    scene_name: str
    controller: str
    dimension: int
    time: np.ndarray
    pose: np.ndarray
    reference: np.ndarray
    nodes: list[np.ndarray]
    tensions: list[np.ndarray]
    paid_out: np.ndarray
    velocity: np.ndarray | None = None
    node_velocities: list[np.ndarray] | None = None
    pulley_penetration: np.ndarray | None = None
    wall_time: float = 0.0
    cpu_time: float = 0.0
    steps: int = 0
    newton_iterations: int = 0
    status: str = "completed"
    failure_time: float | None = None
    winch_reservoir: np.ndarray | None = None
    metadata: dict[str, Any] = field(default_factory=dict)

    # ----------------------------------------------------------------- derived
    @property
    def space(self) -> Space:
        """The run's :class:`~cdpr_exu.space.Space` (what a pose, a position and a rotation are)."""
        return space_of(self.dimension)

    @property
    def labels(self) -> tuple[str, ...]:
        """The names of the pose's entries (the Space's ``pose_labels``)."""
        return self.space.pose_labels

    @property
    def error(self) -> np.ndarray:
        """Pose error actual - reference, shape (N, pose_size) [m, rad] (spatial: the rotation vectors' difference;
        the angle between the orientations is :meth:`Space.rotation_error_deg`)."""
        return self.pose - self.reference

    @property
    def position(self) -> np.ndarray:
        """The platform centre's positions, shape (N, d) [m]: (x, z) planar, (x, y, z) spatial."""
        return self.pose[:, :self.space.position_size]

    @property
    def position_error(self) -> np.ndarray:
        """Actual minus reference position of the centre, shape (N, d) [m]."""
        d = self.space.position_size
        return self.pose[:, :d] - self.reference[:, :d]

    @property
    def simulated_time(self) -> float:
        return float(self.time[-1]) if len(self.time) else 0.0

    @property
    def error_figures(self) -> tuple[str, ...]:
        """The figures of :meth:`summary` measured from its ``after`` on (the rest cover the whole run): each
        position axis's largest absolute error, the vertical error's range, the centre's largest and RMS
        error, the platform's largest rotation and its largest rotation error (where the space reports it)."""
        space = self.space
        vertical = space.position_labels[space.vertical]
        names = (*(f"max_abs_error_{label}_m" for label in space.position_labels), f"min_error_{vertical}_m",
                 f"max_error_{vertical}_m", "max_position_error_m", "rms_position_error_m", "max_abs_rotation_deg",
                 "max_rotation_error_deg")
        return tuple(name for name in names if name not in LEFT_OUT[space])

    def summary(self, after: float = 0.0) -> dict[str, Any]:
        """Scalar figures of the run [SI, degrees]: errors (:attr:`error_figures`) measured from time
        ``after`` on, the safety figures (tensions, slack, pushing, tension limits, a platform above
        its exits) over the whole run (:func:`safety_figures`).

        The figures are named from the Space's labels, the same rule in both dimensions:
        ``max_abs_error_<axis>_m`` for each position axis, ``min_error_z_m`` / ``max_error_z_m`` for the
        vertical one, ``max_position_error_m`` / ``rms_position_error_m`` for the centre,
        ``max_abs_rotation_deg`` (the platform's rotation from its home orientation) and
        ``max_rotation_error_deg`` (the angle from the reference's orientation to the platform's);
        planar summaries leave out what :data:`LEFT_OUT` says.

        A figure that does not exist (no sample at or after ``after``: a run shorter than
        the error window, or one that failed before it) is None, and ``notes`` says why;
        ``warnings`` says what no real robot can do (elements that push, a platform above
        its exits).
        """
        space = self.space
        d, vertical = space.position_size, space.vertical
        mask = self.time >= after
        err = self.position_error[mask]
        pose, reference = self.pose[mask], self.reference[mask]
        position_error = np.linalg.norm(err, axis=1) if len(err) else np.zeros(0)
        safety = safety_figures(self.time, self.tensions, self.pose[:, vertical] if len(self.time) else None,
                                self.metadata.get("highest_exit_z_m"), self.metadata.get("tension_limits_N"))
        notes = []
        if not len(err):
            notes.append(f"no sample at or after t = {after:g} s (the run reached {self.simulated_time:g} s): "
                         "its error and rotation figures do not exist and are null")
        limits = {k: safety.pop(k) for k in ("tension_limits_N", "tension_limit_violations") if k in safety}
        warnings_ = safety.pop("warnings")
        label = space.position_labels[vertical]
        summary = {
            "scene": self.scene_name,
            "controller": self.controller,
            "dimension": self.dimension,
            "status": self.status,
            "errors_measured_after_s": after,
            **{f"max_abs_error_{name}_m": _nan_max(np.abs(err[:, k])) for k, name in enumerate(space.position_labels)},
            f"min_error_{label}_m": _nan_min(err[:, vertical]),
            f"max_error_{label}_m": _nan_max(err[:, vertical]),
            "max_position_error_m": _nan_max(position_error),
            "rms_position_error_m": float(np.sqrt(np.mean(position_error**2))) if len(err) else None,
            "max_abs_rotation_deg": (_nan_max(space.rotation_error_deg(pose, np.zeros_like(pose)))
                                     if len(err) else None),
            "max_rotation_error_deg": _nan_max(space.rotation_error_deg(pose, reference)) if len(err) else None,
            **safety,
            "max_pulley_penetration_m": None if self.pulley_penetration is None else _nan_max(self.pulley_penetration),
            "wall_time_s": self.wall_time,
            "cpu_time_s": self.cpu_time,
            "simulated_time_s": self.simulated_time,
            "real_time_factor": self.simulated_time / self.wall_time if self.wall_time > 0 else None,
            "steps": int(self.steps),
            "newton_iterations": int(self.newton_iterations),
            "failure_time_s": self.failure_time,
            "max_winch_reservoir_m": (None if self.winch_reservoir is None or not len(self.winch_reservoir)
                                      else self.winch_reservoir.max(axis=0).tolist()),
            "notes": notes,
            "warnings": warnings_,
            **limits,
        }
        for key in LEFT_OUT[space]:
            del summary[key]
        return summary

    # ----------------------------------------------------------------- files
    def save(self, folder: str | Path, after: float = 1.0, extra: dict[str, Any] | None = None) -> dict[str, Path]:
        """Write ``result.npz``, ``pose.csv`` and ``summary.json`` into ``folder``.

        ``summary.json`` is :meth:`summary` over the whole run with the provenance (:func:`provenance`),
        ``extra``'s entries, the metadata and the errors after ``after`` [s] (``after_start_up``); the wall-clock
        figures go to ``timing.json`` (:func:`~cdpr_exu.core.output.write_summary`). ``result.npz``
        holds the same arrays under the same names in both dimensions (``platform_pose``,
        ``reference_pose``, ``platform_velocity`` where recorded, ...). Returns the paths written, by kind.
        """
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        arrays = {"time": self.time, "platform_pose": self.pose}
        if self.velocity is not None:
            arrays["platform_velocity"] = self.velocity
        arrays["reference_pose"] = self.reference
        arrays["paid_out"] = self.paid_out
        if self.pulley_penetration is not None:
            arrays["pulley_penetration"] = self.pulley_penetration
        if self.winch_reservoir is not None:
            arrays["winch_reservoir"] = self.winch_reservoir
        for i, (nodes, tensions) in enumerate(zip(self.nodes, self.tensions)):
            arrays[f"nodes_{i}"] = nodes
            if self.node_velocities is not None:
                arrays[f"node_velocities_{i}"] = self.node_velocities[i]
            arrays[f"tensions_{i}"] = tensions
        # The wall time lives in timing.json, so that result.npz is the same from run to run; the
        # dimension is written where it is not the default (2, as in a scene file).
        info = {"scene_name": self.scene_name, "controller": self.controller,
                **({} if "dimension" in LEFT_OUT[self.space] else {"dimension": self.dimension}),
                "steps": self.steps, "newton_iterations": self.newton_iterations, "status": self.status,
                "failure_time": self.failure_time, "metadata": self.metadata}
        write_npz(folder / "result.npz", info=np.array(json_text(info)), **arrays)
        write_pose_csv(folder / "pose.csv", self.time, self.pose, self.reference, POSE_COLUMNS[self.space])
        summary = {**self.summary(0.0), **provenance(), **(extra or {})}
        summary.update({k: v for k, v in self.metadata.items() if k not in summary})
        summary["after_start_up"] = after_start_up(self.summary(after), self.error_figures)
        summary["error_convention"] = "actual - reference"
        write_summary(folder, summary)
        return {"npz": folder / "result.npz", "csv": folder / "pose.csv", "summary": folder / "summary.json"}

    @classmethod
    def load(cls, path: str | Path) -> "Result":
        """Read a ``result.npz`` written by :meth:`save` (a folder is accepted too)."""
        path = Path(path)
        if path.is_dir():
            path = path / "result.npz"
        with np.load(path, allow_pickle=False) as data:
            info = json.loads(str(data["info"]))
            timing = path.parent / "timing.json"
            if "wall_time" not in info and timing.is_file():
                times = json.loads(timing.read_text())
                info["wall_time"] = times.get("wall_time_s") or 0.0
                info["cpu_time"] = times.get("cpu_time_s") or 0.0
            m = sum(1 for k in data.files if k.startswith("nodes_"))

            def optional(name):
                return data[name] if name in data.files else None

            return cls(
                scene_name=info["scene_name"], controller=info["controller"], dimension=info.get("dimension", 2),
                time=data["time"], pose=data["platform_pose"], reference=data["reference_pose"],
                nodes=[data[f"nodes_{i}"] for i in range(m)], tensions=[data[f"tensions_{i}"] for i in range(m)],
                paid_out=data["paid_out"], velocity=optional("platform_velocity"),
                node_velocities=([data[f"node_velocities_{i}"] for i in range(m)]
                                 if "node_velocities_0" in data.files else None),
                pulley_penetration=optional("pulley_penetration"),
                wall_time=info.get("wall_time", 0.0), cpu_time=info.get("cpu_time", 0.0), steps=info["steps"],
                newton_iterations=info["newton_iterations"], status=info["status"],
                failure_time=info["failure_time"], metadata=info.get("metadata", {}),
                winch_reservoir=optional("winch_reservoir"),
            )


def provenance() -> dict[str, Any]:
    """Package versions, Python and the date, for every file a run writes."""
    versions = {}
    for package in ("cdpr-exu", "exudyn", "numpy", "scipy", "numba"):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    return {
        "versions": versions,
        "python": _platform.python_version(),
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
    }


def slack_time(times: np.ndarray, tensions: np.ndarray) -> float | None:
    """Time [s] during which some element of a cable carries no tension (slack, or pushing).

    ``times`` shape (N,) [s]; ``tensions`` shape (N, n) [N], the cable's element tensions
    at those times. Each sample stands for the interval after it. None with fewer than
    two samples.
    """
    if len(times) < 2:
        return None
    slack = np.any(np.asarray(tensions).reshape(len(times), -1) <= 0.0, axis=1)
    widths = np.diff(times, append=times[-1])
    return float(np.sum(widths[slack]))


def _nan_max(values) -> float | None:
    """Largest finite entry of ``values``, or None when there is none."""
    values = np.asarray(values, dtype=float)
    return float(np.nanmax(values)) if values.size and np.isfinite(values).any() else None


def _nan_min(values) -> float | None:
    """Smallest finite entry of ``values``, or None when there is none."""
    values = np.asarray(values, dtype=float)
    return float(np.nanmin(values)) if values.size and np.isfinite(values).any() else None


def safety_figures(times: np.ndarray, tensions, heights: np.ndarray | None = None,
                   highest_exit: float | None = None, limits=None) -> dict[str, Any]:
    """What a run did that a real robot could not, over its samples.

    One computation for planar and spatial summaries: the element tensions, each cable's
    slack time, elements that pushed (a negative tension: the lumped cable carried
    compression), the tension limits crossed (:func:`tension_limit_report`) and a platform
    above its highest exit (every cable then pulls it down: only pushing cables could
    hold it there). Never limited to an error window: a run shorter than the window, or
    a jolt at its start, is reported all the same.

    The lowest tensions and the slack times cover the samples after t = 0: the sample at
    t = 0 is the initial condition, not something the run did (a planar run starts from
    straight unstretched cables, which carry nothing there (0 N to round-off): every run would read 0 N and
    one more output period of slack). Pushing, the largest tension, a platform above its
    exits and the tension limits cover every sample, t = 0 included: the warning says when
    the compression is in the initial state.

    Parameters
    ----------
    times : ndarray, shape (N,) [s]
    tensions : sequence of ndarray, each shape (N, n_i) [N]
        Element tensions of each cable (tension positive).
    heights : ndarray, shape (N,) [m], optional
        Height (z) of the platform's centre of mass.
    highest_exit : float [m], optional
        Height of the highest exit: the highest pulley centre (planar), exit point or swivel
        inlet (spatial). Without it (or ``heights``), ``platform_above_exits`` is None.
    limits : list of [t_min or None, t_max or None] [N], one per cable, or None

    Returns
    -------
    dict
        ``min_element_tension_N``, ``max_element_tension_N``, ``min_tension_per_cable_N``,
        ``slack_time_per_cable_s``, ``elements_pushed``, ``platform_above_exits``,
        ``highest_exit_z_m``, ``warnings`` (one sentence per fact above) and, with ``limits``,
        ``tension_limits_N`` and ``tension_limit_violations``.
    """
    times = np.asarray(times, dtype=float)
    tensions = [np.asarray(t, dtype=float) for t in tensions]
    later = times > 0.0  # after the initial condition
    lowest = [_nan_min(t[later]) for t in tensions]
    known = [value for value in lowest if value is not None]
    everywhere = [_nan_min(t) for t in tensions]  # t = 0 included
    pushed_at = [value for value in everywhere if value is not None]
    pushed = bool(pushed_at) and min(pushed_at) < 0.0
    warnings_ = []
    if pushed:
        cable = int(np.argmin([np.inf if value is None else value for value in everywhere]))
        series = tensions[cable].reshape(len(times), -1)
        per_sample = np.min(np.where(np.isfinite(series), series, np.inf), axis=1)
        pushing = per_sample < 0.0
        initial = "" if later[0] or not pushing[0] else (
            "; in the initial state, at t = 0" + ("" if pushing[later].any() else " only") + ", where the run starts from")
        warnings_.append(f"elements pushed (lowest tension {min(pushed_at):.4g} N, cable {cable + 1} at "
                         f"t = {times[int(np.argmin(per_sample))]:.4f} s; first push at "
                         f"t = {times[int(np.argmax(pushing))]:.4f} s{initial}): the lumped cable carried compression, "
                         "which a real cable cannot; effects.slack = true makes the elements tension-only")
    above = None
    if heights is not None and highest_exit is not None and len(times):
        heights = np.asarray(heights, dtype=float)
        rise = np.isfinite(heights) & (heights > highest_exit)
        above = bool(rise.any())
        if above:
            warnings_.append(f"the platform rose above its highest exit (z = {highest_exit:.4g} m) at "
                             f"t = {times[int(np.argmax(rise))]:.4f} s, up to z = {np.nanmax(heights):.4g} m: every "
                             "cable pulls it down there, so only cables that push could hold it")
    return {
        "min_element_tension_N": min(known) if known else None,
        "max_element_tension_N": _nan_max(np.concatenate([t.ravel() for t in tensions])) if tensions else None,
        "min_tension_per_cable_N": lowest,
        "slack_time_per_cable_s": [slack_time(times[later], t[later]) for t in tensions],
        "elements_pushed": pushed,
        "platform_above_exits": above,
        "highest_exit_z_m": highest_exit,
        "warnings": warnings_,
        **tension_limit_report(times, tensions, limits),
    }


def after_start_up(settled: dict[str, Any], error_figures) -> dict[str, Any]:
    """The ``after_start_up`` entry of a run's summary.json: the error figures ``error_figures`` of a
    summary measured after the start-up (``settled``), with its window and notes (its safety figures
    cover the whole run, as the summary's own)."""
    return {key: settled[key] for key in ("errors_measured_after_s", *error_figures, "notes")}


def warning_flags(summary: dict[str, Any]) -> list[str]:
    """What a summary's safety figures flag, in words ("cables pushed", "platform above its exits"): the
    comparison tables and the printed status show them beside the status."""
    return [text for key, text in (("elements_pushed", "cables pushed"), ("platform_above_exits",
                                                                          "platform above its exits"))
            if summary.get(key)]


def status_text(summary: dict[str, Any]) -> str:
    """A summary's status as printed: "completed" is not clean when its safety figures flag something
    ("completed (cables pushed: see the warnings)")."""
    flags = warning_flags(summary)
    return summary["status"] + (f" ({', '.join(flags)}: see the warnings)" if flags else "")


def raise_warnings(summary: dict[str, Any], label: str = "") -> None:
    """Issue each of ``summary``'s ``warnings`` as an :class:`~cdpr_exu.core.errors.UnphysicalResultWarning`
    (prefixed with ``label``): the ``cdpr`` command prints each once, as one line."""
    for text in summary.get("warnings", ()):
        _warnings.warn(f"{label}{text}", UnphysicalResultWarning, stacklevel=2)


def tension_limit_report(times: np.ndarray, tensions, limits) -> dict[str, Any]:
    """``tension_limit_violations``: each cable's element tensions outside its (t_min, t_max), if any are set.

    One entry per cable and limit crossed: the limit, when it was first crossed, the
    most extreme tension and for how long some element was beyond it. Empty (``{}``:
    absent from the summary) for a scene without tension limits. Planar and spatial
    runs report the same way.

    Parameters
    ----------
    times : ndarray, shape (N,) [s]
    tensions : sequence of ndarray, each shape (N, n) [N]
        Element tensions of each cable at those times.
    limits : list of [t_min or None, t_max or None] [N], one per cable, or None
    """
    if limits is None:
        return {}
    times = np.asarray(times, dtype=float)
    widths = np.diff(times, append=times[-1]) if len(times) else np.zeros(0)
    violations = []
    for i, (series, (low, high)) in enumerate(zip(tensions, limits)):
        series = np.asarray(series, dtype=float)
        if not series.size:
            continue
        for name, limit, extreme, beyond in (
                ("min_tension", low, np.nanmin(series, axis=1), lambda x, v: x < v),
                ("max_tension", high, np.nanmax(series, axis=1), lambda x, v: x > v)):
            if limit is None:
                continue
            crossed = beyond(extreme, limit)
            if np.any(crossed):
                worst = extreme[crossed].min() if name == "min_tension" else extreme[crossed].max()
                violations.append({"cable": i + 1, "limit": name, "limit_N": float(limit),
                                   "first_time_s": float(times[np.argmax(crossed)]), "extreme_N": float(worst),
                                   "duration_s": float(np.sum(widths[crossed]))})
    return {"tension_limits_N": limits, "tension_limit_violations": violations}
