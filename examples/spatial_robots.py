"""The shipped spatial robots at rest and under each spatial controller.

Run:  python examples/spatial_robots.py

Writes ``results/spatial/<scene>/static/`` (``cdpr static``: summary.json and the 3-D rest
figure of spatial-four-cable, spatial-cogiro and spatial-ipanema) and
``results/spatial/<scene>/compare/`` (``cdpr compare``: summary.json, comparison.md and an
overview figure per controller: those of :data:`CONTROLLERS` for spatial-cogiro and spatial-ipanema,
every spatial controller, the learning ones too, for spatial-cogiro-mismatch, the CoGiRo-class robot
whose controllers plan on a model 10 % off in platform mass and cable density), and the table
``results/spatial/controllers.md`` that the README and docs/spatial.md show. About five
minutes on one core (the chain version's statics, ``tension_aware_chain``, take about
20 s of it on CoGiRo and 14 s on IPAnema; the learning controllers' 10 trials each about 40 s).
"""

from pathlib import Path

from cdpr_exu.cli.compare import print_controller_row
from cdpr_exu.post.plots import plot_rest
from cdpr_exu.run.rest import solve_rest
from cdpr_exu.studies.comparison import compare_controllers
from cdpr_exu.scenes.scene import load_scene

RESULTS = Path("results/spatial")
#: The controllers of the shipped robots' rows; the mismatch scene runs every spatial controller, the learning
#: ones (ilc, model_feed_forward and its closed loop) too (None: :func:`controllers.registry.controllers_for`).
CONTROLLERS = ["ideal_ik", "tension_aware", "tension_aware_chain", "closed_loop_tension_aware"]
COMPARED = {"spatial-cogiro": CONTROLLERS, "spatial-ipanema": CONTROLLERS, "spatial-cogiro-mismatch": None}


def main() -> None:
    for name in ("spatial-four-cable", "spatial-cogiro", "spatial-ipanema"):
        rest = solve_rest(load_scene(name))
        rest.save(RESULTS / name / "static")
        plot_rest(rest, RESULTS / name / "static" / "rest_profile.png")
        print(f"{name}: at rest at {rest.position.round(6).tolist()} m")
    rows = ["| robot | controller | max position error [mm] | RMS position error [mm] | max rotation error [deg] "
            "| min element tension [N] |", "|---|---|---|---|---|---|"]
    for name, controllers in COMPARED.items():
        summaries = compare_controllers(load_scene(name), controllers, out=RESULTS / name / "compare",
                                        report=print_controller_row)
        for controller, s in summaries.items():
            rows.append(f"| {name} | {controller} | {1000 * s['max_position_error_m']:.3f} | "
                        f"{1000 * s['rms_position_error_m']:.3f} | {s['max_rotation_error_deg']:.4f} | "
                        f"{s['min_element_tension_N']:.1f} |")
    (RESULTS / "controllers.md").write_text("\n".join(rows) + "\n")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
