"""Parameter studies: run one scene over a grid of parameter values, in parallel.

A study varies fields of a base scene, named by *parameter paths* into its plain-data
form (:meth:`~cdpr_exu.scenes.scene.Scene.to_dict`):

- ``"platform.mass=1,2.5,5"``: one field;
- ``"cables.n_elements=5,10,15"``: a list field without an index applies to every
  entry (every cable); ``"cables[1].radius=0.004,0.006"`` to one entry;
- ``"platform.initial_pose[1]=-2,-1.9"``: one entry of a vector field;
- ``"solver.step_size=1e-3,2e-3"``, ``"effects.bending=true,false"``,
  ``"effects.preset=full,catenary"``, ``"trajectory.angular_rate=1,1.5"``.

Values are TOML scalars (a bare word is a string). The study runs the cartesian product
of the values, or with ``mode="zip"`` the i-th values together. Each run is one row: its
parameters, its status (``"completed"``, ``"failed: ..."``, ``"refused: ..."``: recorded,
never fatal) and the figures of :meth:`~cdpr_exu.results.result.Result.summary`. Runs go to
any :class:`concurrent.futures.Executor`: a process pool of single-threaded processes by
default, or a Dask cluster (``scheduler="tcp://host:8786"`` or ``"local"``).

Only the standard library is imported at the top, so that a spawned worker sets its thread
limits before NumPy, Numba or Exudyn load.
"""

from __future__ import annotations

import contextlib
import copy
import csv
import difflib
import itertools
import json
import math
import multiprocessing
import os
import re
import time
import tomllib
import warnings
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Sequence

from cdpr_exu.core.errors import CdprError, SceneError

if TYPE_CHECKING:  # pragma: no cover
    from cdpr_exu.scenes.scene import Scene

#: Environment that keeps every worker process on one thread (one run per core).
SINGLE_THREAD_ENVIRONMENT = {
    "OMP_NUM_THREADS": "1",
    "MKL_NUM_THREADS": "1",
    "OPENBLAS_NUM_THREADS": "1",
    "NUMBA_NUM_THREADS": "1",
}

#: Summary figures of :meth:`Result.summary` recorded for every run, in column order.
FIGURES = (
    "max_abs_error_x_m",
    "max_abs_error_z_m",
    "max_position_error_m",
    "rms_position_error_m",
    "max_abs_rotation_deg",
    "min_element_tension_N",
    "max_element_tension_N",
    "max_pulley_penetration_m",
    "simulated_time_s",
    "wall_time_s",
    "real_time_factor",
    "steps",
    "newton_iterations",
    "failure_time_s",
    "errors_measured_after_s",
)

#: Files a study writes into its output folder.
STUDY_FILES = {"csv": "study.csv", "json": "study.json", "scene": "base_scene.toml"}

#: Effects that need another effect on: ``{dependent: needed}``.
DEPENDENT_EFFECTS = {"bending_damping": "bending"}

_SEGMENT = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)$")

_MODES = ("grid", "zip")


@dataclass(frozen=True)
class Variation:
    """One varied parameter: a path into the scene's plain data (``"cables[1].radius"``) and its values
    (numbers, booleans or strings)."""

    path: str
    values: tuple

    def __post_init__(self) -> None:
        _split_path(self.path)
        object.__setattr__(self, "values", tuple(self.values))
        if not self.values:
            raise SceneError(f"parameter {self.path!r} needs at least one value")
        for value in self.values:
            if isinstance(value, (dict, list, tuple)) or value is None:
                raise SceneError(f"parameter {self.path!r}: values must be numbers, booleans or strings, got {value!r}")


def _parse_value(text: str, path: str) -> Any:
    """One TOML scalar; a bare word (``full``) is taken as a string."""
    text = text.strip()
    if not text:
        raise SceneError(f"parameter {path!r} has an empty value")
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if re.fullmatch(r"[A-Za-z_][A-Za-z0-9_\-]*", text):
            return text
        raise SceneError(f"parameter {path!r}: {text!r} is not a number, true/false or a string") from None
    if isinstance(value, (dict, list)) or not isinstance(value, (int, float, bool, str)):
        raise SceneError(f"parameter {path!r}: values must be numbers, booleans or strings, got {text!r}")
    return value


