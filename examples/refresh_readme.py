"""Copy the tables that the examples wrote under results/ into the README and docs/.

Run:  python examples/refresh_readme.py

Each block in README.md and docs/*.md between ``<!-- table: PATH -->`` and ``<!-- /table -->`` is
replaced by the contents of PATH (a Markdown table an example script wrote), so the
README's numbers are always the ones in results/, never typed by hand. ``PATH`` copies
the file's first table, ``PATH#N`` its N-th; the text around it is not copied.
"""

from __future__ import annotations

import re
from pathlib import Path

BLOCK = re.compile(r"(<!-- table: (?P<path>[^ ]+) -->\n)(?P<body>.*?)(<!-- /table -->)", re.S)


def table_of(reference: str, root: Path) -> str:
    """The table named by ``PATH`` (its first table) or ``PATH#N`` (its N-th, from 1)."""
    path, _, number = reference.partition("#")
    lines = (root / path).read_text().splitlines()
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
    return tables[int(number or 1) - 1]


def refresh(document: Path, root: Path) -> int:
    """Refresh the marked tables of ``document``; paths are relative to ``root``."""
    text = document.read_text()
    count = 0

    def replace(match: re.Match) -> str:
        nonlocal count
        count += 1
        return match.group(1) + table_of(match.group("path"), root) + match.group(4)

    document.write_text(BLOCK.sub(replace, text))
    return count


if __name__ == "__main__":
    root = Path(__file__).resolve().parent.parent
    for document in [root / "README.md", *sorted((root / "docs").glob("*.md"))]:
        print(f"refreshed {refresh(document, root)} tables in {document.relative_to(root)}")
