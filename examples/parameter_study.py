"""Parameter study: the paper's circle over cable discretisation and platform mass.

Runs the paper's scenario 1 (``paper-circle``: 10 s on the circle under ideal
inverse-kinematics control) for every combination of

- ``cables.n_elements`` in (5, 10, 15): elements per cable (both cables),
- ``platform.mass`` in (1, 2.5, 5) kg,

on all cores (one single-threaded process per core), and writes
``results/parameter_study/``: ``study.csv``, ``study.json``, ``base_scene.toml``,
``vs_cables_n_elements.png``, ``vs_platform_mass.png`` and ``heatmap.png``.
Errors are measured after the first second (the start-up transient).

With 5 elements an element is 0.75 m long, and the paper's circle needs more than
3.75 - 0.75 m of cable between pulley and platform: the model cannot keep one
element on the winch side, so those runs are recorded as refused, not run.

The same study from the command line::

    cdpr study sweep paper-circle --param cables.n_elements=5,10,15 \\
        --param platform.mass=1,2.5,5 --out results/parameter_study

Run::

    python examples/parameter_study.py                # the full 10 s runs
    python examples/parameter_study.py --end-time 2   # a quick look
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.studies.study import format_table, parse_parameter, run_study

OUT = Path(__file__).resolve().parents[1] / "results" / "parameter_study"

PARAMETERS = ["cables.n_elements=5,10,15", "platform.mass=1,2.5,5"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--end-time", type=float, help="shorten the runs [s] (default: the scene's 10 s)")
    parser.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    parser.add_argument("--out", type=Path, default=OUT, help=f"output folder (default {OUT})")
    args = parser.parse_args()

    scene = load_scene("paper-circle")
    if args.end_time is not None:
        scene = scene.with_changes(solver=replace(scene.solver, end_time=args.end_time))
    variations = [parse_parameter(p) for p in PARAMETERS]
    rows = run_study(scene, variations, out=args.out, workers=args.workers, after=1.0)
    print(format_table(rows, variations))
    print(f"written to {args.out}/")


if __name__ == "__main__":  # required: the worker processes are spawned and re-import this file
    main()
