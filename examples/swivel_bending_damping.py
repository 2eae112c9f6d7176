"""Does the cables' bending damping converge at a swivel pulley as the elements shrink?

Run:  python examples/swivel_bending_damping.py        (about 2 minutes)

The shipped swivel scene (``spatial-four-cable-swivel``: 4 cables over swivel pulleys of
r_p = 0.1 m, a 5 kg point mass on a 0.1 m circle, 4 s) with its bending dampers on and
off, at 48 (shipped, 5 cm elements), 96 and 192 elements per cable. For each count: the
platform's largest distance between the damped and the undamped path after 1 s (what the
dampers do), each path's change from the next finer run (the discretisation), and how
often some element is slack after 1 s.

Why it is asked: a Kelvin-Voigt bending damper c_theta = d_n J / l_e acts on the rate of
the joint angle, and the cable running onto the disc bends from straight to 1 / r_p. If
that happened within one element, the dissipation 2 c_theta (v / r_p)^2 would grow without
bound as the elements shrink. In the continuum the bending stiffness spreads the change of
curvature over the bending length lambda = sqrt(E J / T) next to the disc (about 0.18 m
here), so the dissipation tends to d_n J v^2 / (2 r_p^2 lambda): a tension step across the
wrap of about d_n J v / (2 r_p^2 lambda), which this script also prints. Writes
``results/swivel_bending_damping/``: ``convergence.md``, ``summary.json`` and
``lag.png`` (the damped path's distance from the undamped one over time).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from cdpr_exu.core.output import write_summary
from cdpr_exu.results.result import provenance
from cdpr_exu.run.error_estimate import path_distance
from cdpr_exu.run.simulate import simulate
from cdpr_exu.scenes.scene import load_scene

NAME = "spatial-four-cable-swivel"
COUNTS = (48, 96, 192)
AFTER = 1.0  # s: the ramp of the circle left out


def scene_for(n_elements: int, damped: bool):
    """The shipped swivel scene with ``n_elements`` per cable, bending dampers on or off."""
    scene = load_scene(NAME)
    return replace(scene, effects=replace(scene.effects, bending_damping=damped),
                   cables=tuple(replace(c, n_elements=n_elements) for c in scene.cables))


def slack_fraction(result) -> float:
    """Share of the samples after AFTER in which some element of some cable carries nothing."""
    mask = result.time >= AFTER - 1e-9
    slack = np.zeros(int(mask.sum()), dtype=bool)
    for tensions in result.tensions:
        slack |= tensions[mask].min(axis=1) <= 0.0
    return float(slack.mean())


def tension_step_estimate(scene, result) -> dict:
    """The continuum estimate of the dampers' tension step across the wrap, d_n J v / (2 r_p^2 lambda), at the
    largest pay-out rate of the run and the smallest anchor tension after AFTER [N, m/s, m]."""
    cable = scene.cables[0]
    radius = float(scene.exits[0].radius)
    inertia = np.pi * cable.radius**4 / 4.0
    mask = result.time >= AFTER - 1e-9
    speed = float(np.abs(np.gradient(result.paid_out, result.time, axis=0))[mask].max())
    tension = float(min(t[mask, -1].min() for t in result.tensions))
    bending_length = float(np.sqrt(cable.youngs_modulus * inertia / tension))
    step = cable.damping_constant * inertia * speed / (2.0 * radius**2 * bending_length)
    return {"pay_out_speed_m_per_s": speed, "smallest_anchor_tension_N": tension,
            "bending_length_m": bending_length, "tension_step_N": step}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="results/swivel_bending_damping")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results, cpu = {}, {}
    for n in COUNTS:
        for damped in (False, True):
            start = time.process_time()
            results[n, damped] = simulate(scene_for(n, damped))
            cpu[n, damped] = time.process_time() - start
            print(f"{n:4d} elements, bending damping {'on ' if damped else 'off'}: {results[n, damped].status}, "
                  f"{cpu[n, damped]:.1f} s CPU", flush=True)
    rows = []
    for i, n in enumerate(COUNTS):
        on, off = results[n, True], results[n, False]
        finer = COUNTS[i + 1] if i + 1 < len(COUNTS) else None
        rows.append({
            "n_elements": n, "element_length_m": scene_for(n, True).cables[0].element_length,
            "damping_moves_path_m": path_distance(on, off, AFTER),
            "change_to_finer_damped_m": path_distance(on, results[finer, True], AFTER) if finer else None,
            "change_to_finer_undamped_m": path_distance(off, results[finer, False], AFTER) if finer else None,
            "slack_sample_fraction_damped": slack_fraction(on),
            "slack_sample_fraction_undamped": slack_fraction(off),
            "max_error_damped_m": on.summary(AFTER)["max_position_error_m"],
            "max_error_undamped_m": off.summary(AFTER)["max_position_error_m"],
            "cpu_time_s": {"damped": cpu[n, True], "undamped": cpu[n, False]},  # to timing.json (write_summary)
        })
    estimate = tension_step_estimate(scene_for(COUNTS[-1], True), results[COUNTS[-1], True])

    def mm(value):
        return "" if value is None else f"{1000 * value:.2f}"

    lines = [f"# Bending damping at swivel pulleys over the discretisation (`{NAME}`, 4 s)", "",
             "Written by `examples/swivel_bending_damping.py`. Distances: the platform centre's largest, after "
             f"{AFTER:g} s. Slack: share of the samples after {AFTER:g} s with some element at zero tension.", "",
             "| elements per cable | element [cm] | dampers move the path [mm] | damped: change to the next finer [mm] "
             "| undamped: change to the next finer [mm] | slack samples, damped | slack samples, undamped "
             "| max error damped / undamped [mm] |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['n_elements']} | {100 * r['element_length_m']:.2f} | {mm(r['damping_moves_path_m'])} "
                     f"| {mm(r['change_to_finer_damped_m'])} | {mm(r['change_to_finer_undamped_m'])} "
                     f"| {100 * r['slack_sample_fraction_damped']:.1f} % | {100 * r['slack_sample_fraction_undamped']:.1f} % "
                     f"| {mm(r['max_error_damped_m'])} / {mm(r['max_error_undamped_m'])} |")
    lines += ["", "Continuum estimate of the dampers' tension step across the wrap, d_n J v / (2 r_p^2 lambda), "
              f"at the largest pay-out speed v = {estimate['pay_out_speed_m_per_s']:.3f} m/s and the bending length "
              f"lambda = sqrt(E J / T) = {estimate['bending_length_m']:.3f} m of the smallest anchor tension "
              f"T = {estimate['smallest_anchor_tension_N']:.1f} N ({COUNTS[-1]} elements): "
              f"{estimate['tension_step_N']:.1f} N.", ""]
    (out / "convergence.md").write_text("\n".join(lines))
    write_summary(out, {"scene": NAME, "after_s": AFTER, "rows": rows, "tension_step_estimate": estimate,
                        **provenance()})

    figure = Figure(figsize=(7.0, 3.6))
    FigureCanvasAgg(figure)
    axes = figure.add_subplot(1, 1, 1)
    for n in COUNTS:
        on, off = results[n, True], results[n, False]
        path = np.column_stack([np.interp(on.time, off.time, off.pose[:, k]) for k in range(3)])
        axes.plot(on.time, 1000 * np.linalg.norm(on.pose[:, :3] - path, axis=1), label=f"{n} elements")
    axes.set_xlabel("time [s]")
    axes.set_ylabel("damped - undamped path [mm]")
    axes.set_title("What the bending dampers do to the platform's path, over the discretisation")
    axes.legend()
    axes.grid(True, alpha=0.3)
    figure.tight_layout()
    figure.savefig(out / "lag.png", dpi=110)
    print("\n".join(lines))
    print(f"written to {out}/")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
