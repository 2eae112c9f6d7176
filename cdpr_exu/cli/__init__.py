"""The ``cdpr`` command line: one module per command (run, scenes, compare, study, view, static, import).

The commands parse their options, call the library and print what the user sees; the
library returns data and prints nothing. ``main`` is the console script's entry point.
"""

from cdpr_exu.cli.main import build_parser, main
from cdpr_exu.cli.run import run_scene

__all__ = ["build_parser", "main", "run_scene"]
