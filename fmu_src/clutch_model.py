"""Temperature-aware dry-clutch torque model (paper eqs. 2-5), numpy only.

One implementation of the physics, used by the FMU slave (``CushionClutch``)
and by the Python API (:mod:`cushion_clutch.model`). SI units throughout;
temperatures in K except where a name says ``_degC`` (the tables).

- Cushion-spring temperature: ``C dtheta_cs/dt = U (theta_cm - theta_cs) +
  H (theta_a - theta_cs)``, advanced with its exact solution for an input
  held over the step, so any step size is stable and exact.
- Kiss point at the bearing: ``x_kiss = x_kiss_ref - lever_ratio delta_kiss(theta_cs)``.
- Cushion compression: ``u = (x_to - x_kiss) / lever_ratio``; ``u_f = max(u, 0)``.
- Force ``F(u, theta_cs)``: shape-preserving (PCHIP, Fritsch-Carlson) cubic in u
  per table temperature, linear between temperatures; u below the table's
  first contact gives its first force (zero), beyond full compression the
  full-compression force; temperatures outside the table are clamped.
- Torque ``T = n_surfaces mu R_eq F``.
"""
from __future__ import annotations

import math
from bisect import bisect_right
from dataclasses import dataclass, fields
from pathlib import Path

import numpy as np

KELVIN = 273.15

#: The FMU interface, in value-reference order: (name, causality, unit, description).
#: Both FMUs (pythonfmu and native C) expose exactly these; parameters take
#: their defaults from :class:`ClutchParameters`.
VARIABLES = (
    ("x_to", "input", "m", "throwout-bearing position, 0 = open"),
    ("theta_cm", "input", "K", "clutch facing temperature"),
    ("torque", "output", "N.m", "transmissible clutch torque n*mu*R_eq*F"),
    ("force", "output", "N", "cushion-spring clamp force F(u, theta_cs)"),
    ("theta_cs", "output", "K", "cushion-spring temperature"),
    ("u_f", "output", "m", "cushion compression from the kiss point, clipped at 0"),
    ("x_kiss", "output", "m", "kiss point at the bearing at theta_cs"),
    ("n_surfaces", "parameter", "1", "number of friction surfaces"),
    ("mu", "parameter", "1", "dynamic friction coefficient"),
    ("R_eq", "parameter", "m", "equivalent friction radius"),
    ("U", "parameter", "W/K", "facing-to-cushion-spring thermal conductance"),
    ("H", "parameter", "W/K", "cushion-spring-to-ambient heat transfer coefficient"),
    ("C", "parameter", "J/K", "cushion-spring heat capacity"),
    ("theta_a", "parameter", "K", "ambient temperature"),
    ("theta_cs_start", "parameter", "K", "initial cushion-spring temperature"),
    ("x_kiss_ref", "parameter", "m", "kiss point at the bearing at the table reference temperature"),
    ("lever_ratio", "parameter", "1", "diaphragm-spring lever ratio, bearing / pressure-plate travel"),
)
#: largest |x_to| accepted by the FMUs, m (a bearing stroke is centimetres)
X_TO_LIMIT = 1.0
#: open upper bound of an accepted facing temperature, K
THETA_CM_LIMIT = 2000.0


