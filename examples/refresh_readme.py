"""Copy the tables and figures that the examples and benchmarks wrote into the README and docs/.

Run:  python examples/refresh_readme.py            (rewrites README.md and docs/*.md)
      python examples/refresh_readme.py --check    (changes nothing; exit 1 if a refresh would)

No number measured by a script is typed by hand into README.md or docs/*.md: each is a
marker that this script fills in from the file that produced it.

*Tables.* Each block between ``<!-- table: PATH -->`` and ``<!-- /table -->`` is replaced
by the contents of PATH (a Markdown table a script wrote). ``PATH`` copies the file's
first table, ``PATH#N`` its N-th; the text around it is not copied.

*Figures in the text.* Each ``<!-- value: PATH#KEYS | SPEC -->TEXT<!-- /value -->`` (on one
line) has TEXT replaced by the number at KEYS in the file PATH, written as SPEC says: a JSON
file; a CSV file (a list of its rows, each a dict by column name); or a Markdown file (a list
of its tables from 1, each a list of its rows, each a dict by column header and by column
number from 0). The comment is invisible in the rendered Markdown; only TEXT shows.

* ``KEYS``: dot-separated steps into the JSON: a dict key, a list index (``0``, ``-1``),
  or ``[field=value,...]``, the one element of a list of dicts whose fields have those
  values (numbers compared as numbers; a value with a comma in double quotes):
  ``rows.[step=0.01,n=60].error_m``, ``rows.[variant="full, step 5e-3 s"].max_abs_error_x_m``.
* ``SPEC`` is ``UNIT:FORMAT``. UNIT scales the SI value: ``mm`` (x 1e3), ``cm`` (x 1e2),
  ``um`` (x 1e6), ``%`` (x 100), ``1`` (as it is); a leading ``-`` also flips the sign
  (``-mm``: a length difference of -3.25e-3 m written as 3.25 mm "less"). FORMAT is a number of decimals
  (``1``: 18.0) or a Python format spec (``.2g``, ``.0e``, ``+.2f``).
  Example: ``<!-- value: results/paper_circle/summary.json#error_estimate.max_position_error_m | mm:1 -->18.0<!-- /value -->``.

``tests/test_readme.py`` checks that a refresh changes nothing in the committed README and
docs and that every marker's source exists: regenerate a result with its script, then run
this script, and the documents follow.
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
from pathlib import Path

BLOCK = re.compile(r"(<!-- table: (?P<path>[^ ]+) -->\n)(?P<body>.*?)(<!-- /table -->)", re.S)
VALUE = re.compile(r"(?P<open><!-- value: (?P<path>[^#|\s]+)#(?P<keys>[^|]+?) \| (?P<spec>\S+) -->)"
                   r"(?P<body>[^<\n]*)(?P<close><!-- /value -->)")
SCALES = {"1": 1.0, "mm": 1e3, "cm": 1e2, "um": 1e6, "%": 1e2}
FILTER = re.compile(r"\[(?P<conditions>[^\]]+)\]")


def _tables(text: str) -> list[str]:
    """The Markdown tables of ``text``, in order."""
    lines = text.splitlines()
    tables, i = [], 0
    while i < len(lines):
        if lines[i].startswith("|"):
            j = i
            while j < len(lines) and lines[j].startswith("|"):
                j += 1
            tables.append("\n".join(lines[i:j]) + "\n")
            i = j
        else:
            i += 1
    return tables


def _cells(line: str) -> list[str]:
    return [cell.strip() for cell in re.split(r"(?<!\\)\|", line.strip().strip("|"))]


def _table_rows(table: str) -> list[dict]:
    """A Markdown table's rows, each a dict by header and by column number (from 0)."""
    header, _, *rows = table.splitlines()
    names = _cells(header)
    out = []
    for row in rows:
        cells = [_number(cell) for cell in _cells(row)]
        out.append({**dict(zip(names, cells)), **{str(k): cell for k, cell in enumerate(cells)}})
    return out


def table_of(reference: str, root: Path) -> str:
    """The table named by ``PATH`` (its first table) or ``PATH#N`` (its N-th, from 1)."""
    path, _, number = reference.partition("#")
    return _tables((root / path).read_text())[int(number or 1) - 1]


