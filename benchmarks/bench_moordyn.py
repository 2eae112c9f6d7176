"""Side by side with MoorDyn: two lumped-mass lines holding a 1 kg point mass.

The paper's static scene with the cable ends fixed at the pulley centres
(``paper-catenary-fixed``): two lines of 15 segments (the paper's cable, Table 2)
from (-1.75, 0) and (1.75, 0) m hold a 1 kg point mass; both start straight and
unstrained and drop under gravity for 10 s. Like physics on both sides: axial
stiffness, axial Kelvin-Voigt damping, consistent lumped masses, gravity; no bending,
no pulley contact, no fluid (MoorDyn: water density, drag and added mass 0).

Two dampings:

- the paper's, d_n = 1e9 N s/m^2 (BA = d_n A = 78 540 N s): over-damped axial modes,
  c_i / m_i ~ 1e7 1/s. MoorDyn is explicit (its default RK2) and is stable only near
  6e-8 s steps. By default a short stretch (2 ms) is timed and the time scaled to 10 s
  (said in the output; no final position). With ``--full`` MoorDyn runs the whole 10 s
  (978 s measured here, ~16 min on one core; progress on stderr every simulated second).
- 0.8 of critical per segment (MoorDyn's ``BA = -0.8``: c = 0.8 l sqrt(E rho)): both
  codes run the full 10 s.

Our side: ``Effects.from_preset("catenary", pulley_contact=False)`` on the scene,
Exudyn's implicit generalized-alpha at the scene's step (2e-3 s) and spectral radius
(0: numerical damping of the stiff modes), and at spectral radius 1 (none); started
from zero accelerations (the default). With ``--full`` or ``--moordyn-from`` also with
the "consistent start" (``SolverSpec.initial_accelerations=True``: Exudyn's
``computeInitialAccelerations``), at ``--consistent-steps`` (default 2e-3, 5e-4,
1e-4 s; spectral radius 0 and 1). From zero accelerations our error of this drop from
rest is of first order in the step; with the consistent start, of second order.

MoorDyn starts its lines on a catenary profile; this script overwrites the line
states (through ``Serialize``/``Deserialize``) with the straight lines of our model,
so that both drop from straight. MoorDyn's frame is 3D with z up: our (x, z) is its
(x, z) with the whole scene 10 m below its free surface.

Accuracy (both cases; at the paper's damping only with ``--full``): the point mass's
(x, z) is recorded by both codes at common output times (every 0.01 s to 0.2 s, then
every 0.1 s) and a table gives, per run, the wall time, MoorDyn's wall time / the
run's, and the distance to MoorDyn's path: max over 0-10 s, at 10 s, max over
0-0.2 s, and a self-error (ours: to our finest step at the same spectral radius and
start; MoorDyn: to MoorDyn at half its step). ``--full`` adds our runs at finer steps
(``--steps``, default 2e-3, 5e-4, 1e-4, 1e-5 s; spectral radius 0 and 1) and MoorDyn at
half its step: 3e-8 s over the first 0.2 s (``--check-time``) at the paper's damping,
1e-4 s over 10 s at the moderate one.

``--moordyn-from PATH`` reads MoorDyn's runs (paths and wall times, both dampings) from
a JSON written by ``--full --json`` instead of running MoorDyn again, and runs ours as
``--full`` does (~6 min). The output says so; the ratios use the stored MoorDyn wall
times. MoorDyn is only re-timed briefly as a check of the machine's speed against the
stored run (the paper case: a 2 ms stretch scaled to 10 s; the moderate case: the full
0.5 s run, whose path is also compared with the stored one).

Verified with ``--full`` (2026-11-23; cdpr-exu at commit 86a7149, Exudyn 1.13.6,
MoorDyn 2.7.2, Python 3.11; 2-core machine shared with other work; ~22 min in all,
of which MoorDyn at the paper's damping 978 s + 40 s for its half-step check and our
1e-5 s runs ~1 min each). Numbers in ``benchmarks/results/moordyn_full.json`` (paths
included), printed output in ``benchmarks/results/moordyn_full.txt``; made by
``python benchmarks/bench_moordyn.py --full --json /tmp/moordyn_full.json``.
MoorDyn's own time error at the paper's damping is nil for the purpose: dtM 6e-8
and 3e-8 s give paths 3e-12 m apart over 0-0.2 s (its step is set by stability, not
accuracy). At the moderate damping it is not: dtM 2e-4 s (its stability limit) and
1e-4 s are 2.7 um apart, so its 2e-4 s path is ~3.6 um from its own h -> 0 limit
(Richardson, RK2 being second order).

Verified with ``--moordyn-from`` (2026-11-23; cdpr-exu at commit e8b8fcd, the rest as
above; 5 min 43 s): ``python benchmarks/bench_moordyn.py --moordyn-from
benchmarks/results/moordyn_full.json --json benchmarks/results/moordyn_reuse.json >
benchmarks/results/moordyn_reuse.txt``. MoorDyn's paths and wall times (978 s; 0.47 s)
are those of ``moordyn_full.json``; the timing check gave 977 s and 0.34 s (the
latter's path identical to the stored one). Our zero-start paths are identical to those
of ``moordyn_full.json``. Max distance to MoorDyn's path over 0-10 s, spectral radius 0 /
1, and MoorDyn's (stored) wall time / ours:

- Paper's damping. Zero start: h = 2e-3 s: 1.51 / 0.84 mm, 944 / 1260 x; 5e-4 s:
  0.22 / 0.18 mm, 500 / 423 x; 1e-4 s: 0.037 / 0.035 mm, 117 / 142 x; 1e-5 s: 3.5 /
  3.5 um, 15 / 13 x (first order). Consistent start: 2e-3 s: 0.99 / 0.19 mm, 1110 /
  1340 x; 5e-4 s: 0.064 / 0.012 mm, 396 / 565 x; 1e-4 s: 2.7 / 0.47 um, 112 / 135 x
  (second order: x 1/16 per 1/4 of the step, x 1/25 per 1/5). Richardson-extrapolating the
  consistent-start paths at 5e-4 and 1e-4 s (spectral radius 1) lands 1 nm from MoorDyn's
  path: the models agree; what is left is our time error. Target "100 x faster at equal
  accuracy": met to 0.5 um with the consistent start (1e-4 s, rho 1: 0.47 um at 135 x;
  rho 0: 2.7 um at 112 x), against 35 um from zero accelerations at the same cost; 12 um
  at 565 x (5e-4 s, rho 1). Literal equality with MoorDyn's own 3e-12 m is out of reach
  at any practical step.
- Moderate damping (MoorDyn 0.47 s stored). Zero start: 2e-3 s: 1.71 / 0.89 mm, 1.22 /
  1.22 x (ours faster); 5e-4 s: 0.24 / 0.19 mm, 0.30 / 0.34 x (3.0-3.3 x slower); 1e-4
  s: 0.040 / 0.038 mm, 13 x slower; 1e-5 s: 6.8 um, 120-140 x slower. Consistent start:
  2e-3 s: 1.17 / 0.28 mm, 1.24 / 1.25 x (ours faster); 5e-4 s: 0.080 / 0.019 mm, 0.31 /
  0.36 x (3.2 / 2.8 x slower); 1e-4 s: 6.6 / 4.2 um, 12 / 14 x slower; most of the last
  4.2 um is MoorDyn's own error (ours is 1.0 um from MoorDyn's extrapolated path).
  Target "within a factor 3 of MoorDyn": met at the scene's step (faster, to 0.28 mm with
  the consistent start and rho 1) and at 5e-4 s (rho 1, consistent start: 2.8 x slower,
  to 19 um), but not at MoorDyn's own accuracy (~3.6 um): a check run outside the table
  (consistent start, rho 1, h = 2e-4 s) is 3.0 um from MoorDyn's extrapolated path in
  3.7 s, 8 x MoorDyn's stored 0.47 s (11 x its 0.34 s of the timing check).

Run: ``python benchmarks/bench_moordyn.py [--short 0.002] [--full | --moordyn-from PATH]
[--steps 2e-3,...] [--consistent-steps 2e-3,...] [--json PATH]``. Needs ``pip install
moordyn`` (the ``moordyn`` extra); without it, the script says so and exits cleanly
(with ``--moordyn-from`` it runs, without the timing check). Without ``--full`` or
``--moordyn-from`` it takes a few seconds. Timings are
wall times on this (shared) machine, one process each; compare ratios (they vary by
~20-50 % from run to run on the shared machine).
"""

