"""Calibrate spring parameters to measured load-deflection curves (room temperature, and hot).

The measured curves (:mod:`.measured`, CSV ``u_m,force_N``, kept as measured)
give the compression from the reference temperature's kiss point (where one
pair passes ``sweep.kiss_force_N``, 10 N in the paper) and the force of one
paddle pair or of the whole spring, each at its spring temperature. The named
parameters are fitted by bounded least squares (:func:`scipy.optimize.least_squares`)
on the force residuals relative to the largest measured force; every FE
case runs through :func:`~cushion_clutch.fe.sweep.run_sweep`, so it is cached
on disk and may run on a Dask cluster. The Jacobian's finite-difference
cases of one iteration run in parallel.
"""
from __future__ import annotations

import dataclasses
import logging
import math
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ...errors import ParameterError
from ..cases import DEFAULT_CACHE
from ..params import SpringParams
from ..sweep import run_sweep
from ..tables import curve_from_case
from .measured import U_OFFSET_LIMIT_M, Measured

log = logging.getLogger(__name__)

#: relative finite-difference step of the Jacobian (FE curves are piecewise
#: linear between increments; a small step would differentiate that noise)
FD_STEP = 0.02
#: sections whose float keys may be fitted
FIT_SECTIONS = ("geometry", "carrier", "material", "solver")


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


#: a fitted value this close to a bound (fraction of the bound interval) is "at the bound"
AT_BOUND = 1e-3
#: 1-sigma above this fraction of the value: not identifiable
MAX_REL_SIGMA = 0.20
#: |correlation| above this with another fitted parameter: not identifiable
MAX_CORRELATION = 0.95
#: runs-test p-value below this: the residual is systematic, not noise
RUNS_P = 0.01


@dataclass(frozen=True)
class Calibration:
    """Result of :func:`calibrate` (forces on the measured basis, N; one entry per measured curve)."""

    params: SpringParams
    names: list[str]
    start: np.ndarray
    values: np.ndarray
    bounds: list
    std: np.ndarray
    correlation: np.ndarray
    sensitivity: np.ndarray
    """d ln F / d ln p, force-weighted mean over the curves (% force per % parameter)."""
    measured: list
    fe_start_N: list
    fe_fit_N: list
    rms_N: float
    max_N: float
    rms_pct: float
    """RMS error in % of each curve's largest measured force."""
    max_pct: float
    """Largest error in % of that curve's largest measured force."""
    runs: int
    runs_expected: float
    runs_p: float
    lag1_autocorrelation: float
    fe_cases: int
    cached_cases: int
    wall_time_s: float
    message: str

    def warnings(self) -> list[str]:
        """Every fitted parameter at a bound or not identifiable, and a systematic residual."""
        out = []
        for i, (n, v, (lo, hi), sd) in enumerate(zip(self.names, self.values, self.bounds, self.std)):
            if min(v - lo, hi - v) <= AT_BOUND * (hi - lo):
                out.append(f"{n} = {v:.5g} ends at its {'lower' if v - lo < hi - v else 'upper'} bound "
                           f"({lo:.5g}:{hi:.5g}); the fit wants it further, the true value is not there "
                           "or another parameter (fitted or not) is wrong")
            if not np.isfinite(sd) or sd > MAX_REL_SIGMA * abs(v):
                out.append(f"{n} is not identifiable: 1-sigma {sd:.3g} = "
                           f"{(sd / abs(v) if v else np.inf):.0%} of its value (limit {MAX_REL_SIGMA:.0%})")
            for j in range(i + 1, len(self.names)):
                c = self.correlation[i, j]
                if not np.isfinite(c) or abs(c) > MAX_CORRELATION:
                    out.append(f"{n} and {self.names[j]} are not identifiable apart: correlation "
                               f"{c:+.3f} (limit {MAX_CORRELATION})")
        if self.runs_p < RUNS_P:
            out.append(f"the residual is systematic, not noise: {self.runs} runs of one sign against "
                       f"{self.runs_expected:.1f} expected for noise (runs test p = {self.runs_p:.2g}), "
                       f"lag-1 autocorrelation {self.lag1_autocorrelation:+.2f}; the model cannot follow "
                       "the measured shape")
        return out


def runs_test(residuals: Sequence[np.ndarray]) -> tuple[int, float, float]:
    """Wald-Wolfowitz runs test of the residual signs, each curve ordered by u.

    Returns the number of runs, the number expected for independent noise and
    the one-sided p-value of so few runs (normal approximation).
    """
    from scipy.stats import norm
    runs, n_pos, n_neg = 0, 0, 0
    for r in residuals:
        sign = np.sign(r[r != 0])
        runs += int(len(sign) > 0) + int(np.sum(sign[1:] != sign[:-1]))
        n_pos += int(np.sum(sign > 0))
        n_neg += int(np.sum(sign < 0))
    n = n_pos + n_neg
    if n_pos == 0 or n_neg == 0:
        return runs, 1.0 + 2.0 * n_pos * n_neg / max(n, 1), 0.0 if n > 3 else 1.0
    mean = 1.0 + 2.0 * n_pos * n_neg / n + (len(residuals) - 1)
    var = 2.0 * n_pos * n_neg * (2.0 * n_pos * n_neg - n) / (n * n * (n - 1))
    return runs, mean, float(norm.cdf((runs - mean) / math.sqrt(var))) if var > 0 else 1.0


