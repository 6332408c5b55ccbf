"""Cushion-spring table F(u, theta) and kiss-point shift delta_kiss(theta), numpy only.

Shared by the pythonfmu slave and the Python API (through ``clutch_model``).
Force: shape-preserving (PCHIP, Fritsch-Carlson) cubic in u per table
temperature; u below a curve's first contact gives its first force (zero),
beyond its full compression the full-compression force. Each interval's cubic is
kept as its Hermite form collected by powers of t (built once per table) and
evaluated with its slope in one call (:meth:`Curve.value_slope`), in plain floats.

Between two table temperatures the curves are blended on a common normalised
compression: first contact ``a(theta)`` and full compression ``b(theta)`` are
linear in theta between their table values, and at ``u`` each neighbouring curve
``k`` is read at ``a_k + (u - a(theta)) (b_k - a_k) / (b(theta) - a(theta))``, then
the two forces are weighted linearly in theta. So the blended curve starts
rising exactly at ``a(theta)``, is solid exactly at ``b(theta)``, equals the table
curve at a table temperature, and every quantity (force, first contact, full
compression, hence kiss point, clamp load and torque) is continuous in theta.
(Blending the curves at the same ``u`` instead gives a curve whose first contact
and full compression are the extreme ones of the two neighbours: a step at
every table temperature.) Temperatures outside the table are clamped.
"""
from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from pathlib import Path

import numpy as np

try:                                    # inside the pythonfmu FMU the modules are siblings
    from .friction import FrictionTable
    from ..number_check import KELVIN
    from .table_format import FORCE_DEFLECTION, FRICTION, TableError, read_tables
except ImportError:
    from friction import FrictionTable
    from number_check import KELVIN
    from table_format import FORCE_DEFLECTION, FRICTION, TableError, read_tables