from __future__ import annotations

import argparse
import contextlib
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from cdpr_exu.scenes.scene import Effects, load_scene
from cdpr_exu.run.simulate import simulate

END_TIME = 10.0
#: MoorDyn's scene sits this far below its free surface [m] (no fluid anyway).
DEPTH_OFFSET = 10.0
#: Fraction of critical damping per segment of the moderate case (MoorDyn's -BA).
DAMPING_RATIO = 0.8
#: MoorDyn's coupling step and the sampling period of the compared paths [s].
COUPLING_STEP = 0.01
#: The paths are compared every COUPLING_STEP up to this many coupling steps (0.2 s) ...
DENSE_UNTIL_TICKS = 20
#: ... then every SPARSE_TICKS coupling steps (0.1 s).
SPARSE_TICKS = 10
#: End of the drop's transient [s]: the span of MoorDyn's half-step check at the paper's damping.
EARLY_TIME = DENSE_UNTIL_TICKS * COUPLING_STEP


@contextlib.contextmanager
def _quiet_stdout():
    """Silence MoorDyn's C++ console output (it prints every coupling step)."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)


def moordyn_input(scene, axial_damping_ns: float, time_step: float) -> str:
    """MoorDyn v2 input file of the scene's two lines and point mass."""
    cable = scene.cables[0]
    (xa, za), (xb, zb) = scene.exits[0].point, scene.exits[1].point
    x0, z0, _ = scene.platform.initial_pose
    d = -DEPTH_OFFSET
    return f"""--------------------- MoorDyn Input File -------------------------------------
cdpr-exu: two cables holding a point mass (paper-catenary-fixed), no fluid
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA     BA/-zeta    EI    Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)    (N-s/-)     (N-m^2) (-)  (-)    (-)     (-)
cable      {2 * cable.radius!r}  {cable.linear_density!r}  {cable.axial_rigidity!r}  {axial_damping_ns!r}  0.0  0.0  0.0  0.0  0.0
---------------------- POINTS --------------------------------
ID   Attachment  X       Y     Z     M      V     CdA   CA
(#)   (-)        (m)    (m)   (m)   (kg)   (m^3)  (m^2) (-)
1     Fixed     {xa!r}    0    {za + d!r}     0      0      0     0
2     Fixed     {xb!r}    0    {zb + d!r}     0      0      0     0
3     Free      {x0!r}    0    {z0 + d!r}  {scene.platform.mass!r}    0      0     0
---------------------- LINES --------------------------------------
ID    LineType   AttachA  AttachB  UnstrLen  NumSegs   Outputs
(#)   (name)     (#)      (#)      (m)       (-)       (-)
1     cable      1        3        {cable.unstrained_length!r}  {cable.n_elements}   -
2     cable      2        3        {cable.unstrained_length!r}  {cable.n_elements}   -
---------------------- OPTIONS -----------------------------------------
0        writeLog
{time_step!r}     dtM
{scene.gravity!r}      g
0.0      WtrDnsty
1000     WtrDpth
0        TmaxIC
----------------------- OUTPUTS --------------------------------------------
END
------------------------- need this line --------------------------------------
"""


