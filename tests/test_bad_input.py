"""Bad input and what the user gets: the cases of docs/bad_input.md, through the real command line (issue 23.19).

Each case is a scene file (a shipped scene's TOML with fields changed or removed, or raw
bytes) or a command line, the words the user must read and the exit code. Each runs through
``cdpr_exu.cli.main`` in a fresh folder (examples/bad_input_table.py ``run_case``); that script
writes docs/bad_input.md from these same cases, and the last test checks the committed file
is what it writes.
"""

from __future__ import annotations

import importlib.util
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _table_script():
    """examples/bad_input_table.py, imported from its path (examples/ is no package)."""
    if "bad_input_table" in sys.modules:
        return sys.modules["bad_input_table"]
    spec = importlib.util.spec_from_file_location("bad_input_table", ROOT / "examples" / "bad_input_table.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


TABLE = _table_script()
DELETE = TABLE.DELETE


@dataclass(frozen=True)
class Case:
    """One kind of bad input.

    Attributes
    ----------
    bad_input : str
        What the user did, in the table's words.
    command : tuple of str
        The ``cdpr`` command line (``scene.toml`` is the case's scene file).
    expected : str
        Words the line the user reads must contain.
    exit_code : int
    scene : str or None
        Shipped scene whose TOML is written as ``scene.toml``, with ``changes`` applied.
    changes : tuple of (path, value)
        Key paths into that TOML and their new values (``DELETE``: removed).
    content : bytes or None
        The scene file's bytes instead.
    """

    bad_input: str
    command: tuple
    expected: str
    exit_code: int = 2
    scene: str | None = None
    changes: tuple = ()
    content: bytes | None = None


RUN = ("run", "scene.toml")
CASES = [
    # scene fields
    Case("a negative or zero number", RUN, "platform.mass must be positive [kg], got -2.5",
         scene="paper-circle", changes=((("platform", "mass"), -2.5),)),
    Case("text where a number belongs", RUN, "cables[0].radius must be a real number [m], got '0.005'",
         scene="paper-circle", changes=((("cable", "radius"), "0.005"),)),
    Case("`true` / `false` where a number belongs", RUN, "solver.step_size must be a real number [s], got True",
         scene="paper-circle", changes=((("solver", "step_size"), True),)),
    Case("a vector of the wrong length", RUN, "platform.initial_pose must have 3 entries [m, m, rad], got 2",
         scene="paper-circle", changes=((("platform", "initial_pose"), [0.0, -2.0]),)),
    Case("a misspelt field", RUN, "solver has unknown field(s) ['stepsize']",
         scene="paper-circle", changes=((("solver", "stepsize"), 1e-3),)),
    Case("a required field left out (planar)", RUN, "scene 'scene.toml' lacks platform.mass [kg]",
         scene="paper-circle", changes=((("platform", "mass"), DELETE),)),
    Case("a required field left out (spatial)", RUN, "lacks cables[1].unstrained_length [m]",
         scene="spatial-four-cable", changes=((("cables", 1, "unstrained_length"), DELETE),)),
    Case("an empty scene file", RUN, "lacks pulleys, platform, trajectory", content=b""),
    Case("an unknown trajectory kind", RUN,
         "trajectory.kind must be one of ['circle', 'file', 'hold', 'point_to_point', 'waypoints']",
         scene="paper-circle", changes=((("trajectory", "kind"), "spiral"),)),
    Case("a bad trajectory value", RUN, "trajectory.radius must be >= 0 [m], got -1.0",
         scene="paper-circle", changes=((("trajectory", "radius"), -1.0),)),
    Case("contradictory choices", RUN, "solver.integrator = 'rk44' needs winch.kind = 'fixed'",
         scene="paper-circle", changes=((("solver", "integrator"), "rk44"),)),
    Case("elements too long for the pulley", RUN, "cables[0].n_elements = 8 is too coarse",
         scene="paper-circle", changes=((("cable", "n_elements"), 8),)),
    # poses the cables cannot reach or hold
    Case("a platform started above its pulleys", RUN, "platform.initial_pose [0.0, 0.5, 0.0] (x [m], z [m], "
         "rotation [rad]) is above the pulleys", scene="paper-circle",
         changes=((("platform", "initial_pose"), [0.0, 0.5, 0.0]),)),
    Case("a cable too short for the initial pose", RUN, "cables[0].unstrained_length = 1.0 m is shorter than",
         scene="paper-circle", changes=((("cable", "unstrained_length"), 1.0),)),
    Case("a reference above the pulleys", RUN, "is outside the workspace", scene="paper-circle",
         changes=((("trajectory",), {"kind": "point_to_point", "start": [0.0, -2.0, 0.0], "end": [0.0, 1.0, 0.0],
                                      "duration": 2.0}),)),
    Case("a reference the tension limits cannot hold", RUN, "within the cables' tension limits",
         scene="paper-circle", changes=((("cable", "max_tension"), 15.0),)),
    Case("a winch line too short for the reference (spatial)", RUN, "exits[0].winch_line = 0.1 mm less two elements",
         scene="spatial-four-cable-swivel", changes=tuple(((("exits", i, "winch_line"), 1e-4)) for i in range(4))),
    # files and names
    Case("a file that is not UTF-8 (Latin-1, binary)", RUN, "scene file 'scene.toml' is not UTF-8 TOML",
         content='name = "café"\n'.encode("latin-1")),
    Case("a file that is not valid TOML", RUN, "scene 'scene.toml' is not valid TOML: Expected ']'",
         content=b"name = 'x'\n[cable\n"),
    Case("a folder given as the scene", ("run", "."), "scene '.' is a directory"),
    Case("a misspelt scene name", ("run", "spatial-cogiroo"), "did you mean 'spatial-cogiro'?"),
    # options
    Case("`--out` naming an existing file", ("run", "paper-circle", "--out", "scene.toml"),
         "is an existing file, not a folder", content=b""),
    Case("an override out of range", ("run", "paper-circle", "--end-time", "-1"),
         "solver.end_time must be positive [s], got -1.0"),
    Case("a number option that is not a number", ("run", "paper-circle", "--end-time", "abc"),
         "argument --end-time: invalid float value: 'abc'"),
    Case("a tolerance that is not a length", ("run", "paper-circle", "--tolerance", "5xx"),
         "--tolerance must be a length such as 5mm"),
]


@pytest.mark.parametrize("case", CASES, ids=[case.bad_input for case in CASES])
def test_each_bad_input_is_refused_with_the_words_the_table_shows(case, tmp_path):
    outcome = TABLE.run_case(case, tmp_path)
    assert outcome.exit_code == case.exit_code, outcome
    assert outcome.message.startswith("cdpr: error: ") or outcome.message.startswith("usage:") \
        or "error:" in outcome.message, outcome
    assert case.expected in outcome.message, outcome.message


def test_the_committed_table_is_what_the_cases_give():
    """Regenerate with `python examples/bad_input_table.py` when a message changes."""
    assert (ROOT / "docs" / "bad_input.md").read_text() == TABLE.document(CASES)
