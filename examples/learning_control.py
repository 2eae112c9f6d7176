"""Iterative learning control and model-based feed-forward on a plant that differs from its model.

Run:  python examples/learning_control.py        (about 2 minutes)

The controller's model is the paper circle (2.5 kg platform, 0.35 kg/m cables); the
plant has the platform mass +10 % (2.75 kg) and the cable density -10 % (0.315 kg/m),
issue 13's mismatch. Both use tension-only cables (effects.slack = true). Errors are
actual - reference, measured after the first second. Writes ``results/learning_control/``:

* ``trials.md``: the ILC trials on the plant and the learning on the model, one row per trial;
* ``response.md``: the measured position response of the model that the learning law was
  designed from (largest singular value of I - gamma exp(i omega tau) G per band);
* ``summary.json``: the same numbers;
* ``error_per_trial.png``: max and RMS error per trial; ``errors.png``: the plant's error
  over time under ideal IK, model-based feed-forward and the best ILC trial.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from cdpr_exu.core.output import write_summary
from cdpr_exu.results.result import provenance
from cdpr_exu.scenes.scene import load_scene
from cdpr_exu.studies.learning import (DEFAULT_LAW, DEFAULT_RULE, learn_lengths, measure_response, model_feed_forward,
                                      trial_line)

OUT = Path("results/learning_control")
AFTER = 1.0  # s, the start-up excluded from the errors
#: Issue 13's rigid zero-dynamics feed-forward on the paper circle (measured outside the project):
#: lengths from the reference pose with the rigid platform's periodic rotation, then plus sag and stretch.
RIGID_BASELINE = {"rotation only": 1.03, "rotation, sag and stretch": 1.22}


def mismatch_pair():
    """(model, plant): the paper circle on tension-only cables and its +10 % mass, -10 % density plant."""
    scene = load_scene("paper-circle")
    model = scene.with_changes(name="paper-circle-model", effects=replace(scene.effects, slack=True))
    plant = model.with_changes(name="paper-circle-mismatch-plant", platform=replace(model.platform, mass=2.75),
                               cables=tuple(replace(c, linear_density=0.315) for c in model.cables))
    return model, plant


def trial_rows(trials, reference: float) -> list[str]:
    """Markdown rows of the trials: errors [mm], ratio to ``reference`` [m], change, tension, slack."""
    rows, previous = [], None
    for trial in trials:
        error = trial.max_position_error_m
        change = "" if previous is None else f"{100 * (error / previous - 1):+.1f} %"
        rows.append(f"| {trial.number} | {1000 * error:.2f} | {1000 * trial.rms_position_error_m:.2f} | "
                    f"{reference / error:.1f}x | {change} | {trial.min_element_tension_N:.2f} | "
                    f"{trial.slack_time_s:.3f} | {1000 * trial.max_correction_m:.1f} |")
        previous = error
    return rows


HEADER = ("| trial | max pos. error [mm] | RMS pos. error [mm] | vs ideal IK on the plant | change | "
          "min element tension [N] | slack time [s] | max correction [mm] |\n|---|---|---|---|---|---|---|---|")


def plot_trials(ilc, on_model, plant_feed_forward, reference: float, path: Path) -> None:
    figure = Figure(figsize=(7.0, 4.2))
    axes = figure.add_subplot()
    for learning, label, style in ((ilc, "ILC on the plant", "o-"), (on_model, "learning on the model", "s--")):
        numbers = [t.number for t in learning.trials]
        axes.semilogy(numbers, [1000 * t.max_position_error_m for t in learning.trials], style, label=f"{label}: max")
        axes.semilogy(numbers, [1000 * t.rms_position_error_m for t in learning.trials], style, alpha=0.45,
                      label=f"{label}: RMS")
    axes.axhline(1000 * plant_feed_forward, color="tab:green", lw=1.2,
                 label="model's commands on the plant (max)")
    axes.axhline(1000 * reference / 20, color="k", lw=0.8, ls=":", label="20x less than ideal IK")
    axes.axhline(1000 * reference / 5, color="k", lw=0.8, ls="-.", label="5x less than ideal IK")
    axes.set_xlabel("trial (1: ideal inverse kinematics)")
    axes.set_ylabel(f"position error after {AFTER:g} s [mm]")
    axes.set_title("Error per trial, paper circle with a +10 % mass / -10 % density plant", fontsize=10)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=7)
    figure.tight_layout()
    FigureCanvasAgg(figure).print_png(str(path))


def plot_errors(runs: dict, path: Path) -> None:
    figure = Figure(figsize=(7.0, 3.8))
    axes = figure.add_subplot()
    for label, result in runs.items():
        error = np.linalg.norm(result.error[:, :2], axis=1)
        axes.semilogy(result.time, np.maximum(1000 * error, 1e-3), lw=0.9, label=label)
    axes.axvline(AFTER, color="k", lw=0.6, ls=":")
    axes.set_xlabel("time [s]")
    axes.set_ylabel("position error on the plant [mm]")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    FigureCanvasAgg(figure).print_png(str(path))


def response_table(response) -> tuple[str, list[dict]]:
    rows, data = [], []
    for gain, lead in ((0.5, 0.0), (0.7, 0.0), (0.7, 0.02), (1.0, 0.0), (1.0, 0.02), (0.7, 0.06)):
        contraction = response.contraction(gain, lead)
        bands = [float(contraction[response.frequencies <= band].max()) for band in (1.0, 2.0, 5.0)]
        rows.append(f"| {gain} | {lead} | " + " | ".join(f"{b:.2f}" for b in bands) + " |")
        data.append({"gain": gain, "lead_s": lead, "max_singular_value_to_1_2_5_Hz": bands})
    text = ("Largest singular value of I - gamma exp(i omega tau) G over the measured frequencies "
            f"({response.frequencies[0]:.2f} to {response.frequencies[-1]:.2f} Hz), G measured on the model "
            "(below 1: the error at that frequency shrinks every trial)\n\n"
            "| gain gamma | lead tau [s] | <= 1 Hz | <= 2 Hz | <= 5 Hz |\n|---|---|---|---|---|\n" + "\n".join(rows) + "\n")
    return text, data


def print_trial(trial) -> None:
    print(trial_line(trial), flush=True)


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    model, plant = mismatch_pair()
    print("measuring the model's position response (3 runs)")
    response = measure_response(model, after=AFTER)
    response_md, response_data = response_table(response)
    (OUT / "response.md").write_text(response_md)
    print(response_md)

    print(f"ILC on the plant (law {DEFAULT_LAW}, rule {DEFAULT_RULE})")
    ilc = learn_lengths(plant, after=AFTER, on_trial=print_trial)
    print(f"  kept trial {ilc.best_trial}: {ilc.stop_reason}")
    ideal_on_plant = ilc.trials[0].max_position_error_m  # trial 1 is the ideal IK
    print("learning on the model, then its commands open loop on the plant")
    on_model, feed_forward = model_feed_forward(model, plant, after=AFTER, on_trial=print_trial)
    print(f"  kept trial {on_model.best_trial}: {on_model.stop_reason}")
    ff = feed_forward.summary(after=AFTER)
    ff_slack = max(s for s in ff["slack_time_per_cable_s"] if s is not None)
    best = ilc.trials[ilc.best_trial - 1]

    text = [f"Paper circle, model 2.5 kg / 0.35 kg/m, plant 2.75 kg / 0.315 kg/m, tension-only cables; errors "
            f"after {AFTER:g} s (actual - reference); ideal IK on the plant: {1000 * ideal_on_plant:.2f} mm.", "",
            "| controller (on the plant) | max pos. error [mm] | RMS pos. error [mm] | vs ideal IK | "
            "min element tension [N] | slack time [s] |", "|---|---|---|---|---|---|",
            f"| ideal_ik | {1000 * ideal_on_plant:.2f} | {1000 * ilc.trials[0].rms_position_error_m:.2f} | 1.0x | "
            f"{ilc.trials[0].min_element_tension_N:.2f} | {ilc.trials[0].slack_time_s:.3f} |",
            *(f"| rigid zero-dynamics feed-forward, {k} (issue 13, on the model) | | | {v:.2f}x | | |"
              for k, v in RIGID_BASELINE.items()),
            f"| model_feed_forward (learned on the model, {on_model.best_trial} trials) | "
            f"{1000 * ff['max_position_error_m']:.2f} | {1000 * ff['rms_position_error_m']:.2f} | "
            f"{ideal_on_plant / ff['max_position_error_m']:.1f}x | {ff['min_element_tension_N']:.2f} | {ff_slack:.3f} |",
            f"| ilc (trial {best.number} of {len(ilc.trials)} on the plant) | {1000 * best.max_position_error_m:.2f} | "
            f"{1000 * best.rms_position_error_m:.2f} | {ideal_on_plant / best.max_position_error_m:.1f}x | "
            f"{best.min_element_tension_N:.2f} | {best.slack_time_s:.3f} |", "",
            f"ILC on the plant (stopped: {ilc.stop_reason}):", "", HEADER, *trial_rows(ilc.trials, ideal_on_plant), "",
            f"Learning on the model (stopped: {on_model.stop_reason}); the ratio is to the ideal IK on the plant:", "",
            HEADER, *trial_rows(on_model.trials, ideal_on_plant), ""]
    (OUT / "trials.md").write_text("\n".join(text))
    print("\n".join(text))
    write_summary(OUT, {
        "model": model.name, "plant": plant.name, "errors_measured_after_s": AFTER,
        "error_convention": "actual - reference", "ideal_ik_on_plant_max_position_error_m": ideal_on_plant,
        "rigid_zero_dynamics_feed_forward_vs_ideal_ik": RIGID_BASELINE,
        "ilc_on_plant": ilc.to_dict(), "learning_on_model": on_model.to_dict(),
        "model_feed_forward_on_plant": {k: ff[k] for k in ("max_position_error_m", "rms_position_error_m",
                                                           "min_element_tension_N", "slack_time_per_cable_s")},
        "position_response": response_data, **provenance()})
    plot_trials(ilc, on_model, ff["max_position_error_m"], ideal_on_plant, OUT / "error_per_trial.png")
    from cdpr_exu.run.simulate import simulate

    plot_errors({"ideal IK": simulate(plant), "model_feed_forward": feed_forward,
                 f"ilc, trial {best.number}": ilc.result}, OUT / "errors.png")
    print(f"written to {OUT}/")


if __name__ == "__main__":
    main()
