"""The ``cdpr`` command line, one module per command (run, scenes, compare, study, view, static, workspace,
import): they parse options, call the library (which returns data and prints nothing) and print what the
user sees; ``main`` is the console script."""

from cdpr_exu.cli.main import build_parser, main
from cdpr_exu.cli.run import run_scene

__all__ = ["build_parser", "main", "run_scene"]
