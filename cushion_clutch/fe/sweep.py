"""Temperature sweep: one ccx job per temperature, in parallel, cached, resumable.

Each case runs in its own folder under the cache; a finished case leaves a
``result.json`` keyed by a hash of everything that decides its result, so a
rerun after a failure only computes what is missing. On one machine cases
run in threads (each thread waits on one ccx process); with a Dask
scheduler address they run on the cluster's workers instead.
"""
from __future__ import annotations

import dataclasses
import datetime as _dt
import hashlib
import json
import logging
import os
import platform
import threading
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .. import __version__, interrupt
from .ccx import RunStats, ccx_version, run_ccx
from .deck import paddle_deck
from ..errors import SweepError
from .geometry import half_pair_assembly, pair_assembly
from .params import SpringParams
from .results import CaseResult, parse_case
from .tables import Curve, curve_from_case, kiss_shift, progressivity, write_tables

log = logging.getLogger(__name__)

DEFAULT_CACHE = Path(os.environ.get("CUSHION_CLUTCH_CACHE", ".cache/cushion_clutch"))

#: progress callback: (theta_degC, event, value); events "start", "increment", "done", "failed"
Progress = Callable[[float, str, float], None]


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


def solve_shipped(params: SpringParams, theta_degC: float, paddles: int, surface: bytes | None,
                  threads: int) -> dict:
    """On a Dask worker: solve one case in a private folder with its shipped surface; return its JSON data."""
    import tempfile
    with tempfile.TemporaryDirectory(prefix="cushion_case_") as tmp:
        if surface is not None:
            path = Path(tmp) / "surface.npz"
            path.write_bytes(surface)
            params = params.replace(geometry={"surface_file": str(path)})
        work = Path(tmp) / "ccx"
        work.mkdir()
        return solve_case(params.replace(solver={"threads": threads}), theta_degC, work,
                          paddles=paddles).to_json()


#: heating alone may load a plate by at most this fraction of the kiss force (contact noise)
HEATING_FORCE_FRACTION = 0.1


def check_heating(result: CaseResult, params: SpringParams) -> None:
    """Refuse a case in which heating alone pressed the paddle on a plate (a spurious force).

    The plates are held during heating, so any force on them then is an
    artefact: the carrier clearance is below the paddle's growth towards the
    carrier (or within the contact law's reach of it).

    Raises
    ------
    ResultError
        Naming the force, the clearance and the least clearance to try.
    """
    from ..errors import ResultError
    limit = HEATING_FORCE_FRACTION * params.sweep.kiss_force_N
    worst = max(abs(result.thermal_force_N), abs(result.thermal_force_lower_N))
    if worst > limit:
        g = params.geometry
        raise ResultError(
            f"theta = {result.theta_degC:g} degC: heating alone pressed the paddle on "
            f"{'the carrier' if abs(result.thermal_force_lower_N) >= abs(result.thermal_force_N) else 'a plate'} "
            f"with {worst:.3g} N (limit {limit:.3g} N, {HEATING_FORCE_FRACTION:.0%} of the kiss force): "
            f"geometry.carrier_clearance_m = {g.carrier_clearance_m:g} m is below the paddle's growth towards "
            f"the carrier (the sheet alone: {params.min_carrier_clearance_m():.3g} m at "
            f"{max(params.sweep.temperatures_degC):g} degC) plus the contact law's reach; use at least "
            f"{max(1e-5, 2 * params.min_carrier_clearance_m()):.3g} m")


