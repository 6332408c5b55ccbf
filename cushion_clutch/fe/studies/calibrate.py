"""Calibrate spring parameters to a measured room-temperature load-deflection curve.

The measured curve (CSV ``u_m,force_N``) is the compression from the kiss
point (the point where one pair passes ``sweep.kiss_force_N``, 10 N in the
paper) and the force of one paddle pair or of the whole spring. The named
parameters are fitted by bounded least squares (:func:`scipy.optimize.least_squares`)
on the force residuals relative to the largest measured force; every FE
case runs through :func:`~cushion_clutch.fe.sweep.run_sweep`, so it is cached
on disk and may run on a Dask cluster. The Jacobian's finite-difference
cases of one iteration run in parallel.
"""
from __future__ import annotations

import csv
import dataclasses
import logging
import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ...errors import ParameterError, TableError
from ..params import SpringParams
from ..cases import DEFAULT_CACHE
from ..sweep import run_sweep
from ..tables import curve_from_case

log = logging.getLogger(__name__)

#: relative finite-difference step of the Jacobian (FE curves are piecewise
#: linear between increments; a small step would differentiate that noise)
FD_STEP = 0.02
#: sections whose float keys may be fitted
FIT_SECTIONS = ("geometry", "carrier", "material", "solver")


@dataclass(frozen=True)
class Measured:
    """A measured load-deflection curve, SI.

    Attributes
    ----------
    u_m : ndarray
        Compression from the kiss point, m, strictly increasing, >= 0.
    force_N : ndarray
        Force, N, non-decreasing.
    basis : str
        ``"pair"`` (one paddle pair) or ``"spring"`` (the whole spring).
    """

    u_m: np.ndarray
    force_N: np.ndarray
    basis: str = "pair"


def read_measured(path: str | Path, basis: str = "pair") -> Measured:
    """Read and check a measured curve CSV with the header ``u_m,force_N``.

    Raises
    ------
    TableError
        Missing file, wrong header, non-numeric, non-finite or too few rows,
        negative compression, u not strictly increasing or force decreasing.
    """
    path = Path(path)
    if basis not in ("pair", "spring"):
        raise TableError(f"measured basis = {basis!r}: allowed 'pair' or 'spring'")
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].lstrip().startswith("#")]
    except OSError as exc:
        raise TableError(f"{path}: cannot read the measured curve ({exc.strerror})") from exc
    if not rows or [c.strip() for c in rows[0]] != ["u_m", "force_N"]:
        raise TableError(f"{path}: the first line must be the header 'u_m,force_N', got "
                         f"{','.join(rows[0]) if rows else 'an empty file'!r}")
    data = []
    for i, row in enumerate(rows[1:], start=2):
        try:
            vals = [float(v) for v in row]
        except ValueError:
            raise TableError(f"{path}, line {i}: not two numbers: {','.join(row)!r}") from None
        if len(vals) != 2 or not all(math.isfinite(v) for v in vals):
            raise TableError(f"{path}, line {i}: need two finite numbers u_m,force_N, got {row}")
        data.append(vals)
    if len(data) < 4:
        raise TableError(f"{path}: need at least 4 data rows, got {len(data)}")
    a = np.array(data)
    if a[0, 0] < -1e-9:
        raise TableError(f"{path}: u_m must be >= 0 (compression from the kiss point), "
                         f"first row has {a[0, 0]:g}")
    if np.any(np.diff(a[:, 0]) <= 0):
        i = int(np.argmax(np.diff(a[:, 0]) <= 0)) + 3
        raise TableError(f"{path}, line {i}: u_m must increase strictly (non-monotone curve)")
    if np.any(np.diff(a[:, 1]) < 0):
        i = int(np.argmax(np.diff(a[:, 1]) < 0)) + 3
        raise TableError(f"{path}, line {i}: force_N decreases (non-monotone curve)")
    return Measured(a[:, 0], a[:, 1], basis)


def fit_keys(params: SpringParams, names: Sequence[str]) -> list[tuple[str, str]]:
    """Resolve parameter names (``thickness_m`` or ``geometry.thickness_m``) to (section, key).

    Raises
    ------
    ParameterError
        For an unknown or non-numeric name, listing the names that can be fitted.
    """
    allowed: dict[str, tuple[str, str]] = {}
    for sec in FIT_SECTIONS:
        for f in dataclasses.fields(getattr(params, sec)):
            value = getattr(getattr(params, sec), f.name)
            if isinstance(value, float) and not isinstance(value, bool):
                allowed[f"{sec}.{f.name}"] = (sec, f.name)
                allowed.setdefault(f.name, (sec, f.name))
    out, problems = [], []
    for name in names:
        if name in allowed:
            out.append(allowed[name])
        else:
            problems.append(f"--fit {name!r}: unknown parameter (allowed: "
                            f"{', '.join(sorted(k for k in allowed if '.' not in k))})")
    if len(set(out)) != len(out):
        problems.append(f"--fit {','.join(names)}: a parameter is named twice")
    if problems:
        raise ParameterError(problems)
    return out


