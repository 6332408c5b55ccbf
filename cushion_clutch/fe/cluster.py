"""Dask clusters for FE cases: connect, check every worker, ship the inputs, watch for lost workers, close.

The one place where the FE code talks to Dask (:func:`open_cluster`,
:func:`run_cases`). Before any case is submitted every worker is probed with a
self-contained function (shipped by value, so it runs even where the package
is missing): the package must import at the client's version and ``ccx`` must
run, at one version on all workers. That version, not the client's, goes into
the cache keys, so the client needs no ``ccx``. Each case carries the files it
reads (a scanned surface) as bytes, so workers need no shared disk. While cases
run, workers that leave are logged; when none is left for ``LOST_GRACE_S`` the
run stops with the lost workers named (finished cases are already cached).
"""
from __future__ import annotations

import contextlib
import logging
import os
import time
import weakref
from concurrent.futures import ThreadPoolExecutor
from concurrent.futures import TimeoutError as FuturesTimeout
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Hashable, Iterator, Sequence

from .. import __version__
from ..errors import ClusterError
from .ccx import parse_version

log = logging.getLogger(__name__)

PACKAGE = "cushion_clutch"
#: connecting and checking the workers takes at most this long, s
CHECK_TIMEOUT_S = 25.0
#: with no worker left for this long, a run stops and names the lost workers, s
LOST_GRACE_S = 30.0
#: how often a run looks at the workers while it waits, s
POLL_S = 0.5

_PROBE_SOURCE = '''
def cushion_probe(package, need_ccx=True):
    import importlib, os, platform, shutil, subprocess, sys
    out = {"host": platform.node(), "python": sys.version.split()[0], "cores": os.cpu_count() or 1}
    try:
        out["package"] = getattr(importlib.import_module(package), "__version__", "unknown")
    except BaseException as exc:
        out["package_error"] = type(exc).__name__ + ": " + str(exc)
    if not need_ccx:
        return out
    exe = os.environ.get("CCX", "ccx")
    path = shutil.which(exe)
    if path is None:
        out["ccx_error"] = "no " + repr(exe) + " on its PATH"
    else:
        out["ccx_path"] = path
        try:
            run = subprocess.run([path, "-v"], capture_output=True, text=True, timeout=15)
            out["ccx_output"] = run.stdout + run.stderr
        except BaseException as exc:
            out["ccx_error"] = path + " -v failed: " + type(exc).__name__ + ": " + str(exc)
    return out
'''


def _probe():
    """The probe as a function of a module nobody can import: cloudpickle ships it by value."""
    namespace = {"__name__": "cushion_clutch_worker_probe"}
    exec(_PROBE_SOURCE, namespace)  # noqa: S102 - our own constant source
    return namespace["cushion_probe"]


@dataclass(frozen=True)
class WorkerInfo:
    """What the probe found on one worker."""

    address: str
    host: str
    threads: int
    cores: int
    package: str | None
    ccx_version: str | None
    problems: tuple