def parse_parameter(text: str) -> Variation:
    """Read ``"PATH=V1,V2,..."`` (TOML scalars or bare words; quoted strings may hold commas) into a
    :class:`Variation`; SceneError without ``=``, for a malformed path or a value that is no scalar."""
    if not isinstance(text, str) or "=" not in text:
        raise SceneError(f"parameter {text!r} must read PATH=V1,V2,... (e.g. platform.mass=1,2.5,5)")
    path, _, values_text = text.partition("=")
    path = path.strip()
    _split_path(path)
    try:  # the whole list at once: quoted strings may hold commas
        values = tomllib.loads(f"v = [{values_text}]")["v"]
        if any(isinstance(v, (dict, list)) for v in values):
            raise SceneError(f"parameter {path!r}: values must be numbers, booleans or strings, got {values_text!r}")
    except tomllib.TOMLDecodeError:
        values = [_parse_value(part, path) for part in values_text.split(",")]
    if not values:
        raise SceneError(f"parameter {path!r} has no values (write {path}=V1,V2,...)")
    return Variation(path, tuple(values))


def _split_path(path: str) -> list[str | int]:
    """``"cables[1].radius"`` -> ``["cables", 1, "radius"]``."""
    if not isinstance(path, str) or not path:
        raise SceneError(f"parameter path must be a non-empty string, got {path!r}")
    parts: list[str | int] = []
    for segment in path.split("."):
        match = _SEGMENT.match(segment)
        if match is None:
            raise SceneError(f"parameter path {path!r} is malformed at {segment!r} "
                             "(write e.g. cables.n_elements or cables[1].radius)")
        parts.append(match.group(1))
        parts.extend(int(i) for i in re.findall(r"\[(\d+)\]", match.group(2)))
    return parts


def _assign(node: Any, parts: list[str | int], value: Any, path: str, done: str, write: bool) -> None:
    """Walk ``parts`` from ``node`` and set the leaf (every entry of an unindexed list)."""
    head, rest = parts[0], parts[1:]
    if isinstance(head, int):
        if not isinstance(node, list):
            raise SceneError(f"unknown parameter path {path!r}: {done} is not a list")
        if head >= len(node):
            raise SceneError(f"unknown parameter path {path!r}: {done} has {len(node)} entries, no [{head}]")
        key, where = head, f"{done}[{head}]"
    elif isinstance(node, list):  # a name after a list: every entry
        if not node:
            raise SceneError(f"unknown parameter path {path!r}: {done} is empty")
        for i, entry in enumerate(node):
            _assign(entry, parts, value, path, f"{done}[{i}]", write)
        return
    elif isinstance(node, dict):
        if head not in node:
            close = difflib.get_close_matches(head, list(node), n=1)
            hint = f" (did you mean {close[0]!r}?)" if close else ""
            raise SceneError(f"unknown parameter path {path!r}: {done or 'the scene'} has no field {head!r}"
                             f"{hint}; known: {', '.join(sorted(node))}")
        key, where = head, f"{done}.{head}" if done else head
    else:
        raise SceneError(f"unknown parameter path {path!r}: {done} is a value, it has no field {head!r}")
    if rest:
        _assign(node[key], rest, value, path, where, write)
        return
    if isinstance(node[key], dict):
        raise SceneError(f"parameter path {path!r} names a table; name one of its fields: "
                         f"{', '.join(sorted(node[key]))}")
    if isinstance(node[key], list):
        raise SceneError(f"parameter path {path!r} names a list; name one of its entries, e.g. {where}[0]")
    if write:
        node[key] = value


def check_parameter_path(scene_data: Mapping[str, Any], path: str) -> None:
    """Raise SceneError naming ``path`` unless it names scalar fields of ``scene_data``."""
    _assign(dict(scene_data), _split_path(path), None, path, "", write=False)