def with_values(params: SpringParams, keys: Sequence[tuple[str, str]], values: Sequence[float]) -> SpringParams:
    """A copy of ``params`` with the given (section, key) values (checked)."""
    changes: dict[str, dict] = {}
    for (sec, key), v in zip(keys, values):
        changes.setdefault(sec, {})[key] = float(v)
    return params.replace(**changes)


def check_bounds(params: SpringParams, keys, bounds: dict[str, tuple[float, float]] | None,
                 spread: float = 0.3) -> list[tuple[float, float]]:
    """Bounds of each fitted key: given ones, else +-``spread`` of the start value.

    Given bounds are checked against the TOML's allowed ranges by building the
    parameter set at each bound. Raises :class:`ParameterError` naming the key.
    """
    bounds = dict(bounds or {})
    out, problems = [], []
    names = {f"{s}.{k}": (s, k) for s, k in keys} | {k: (s, k) for s, k in keys}
    for b in bounds:
        if b not in names:
            problems.append(f"--bounds {b}: not among the fitted parameters")
    for sec, key in keys:
        x0 = getattr(getattr(params, sec), key)
        lo, hi = bounds.get(key, bounds.get(f"{sec}.{key}", (x0 * (1 - spread), x0 * (1 + spread))))
        if not lo < hi:
            problems.append(f"--bounds {key}: need lower < upper, got {lo:g}:{hi:g}")
        elif not lo <= x0 <= hi:
            problems.append(f"--bounds {key}: the start value {x0:g} lies outside {lo:g}:{hi:g}")
        for v in (lo, hi):
            try:
                with_values(params, [(sec, key)], [v])
            except ParameterError as exc:
                problems += [f"--bounds {key}: {v:g} is outside the allowed range: {p}"
                             for p in exc.problems]
        out.append((float(lo), float(hi)))
    if problems:
        raise ParameterError(problems)
    return out


def parse_bounds(text: str | None) -> dict[str, tuple[float, float]]:
    """``"wave_height_m=0.5e-3:0.9e-3,thickness_m=0.3e-3:0.5e-3"`` to a dict."""
    out: dict[str, tuple[float, float]] = {}
    for item in filter(None, (s.strip() for s in (text or "").split(","))):
        try:
            name, rng = item.split("=")
            lo, hi = (float(v) for v in rng.split(":"))
        except ValueError:
            raise ParameterError([f"--bounds {item!r}: expected NAME=LOWER:UPPER"]) from None
        out[name.strip()] = (lo, hi)
    return out


@dataclass(frozen=True)
class Calibration:
    """Result of :func:`calibrate` (forces on the measured basis, N)."""

    params: SpringParams
    names: list[str]
    start: np.ndarray
    values: np.ndarray
    std: np.ndarray
    sensitivity: np.ndarray
    """d ln F / d ln p, force-weighted mean over the curve (% force per % parameter)."""
    measured: Measured
    fe_start_N: np.ndarray
    fe_fit_N: np.ndarray
    rms_N: float
    max_N: float
    rms_pct: float
    """RMS error in % of the largest measured force."""
    max_pct: float
    """Largest error in % of the largest measured force."""
    fe_cases: int
    cached_cases: int
    wall_time_s: float
    message: str


