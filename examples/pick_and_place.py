"""Pick and place on the CoGiRo-class robot along a path read from a CSV file.

Run:  python examples/pick_and_place.py [--out results/pick-and-place]

Loads examples/pick_and_place/scene.toml (spatial-cogiro's robot with CASPR's tension limits,
its ``[trajectory]`` of kind "file" reading path.csv beside it: lift, move and lower) and runs
it under ideal inverse kinematics as ``cdpr run`` does: the output folder holds the usual run
files (scene.toml with the path's waypoints, result.npz, pose.csv, summary.json, solution.sol)
and overview.png, whose top row draws the platform's path against the reference from above
and from the side. About 10 s of simulated time, well under a minute.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from cdpr_exu.cli import run_scene
from cdpr_exu.scenes.scene import load_scene

SCENE = Path(__file__).parent / "pick_and_place" / "scene.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/pick-and-place")
    run_scene(load_scene(SCENE), Path(parser.parse_args().out))


if __name__ == "__main__":
    main()