def case_key(params: SpringParams, theta_degC: float, paddles: int, ccx: str) -> str:
    """Hash of everything that decides a case's result."""
    d = params.to_dict()
    d.pop("description", None)
    d.pop("tolerances", None)                 # scatter declarations, not this case's values
    if params.geometry.surface_file:          # the scan's content, wherever the file lies
        from .surface import surface_digest
        d["geometry"]["surface_file"] = surface_digest(params.geometry.surface_file)
    d["sweep"].pop("temperatures_degC", None)
    d["solver"].pop("threads", None)          # effort limits do not change a converged result
    d["solver"].pop("max_increments", None)
    blob = json.dumps([d, float(theta_degC), paddles, ccx, __version__], sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def run_sweep(params: SpringParams, *, cache_dir: Path = DEFAULT_CACHE, jobs: int | None = None,
              scheduler: str | object | None = None, paddles: int = 1,
              progress: Progress | None = None) -> dict[float, CaseOutcome]:
    """Solve every temperature of ``params.sweep``, reusing cached cases.

    Parameters
    ----------
    jobs : int, optional
        Parallel ccx jobs on this machine (default: number of cores). With
        fewer cases than jobs, each ccx gets the idle cores as threads.
    scheduler : str or distributed.Client, optional
        A Dask scheduler address (``tcp://host:8786``) or client; cases then
        run on its workers, which are checked first (:mod:`.cluster`); the
        client needs no ccx.

    Raises
    ------
    SweepError
        If any case failed; the finished ones stay in the cache.
    ClusterError
        If the cluster cannot run the cases (named workers) or lost all its workers.
    """
    if scheduler is not None:
        from .cluster import open_cluster
        with open_cluster(scheduler) as (client, info):
            return _run_sweep(params, cache_dir, jobs, (client, info), paddles, progress)
    return _run_sweep(params, cache_dir, jobs, None, paddles, progress)


def _run_sweep(params: SpringParams, cache_dir: Path, jobs: int | None, cluster, paddles: int,
               progress: Progress | None) -> dict[float, CaseOutcome]:
    ccx = cluster[1].ccx_version if cluster else ccx_version()
    cache_dir = Path(cache_dir) / params.name
    todo: list[tuple[float, Path]] = []
    done: dict[float, CaseOutcome] = {}
    for theta in params.sweep.temperatures_degC:
        folder = cache_dir / f"theta_{theta:g}_{case_key(params, theta, paddles, ccx)}"
        cached = folder / "result.json"
        if cached.exists():
            done[theta] = CaseOutcome.from_json(json.loads(cached.read_text()))
            log.info("theta = %g degC: cached (%s)", theta, folder)
            if progress:
                progress(theta, "done", 1.0)
        else:
            todo.append((theta, folder))
    failures: dict[float, BaseException] = {}

    def finish(theta: float, folder: Path, outcome: CaseOutcome) -> None:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / "result.json.tmp"
        tmp.write_text(json.dumps(outcome.to_json()))
        os.replace(tmp, folder / "result.json")
        done[theta] = outcome
        if progress:
            progress(theta, "done", 1.0)

    if cluster is not None and todo:
        from .cluster import run_cases
        folders = dict(todo)

        def on_done(theta: float, data: dict | None, exc: BaseException | None) -> None:
            if exc is None:
                finish(theta, folders[theta], dataclasses.replace(CaseOutcome.from_json(data), from_cache=False))
            else:
                failures[theta] = exc
                if progress:
                    progress(theta, "failed", 0.0)
        run_cases(cluster[0], cluster[1], solve_shipped, [(t, params, t, paddles) for t, _ in todo], on_done)
    elif todo:
        lock = threading.Lock()
        threads = max(params.solver.threads, idle_threads(jobs or os.cpu_count() or 1, len(todo)))
        solve_params = params.replace(solver={"threads": threads}) if threads != params.solver.threads else params

        def work(theta: float, folder: Path) -> CaseOutcome:
            if progress:
                progress(theta, "start", 0.0)

            def inc(n: int) -> None:
                if progress:
                    with lock:
                        progress(theta, "increment", n)
            interrupt.check()                       # cancelled while queued: do not start
            outcome = solve_case(solve_params, theta, folder, paddles=paddles, on_increment=inc)
            with lock:                              # cached at once, so an interrupt keeps it
                finish(theta, folder, outcome)
            return outcome

        pool = ThreadPoolExecutor(max_workers=jobs or os.cpu_count() or 1)
        try:
            futs = {pool.submit(work, t, f): (t, f) for t, f in todo}
            for fut in as_completed(futs):
                theta, folder = futs[fut]
                try:
                    fut.result()
                except Exception as exc:  # noqa: BLE001 - collected and re-raised as SweepError
                    log.error("theta = %g degC failed: %s", theta, exc)
                    failures[theta] = exc
                    if progress:
                        progress(theta, "failed", 0.0)
        except BaseException as exc:                # Ctrl-C / SIGTERM: drop the queue, end running ccx
            with interrupt.cancelling(isinstance(exc, KeyboardInterrupt)):
                pool.shutdown(wait=True, cancel_futures=True)
            raise
        pool.shutdown(wait=True)
        interrupt.check()
    if failures:
        raise SweepError(failures)
    return {t: done[t] for t in sorted(done)}


def build_tables(params: SpringParams, outcomes: dict[float, CaseOutcome], out_dir: Path,
                 *, wall_time_s: float | None = None) -> tuple[list[Curve], dict[float, float]]:
    """Turn solved cases into a table set in ``out_dir`` (atomic), with metadata."""
    curves = [curve_from_case(o.result, params.n_pairs, params.sweep.kiss_force_N)
              for o in outcomes.values()]
    shifts = kiss_shift(curves, params.material.reference_temperature_degC)
    crest = crest_growth(outcomes, params.material.reference_temperature_degC)
    prog = {f"{c.theta_degC:g}": progressivity(c.u_m, c.force_N) for c in curves}
    any_case = next(iter(outcomes.values()))
    metadata = {
        "generator": f"cushion_clutch {__version__} (cushion-clutch sweep)",
        "solver": {"name": "CalculiX ccx",
                   "version": ", ".join(sorted({o.ccx_version for o in outcomes.values()}))},
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "host": platform.node(),
        "spring": params.to_dict(),
        "model": "half pair: paddle A against the carrier plane, composed in series "
                 "(pair travel = 2 x paddle travel)" if any_case.result.paddles == 1 else "full pair",
        "mesh": {"element_size_m": params.mesh.element_size_m, "element_type": params.mesh.element_type,
                 "nodes": any_case.n_nodes, "elements": any_case.n_elements},
        "units": {"theta_degC": "degC", "u_m": "m", "force_N": "N", "delta_kiss_m": "m"},
        "definitions": {
            "u_m": "compression of one paddle pair from its own kiss point at that temperature",
            "force_N": f"axial force of the whole spring ({params.n_pairs} pairs)",
            "kiss_point": f"where the force of one pair passes {params.sweep.kiss_force_N:g} N",
            "delta_kiss_m": "growth of the free height (kiss-point shift towards the open side) "
                            "relative to the reference temperature",
            "crest_growth_m": "rise of the pair's wave crests (mean radius) from heating alone, "
                              "relative to the reference temperature (crest_growth.csv)",
            "progressivity": "whole-spring tangent stiffness k (N/m, secant over 5 % of the travel) "
                             "at 20, 50 and 90 % of the travel from the kiss point to full "
                             "compression, and k(90 %)/k(20 %)",
        },
        "progressivity": prog,
        "kiss_point": {f"{t:g}": {"delta_kiss_m": shifts[t], "crest_growth_m": crest[t]}
                       for t in sorted(shifts)},
        "cases": {f"{t:g}": {"increments": o.stats.increments, "iterations": o.stats.iterations,
                             "cutbacks": o.stats.cutbacks, "wall_time_s": round(o.stats.wall_time_s, 2),
                             "crest_rise_m": o.result.crest_rise_m,
                             "full_compression_force_N": float(c.force_N[-1]),
                             "removed_decrease_N": c.removed_decrease_N}
                  for (t, o), c in zip(outcomes.items(), curves)},
        "run_wall_time_s": wall_time_s,
        "cases_from_cache": [t for t, o in outcomes.items() if o.from_cache],
        "note": "wall_time_s per case is ccx's own run time, also for cases served from the cache",
    }
    write_tables(out_dir, curves, params.material.reference_temperature_degC, metadata, crest)
    return curves, shifts


def crest_growth(outcomes: dict[float, CaseOutcome], reference_degC: float) -> dict[float, float]:
    """Free-height growth of one pair at the crest from heating, relative to the reference, m.

    The half-pair model's crest rise stands for both paddles by symmetry;
    the full-pair model's paddle A is one of two equal paddles.
    """
    rise = {t: 2.0 * o.result.crest_rise_m for t, o in outcomes.items()}
    ref = min(rise, key=lambda t: abs(t - reference_degC))
    return {t: r - rise[ref] for t, r in rise.items()}
