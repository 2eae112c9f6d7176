"""Copy the tables that the examples wrote under results/ into the README.

Run:  python examples/refresh_readme.py

Each block in README.md between ``<!-- table: PATH -->`` and ``<!-- /table -->`` is
replaced by the contents of PATH (a Markdown table an example script wrote), so the
README's numbers are always the ones in results/, never typed by hand. Lines of PATH
before its first table row (a title) are skipped.
"""

from __future__ import annotations

import re
from pathlib import Path

BLOCK = re.compile(r"(<!-- table: (?P<path>[^ ]+) -->\n)(?P<body>.*?)(<!-- /table -->)", re.S)


def table_of(path: Path) -> str:
    lines = path.read_text().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("|"))
    return "\n".join(lines[start:]).strip() + "\n"


def refresh(readme: Path) -> int:
    text = readme.read_text()
    count = 0

    def replace(match: re.Match) -> str:
        nonlocal count
        count += 1
        return match.group(1) + table_of(readme.parent / match.group("path")) + match.group(4)

    readme.write_text(BLOCK.sub(replace, text))
    return count


if __name__ == "__main__":
    readme = Path(__file__).resolve().parent.parent / "README.md"
    print(f"refreshed {refresh(readme)} tables in {readme}")