#: brackets (blended curves) a table keeps, by exact temperature
BRACKETS_KEPT = 64
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
    """One F(u) curve with its PCHIP slopes, evaluated in plain Python (fast for scalars).

    Below the curve's first contact ``x_first`` (the last row still at the first force) F is its first force and
    dF/du is 0; beyond its last row F is the last force and dF/du is 0.
    """

    __slots__ = ("x", "y", "d", "x_min", "x_max", "x_first", "y_first", "y_last", "inv_h", "coef")

    def __init__(self, u: np.ndarray, force: np.ndarray):
        self.x = [float(v) for v in u]
        self.y = [float(v) for v in force]
        self.d = [float(v) for v in pchip_slopes(u, force)]
        self.x_min, self.x_max = self.x[0], self.x[-1]
        #: first contact: the last row still at the first force (a curve may begin with several 0 N rows), m
        self.x_first = self.x[max(k for k, f in enumerate(self.y) if f == self.y[0])]
        self.y_first, self.y_last = self.y[0], self.y[-1]
        # per interval i: 1/h and the Hermite cubic in t = (u - x_i)/h as F = c0 + t (c1 + t (c2 + t c3))
        # (the Hermite basis y_i h_00 + h d_i h_10 + y_i+1 h_01 + h d_i+1 h_11 collected by powers of t)
        x, y, d = self.x, self.y, self.d
        self.inv_h, self.coef = [], []
        for i in range(len(x) - 1):
            h = x[i + 1] - x[i]
            dy = y[i + 1] - y[i]
            self.inv_h.append(1.0 / h)
            self.coef.append((y[i], h * d[i], 3.0 * dy - h * (2.0 * d[i] + d[i + 1]), h * (d[i] + d[i + 1]) - 2.0 * dy))

    def value_slope(self, u: float) -> tuple[float, float]:
        """(F, dF/du) of the interpolant at ``u`` (N, N/m): the one evaluation of the curve (the Newton
        iterations of :mod:`cover` need both at the same point, so the interval is found once)."""
        if u <= self.x_first:
            return self.y_first, 0.0
        if u >= self.x_max:
            return self.y_last, 0.0
        x = self.x
        i = bisect_right(x, u) - 1
        k = self.inv_h[i]
        t = (u - x[i]) * k
        c0, c1, c2, c3 = self.coef[i]
        return c0 + t * (c1 + t * (c2 + t * c3)), (c1 + t * (2.0 * c2 + 3.0 * t * c3)) * k

    def u_at(self, force: float) -> float:
        """The compression where F reaches ``force`` (N), m: ``x_first`` at or below the first force, ``x_max``
        above the last; in between the cubic of the interval where it is reached, solved by three Newton steps
        in t from the chord (a start for the inverse of :mod:`cover`, which refines it on the blended curve)."""
        y = self.y
        j = bisect_left(y, force)
        if j == 0:
            return self.x_first
        if j == len(y):
            return self.x_max
        i = j - 1
        c0, c1, c2, c3 = self.coef[i]
        t = (force - c0) / (y[j] - c0)              # y[i] < force <= y[j]
        for _ in range(3):
            d = c1 + t * (2.0 * c2 + 3.0 * t * c3)
            if not d > 0.0:
                break
            t -= (c0 + t * (c1 + t * (c2 + t * c3)) - force) / d
            t = 0.0 if t < 0.0 else (1.0 if t > 1.0 else t)
        return self.x[i] + t / self.inv_h[i]

    def __call__(self, u: float) -> float:
        """F(u), N."""
        return self.value_slope(u)[0]

    def slope(self, u: float) -> float:
        """dF/du of the interpolant (0 outside the table), N/m."""
        return self.value_slope(u)[1]


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
        self._kept: dict[float, Bracket] = {}

    @classmethod
    def from_dir(cls, folder: str | Path) -> "SpringTable":
        """The table set of ``folder`` (:func:`.table_format.read_tables`, the one reader) and its optional
        ``friction.csv``.

        Raises
        ------
        TableError
            With the file name, if a file is malformed (a ``ValueError``).
        """
        folder = Path(folder)
        ts = read_tables(folder)
        try:
            table = cls(ts.theta_degC, list(ts.u_m), list(ts.force_N), ts.delta_kiss_m)
        except ValueError as exc:
            raise TableError(f"{folder / FORCE_DEFLECTION}: {exc}") from exc
        if (folder / FRICTION).exists():
            table.friction = FrictionTable.from_csv(folder / FRICTION)
        return table

    def _bracket(self, theta_degC: float) -> tuple[int, float]:
        """Index i and weight w of table i + 1 so that theta lies between tables i and i + 1.

        At a table temperature and beyond either end w is 0 (table i alone counts; clamped).
        """
        ts = self.theta_degC
        if theta_degC <= ts[0] or len(ts) == 1:
            return 0, 0.0
        if theta_degC >= ts[-1]:
            return len(ts) - 1, 0.0
        i = bisect_right(ts, theta_degC) - 1
        return i, (theta_degC - ts[i]) / (ts[i + 1] - ts[i])

    def bracket(self, theta_degC: float) -> "Bracket":
        """The blended curve at ``theta_degC`` (kept for the last :data:`BRACKETS_KEPT` temperatures asked, by
        exact value: a bracket depends on the temperature alone)."""
        b = self._kept.get(theta_degC)
        if b is not None:
            return b
        i, w = self._bracket(theta_degC)
        d = self.delta_kiss_m
        b = Bracket(theta_degC, self.curves[i], self.curves[i + 1] if w != 0.0 else None, w,
                    d[i] if w == 0.0 else (1.0 - w) * d[i] + w * d[i + 1])
        if len(self._kept) >= BRACKETS_KEPT:
            self._kept.clear()
        self._kept[theta_degC] = b
        return b

    def force(self, u_m: float, theta_degC: float) -> float:
        """Whole-spring force at compression ``u_m`` from the kiss point, N."""
        return self.bracket(theta_degC).force(u_m)

    def force_slope(self, u_m: float, theta_degC: float) -> float:
        """dF/du at compression ``u_m`` and ``theta_degC``, N/m."""
        return self.bracket(theta_degC).slope(u_m)

    def delta_kiss(self, theta_degC: float) -> float:
        """Kiss-point shift of the spring, m (linear in theta, clamped)."""
        return self.bracket(theta_degC).delta_kiss

    def full_compression(self, theta_degC: float) -> float:
        """Compression from which F no longer grows at this temperature, m (linear in theta between the tables)."""
        return self.bracket(theta_degC).full

    def first_contact(self, theta_degC: float) -> float:
        """Compression below which F is its first (zero) value at this temperature, m (linear in theta)."""
        return self.bracket(theta_degC).first