class _Model:
    """FE force at the measured points for parameter vectors, memoised and cached on disk.

    Every curve's u is the compression from the reference temperature's kiss
    point; a hot case's own curve (from its own kiss point) is read at
    ``u + delta_kiss(theta)``, so the kiss-point shift is fitted too.
    """

    def __init__(self, base: SpringParams, keys, measured: list[Measured], cache_dir: Path,
                 jobs: int, scheduler, on_case: Callable[[int], None] | None):
        self.ref = base.material.reference_temperature_degC
        temps = tuple(sorted({self.ref, *(m.theta_degC for m in measured)}))
        self.base = base.replace(sweep={"temperatures_degC": temps})
        self.keys, self.measured, self.cache_dir = keys, measured, Path(cache_dir)
        self.jobs, self.scheduler, self.on_case = jobs, scheduler, on_case
        self.memo: dict[tuple, np.ndarray] = {}
        #: per parameter vector: the FE kiss shift of each measured curve's temperature, m
        self.shifts: dict[tuple, list[float]] = {}
        self.solved = self.cached = 0

    def forces(self, values) -> list[np.ndarray]:
        return self.many([values])[0]

    def many(self, vectors) -> list[list[np.ndarray]]:
        keys = [tuple(np.round(v, 15)) for v in vectors]
        todo = [k for k in dict.fromkeys(keys) if k not in self.memo]
        with ThreadPoolExecutor(max_workers=max(1, min(self.jobs, len(todo) or 1))) as pool:
            for k, f in zip(todo, pool.map(self._solve, todo)):
                self.memo[k] = f
        return [self.memo[k] for k in keys]

    def _solve(self, values) -> list[np.ndarray]:
        from ..tables import kiss_shift
        p = with_values(self.base, self.keys, values)
        outcomes = run_sweep(p, cache_dir=self.cache_dir, jobs=1, scheduler=self.scheduler)
        self.cached += sum(o.from_cache for o in outcomes.values())
        self.solved += len(outcomes)
        if self.on_case:
            self.on_case(self.solved)
        out, shifts = [], []
        for m in self.measured:
            n = p.n_pairs if m.basis == "spring" else 1
            curves = {t: curve_from_case(o.result, n, p.sweep.kiss_force_N) for t, o in outcomes.items()}
            shift = kiss_shift(list(curves.values()), self.ref)[m.theta_degC]
            shifts.append(float(shift))
            c = curves[m.theta_degC]
            out.append(_interp_extrapolate(m.u_m + shift, c.u_m, c.force_N))
        self.shifts[tuple(np.round(values, 15))] = shifts
        return out


def offset_problems(measured: Sequence[Measured], shifts: Sequence[float],
                    u_offset_limit_m: float = U_OFFSET_LIMIT_M) -> list[str]:
    """Every measured curve starting before the FE's first touch: a curve's compression, counted from the
    reference temperature's kiss point, may go down to ``-(shift + u_offset_limit_m)``, where ``shift`` is the
    kiss shift the FE predicts at its temperature (0 at the reference temperature: the plain zero offset).
    A hot spring has grown by ``shift``, so a bench curve started where it first touches begins that much earlier.
    """
    out = []
    for m, shift in zip(measured, shifts):
        allowed = -(max(shift, 0.0) + u_offset_limit_m)
        if float(np.min(m.u_m)) < allowed:
            out.append(f"measured curve {m.source or '(in code)'} at {m.theta_degC:g} degC starts at u_m = "
                       f"{float(np.min(m.u_m)):g} m; allowed >= {allowed:.4g} m (the FE kiss shift {shift:.4g} m at "
                       f"{m.theta_degC:g} degC plus a zero offset of {u_offset_limit_m:g} m)")
    return out


def _interp_extrapolate(x, xp, fp) -> np.ndarray:
    """Linear interpolation (first force before the curve), beyond its end with the last slope."""
    y = np.interp(x, xp, fp)
    beyond = x > xp[-1]
    if beyond.any():
        slope = (fp[-1] - fp[-2]) / (xp[-1] - xp[-2])
        y[beyond] = fp[-1] + slope * (x[beyond] - xp[-1])
    return y


