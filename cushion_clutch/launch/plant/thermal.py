"""Lumped facing thermal model, shared by the plant and the TCU's observer.

``C_f dtheta_cm/dt = share P_slip - G_f (theta_cm - theta_a)``, advanced with
its exact solution for a slip power held over the step (stable for any step).
"""
from __future__ import annotations

import math


class FacingModel:
    """Facing temperature (K) heated by slip power (W).

    Parameters
    ----------
    capacity_J_per_K, loss_W_per_K, heat_share : float
        ``C_f`` (J/K), ``G_f`` (W/K) and the share of slip power into this facing pair (1).
    theta_a : float
        Ambient temperature, K.
    dt : float
        The step this instance advances, s.
    """

    __slots__ = ("c", "g", "share", "theta_a", "dt", "decay")

    def __init__(self, capacity_J_per_K: float, loss_W_per_K: float, heat_share: float, theta_a: float,
                 dt: float):
        self.c, self.g, self.share, self.theta_a, self.dt = capacity_J_per_K, loss_W_per_K, heat_share, theta_a, dt
        self.decay = math.exp(-dt * loss_W_per_K / capacity_J_per_K)

    def step(self, theta_cm: float, p_slip_W: float) -> float:
        """Temperature after ``dt`` with ``p_slip_W`` held, K."""
        q = self.share * p_slip_W
        if self.g > 0.0:
            theta_inf = self.theta_a + q / self.g
            return theta_inf + (theta_cm - theta_inf) * self.decay
        return theta_cm + q * self.dt / self.c
