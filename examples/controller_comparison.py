"""Compare the controllers on the paper circle, on a plant their model does not match, and on
the quasi-static circle.

Run:  python examples/controller_comparison.py

Writes ``results/controllers/`` (paper circle, 10 s), ``results/controllers_mismatch/``
(``paper-circle-mismatch``: the plant 10 % heavier, its cable 10 % lighter than the
controllers believe), ``results/controllers_mismatch_30/`` (the same with a 30-element
plant, the controllers keeping the paper's 15) and ``results/controllers_slow/`` (one
turn at 0.05 rad/s, 126 s); about 20 minutes on two cores, most of it the learning
controllers' trials on the slow circle: summary.json keyed by controller,
comparison.md, a pose CSV per controller, and the path and error figures. As
``cdpr compare`` does, the circles start smoothly from rest over 1 s
(:func:`~cdpr_exu.studies.comparison.smooth_start`).
Equivalent to ``cdpr compare paper-circle --out results/controllers`` and
``cdpr compare paper-circle-slow --out results/controllers_slow``.
"""

from dataclasses import replace

from cdpr_exu.cli.compare import print_controller_row, print_progress
from cdpr_exu.studies.comparison import compare_controllers, markdown_table, smooth_start
from cdpr_exu.scenes.scene import ControllerModel, load_scene


def fine_plant(scene, n_elements: int = 30):
    """``scene`` whose simulated cables have ``n_elements`` each; the controllers keep their model's."""
    model = scene.controller_scene()
    believed = scene.controller_model or ControllerModel()
    believed = replace(believed, cable={**believed.cable, "n_elements": model.cables[0].n_elements})
    return scene.with_changes(cables=tuple(replace(c, n_elements=n_elements) for c in scene.cables),
                              controller_model=believed)


def scenes():
    """(scene, output folder) of each comparison."""
    mismatch = load_scene("paper-circle-mismatch")
    yield load_scene("paper-circle"), "results/controllers"
    yield mismatch, "results/controllers_mismatch"
    yield fine_plant(mismatch), "results/controllers_mismatch_30"
    yield load_scene("paper-circle-slow"), "results/controllers_slow"


def main() -> None:
    for scene, folder in scenes():
        print(f"{scene.name} -> {folder}")
        summaries = compare_controllers(smooth_start(scene), out=folder, report=print_controller_row,
                                        learning_report=print_progress)
        print(markdown_table(summaries))


if __name__ == "__main__":
    main()
