"""Vehicle mass and road grade from the longitudinal dynamics: recursive least squares with forgetting.

With the clutch transmitting torque, the driving force at the wheels is
``F = eta i T_c / r`` and ``F - F_air = m_eq a + F_load`` with
``F_load = m g (sin(alpha) + c_r cos(alpha))``. The TCU knows the clutch
torque only from the engine side, ``T_c = T_est - J_e dw_e/dt`` (the engine
control unit's torque estimate, see :mod:`.sensors`), and the acceleration
from the differentiated input-shaft speed. Regressor ``phi = [a, 1]``,
parameters ``[m_eq, F_load]``; the mass follows from ``m_eq`` minus the
(known) rotating inertia, the grade from ``F_load`` with the known rolling
coefficient.

Excitation: an update needs the clutch to carry torque (``torque_min_Nm``)
with the car moving (``speed_min_m_s``); ``m_eq`` is only separable from
``F_load`` where the acceleration varies (the launch's slip phase and
lock-up). With the clutch locked after a launch the engine governor holds
the speed (a ~ 0), so locked-only samples tell ``F_load`` and not the mass:
both the slip phase and the locked phase are used (the engine-side clutch
torque is valid in both). A parameter is reported as estimated only once its
variance fell below ``ready_sd`` of its prior.
"""
from __future__ import annotations

import math

import numpy as np

from ..scenario.tcu_params import MassGrade

G = 9.81  #: gravity, m/s2


class MassGradeEstimator:
    """RLS on ``F - F_air = m_eq a + F_load``.

    Parameters
    ----------
    mg : MassGrade
    i_tot, r_m, eta : float
        Total ratio (1), wheel radius (m), efficiency (1) of the launch gear.
    j_disc_kg_m2 : float
        Disc-side rotating inertia at the disc (known to the TCU), kg m2.
    rolling, air_N_s2_per_m2 : float
        Rolling coefficient (1) and ``0.5 rho c_d A`` (N s2/m2), known to the TCU.
    slope0_percent : float
        The grade the TCU assumes before any estimate, %.
    """

    __slots__ = ("mg", "i_tot", "r", "eta", "m_rot", "c_r", "air", "theta", "P", "lam", "r_noise", "p0",
                 "updates", "_cap")

    def __init__(self, mg: MassGrade, i_tot: float, r_m: float, eta: float, j_disc_kg_m2: float,
                 rolling: float, air_N_s2_per_m2: float, slope0_percent: float = 0.0):
        self.mg, self.i_tot, self.r, self.eta = mg, i_tot, r_m, eta
        self.m_rot = eta * j_disc_kg_m2 * (i_tot / r_m) ** 2
        self.c_r, self.air = rolling, air_N_s2_per_m2
        alpha = math.atan(slope0_percent / 100.0)
        m_eq = mg.mass_prior_kg + self.m_rot
        self.theta = np.array([m_eq, mg.mass_prior_kg * G * (math.sin(alpha) + rolling * math.cos(alpha))])
        self.p0 = np.array([mg.mass_prior_sd_kg, mg.load_prior_sd_N]) ** 2
        self.P = np.diag(self.p0)
        self._cap = float(self.p0.sum())       # the covariance's bound on its trace
        self.lam, self.r_noise = mg.forgetting, mg.noise_sd_N ** 2
        self.updates = 0

    def update(self, clutch_torque_Nm: float, v_m_s: float, a_m_s2: float) -> bool:
        """One sample: engine-side clutch torque (N.m), speed (m/s), acceleration (m/s2); True if used."""
        if clutch_torque_Nm < self.mg.torque_min_Nm or v_m_s < self.mg.speed_min_m_s:
            return False
        y = self.eta * self.i_tot * clutch_torque_Nm / self.r - self.air * v_m_s * v_m_s
        # numpy for the products (its matrix-vector product's rounding is the reference's), plain floats for
        # the elementwise rest (the same IEEE operations without numpy's per-call cost)
        phi = np.array([a_m_s2, 1.0])
        pphi = self.P @ phi
        den = self.lam * self.r_noise + (phi @ pphi).item()
        pp0, pp1 = pphi.tolist()
        k0, k1 = pp0 / den, pp1 / den
        e = y - (phi @ self.theta).item()
        t0, t1 = self.theta.tolist()
        self.theta = np.array([t0 + k0 * e, t1 + k1 * e])
        (p00, p01), (p10, p11) = self.P.tolist()
        lam = self.lam
        p00, p01 = (p00 - k0 * pp0) / lam, (p01 - k0 * pp1) / lam
        p10, p11 = (p10 - k1 * pp0) / lam, (p11 - k1 * pp1) / lam
        tr, cap = p00 + p11, self._cap
        if tr > cap:                      # bounded covariance: no wind-up while the data do not excite
            f = cap / tr
            p00, p01, p10, p11 = p00 * f, p01 * f, p10 * f, p11 * f
        self.P = np.array([[p00, p01], [p10, p11]])
        self.updates += 1
        return True

    @property
    def mass_kg(self) -> float:
        """Estimated vehicle mass, kg."""
        return float(self.theta[0] - self.m_rot)

    @property
    def load_N(self) -> float:
        """Estimated grade plus rolling force, N."""
        return float(self.theta[1])

    @property
    def slope_percent(self) -> float:
        """Estimated grade from the load force, the mass estimate and the rolling coefficient, %."""
        m = max(self.mass_kg, 1.0)
        q = self.load_N / (m * G) / math.hypot(1.0, self.c_r)
        alpha = math.asin(max(-1.0, min(1.0, q))) - math.atan(self.c_r)
        return 100.0 * math.tan(alpha)

    def ready(self) -> tuple[bool, bool]:
        """(mass estimated, load estimated): each parameter's sd below ``ready_sd`` of its prior sd."""
        sd = np.sqrt(np.diag(self.P) / self.p0)
        return bool(sd[0] < self.mg.ready_sd), bool(sd[1] < self.mg.ready_sd)

    def holding_torque_Nm(self) -> float:
        """Clutch torque that holds the car at rest with the estimated load, N.m."""
        return self.load_N * self.r / (self.eta * self.i_tot)

    def inertia_at_disc_kg_m2(self) -> float:
        """Estimated vehicle inertia as the clutch feels it, kg m2."""
        return float(self.theta[0]) * self.r ** 2 / (self.eta * self.i_tot ** 2)