def apply_parameters(scene_data: Mapping[str, Any], assignments: Iterable[tuple[str, Any]]) -> dict[str, Any]:
    """A copy of the plain scene data with each ``(path, value)`` set (not validated).

    ``effects.preset`` is set first and resets the flags to the new preset's, keeping the
    base's own deviations from its preset. Switching an effect off also switches off those
    that need it (:data:`DEPENDENT_EFFECTS`) unless they are varied too.
    """
    data = copy.deepcopy(dict(scene_data))
    assignments = sorted(assignments, key=lambda a: a[0] != "effects.preset")
    for path, value in assignments:
        if path == "effects.preset":
            data["effects"] = _effects_for_preset(data.get("effects", {}), value)
            continue
        _assign(data, _split_path(path), value, path, "", write=True)
    effects = data.get("effects")
    varied = {path for path, _ in assignments}
    if isinstance(effects, dict):
        for dependent, needed in DEPENDENT_EFFECTS.items():
            if effects.get(needed) is False and f"effects.{dependent}" not in varied \
                    and f"effects.{needed}" in varied | {"effects.preset"}:
                effects[dependent] = False
    return data


def _effects_for_preset(effects: Mapping[str, Any], preset: Any) -> dict[str, Any]:
    from cdpr_exu.scenes.scene import PRESETS

    base_preset = effects.get("preset", "full")
    flags = PRESETS.get(base_preset, {})
    kept = {k: v for k, v in effects.items() if k != "preset" and (k not in flags or flags[k] != v)}
    return {"preset": preset, **kept}


def combinations(variations: Sequence[Variation], mode: str = "grid") -> list[tuple[tuple[str, Any], ...]]:
    """The parameter assignments of every run: ``"grid"``, the cartesian product (the last parameter
    fastest); ``"zip"``, the i-th values together (equal lengths required)."""
    if mode not in _MODES:
        raise SceneError(f"mode must be 'grid' or 'zip', got {mode!r}")
    if not variations:
        return [()]
    paths = [v.path for v in variations]
    if mode == "zip":
        lengths = {v.path: len(v.values) for v in variations}
        if len(set(lengths.values())) != 1:
            raise SceneError(f"zipped parameters need equal numbers of values, got {lengths}")
        return [tuple(zip(paths, values)) for values in zip(*(v.values for v in variations))]
    return [tuple(zip(paths, values)) for values in itertools.product(*(v.values for v in variations))]


def as_variations(variations: Any) -> list[Variation]:
    """Variations from strings ``"PATH=V1,V2"``, ``(path, values)`` pairs, a dict or Variations."""
    if isinstance(variations, (str, Variation)):
        variations = [variations]
    if isinstance(variations, Mapping):
        variations = list(variations.items())
    out = []
    for item in variations:
        if isinstance(item, Variation):
            out.append(item)
        elif isinstance(item, str):
            out.append(parse_parameter(item))
        else:
            path, values = item
            if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
                values = [values]
            out.append(Variation(path, tuple(values)))
    seen = set()
    for v in out:
        if v.path in seen:
            raise SceneError(f"parameter {v.path!r} is given twice; list all its values in one PATH=V1,V2,...")
        seen.add(v.path)
    return out


def _nan_figures() -> dict[str, Any]:
    return {name: float("nan") for name in FIGURES}


#: Model configurations already run once in this process (see :func:`warm_up`).
_WARMED: set[str] = set()


def warm_up(scene) -> None:
    """Run two steps of ``scene`` once per process and model configuration, untimed: the first run
    in a process loads Numba's kernels and Exudyn's code paths (0.2 to 2 s), which no run's time holds."""
    from cdpr_exu.run.simulate import simulate

    effects = scene.to_dict()["effects"]
    configuration = [scene.dimension, effects, [exit_.kind for exit_ in scene.exits], scene.winch.kind]
    key = json.dumps(configuration, sort_keys=True)
    if key in _WARMED:
        return
    _WARMED.add(key)

    solver = scene.solver
    short = replace(solver, end_time=2 * solver.step_size, output_period=solver.step_size)
    try:
        simulate(scene.with_changes(solver=short))
    except Exception:  # noqa: BLE001 - only a warm-up; the real run reports any problem
        pass


