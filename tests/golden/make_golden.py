"""Store the golden cases (tests/golden/cases.py) computed by the code as it is now.

Run from the project root:  python tests/golden/make_golden.py [CASE ...]

Only when the current code's numbers are the trusted ones: before a restructuring, or
after a change that moves numbers on purpose (name the cases it moves; its commit says
which numbers moved and by how much).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cases import CASES  # noqa: E402

FOLDER = Path(__file__).resolve().parent

if __name__ == "__main__":
    names = sys.argv[1:] or sorted(CASES)
    unknown = sorted(set(names) - set(CASES))
    if unknown:
        sys.exit(f"unknown case(s) {unknown}; known: {sorted(CASES)}")
    for name in names:
        start = time.process_time()
        arrays = CASES[name]()
        np.savez_compressed(FOLDER / f"{name}.npz", **arrays)
        print(f"{name}: {len(arrays)} arrays, {time.process_time() - start:.1f} s CPU", flush=True)
