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
  on one ccx process; Ctrl-C drops the queue and ends running ccx), or on Dask:
  an external scheduler (address or client) or a ``LocalCluster`` of
  single-threaded worker processes. Every input file a case needs (today a
  scanned surface) travels with the task, so workers need no shared disk. A
  client or cluster made here is closed here.
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
from .deck import paddle_deck
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

    def to_json(self) -> dict:
        r = self.result
        return {"theta_degC": r.theta_degC, "paddles": r.paddles, "crest_rise_m": r.crest_rise_m,
                "travel_m": r.travel_m.tolist(), "force_N": r.force_N.tolist(),
                "thermal_force_N": r.thermal_force_N, "stats": vars(self.stats),
                "n_nodes": self.n_nodes, "n_elements": self.n_elements}

    @classmethod
    def from_json(cls, d: dict) -> "CaseOutcome":
        r = CaseResult(d["theta_degC"], d["paddles"], d["crest_rise_m"], np.array(d["travel_m"]),
                       np.array(d["force_N"]), d["thermal_force_N"])
        return cls(r, RunStats(**d["stats"]), d["n_nodes"], d["n_elements"], from_cache=True)


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
    n_nodes = assembly.mesh.n_nodes
    return CaseOutcome(result, stats, n_nodes, assembly.mesh.n_elements)


def case_key(params: SpringParams, theta_degC: float, paddles: int, ccx: str) -> str:
    """Hash of everything that decides a case's result (``ccx``: the solving machine's ccx version)."""
    d = params.to_dict()
    d.pop("description", None)
    d.pop("tolerances", None)                 # scatter declarations, not this case's values
    if params.geometry.surface_file:          # the scan's content, wherever the file lies
        d["geometry"]["surface_file"] = surface_digest(params.geometry.surface_file)
    d["sweep"].pop("temperatures_degC", None)
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


def solve_remote(params: SpringParams, theta_degC: float, paddles: int, files: dict[str, bytes]) -> tuple[dict, str]:
    """On a worker: solve one case in a private folder; return its JSON data and the worker's ccx version.

    ``files`` maps each input file name of :func:`input_files` to its content;
    they are written into the private folder, so workers need no shared disk.
    """
    with tempfile.TemporaryDirectory(prefix="cushion_case_") as tmp:
        if params.geometry.surface_file:
            path = Path(tmp) / "surface.npz"
            path.write_bytes(files[params.geometry.surface_file])
            params = params.replace(geometry={"surface_file": str(path)})
        work = Path(tmp) / "ccx"
        work.mkdir()
        return solve_case(params, theta_degC, work, paddles=paddles).to_json(), ccx_version()


def connect(scheduler: str | object | None = None, workers: int | None = None):
    """A Dask client, the client to close (None if the caller's) and the LocalCluster made here (or None).

    ``scheduler``: an address, a ``distributed.Client``, or None for a
    LocalCluster of ``workers`` single-threaded processes (default: cores).
    """
    from distributed import Client, LocalCluster
    if scheduler is None:
        cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                               processes=True, dashboard_address=None)
        client = Client(cluster)
        return client, client, cluster
    if isinstance(scheduler, str):
        client = Client(scheduler)
        return client, client, None
    return scheduler, None, None


def workers_ccx_version(client) -> str:
    """The ccx version every worker of ``client`` reports (waits for a first worker).

    Raises
    ------
    CcxVersionError
        If the workers report different versions.
    """
    client.wait_for_workers(1)
    versions = client.run(ccx_version)
    if len(set(versions.values())) != 1:
        raise CcxVersionError("Dask workers report different ccx versions, so their cases would not be "
                              f"comparable: {versions}")
    return next(iter(versions.values()))


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
        made here is closed here).
    local_cluster : bool
        Without ``scheduler``: run on a LocalCluster of ``jobs`` processes
        instead of threads.
    on_event : callable, optional
        Called with (case index, event, value); see :data:`CaseEvent`.

    Returns
    -------
    outcomes, failures
        Per case its outcome (None if it failed), and case index to exception.
    """
    cache_dir = Path(cache_dir)

    def emit(i: int, event: str, value: float = 0.0) -> None:
        if on_event:
            on_event(i, event, value)

    use_dask = scheduler is not None or local_cluster
    outcomes: list[CaseOutcome | None] = [None] * len(cases)
    failures: dict[int, BaseException] = {}
    client = owned = cluster = None
    try:
        # the key holds the solving machine's ccx version: this machine's, or (Dask) the workers'
        # once they are asked, which only happens if a case is not cached under this machine's version
        ccx = _local_ccx(required=not use_dask)
        todo = _lookup(cases, cache_dir, ccx, range(len(cases)), outcomes, emit) if ccx else list(range(len(cases)))
        if todo and use_dask:
            client, owned, cluster = connect(scheduler, jobs)
            workers = workers_ccx_version(client)
            if workers != ccx:
                ccx = workers
                todo = _lookup(cases, cache_dir, ccx, todo, outcomes, emit)
            _run_dask(client, cases, [(i, case_folder(cache_dir, cases[i], ccx)) for i in todo], ccx,
                      outcomes, failures, emit)
        elif todo:
            _run_threads(cases, [(i, case_folder(cache_dir, cases[i], ccx)) for i in todo], jobs,
                         outcomes, failures, emit)
    finally:
        if owned is not None:
            owned.close()
        if cluster is not None:
            cluster.close()
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


def _run_dask(client, cases, todo, ccx, outcomes, failures, emit) -> None:
    from distributed import as_completed as dask_completed
    blobs: dict[str, object] = {}
    futures = {}
    for i, folder in todo:
        case = cases[i]
        names = input_files(case.params)
        for name in names:
            if name not in blobs:
                blobs[name] = client.scatter(Path(name).read_bytes(), broadcast=True)
        fut = client.submit(solve_remote, case.params, case.theta_degC, case.paddles,
                            {name: blobs[name] for name in names}, pure=False)
        futures[fut] = (i, folder)
    for fut in dask_completed(futures):
        i, folder = futures[fut]
        try:
            data, version = fut.result()
            if version != ccx:
                raise CcxVersionError(f"solved by ccx {version}, not {ccx} (the version of its cache key); "
                                      "not cached")
        except Exception as exc:  # noqa: BLE001 - collected and returned
            _failed(cases[i], i, exc, failures, emit)
        else:
            store(folder, data)
            outcomes[i] = dataclasses.replace(CaseOutcome.from_json(data), from_cache=False)
            emit(i, "done", 1.0)


def _run_threads(cases, todo, jobs, outcomes, failures, emit) -> None:
    lock = threading.Lock()

    def work(i: int, folder: Path) -> CaseOutcome:
        case = cases[i]
        emit(i, "start", 0.0)

        def inc(n: int) -> None:
            with lock:
                emit(i, "increment", n)
        interrupt.check()                       # cancelled while queued: do not start
        outcome = solve_case(case.params, case.theta_degC, folder, paddles=case.paddles, on_increment=inc)
        with lock:                              # cached at once, so an interrupt keeps it
            store(folder, outcome.to_json())
            outcomes[i] = outcome
            emit(i, "done", 1.0)
        return outcome

    pool = ThreadPoolExecutor(max_workers=jobs or os.cpu_count() or 1)
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
