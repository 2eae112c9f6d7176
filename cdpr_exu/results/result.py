"""The result of a run, planar or spatial: time series of the platform, the cables and the winches, and their files.

A :class:`Result` is plain NumPy data at its sample times: the end of the first step at or after each output
time, so up to a step past it, and other steps sample at other times (compare two runs at the same times,
interpolating one, not row by row). Its dimension is data (:attr:`Result.space`):
the pose is the Space's (``(x, z, rotation)`` in the paper's plane, ``(x, y, z, rotation vector)`` in
space) and its summary's figures are named from the Space's labels. It saves to ``result.npz`` +
``pose.csv`` + ``summary.json`` and loads back from the ``.npz``.
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
from cdpr_exu.core.output import json_text, write_npz, write_pose_csv, write_summary
from cdpr_exu.space import PLANE, SPACE, Space, space_of

#: Figures a space's summaries leave out: a planar summary.json (committed in results/, read by the
#: README's tables) has no ``dimension`` (absent means 2, as in a scene file) and no
#: ``max_rotation_error_deg`` (its rotation about the one axis is ``max_abs_rotation_deg``).
LEFT_OUT = {PLANE: ("dimension", "max_rotation_error_deg"), SPACE: ()}


@dataclass
class Result:
    """Time series of one run, planar or spatial (``dimension`` 2 or 3). Units SI.

    Attributes
    ----------
    time : ndarray, shape (N,) [s]
        The sample times: each the end of the first step at or after an output time (one sample for a step
        over several), and the state a run stops at.
    pose, reference : ndarray, shape (N, pose_size) [m, rad]
        The platform's pose and its reference: (x, z, rotation counter-clockwise) planar,
        (x, y, z, rotation vector) spatial.
    nodes : list of ndarray, each shape (N, n_i + 1, d) [m]
        Node positions of cable i, upper end (winch or exit) first.
    tensions : list of ndarray, each shape (N, n_i) [N]
        Axial force of each element (tension positive).
    paid_out : ndarray, shape (N, m) [m]
        Commanded paid-out length of each winch.
    velocity, node_velocities, pulley_penetration : ndarray or None
        Where the run records them (planar runs): the pose's time derivative (N, pose_size), the nodes'
        velocities [m/s], the deepest node penetration into each cable's pulley (N, m) [m].
    status : str
        "completed", "failed: <cause>" or "interrupted at ...".
    winch_reservoir : ndarray, shape (N, m), or None [m]
        Slack rope held at each winch drum (:func:`cdpr_exu.builder.winch.reservoir_split`), which
        lengthens the winch element (element 0); None without a reservoir.
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
    #: The solver's Jacobian updates and discontinuous iterations of the run (benchmarks; not saved).
    jacobians: int = 0
    discontinuous_iterations: int = 0
    status: str = "completed"
    failure_time: float | None = None
    winch_reservoir: np.ndarray | None = None
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def space(self) -> Space:
        return space_of(self.dimension)

    @property
    def error(self) -> np.ndarray:
        """Pose error actual - reference, shape (N, pose_size) [m, rad] (spatial: the rotation vectors'
        difference; the angle between the orientations is :meth:`Space.rotation_error_deg`)."""
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
        """The figures of :meth:`summary` measured from its ``after`` on, named from the Space's labels: each
        position axis's largest absolute error, the vertical error's range, the centre's largest and RMS
        error, the platform's largest rotation (from its home orientation) and rotation error (the angle
        from the reference's orientation), less what :data:`LEFT_OUT` says."""
        space = self.space
        vertical = space.position_labels[space.vertical]
        names = (*(f"max_abs_error_{label}_m" for label in space.position_labels), f"min_error_{vertical}_m",
                 f"max_error_{vertical}_m", "max_position_error_m", "rms_position_error_m", "max_abs_rotation_deg",
                 "max_rotation_error_deg")
        return tuple(name for name in names if name not in LEFT_OUT[space])

    def summary(self, after: float = 0.0) -> dict[str, Any]:
        """Scalar figures of the run [SI, degrees]: the errors (:attr:`error_figures`) from time ``after``
        on, the safety figures (:func:`safety_figures`) over the whole run. A figure without a sample at or
        after ``after`` is None, and ``notes`` says why."""
        space = self.space
        vertical = space.vertical
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

    def save(self, folder: str | Path, after: float = 1.0, extra: dict[str, Any] | None = None) -> dict[str, Path]:
        """Write ``result.npz``, ``pose.csv`` and ``summary.json`` into ``folder``; returns the paths by kind.

        ``summary.json`` is :meth:`summary` over the whole run with the provenance, ``extra``'s entries,
        the metadata and the errors after ``after`` [s] (``after_start_up``); wall-clock figures go to
        ``timing.json`` (:func:`~cdpr_exu.core.output.write_summary`).
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
        # no wall time (timing.json has it): result.npz is the same from run to run
        info = {"scene_name": self.scene_name, "controller": self.controller,
                **({} if "dimension" in LEFT_OUT[self.space] else {"dimension": self.dimension}),
                "steps": self.steps, "newton_iterations": self.newton_iterations, "status": self.status,
                "failure_time": self.failure_time, "metadata": self.metadata}
        write_npz(folder / "result.npz", info=np.array(json_text(info)), **arrays)
        write_pose_csv(folder / "pose.csv", self.time, self.pose, self.reference, self.space.pose_columns)
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
    """Time [s] during which some element of a cable (``tensions`` (N, n) [N] at ``times`` (N,) [s]) carries
    no tension, each sample standing for the interval after it; None with fewer than two samples."""
    if len(times) < 2:
        return None
    slack = np.any(np.asarray(tensions).reshape(len(times), -1) <= 0.0, axis=1)
    widths = np.diff(times, append=times[-1])
    return float(np.sum(widths[slack]))


def _nan_max(values, extreme=np.nanmax) -> float | None:
    """Largest (``extreme=np.nanmin``: smallest) finite entry of ``values``, or None when there is none."""
    values = np.asarray(values, dtype=float)
    return float(extreme(values)) if values.size and np.isfinite(values).any() else None


def _nan_min(values) -> float | None:
    return _nan_max(values, np.nanmin)


def safety_figures(times: np.ndarray, tensions, heights: np.ndarray | None = None,
                   highest_exit: float | None = None, limits=None) -> dict[str, Any]:
    """What a run did that a real robot could not, over all its samples (never an error window).

    The element tensions, each cable's slack time, elements that pushed, the tension limits crossed and
    a platform above its highest exit, with a warning for each. The lowest tensions and slack times
    leave out t = 0, the initial condition (a planar run starts from unstretched cables at 0 N).
    ``tensions`` (N, n_i) [N] per cable at ``times`` (N,) [s]; ``heights`` (N,) [m] of the platform's centre
    and ``highest_exit`` [m] (without them ``platform_above_exits`` is None); ``limits``: [t_min, t_max]
    [N] (or None) per cable, or None.
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
    """The ``after_start_up`` entry of a summary.json: ``settled``'s ``error_figures``, window and notes."""
    return {key: settled[key] for key in ("errors_measured_after_s", *error_figures, "notes")}


