"""The FE case engine: solve (spring, temperature) cases once, cached, on threads or on Dask.

Every study that runs ccx goes through :func:`run_cases`: the temperature sweep
(:mod:`.sweep`), the calibration (through the sweep) and the tolerance study
(:mod:`.tolerance`).

- **Case key** (:func:`case_key`): a hash of everything that decides a case's
  result: the spring (a scanned surface by its content), the temperature, the
  model (half pair or full pair), the code version and the ccx version *that
  the solving machine reports* (this machine, or every Dask worker; workers that
  disagree are refused, and a result solved by another version is not cached).
- **Cache layout**: ``<cache>/<spring name>/theta_<theta>_<key>/result.json``,
  written atomically (a temporary file renamed into place) as soon as a case
  finishes, so an interrupted run keeps what it finished and resumes.
- **Where cases run**: on this machine, one thread per running case (each waits
  on one ccx process, with the idle cores as ccx threads when there are fewer
  cases than jobs, :func:`idle_threads`; Ctrl-C drops the queue and ends running
  ccx), or on Dask through the one choke point :mod:`.cluster`: an external
  scheduler (address or client) or a ``LocalCluster`` of single-threaded worker
  processes. Every worker is checked first (package importable at this version,
  ccx runs, one ccx version; what a worker lacks is named), lost workers are
  reported, and the client needs no ccx. Every input file a case needs (today a
  scanned surface) travels with the task, so workers need no shared disk. A
  client or cluster made here is closed here.
- **Heating check** (:func:`check_heating`): a case whose plates carry force
  from heating alone (carrier clearance too small) is refused.
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import logging
import os
import tempfile
import threading
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .. import __version__, interrupt
from ..errors import CalculixNotFoundError, CcxVersionError
from .ccx import RunStats, ccx_version, run_ccx
from .cluster import open_cluster
from .cluster import run_cases as run_on_cluster
from .deck import paddle_deck
from .joint import resolve_far_end
from .geometry import half_pair_assembly, pair_assembly
from .params import SpringParams
from .results import CaseResult, parse_case
from .surface import surface_digest

log = logging.getLogger(__name__)

DEFAULT_CACHE = Path(os.environ.get("CUSHION_CLUTCH_CACHE", ".cache/cushion_clutch"))
RESULT = "result.json"

#: event callback: (case index, event, value); events "cached", "start", "increment" (value: converged
#: increments so far; local runs only), "done", "failed"
CaseEvent = Callable[[int, str, float], None]


@dataclass(frozen=True)
class Case:
    """One case to solve: a spring at one uniform temperature (degC), half pair (1) or full pair (2)."""

    params: SpringParams
    theta_degC: float
    paddles: int = 1
    #: how log messages name the case
    label: str = ""


@dataclass(frozen=True)
class CaseOutcome:
    """A solved case: its raw result, cost and model size."""

    result: CaseResult
    stats: RunStats
    n_nodes: int
    n_elements: int
    from_cache: bool = False
    ccx_version: str = "unknown"
    """the CalculiX version that solved it (on whichever machine ran it)"""

    def to_json(self) -> dict:
        r = self.result
        return {"theta_degC": r.theta_degC, "paddles": r.paddles, "crest_rise_m": r.crest_rise_m,
                "travel_m": r.travel_m.tolist(), "force_N": r.force_N.tolist(),
                "thermal_force_N": r.thermal_force_N, "thermal_force_lower_N": r.thermal_force_lower_N,
                "stats": vars(self.stats),
                "n_nodes": self.n_nodes, "n_elements": self.n_elements, "ccx_version": self.ccx_version}

    @classmethod
    def from_json(cls, d: dict) -> "CaseOutcome":
        r = CaseResult(d["theta_degC"], d["paddles"], d["crest_rise_m"], np.array(d["travel_m"]),
                       np.array(d["force_N"]), d["thermal_force_N"], d.get("thermal_force_lower_N", 0.0))
        return cls(r, RunStats(**d["stats"]), d["n_nodes"], d["n_elements"], from_cache=True,
                   ccx_version=d.get("ccx_version", "unknown"))


def solve_case(params: SpringParams, theta_degC: float, workdir: Path, *, paddles: int = 1,
               on_increment: Callable[[int], None] | None = None) -> CaseOutcome:
    """Build, run and parse one temperature case.

    Parameters
    ----------
    params : SpringParams
    theta_degC : float
        Uniform paddle temperature, degC.
    workdir : Path
        Folder for ccx's files.
    paddles : int
        1: half-pair model with the carrier plane (default, composed in
        series); 2: the full back-to-back pair.
    on_increment : callable, optional
        Called with the running count of converged increments.
    """
    params = resolve_far_end(params)              # the predicted joint's stiffness unless one is given
    size = params.mesh.element_size_m
    build = half_pair_assembly if paddles == 1 else pair_assembly
    assembly = build(params.geometry, size, params.solver.initial_gap_m, params.mesh.element_type)
    deck, _ = paddle_deck(assembly, params, theta_degC)
    count = [0]

    def on_line(line: str) -> None:
        if on_increment is not None and line.lstrip().startswith("convergence"):
            count[0] += 1
            on_increment(count[0])

    stats = run_ccx(deck, Path(workdir), threads=params.solver.threads,
                    theta_degC=theta_degC, on_line=on_line)
    result = parse_case(Path(workdir) / "case.dat", theta_degC, assembly.paddles)
    check_heating(result, params)
    n_nodes = assembly.mesh.n_nodes
    return CaseOutcome(result, stats, n_nodes, assembly.mesh.n_elements, ccx_version=ccx_version())


#: heating alone may load a plate by at most this fraction of the kiss force (contact noise)
HEATING_FORCE_FRACTION = 0.1


def check_heating(result: CaseResult, params: SpringParams) -> None:
    """Refuse a case in which heating alone pressed the paddle on a plate (a spurious force).

    The plates are held during heating, so any force on them then is an
    artefact: on the carrier, the carrier clearance is below the paddle's growth
    towards the carrier (or within the contact law's reach of it); on the upper
    plate, the hot wave's crest grew through the start gap ``solver.initial_gap_m``.

    Raises
    ------
    ResultError
        Naming the force, the plate, and the clearance (least value to try) or the start gap.
    """
    from ..errors import ResultError
    limit = HEATING_FORCE_FRACTION * params.sweep.kiss_force_N
    worst = max(abs(result.thermal_force_N), abs(result.thermal_force_lower_N))
    if worst <= limit:
        return
    head = f"theta = {result.theta_degC:g} degC: heating alone pressed the paddle on "
    tail = f"with {worst:.3g} N (limit {limit:.3g} N, {HEATING_FORCE_FRACTION:.0%} of the kiss force): "
    if abs(result.thermal_force_lower_N) >= abs(result.thermal_force_N):
        g = params.geometry
        raise ResultError(
            f"{head}the carrier {tail}geometry.carrier_clearance_m = {g.carrier_clearance_m:g} m is below the "
            f"paddle's growth towards the carrier (the sheet alone: {params.min_carrier_clearance_m():.3g} m at "
            f"{max(params.sweep.temperatures_degC):g} degC) plus the contact law's reach; use at least "
            f"{max(1e-5, 2 * params.min_carrier_clearance_m()):.3g} m")
    # the upper plate (the facing side): the hot wave grew into the start gap (a stiff far-edge joint grows it most)
    raise ResultError(
        f"{head}the upper plate {tail}the hot wave's crest grew by more than solver.initial_gap_m = "
        f"{params.solver.initial_gap_m:g} m (the plate's start gap) less the contact law's reach; raise "
        f"solver.initial_gap_m")


def idle_threads(slots: int, n_cases: int) -> int:
    """ccx threads per case when ``n_cases`` run on ``slots`` jobs: the idle cores shared out.

    Cores that other processes keep busy (the 1-minute load average) do not
    count: on a loaded machine extra threads only contend (2 threads ran 0.69x as
    fast as 1 at load 15-19 on 2 cores). Cache keys ignore ``solver.threads``.
    """
    cores = os.cpu_count() or 1
    try:
        idle = max(1, int(cores - os.getloadavg()[0] + 0.5))
    except OSError:                                 # no load average on this platform
        idle = cores
    return max(1, min(idle, cores, slots // max(1, n_cases)))


def case_key(params: SpringParams, theta_degC: float, paddles: int, ccx: str) -> str:
    """Hash of everything that decides a case's result (``ccx``: the solving machine's ccx version)."""
    d = params.to_dict()
    d.pop("description", None)
    d.pop("tolerances", None)                 # scatter declarations, not this case's values
    if params.geometry.surface_file:          # the scan's content, wherever the file lies
        d["geometry"]["surface_file"] = surface_digest(params.geometry.surface_file)
    d["sweep"].pop("temperatures_degC", None)
    if not d["material"].get("expansion_coefficients_per_K"):   # no table: the key as before the table existed
        d["material"].pop("expansion_coefficients_per_K", None)
    d["solver"].pop("threads", None)          # effort limits do not change a converged result
    d["solver"].pop("max_increments", None)
    blob = json.dumps([d, float(theta_degC), paddles, ccx, __version__], sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def case_folder(cache_dir: Path, case: Case, ccx: str) -> Path:
    """The case's cache folder: ``<cache_dir>/<spring name>/theta_<theta>_<key>``."""
    key = case_key(case.params, case.theta_degC, case.paddles, ccx)
    return Path(cache_dir) / case.params.name / f"theta_{case.theta_degC:g}_{key}"


