"""Cushion-spring table F(u, theta) and kiss-point shift delta_kiss(theta), numpy only.

Shared by the pythonfmu slave and the Python API (through ``clutch_model``).
Force: shape-preserving (PCHIP, Fritsch-Carlson) cubic in u per table
temperature, linear between temperatures; u below the table's first contact
gives its first force (zero), beyond full compression the full-compression
force; temperatures outside the table are clamped.
"""
from __future__ import annotations

import math
from bisect import bisect_right
from pathlib import Path

import numpy as np

try:                                    # inside the pythonfmu FMU the modules are siblings
    from .friction import FrictionTable
    from .table_format import COLUMNS, FORCE_DEFLECTION, FRICTION, KISS_POINT, load_csv
except ImportError:
    from friction import FrictionTable
    from table_format import COLUMNS, FORCE_DEFLECTION, FRICTION, KISS_POINT, load_csv

KELVIN = 273.15
#: largest accepted table force, N (a clutch clamp load is kN; larger values are corrupt tables)
FORCE_LIMIT_N = 1e9


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

    def slope(self, u: float) -> float:
        """dF/du of the interpolant (0 outside the table), N/m."""
        x, y, d = self.x, self.y, self.d
        if u <= self.x_min or u >= self.x_max:
            return 0.0
        i = bisect_right(x, u) - 1
        h = x[i + 1] - x[i]
        t = (u - x[i]) / h
        t2 = t * t
        return ((6 * t2 - 6 * t) * (y[i] - y[i + 1]) / h + (3 * t2 - 4 * t + 1) * d[i]
                + (3 * t2 - 2 * t) * d[i + 1])


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
        u_m, force_N = [np.asarray(u, float) for u in u_m], [np.asarray(f, float) for f in force_N]
        for t, u, f in zip(self.theta_degC, u_m, force_N):
            if u.ndim != 1 or len(u) < 2 or u.shape != f.shape:
                raise ValueError(f"curve at {t:g} degC: needs >= 2 (u, force) rows, got {len(u)}")
        self.curves = [Curve(u, f) for u, f in zip(u_m, force_N)]
        self.delta_kiss_m = [float(d) for d in delta_kiss_m]
        if not (len(self.curves) == len(self.delta_kiss_m) == len(self.theta_degC)):
            raise ValueError("force and kiss-point tables have different temperatures")
        for t, c in zip(self.theta_degC, self.curves):
            if len(c.x) < 2 or any(b <= a for a, b in zip(c.x, c.x[1:])) or any(
                    b < a for a, b in zip(c.y, c.y[1:])) or not all(map(math.isfinite, c.y)):
                raise ValueError(f"curve at {t:g} degC: u must increase and force must not decrease")
            if abs(c.y[-1]) > FORCE_LIMIT_N:
                raise ValueError(f"curve at {t:g} degC: |force| > {FORCE_LIMIT_N:g} N (torque would overflow)")
        #: optional mu(theta_cm, omega_slip) table (``friction.csv``); None: the constant parameter mu
        self.friction = None
        self.theta_min_K = self.theta_degC[0] + KELVIN
        self.theta_max_K = self.theta_degC[-1] + KELVIN

    @classmethod
    def from_dir(cls, folder: str | Path) -> "SpringTable":
        """Read ``force_deflection.csv``, ``kiss_point.csv`` and the optional ``friction.csv``.

        Raises
        ------
        ValueError
            With the file name, if a file is malformed.
        """
        folder = Path(folder)
        fd = load_csv(folder / FORCE_DEFLECTION, COLUMNS[FORCE_DEFLECTION])
        kp = load_csv(folder / KISS_POINT, COLUMNS[KISS_POINT])
        negative = np.flatnonzero(fd[:, 2] < 0.0)
        if negative.size:
            k = int(negative[0])
            raise ValueError(f"{folder / FORCE_DEFLECTION}: row {k + 1} (line {k + 2}): force_N = {float(fd[k, 2])!r} "
                             f"< 0 (a clamp force cannot be negative; {negative.size} such row(s))")
        thetas = np.unique(fd[:, 0])
        if not np.array_equal(np.sort(kp[:, 0]), thetas):
            raise ValueError(f"{folder}: {KISS_POINT} and {FORCE_DEFLECTION} temperatures differ")
        kp = kp[np.argsort(kp[:, 0])]
        try:
            table = cls(thetas, [fd[fd[:, 0] == t, 1] for t in thetas],
                        [fd[fd[:, 0] == t, 2] for t in thetas], kp[:, 1])
        except ValueError as exc:
            raise ValueError(f"{folder / FORCE_DEFLECTION}: {exc}") from exc
        if (folder / FRICTION).exists():
            table.friction = FrictionTable.from_csv(folder / FRICTION)
        return table

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

    def force_slope(self, u_m: float, theta_degC: float) -> float:
        """dF/du at compression ``u_m`` and ``theta_degC``, N/m."""
        i, w = self._bracket(theta_degC)
        d0 = self.curves[i].slope(u_m)
        return d0 if w == 0.0 else (1.0 - w) * d0 + w * self.curves[i + 1].slope(u_m)

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
