"""Friction coefficient mu(theta_cm, omega_slip) of the facings, from a table; numpy only.

File ``friction.csv`` of a table set (optional), columns
``theta_degC,omega_slip_rad_s,mu``: facing temperature [degC], slip speed
[rad/s, >= 0] and the dynamic friction coefficient [1] on a full rectangular
grid, rows in any order. Evaluated bilinearly in (theta, |omega_slip|) and
clamped to the grid's edges. Without the file the clutch uses the constant
parameter ``mu`` (the paper's model).
"""
from __future__ import annotations

import math
from bisect import bisect_right
from pathlib import Path

import numpy as np

try:                                    # inside the pythonfmu FMU the modules are siblings
    from .table_format import COLUMNS as TABLE_COLUMNS, FRICTION, TableError, load_csv
except ImportError:
    from table_format import COLUMNS as TABLE_COLUMNS, FRICTION, TableError, load_csv

COLUMNS = TABLE_COLUMNS[FRICTION]
#: largest accepted friction coefficient in a table, 1
MU_LIMIT = 2.0


def _bracket(grid: list[float], v: float) -> tuple[int, float]:
    """Index i and weight w with v between grid[i] and grid[i+1] (clamped; w = 0 for one point)."""
    if len(grid) == 1 or v <= grid[0]:
        return 0, 0.0
    if v >= grid[-1]:
        return len(grid) - 2, 1.0
    i = bisect_right(grid, v) - 1
    return i, (v - grid[i]) / (grid[i + 1] - grid[i])


class FrictionTable:
    """mu on a (theta_degC, omega_slip_rad_s) grid, bilinear and clamped.

    Parameters
    ----------
    theta_degC : sequence of float
        Facing temperatures, degC, strictly increasing.
    omega_rad_s : sequence of float
        Slip speeds, rad/s, >= 0, strictly increasing.
    mu : array_like, shape (len(theta_degC), len(omega_rad_s))
        Friction coefficient, 1, in [0, 2].
    """

    def __init__(self, theta_degC, omega_rad_s, mu):
        self.theta_degC = [float(t) for t in theta_degC]
        self.omega_rad_s = [float(w) for w in omega_rad_s]
        m = np.asarray(mu, float)
        problems = []
        for name, g in (("theta_degC", self.theta_degC), ("omega_slip_rad_s", self.omega_rad_s)):
            if not g or any(b <= a for a, b in zip(g, g[1:])) or not all(map(math.isfinite, g)):
                problems.append(f"{name} must be finite and strictly increasing")
        if self.omega_rad_s and self.omega_rad_s[0] < 0.0:
            problems.append("omega_slip_rad_s must be >= 0")
        if m.shape != (len(self.theta_degC), len(self.omega_rad_s)):
            problems.append(f"mu must have shape {(len(self.theta_degC), len(self.omega_rad_s))}")
        elif not np.all(np.isfinite(m)) or np.any(m < 0.0) or np.any(m > MU_LIMIT):
            problems.append(f"mu must be finite and in [0, {MU_LIMIT:g}]")
        if problems:
            raise TableError("friction table: " + "; ".join(problems))
        self.mu = [[float(v) for v in row] for row in m]

    @classmethod
    def from_csv(cls, path: str | Path) -> "FrictionTable":
        """Read ``theta_degC,omega_slip_rad_s,mu`` rows forming a full grid (any order).

        Raises
        ------
        TableError
            Naming the file, if it is malformed or not a full grid (a ``ValueError``).
        """
        data = load_csv(Path(path), COLUMNS)
        thetas, omegas = np.unique(data[:, 0]), np.unique(data[:, 1])
        if len(data) != len(thetas) * len(omegas):
            raise TableError(f"{path}: rows must form a full grid of {len(thetas)} temperatures x "
                             f"{len(omegas)} slip speeds, each once (got {len(data)} rows)")
        grid = np.full((len(thetas), len(omegas)), np.nan)
        grid[np.searchsorted(thetas, data[:, 0]), np.searchsorted(omegas, data[:, 1])] = data[:, 2]
        if np.isnan(grid).any():
            raise TableError(f"{path}: a (theta_degC, omega_slip_rad_s) pair appears twice")
        try:
            return cls(thetas, omegas, grid)
        except ValueError as exc:
            raise TableError(f"{path}: {exc}") from exc

    def __call__(self, theta_degC: float, omega_slip_rad_s: float) -> float:
        """mu at facing temperature ``theta_degC`` (degC) and slip speed ``|omega_slip_rad_s|`` (rad/s)."""
        i, wi = _bracket(self.theta_degC, theta_degC)
        j, wj = _bracket(self.omega_rad_s, abs(omega_slip_rad_s))
        m = self.mu
        i1 = min(i + 1, len(self.theta_degC) - 1)
        j1 = min(j + 1, len(self.omega_rad_s) - 1)
        lo = (1.0 - wj) * m[i][j] + wj * m[i][j1]
        hi = (1.0 - wj) * m[i1][j] + wj * m[i1][j1]
        return (1.0 - wi) * lo + wi * hi
