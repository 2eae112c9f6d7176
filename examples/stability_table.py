"""Largest stable step of the implicit solver, and of explicit RK44, on each hard case.

For the paper scene (tension-only elements, the default, and the paper's springs) and
every hard case of it (damping scaled by 1e-3 and 1e3, pulley
stiffness 1e5 and 1e9 N/m, 9, 50 and 100 elements per cable, a circle four times
faster, its cables going slack, a 0.1 kg and a 100 kg platform, a platform flung up until
its cables go slack, a winch paying out several elements over the pulley):

* Exudyn's implicit generalized-alpha (the project's solver): a ladder of steps
  2e-4 ... 5e-2 s climbed up to the first unstable rung, then two geometric
  bisections between it and the last stable rung (larger rungs that pass again are
  listed, not counted). A step is *stable* when both of these runs complete (no
  monitor stop, no solver failure, no NaN):
  - the case's own motion over 0.5 s, and its platform pose stays within 1 cm and
    0.05 rad of the same run at 1e-4 s;
  - the same robot held still (fixed winches, held reference, 0.5 s), and its total
    mechanical energy never rises after the start-up steps (t >= 5 h) by more than
    1e-4 J (no work is put in).
  The energy the very first steps inject (Exudyn carries the initial accelerations
  into the first step) is reported separately, with the largest step free of it.
* Exudyn's explicit RK44 on the held robot (RK44 cannot drive the winches): a ladder
  5e-4 ... 1e-8 s downwards, each run 2e-3 s long but at least 2000 and at most
  20 000 steps; the first stable rung from the top is the largest stable step.
  *Stable*: completes, no NaN, energy never rises by more than 1e-4 J, and the
  platform stays within 1e-5 m (or 1 % of its motion) of the implicit solver's
  answer at a step of min(run / 100, 1e-5 s) (the stiff joint spring of explicit runs stretches by 7.8e-6 m under the
  platform's weight). Below 1e-8 s the runs would take hours: reported as
  "< 1e-8". Also shown: the estimate 2.8 m_i / (4 c_i) of
  ``cdpr_exu.run.solver.explicit_step_limit``.

Writes ``stability.csv`` and ``stability.md`` (the table and these criteria) into
``results/stability/``. Run: ``python examples/stability_table.py [--quick]``;
about 10 minutes on two cores (``--quick``: three cases, a minute).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import math
import time
from pathlib import Path

import numpy as np

from cdpr_exu.results.energy import energy_rise, mechanical_energy
from cdpr_exu.core.errors import CdprError, SolverFailure
from cdpr_exu.core.output import write_json
from cdpr_exu.scenes.scene import Effects, Scene, WinchSpec, load_scene
from cdpr_exu.run.simulate import simulate
from cdpr_exu.run.solver import explicit_step_limit
from cdpr_exu.scenes.trajectories import CircleTrajectory, HoldTrajectory, PointToPointTrajectory

PAPER = load_scene("paper-circle")

#: Implicit ladder [s]; the reference step below it.
IMPLICIT_STEPS = [2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1e-2, 2e-2, 5e-2]
REFERENCE_STEP = 1e-4
RUN_TIME = 0.5  # [s] of the case's motion and of the held robot
POSITION_TOLERANCE = 0.01  # [m] from the 1e-4 s run
ROTATION_TOLERANCE = 0.05  # [rad]
ENERGY_TOLERANCE = 1e-4  # [J]
START_UP_STEPS = 5  # steps after which the held energy must not rise
#: Explicit ladder [s], from the top.
EXPLICIT_STEPS = [5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6, 5e-7, 2e-7, 1e-7, 5e-8, 2e-8, 1e-8]
EXPLICIT_TIME = 2e-3  # [s] simulated, but at least 2000 and at most 20 000 steps
EXPLICIT_MIN_STEPS = 2_000
EXPLICIT_MAX_STEPS = 20_000
EXPLICIT_TOLERANCE = 1e-5  # [m] from the implicit answer (or 1 % of the platform's motion)


# --------------------------------------------------------------------------- cases


def _cables(scene: Scene, **changes) -> Scene:
    return scene.with_changes(cables=tuple(dataclasses.replace(c, **changes) for c in scene.cables))


def _pulleys(scene: Scene, **changes) -> Scene:
    return scene.with_changes(exits=tuple(dataclasses.replace(p, **changes) for p in scene.exits))


def _platform_mass(scene: Scene, mass: float) -> Scene:
    platform = scene.platform
    return scene.with_changes(platform=dataclasses.replace(platform, mass=mass,
                                                           inertia=platform.inertia * mass / platform.mass))


def _springs(scene: Scene) -> Scene:
    return scene.with_changes(effects=Effects.from_preset("paper"))


def _payout(scene: Scene) -> Scene:
    start, end = (0.0, -0.8, 0.0), (0.0, -2.3, 0.0)
    return scene.with_changes(platform=dataclasses.replace(scene.platform, initial_pose=start),
                              trajectory=PointToPointTrajectory(start=start, end=end, duration=1.0))


#: name -> (what it is, the paper scene made hard in one respect; its own motion)
CASES = {
    "paper": ("the paper's parameters (15 elements, k_p 1e7 N/m), tension-only elements (the default)",
              lambda s: s),
    "paper, springs": ("the paper's spring elements, which also push (preset 'paper')", _springs),
    "damping x1e-3": ("axial and bending damping dn = 1e6 N s/m^2", lambda s: _cables(s, damping_constant=1e6)),
    "damping x1e3": ("dn = 1e12 N s/m^2 (viscous rods)", lambda s: _cables(s, damping_constant=1e12)),
    "k_p 1e5": ("pulley contact stiffness 1e5 N/m", lambda s: _pulleys(s, contact_stiffness=1e5)),
    "k_p 1e9": ("pulley contact stiffness 1e9 N/m", lambda s: _pulleys(s, contact_stiffness=1e9)),
    "9 elements": ("9 elements per cable (the coarsest accepted)", lambda s: _cables(s, n_elements=9)),
    "50 elements": ("50 elements per cable", lambda s: _cables(s, n_elements=50)),
    "100 elements": ("100 elements per cable", lambda s: _cables(s, n_elements=100)),
    "circle x4": ("angular rate 6 rad/s (R w^2 = 14.4 m/s^2 > g): the cables go slack",
                  lambda s: s.with_changes(trajectory=CircleTrajectory((0.0, -1.6), angular_rate=6.0))),
    "platform 0.1 kg": ("platform mass 0.1 kg (inertia scaled)", lambda s: _platform_mass(s, 0.1)),
    "platform 100 kg": ("platform mass 100 kg (inertia scaled)", lambda s: _platform_mass(s, 100.0)),
    "flung up": ("lift 0.4 m in 0.35 s (decelerating at 18.8 m/s^2 > g): the cables go slack",
                 lambda s: s.with_changes(trajectory=PointToPointTrajectory(
                            start=(0.0, -2.0, 0.0), end=(0.0, -1.6, 0.0), duration=0.35))),
    "fast pay-out": ("lower 1.5 m in 1 s (run 1 s): 1.1 m, 4.4 elements, paid out over the pulley", _payout),
}
#: Cases whose own motion runs longer than RUN_TIME [s].
RUN_TIMES = {"fast pay-out": 1.0}
QUICK = ["paper", "damping x1e-3", "platform 100 kg"]


def moving_scene(name: str, step: float) -> Scene:
    scene = CASES[name][1](PAPER)
    return scene.with_changes(solver=dataclasses.replace(
        scene.solver, end_time=RUN_TIMES.get(name, RUN_TIME), step_size=step, output_period=max(0.005, step)))


def held_scene(name: str, step: float, end_time: float = RUN_TIME, output_period: float | None = None,
               integrator: str = "generalized_alpha") -> Scene:
    scene = CASES[name][1](PAPER)
    scene = scene.with_changes(trajectory=HoldTrajectory(tuple(scene.platform.initial_pose)),
                               winch=WinchSpec(kind="fixed"))
    return scene.with_changes(solver=dataclasses.replace(
        scene.solver, end_time=end_time, step_size=step, integrator=integrator,
        output_period=output_period if output_period is not None else max(0.01, step)))


# --------------------------------------------------------------------------- checks


def finite(result) -> bool:
    return all(np.all(np.isfinite(a)) for a in [result.pose, result.velocity,
                                                 *result.nodes, *result.tensions])


def attempt(scene: Scene):
    """(result or None, why it is not usable or None, wall time)."""
    start = time.perf_counter()
    try:
        result = simulate(scene)
    except SolverFailure as failure:
        return None, _short_reason(str(failure)), time.perf_counter() - start
    except CdprError as err:
        return None, f"refused: {err}", time.perf_counter() - start
    if not finite(result):
        return None, "NaN in the result", time.perf_counter() - start
    return result, None, time.perf_counter() - start


def _short_reason(message: str) -> str:
    """The core of a SolverFailure message: what stopped the run, and when."""
    head = message.split("Likely cause:")[0].strip().rstrip(".")
    if "): " in head:
        head = head.split("): ", 1)[1]
    return head[:160]


def pose_deviation(result, reference) -> tuple[float, float]:
    """Largest position [m] and rotation [rad] difference from the reference, interpolated in time."""
    positions, rotation = 0.0, 0.0
    for k in range(3):
        ref = np.interp(result.time, reference.time, reference.pose[:, k])
        diff = np.abs(result.pose[:, k] - ref)
        if k < 2:
            positions = max(positions, float(diff.max()))
        else:
            rotation = float(diff.max())
    return positions, rotation


# --------------------------------------------------------------------------- implicit


def implicit_check(name: str, step: float, reference) -> dict:
    """Is ``step`` stable for case ``name``? With the figures that decide it."""
    out = {"step": step, "stable": False, "reason": "", "start_up_rise_J": math.nan, "wall_s": 0.0}
    moving, why, wall = attempt(moving_scene(name, step))
    out["wall_s"] += wall
    if moving is None:
        out["reason"] = f"own motion: {why}"
        return out
    if reference is not None:
        position, rotation = pose_deviation(moving, reference)
        out["deviation_m"], out["deviation_rad"] = position, rotation
        if position > POSITION_TOLERANCE or rotation > ROTATION_TOLERANCE:
            out["reason"] = f"own motion off the 1e-4 s answer by {1000 * position:.1f} mm, {rotation:.3f} rad"
            return out
    scene = held_scene(name, step)
    held, why, wall = attempt(scene)
    out["wall_s"] += wall
    if held is None:
        out["reason"] = f"held: {why}"
        return out
    energy = mechanical_energy(scene, held)
    after = held.time >= START_UP_STEPS * step - 1e-9
    out["start_up_rise_J"] = energy_rise(energy)
    late_rise = energy_rise(energy[after])
    if late_rise > ENERGY_TOLERANCE:
        out["reason"] = f"held: energy rises by {late_rise:.3g} J after the start-up"
        return out
    out["stable"] = True
    return out


def implicit_ladder(name: str) -> dict:
    """Climb the ladder until the first unstable rung; bisect twice between it and the last stable one."""
    reference, why, wall = attempt(moving_scene(name, REFERENCE_STEP))
    total = wall
    checks = []
    for step in IMPLICIT_STEPS:
        check = implicit_check(name, step, reference)
        total += check["wall_s"]
        checks.append(check)
        print(f"    implicit {step:8.1e} s: {'stable' if check['stable'] else 'NOT: ' + check['reason']}", flush=True)
    row = {"reference": "ok" if reference is not None else f"reference failed: {why}"}
    failing = [c for c in checks if not c["stable"]]
    first_unstable = failing[0] if failing else None
    below = [c for c in checks if c["stable"] and (first_unstable is None or c["step"] < first_unstable["step"])]
    passes_again = [c["step"] for c in checks if c["stable"] and first_unstable is not None
                    and c["step"] > first_unstable["step"]]
    if not below:
        row.update(largest=None, first_unstable=checks[0]["step"], why=checks[0]["reason"], jolt=None,
                   jolt_free=None, wall=total, passes_again=passes_again)
        return row
    best = below[-1]
    if first_unstable is not None:  # two geometric bisections between the rungs
        low, high = best, first_unstable
        for _ in range(2):
            middle = implicit_check(name, math.sqrt(low["step"] * high["step"]), reference)
            total += middle["wall_s"]
            print(f"    implicit {middle['step']:8.2e} s: "
                  f"{'stable' if middle['stable'] else 'NOT: ' + middle['reason']}", flush=True)
            low, high = (middle, high) if middle["stable"] else (low, middle)
        best, first_unstable = low, high
    jolt_free = [c["step"] for c in below if c["start_up_rise_J"] <= ENERGY_TOLERANCE]
    row.update(largest=best["step"], first_unstable=first_unstable["step"] if first_unstable else None,
               why=first_unstable["reason"] if first_unstable else "stable up to the largest rung",
               jolt=best["start_up_rise_J"], jolt_free=max(jolt_free) if jolt_free else None,
               deviation_m=best.get("deviation_m"), wall=total, passes_again=passes_again)
    return row


# --------------------------------------------------------------------------- explicit


def explicit_run_length(step: float) -> float:
    """EXPLICIT_TIME, but at least EXPLICIT_MIN_STEPS and at most EXPLICIT_MAX_STEPS steps [s]."""
    steps = min(max(EXPLICIT_TIME / step, EXPLICIT_MIN_STEPS), EXPLICIT_MAX_STEPS)
    return round(steps) * step


def explicit_ladder(name: str) -> dict:
    estimate = explicit_step_limit(held_scene(name, 1e-3))
    total, tried, why = 0.0, [], ""
    for step in EXPLICIT_STEPS:
        end = explicit_run_length(step)
        scene = held_scene(name, step, end_time=end, output_period=end / 10, integrator="rk44")
        result, why, wall = attempt(scene)
        total += wall
        if result is not None:
            rise = energy_rise(mechanical_energy(scene, result))
            reference_step = min(end / 100, 1e-5)
            implicit, _, wall = attempt(held_scene(name, reference_step, end_time=end, output_period=end / 10))
            total += wall
            deviation = math.inf if implicit is None else float(
                np.abs(result.pose[:, :2] - implicit.pose[:, :2]).max())
            moved = 0.0 if implicit is None else float(
                np.abs(implicit.pose[:, :2] - implicit.pose[0, :2]).max())
            tolerance = max(EXPLICIT_TOLERANCE, 0.01 * moved)
            if rise > ENERGY_TOLERANCE:
                why = f"energy rises by {rise:.3g} J"
            elif deviation > tolerance:
                why = f"{deviation:.2g} m off the implicit answer"
            else:
                print(f"    RK44     {step:8.1e} s: stable ({end:.2g} s simulated)", flush=True)
                return {"largest": step, "first_unstable": tried[-1] if tried else None, "estimate": estimate,
                        "simulated": end, "wall": total, "why": ""}
        print(f"    RK44     {step:8.1e} s: NOT: {why}", flush=True)
        tried.append(step)
    return {"largest": None, "first_unstable": tried[-1], "estimate": estimate, "simulated": None,
            "wall": total, "why": why}


# --------------------------------------------------------------------------- output


def _s(value) -> str:
    return "" if value is None or (isinstance(value, float) and math.isnan(value)) else f"{value:.3g}"


def write(rows: list[dict], out: Path, wall: float) -> None:
    out.mkdir(parents=True, exist_ok=True)
    fields = ["case", "description", "implicit_largest_stable_step_s", "implicit_first_unstable_step_s",
              "implicit_unstable_because", "implicit_start_up_energy_jolt_J", "implicit_largest_jolt_free_step_s",
              "implicit_deviation_at_largest_m", "rk44_largest_stable_step_s", "rk44_estimated_limit_s",
              "rk44_first_unstable_step_s", "step_ratio_implicit_to_rk44"]
    with open(out / "stability.csv", "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=fields)
        writer.writeheader()
        for r in rows:
            imp, exp = r["implicit"], r["explicit"]
            ratio = imp["largest"] / exp["largest"] if imp["largest"] and exp["largest"] else None
            writer.writerow({
                "case": r["case"], "description": r["description"],
                "implicit_largest_stable_step_s": _s(imp["largest"]),
                "implicit_first_unstable_step_s": _s(imp["first_unstable"]),
                "implicit_unstable_because": imp["why"],
                "implicit_start_up_energy_jolt_J": _s(imp["jolt"]),
                "implicit_largest_jolt_free_step_s": _s(imp["jolt_free"]),
                "implicit_deviation_at_largest_m": _s(imp.get("deviation_m")),
                "rk44_largest_stable_step_s": _s(exp["largest"]) if exp["largest"] else f"< {EXPLICIT_STEPS[-1]:g}",
                "rk44_estimated_limit_s": _s(exp["estimate"]),
                "rk44_first_unstable_step_s": _s(exp["first_unstable"]),
                "step_ratio_implicit_to_rk44": _s(ratio),
            })
    # Wall-clock figures change from run to run: in the untracked timing.json, not in the tables.
    write_json(out / "timing.json", {"wall_time_s": wall, "cases": [
        {"case": r["case"], "implicit_wall_time_s": r["implicit"]["wall"], "rk44_wall_time_s": r["explicit"]["wall"]}
        for r in rows]})
    lines = [
        "# Largest stable step: implicit generalized-alpha vs explicit RK44",
        "",
        "Written by `examples/stability_table.py` (its wall times in timing.json). Paper scene "
        f"(`paper-circle`, spectral radius {PAPER.solver.spectral_radius:g}, modified Newton), one hard change per row.",
        "",
        "| case | implicit: largest stable step [s] | first unstable [s], why | start-up energy jolt at it [J] "
        "| largest jolt-free step [s] | RK44: largest stable step [s] | RK44 estimate [s] | ratio |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        imp, exp = r["implicit"], r["explicit"]
        ratio = imp["largest"] / exp["largest"] if imp["largest"] and exp["largest"] else None
        unstable = f"{_s(imp['first_unstable'])}: {imp['why']}" if imp["first_unstable"] else imp["why"]
        rk44 = _s(exp["largest"]) if exp["largest"] else f"< {EXPLICIT_STEPS[-1]:g}"
        largest = _s(imp["largest"]) if imp["largest"] else f"none >= {IMPLICIT_STEPS[0]:g}"
        if imp.get("passes_again"):
            largest += f" (passes again at {', '.join(f'{h:g}' for h in imp['passes_again'])})"
        lines.append(f"| {r['case']} | {largest} | {unstable} | {_s(imp['jolt'])} | {_s(imp['jolt_free'])} "
                     f"| {rk44} | {_s(exp['estimate'])} | {_s(ratio) or '-'} |")
    ratios = [r["implicit"]["largest"] / r["explicit"]["largest"] for r in rows
              if r["implicit"]["largest"] and r["explicit"]["largest"]]
    estimates = [(r["explicit"]["largest"], r["explicit"]["estimate"]) for r in rows if r["explicit"]["largest"]]
    never = [r["case"] for r in rows if not r["implicit"]["largest"]]
    lines += [""]
    if ratios:
        lines.append(f"Where both are known, the implicit solver's largest stable step is {min(ratios):.2g} to "
                     f"{max(ratios):.2g} times RK44's.")
    if estimates:
        lines.append("RK44's largest stable rung lies within a factor of "
                     f"{max(max(e / s, s / e) for s, e in estimates):.2g} of the estimate.")
    if never:
        lines.append(f"No implicit step is stable for {', '.join(never)}: every run is stopped by the "
                     "plausibility monitor, whatever the step (see 'why').")
    jolted = [r["case"] for r in rows if r["implicit"]["jolt"] and r["implicit"]["jolt"] > ENERGY_TOLERANCE]
    if jolted:
        lines.append(f"At their largest stable step, {len(jolted)} of {len(rows)} cases gain energy in the "
                     "start-up steps (column 4); free of that, the steps are those of column 5.")
    lines += [
        "",
        "Cases: " + "; ".join(f"**{r['case']}**: {r['description']}" for r in rows) + ".",
        "",
        "## Criteria",
        "",
        "**Implicit** (Exudyn's generalized-alpha as `cdpr_exu.run.simulate` sets it up): steps "
        f"{', '.join(f'{h:g}' for h in IMPLICIT_STEPS)} s, climbed up to the first unstable rung, then "
        "two geometric bisections between it and the last stable rung; larger rungs that pass again "
        "are listed in brackets but not counted (stability must hold for every smaller step). "
        "A step is stable when",
        "",
        f"1. the case's own motion over {RUN_TIME} s completes: no stop by the plausibility monitor "
        "(strain beyond 5 %, an element cutting half a radius into a pulley, the platform leaving the "
        "workspace or rising above the pulleys), no solver failure, no NaN;",
        f"2. its platform pose stays within {1000 * POSITION_TOLERANCE:g} mm and {ROTATION_TOLERANCE} rad of "
        f"the same run at {REFERENCE_STEP:g} s (interpolated to the run's output times);",
        f"3. the same robot held still (fixed winches, held reference, {RUN_TIME} s; no work put in) "
        "completes without NaN, and its total mechanical energy (kinetic, gravitational, axial, bending, "
        f"pulley contact) never rises by more than {ENERGY_TOLERANCE:g} J after the first "
        f"{START_UP_STEPS} steps.",
        "",
        "The *start-up energy jolt* is the energy the held run gains in its first steps: Exudyn "
        "carries the consistent initial accelerations into the first step "
        "(`generalizedAlpha.computeInitialAccelerations`, on in `solver_settings`), although the "
        "Kelvin-Voigt damping would stop them within microseconds. The *largest jolt-free step* is the "
        f"largest stable rung whose held energy never rises at all (by {ENERGY_TOLERANCE:g} J).",
        "",
        "**Explicit RK44** (Exudyn's classical Runge-Kutta, `solver.integrator = \"rk44\"`): on the held "
        "robot only, since Exudyn's explicit solvers eliminate the winch constraints and ignore their "
        "commands; the platform joints are the stiff spring-dampers of "
        "`cdpr_exu.builder.platform.explicit_joint_spring`. Steps "
        f"{', '.join(f'{h:g}' for h in EXPLICIT_STEPS)} s from the top, each run {EXPLICIT_TIME:g} s "
        f"long but at least {EXPLICIT_MIN_STEPS} and at most {EXPLICIT_MAX_STEPS} steps (an unstable "
        "step grows the error by a fixed factor per step, so thousands of steps show it); the first "
        "stable rung is the largest stable step. Stable: completes without NaN or monitor stop, energy "
        f"never rises by more than {ENERGY_TOLERANCE:g} J, and the platform stays within "
        f"{EXPLICIT_TOLERANCE:g} m (or 1 % of its motion) of the implicit solver's answer (step "
        "min(run / 100, 1e-5 s)). *RK44 estimate*: 2.8 / max(4 c_i / m_i, 2 sqrt(k_i / m_i) (+) sqrt(k_p / m_i)) "
        "(`cdpr_exu.run.solver.explicit_step_limit`): the zig-zag mode of the over-damped axial chain. "
        f"'< {EXPLICIT_STEPS[-1]:g}': not stable at any rung; smaller steps would take hours.",
    ]
    (out / "stability.md").write_text("\n".join(lines) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(Path(__file__).resolve().parent.parent / "results" / "stability"))
    parser.add_argument("--quick", action="store_true", help=f"only {', '.join(QUICK)}")
    args = parser.parse_args()
    start = time.perf_counter()
    rows = []
    for name in (QUICK if args.quick else CASES):
        print(f"{name}: {CASES[name][0]}", flush=True)
        implicit = implicit_ladder(name)
        explicit = explicit_ladder(name)
        rows.append({"case": name, "description": CASES[name][0], "implicit": implicit, "explicit": explicit})
        print(f"  -> implicit {_s(implicit['largest']) or 'none'} s, RK44 {_s(explicit['largest']) or '< 1e-8'} s "
              f"(estimate {_s(explicit['estimate'])} s); {time.perf_counter() - start:.0f} s so far", flush=True)
    write(rows, Path(args.out), time.perf_counter() - start)
    print(f"written to {args.out}/stability.csv and stability.md in {(time.perf_counter() - start) / 60:.1f} min")


if __name__ == "__main__":
    main()