def cached_outcome(folder: Path) -> CaseOutcome | None:
    """The case cached in ``folder``, or None."""
    path = Path(folder) / RESULT
    return CaseOutcome.from_json(json.loads(path.read_text())) if path.exists() else None


def store(folder: Path, data: dict) -> None:
    """Write a case's ``result.json`` atomically (complete or absent, never half-written)."""
    folder.mkdir(parents=True, exist_ok=True)
    tmp = folder / f"{RESULT}.tmp"
    tmp.write_text(json.dumps(data))
    os.replace(tmp, folder / RESULT)


def input_files(params: SpringParams) -> list[str]:
    """Files a case reads besides its parameters (shipped to Dask workers): a scanned surface."""
    return [params.geometry.surface_file] if params.geometry.surface_file else []


def solve_shipped(params: SpringParams, theta_degC: float, paddles: int, surface: bytes | None,
                  threads: int) -> dict:
    """On a Dask worker: solve one case in a private folder with its shipped surface; return its JSON data.

    The function :func:`.cluster.run_cases` submits; the data carry the
    worker's ccx version (``ccx_version``), so the client needs no ccx.
    """
    with tempfile.TemporaryDirectory(prefix="cushion_case_") as tmp:
        if params.geometry.surface_file:
            if surface is None:
                raise ValueError(f"{params.geometry.surface_file}: the scanned surface was not shipped")
            path = Path(tmp) / "surface.npz"
            path.write_bytes(surface)
            params = params.replace(geometry={"surface_file": str(path)})
        work = Path(tmp) / "ccx"
        work.mkdir()
        return solve_case(params.replace(solver={"threads": threads}), theta_degC, work,
                          paddles=paddles).to_json()


