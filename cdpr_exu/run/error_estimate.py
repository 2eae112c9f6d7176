"""How accurate is a run? A Richardson estimate of its discretisation error in the cable.

The accuracy study (``results/accuracy``) shows that on the paper circle the error of
the lumped cable falls as n^-p with p close to 2 (observed 1.9 to 2.5 from 10 to 45
elements per cable; the step contributes far less at the shipped 2e-3 s). So a second,
*companion* run with r times as many elements (r = 2 for coarse cables, 1/2 for fine
ones, where that is cheaper and the coarser cable still fits its pulleys) tells the
first run's error:

    e(n) ~ |x_n - x_rn| / |1 - r^-p|,

the largest distance between the two platform paths after the start-up, scaled. This
is Richardson extrapolation on the path; on the 10 s paper circle it gave 1.18 times
(15 elements) and 1.29 times (30 elements) the true error against the converged
reference of the accuracy study (``tests/test_error_estimate.py``).

:func:`elements_for_tolerance` inverts the same model: the fewest elements whose
estimated error stays below a tolerance.

Spatial scenes (``dimension = 3``, :mod:`cdpr_exu.run.run_3d`) get the same estimate
on the platform centre's 3-D path. Measured on the four-cable robot without bending
(``tests/test_error_estimate.py``): held on its catenary pose, the error falls as n^-2
and the estimate is 1.05 (4 elements) and 1.03 (8) times the true error against the
elastic catenary; during a 1 s point-to-point move the estimate at 8 elements is 1.46
times the error against 32 elements at the same 1e-2 s step and 0.89 times that against
64 elements at 2.5e-3 s. In motion the discretisation error is of order 2 too (1.96 from
16 to 64 elements with linear spring-dampers, where the step and Newton leave it clean);
what once looked like n^-1.3 was the 1e-2 s step's error and the Newton error of
tension-only references at 32 elements and more (docs/accuracy.md, "The order of the
spatial error in motion"). Units SI.
"""

from __future__ import annotations

import math
import re
import time
from dataclasses import dataclass, replace
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
    """The estimated discretisation error of a run's platform path.

    Attributes
    ----------
    max_position_error_m : float or None [m]
        Estimated largest position error of the platform centre after ``after_s``;
        None when no estimate exists (``note`` says why).
    companion_n_elements : int or None
        Elements per cable of the companion run.
    order : float
        Assumed order of the error in the number of elements.
    after_s : float [s]
    note : str
        How the estimate was made, or why there is none.
    companion_wall_time_s, companion_cpu_time_s : float [s]
        Wall and process CPU time of the companion run (its simulate() call).
    """

    max_position_error_m: float | None
    companion_n_elements: int | None
    order: float
    after_s: float
    note: str
    companion_wall_time_s: float = 0.0
    companion_cpu_time_s: float = 0.0

    def to_dict(self) -> dict:
        return {"max_position_error_m": self.max_position_error_m, "companion_n_elements": self.companion_n_elements,
                "order": self.order, "after_s": self.after_s, "note": self.note,
                "companion_wall_time_s": self.companion_wall_time_s, "companion_cpu_time_s": self.companion_cpu_time_s}


def richardson_factor(ratio: float, order: float = ORDER) -> float:
    """Factor from the difference of two runs (n and ratio * n elements) to the error of the first.

    e(n) = |x_n - x_{rn}| / |1 - r^-p|: 4/3 for a companion twice as fine (r = 2, p = 2),
    1/3 for one half as fine (r = 1/2).
    """
    if ratio <= 0 or ratio == 1 or order <= 0:
        raise SceneError(f"richardson_factor needs ratio > 0, != 1 and order > 0; got {ratio}, {order}")
    return 1.0 / abs(1.0 - ratio ** (-order))


def companion_elements(scene) -> int:
    """Elements per cable of the companion run: half as many for fine cables (if they still
    fit the pulleys, which the planar model or the spatial scene's swivel check says), else
    twice as many."""
    n = max(c.n_elements for c in scene.cables)
    if n >= 30:
        try:
            build_model(_with_elements(scene, n // 2))  # a spatial scene checks its swivel pulleys, the planar
            # builder its elements against the pulleys
            return n // 2
        except CdprError:
            pass
    return 2 * n


def _with_elements(scene, n: int):
    """``scene`` (planar or spatial) with ``n`` elements per cable."""
    return scene.with_changes(cables=tuple(replace(c, n_elements=int(n)) for c in scene.cables))


def path_distance(result, other, after: float = 0.0) -> float:
    """Largest distance [m] of ``result``'s platform centre from ``other``'s from ``after`` [s] on.

    Both runs sample at the output times, or up to a step after them where a step was
    shrunk: ``other``'s path is interpolated onto ``result``'s sample times.
    """
    mask = result.time >= after - 1e-9
    positions, other_positions = result.position, other.position
    path = np.column_stack([np.interp(result.time[mask], other.time, other_positions[:, k])
                            for k in range(other_positions.shape[1])])
    return float(np.linalg.norm(positions[mask] - path, axis=1).max())


def _not_applicable(note: str) -> ErrorEstimate:
    return ErrorEstimate(None, None, ORDER, AFTER, note)


def estimate_error(scene, result, controller_factory: Callable | None = None, after: float = AFTER) -> ErrorEstimate:
    """Estimate the discretisation error of ``result`` (a run of ``scene``) by Richardson.

    Parameters
    ----------
    scene : Scene
    result : Result
        The run to judge (completed).
    controller_factory : callable, optional
        Makes a fresh controller of the same kind as the run's (default: ideal IK).
    after : float [s]
        Compare the paths from this time on.
    """
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
    """The strict-JSON entries of ``summary.json`` for an estimate: ``error_estimate`` and, when a
    companion run was made, its wall and CPU times (which :func:`cdpr_exu.core.output.write_summary` puts
    into ``timing.json``)."""
    timing = ("companion_wall_time_s", "companion_cpu_time_s")
    data = {"error_estimate": {k: v for k, v in estimate.to_dict().items() if k not in timing}}
    if estimate.companion_n_elements is not None:
        data.update({k: getattr(estimate, k) for k in timing})
    return data


def elements_for_tolerance(n: int, estimated_error: float, tolerance: float, order: float = ORDER) -> int:
    """Fewest elements per cable, never fewer than ``n``, whose error by e(n) = C n^-p through (n, estimated_error)
    is below ``tolerance``.

    Never fewer than the scene's ``n``: the model is fitted on n and the companion run's 2n
    (Richardson), and below n it would be extrapolated out of the measured range, where coarser
    cables meet other limits the model knows nothing of (elements too long for the pulley are
    refused, swivel pulleys need elements of at most half their radius, and the error's order
    in motion is not 2: docs/accuracy.md). A tolerance met already keeps ``n``.
    """
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
