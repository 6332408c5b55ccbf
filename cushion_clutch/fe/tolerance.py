"""Tolerance studies: sample the declared production scatter, solve every sample on Dask.

Each sample is the spring with its ``[tolerances]`` keys drawn (Latin
hypercube or Monte Carlo, seeded; normal distributions truncated at
``Tolerances.TRUNCATE_SD``). Every (sample, temperature) case goes through
the sweep's cache (same folders and keys as :func:`cushion_clutch.fe.sweep.run_sweep`,
so a study and ``cushion-clutch sweep`` share cases); only missing cases are
submitted to a Dask cluster, and each finished case is cached as soon as it
arrives, so an interrupted study resumes. The cluster is a
``distributed.LocalCluster`` of single-threaded worker processes unless a
scheduler address (``tcp://host:8786``) or a client is given.
"""
from __future__ import annotations

import dataclasses
import json
import logging
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from scipy.stats import norm, qmc

from ..errors import ParameterError, StudyError
from .params import TOLERANCE_KEYS, SpringParams, Tolerances
from .sweep import DEFAULT_CACHE, CaseOutcome, case_key, solve_shipped

log = logging.getLogger(__name__)

METHODS = ("lhs", "mc")

#: progress callback: (cases finished, cases in total, cases served from the cache)
StudyProgress = Callable[[int, int, int], None]


@dataclass(frozen=True)
class Sample:
    """One drawn spring.

    Attributes
    ----------
    index : int
        0 is the nominal spring; drawn samples are 1..N.
    deviations : dict of str to float
        Drawn deviation of each declared tolerance key (its unit: see
        :data:`cushion_clutch.fe.params.TOLERANCE_KEYS`).
    params : SpringParams
        The spring to solve.
    """

    index: int
    deviations: dict
    params: SpringParams


def draw(tolerances: Tolerances, n: int, method: str = "lhs", seed: int = 0) -> dict[str, np.ndarray]:
    """``n`` deviations of every declared tolerance: Latin hypercube or Monte Carlo, seeded.

    Raises
    ------
    ParameterError
        No tolerance declared, a bad ``n`` or ``method``.
    """
    problems = []
    if method not in METHODS:
        problems.append(f"--method {method!r}: allowed {', '.join(METHODS)}")
    if isinstance(n, bool) or not isinstance(n, int) or not 2 <= n <= 100000:
        problems.append(f"--samples {n!r}: must be an integer in [2, 100000]")
    sds = tolerances.declared()
    if not sds:
        problems.append("[tolerances]: no tolerance declared; add e.g. thickness_m = {sd = 5e-6} "
                        f"(keys: {', '.join(TOLERANCE_KEYS)})")
    if problems:
        raise ParameterError(problems)
    d = len(sds)
    if method == "lhs":
        u = qmc.LatinHypercube(d, rng=np.random.default_rng(seed)).random(n)
    else:
        u = np.random.default_rng(seed).random((n, d))
    lo, hi = norm.cdf(-Tolerances.TRUNCATE_SD), norm.cdf(Tolerances.TRUNCATE_SD)
    z = norm.ppf(lo + u * (hi - lo))
    return {k: sd * z[:, j] for j, (k, sd) in enumerate(sds.items())}


def apply_deviations(base: SpringParams, deviations: dict[str, float]) -> SpringParams:
    """The spring with the deviations applied (checked like any spring)."""
    g, m = base.geometry, base.material
    geometry = {"thickness_m": g.thickness_m + deviations.get("thickness_m", 0.0),
                "wave_height_m": g.wave_height_m + deviations.get("wave_height_m", 0.0)}
    scale = 1.0 + deviations.get("youngs_modulus_scale", 0.0)
    return base.replace(geometry=geometry,
                        material={"youngs_modulus_Pa": tuple(e * scale for e in m.youngs_modulus_Pa)})


def make_samples(base: SpringParams, n: int, method: str = "lhs", seed: int = 0) -> list[Sample]:
    """The nominal spring (index 0) and ``n`` drawn samples (1..n)."""
    dev = draw(base.tolerances, n, method, seed)
    samples = [Sample(0, {k: 0.0 for k in dev}, base)]
    for i in range(n):
        d = {k: float(v[i]) for k, v in dev.items()}
        samples.append(Sample(i + 1, d, apply_deviations(base, d)))
    return samples


def case_folder(cache_dir: Path, params: SpringParams, theta: float, ccx: str, paddles: int = 1) -> Path:
    """The case's cache folder: the layout of :func:`cushion_clutch.fe.sweep.run_sweep`."""
    return Path(cache_dir) / params.name / f"theta_{theta:g}_{case_key(params, theta, paddles, ccx)}"


def run_study(samples: list[Sample], temperatures_degC: tuple[float, ...], *, cache_dir: Path = DEFAULT_CACHE,
              scheduler: str | object | None = None, workers: int | None = None,
              progress: StudyProgress | None = None) -> list[dict[float, CaseOutcome]]:
    """Solve every sample at every temperature; cached cases are not re-solved.

    Returns
    -------
    list of dict
        For each sample (in order), temperature (degC) to its case.

    Raises
    ------
    StudyError
        If cases failed; the finished ones stay cached and a rerun resumes.
    """
    from .cluster import open_cluster
    with open_cluster(scheduler, workers) as (client, info):
        return _run_study(samples, temperatures_degC, cache_dir, client, info, progress)


def _run_study(samples, temperatures_degC, cache_dir, client, info, progress):
    """:func:`run_study` on a checked cluster (``info``: :class:`.cluster.ClusterInfo`)."""
    from .cluster import run_cases
    ccx = info.ccx_version                   # the workers' CalculiX, not the client's
    results: list[dict[float, CaseOutcome]] = [{} for _ in samples]
    todo = []
    for i, s in enumerate(samples):
        for theta in temperatures_degC:
            folder = case_folder(cache_dir, s.params, theta, ccx)
            if (folder / "result.json").exists():
                results[i][theta] = CaseOutcome.from_json(json.loads((folder / "result.json").read_text()))
            else:
                todo.append((i, theta, folder))
    total = len(samples) * len(temperatures_degC)
    cached = total - len(todo)
    done = [cached]
    if progress:
        progress(cached, total, cached)
    failures = {}

    def on_done(key, data, exc) -> None:
        i, theta, folder = key
        if exc is not None:
            log.error("sample %d, theta = %g degC failed: %s", samples[i].index, theta, exc)
            failures[(samples[i].index, theta)] = exc
        else:
            folder.mkdir(parents=True, exist_ok=True)
            tmp = folder / "result.json.tmp"
            tmp.write_text(json.dumps(data))
            os.replace(tmp, folder / "result.json")
            results[i][theta] = dataclasses.replace(CaseOutcome.from_json(data), from_cache=False)
        done[0] += 1
        if progress:
            progress(done[0], total, cached)

    if todo:
        run_cases(client, info, solve_shipped,
                  [((i, theta, folder), samples[i].params, theta, 1) for i, theta, folder in todo], on_done)
    if failures:
        raise StudyError(failures)
    return [{t: r[t] for t in sorted(r)} for r in results]