@dataclass(frozen=True)
class ClusterInfo:
    """The checked workers and the ccx version they all run."""

    scheduler: str
    workers: tuple
    ccx_version: str

    @property
    def slots(self) -> int:
        """Cases the cluster runs at once (worker threads)."""
        return sum(w.threads for w in self.workers)

    def threads_per_case(self, n_cases: int) -> int:
        """ccx threads for each of ``n_cases`` cases: the idle slots shared out, at most a host's cores."""
        if n_cases <= 0 or n_cases >= self.slots:
            return 1
        return max(1, min(self.slots // n_cases, min(w.cores for w in self.workers)))


def _judge(address: str, threads: int, answer, need_ccx: bool = True) -> WorkerInfo:
    if isinstance(answer, BaseException):
        return WorkerInfo(address, "?", threads, 1, None, None,
                          (f"the check failed: {type(answer).__name__}: {answer}",))
    problems = []
    package = answer.get("package")
    if "package_error" in answer:
        problems.append(f"cannot import {PACKAGE} ({answer['package_error']}); install it there "
                        f"(pip install cushion-clutch=={__version__})")
    elif package != __version__:
        problems.append(f"has {PACKAGE} {package}, the client {__version__}; install the same version")
    version = None
    if not need_ccx:
        pass
    elif "ccx_error" in answer:
        problems.append(f"cannot run CalculiX: {answer['ccx_error']} (apt-get install calculix-ccx, or set CCX)")
    else:
        version = parse_version(answer.get("ccx_output", ""))
        if version == "unknown":
            problems.append(f"{answer.get('ccx_path')} -v prints no CalculiX version")
    return WorkerInfo(address, answer.get("host", "?"), threads, int(answer.get("cores", 1)), package,
                      version, tuple(problems))


_CHECKED: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def check_workers(client, timeout_s: float = CHECK_TIMEOUT_S, need_ccx: bool = True) -> ClusterInfo:
    """Probe every worker of ``client``; return the cluster's ccx version or name what each worker lacks.

    ``need_ccx`` False (work without CalculiX, e.g. the fleet's launch simulations): only the package is
    checked, and the info's ``ccx_version`` is "".

    Raises
    ------
    ClusterError
        No worker within ``timeout_s``, no answer within it, a worker that
        cannot import the package (or has another version) or cannot run ccx,
        or workers with different ccx versions. Every worker concerned is named.
    """
    with contextlib.suppress(TypeError):
        if client in _CHECKED and (_CHECKED[client].ccx_version or not need_ccx):
            return _CHECKED[client]
    address = getattr(client.scheduler, "address", str(client))
    start = time.monotonic()
    try:
        client.wait_for_workers(1, timeout=timeout_s)
    except Exception as exc:  # noqa: BLE001 - distributed raises its own TimeoutError kinds
        raise ClusterError(f"no Dask worker joined the scheduler {address} within {timeout_s:g} s "
                           f"({type(exc).__name__}); start workers: python -m distributed.cli.dask_worker "
                           f"{address}") from None
    threads = client.nthreads()
    pool = ThreadPoolExecutor(max_workers=1)
    future = pool.submit(client.run, _probe(), PACKAGE, need_ccx, on_error="return")
    try:
        answers = future.result(timeout=max(1.0, timeout_s - (time.monotonic() - start)))
    except FuturesTimeout:
        raise ClusterError(f"the workers of {address} did not answer the check within {timeout_s:g} s: "
                           f"{', '.join(sorted(threads))}") from None
    except Exception as exc:  # noqa: BLE001 - any failure of the check is the cluster's
        raise ClusterError(f"checking the workers of {address} failed: {type(exc).__name__}: {exc}") from None
    finally:
        pool.shutdown(wait=False)
    workers = [_judge(a, threads.get(a, 1), answers[a], need_ccx) for a in sorted(answers)]
    problems = [f"worker {w.address} (host {w.host}) {p}" for w in workers for p in w.problems]
    versions = {w.ccx_version for w in workers if w.ccx_version}
    if not problems and len(versions) > 1:
        problems.append("the workers run different CalculiX versions (cases would not be comparable): "
                        + "; ".join(f"{w.address} {w.ccx_version}" for w in workers))
    if problems:
        raise ClusterError(f"the Dask cluster at {address} cannot run the {'FE cases' if need_ccx else 'tasks'}:"
                           "\n  - " + "\n  - ".join(problems))
    info = ClusterInfo(address, tuple(workers), versions.pop() if versions else "")
    log.info("cluster %s: %d worker(s), %d slot(s), CalculiX %s", address, len(workers), info.slots,
             info.ccx_version)
    with contextlib.suppress(TypeError):
        _CHECKED[client] = info
    return info


@contextlib.contextmanager
def open_cluster(scheduler=None, workers: int | None = None, timeout_s: float = CHECK_TIMEOUT_S,
                 need_ccx: bool = True) -> Iterator[tuple[object, ClusterInfo]]:
    """A checked Dask client, closed (with the LocalCluster it owns) on exit.

    ``scheduler``: an address (``tcp://host:8786``), a ``distributed.Client``
    (not closed here), or None for a LocalCluster of ``workers`` single-threaded
    processes (default: cores). ``need_ccx``: as :func:`check_workers`.
    """
    from distributed import Client, LocalCluster
    own_client = own_cluster = None
    if scheduler is None:
        own_cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1,
                                   processes=True, dashboard_address=None, silence_logs=logging.ERROR)
        client = own_client = Client(own_cluster)
    elif isinstance(scheduler, str):
        try:
            client = own_client = Client(scheduler, timeout=f"{timeout_s:g}s")
        except (OSError, TimeoutError) as exc:
            raise ClusterError(f"cannot reach the Dask scheduler {scheduler} within {timeout_s:g} s: "
                               f"{exc}") from None
    else:
        client = scheduler
    try:
        yield client, check_workers(client, timeout_s, need_ccx)
    finally:
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()


def run_cases(client, info: ClusterInfo, solve: Callable[..., dict],
              cases: Sequence[tuple[Hashable, object, float, int]],
              on_done: Callable[[Hashable, dict | None, BaseException | None], None], *,
              lost_grace_s: float = LOST_GRACE_S) -> None:
    """Run ``(key, params, theta_degC, paddles)`` cases on the cluster, calling ``on_done`` as each ends.

    ``solve(params, theta_degC, paddles, surface_bytes, threads)`` runs on a
    worker (:func:`cushion_clutch.fe.cases.solve_shipped`). Every case gets
    ``info.threads_per_case(len(cases))`` ccx threads and its scanned surface
    (if any) as bytes. ``on_done(key, data, None)`` for a
    solved case, ``on_done(key, None, exc)`` for a failed one (a case whose
    workers died is reported as such).

    Raises
    ------
    ClusterError
        When no worker has been left for ``lost_grace_s``; names the lost workers
        and how many cases were unfinished.
    """
    threads = info.threads_per_case(len(cases))
    blobs, futures = {}, {}
    for key, params, theta, paddles in cases:
        sf = params.geometry.surface_file
        if sf and sf not in blobs:
            blobs[sf] = client.scatter(Path(sf).read_bytes(), broadcast=True)
        fut = client.submit(solve, params, theta, paddles, blobs.get(sf) if sf else None, threads, pure=False)
        futures[fut] = key
    watch(client, info, futures, on_done, lost_grace_s=lost_grace_s)


def watch(client, info: ClusterInfo, futures: dict, on_done: Callable[[Hashable, object, BaseException | None], None],
          *, lost_grace_s: float = LOST_GRACE_S, what: str = "case(s)",
          resume: str = "finished cases are cached, a rerun resumes") -> None:
    """Wait for ``futures`` (future -> key), calling ``on_done(key, result, None)`` or ``on_done(key, None, exc)``
    as each ends; workers that leave are logged by address.

    Raises
    ------
    ClusterError
        When no worker has been left for ``lost_grace_s``: the lost workers named, how many were unfinished.
    """
    from distributed import as_completed
    from distributed.scheduler import KilledWorker

    known = set(client.nthreads())
    lost: list[str] = []
    alone_since = None
    next_look = time.monotonic() + POLL_S
    ac = as_completed(futures)
    remaining = len(futures)
    while remaining:
        if ac.has_ready():
            for fut in ac.next_batch(block=False):
                remaining -= 1
                key = futures[fut]
                try:
                    data = fut.result()
                except KilledWorker as exc:
                    on_done(key, None, ClusterError(f"the workers running it died: {exc}"))
                except Exception as exc:  # noqa: BLE001 - handed to the caller, who collects failures
                    on_done(key, None, exc)
                else:
                    on_done(key, data, None)
            continue
        time.sleep(0.05)
        if time.monotonic() < next_look:
            continue
        next_look = time.monotonic() + POLL_S
        now = set(client.nthreads())
        for address in sorted(known - now):
            log.warning("Dask worker %s left the cluster", address)
            lost.append(address)
        known = now
        if now:
            alone_since = None
        elif alone_since is None:
            alone_since = time.monotonic()
        elif time.monotonic() - alone_since > lost_grace_s:
            client.cancel(list(futures))
            raise ClusterError(
                f"all Dask workers of {info.scheduler} were lost ({', '.join(lost) or 'none known'}) and none "
                f"joined for {lost_grace_s:g} s; {remaining} {what} unfinished; {resume}")