def solve_remote(params: SpringParams, theta_degC: float, paddles: int, files: dict[str, bytes]) -> tuple[dict, str]:
    """:func:`solve_shipped` with the input files as a dict; return its JSON data and the worker's ccx version.

    ``files`` maps each input file name of :func:`input_files` to its content;
    they are written into the private folder, so workers need no shared disk.
    """
    sf = params.geometry.surface_file
    data = solve_shipped(params, theta_degC, paddles, files[sf] if sf else None, params.solver.threads)
    return data, data["ccx_version"]


def run_cases(cases: list[Case], *, cache_dir: Path = DEFAULT_CACHE, jobs: int | None = None,
              scheduler: str | object | None = None, local_cluster: bool = False,
              on_event: CaseEvent | None = None) -> tuple[list[CaseOutcome | None], dict[int, BaseException]]:
    """Solve ``cases``, reusing and filling the cache.

    Parameters
    ----------
    jobs : int, optional
        Cases at a time on this machine: threads, or the LocalCluster's worker
        processes (default: number of cores).
    scheduler : str or distributed.Client, optional
        Run on this Dask scheduler's workers (an address or a client; a client
        made here is closed here), checked first by :func:`.cluster.open_cluster`.
    local_cluster : bool
        Without ``scheduler``: run on a LocalCluster of ``jobs`` processes
        instead of threads.
    on_event : callable, optional
        Called with (case index, event, value); see :data:`CaseEvent`.

    Returns
    -------
    outcomes, failures
        Per case its outcome (None if it failed), and case index to exception.

    Raises
    ------
    ClusterError
        If the Dask workers cannot run the cases (each worker named with what
        it lacks) or all of them were lost (finished cases stay cached).
    """
    cache_dir = Path(cache_dir)

    def emit(i: int, event: str, value: float = 0.0) -> None:
        if on_event:
            on_event(i, event, value)

    use_dask = scheduler is not None or local_cluster
    outcomes: list[CaseOutcome | None] = [None] * len(cases)
    failures: dict[int, BaseException] = {}
    # the key holds the solving machine's ccx version: this machine's, or (Dask) the workers'
    # once they are checked, which only happens if a case is not cached under this machine's version
    ccx = _local_ccx(required=not use_dask)
    todo = _lookup(cases, cache_dir, ccx, range(len(cases)), outcomes, emit) if ccx else list(range(len(cases)))
    if todo and use_dask:
        with open_cluster(scheduler, jobs) as (client, info):
            if info.ccx_version != ccx:
                ccx = info.ccx_version
                todo = _lookup(cases, cache_dir, ccx, todo, outcomes, emit)
            _run_dask(client, info, cases, [(i, case_folder(cache_dir, cases[i], ccx)) for i in todo],
                      outcomes, failures, emit)
    elif todo:
        _run_threads(cases, [(i, case_folder(cache_dir, cases[i], ccx)) for i in todo], jobs,
                     outcomes, failures, emit)
    return outcomes, failures


