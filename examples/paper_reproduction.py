"""Reproduce the paper's circle (scenario 1) and tabulate how model choices move it.

Run:  python examples/paper_reproduction.py [--out results/paper_circle]

Writes the main run (result, summary, Exudyn solution file, figures) into the output
folder, as ``cdpr run paper-circle`` does, and ``variants.md`` / ``variants.json``
(each variant's wall time and real-time factor in the untracked ``variants_timing.json``):
the same scene on the model ladder (ideal, elastic, catenary, full), as the paper
published it (spring elements that push), with the paper's mass lumping, and at other
step sizes, each against the paper's
reported maxima (8.5 cm in x, 11 cm in z, 15 degrees).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from cdpr_exu.cli import run_scene
from cdpr_exu.core.errors import SolverFailure
from cdpr_exu.core.output import write_summary
from cdpr_exu.scenes.scene import Effects, load_scene
from cdpr_exu.run.simulate import simulate

PAPER = {"max_abs_error_x_m": 0.085, "max_abs_error_z_m": 0.11, "max_abs_rotation_deg": 15.0}


def variants(scene):
    """(label, scene) pairs of the comparison table."""
    paper_lumping = scene.with_changes(cables=tuple(replace(c, mass_lumping="paper") for c in scene.cables))
    yield "full (default: tension-only elements, consistent lumping, step 2e-3 s)", scene
    yield "paper (the paper's spring elements, which push)", scene.with_changes(effects=Effects.from_preset("paper"))
    yield "full, paper's mass lumping", paper_lumping
    yield "full, step 5e-4 s", scene.with_changes(solver=replace(scene.solver, step_size=5e-4))
    yield "full, step 5e-3 s", scene.with_changes(solver=replace(scene.solver, step_size=5e-3))
    yield "elastic (massless elastic ropes)", scene.with_changes(effects=Effects.from_preset("elastic"))
    yield "ideal (massless inextensible ropes)", scene.with_changes(effects=Effects.from_preset("ideal"))
    yield "catenary (no bending)", scene.with_changes(effects=Effects.from_preset("catenary"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="results/paper_circle")
    args = parser.parse_args()
    out = Path(args.out)
    scene = load_scene("paper-circle")
    run_scene(scene, out, error_estimate=True)  # as the README command writes it

    rows = []
    for label, variant in variants(scene):
        try:
            result = simulate(variant)
            status = "completed"
        except SolverFailure as err:
            result, status = err.partial_result, f"stopped at {err.time:.2f} s: {str(err).split(': ', 1)[-1][:90]}"
        summary = result.summary()
        rows.append({"variant": label, "status": status, **{k: summary[k] for k in (
            "max_abs_error_x_m", "max_abs_error_z_m", "min_error_z_m", "max_error_z_m",
            "max_abs_rotation_deg", "min_element_tension_N", "wall_time_s", "real_time_factor")}})
        print(f"{label:50s} {status[:40]:40s} x {100 * summary['max_abs_error_x_m']:6.2f} cm  "
              f"z {100 * summary['max_abs_error_z_m']:6.2f} cm  rot {summary['max_abs_rotation_deg']:6.2f} deg  "
              f"{summary['real_time_factor']:6.1f}x real time")
    # The wall-clock figures go to variants_timing.json (git-ignored), so that variants.* are the same from
    # run to run (the folder's timing.json is the main run's).
    write_summary(out, {"paper": PAPER, "rows": rows}, name="variants.json", timing_name="variants_timing.json")
    lines = [
        "| model variant | max \\|err x\\| [cm] | max \\|err z\\| [cm] | z error range [cm] | max \\|rot\\| [deg] | status |",
        "|---|---|---|---|---|---|",
        f"| paper (20-sim, bond graph) | {100 * PAPER['max_abs_error_x_m']:.1f} | {100 * PAPER['max_abs_error_z_m']:.1f} "
        f"| negative throughout | {PAPER['max_abs_rotation_deg']:.0f} | |",
    ]
    for row in rows:
        lines.append(
            f"| {row['variant']} | {100 * row['max_abs_error_x_m']:.2f} | {100 * row['max_abs_error_z_m']:.2f} | "
            f"{100 * row['min_error_z_m']:+.2f} .. {100 * row['max_error_z_m']:+.2f} | "
            f"{row['max_abs_rotation_deg']:.1f} | {row['status']} |")
    (out / "variants.md").write_text("\n".join(lines) + "\n")
    print(f"written {out / 'variants.md'}")


if __name__ == "__main__":
    main()
