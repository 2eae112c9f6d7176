"""Pulley contact candidates for speed at fine discretisation (issue 14, item 2), measured side by side.

On the paper circle (full model) at 60 elements per cable and a 1e-2 s step, the
fastest setting that met the 1 mm accuracy before this study, it runs:

- ``node``: the default, the law of Exudyn's sphere contact item computed in the cables' numba
  object with its contact state frozen while Newton converges and switched in a PostNewton
  function (discontinuous iterations), as Exudyn's items do (:mod:`cdpr_exu.physics.node_contact`);
- the same with Exudyn's discontinuous settings loosened
  (``timeIntegration.discontinuous.maxIterations`` 1 and 2);
- ``node_smooth``: the same penalty law in the cables' numba object, switched on
  smoothly over a penetration band b (:mod:`cdpr_exu.physics.node_contact`), for b = 0 (sharp),
  1e-5 m (the shipped band), 1e-4 m and 1e-3 m.

It prints x real time (CPU time of the single-threaded run), Newton iterations, Jacobian
updates and discontinuous iterations per step, and how far each path moves from the
default's (largest platform position difference over the run, at the same times: the default's path
interpolated at each run's sample times, which follow its steps). All from one run on one
machine: compare ratios.

Run: ``python benchmarks/bench_contact_models.py [--end-time 10]``; writes
``benchmarks/results/contact_models.md``.
"""

from __future__ import annotations

import argparse
import contextlib
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

import cdpr_exu.builder.model
import cdpr_exu.physics.node_contact
import cdpr_exu.run.simulate
from cdpr_exu.scenes.scene import load_scene


@contextlib.contextmanager
def discontinuous_iterations(limit):
    """Run with Exudyn's ``discontinuous.maxIterations`` set to ``limit`` (None: unchanged)."""
    original = cdpr_exu.run.simulate.solver_settings

    def settings(*args, **kwargs):
        result = original(*args, **kwargs)
        if limit is not None:
            result.timeIntegration.discontinuous.maxIterations = limit
        return result
    cdpr_exu.run.simulate.solver_settings = settings
    try:
        yield
    finally:
        cdpr_exu.run.simulate.solver_settings = original


@contextlib.contextmanager
def onset_band(band):
    """Build ``node_smooth`` contacts with onset band ``band`` [m] (None: the shipped one)."""
    original = cdpr_exu.physics.node_contact.CONTACT_ONSET_DEPTH
    cdpr_exu.physics.node_contact.CONTACT_ONSET_DEPTH = original if band is None else band
    try:
        yield
    finally:
        cdpr_exu.physics.node_contact.CONTACT_ONSET_DEPTH = original


def run(scene):
    """One run: (result, Exudyn's iteration statistics, CPU time [s])."""
    captured = {}
    build = cdpr_exu.run.simulate.build_model

    def capture(*args, **kwargs):
        captured["model"] = build(*args, **kwargs)
        return captured["model"]
    cdpr_exu.run.simulate.build_model = capture
    cpu = time.process_time()
    try:
        result = cdpr_exu.run.simulate.simulate(scene)
    finally:
        cdpr_exu.run.simulate.build_model = build
    return result, captured["model"].mbs.sys["dynamicSolver"].it, time.process_time() - cpu


CANDIDATES = (
    ("node (default: frozen in Newton)", "node", None, None),
    ("node, discontinuous.maxIterations = 2", "node", 2, None),
    ("node, discontinuous.maxIterations = 1", "node", 1, None),
    ("node_smooth, b = 0 (sharp)", "node_smooth", None, 0.0),
    ("node_smooth, b = 1e-5 m (shipped)", "node_smooth", None, None),
    ("node_smooth, b = 1e-4 m", "node_smooth", None, 1e-4),
    ("node_smooth, b = 1e-3 m", "node_smooth", None, 1e-3),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=10.0, help="simulated time per run [s] (default 10)")
    parser.add_argument("--elements", type=int, default=60, help="elements per cable (default 60)")
    parser.add_argument("--step", type=float, default=1e-2, help="time step [s] (default 1e-2)")
    parser.add_argument("--out", default="benchmarks/results/contact_models.md")
    args = parser.parse_args()
    paper = load_scene("paper-circle")
    base = paper.with_changes(cables=tuple(replace(c, n_elements=args.elements) for c in paper.cables),
                              solver=replace(paper.solver, end_time=args.end_time, step_size=args.step))
    for model in ("node", "node_smooth"):  # warm-up: numba, imports
        run(paper.with_changes(effects=replace(paper.effects, pulley_contact_model=model),
                               solver=replace(paper.solver, end_time=0.05)))
    rows, reference = [], None
    for label, model, limit, band in CANDIDATES:
        scene = base.with_changes(effects=replace(base.effects, pulley_contact_model=model))
        with discontinuous_iterations(limit), onset_band(band):
            result, it, cpu = run(scene)
        # Samples fall at the first step end past each output time, so runs with other steps sample at other
        # times (up to a step apart: 6 mm at 0.6 m/s and 1e-2 s): the default's path is read at this run's times.
        reference = reference or (result.time, result.pose[:, :2])
        at = np.column_stack([np.interp(result.time, reference[0], column) for column in reference[1].T])
        moved = float(np.linalg.norm(result.pose[:, :2] - at, axis=1).max())
        steps = max(int(it.currentStepIndex), 1)
        row = (label, result.simulated_time / cpu, it.newtonStepsCount / steps,
               it.newtonJacobiCount / steps, it.discontinuousIterationsCount / steps, steps, 1000 * moved)
        rows.append(row)
        print("{}: {:.2f}x real time, {:.2f} Newton iterations, {:.2f} Jacobians, {:.2f} discontinuous "
              "iterations per step, {} steps, path moved {:.3f} mm".format(*row), flush=True)
    lines = [f"# Pulley contact candidates (paper circle, full model, {args.elements} elements per cable, "
             f"step {args.step:g} s, {args.end_time:g} s, one run each)", "",
             "Path moved: largest platform position difference from the default (the contact frozen in Newton), at the "
             "same times (the default's path interpolated at each run's sample times). "
             "CPU time of one single-threaded run (the wall time of a shared machine varies with its load): compare ratios.", "",
             "| contact | x real time | Newton iterations / step | Jacobians / step | discontinuous iterations / step "
             "| steps taken | path moved [mm] |", "|---|---|---|---|---|---|---|"]
    lines += ["| {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {} | {:.3f} |".format(*row) for row in rows]
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
