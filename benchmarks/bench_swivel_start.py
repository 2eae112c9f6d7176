"""Benchmark: the start of a robot over swivel pulleys, by the chain statics against the dynamic settle.

Builds ``spatial-four-cable-swivel`` (4 cables x 48 elements and 6 on each winch line,
bending, tension-only elements: the model ``cdpr run`` builds) and brings it to rest
twice, on two fresh models in this one process (one core): by
:func:`cdpr_exu.run.settle.start_at_rest` (the chain statics, then Exudyn's
static solver to polish) and by the fallback :func:`cdpr_exu.run.settle.settle`
(0.5 s of damped dynamics, then Exudyn's static solver). Then the same without bending,
and with spring elements (the model ``cdpr static`` builds). It prints the CPU and wall
time of each start, their ratio, and how far apart the two starts' states lie (largest
coordinate difference [m, rad]): both are the same model's static equilibrium.

Run: ``python benchmarks/bench_swivel_start.py``; writes ``benchmarks/results/swivel_start.md``.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import replace
from pathlib import Path

import exudyn as exu
import numpy as np

from cdpr_exu.builder.robot_3d import build_spatial_robot, scene_chain_spec
from cdpr_exu.run.settle import settle, start_at_rest
from cdpr_exu.statics.statics import catenary_platform
from cdpr_exu.scenes.scene import load_scene

RESULTS = Path(__file__).resolve().parent / "results" / "swivel_start.md"


def _built(scene, tension_only):
    mbs = exu.SystemContainer().AddSystem()
    items = build_spatial_robot(mbs, catenary_platform(scene), scene.unstrained_lengths,
                                scene_chain_spec(scene, tension_only=tension_only), exits=scene.exits)
    mbs.Assemble()
    return mbs, items


def _timed(start, scene, tension_only):
    """CPU and wall time [s] of ``start`` on a freshly built robot, and its coordinates at rest."""
    mbs, items = _built(scene, tension_only)
    cpu, wall = time.process_time(), time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a fallback or a failed polish would not be what is timed
        start(mbs, items)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    return cpu, wall, np.asarray(mbs.systemData.GetODE2Coordinates(exu.ConfigurationType.Initial))


def main() -> None:
    scene = load_scene("spatial-four-cable-swivel")
    no_bending = replace(scene, effects=replace(scene.effects, bending=False, bending_damping=False))
    _timed(start_at_rest, scene, True)  # numba's compilation (cached on disk) and Exudyn's first call, not timed
    rows = []
    for label, variant, tension_only in (("shipped (bending, tension-only: cdpr run)", scene, True),
                                         ("bending, spring elements (cdpr static)", scene, False),
                                         ("no bending, tension-only", no_bending, True)):
        statics = _timed(start_at_rest, variant, tension_only)
        settled = _timed(settle, variant, tension_only)
        apart = float(np.abs(statics[2] - settled[2]).max())
        rows.append((label, settled[0], statics[0], settled[1], statics[1], apart))
        print(f"{label:44s} settle {settled[0]:6.2f} s CPU ({settled[1]:6.2f} wall), chain statics "
              f"{statics[0]:6.3f} s CPU ({statics[1]:6.3f} wall): {settled[0] / statics[0]:5.0f}x; "
              f"states {apart:.2g} apart", flush=True)
    lines = ["| spatial-four-cable-swivel, 4 x (48 + 6) elements | dynamic settle, CPU [s] | chain statics, CPU [s] | "
             "ratio | wall [s], settle / chain statics | largest coordinate difference of the two starts |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {label} | {settle_cpu:.2f} | {statics_cpu:.3f} | {settle_cpu / statics_cpu:.0f} | "
              f"{settle_wall:.2f} / {statics_wall:.3f} | {apart:.1e} |"
              for label, settle_cpu, statics_cpu, settle_wall, statics_wall, apart in rows]
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text("\n".join(lines) + "\n")
    print(f"written to {RESULTS}")


if __name__ == "__main__":
    main()
