"""How accurate is a run? A Richardson estimate of its discretisation error in the cable.

The lumped cable's error falls as n^-p with p close to 2 (``results/accuracy``, docs/accuracy.md), so a
*companion* run with r times as many elements (r = 2, or 1/2 for fine cables) tells a run's error:

    e(n) ~ |x_n - x_rn| / |1 - r^-p|,

the largest distance between the two platform paths after the start-up, scaled. Against the
converged references of ``tests/test_error_estimate.py`` it gave 1.18 and 1.29 times the true error
on the 10 s paper circle (15, 30 elements) and 0.89 to 1.46 times on the four-cable spatial robot.
:func:`elements_for_tolerance` inverts the same model. Units SI.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import asdict, dataclass, replace
from typing import Callable

import numpy as np

from controllers.ideal_ik import IdealIKController

from cdpr_exu.builder.model import build_model
from cdpr_exu.core.errors import CdprError, RunInterrupted, SceneError, SolverFailure
from cdpr_exu.core.output import length_text
from cdpr_exu.run.simulate import simulate

#: Order of the error in the number of elements assumed by the estimate (see above).
ORDER = 2.0
#: Errors are compared after the start-up, as in the rest of the project [s].
AFTER = 1.0
#: Finest cable :func:`elements_for_tolerance` proposes.
MAX_ELEMENTS = 400


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated largest position error of a run's platform centre after ``after_s`` [s] (None: ``note``
    says why), with the companion run's elements per cable and wall and CPU time [s]."""

    max_position_error_m: float | None
    companion_n_elements: int | None
    order: float
    after_s: float
    note: str
    companion_wall_time_s: float = 0.0
    companion_cpu_time_s: float = 0.0

    def to_dict(self) -> dict:
        return asdict(self)


def richardson_factor(ratio: float, order: float = ORDER) -> float:
    """Factor 1 / |1 - r^-p| from the difference of two runs (n and ``ratio`` n elements) to the error of
    the first: 4/3 for a companion twice as fine (p = 2), 1/3 for one half as fine."""
    if ratio <= 0 or ratio == 1 or order <= 0:
        raise SceneError(f"richardson_factor needs ratio > 0, != 1 and order > 0; got {ratio}, {order}")
    return 1.0 / abs(1.0 - ratio ** (-order))


def companion_elements(scene) -> int:
    """Elements per cable of the companion run: half as many for fine cables that fit, else twice."""
    n = max(c.n_elements for c in scene.cables)
    if n >= 30:
        try:
            build_model(_with_elements(scene, n // 2))
            return n // 2
        except CdprError:
            pass
    return 2 * n


def _with_elements(scene, n: int):
    """``scene`` (planar or spatial) with ``n`` elements per cable."""
    return scene.with_changes(cables=tuple(replace(c, n_elements=int(n)) for c in scene.cables))


def path_distance(result, other, after: float = 0.0) -> float:
    """Largest distance [m] of ``result``'s platform centre from ``other``'s (interpolated) after ``after``
    [s]."""
    mask = result.time >= after - 1e-9
    positions, other_positions = result.position, other.position
    path = np.column_stack([np.interp(result.time[mask], other.time, other_positions[:, k])
                            for k in range(other_positions.shape[1])])
    return float(np.linalg.norm(positions[mask] - path, axis=1).max())


def _not_applicable(note: str) -> ErrorEstimate:
    return ErrorEstimate(None, None, ORDER, AFTER, note)


def estimate_error(scene, result, controller_factory: Callable | None = None, after: float = AFTER) -> ErrorEstimate:
    """Estimate the discretisation error of ``result`` (a completed run of ``scene``) by Richardson, the
    paths compared from ``after`` [s] on; ``controller_factory`` makes a controller of the run's kind."""
    if not scene.effects.cable_mass:
        return _not_applicable("massless ropes have no elements: the estimate in the number of elements does not apply")
    if result.status != "completed":
        return _not_applicable("the run did not complete")
    mask = result.time >= after - 1e-9
    if not mask.any():
        return _not_applicable(f"the run is shorter than the {after} s start-up after which errors are measured")
    n = max(c.n_elements for c in scene.cables)
    n_companion = companion_elements(scene)
    companion_scene = _with_elements(scene, n_companion)
    controller = (controller_factory or IdealIKController)()
    start, cpu_start = time.perf_counter(), time.process_time()
    try:
        companion = simulate(companion_scene, controller)
    except RunInterrupted:  # Ctrl-C is the user's, not a failed companion
        raise
    except (SolverFailure, CdprError) as err:
        return _not_applicable(f"the companion run at {n_companion} elements did not complete: {str(err)[:200]}")
    wall, cpu = time.perf_counter() - start, time.process_time() - cpu_start
    if companion.time[-1] < result.time[-1] - 1e-9:
        return _not_applicable("the companion run ended before this run")
    difference = path_distance(result, companion, after)
    ratio = n_companion / n
    estimate = float(difference * richardson_factor(ratio))
    note = (f"Richardson from a companion run at {n_companion} elements per cable (this run: {n}), the error "
            f"assumed of order {ORDER:g} in the number of elements: {richardson_factor(ratio):.3g} times the "
            f"largest distance between the two paths after {after} s ({1000 * difference:.3g} mm)")
    return ErrorEstimate(estimate, n_companion, ORDER, after, note, wall, cpu)


def estimate_line(estimate: ErrorEstimate) -> str:
    """The line ``cdpr run`` prints for an estimate (planar and spatial)."""
    return (f"  estimated discretisation error after {estimate.after_s} s: "
            f"{length_text(estimate.max_position_error_m)} ({estimate.note})")


def summary_entry(estimate: ErrorEstimate) -> dict:
    """The entries of ``summary.json`` for an estimate (the companion's times go to ``timing.json``)."""
    timing = ("companion_wall_time_s", "companion_cpu_time_s")
    data = {"error_estimate": {k: v for k, v in estimate.to_dict().items() if k not in timing}}
    if estimate.companion_n_elements is not None:
        data.update({k: getattr(estimate, k) for k in timing})
    return data


def elements_for_tolerance(n: int, estimated_error: float, tolerance: float, order: float = ORDER) -> int:
    """Fewest elements per cable whose error by e(n) = C n^-p through (n, estimated_error) is below
    ``tolerance``, never fewer than ``n`` (the model is not extrapolated out of its measured range)."""
    if estimated_error <= tolerance:
        return n
    needed = math.ceil(n * (estimated_error / tolerance) ** (1.0 / order))
    if needed > MAX_ELEMENTS:
        raise SceneError(f"--tolerance {tolerance * 1000:g} mm needs about {needed} elements per cable by the error "
                         f"model (more than {MAX_ELEMENTS}); ask for a looser tolerance")
    return needed


_UNITS = {"": 1.0, "m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6}


def parse_length(text: str, option: str = "--tolerance") -> float:
    """A length such as ``5mm``, ``0.5 cm`` or ``0.002`` (metres) [m]; refused naming ``option``."""
    match = re.fullmatch(r"\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*(m|cm|mm|um)?\s*", str(text))
    if not match:
        raise SceneError(f"{option} must be a length such as 5mm, 0.5cm or 0.002 (metres), got {text!r}")
    value = float(match.group(1)) * _UNITS[match.group(2) or ""]
    if not value > 0 or not math.isfinite(value):
        raise SceneError(f"{option} must be positive, got {text!r}")
    return value
