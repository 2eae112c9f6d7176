"""The workspace that sagging cables leave: the CoGiRo-class robot, massless against catenary cables (issue 26.3).

``spatial-cogiro`` (8 steel cables of 0.14 kg/m, EA = 2.83 MN, on a 91 kg platform under a 15 x 11 x 5.4 m
frame) within CASPR's tension limits for CoGiRo (100-5000 N, :mod:`cdpr_exu.physics.cogiro`), at the
scene's initial orientation (unrotated), on a grid of 0.5 m over the frame (x -7..7 m, y -5..5 m,
z 0.5..5 m, the exits at 5.4 m: 6090 positions): where straight massless cables hold the platform, where elastic catenaries
with the cables' weight do (:mod:`cdpr_exu.statics.feasibility`), with the scene's cables and with cables
4 times heavier. Writes ``results/workspace/steel/`` and ``results/workspace/heavy_4x/`` (the files of
``cdpr workspace``: workspace.csv, summary.json, summary.md, slices.png, view3d.png, scene.toml, grid.json)
and ``results/workspace/summary.md`` (the two cases side by side).

The same from the command line (one case)::

    cdpr workspace spatial-cogiro --grid x=-7:7:29 --grid y=-5:5:21 --grid z=0.5:5:10 \\
        --min-tension 100 --max-tension 5000 --out results/workspace/steel

Run (about 4 min of CPU time, 2 processes; an interrupted run resumes, ``--fresh`` starts over)::

    python examples/workspace_study.py [--workers N] [--fresh]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

from cdpr_exu.physics import cogiro
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.statics.feasibility import tension_bounds
from cdpr_exu.studies.workspace_grid import WORKSPACE_FILES, make_grid, run_workspace, summarise

OUT = Path(__file__).resolve().parents[1] / "results" / "workspace"
GRID = ["x=-7:7:29", "y=-5:5:21", "z=0.5:5:10"]
#: Each case's folder and the factor on the cables' linear density.
CASES = {"steel": 1.0, "heavy_4x": 4.0}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    parser.add_argument("--fresh", action="store_true", help="start over (forget the rows already checked)")
    args = parser.parse_args()
    scene = load_scene("spatial-cogiro")
    limits = tension_bounds(scene, cogiro.MIN_TENSION, cogiro.MAX_TENSION)
    lines = ["# The workspace that sagging cables leave: spatial-cogiro", "",
             f"Grid {' '.join(GRID)} (0.5 m, 0.125 m^3 per position), unrotated, tensions within "
             f"[{cogiro.MIN_TENSION:g}, {cogiro.MAX_TENSION:g}] N (python examples/workspace_study.py).", "",
             "| cables | linear density [kg/m] | massless [m^3] | catenary [m^3] | catenary keeps | lost to sag |",
             "|---|---|---|---|---|---|"]
    for name, factor in CASES.items():
        case = replace(scene, cables=tuple(replace(c, linear_density=factor * c.linear_density) for c in scene.cables))
        if args.fresh:
            (OUT / name / WORKSPACE_FILES["rows"]).unlink(missing_ok=True)
        grid = make_grid(case, GRID)
        start = time.perf_counter()
        summary = summarise(run_workspace(case, grid, limits, OUT / name, workers=args.workers), grid)
        print(f"{name}: {time.perf_counter() - start:.0f} s")
        volume = summary["held_volume"]
        lines.append(f"| {name} | {case.cables[0].linear_density:g} | {volume['massless']:.2f} | "
                     f"{volume['catenary']:.2f} | {100 * summary['catenary_keeps']:.1f} % | "
                     f"{100 * summary['lost_to_sag']:.1f} % |")
    (OUT / "summary.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":  # required: the worker processes are spawned and re-import this file
    main()
