"""Dense against sparse cable Jacobians on the paper circle, over the number of elements.

For n = 15, 30, 60, 120 and 240 elements per cable, runs the paper circle (full model,
step 2e-3 s) with the cables' Jacobian handed to Exudyn as a dense (2N)^2 matrix and as
sparse triplets, after a warm-up (numba kernels loaded), and prints the CPU time per
Newton iteration of each, their ratio, the largest path difference (round-off only), and
the exponent of the cost per iteration in n from 30 to 240 elements. All ratios come from
one run on one machine. Writes ``benchmarks/results/sparse_jacobian.md``.

Run: ``python benchmarks/bench_sparse_jacobian.py [--end-time 1]``
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.run.simulate import simulate

ELEMENTS = (15, 30, 60, 120, 240)


def _run(scene, sparse: bool):
    """(result, CPU seconds) of one run with the dense or the sparse Jacobian."""
    start = time.process_time()
    result = simulate(scene, sparse_jacobian=sparse)
    return result, time.process_time() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--end-time", type=float, default=1.0, help="simulated time per run [s] (default 1)")
    parser.add_argument("--out", default="benchmarks/results/sparse_jacobian.md")
    args = parser.parse_args()
    paper = load_scene("paper-circle")
    warm = paper.with_changes(solver=replace(paper.solver, end_time=0.05))
    _run(warm, True), _run(warm, False)
    rows = []
    for n in ELEMENTS:
        scene = paper.with_changes(cables=tuple(replace(c, n_elements=n) for c in paper.cables),
                                   solver=replace(paper.solver, end_time=args.end_time))
        sparse, sparse_cpu = _run(scene, True)
        dense, dense_cpu = _run(scene, False)
        difference = float(np.abs(sparse.pose - dense.pose).max())
        per_sparse = sparse_cpu / max(sparse.newton_iterations, 1)
        per_dense = dense_cpu / max(dense.newton_iterations, 1)
        rows.append((n, per_dense, per_sparse, dense.newton_iterations / max(dense.steps, 1), difference))
        print(f"n = {n:3d}: {1e6 * per_dense:8.1f} us (dense) {1e6 * per_sparse:8.1f} us (sparse) per Newton "
              f"iteration, ratio {per_dense / per_sparse:5.2f}, path difference {difference:.1e} m", flush=True)
    fit = [(n, d, s) for n, d, s, _, _ in rows if n >= 30]
    logs = np.log([n for n, _, _ in fit])
    dense_exponent = np.polyfit(logs, np.log([d for _, d, _ in fit]), 1)[0]
    sparse_exponent = np.polyfit(logs, np.log([s for _, _, s in fit]), 1)[0]
    lines = [f"# Dense against sparse cable Jacobians (paper circle, full model, step 2e-3 s, {args.end_time} s)",
             "", "CPU time per Newton iteration, one run each after a warm-up, same machine and run.", "",
             "| elements per cable | dense [us] | sparse [us] | dense / sparse | Newton iterations per step | "
             "path difference [m] |", "|---|---|---|---|---|---|"]
    for n, per_dense, per_sparse, iterations, difference in rows:
        lines.append(f"| {n} | {1e6 * per_dense:.1f} | {1e6 * per_sparse:.1f} | {per_dense / per_sparse:.2f} | "
                     f"{iterations:.1f} | {difference:.1e} |")
    lines += ["", f"Cost per Newton iteration from 30 to 240 elements grows as n^{dense_exponent:.2f} (dense) and "
              f"n^{sparse_exponent:.2f} (sparse)."]
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text("\n".join(lines) + "\n")
    print("\n".join(lines[-1:]))


if __name__ == "__main__":
    main()