def warning_flags(summary: dict[str, Any]) -> list[str]:
    """What a summary's safety figures flag, in words ("cables pushed", "platform above its exits")."""
    return [text for key, text in (("elements_pushed", "cables pushed"), ("platform_above_exits",
                                                                          "platform above its exits"))
            if summary.get(key)]


def status_text(summary: dict[str, Any]) -> str:
    """A summary's status as printed, with its flags ("completed (cables pushed: see the warnings)")."""
    flags = warning_flags(summary)
    return summary["status"] + (f" ({', '.join(flags)}: see the warnings)" if flags else "")


def raise_warnings(summary: dict[str, Any], label: str = "") -> None:
    """Issue each of ``summary``'s ``warnings``, prefixed with ``label``, as an UnphysicalResultWarning."""
    for text in summary.get("warnings", ()):
        _warnings.warn(f"{label}{text}", UnphysicalResultWarning, stacklevel=2)


def tension_limit_report(times: np.ndarray, tensions, limits) -> dict[str, Any]:
    """``tension_limit_violations``: one entry per cable and limit (t_min, t_max) its element tensions
    (N, n) [N] at ``times`` (N,) [s] crossed: the limit, when first crossed, the most extreme tension and
    for how long; ``{}`` (absent from the summary) without ``limits``."""
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