def _local_ccx(required: bool) -> str | None:
    """This machine's ccx version; None if ccx is not installed here and ``required`` is false (Dask)."""
    try:
        return ccx_version()
    except CalculixNotFoundError:
        if required:
            raise
        return None


def _lookup(cases, cache_dir, ccx, indices, outcomes, emit) -> list[int]:
    """Fill ``outcomes`` from the cache (keys with ``ccx``); return the indices still to solve."""
    todo = []
    for i in indices:
        folder = case_folder(cache_dir, cases[i], ccx)
        outcome = cached_outcome(folder)
        if outcome is None:
            todo.append(i)
            continue
        outcomes[i] = outcome
        log.info("%s: cached (%s)", cases[i].label, folder)
        emit(i, "cached", 1.0)
    return todo


def _failed(case: Case, i: int, exc: BaseException, failures: dict, emit) -> None:
    log.error("%s failed: %s", case.label, exc)
    failures[i] = exc
    emit(i, "failed", 0.0)


def _run_dask(client, info, cases, todo, outcomes, failures, emit) -> None:
    """Solve ``todo`` on the checked cluster (:func:`.cluster.run_cases`), caching each as it ends."""
    folders = dict(todo)
    ccx = info.ccx_version

    def on_done(i: int, data: dict | None, exc: BaseException | None) -> None:
        if exc is None and data.get("ccx_version") != ccx:
            exc = CcxVersionError(f"solved by ccx {data.get('ccx_version')}, not {ccx} (the version of its "
                                  "cache key); not cached")
        if exc is not None:
            _failed(cases[i], i, exc, failures, emit)
            return
        store(folders[i], data)
        outcomes[i] = dataclasses.replace(CaseOutcome.from_json(data), from_cache=False)
        emit(i, "done", 1.0)

    run_on_cluster(client, info, solve_shipped,
                   [(i, cases[i].params, cases[i].theta_degC, cases[i].paddles) for i, _ in todo], on_done)


def _run_threads(cases, todo, jobs, outcomes, failures, emit) -> None:
    lock = threading.Lock()
    slots = jobs or os.cpu_count() or 1
    threads = idle_threads(slots, len(todo))       # fewer cases than jobs: the idle cores as ccx threads

    def work(i: int, folder: Path) -> CaseOutcome:
        case = cases[i]
        params = case.params
        if threads > params.solver.threads:
            params = params.replace(solver={"threads": threads})
        emit(i, "start", 0.0)

        def inc(n: int) -> None:
            with lock:
                emit(i, "increment", n)
        interrupt.check()                       # cancelled while queued: do not start
        outcome = solve_case(params, case.theta_degC, folder, paddles=case.paddles, on_increment=inc)
        with lock:                              # cached at once, so an interrupt keeps it
            store(folder, outcome.to_json())
            outcomes[i] = outcome
            emit(i, "done", 1.0)
        return outcome

    pool = ThreadPoolExecutor(max_workers=slots)
    try:
        futs = {pool.submit(work, i, f): i for i, f in todo}
        for fut in as_completed(futs):
            i = futs[fut]
            try:
                fut.result()
            except Exception as exc:  # noqa: BLE001 - collected and returned
                _failed(cases[i], i, exc, failures, emit)
    except BaseException as exc:                # Ctrl-C / SIGTERM: drop the queue, end running ccx
        with interrupt.cancelling(isinstance(exc, KeyboardInterrupt)):
            pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    interrupt.check()