class _Model:
    """FE force at the measured points for parameter vectors, memoised and cached on disk."""

    def __init__(self, base: SpringParams, keys, measured: Measured, cache_dir: Path,
                 jobs: int, scheduler, on_case: Callable[[int], None] | None):
        ref = base.material.reference_temperature_degC
        self.base = base.replace(sweep={"temperatures_degC": (ref,)})
        self.keys, self.measured, self.cache_dir = keys, measured, Path(cache_dir)
        self.jobs, self.scheduler, self.on_case = jobs, scheduler, on_case
        self.memo: dict[tuple, np.ndarray] = {}
        self.solved = self.cached = 0

    def forces(self, values) -> np.ndarray:
        return self.many([values])[0]

    def many(self, vectors) -> list[np.ndarray]:
        keys = [tuple(np.round(v, 15)) for v in vectors]
        todo = [k for k in dict.fromkeys(keys) if k not in self.memo]
        with ThreadPoolExecutor(max_workers=max(1, min(self.jobs, len(todo) or 1))) as pool:
            for k, f in zip(todo, pool.map(self._solve, todo)):
                self.memo[k] = f
        return [self.memo[k] for k in keys]

    def _solve(self, values) -> np.ndarray:
        p = with_values(self.base, self.keys, values)
        outcome = next(iter(run_sweep(p, cache_dir=self.cache_dir, jobs=1,
                                      scheduler=self.scheduler).values()))
        self.cached += outcome.from_cache
        self.solved += 1
        if self.on_case:
            self.on_case(self.solved)
        n = p.n_pairs if self.measured.basis == "spring" else 1
        c = curve_from_case(outcome.result, n, p.sweep.kiss_force_N)
        return _interp_extrapolate(self.measured.u_m, c.u_m, c.force_N)


def _interp_extrapolate(x, xp, fp) -> np.ndarray:
    """Linear interpolation, extended beyond the last point with the last slope."""
    y = np.interp(x, xp, fp)
    beyond = x > xp[-1]
    if beyond.any():
        slope = (fp[-1] - fp[-2]) / (xp[-1] - xp[-2])
        y[beyond] = fp[-1] + slope * (x[beyond] - xp[-1])
    return y


def calibrate(base: SpringParams, measured: Measured, names: Sequence[str],
              bounds: dict[str, tuple[float, float]] | None = None, *,
              cache_dir: Path = DEFAULT_CACHE, jobs: int = 2, scheduler=None,
              on_case: Callable[[int], None] | None = None, max_iterations: int = 12) -> Calibration:
    """Fit the named parameters of ``base`` to ``measured`` by bounded least squares.

    Residuals are (F_FE - F_measured) / max(F_measured) at the measured
    compressions, FE at the reference temperature. Parameters are scaled by
    their start values. Returns the calibrated parameter set and a report.
    """
    from scipy.optimize import least_squares

    keys = fit_keys(base, names)
    bnds = check_bounds(base, keys, bounds)
    x0 = np.array([getattr(getattr(base, s), k) for s, k in keys], dtype=float)
    model = _Model(base, keys, measured, cache_dir, jobs, scheduler, on_case)
    scale = float(np.max(measured.force_N))
    t0 = time.perf_counter()

    def resid(z):
        return (model.forces(z * x0) - measured.force_N) / scale

    def jac(z):
        steps = [z.copy() for _ in z]
        for i, s in enumerate(steps):
            up = z[i] * (1 + FD_STEP)
            s[i] = up if up * x0[i] <= bnds[i][1] else z[i] * (1 - FD_STEP)
        f0, *fs = model.many([z * x0] + [s * x0 for s in steps])
        return np.column_stack([(f - f0) / scale / (s[i] - z[i]) for i, (f, s) in enumerate(zip(fs, steps))])

    lo = np.array([b[0] for b in bnds]) / x0
    hi = np.array([b[1] for b in bnds]) / x0
    sol = least_squares(resid, np.ones_like(x0), jac=jac, bounds=(lo, hi), x_scale=1.0,
                        diff_step=FD_STEP, max_nfev=max_iterations, xtol=1e-3, ftol=1e-4)
    values = sol.x * x0
    f_fit = model.forces(values)
    f_start = model.forces(x0)
    J = jac(sol.x)
    err = f_fit - measured.force_N
    dof = max(1, len(err) - len(x0))
    s2 = float(np.sum((err / scale) ** 2)) / dof
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
        std = np.sqrt(np.clip(np.diag(cov), 0, None)) * x0
    except np.linalg.LinAlgError:
        std = np.full_like(x0, np.nan)
    w = np.clip(f_fit, 1e-9, None)
    sens = np.array([float(np.sum(J[:, i] * scale * sol.x[i]) / np.sum(w)) for i in range(len(x0))])
    return Calibration(
        params=with_values(base, keys, values), names=[f"{s}.{k}" for s, k in keys], start=x0,
        values=values, std=std, sensitivity=sens, measured=measured, fe_start_N=f_start,
        fe_fit_N=f_fit, rms_N=float(np.sqrt(np.mean(err ** 2))), max_N=float(np.max(np.abs(err))),
        rms_pct=100 * float(np.sqrt(np.mean(err ** 2))) / scale,
        max_pct=100 * float(np.max(np.abs(err))) / scale,
        fe_cases=model.solved, cached_cases=model.cached, wall_time_s=time.perf_counter() - t0,
        message=str(sol.message))
