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

A curve that carries the pair's free height from a datum (``free_height_m`` with
its 1-sigma, :class:`.measured.Measured`) adds one residual: FE free height minus
measured, in units of its 1-sigma. A curve measured from its own kiss point
hardly depends on the wave height; the free height does.

The reported 1-sigma of each parameter (:attr:`Calibration.std`) is not the
linearised noise alone. It combines, in quadrature,

- the noise term: the linearised covariance, the largest of two Jacobians (steps
  up and down) and the heteroscedasticity-consistent (sandwich) estimate, widened
  where the FE's misfit grows more slowly than the linear model says along the
  parameter's profile direction (two FE runs at +-1 sigma; a parameter the data
  hardly see is scanned over its bounds, ``SCAN_POINTS`` runs), and
- the mesh term: how far the fitted value would move if the FE ran on a
  ``MESH_REFINEMENT`` times finer mesh (one more FE case per temperature, linearised).

Poorly identified parameters are named by :meth:`Calibration.warnings`.
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
from .tolerance_report import pair_free_height

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
#: the mesh term compares the fit's mesh with one this factor finer
MESH_REFINEMENT = 1.5
#: the measured data change by less than this (RMS, % of the largest force, or the free height's 1-sigma
#: times the force noise) per 1 % change of a parameter: the data hardly see it
MIN_SENSITIVITY_PCT = 0.25
#: ... unless a measured free height moves by more than this many of its 1-sigma per 1 % change
MIN_DATUM_SENSITIVITY_SD = 0.5
#: condition number of the Jacobian (parameters scaled by their start values) above this: ill-conditioned
MAX_CONDITION = 30.0
#: FE runs of the scan over the bound range of a parameter that the data hardly see
SCAN_POINTS = 8
#: a scanned point this far (chi2, in units of the noise) below the fit's: the fit stopped in a local minimum
DEEPER_CHI2 = 0.5
#: relative force noise assumed before the fit has estimated it (weights a free height against the forces)
NOISE_GUESS = 0.01


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
    std_noise: np.ndarray | None = None
    """Noise term of the 1-sigma: the linearised one (larger of two Jacobians) times ``profile_factor``."""
    profile_factor: np.ndarray | None = None
    """How much wider the FE's profile at +-1 sigma is than linear (>= 1; inf: no curvature found)."""
    std_mesh: np.ndarray | None = None
    """Mesh term of the 1-sigma: the fitted value's linearised move to a ``MESH_REFINEMENT`` times finer mesh."""
    mesh_check_m: float | None = None
    """Element size of the mesh term's finer mesh, m (None: not run)."""
    sensitivity_rms_pct: np.ndarray | None = None
    """RMS change of the measured forces per 1 % of each parameter, % of each curve's largest force."""
    free_height_sensitivity_sd: np.ndarray | None = None
    """Change of each measured free height per 1 % of each parameter, in its 1-sigma (curves x parameters)."""
    condition: float = float("nan")
    """Condition number of the Jacobian, parameters scaled by their start values."""
    free_height: list | None = None
    """Per curve with a measured free height: (theta_degC, measured m, 1-sigma m, FE start m, FE fitted m)."""
    deeper: list | None = None
    """Per parameter scanned over its bounds (poorly seen): (value, chi2 change) of a point with a lower misfit
    than the fit's, by more than ``DEEPER_CHI2`` (the fit stopped in a local minimum), else None."""

    def warnings(self) -> list[str]:
        """Every fitted parameter at a bound, poorly identified or not identifiable, and a systematic residual."""
        out = []
        sens = self.sensitivity_rms_pct if self.sensitivity_rms_pct is not None else np.full(len(self.names), np.inf)
        for i, (n, v, (lo, hi), sd) in enumerate(zip(self.names, self.values, self.bounds, self.std)):
            if min(v - lo, hi - v) <= AT_BOUND * (hi - lo):
                out.append(f"{n} = {v:.5g} ends at its {'lower' if v - lo < hi - v else 'upper'} bound "
                           f"({lo:.5g}:{hi:.5g}); the fit wants it further, the true value is not there "
                           "or another parameter (fitted or not) is wrong")
            if not np.isfinite(sd) or sd > MAX_REL_SIGMA * abs(v):
                out.append(f"{n} is not identifiable: 1-sigma {sd:.3g} = "
                           f"{(sd / abs(v) if v else np.inf):.0%} of its value (limit {MAX_REL_SIGMA:.0%})")
            datum = (np.max(np.abs(self.free_height_sensitivity_sd[:, i]))
                     if self.free_height_sensitivity_sd is not None and len(self.free_height_sensitivity_sd) else 0.0)
            if poorly_seen(sens, self.free_height_sensitivity_sd)[i]:
                seen = (f", the measured free height by {datum:.2f} of its 1-sigma (limit "
                        f"{MIN_DATUM_SENSITIVITY_SD:g})" if self.free_height else "")
                hint = ("" if self.free_height else ". A datum that depends on it identifies it: for the wave "
                        "height the pair's free height (free_height_m and free_height_sd_m in the curve file)")
                out.append(f"{n} is poorly identified: a 1 % change moves the measured forces by {sens[i]:.3f} % "
                           f"RMS of the largest force (limit {MIN_SENSITIVITY_PCT:g} %){seen}; its value rests on "
                           f"the noise and the mesh, read its 1-sigma{hint}")
            if self.deeper and self.deeper[i] is not None:
                value, drop = self.deeper[i]
                out.append(f"{n}: the misfit is lower at {value:.5g} than at the fitted {v:.5g} (chi2 {drop:+.2f} "
                           "in units of the noise, scanned over its bounds): the fit stopped in a local minimum of "
                           "a bumpy misfit; its 1-sigma spans both")
            for j in range(i + 1, len(self.names)):
                c = self.correlation[i, j]
                if not np.isfinite(c) or abs(c) > MAX_CORRELATION:
                    out.append(f"{n} and {self.names[j]} are not identifiable apart: correlation "
                               f"{c:+.3f} (limit {MAX_CORRELATION})")
        if np.isfinite(self.condition) and self.condition > MAX_CONDITION and len(self.names) > 1:
            out.append(f"the fit is ill-conditioned: condition number {self.condition:.3g} of the Jacobian "
                       f"(parameters scaled by their start values; limit {MAX_CONDITION:g}): the data fix a "
                       "combination of the parameters better than each one")
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
        #: per parameter vector: the FE free height of each curve that has a measured one (else None), m
        self.heights: dict[tuple, list[float | None]] = {}
        self.solved = self.cached = 0

    def forces(self, values) -> list[np.ndarray]:
        return self.many([values])[0]

    def free_heights(self, values) -> list[float | None]:
        """The FE free height of each curve with a measured one (None for the others), m."""
        self.many([values])
        return self.heights[tuple(np.round(values, 15))]

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
        out, shifts, heights = [], [], []
        for m in self.measured:
            n = p.n_pairs if m.basis == "spring" else 1
            curves = {t: curve_from_case(o.result, n, p.sweep.kiss_force_N) for t, o in outcomes.items()}
            shift = kiss_shift(list(curves.values()), self.ref)[m.theta_degC]
            shifts.append(float(shift))
            c = curves[m.theta_degC]
            out.append(_interp_extrapolate(m.u_m + shift, c.u_m, c.force_N))
            heights.append(None if m.free_height_m is None else pair_free_height(p, outcomes[m.theta_degC]))
        self.shifts[tuple(np.round(values, 15))] = shifts
        self.heights[tuple(np.round(values, 15))] = heights
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
              on_case: Callable[[int], None] | None = None, max_iterations: int = 12,
              mesh_check: bool = True) -> Calibration:
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

    Notes
    -----
    A curve with a measured free height adds the residual (h_FE - h) / free_height_sd_m times the
    force noise (first 1 %, then, once, the noise the fit found). ``mesh_check`` (default on) runs
    the fitted parameters on a ``MESH_REFINEMENT`` times finer mesh, one FE case per temperature,
    for the mesh term of the 1-sigma (module docstring).
    """
    from scipy.optimize import least_squares

    if isinstance(scheduler, str):                  # one checked client for every FE evaluation
        from ..cluster import open_cluster
        with open_cluster(scheduler) as (client, _):
            return calibrate(base, measured, names, bounds, cache_dir=cache_dir, jobs=jobs, scheduler=client,
                             on_case=on_case, max_iterations=max_iterations, mesh_check=mesh_check)
    measured = [measured] if isinstance(measured, Measured) else list(measured)
    keys = fit_keys(base, names)
    bnds = check_bounds(base, keys, bounds)
    x0 = np.array([getattr(getattr(base, s), k) for s, k in keys], dtype=float)
    model = _Model(base, keys, measured, cache_dir, jobs, scheduler, on_case)
    scales = [float(np.max(m.force_N)) for m in measured]
    datums = [m for m in measured if m.free_height_m is not None]
    n_force = sum(len(m.u_m) for m in measured)
    t0 = time.perf_counter()
    model.forces(x0)                               # the start: its kiss shifts bound each curve's zero offset
    problems = offset_problems(measured, model.shifts[tuple(np.round(x0, 15))])
    if problems:
        raise ParameterError(problems)
    noise = [NOISE_GUESS]                          # force noise (fraction of the largest force) weighting a datum

    def rel_of(mod: _Model, values) -> np.ndarray:
        """Residuals: forces / largest measured force, then each free height / its 1-sigma x the force noise."""
        forces = mod.forces(values)
        r = [(f - m.force_N) / sc for f, m, sc in zip(forces, measured, scales)]
        r += [np.array([(h - m.free_height_m) / m.free_height_sd_m * noise[0]])
              for h, m in zip(mod.free_heights(values), measured) if m.free_height_m is not None]
        return np.concatenate(r)

    def resid(z):
        return rel_of(model, z * x0)

    def jac(z, sign: int = 1):
        steps = [z.copy() for _ in z]
        for i, s in enumerate(steps):
            first, second = z[i] * (1 + sign * FD_STEP), z[i] * (1 - sign * FD_STEP)
            s[i] = first if bnds[i][0] <= first * x0[i] <= bnds[i][1] else second
        model.many([z * x0] + [s * x0 for s in steps])
        r0 = resid(z)
        return np.column_stack([(resid(s) - r0) / (s[i] - z[i]) for i, s in enumerate(steps)])

    lo = np.array([b[0] for b in bnds]) / x0
    hi = np.array([b[1] for b in bnds]) / x0
    z = np.ones_like(x0)
    dof = max(1, n_force + len(datums) - len(x0))
    for _ in range(2 if datums else 1):            # with a datum: refit once with the noise the fit found
        sol = least_squares(resid, z, jac=jac, bounds=(lo, hi), x_scale=1.0, diff_step=FD_STEP,
                            max_nfev=max_iterations, xtol=1e-3, ftol=1e-4)
        z = sol.x
        found = max(math.sqrt(float(np.sum(resid(z) ** 2)) / dof), 1e-9)
        if not datums or abs(math.log(found / noise[0])) < math.log(1.5):
            break
        noise[0] = found
    values = z * x0
    f_fit = model.forces(values)
    f_start = model.forces(x0)
    r = resid(z)
    s2 = float(np.sum(r ** 2)) / dof
    J = jac(z)
    cov, std_up, corr = _covariance(J, s2)
    _, std_down, _ = _covariance(jac(z, -1), s2)
    std_hc = _sandwich_std(J, r, dof)
    with np.errstate(invalid="ignore"):
        std_lin = np.fmax(np.fmax(std_up, std_down), std_hc) * x0
    w = np.clip(np.concatenate(f_fit), 1e-9, None)
    big = np.concatenate([np.full(len(m.u_m), sc) for m, sc in zip(measured, scales)])
    sens = np.array([float(np.sum(J[:n_force, i] * big * z[i]) / np.sum(w)) for i in range(len(x0))])
    # RMS over every measured force of its change per 1 % of the parameter, % of the largest force
    sens_rms = np.sqrt(np.mean(J[:n_force] ** 2, axis=0)) * z     # fraction per unit relative change = % per %
    sens_datum = J[n_force:] / noise[0] * z * 0.01                 # in the datum's 1-sigma per 1 %
    factor, deeper = _profile_factors(lambda zz: float(np.sum(resid(zz) ** 2)) / s2,
                                      lambda zs: model.many([zz * x0 for zz in zs]), z, cov, lo, hi,
                                      poorly_seen(sens_rms, sens_datum))
    std_noise = std_lin * factor
    mesh_m, std_mesh = None, np.zeros_like(x0)
    if mesh_check:
        mesh_m = base.mesh.element_size_m / MESH_REFINEMENT
        fine = _Model(base.replace(mesh={"element_size_m": mesh_m}), keys, measured, cache_dir, jobs, scheduler,
                      on_case)
        dr = rel_of(fine, values) - r
        std_mesh = np.abs(np.linalg.lstsq(J, dr, rcond=None)[0]) * x0
        model.solved, model.cached = model.solved + fine.solved, model.cached + fine.cached
    std = np.sqrt(std_noise ** 2 + std_mesh ** 2)
    cond = float(np.linalg.cond(J)) if np.all(np.isfinite(J)) else float("inf")
    heights = [(m.theta_degC, m.free_height_m, m.free_height_sd_m, h0, h1)
               for m, h0, h1 in zip(measured, model.free_heights(x0), model.free_heights(values))
               if m.free_height_m is not None]
    errors = [f - m.force_N for f, m in zip(f_fit, measured)]
    ordered = [e[np.argsort(m.u_m, kind="stable")] for e, m in zip(errors, measured)]
    runs, expected, p_runs = runs_test(ordered)
    flat = np.concatenate([e / sc for e, sc in zip(ordered, scales)])
    lag1 = float(np.corrcoef(flat[:-1], flat[1:])[0, 1]) if len(flat) > 2 and np.std(flat) > 0 else 0.0
    err = np.concatenate(errors)
    r_force = r[:n_force]
    return Calibration(
        params=with_values(base, keys, values), names=[f"{s}.{k}" for s, k in keys], start=x0,
        values=values, bounds=bnds, std=std, correlation=corr, sensitivity=sens, measured=measured,
        fe_start_N=f_start, fe_fit_N=f_fit, rms_N=float(np.sqrt(np.mean(err ** 2))),
        max_N=float(np.max(np.abs(err))), rms_pct=100 * float(np.sqrt(np.mean(r_force ** 2))),
        max_pct=100 * float(np.max(np.abs(r_force))), runs=runs, runs_expected=expected, runs_p=p_runs,
        lag1_autocorrelation=lag1, fe_cases=model.solved, cached_cases=model.cached,
        wall_time_s=time.perf_counter() - t0, message=str(sol.message), std_noise=std_noise,
        profile_factor=factor, std_mesh=std_mesh, mesh_check_m=mesh_m, sensitivity_rms_pct=sens_rms,
        condition=cond, free_height=heights, free_height_sensitivity_sd=sens_datum,
        deeper=[None if dp is None else (float(dp[0][i] * x0[i]), float(dp[1])) for i, dp in enumerate(deeper)])


def poorly_seen(sensitivity_rms_pct: np.ndarray, free_height_sensitivity_sd: np.ndarray | None) -> np.ndarray:
    """Per parameter: the forces move by less than ``MIN_SENSITIVITY_PCT`` RMS per 1 % and no measured free
    height by ``MIN_DATUM_SENSITIVITY_SD`` of its 1-sigma or more."""
    datum = (np.max(np.abs(free_height_sensitivity_sd), axis=0)
             if free_height_sensitivity_sd is not None and len(free_height_sensitivity_sd)
             else np.zeros(len(sensitivity_rms_pct)))
    return (np.asarray(sensitivity_rms_pct) < MIN_SENSITIVITY_PCT) & (datum < MIN_DATUM_SENSITIVITY_SD)


def _covariance(J: np.ndarray, s2: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Linearised covariance ``s2 (J^T J)^-1``, its 1-sigma and correlation (NaN where singular)."""
    n = J.shape[1]
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return np.full((n, n), np.nan), np.full(n, np.nan), np.full((n, n), np.nan)
    sd = np.sqrt(np.clip(np.diag(cov), 0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    np.fill_diagonal(corr, 1.0)
    return cov, sd, corr


def _sandwich_std(J: np.ndarray, r: np.ndarray, dof: int) -> np.ndarray:
    """1-sigma of the heteroscedasticity-consistent (sandwich, HC1) covariance.

    ``(J^T J)^-1 J^T diag(r^2) J (J^T J)^-1 n / dof``: right when the noise is not the same at every
    point (a bench's noise grows with its force), where ``s2 (J^T J)^-1`` would trust the quiet
    points' small residuals for the loud ones.
    """
    try:
        inv = np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return np.full(J.shape[1], np.nan)
    meat = (J * (r ** 2)[:, None]).T @ J
    cov = inv @ meat @ inv * len(r) / dof
    return np.sqrt(np.clip(np.diag(cov), 0, None))


def _profile_factors(chi2: Callable[[np.ndarray], float], prefetch: Callable[[list], object], z: np.ndarray,
                     cov: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                     scan: Sequence[bool] | None = None) -> tuple[np.ndarray, list]:
    """Per parameter: how much wider than linear the FE's misfit is along its profile direction.

    The direction moves parameter i by its 1-sigma and the others by their linear regression on it
    (``cov[:, i] / sd_i``), where linear theory raises chi2 (in units of the noise) by exactly 1 per
    unit step t squared. A quadratic ``a t^2 + b t`` through the FE's chi2 at t = +-1 (clipped to the bounds)
    gives the curvature a; the factor is ``1 / sqrt(a)`` when a < 1 (a flatter misfit, a wider interval),
    1 when a >= 1 (never narrowed), inf when the FE finds no curvature.

    A parameter with ``scan[i]`` (one the data hardly see) is scanned instead over its whole bound range,
    ``SCAN_POINTS`` FE runs: the interval is where chi2 stays within 1 of the lowest value found
    (crossings interpolated linearly), and its factor the interval's farther end from the fitted value, in
    sigma (at least the quadratic one). ``prefetch`` solves the points' FE cases together (in parallel)
    before ``chi2`` reads them.

    Returns
    -------
    factors : ndarray
        Per parameter, >= 1 or inf.
    deeper : list
        Per parameter, (scaled parameter vector, chi2 change) of the lowest scanned point if its chi2 lies
        more than ``DEEPER_CHI2`` below the fit's (the fit stopped in a local minimum), else None.
    """
    n = len(z)
    scan = list(scan) if scan is not None else [False] * n
    out, deeper = np.full(n, np.inf), [None] * n
    plans = []
    for i in range(n):
        sd = math.sqrt(cov[i, i]) if np.isfinite(cov[i, i]) and cov[i, i] > 0 else float("nan")
        if not np.isfinite(sd):
            plans.append(None)
            continue
        d = cov[:, i] / sd
        room = {}
        for sign in (1.0, -1.0):
            room[sign] = min([np.inf, *(((hi[k] if d[k] * sign > 0 else lo[k]) - z[k]) / (d[k] * sign)
                                        for k in range(n) if d[k] != 0)])
        ts = [sign * min(1.0, room[sign]) for sign in (1.0, -1.0) if min(1.0, room[sign]) > 1e-3]
        grid = ([t for t in np.linspace(-room[-1.0], room[1.0], SCAN_POINTS) if abs(t) > 1e-3]
                if scan[i] and np.isfinite(room[1.0] + room[-1.0]) else [])
        plans.append((d, ts, grid))
    prefetch([z + t * plan[0] for plan in plans if plan for t in [*plan[1], *plan[2]]])
    c0 = chi2(z)
    for i, plan in enumerate(plans):
        if plan is None:
            continue
        d, ts, grid = plan
        pts = [(t, chi2(z + t * d) - c0) for t in ts]
        if len(pts) == 2:
            (t1, d1), (t2, d2) = pts
            a = (d1 / t1 - d2 / t2) / (t1 - t2)
        elif len(pts) == 1:
            a = pts[0][1] / pts[0][0] ** 2
        else:
            a = 0.0
        out[i] = 1.0 / math.sqrt(a) if 0 < a < 1 else (1.0 if a >= 1 else np.inf)
        if grid:
            curve = sorted(pts + [(t, chi2(z + t * d) - c0) for t in grid] + [(0.0, 0.0)])
            lowest = min(c for _, c in curve)
            if lowest < -DEEPER_CHI2:
                t_low = min(curve, key=lambda tc: tc[1])[0]
                deeper[i] = (z + t_low * d, lowest)
            out[i] = max(out[i], _interval_reach(curve, lowest + 1.0))
    return out, deeper


def _interval_reach(curve: list[tuple[float, float]], level: float) -> float:
    """Farthest |t| of the points at or below ``level`` (t = 0 included), each edge moved out to where the
    piecewise-linear chi2 crosses ``level`` towards the next point; the last point if it is never crossed."""
    t = np.array([c[0] for c in curve])
    c = np.array([c[1] for c in curve])
    inside = np.flatnonzero(c <= level)
    inside = np.union1d(inside, np.flatnonzero(t == 0.0))
    lo_i, hi_i = int(inside.min()), int(inside.max())
    ends = []
    for k, step in ((hi_i, 1), (lo_i, -1)):
        j = k + step
        if 0 <= j < len(t) and c[j] > level and c[j] != c[k]:
            ends.append(t[k] + (t[j] - t[k]) * (level - c[k]) / (c[j] - c[k]) if c[k] <= level else t[k])
        else:
            ends.append(t[k])
    return float(max(abs(e) for e in ends))
