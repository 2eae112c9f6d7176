"""``cdpr scenes``: list the shipped scenes."""

from __future__ import annotations

import argparse

from cdpr_exu.core.errors import EXIT_CODES
from cdpr_exu.scenes.scene import load_scene, shipped_scenes


def _cmd_scenes(args: argparse.Namespace) -> int:  # noqa: ARG001

    for name in shipped_scenes():  # planar and spatial
        print(f"{name:24s} {load_scene(name).description}")
    return 0


def add_commands(subparsers) -> None:
    """Register ``cdpr scenes``."""
    scenes = subparsers.add_parser("scenes", help="list the shipped scenes",
                                   epilog="example:\n  cdpr scenes\n\n" + EXIT_CODES,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    scenes.set_defaults(func=_cmd_scenes)