def _start_straight(moordyn, system, n_lines: int) -> int:
    """Overwrite MoorDyn's catenary initial line profiles with straight lines.

    Finds each interior node's (x, y, z) in the serialized state and replaces every
    occurrence by the point on the straight line between the line's ends. Returns the
    number of node triples replaced (at least one per interior node, else it raises).
    """
    data = bytearray(moordyn.Serialize(system))
    values = np.frombuffer(data[: len(data) // 8 * 8], dtype=np.float64).copy()
    replaced = 0
    for number in range(1, n_lines + 1):
        line = moordyn.GetLine(system, number)
        count = moordyn.GetLineNumberNodes(line)
        first = np.array(moordyn.GetLineNodePos(line, 0))
        last = np.array(moordyn.GetLineNodePos(line, count - 1))
        for i in range(1, count - 1):
            node = np.array(moordyn.GetLineNodePos(line, i))
            straight = first + (last - first) * i / (count - 1)
            hits = [k for k in np.flatnonzero(values[:-2] == node[0])
                    if values[k + 1] == node[1] and values[k + 2] == node[2]]
            if not hits:
                raise RuntimeError(f"MoorDyn line {number} node {i} not found in its serialized state")
            for k in hits:
                values[k:k + 3] = straight
                replaced += 1
    data[: values.size * 8] = values.tobytes()
    moordyn.Deserialize(system, bytes(data))
    return replaced


def common_output_times(end_time: float = END_TIME) -> np.ndarray:
    """Output times shared by both codes [s]: every 0.01 s to 0.2 s, then every 0.1 s."""
    ticks = [k for k in range(int(round(end_time / COUPLING_STEP)) + 1)
             if k <= DENSE_UNTIL_TICKS or k % SPARSE_TICKS == 0]
    return np.array(ticks) * COUPLING_STEP


def run_moordyn(scene, axial_damping_ns: float, time_step: float, end_time: float,
                coupling_step: float = COUPLING_STEP, record: bool = False,
                progress: str | None = None) -> dict:
    """Run MoorDyn to ``end_time``; wall time [s] and the point mass's final (x, z) [m].

    ``record``: also store the point mass's (x, z) at :func:`common_output_times` (needs
    the default coupling step). ``progress``: a label; if given, print the simulated
    and the elapsed wall time to stderr every simulated second.
    """
    import moordyn

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "lines.txt"
        path.write_text(moordyn_input(scene, axial_damping_ns, time_step))
        with _quiet_stdout():
            system = moordyn.Create(str(path))
            moordyn.Init_NoIC(system, [], [])
            _start_straight(moordyn, system, 2)
            point = moordyn.GetPoint(system, 3)
            start_position = np.array(moordyn.GetPointPos(point))
            line = moordyn.GetLine(system, 1)
            straightness = _max_deviation_from_chord(
                [moordyn.GetLineNodePos(line, i) for i in range(moordyn.GetLineNumberNodes(line))])
            coupling_step = min(coupling_step, end_time)
            steps = int(round(end_time / coupling_step))
            if record and not math.isclose(coupling_step, COUPLING_STEP):
                raise ValueError("recording needs the default coupling step")
            record_ticks = {int(round(t / COUPLING_STEP)) for t in common_output_times(end_time)} if record else set()
            ticks_per_second = int(round(1.0 / coupling_step))
            times, path_xz = [], []

            def store(k):
                p = moordyn.GetPointPos(point)
                times.append(k * coupling_step)
                path_xz.append((p[0], p[2] + DEPTH_OFFSET))

            if 0 in record_ticks:
                store(0)
            start = time.perf_counter()
            t = 0.0
            try:
                for k in range(1, steps + 1):
                    moordyn.Step(system, [], [], t, coupling_step)
                    t = k * coupling_step
                    if k in record_ticks:
                        store(k)
                    if progress and k % ticks_per_second == 0:
                        elapsed = time.perf_counter() - start
                        print(f"[MoorDyn {progress}] t = {t:5.2f} s of {end_time:g} s, wall {elapsed:8.1f} s, "
                              f"expected total {elapsed * end_time / t:8.1f} s", file=sys.stderr, flush=True)
                position = np.array(moordyn.GetPointPos(point))
            except RuntimeError:  # MoorDyn raises when its explicit integration blows up (NaN)
                position = np.full(3, np.nan)
            wall = time.perf_counter() - start
            scheme = moordyn.GetTimeScheme(system) if hasattr(moordyn, "GetTimeScheme") else None
            moordyn.Close(system)
    finite = bool(np.all(np.isfinite(position)))
    return {"wall_time": wall, "simulated": t, "position": (position[0], position[2] + DEPTH_OFFSET),
            "start": (start_position[0], start_position[2] + DEPTH_OFFSET), "finite": finite,
            "initial_sag": straightness, "scheme": scheme or "RK2 (default)", "step": time_step,
            "times": np.array(times), "path": np.array(path_xz).reshape(-1, 2)}


def _max_deviation_from_chord(points) -> float:
    points = np.asarray(points, dtype=float)
    chord = points[-1] - points[0]
    chord /= np.linalg.norm(chord)
    offsets = points - points[0]
    return float(np.linalg.norm(offsets - np.outer(offsets @ chord, chord), axis=1).max())


def largest_stable_step(scene, axial_damping_ns: float, candidates, probe_time: float) -> float | None:
    """The largest MoorDyn step among ``candidates`` that stays finite over ``probe_time``."""
    for step in sorted(candidates, reverse=True):
        run = run_moordyn(scene, axial_damping_ns, step, probe_time, coupling_step=probe_time)
        if run["finite"] and abs(run["position"][1] - run["start"][1]) < 0.5:
            return step
    return None


def load_stored_moordyn(path: Path, scene_name: str, end_time: float) -> dict:
    """MoorDyn's runs stored by ``--full --json``: per case (by d_n) the full run and its half-step check.

    Returns ``{"source": {...}, "cases": [{"d_n", "BA", "moordyn", "moordyn_half_step"}, ...]}``;
    a case's ``moordyn`` is None unless its MoorDyn path was stored. Paths are cut to
    ``end_time`` (which must not exceed the stored run's) and checked against
    :func:`common_output_times`.
    """
    data = json.loads(Path(path).read_text())
    if data.get("scene") != scene_name:
        raise ValueError(f"{path}: scene {data.get('scene')!r}, not {scene_name!r}")
    if end_time > data["end_time"] + 1e-9:
        raise ValueError(f"{path}: stored runs end at {data['end_time']:g} s, before --end-time {end_time:g} s")
    expected = common_output_times(end_time)

    def moordyn_run(run):
        run = dict(run)
        keep = np.asarray(run.get("times") or [], dtype=float) <= end_time + 1e-9
        run["times"] = np.asarray(run.get("times") or [], dtype=float)[keep]
        run["path"] = np.asarray(run.get("path") or [], dtype=float).reshape(-1, 2)[keep]
        run["position"] = tuple(math.nan if v is None else v for v in run.get("position") or (None, None))
        run["stored"] = True
        simulated = run.get("simulated") or data["end_time"]
        if end_time < simulated - 1e-9:  # --end-time shorter than the stored run: its start, wall time scaled
            run["wall_time"] *= end_time / simulated
            run["simulated"] = end_time
            run["position"] = tuple(run["path"][-1])
            run["wall_time_kind"] = run.get("wall_time_kind", "measured") + f", scaled to {end_time:g} s"
        return run

    cases = []
    for case in data["cases"]:
        runs = [r for r in case["runs"] if r.get("code") == "moordyn"]
        full = [r for r in runs if str(r.get("wall_time_kind", "")).startswith("measured") and r.get("path")]
        md = moordyn_run(full[0]) if full else None
        if md is not None and md["simulated"] + 1e-9 < end_time:
            md = None
        if md is not None and (len(md["times"]) != len(expected) or np.max(np.abs(md["times"] - expected)) > 1e-9):
            raise ValueError(f"{path}: MoorDyn's stored output times of case {case['name']!r} are not the common ones")
        half = [moordyn_run(r) for r in runs if md is not None and r is not full[0] and r.get("path")
                and math.isclose(r["step"], md["step"] / 2)]
        cases.append({"name": case["name"], "d_n": case["d_n"], "BA": case["BA"], "moordyn": md,
                      "moordyn_half_step": half[0] if half else None})
    source = {"file": str(path), "date": data.get("date"), "command": data.get("command"),
              "versions": data.get("versions"), "provenance_note": data.get("provenance_note")}
    return {"source": source, "cases": cases}


def stored_case(stored: dict | None, d_n: float) -> dict | None:
    """The stored case of damping ``d_n`` with a MoorDyn path, or None."""
    for case in (stored or {}).get("cases", ()):
        if math.isclose(case["d_n"], d_n, rel_tol=1e-9) and case["moordyn"] is not None:
            return case
    return None


def run_ours(scene, damping_constant: float, spectral_radius: float, step_size: float | None = None,
             end_time: float = END_TIME, initial_accelerations: bool = False) -> dict:
    """Our implicit model at ``step_size`` (default: the scene's); (x, z) at the common times.

    ``initial_accelerations``: start generalized-alpha from the consistent initial
    accelerations ("consistent start", ``SolverSpec.initial_accelerations``) instead of zero.
    """
    cables = tuple(replace(c, damping_constant=damping_constant) for c in scene.cables)
    solver = replace(scene.solver, end_time=end_time, spectral_radius=spectral_radius,
                     step_size=step_size or scene.solver.step_size, output_period=COUPLING_STEP,
                     initial_accelerations=initial_accelerations)
    run_scene = scene.with_changes(cables=cables, solver=solver,
                                   effects=Effects.from_preset("catenary", pulley_contact=False))
    simulate(run_scene.with_changes(solver=replace(solver, end_time=4 * solver.step_size)))  # warm-up
    result = simulate(run_scene)
    times = common_output_times(end_time)
    index = np.rint(times / COUPLING_STEP).astype(int)
    if len(result.time) <= index[-1] or np.max(np.abs(result.time[index] - times)) > 1e-6:
        raise RuntimeError(f"our run (h={solver.step_size:g}) did not record the common output times: {result.status}")
    x, z, _ = result.pose[-1]
    return {"wall_time": result.wall_time, "position": (x, z), "step": solver.step_size,
            "spectral_radius": spectral_radius, "initial_accelerations": initial_accelerations,
            "newton": result.newton_iterations / max(result.steps, 1),
            "times": times, "path": result.pose[index, :2]}


def path_differences(run: dict, reference: dict) -> dict:
    """|(x, z) difference| of ``run`` to ``reference`` on their common output times [m].

    ``max``: over all common times; ``end``: at the last common time (nan unless both
    reach it); ``max_early``: over t <= EARLY_TIME (the drop's transient); ``until``: the
    last common time.
    """
    if len(run.get("times", ())) == 0 or len(reference.get("times", ())) == 0:
        return {"max": math.nan, "end": math.nan, "max_early": math.nan, "until": math.nan}
    common, i, j = np.intersect1d(np.round(run["times"], 9), np.round(reference["times"], 9), return_indices=True)
    distance = np.linalg.norm(run["path"][i] - reference["path"][j], axis=1)
    early = common <= EARLY_TIME + 1e-9
    ends_together = math.isclose(run["times"][-1], reference["times"][-1])
    return {"max": float(distance.max()), "end": float(distance[-1]) if ends_together else math.nan,
            "max_early": float(distance[early].max()), "until": float(common[-1])}


def _versions() -> dict:
    from importlib import metadata

    versions = {"python": sys.version.split()[0], "platform": platform.platform(), "processor": platform.machine(),
                "cpu_count": os.cpu_count()}
    for package in ("cdpr-exu", "exudyn", "moordyn", "numpy"):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    root = Path(__file__).resolve().parents[1]
    try:  # read-only git queries (no index refresh) of the working tree the package is imported from
        versions["git_commit"] = subprocess.run(["git", "--no-optional-locks", "rev-parse", "HEAD"], cwd=root,
                                                capture_output=True, text=True, timeout=10).stdout.strip() or None
        changed = subprocess.run(["git", "--no-optional-locks", "status", "--porcelain", "--untracked-files=no"],
                                 cwd=root, capture_output=True, text=True, timeout=10).stdout.split("\n")
        versions["git_modified_files"] = sorted(line[3:] for line in changed if line.strip())
    except (OSError, subprocess.SubprocessError):
        versions["git_commit"] = None
    return versions


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, (np.floating, float)):
        return None if not math.isfinite(float(value)) else float(value)
    if isinstance(value, np.integer):
        return int(value)
    return value


def _mm(value: float) -> str:
    """A distance [m] in mm, 8 wide: fixed point from 1e-3 mm, else scientific."""
    if value is None or math.isnan(value):
        return "       -"
    return f"{1000 * value:8.4f}" if 1000 * value >= 1e-3 or value == 0 else f"{1000 * value:8.1e}"


def print_table(cases: list[dict], end_time: float = END_TIME) -> None:
    """Wall time, speed-up and path difference to MoorDyn of every run of every case."""
    print()
    print("Accuracy against MoorDyn's path: |(x, z) difference| of the point mass at the common output times "
          f"(every {COUPLING_STEP:g} s to {EARLY_TIME:g} s, then every {SPARSE_TICKS * COUPLING_STEP:g} s) [mm]")
    head = (f"{'case':12s} {'code / configuration':44s} {'wall [s]':>9s} {'MD/this':>8s} {f'max 0-{end_time:g}s':>9s} "
            f"{f'at {end_time:g} s':>8s} {f'max 0-{EARLY_TIME:g}s':>10s} {'self-err':>8s}")
    print(head)
    print("-" * len(head))
    for case in cases:
        md = case["moordyn"]
        for row in case["rows"]:
            ratio = md["wall_time"] / row["wall_time"] if row["wall_time"] else math.nan
            d = row["vs_moordyn"]
            print(f"{case['short']:12s} {row['label']:44s} {row['wall_time']:9.2f} {ratio:8.3g} {_mm(d['max'])} "
                  f"{_mm(d['end'])} {_mm(d['max_early']):>10s} {_mm(row.get('self_error', math.nan))}")
        print()
    print(f"MD/this: MoorDyn's wall time / this run's (speed-up over MoorDyn; \"(stored)\": MoorDyn's wall time "
          f"and path read from --moordyn-from, not measured now). self-err: max difference over 0-{end_time:g} s to "
          "our finest step at the same spectral radius and start (ours), or to MoorDyn at half its step over the run's "
          f"span (MoorDyn; the paper case over 0-{EARLY_TIME:g} s only). \"consistent start\": generalized-alpha "
          "started from the consistent initial accelerations (SolverSpec.initial_accelerations); else from zero "
          "(the default).")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--short", type=float, default=2.0e-3,
                        help="simulated time of MoorDyn's timed stretch with the paper's damping [s] (without --full)")
    parser.add_argument("--full", action="store_true",
                        help="run MoorDyn to the end at the paper's damping too (~16 min on one core; ~22 min in all), "
                             "compare paths, and run ours at finer steps")
    parser.add_argument("--moordyn-from", type=Path, default=None, metavar="PATH",
                        help="take MoorDyn's runs (paths and wall times) from a JSON written by --full --json "
                             "instead of running MoorDyn again; ours run as with --full (a few minutes). MoorDyn is "
                             "only re-timed briefly, as a check of the machine's speed against the stored run")
    parser.add_argument("--steps", type=str, default="2e-3,5e-4,1e-4,1e-5",
                        help="with --full or --moordyn-from: our step sizes [s], comma-separated (the first should "
                             "be the scene's)")
    parser.add_argument("--consistent-steps", type=str, default="2e-3,5e-4,1e-4",
                        help="with --full or --moordyn-from: our step sizes [s] with the consistent start "
                             "(SolverSpec.initial_accelerations), comma-separated; '' for none")
    parser.add_argument("--check-time", type=float, default=EARLY_TIME,
                        help="with --full: MoorDyn at half its step is run this long at the paper's damping to "
                             "estimate its own time-discretisation error [s]")
    parser.add_argument("--end-time", type=float, default=END_TIME,
                        help="simulated time [s] (10 s; shorter only for trying the script out)")
    parser.add_argument("--json", type=Path, default=None, help="write the numbers of both cases to this JSON file")
    args = parser.parse_args()
    if args.full and args.moordyn_from:
        parser.error("--full runs MoorDyn; --moordyn-from takes its runs from a file: give one of them")
    try:
        import moordyn  # noqa: F401
        have_moordyn = True
    except ImportError:
        have_moordyn = False
    if not have_moordyn and not args.moordyn_from:
        print("MoorDyn is not installed (pip install moordyn, or the project's 'moordyn' extra): skipped.")
        return 0

    versions = _versions()  # at the start: the code that runs (others may commit meanwhile)
    end_time = args.end_time
    scene = load_scene("paper-catenary-fixed")
    cable = scene.cables[0]
    many_steps = args.full or args.moordyn_from is not None
    our_steps = [float(s) for s in args.steps.split(",")] if many_steps else [scene.solver.step_size]
    consistent_steps = [float(s) for s in args.consistent_steps.split(",") if s.strip()] if many_steps else []
    stored = load_stored_moordyn(args.moordyn_from, scene.name, end_time) if args.moordyn_from else None
    # MoorDyn's damping ratio: c = zeta l sqrt(E rho) (stress per strain rate), rho = w / A.
    moderate_dn = DAMPING_RATIO * cable.element_length * math.sqrt(cable.youngs_modulus * cable.linear_density / cable.area)
    cases = (("paper's d_n = 1e9 N s/m^2", "paper", cable.damping_constant),
             (f"{DAMPING_RATIO} of critical per segment (d_n = {moderate_dn:.3g} N s/m^2)", "moderate", moderate_dn))
    print(f"paper-catenary-fixed: 2 lines x {cable.n_elements} segments, 1 kg point mass, dropped from straight, "
          f"{end_time:g} s; no bending, no contact, no fluid")
    if stored:
        source = stored["source"]
        source_versions = source.get("versions") or {}
        print(f"MoorDyn NOT run again: its paths and wall times are read from {source['file']} (stored run of "
              f"{source['date']}, MoorDyn {source_versions.get('moordyn')}, cdpr-exu commit "
              f"{str(source_versions.get('git_commit'))[:7]}). The ratios MD/this use the STORED MoorDyn wall "
              "times; MoorDyn is only re-timed briefly (\"timing check\") to show how this machine's speed "
              "compares now.")
    print(f"{'case':58s} {'code':28s} {'wall [s]':>10s} {'x real time':>12s} {'final x, z [m]':>22s}")
    report = []
    for name, short_name, dn in cases:
        ba = dn * cable.area  # N s: MoorDyn's BA
        ours = {}  # (h, rho, consistent start) -> run
        for consistent, steps in ((False, our_steps), (True, consistent_steps)):
            for h in steps:
                for rho in (0.0, 1.0):
                    run = ours[(h, rho, consistent)] = run_ours(scene, dn, rho, h, end_time, consistent)
                    if many_steps:
                        print(f"[cdpr-exu d_n={dn:.3g}, h={h:g}, rho={rho:g}{', consistent start' if consistent else ''}]"
                              f" wall {run['wall_time']:.1f} s", file=sys.stderr, flush=True)
        c_segment = dn * cable.area / cable.element_length
        stability_guess = 2.0 * (cable.element_mass / 2.0) / (2.0 * c_segment)  # ~ m / c of a node
        md_half = None
        timing_check = None
        from_file = stored_case(stored, dn)
        if stored and from_file is None:
            print(f"{name}: no MoorDyn path for this damping in {stored['source']['file']}: MoorDyn is run here")
        if from_file is not None:
            md, md_half = dict(from_file["moordyn"]), from_file["moordyn_half_step"]
            md["note"] = f"stored run of {stored['source']['date']} ({md.get('note', '')})"
            md["wall_time_kind"] = "stored: " + md.get("wall_time_kind", "measured, full run")
            if have_moordyn:  # a brief re-timing at the stored step: how fast is the machine now?
                if md["wall_time"] > 20.0:
                    short = run_moordyn(scene, ba, md["step"], args.short, coupling_step=args.short / 10)
                    now = short["wall_time"] * end_time / short["simulated"]
                    timing_check = {"kind": f"timed {short['simulated']:g} s, scaled x {end_time / short['simulated']:g}",
                                    "wall_time_now": now, "stored_wall_time": md["wall_time"]}
                else:
                    again = run_moordyn(scene, ba, md["step"], end_time, record=True)
                    timing_check = {"kind": f"full {end_time:g} s again", "wall_time_now": again["wall_time"],
                                    "stored_wall_time": md["wall_time"],
                                    "path_difference_to_stored": path_differences(again, md)["max"]}
        elif dn > 1e8:
            candidates = [2e-8, 4e-8, 6e-8, 8e-8, 1e-7, 1.5e-7]
            step = largest_stable_step(scene, ba, candidates, probe_time=2e-4)
            if step is None:
                print(f"{name}: MoorDyn unstable at every step tried ({candidates}); skipped")
                continue
            if args.full:
                md = run_moordyn(scene, ba, step, end_time, record=True, progress=f"d_n={dn:.3g}, dtM={step:g}")
                md["note"] = f"full {end_time:g} s; its lines started straight to {md['initial_sag']:.1e} m"
                md["wall_time_kind"] = "measured, full run"
                check = min(args.check_time, end_time)
                md_half = run_moordyn(scene, ba, step / 2, check, record=True,
                                      progress=f"d_n={dn:.3g}, dtM={step / 2:g}, to {check:g} s")
            else:
                short = run_moordyn(scene, ba, step, args.short, coupling_step=args.short / 10)
                scaled = short["wall_time"] * end_time / short["simulated"]
                md = {"wall_time": scaled, "position": (math.nan, math.nan), "step": step,
                      "times": np.array([]), "path": np.zeros((0, 2)), "wall_time_kind": "scaled",
                      "timed_stretch": short["simulated"], "timed_wall_time": short["wall_time"],
                      "note": f"timed {short['simulated']:g} s, scaled x {end_time / short['simulated']:g}"}
        else:
            candidates = [2e-5, 5e-5, 1e-4, 2e-4, 5e-4, 1e-3]
            step = largest_stable_step(scene, ba, candidates, probe_time=0.5)
            md = run_moordyn(scene, ba, step, end_time, record=True)
            md["note"] = f"full {end_time:g} s; its lines started straight to {md['initial_sag']:.1e} m"
            md["wall_time_kind"] = "measured, full run"
            if args.full:
                md_half = run_moordyn(scene, ba, step / 2, end_time, record=True)
        for (h, rho, consistent), run in ours.items():
            if h != our_steps[0]:
                continue
            label = f"cdpr-exu implicit, h={run['step']:g}, rho={rho:g}" + (", consistent start" if consistent else "")
            print(f"{name:58s} {label:28s} {run['wall_time']:10.2f} {end_time / run['wall_time']:12.1f} "
                  f"{run['position'][0]:+10.5f} {run['position'][1]:+10.5f}")
        label = f"MoorDyn RK2, dtM={md['step']:g}" + (" (stored)" if md.get("stored") else "")
        position = md["position"]
        where = "   (not run to the end)" if math.isnan(position[1]) else f"{position[0]:+10.5f} {position[1]:+10.5f}"
        print(f"{name:58s} {label:28s} {md['wall_time']:10.2f} {end_time / md['wall_time']:12.3g} {where}")
        print(f"{'':58s} MoorDyn: {md['note']}; explicit step limit ~ m_node / c_i = {stability_guess:.1e} s")
        if timing_check:
            extra = (f"; its path is {1000 * timing_check['path_difference_to_stored']:.1e} mm from the stored one"
                     if "path_difference_to_stored" in timing_check else "")
            print(f"{'':58s} timing check: MoorDyn now ({timing_check['kind']}) {timing_check['wall_time_now']:.2f} s, "
                  f"stored {timing_check['stored_wall_time']:.2f} s (ratio now / stored "
                  f"{timing_check['wall_time_now'] / timing_check['stored_wall_time']:.2f}){extra}")
        base = ours[(our_steps[0], 0.0, False)]
        print(f"{'':58s} wall-time ratio MoorDyn / cdpr-exu (h={our_steps[0]:g}, rho 0): "
              f"{md['wall_time'] / base['wall_time']:.3g}")
        if not math.isnan(position[1]):
            for (h, rho, consistent), run in ours.items():
                if h == our_steps[0]:
                    dz = 1000 * (run["position"][1] - position[1])
                    print(f"{'':58s} final z difference cdpr-exu (h={h:g}, rho {rho:g}"
                          f"{', consistent start' if consistent else ''}) - MoorDyn: {dz:+.2f} mm")

        rows = []
        finest = {consistent: min(steps) for consistent, steps in ((False, our_steps), (True, consistent_steps)) if steps}
        for (h, rho, consistent), run in ours.items():
            run["label"] = f"cdpr-exu h={h:g} rho={rho:g}" + (" consistent start" if consistent else "")
            run["code"] = "cdpr-exu"
            run["vs_moordyn"] = path_differences(run, md)
            reference = ours[(finest[consistent], rho, consistent)]
            run["self_error"] = path_differences(run, reference)["max"] if h != finest[consistent] else math.nan
            rows.append(run)
        md["code"] = "moordyn"
        md["label"] = f"MoorDyn RK2 dtM={md['step']:g}" + (" (scaled)" if md["wall_time_kind"] == "scaled" else "") + (
            " (stored)" if md.get("stored") else "")
        md["vs_moordyn"] = {"max": 0.0 if len(md["times"]) else math.nan, "end": 0.0 if len(md["times"]) else math.nan,
                            "max_early": 0.0 if len(md["times"]) else math.nan, "until": end_time}
        if md_half is not None:
            md["self_error"] = path_differences(md_half, md)["max"]
            md_half["code"] = "moordyn"
            md_half["label"] = f"MoorDyn RK2 dtM={md_half['step']:g}" + (
                f" to {md_half['simulated']:g} s" if md_half["simulated"] < end_time else "") + (
                " (stored)" if md_half.get("stored") else "")
            md_half["vs_moordyn"] = path_differences(md_half, md)
            rows.append(md)
            rows.append(md_half)
        else:
            rows.append(md)
        report.append({"name": name, "short": short_name, "d_n": dn, "BA": ba, "moordyn": md,
                       "moordyn_half_step": md_half, "rows": rows, "explicit_step_limit_estimate": stability_guess,
                       "moordyn_timing_check": timing_check})
    print_table(report, end_time)

    if args.json:
        keep = ("code", "label", "wall_time", "wall_time_kind", "step", "spectral_radius", "initial_accelerations",
                "newton", "position", "vs_moordyn", "self_error", "note", "simulated", "timed_stretch", "timed_wall_time",
                "times", "path", "scheme", "stored")
        data = {
            "command": "python " + " ".join([sys.argv[0], *sys.argv[1:]]),
            "date": datetime.datetime.now().astimezone().isoformat(timespec="seconds"),
            "versions": versions,
            "scene": scene.name, "end_time": end_time, "full": args.full, "our_steps": our_steps,
            "consistent_start_steps": consistent_steps,
            "moordyn_from": stored["source"] if stored else None,
            "units": {"wall_time": "s", "position": "m", "differences": "m (Euclidean distance in x-z)",
                      "d_n": "N s/m^2", "BA": "N s"},
            "cases": [{
                "name": case["name"], "d_n": case["d_n"], "BA": case["BA"],
                "explicit_step_limit_estimate": case["explicit_step_limit_estimate"],
                "moordyn_wall_time": case["moordyn"]["wall_time"],
                "moordyn_wall_time_kind": case["moordyn"]["wall_time_kind"],
                "moordyn_timing_check": case["moordyn_timing_check"],
                "runs": [{**{k: row[k] for k in keep if k in row},
                          "speedup_over_moordyn": case["moordyn"]["wall_time"] / row["wall_time"]}
                         for row in case["rows"]],
            } for case in report],
        }
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(_jsonable(data), indent=1) + "\n")
        print(f"\nwrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