def recorded_run(scene_data: Mapping[str, Any], quiet: tuple[type[Warning], ...] = ()):
    """Build a scene from plain data and simulate it, warmed up, in a single thread; never raises for a
    bad scene or a failed run (the one run of a study's workers). ``quiet``: warnings not shown.

    Returns ``(scene, result, status, cpu_time_s)``: ``status`` ``"completed"``, ``"failed: ..."``
    (``result`` the partial one, or None) or ``"refused: ..."`` (``result`` None); ``scene`` None
    where it could not be built; the CPU time [s] of the run, model building included (NaN without).
    """
    for name, value in SINGLE_THREAD_ENVIRONMENT.items():
        os.environ.setdefault(name, value)  # effective if the libraries are not loaded yet
    from cdpr_exu.core.errors import SolverFailure, UnreachableError
    from cdpr_exu.scenes.scene import scene_from_dict

    scene = None
    try:
        with warnings.catch_warnings():
            for kind in quiet:
                warnings.simplefilter("ignore", kind)
            scene = scene_from_dict(scene_data)
        from cdpr_exu.run.simulate import simulate  # loads Numba and Exudyn: after the thread limits

        warm_up(scene)
        cpu = time.process_time()
        try:
            return scene, simulate(scene), "completed", time.process_time() - cpu
        except SolverFailure as err:
            return scene, err.partial_result, "failed: " + " ".join(str(err).split()), time.process_time() - cpu
    except (SceneError, UnreachableError) as err:
        return scene, None, "refused: " + " ".join(str(err).split()), math.nan
    except Exception as err:  # noqa: BLE001 - a study records every failure and goes on
        return scene, None, f"failed: {type(err).__name__}: " + " ".join(str(err).split()), math.nan


def run_variation(scene_data: dict[str, Any], after: float = 1.0) -> dict[str, Any]:
    """A study's worker: simulate plain scene data (:func:`recorded_run`) and return ``status`` and the
    :data:`FIGURES` (NaN for a refused run), errors from ``after`` [s] on (0 if the run is not longer)."""
    scene, result, status, _ = recorded_run(scene_data)
    if result is None:
        return {"status": status, **_nan_figures()}
    summary = result.summary(after=after if after < scene.solver.end_time else 0.0)
    row = {"status": status}
    for name in FIGURES:
        value = summary.get(name)
        row[name] = float("nan") if value is None else value
    return row