class Bracket:
    """F(u) at one temperature: the two neighbouring table curves blended on a common normalised compression.

    Parameters
    ----------
    theta_degC : float
        The temperature, degC.
    c0, c1 : Curve, Curve or None
        The table curves below and above it (``c1`` None where the weight ``w`` is 0).
    w : float
        Weight of ``c1``, 1 (linear in theta).

    Attributes
    ----------
    first, full : float
        First contact and full compression at this temperature, m: ``(1 - w) a_0 + w a_1`` and
        ``(1 - w) b_0 + w b_1`` of the curves' own (``Curve.x_first``, ``Curve.x_max``).
    f_first, f_full : float
        F at and below first contact and at and beyond full compression, N (the curves' first and last forces,
        blended).
    """

    __slots__ = ("theta_degC", "c0", "c1", "w", "first", "full", "r0", "r1", "w0", "a0", "a1", "f_first",
                 "f_full", "delta_kiss", "force_slope")

    def __init__(self, theta_degC: float, c0: Curve, c1: Curve | None, w: float, delta_kiss: float = math.nan):
        self.theta_degC, self.c0, self.c1, self.w = theta_degC, c0, c1, w
        #: the kiss-point shift at this temperature, m (:meth:`SpringTable.delta_kiss`; NaN if not given)
        self.delta_kiss = delta_kiss
        if w == 0.0:
            self.first, self.full, self.r0, self.r1 = c0.x_first, c0.x_max, 1.0, 0.0
            self.f_first, self.f_full = c0.y_first, c0.y_last
            self.force_slope = c0.value_slope
            return
        self.first = (1.0 - w) * c0.x_first + w * c1.x_first
        self.full = (1.0 - w) * c0.x_max + w * c1.x_max
        span = self.full - self.first
        #: d(u_k)/du: each curve's span over the blended span (0 for a degenerate span)
        self.r0 = (c0.x_max - c0.x_first) / span if span > 0.0 else 0.0
        self.r1 = (c1.x_max - c1.x_first) / span if span > 0.0 else 0.0
        self.w0, self.a0, self.a1 = 1.0 - w, c0.x_first, c1.x_first
        #: F below the first contact: each curve's first force, blended
        self.f_first = self.w0 * c0.y_first + w * c1.y_first
        #: F at and beyond full compression: each curve's last force, blended
        self.f_full = self.w0 * c0.y_last + w * c1.y_last
        self.force_slope = self._blend

    def _blend(self, u: float) -> tuple[float, float]:
        """(F, dF/du) of the blended curve at ``u`` (N, N/m); ``force_slope`` of a bracket between two tables."""
        v = u - self.first
        if v <= 0.0:            # both curves at or below their first contact (r0, r1 >= 0)
            return self.f_first, 0.0
        r0, r1 = self.r0, self.r1
        f0, d0 = self.c0.value_slope(self.a0 + v * r0)
        f1, d1 = self.c1.value_slope(self.a1 + v * r1)
        w0, w = self.w0, self.w
        return w0 * f0 + w * f1, w0 * d0 * r0 + w * d1 * r1

    def u_start(self, force: float) -> float:
        """An estimate of the compression (m) where F reaches ``force`` (N), for the inverse's Newton start: one
        curve's :meth:`Curve.u_at`; between two tables each curve's root on the common normalised compression,
        blended with the weights (the blended root lies between the two)."""
        if self.c1 is None:
            return self.c0.u_at(force)
        r0, r1 = self.r0, self.r1
        if not (r0 > 0.0 and r1 > 0.0):
            return 0.5 * (self.first + self.full)
        return self.first + (self.w0 * (self.c0.u_at(force) - self.a0) / r0
                             + self.w * (self.c1.u_at(force) - self.a1) / r1)

    # ``force_slope(u)``: (F, dF/du) at compression ``u`` (m), N and N/m; set per instance (one curve or a blend)

    def force(self, u: float) -> float:
        """F(u) at this temperature, N."""
        return self.force_slope(u)[0]

    def slope(self, u: float) -> float:
        """dF/du at this temperature, N/m (0 outside the curves)."""
        return self.force_slope(u)[1]