def pchip_slopes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Derivatives of the monotone piecewise cubic Hermite interpolant.

    Interior slopes are the weighted harmonic mean of the neighbouring secant
    slopes (zero where they differ in sign or one is zero); end slopes use the
    three-point formula limited to keep the shape (as SciPy's PchipInterpolator).
    """
    x = np.asarray(x, float)
    y = np.asarray(y, float)
    h = np.diff(x)
    delta = np.diff(y) / h
    n = len(x)
    d = np.zeros(n)
    if n == 2:
        d[:] = delta[0]
        return d
    w1 = 2 * h[1:] + h[:-1]
    w2 = h[1:] + 2 * h[:-1]
    same = (delta[:-1] * delta[1:]) > 0
    with np.errstate(divide="ignore", invalid="ignore"):
        hm = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
    d[1:-1] = np.where(same, hm, 0.0)
    d[0] = _end_slope(h[0], h[1], delta[0], delta[1])
    d[-1] = _end_slope(h[-1], h[-2], delta[-1], delta[-2])
    return d


def _end_slope(h0: float, h1: float, m0: float, m1: float) -> float:
    d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > abs(3 * m0):
        return 3 * m0
    return float(d)


class Curve:
    """One F(u) curve with its PCHIP slopes, evaluated in plain Python (fast for scalars)."""

    __slots__ = ("x", "y", "d", "x_min", "x_max")

    def __init__(self, u: np.ndarray, force: np.ndarray):
        self.x = [float(v) for v in u]
        self.y = [float(v) for v in force]
        self.d = [float(v) for v in pchip_slopes(u, force)]
        self.x_min, self.x_max = self.x[0], self.x[-1]

    def __call__(self, u: float) -> float:
        x, y, d = self.x, self.y, self.d
        if u <= self.x_min:
            return y[0]
        if u >= self.x_max:
            return y[-1]
        i = bisect_right(x, u) - 1
        h = x[i + 1] - x[i]
        t = (u - x[i]) / h
        t2, t3 = t * t, t * t * t
        return ((2 * t3 - 3 * t2 + 1) * y[i] + (t3 - 2 * t2 + t) * h * d[i]
                + (-2 * t3 + 3 * t2) * y[i + 1] + (t3 - t2) * h * d[i + 1])


class SpringTable:
    """F(u, theta) and delta_kiss(theta) from a table set.

    Parameters
    ----------
    theta_degC : sequence of float
        Table temperatures, degC, strictly increasing.
    u_m, force_N : sequences of arrays
        Per temperature: compression from the kiss point (m) and whole-spring
        force (N), non-decreasing.
    delta_kiss_m : sequence of float
        Kiss-point shift (growth of the free height) per temperature, m.
    """

    def __init__(self, theta_degC, u_m, force_N, delta_kiss_m):
        self.theta_degC = [float(t) for t in theta_degC]
        if len(self.theta_degC) < 1 or any(b <= a for a, b in zip(self.theta_degC, self.theta_degC[1:])):
            raise ValueError("table temperatures must be strictly increasing")
        self.curves = [Curve(np.asarray(u, float), np.asarray(f, float)) for u, f in zip(u_m, force_N)]
        self.delta_kiss_m = [float(d) for d in delta_kiss_m]
        if not (len(self.curves) == len(self.delta_kiss_m) == len(self.theta_degC)):
            raise ValueError("force and kiss-point tables have different temperatures")
        for t, c in zip(self.theta_degC, self.curves):
            if len(c.x) < 2 or any(b <= a for a, b in zip(c.x, c.x[1:])) or any(
                    b < a for a, b in zip(c.y, c.y[1:])) or not all(map(math.isfinite, c.y)):
                raise ValueError(f"curve at {t:g} degC: u must increase and force must not decrease")
        self.theta_min_K = self.theta_degC[0] + KELVIN
        self.theta_max_K = self.theta_degC[-1] + KELVIN

    @classmethod
    def from_dir(cls, folder: str | Path) -> "SpringTable":
        """Read ``force_deflection.csv`` and ``kiss_point.csv`` from a folder.

        Raises
        ------
        ValueError
            With the file name, if a file is malformed.
        """
        folder = Path(folder)
        fd = load_csv(folder / "force_deflection.csv", ("theta_degC", "u_m", "force_N"))
        kp = load_csv(folder / "kiss_point.csv", ("theta_degC", "delta_kiss_m"))
        thetas = np.unique(fd[:, 0])
        if not np.array_equal(np.sort(kp[:, 0]), thetas):
            raise ValueError(f"{folder}: kiss_point.csv and force_deflection.csv temperatures differ")
        kp = kp[np.argsort(kp[:, 0])]
        return cls(thetas, [fd[fd[:, 0] == t, 1] for t in thetas],
                   [fd[fd[:, 0] == t, 2] for t in thetas], kp[:, 1])

    def _bracket(self, theta_degC: float) -> tuple[int, float]:
        """Index i and weight w so that theta lies between table i and i+1 (clamped)."""
        ts = self.theta_degC
        if theta_degC <= ts[0] or len(ts) == 1:
            return 0, 0.0
        if theta_degC >= ts[-1]:
            return len(ts) - 2, 1.0
        i = bisect_right(ts, theta_degC) - 1
        return i, (theta_degC - ts[i]) / (ts[i + 1] - ts[i])

    def force(self, u_m: float, theta_degC: float) -> float:
        """Whole-spring force at compression ``u_m`` from the kiss point, N."""
        i, w = self._bracket(theta_degC)
        f0 = self.curves[i](u_m)
        return f0 if w == 0.0 else (1.0 - w) * f0 + w * self.curves[i + 1](u_m)

    def delta_kiss(self, theta_degC: float) -> float:
        """Kiss-point shift of the spring, m (linear in theta, clamped)."""
        i, w = self._bracket(theta_degC)
        d = self.delta_kiss_m
        return d[i] if w == 0.0 else (1.0 - w) * d[i] + w * d[i + 1]

    def _active(self, theta_degC: float) -> list[Curve]:
        """Curves that carry weight at this temperature."""
        i, w = self._bracket(theta_degC)
        return [c for c, wc in ((self.curves[i], 1.0 - w), (self.curves[min(i + 1, len(self.curves) - 1)], w))
                if wc > 0.0]

    def full_compression(self, theta_degC: float) -> float:
        """Compression from which F no longer grows at this temperature, m."""
        return max(c.x_max for c in self._active(theta_degC))

    def first_contact(self, theta_degC: float) -> float:
        """Compression below which F is its first (zero) value at this temperature, m (<= 0)."""
        return min(c.x_min for c in self._active(theta_degC))


def load_csv(path: Path, columns: tuple[str, ...]) -> np.ndarray:
    """Rows of a table CSV with exactly ``columns`` as header; ValueError names the file."""
    try:
        with open(path) as fh:
            header = fh.readline().strip().split(",")
            data = np.loadtxt(fh, delimiter=",", ndmin=2)
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from exc
    if tuple(h.strip() for h in header) != columns or data.shape[1] != len(columns):
        raise ValueError(f"{path}: header must be {','.join(columns)}")
    if not np.all(np.isfinite(data)):
        raise ValueError(f"{path}: non-finite value")
    return data


@dataclass
class ClutchParameters:
    """Clutch and thermal parameters (SI; temperatures in K)."""

    n_surfaces: float = 2.0       #: number of friction surfaces (pairs of contact), 1
    mu: float = 0.28              #: dynamic friction coefficient, 1
    R_eq: float = 0.089           #: equivalent friction radius, m
    U: float = 0.1                #: facing-to-cushion-spring conductance, W/K
    H: float = 0.04               #: cushion-spring-to-ambient transfer coefficient, W/K
    C: float = 1.0                #: cushion-spring heat capacity, J/K
    theta_a: float = 293.15       #: ambient temperature, K
    theta_cs_start: float = 293.15  #: initial cushion-spring temperature, K
    x_kiss_ref: float = 0.004     #: kiss point at the bearing at the table's reference temperature, m
    lever_ratio: float = 3.0      #: diaphragm-spring lever ratio, bearing travel / pressure-plate travel, 1

    #: allowed ranges: (low, high, low_open, high_open)
    RANGES = {
        "n_surfaces": (1.0, 16.0, False, False),
        "mu": (0.0, 2.0, False, False),
        "R_eq": (0.0, 1.0, True, False),
        "U": (0.0, 1e4, False, False),
        "H": (0.0, 1e4, False, False),
        "C": (0.0, 1e6, True, False),
        "theta_a": (0.0, 2000.0, True, False),
        "theta_cs_start": (0.0, 2000.0, True, False),
        "x_kiss_ref": (-1.0, 1.0, False, False),
        "lever_ratio": (0.0, 100.0, True, False),
    }

    def problems(self) -> list[str]:
        """Every parameter outside its allowed range, with the range."""
        out = []
        for f in fields(self):
            v = getattr(self, f.name)
            lo, hi, lo_open, hi_open = self.RANGES[f.name]
            ok = isinstance(v, (int, float)) and math.isfinite(v) and (
                v > lo if lo_open else v >= lo) and (v < hi if hi_open else v <= hi)
            if not ok:
                out.append(f"{f.name} = {v!r} is out of range {'(' if lo_open else '['}{lo:g}, "
                           f"{hi:g}{')' if hi_open else ']'}")
        if not out and self.U + self.H <= 0.0:
            out.append("U + H must be > 0 (the cushion spring needs a heat path)")
        return out


def thermal_step(theta_cs: float, theta_cm: float, dt: float, p: ClutchParameters) -> float:
    """Exact cushion-spring temperature after ``dt`` s with ``theta_cm`` held, K."""
    g = p.U + p.H
    theta_inf = (p.U * theta_cm + p.H * p.theta_a) / g
    return theta_inf + (theta_cs - theta_inf) * math.exp(-dt * g / p.C)


@dataclass
class Outputs:
    """Model outputs at one instant (SI)."""

    torque: float     #: transmissible clutch torque, N.m
    force: float      #: cushion-spring (clamp) force, N
    u_f: float        #: cushion compression from the kiss point, clipped at 0, m
    x_kiss: float     #: kiss point at the bearing, m
    clamped: bool     #: theta_cs was outside the table and was clamped


def outputs(x_to: float, theta_cs: float, table: SpringTable, p: ClutchParameters) -> Outputs:
    """Torque and force from bearing position ``x_to`` (m) and ``theta_cs`` (K)."""
    theta_c = theta_cs - KELVIN
    x_kiss = p.x_kiss_ref - p.lever_ratio * table.delta_kiss(theta_c)
    u = (x_to - x_kiss) / p.lever_ratio
    force = table.force(u, theta_c)
    clamped = not (table.theta_min_K <= theta_cs <= table.theta_max_K)
    return Outputs(p.n_surfaces * p.mu * p.R_eq * force, force, max(u, 0.0), x_kiss, clamped)


def x_to_for_torque(torque: float, theta_cs: float, table: SpringTable, p: ClutchParameters,
                    tol_m: float = 1e-12) -> float:
    """Bearing position (m) giving ``torque`` (N.m) at ``theta_cs`` (K): the TCU's inverse.

    F is non-decreasing in u, so the smallest position reaching the torque is
    found by bisection. A torque at or below zero returns the first-contact
    position; above the full-compression torque, the full-compression position.
    """
    theta_c = theta_cs - KELVIN
    gain = p.n_surfaces * p.mu * p.R_eq
    x_kiss = p.x_kiss_ref - p.lever_ratio * table.delta_kiss(theta_c)
    lo, hi = table.first_contact(theta_c), table.full_compression(theta_c)
    if gain <= 0.0 or torque <= gain * table.force(lo, theta_c):
        return x_kiss + p.lever_ratio * lo
    if torque >= gain * table.force(hi, theta_c):
        return x_kiss + p.lever_ratio * hi
    target = torque / gain
    while hi - lo > tol_m:
        mid = 0.5 * (lo + hi)
        if table.force(mid, theta_c) < target:
            lo = mid
        else:
            hi = mid
    return x_kiss + p.lever_ratio * hi
