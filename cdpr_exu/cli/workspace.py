"""``cdpr workspace``: the positions the cables hold within their tension limits, massless and catenary
(:mod:`cdpr_exu.studies.workspace_grid`).

Examples::

    cdpr workspace paper-circle --grid x=-1.5:1.5:13 --grid z=-3.5:-0.5:13 --min-tension 1 --max-tension 40 --out out/ws
"""

from __future__ import annotations

import argparse
import time

from cdpr_exu.core.errors import EXIT_CODES, EXIT_OK, SceneError
from cdpr_exu.core.output import check_output_folder
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.statics.feasibility import STATUSES, tension_bounds
from cdpr_exu.studies.workspace_grid import make_grid, run_workspace, summarise, summary_markdown

EPILOG = """examples:
  cdpr workspace paper-circle --grid x=-1.5:1.5:13 --grid z=-3.5:-0.5:13 --min-tension 1 --max-tension 40 --out out/ws
  cdpr workspace spatial-cogiro --grid x=-7:7:15 --grid y=-5:5:11 --grid z=0.5:4.5:9 \\
      --min-tension 100 --max-tension 5000 --out out/cogiro
  cdpr workspace spatial-cogiro --grid x=-7:7:29 --grid z=0:5:21 --orientation 0,0,0 --orientation 0,0,0.2 \\
      --min-tension 100 --max-tension 5000 --out out/cogiro_yaw --scheduler local

--grid LABEL=START:STOP:COUNT (or LABEL=VALUE): an axis of the platform's position [m] (x, z planar; x, y, z
spatial); an axis not given stays at the scene's initial pose (spatial: the reference's start). Each
--orientation (the angle [rad] planar, the rotation vector [rad] spatial; default the initial one) must
hold. The tension limits are the scene's cables' min_tension and max_tension, or --min-tension and
--max-tension for every cable.

writes workspace.csv (per position and orientation: each model's status, per cable the tensions, lengths
and sags; empty cells where a model does not hold), summary.json and summary.md (the volume each model
holds, the share of the massless workspace the catenary model keeps), slices.png, view3d.png (three
varied axes), scene.toml, grid.json and points.jsonl; started again into the same --out, a grid resumes.
statuses: """ + "; ".join(f"{k}: {v}" for k, v in STATUSES.items()) + "\n"


def _orientation(text: str) -> list:
    try:
        return [float(v) for v in text.split(",")]
    except ValueError:
        raise SceneError(f"orientation {text!r} must be numbers separated by commas [rad]") from None


def _cmd_workspace(args: argparse.Namespace) -> int:
    scene = load_scene(args.scene)
    limits = tension_bounds(scene, args.min_tension, args.max_tension)
    grid = make_grid(scene, args.grid, [_orientation(text) for text in args.orientation or ()])
    out = check_output_folder(args.out, command="workspace")  # after every check: nothing written on bad input
    start = time.perf_counter()
    rows = run_workspace(scene, grid, limits, out, workers=args.workers, scheduler=args.scheduler,
                         progress=not args.quiet)
    if not args.quiet:
        print(summary_markdown(scene.name, summarise(rows, grid), limits.tolist()))
        print(f"{len(rows)} positions and orientations in {time.perf_counter() - start:.0f} s"
              + (f"; written to {out}/" if out is not None else ""))
    return EXIT_OK


def add_commands(subparsers) -> None:
    """Register ``cdpr workspace``."""
    parser = subparsers.add_parser(
        "workspace", help="where the cables hold the platform within their tension limits, massless and catenary",
        description="Check a grid of platform positions: can straight massless cables, and elastic catenaries "
        "with the cables' weight, hold the platform there with every tension within [t_min, t_max]? In parallel, "
        "resumable.", epilog=EPILOG + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", help="shipped scene name (see `cdpr scenes`) or path to a .toml file")
    parser.add_argument("--grid", action="append", required=True, metavar="LABEL=START:STOP:COUNT",
                        help="an axis of the grid; repeat for more axes")
    parser.add_argument("--orientation", action="append", metavar="ROTATION",
                        help="an orientation that must hold (comma-separated [rad]); repeat for more")
    parser.add_argument("--min-tension", type=float, help="t_min of every cable [N] (default: the scene's)")
    parser.add_argument("--max-tension", type=float, help="t_max of every cable [N] (default: the scene's)")
    parser.add_argument("--out", help="output folder (created; resumed when it holds this grid's rows)")
    parser.add_argument("--workers", type=int, help="worker processes (default: one per core)")
    parser.add_argument("--scheduler", metavar="ADDRESS|local",
                        help="run on a Dask cluster: its scheduler's address (tcp://host:8786), or 'local'")
    parser.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    parser.set_defaults(func=_cmd_workspace)
