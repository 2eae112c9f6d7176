"""Copy the tables that the examples wrote under results/ into the README and docs/.

Run:  python examples/refresh_readme.py

Each block in README.md and docs/*.md between ``<!-- table: PATH -->`` and ``<!-- /table -->`` is
replaced by the contents of PATH (a Markdown table an example script wrote), so the
README's numbers are always the ones in results/, never typed by hand. The first
table of PATH is copied; text before and after it is not.
"""

from __future__ import annotations

import re
from pathlib import Path

BLOCK = re.compile(r"(<!-- table: (?P<path>[^ ]+) -->\n)(?P<body>.*?)(<!-- /table -->)", re.S)


def table_of(path: Path) -> str:
    lines = path.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("|"))
    end = next((i for i in range(start, len(lines)) if not lines[i].startswith("|")), len(lines))
    return "\n".join(lines[start:end]) + "\n"


def refresh(document: Path, root: Path) -> int:
    """Refresh the marked tables of ``document``; paths are relative to ``root``."""
    text = document.read_text()
    count = 0

    def replace(match: re.Match) -> str:
        nonlocal count
        count += 1
        return match.group(1) + table_of(root / match.group("path")) + match.group(4)

    document.write_text(BLOCK.sub(replace, text))
    return count


if __name__ == "__main__":
    root = Path(__file__).resolve().parent.parent
    for document in [root / "README.md", *sorted((root / "docs").glob("*.md"))]:
        print(f"refreshed {refresh(document, root)} tables in {document.relative_to(root)}")
