"""The ``cdpr`` command: its parser and entry point; each command lives in a module of this package.

Examples::

    cdpr run paper-circle --out results/paper_circle
    cdpr run my_robot.toml --out out/my_robot --end-time 5 --step-size 1e-3
    cdpr scenes
"""

from __future__ import annotations

import argparse
import sys
import warnings

from cdpr_exu.cli import compare, import_caspr, run, scenes, static, study, view, workspace
from cdpr_exu.core.errors import (EXIT_BAD_INPUT, EXIT_CODES, EXIT_INTERRUPTED, EXIT_RUN_FAILED, CdprError,
                                  CdprWarning, RunInterrupted, SolverFailure)

#: The command modules, in the order ``cdpr --help`` lists their commands: each has
#: ``add_commands(subparsers)``, which adds parsers whose ``func`` takes the parsed arguments
#: and returns an exit code.
COMMAND_MODULES = (run, scenes, compare, study, view, static, workspace, import_caspr)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``cdpr`` (every sub-command's ``--help`` has examples)."""
    parser = argparse.ArgumentParser(
        prog="cdpr", description="Simulate cable-driven parallel robots with massive, elastic, bending cables "
        "over pulleys (Exudyn, implicit solver). Units: SI.",
        epilog="examples:\n  cdpr run paper-circle --out results/paper_circle\n  cdpr scenes\n\n" + EXIT_CODES,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)
    for module in COMMAND_MODULES:
        module.add_commands(sub)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None):  # noqa: ARG001
    """Print the project's warnings as one line each, without source locations."""
    print(f"cdpr: warning: {message}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``cdpr`` console script; returns the exit code (see ``cdpr --help``)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    shown = warnings.showwarning
    warnings.showwarning = _show_warning
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always", CdprWarning)
            return args.func(args)
    except RunInterrupted as err:
        print(f"cdpr: {err}; the partial result is written", file=sys.stderr)
        return EXIT_INTERRUPTED
    except KeyboardInterrupt:
        print("cdpr: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except SolverFailure as err:
        print(f"cdpr: solver failure: {err}", file=sys.stderr)
        return EXIT_RUN_FAILED
    except CdprError as err:
        print(f"cdpr: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    finally:
        warnings.showwarning = shown

