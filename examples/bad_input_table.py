"""Write docs/bad_input.md: each kind of bad input, run through the real command line, and what the user gets.

Run:  python examples/bad_input_table.py

The cases are the ones ``tests/test_bad_input.py`` checks (a scene file with one field
changed, a file that is no scene, a command line); each runs in a fresh folder through
``cdpr_exu.cli.main`` exactly as ``cdpr ...`` would, and the table shows the exit code and
the line the user reads. ``tests/test_bad_input.py`` also checks that the committed
docs/bad_input.md is what this script writes, so the two never drift apart. A few
seconds.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import sys
import tempfile
import tomllib
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCUMENT = ROOT / "docs" / "bad_input.md"
#: Stands for "remove this field" in a case's changes.
DELETE = "<delete>"
#: Longest message shown in the table [characters]; the rest is cut at a word and marked "...".
SHOWN_LENGTH = 170

INTRODUCTION = """# Bad input, and what the user gets

Every refusal happens before any simulation starts, names the field (as a path such as
`pulleys[0].center`, `cables[1].unstrained_length` or `trajectory.radius`) with its unit,
and then the value. In Python the errors are `cdpr_exu.SceneError` (a field or an
argument), `cdpr_exu.UnreachableError` (a pose the cables cannot reach or hold) and
`cdpr_exu.OutputError` (an output folder); all derive from `cdpr_exu.CdprError`. On the
command line they print one line `cdpr: error: ...` and exit with code 2 (`cdpr --help`
lists every exit code).

The table is written by `python examples/bad_input_table.py`, which runs each case through
the real command line (`SCENE` is the scene file the case writes: a shipped scene with the
change shown); `tests/test_bad_input.py` checks each case and that this file is what the
script writes. Long messages are cut at "...".

"""

CONCLUSION = """
## Runs that fail, and other exit codes

* A run that leaves the model's valid range or that the solver cannot continue exits 3
  with the time, the cause found (strain over 5 %, a cable slipping through a pulley, a
  platform above the pulleys, Newton's failure) and a hint that follows that cause; what
  was computed up to then is written to `--out` (`tests/test_cli.py`,
  `tests/test_silent_degradation.py`).
* `cdpr static` exits 3 when its equilibrium holds the platform above its exits (cables
  cannot push; the cause, e.g. cables that bend like rods, is named), and warns
  (`cdpr: warning: ...`, and `warnings` in `summary.json`) when a spatial rest lies more
  than 5 % of the shortest cable from its catenaries' answer (`tests/test_spatial_swivel.py`).
* Ctrl-C exits 130 and writes what was computed; a step longer than the output period is
  not refused but warned about, with the sample count.
"""


@dataclass(frozen=True)
class Outcome:
    """What a case gives: the exit code and the line the user reads (the error, else the first warning)."""

    exit_code: int
    message: str


def _scene_text(case) -> bytes | None:
    """The bytes of the case's scene file: raw ``content``, or a shipped scene's TOML with ``changes``."""
    import tomli_w

    from cdpr_exu.scenes.scene import shipped_scene_text

    if case.content is not None:
        return case.content
    if case.scene is None:
        return None
    data = tomllib.loads(shipped_scene_text(case.scene))
    for path, value in case.changes:
        *parents, last = path
        table = data
        for key in parents:
            table = table[key]
        if isinstance(value, str) and value == DELETE:
            del table[last]
        else:
            table[last] = value
    return tomli_w.dumps(data).encode()


def run_case(case, folder: Path) -> Outcome:
    """Run one case in ``folder`` (its scene file is written there as ``scene.toml``) through the real
    ``cdpr`` entry point; returns the exit code and the line the user reads."""
    from cdpr_exu.cli import main

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    text = _scene_text(case)
    if text is not None:
        (folder / "scene.toml").write_bytes(text)
    errors = io.StringIO()
    with contextlib.chdir(folder), contextlib.redirect_stderr(errors), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(list(case.command))
        except SystemExit as stop:  # argparse's refusals
            code = stop.code
    lines = [line for line in errors.getvalue().splitlines() if line.strip()]
    said = [line for line in lines if "error:" in line] or [line for line in lines if "warning:" in line] or lines
    return Outcome(int(code), said[0] if said else "")


def _short(message: str) -> str:
    """The message cut at a word before :data:`SHOWN_LENGTH` characters, as Markdown code."""
    if len(message) > SHOWN_LENGTH:
        message = message[:SHOWN_LENGTH].rsplit(" ", 1)[0] + " ..."
    return "`" + message.replace("`", "'").replace("|", "\\|") + "`"


def document(cases) -> str:
    """docs/bad_input.md for ``cases``: each run in a fresh folder, its command, exit code and message."""
    rows = ["| bad input | command | what the user gets | exit code |", "|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as scratch:
        for k, case in enumerate(cases):
            outcome = run_case(case, Path(scratch) / str(k))
            command = "cdpr " + " ".join(case.command)
            rows.append(f"| {case.bad_input} | `{command}` | {_short(outcome.message)} | {outcome.exit_code} |")
    return INTRODUCTION + "\n".join(rows) + "\n" + CONCLUSION


def load_cases():
    """The cases of ``tests/test_bad_input.py``."""
    spec = importlib.util.spec_from_file_location("bad_input_cases", ROOT / "tests" / "test_bad_input.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module.CASES


def main() -> None:
    DOCUMENT.write_text(document(load_cases()))
    print(f"wrote {DOCUMENT.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
