"""Run a short paper circle, then replay it: Exudyn's SolutionViewer, or a GIF without a display.

Run:  python examples/solution_viewer_export.py [--out results/solution_viewer] [--end-time 3]

Writes the run folder (scene.toml, Exudyn's solution.sol, result.npz, summary) as
``cdpr run paper-circle --out DIR`` does, prints the command that replays it in
Exudyn's interactive viewer (it needs a display), and renders ``animation.gif`` with
Exudyn's software raytracer, which needs none. The same from the shell::

    cdpr run paper-circle --out results/solution_viewer --end-time 3
    cdpr view results/solution_viewer
    cdpr animate results/solution_viewer --out results/solution_viewer/animation.gif
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

from cdpr_exu.cli import run_scene
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.post.viewer import NoDisplayError, display_problem, render_animation, view_solution


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/solution_viewer", help="run folder to write")
    parser.add_argument("--end-time", type=float, default=3.0, help="simulated time [s]")
    parser.add_argument("--view", action="store_true", help="also open the SolutionViewer here (needs a display)")
    args = parser.parse_args()
    out = Path(args.out)

    scene = load_scene("paper-circle")
    scene = scene.with_changes(solver=replace(scene.solver, end_time=args.end_time))
    run_scene(scene, out, figures=False)  # writes solution.sol next to the result

    print(f"\nReplay it interactively (needs a display):  cdpr view {out}")
    start = time.perf_counter()
    gif, _, _ = render_animation(out, out / "animation.gif", fps=25, size=(640, 480), progress=True)
    print(f"Animation without a display: {gif} ({time.perf_counter() - start:.1f} s)")

    if args.view:
        problem = display_problem()
        if problem is not None:
            print(f"Not opening the viewer: {problem}")
            return
        try:
            view_solution(out)
        except NoDisplayError as err:
            print(err)


if __name__ == "__main__":
    main()