def _split_keys(keys: str) -> list[str]:
    """``a.[x=1.5,y=2].b`` -> ``['a', '[x=1.5,y=2]', 'b']`` (dots inside brackets kept)."""
    steps, depth, current = [], 0, ""
    for char in keys.strip():
        if char == "." and depth == 0:
            steps.append(current)
            current = ""
            continue
        depth += {"[": 1, "]": -1}.get(char, 0)
        current += char
    return [*steps, current]


def _conditions(conditions: str) -> list[tuple[str, str]]:
    """``x=1.5, name="a, b"`` -> ``[('x', '1.5'), ('name', 'a, b')]``: commas inside quotes kept."""
    parts = [part.strip() for part in re.findall(r'(?:[^,"]|"[^"]*")+', conditions)]
    pairs = []
    for part in parts:
        field, _, wanted = part.partition("=")
        wanted = wanted.strip()
        pairs.append((field.strip(), wanted[1:-1] if len(wanted) >= 2 and wanted[0] == wanted[-1] == '"' else wanted))
    return pairs


def _matches(item, conditions: str) -> bool:
    if not isinstance(item, dict):
        return False
    for field, wanted in _conditions(conditions):
        value = item.get(field, object())
        try:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ValueError
            if abs(float(value) - float(wanted)) > 1e-12 * max(1.0, abs(float(wanted))):
                return False
        except ValueError:
            if str(value) != wanted:
                return False
    return True


def _number(cell: str):
    """A CSV cell as a number where it is one, else the text."""
    try:
        return int(cell)
    except ValueError:
        try:
            return float(cell)
        except ValueError:
            return cell


def value_at(path: str, keys: str, root: Path):
    """The value at ``keys`` (see the module docstring) in the JSON file ``root / path``."""
    if path.endswith(".csv"):
        with open(root / path, newline="") as handle:
            value = [{key: _number(cell) for key, cell in row.items()} for row in csv.DictReader(handle)]
    elif path.endswith(".md"):
        value = [None, *(_table_rows(table) for table in _tables((root / path).read_text()))]
    else:
        value = json.loads((root / path).read_text())
    for step in _split_keys(keys):
        selector = FILTER.fullmatch(step)
        if selector:
            found = [item for item in value if _matches(item, selector.group("conditions"))]
            if len(found) != 1:
                raise KeyError(f"{path}#{keys}: {step} matches {len(found)} elements, not one")
            value = found[0]
        elif isinstance(value, list):
            value = value[int(step)]
        else:
            value = value[step]
    return value


def formatted(value, spec: str) -> str:
    """``value`` written as ``spec`` (``UNIT:FORMAT``, see the module docstring) says."""
    unit, _, form = spec.partition(":")
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != value:
        raise ValueError(f"not a number: {value!r}")
    scaled = (-1.0 if unit.startswith("-") else 1.0) * value * SCALES[unit.removeprefix("-")]
    return f"{scaled:.{int(form)}f}" if form.isdigit() else format(scaled, form)


def markers(text: str) -> list[re.Match]:
    """The figure markers of ``text``."""
    return list(VALUE.finditer(text))


def refreshed(text: str, root: Path) -> tuple[str, int, int]:
    """``text`` with its tables and figures refreshed from the files under ``root``, and their counts."""
    tables = figures = 0

    def table(match: re.Match) -> str:
        nonlocal tables
        tables += 1
        return match.group(1) + table_of(match.group("path"), root) + match.group(4)

    def figure(match: re.Match) -> str:
        nonlocal figures
        figures += 1
        value = value_at(match.group("path"), match.group("keys"), root)
        return match.group("open") + formatted(value, match.group("spec")) + match.group("close")

    text = BLOCK.sub(table, text)
    return VALUE.sub(figure, text), tables, figures


def documents(root: Path) -> list[Path]:
    """The documents this script refreshes: README.md and docs/*.md."""
    return [root / "README.md", *sorted((root / "docs").glob("*.md"))]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="change nothing; exit 1 if a refresh would")
    args = parser.parse_args()
    root = Path(__file__).resolve().parent.parent
    stale = []
    for document in documents(root):
        text = document.read_text()
        new, tables, figures = refreshed(text, root)
        name = document.relative_to(root)
        if new != text:
            stale.append(str(name))
            if not args.check:
                document.write_text(new)
        print(f"{'checked' if args.check else 'refreshed'} {tables} tables and {figures} figures in {name}"
              + (" (changed)" if new != text else ""))
    if args.check and stale:
        print(f"out of date: {', '.join(stale)}: run python examples/refresh_readme.py", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
