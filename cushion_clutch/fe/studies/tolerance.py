"""Tolerance studies: sample the declared production scatter, solve every sample on Dask.

Each sample is the spring with its ``[tolerances]`` keys drawn (Latin
hypercube or Monte Carlo, seeded; normal distributions truncated at
``Tolerances.TRUNCATE_SD``). Every (sample, temperature) case goes through
the sweep's cache (same folders and keys as :func:`cushion_clutch.fe.sweep.run_sweep`,
so a study and ``cushion-clutch sweep`` share cases); the FE case engine
(:mod:`.cases`) submits only missing cases to a Dask cluster and caches each
finished case as soon as it arrives, so an interrupted study resumes. The
cluster is a ``distributed.LocalCluster`` of single-threaded worker processes
unless a scheduler address (``tcp://host:8786``) or a client is given.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from scipy.stats import norm, qmc

from ...errors import ParameterError, StudyError
from ...number_check import is_number
from ..cases import DEFAULT_CACHE, Case, CaseOutcome, run_cases
from ..params import TOLERANCE_KEYS, SpringParams, Tolerances

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
    if not (is_number(n) and isinstance(n, int) and 2 <= n <= 100000):
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
    cases = [Case(s.params, theta, 1, f"sample {s.index}, theta = {theta:g} degC")
             for s in samples for theta in temperatures_degC]
    total, counts = len(cases), {"done": 0, "cached": 0}

    def on_event(i: int, event: str, value: float) -> None:
        if event in ("cached", "done", "failed"):
            counts["done"] += 1
            counts["cached"] += event == "cached"
            if progress:
                progress(counts["done"], total, counts["cached"])

    outcomes, failures = run_cases(cases, cache_dir=cache_dir, jobs=workers, scheduler=scheduler,
                                   local_cluster=True, on_event=on_event)
    if failures:
        raise StudyError({(samples[i // len(temperatures_degC)].index, cases[i].theta_degC): exc
                          for i, exc in failures.items()})
    n = len(temperatures_degC)
    return [{cases[j].theta_degC: outcomes[j] for j in sorted(range(k * n, (k + 1) * n),
                                                              key=lambda j: cases[j].theta_degC)}
            for k in range(len(samples))]
