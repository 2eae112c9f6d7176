"""The safety net of the one-core restructuring (issue 24): every kind of run, rest and statics
the library has, planar and spatial, gives the numbers stored in tests/golden/ bit for bit.

The cases are in tests/golden/cases.py; tests/golden/make_golden.py stored them from the code
before the restructuring. ``np.array_equal`` is the tolerance: a restructuring that moves any
number by any amount (a different order of floating-point operations, another item order in
Exudyn) fails here and must either be undone or be a deliberate change whose commit
regenerates the case and says which numbers moved and by how much.
"""

import sys
from pathlib import Path

import numpy as np
import pytest

GOLDEN = Path(__file__).resolve().parent / "golden"
sys.path.insert(0, str(GOLDEN))
from cases import CASES  # noqa: E402


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(CASES))
def test_the_case_gives_its_stored_numbers_bit_for_bit(name):
    stored = np.load(GOLDEN / f"{name}.npz")
    computed = CASES[name]()
    assert sorted(computed) == sorted(stored.files)
    moved = [key for key in stored.files if not np.array_equal(stored[key], computed[key])]
    assert moved == [], {key: (float(np.max(np.abs(np.asarray(stored[key], float) - np.asarray(computed[key], float))))
                               if np.shape(stored[key]) == np.shape(computed[key]) else
                               f"shape {np.shape(stored[key])} -> {np.shape(computed[key])}") for key in moved}


def test_every_case_is_stored():
    assert sorted(p.stem for p in GOLDEN.glob("*.npz")) == sorted(CASES)