@contextlib.contextmanager
def _environment(values: Mapping[str, str]):
    """Set environment variables for the block (spawned processes inherit them)."""
    saved = {name: os.environ.get(name) for name in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for name, value in saved.items():
            if value is None:
                os.environ.pop(name, None)
            else:
                os.environ[name] = value


def local_dask_cluster(n_workers: int | None = None):
    """A Dask ``LocalCluster`` of single-threaded worker processes (one per core)."""
    import dask
    from dask.distributed import LocalCluster

    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", {}))
    environ.update(SINGLE_THREAD_ENVIRONMENT)
    with dask.config.set({"distributed.nanny.pre-spawn-environ": environ}):
        return LocalCluster(n_workers=n_workers or os.cpu_count() or 1, threads_per_worker=1,
                            processes=True, dashboard_address=None)


@contextlib.contextmanager
def executor_for(executor: Executor | None, workers: int | None, scheduler: str | None):
    """The executor to use; the ones made here are shut down afterwards."""
    if executor is not None:
        yield executor
        return
    if scheduler:
        try:
            from dask.distributed import Client
        except ImportError:
            raise CdprError("a Dask scheduler needs dask.distributed: pip install 'cdpr-exu[cluster]'") from None
        if scheduler == "local":
            with local_dask_cluster(workers) as cluster, Client(cluster) as client:
                yield client.get_executor()
        else:
            try:
                client = Client(scheduler, timeout=30)
            except OSError as err:
                raise CdprError(f"cannot reach the Dask scheduler {scheduler!r}: {err}") from None
            with client:
                yield client.get_executor()
        return
    workers = workers or os.cpu_count() or 1
    # spawned processes start a fresh interpreter in this environment: one thread each for BLAS, OpenMP, Numba
    with _environment(SINGLE_THREAD_ENVIRONMENT):
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn"))
        try:
            yield pool
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


def progress_bar(total: int, enabled: bool):
    """A tqdm bar over ``total`` runs, shown when ``enabled`` and the output is a terminal."""
    from tqdm import tqdm

    # disable=None: no bar when the output is not a terminal
    return tqdm(total=total, unit="run", desc="study", disable=None if enabled else True, mininterval=0.25)


def run_study(base_scene: "Scene | str | Path", variations: Any, executor: Executor | None = None,
              out: str | Path | None = None, progress: bool = True, after: float = 1.0, *,
              mode: str = "grid", workers: int | None = None, scheduler: str | None = None,
              plots: bool = True) -> list[dict[str, Any]]:
    """Run ``base_scene`` (a Scene, shipped name or TOML path) once per combination of parameter values.

    Parameters
    ----------
    variations : sequence
        ``"PATH=V1,V2"`` strings, :class:`Variation` objects, ``(path, values)`` pairs, or a dict.
    executor : concurrent.futures.Executor, optional
        Where the runs go (not shut down here). Default: a process pool of ``workers``
        single-threaded processes (default: cores), or the Dask cluster of ``scheduler``
        (``"tcp://host:8786"``, the project installed on its workers, or ``"local"``).
    out : path, optional
        Folder for :func:`write_study` (with the figures if ``plots``).
    after : float [s]
        Errors are measured from this time on (from 0 for runs not longer than it).

    Returns
    -------
    list of dict
        In the order of :func:`combinations`: the parameters (by path), ``run``, ``status``
        and the :data:`FIGURES`.

    Raises
    ------
    SceneError
        Before any run, for an unknown path, a malformed value or unequal zipped lengths
        (invalid values of a known path are recorded as refused runs).
    """
    from cdpr_exu.scenes.scene import Scene, load_scene, scene_from_dict

    if workers is not None and (isinstance(workers, bool) or int(workers) != workers or workers < 1):
        raise SceneError(f"workers must be a whole number of at least 1, got {workers!r}")
    scene = base_scene if isinstance(base_scene, Scene) else load_scene(base_scene)
    after = float(after)
    variations = as_variations(variations)
    base_data = scene.to_dict()
    for variation in variations:
        check_parameter_path(base_data, variation.path)
    runs = combinations(variations, mode)

    rows: list[dict[str, Any]] = []
    pending: list[tuple[int, dict[str, Any]]] = []
    for index, assignments in enumerate(runs):
        row = {path: value for path, value in assignments}
        row["run"] = index
        data = apply_parameters(base_data, assignments)
        try:
            data = scene_from_dict(data).to_dict()
        except SceneError as err:
            row.update({"status": "refused: " + " ".join(str(err).split()), **_nan_figures()})
        else:
            pending.append((index, data))
        rows.append(row)

    bar = progress_bar(len(rows), progress)
    bar.update(len(rows) - len(pending))
    start = time.perf_counter()
    simulated = 0.0
    try:
        if pending:
            if executor is None and scheduler is None:
                workers = min(workers or os.cpu_count() or 1, len(pending))
            with executor_for(executor, workers, scheduler) as pool:
                futures: dict[Future, int] = {pool.submit(run_variation, data, after): index
                                              for index, data in pending}
                for future in as_completed(futures):
                    index = futures[future]
                    try:
                        outcome = future.result()
                    except Exception as err:  # noqa: BLE001 - a lost worker fails one run, not the study
                        outcome = {"status": f"failed: worker error: {type(err).__name__}: "
                                   + " ".join(str(err).split()), **_nan_figures()}
                    rows[index].update(outcome)
                    if math.isfinite(outcome.get("simulated_time_s", float("nan"))):
                        simulated += outcome["simulated_time_s"]
                    elapsed = time.perf_counter() - start
                    bar.set_postfix_str(f"{simulated / elapsed:.1f} simulated s per wall s", refresh=False)
                    bar.update(1)
    finally:
        bar.close()

    if out is not None:
        write_study(out, rows, scene, variations, mode=mode, after=after, plots=plots)
    return rows


def study_columns(rows: Sequence[Mapping[str, Any]], variations: Sequence[Variation]) -> list[str]:
    """CSV columns: the parameters, run, status and the figures, but the wall-clock ones (``timing.json``)."""
    from cdpr_exu.core.output import TIMING_KEYS

    columns = [v.path for v in variations] + ["run", "status", *(f for f in FIGURES if f not in TIMING_KEYS)]
    for row in rows:
        columns.extend(k for k in row if k not in columns and k not in TIMING_KEYS)
    return columns


def write_study(out: str | Path, rows: Sequence[Mapping[str, Any]], base_scene: "Scene",
                variations: Sequence[Variation], *, mode: str = "grid", after: float = 1.0,
                plots: bool = True) -> dict[str, Path]:
    """Write ``study.csv``, ``study.json``, ``base_scene.toml`` and the figures
    (:func:`cdpr_exu.post.study_plots.plot_study`); return the paths."""
    from cdpr_exu.core.output import check_output_folder, clear_outputs, value_text, write_summary
    from cdpr_exu.results.result import provenance
    from cdpr_exu.scenes.scene import save_scene

    out = check_output_folder(out, command="study sweep")
    clear_outputs(out, "study sweep")  # no figure of an earlier study's parameters stays
    paths = {"scene": save_scene(base_scene, out / STUDY_FILES["scene"])}
    columns = study_columns(rows, variations)
    with open(out / STUDY_FILES["csv"], "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for row in rows:
            writer.writerow([value_text(row.get(c)) for c in columns])
    paths["csv"] = out / STUDY_FILES["csv"]
    data = {
        "variations": [{"path": v.path, "values": list(v.values)} for v in variations],
        "mode": mode,
        "errors_measured_after_s": after,
        "columns": columns,
        "rows": [dict(row) for row in rows],  # NaN as null (write_summary)
        "base_scene": base_scene.to_dict(),
        **provenance(),
    }
    write_summary(out, data, name=STUDY_FILES["json"])  # the date and each row's wall time go to timing.json
    paths["json"] = out / STUDY_FILES["json"]
    if plots and variations:
        from cdpr_exu.post.study_plots import plot_study

        paths.update(plot_study(rows, variations, out, mode=mode))
    return paths


def format_table(rows: Sequence[Mapping[str, Any]], variations: Sequence[Variation]) -> str:
    """A plain-text table of a study (parameters, status, errors [mm], wall time [s]), then the causes of
    failed and refused runs, once each."""
    from cdpr_exu.core.output import finite_number, value_text

    head = [v.path for v in variations] + ["run", "status", "max err [mm]", "rms err [mm]", "wall [s]",
                                           "x real time"]
    lines, causes = [], {}
    for row in rows:
        status = str(row.get("status", ""))
        kind, _, cause = status.partition(": ")
        if cause:
            causes.setdefault(cause, []).append(str(row.get("run", "")))
        cells = [value_text(row.get(v.path)) for v in variations] + [value_text(row.get("run")), kind]
        for name, scale, fmt in (("max_position_error_m", 1000.0, "{:.2f}"), ("rms_position_error_m", 1000.0, "{:.2f}"),
                                 ("wall_time_s", 1.0, "{:.2f}"), ("real_time_factor", 1.0, "{:.2f}")):
            value = row.get(name)
            cells.append(fmt.format(scale * value) if finite_number(value) else "-")
        lines.append(cells)
    widths = [max(len(str(c)) for c in column) for column in zip(head, *lines)]
    out = ["  ".join(str(c).ljust(w) for c, w in zip(head, widths)).rstrip()]
    out.extend("  ".join(str(c).ljust(w) for c, w in zip(cells, widths)).rstrip() for cells in lines)
    for cause, runs in causes.items():
        out.append(f"run{'s' if len(runs) > 1 else ''} {', '.join(runs)}: {cause}")
    return "\n".join(out)
