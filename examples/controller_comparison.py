"""Compare the controllers on the paper circle and on its quasi-static version.

Run:  python examples/controller_comparison.py

Writes ``results/controllers/`` (paper circle, 10 s) and ``results/controllers_slow/``
(one turn at 0.05 rad/s, 126 s; about 4 minutes): summary.json keyed by controller,
comparison.md, a pose CSV per controller, and the path and error figures. As
``cdpr compare`` does, the circles start smoothly from rest over 1 s
(:func:`~cdpr_exu.studies.comparison.smooth_start`).
Equivalent to ``cdpr compare paper-circle --out results/controllers`` and
``cdpr compare paper-circle-slow --out results/controllers_slow``.
"""

from cdpr_exu.studies.comparison import compare_controllers, markdown_table, smooth_start
from cdpr_exu.scenes.scene import load_scene


def main() -> None:
    for scene_name, folder in (("paper-circle", "results/controllers"),
                               ("paper-circle-slow", "results/controllers_slow")):
        print(f"{scene_name} -> {folder}")
        summaries = compare_controllers(smooth_start(load_scene(scene_name)), out=folder, quiet=False)
        print(markdown_table(summaries))


if __name__ == "__main__":
    main()