def calibrate(base: SpringParams, measured: Measured | Sequence[Measured], names: Sequence[str],
              bounds: dict[str, tuple[float, float]] | None = None, *,
              cache_dir: Path = DEFAULT_CACHE, jobs: int = 2, scheduler=None,
              on_case: Callable[[int], None] | None = None, max_iterations: int = 12) -> Calibration:
    """Fit the named parameters of ``base`` to the measured curve(s) by bounded least squares.

    Residuals are (F_FE - F_measured) / max(F_measured) of each curve at its
    measured compressions, FE at each curve's temperature (hot curves: u from
    the reference temperature's kiss point, so thermal keys such as
    ``carrier.temperature_ratio`` or ``geometry.far_end_stiffness_N_per_m`` are
    fitted by the kiss-point shift and the hot curve's shape). Parameters are
    scaled by their start values. Returns the calibrated parameter set and a report.

    Raises
    ------
    ParameterError
        A curve starting before the spring first touches at its temperature (:func:`offset_problems`), besides
        the errors of :func:`fit_keys` and :func:`check_bounds`.
    """
    from scipy.optimize import least_squares

    if isinstance(scheduler, str):                  # one checked client for every FE evaluation
        from ..cluster import open_cluster
        with open_cluster(scheduler) as (client, _):
            return calibrate(base, measured, names, bounds, cache_dir=cache_dir, jobs=jobs, scheduler=client,
                             on_case=on_case, max_iterations=max_iterations)
    measured = [measured] if isinstance(measured, Measured) else list(measured)
    keys = fit_keys(base, names)
    bnds = check_bounds(base, keys, bounds)
    x0 = np.array([getattr(getattr(base, s), k) for s, k in keys], dtype=float)
    model = _Model(base, keys, measured, cache_dir, jobs, scheduler, on_case)
    scales = [float(np.max(m.force_N)) for m in measured]
    t0 = time.perf_counter()
    model.forces(x0)                               # the start: its kiss shifts bound each curve's zero offset
    problems = offset_problems(measured, model.shifts[tuple(np.round(x0, 15))])
    if problems:
        raise ParameterError(problems)

    def rel(forces) -> np.ndarray:
        return np.concatenate([(f - m.force_N) / sc for f, m, sc in zip(forces, measured, scales)])

    def resid(z):
        return rel(model.forces(z * x0))

    def jac(z):
        steps = [z.copy() for _ in z]
        for i, s in enumerate(steps):
            up = z[i] * (1 + FD_STEP)
            s[i] = up if up * x0[i] <= bnds[i][1] else z[i] * (1 - FD_STEP)
        f0, *fs = model.many([z * x0] + [s * x0 for s in steps])
        r0 = rel(f0)
        return np.column_stack([(rel(f) - r0) / (s[i] - z[i]) for i, (f, s) in enumerate(zip(fs, steps))])

    lo = np.array([b[0] for b in bnds]) / x0
    hi = np.array([b[1] for b in bnds]) / x0
    sol = least_squares(resid, np.ones_like(x0), jac=jac, bounds=(lo, hi), x_scale=1.0,
                        diff_step=FD_STEP, max_nfev=max_iterations, xtol=1e-3, ftol=1e-4)
    values = sol.x * x0
    f_fit = model.forces(values)
    f_start = model.forces(x0)
    J = jac(sol.x)
    r = rel(f_fit)
    dof = max(1, len(r) - len(x0))
    s2 = float(np.sum(r ** 2)) / dof
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
        sd_z = np.sqrt(np.clip(np.diag(cov), 0, None))
        std = sd_z * x0
        with np.errstate(invalid="ignore", divide="ignore"):
            corr = cov / np.outer(sd_z, sd_z)
    except np.linalg.LinAlgError:
        std = np.full_like(x0, np.nan)
        corr = np.full((len(x0), len(x0)), np.nan)
    np.fill_diagonal(corr, 1.0)
    w = np.clip(np.concatenate(f_fit), 1e-9, None)
    big = np.concatenate([np.full(len(m.u_m), sc) for m, sc in zip(measured, scales)])
    sens = np.array([float(np.sum(J[:, i] * big * sol.x[i]) / np.sum(w)) for i in range(len(x0))])
    errors = [f - m.force_N for f, m in zip(f_fit, measured)]
    ordered = [e[np.argsort(m.u_m, kind="stable")] for e, m in zip(errors, measured)]
    runs, expected, p_runs = runs_test(ordered)
    flat = np.concatenate([e / sc for e, sc in zip(ordered, scales)])
    lag1 = float(np.corrcoef(flat[:-1], flat[1:])[0, 1]) if len(flat) > 2 and np.std(flat) > 0 else 0.0
    err = np.concatenate(errors)
    return Calibration(
        params=with_values(base, keys, values), names=[f"{s}.{k}" for s, k in keys], start=x0,
        values=values, bounds=bnds, std=std, correlation=corr, sensitivity=sens, measured=measured,
        fe_start_N=f_start, fe_fit_N=f_fit, rms_N=float(np.sqrt(np.mean(err ** 2))),
        max_N=float(np.max(np.abs(err))), rms_pct=100 * float(np.sqrt(np.mean(r ** 2))),
        max_pct=100 * float(np.max(np.abs(r))), runs=runs, runs_expected=expected, runs_p=p_runs,
        lag1_autocorrelation=lag1, fe_cases=model.solved, cached_cases=model.cached,
        wall_time_s=time.perf_counter() - t0, message=str(sol.message))
