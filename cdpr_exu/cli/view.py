"""``cdpr view`` and ``cdpr animate``: replay a run folder (:mod:`cdpr_exu.post.viewer`)."""

from __future__ import annotations

import argparse
import sys

from cdpr_exu.core.errors import EXIT_CODES
from cdpr_exu.post.viewer import (DEFAULT_FPS, DEFAULT_SIZE, NoDisplayError, parse_size, render_animation,
                                   view_solution)

EPILOG_VIEW = """examples:
  cdpr run paper-circle --out results/paper_circle
  cdpr view results/paper_circle
  cdpr view results/paper_circle --every 10
Needs a display; without one, use `cdpr animate`.
"""

EPILOG_ANIMATE = """examples:
  cdpr animate results/paper_circle                    # results/paper_circle/animation.gif
  cdpr animate results/paper_circle --out circle.mp4   # needs: pip install imageio-ffmpeg
  cdpr animate results/paper_circle --fps 20 --every 10 --size 480x360 --frames-dir frames/
"""


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text!r}")
    return value


def _size_argument(text: str) -> tuple[int, int]:
    try:
        return parse_size(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def _cmd_view(args: argparse.Namespace) -> int:
    try:
        view_solution(args.run_dir, every=args.every)
    except NoDisplayError as err:
        print(f"cdpr view: {err}", file=sys.stderr)
        return 1
    return 0


def _cmd_animate(args: argparse.Namespace) -> int:
    out, frames, seconds = render_animation(args.run_dir, args.out, fps=args.fps, every=args.every,
                                            size=args.size, frames_dir=args.frames_dir,
                                            progress=not args.quiet)
    if not args.quiet:
        print(f"wrote {out}: {frames} frames of {args.size[0]}x{args.size[1]} at {args.fps:g} frames/s "
              f"({seconds:.3f} s per frame)")
    return 0


def add_commands(subparsers) -> None:
    """Add ``view`` and ``animate`` to the ``cdpr`` command."""
    view = subparsers.add_parser(
        "view", help="replay a run in Exudyn's interactive SolutionViewer (needs a display)",
        description="Replay a run folder (written by `cdpr run SCENE --out DIR`) in Exudyn's interactive "
        "SolutionViewer, with pulleys, platform and reference path drawn. Exits with code 1 when no "
        "window can be opened here.", epilog=EPILOG_VIEW + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    view.add_argument("run_dir", help="run folder with scene.toml and solution.sol")
    view.add_argument("--every", type=_positive_int, help="show every K-th stored row (default: about real time)")
    view.set_defaults(func=_cmd_view)

    animate = subparsers.add_parser(
        "animate", help="render a run to a GIF or MP4 without a display",
        description="Render a run folder (written by `cdpr run SCENE --out DIR`) with Exudyn's software "
        "raytracer, no display needed, into a GIF (or an MP4 with imageio-ffmpeg installed); a spatial run "
        "folder is drawn with matplotlib's 3-D axes. The options are checked before any rendering.",
        epilog=EPILOG_ANIMATE + "\n" + EXIT_CODES, formatter_class=argparse.RawDescriptionHelpFormatter)
    animate.add_argument("run_dir", help="run folder with scene.toml and solution.sol")
    animate.add_argument("--out", help="animation file, .gif or .mp4 (default: RUN_DIR/animation.gif)")
    animate.add_argument("--fps", type=float, default=DEFAULT_FPS, help="frames per second (default: 25)")
    animate.add_argument("--every", type=_positive_int,
                         help="use every K-th stored row (default: real-time playback at --fps)")
    animate.add_argument("--size", type=_size_argument, default=DEFAULT_SIZE, metavar="WxH",
                         help="image size in pixels (default: 640x480)")
    animate.add_argument("--frames-dir", help="also write each frame as a PNG into this folder")
    animate.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no message")
    animate.set_defaults(func=_cmd_animate)
