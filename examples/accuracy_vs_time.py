"""What accuracy costs in time: the model ladder over elements and step sizes.

Runs the accuracy study (:mod:`cdpr_exu.studies.accuracy`) on the paper's circle and on its
static catenary scene: every preset (ideal, elastic, catenary, full) and the full
model with linear bending, over 8..60 elements per cable and steps of 5e-4..1e-2 s,
each run compared with the reference (full, 90 elements, 5e-4 s). Writes, for each
scene, ``accuracy.csv``, ``accuracy.json``, ``tables.md`` (the cheapest configuration
per tolerance, each model's cost, what each effect changes), ``pareto.png`` and the
reference's series into ``results/accuracy/<scene>/``.

Run: ``python examples/accuracy_vs_time.py [--quick] [--out results/accuracy]``;
about 12 minutes on two cores (``--quick``: under a minute). The same from the command line:
``cdpr study accuracy paper-circle --out results/accuracy/paper_circle``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from cdpr_exu.studies.accuracy import COST, FULL_GRID, QUICK_GRID, TOLERANCES, cheapest_meeting, run_accuracy_study

SCENES = {"paper-circle": "paper_circle", "paper-catenary": "paper_catenary"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).resolve().parent.parent / "results" / "accuracy"))
    parser.add_argument("--quick", action="store_true", help="the small grid over 1.5 s")
    parser.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    args = parser.parse_args()
    grid = QUICK_GRID if args.quick else FULL_GRID
    start = time.perf_counter()
    for scene, folder in SCENES.items():
        study = run_accuracy_study(scene, grid, out=Path(args.out) / folder, workers=args.workers)
        reference = study.reference_row
        done = sum(r["status"] == "completed" for r in study.rows)
        print(f"\n{scene}: {len(study.rows)} runs ({done} completed), reference {study.reference.label} "
              f"({reference[COST]:.0f} s CPU); comparison: {study.comparison}")
        for tolerance in TOLERANCES:
            best = cheapest_meeting(study.rows, tolerance)
            if best is None:
                print(f"  {1000 * tolerance:4g} mm: no configuration")
            else:
                print(f"  {1000 * tolerance:4g} mm: {best['model']}, n = {best['n_elements'] or '-'}, "
                      f"h = {best['step_size_s']:g} s: {best[COST]:.2f} s CPU "
                      f"({best['real_time_factor']:.1f} x real time), error {1000 * best['position_error_max_m']:.2f} mm")
        print(f"  written to {Path(args.out) / folder}/ (tables.md, pareto.png, accuracy.csv)")
    print(f"\nall done in {(time.perf_counter() - start) / 60:.1f} min")


if __name__ == "__main__":  # the process pool spawns workers that import this file
    main()
