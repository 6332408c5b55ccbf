"""The cushion spring's heat-path models that the FE transient is identified with and drawn against: the
paper's first-order ODE (eq. 2-4) and two parallel lags, both integrated as the FE integrates (backward Euler on
its increments), degC. Shared by :mod:`.heat_path` (the fit) and :mod:`.heat_plots` (the figure)."""
from __future__ import annotations

import numpy as np

#: the paper's cushion-spring parameters (eq. 2): U W/K, H W/K, C J/K
PAPER = {"U_W_per_K": 0.1, "H_W_per_K": 0.04, "C_J_per_K": 1.0}


def first_order(theta_cm: np.ndarray, dt: np.ndarray, theta_a: float, tau_s: float, gain: float) -> np.ndarray:
    """theta_cs of eq. 4 integrated as the FE integrates (backward Euler on the same increments), degC."""
    out = np.empty_like(theta_cm)
    x = theta_a
    for n in range(len(theta_cm)):
        a = tau_s / dt[n]
        x = (a * x + gain * theta_cm[n] + (1.0 - gain) * theta_a) / (a + 1.0)
        out[n] = x
    return out


def two_lags(theta_cm: np.ndarray, dt: np.ndarray, theta_a: float, k1: float, tau1: float, k2: float,
             tau2: float) -> np.ndarray:
    """theta_cs as two parallel first-order lags of theta_cm - theta_a (gains k1, k2), degC."""
    u = theta_cm - theta_a
    out = np.empty_like(u)
    x1 = x2 = 0.0
    for n in range(len(u)):
        a1, a2 = tau1 / dt[n], tau2 / dt[n]
        x1 = (a1 * x1 + k1 * u[n]) / (a1 + 1.0)
        x2 = (a2 * x2 + k2 * u[n]) / (a2 + 1.0)
        out[n] = x1 + x2
    return out + theta_a
