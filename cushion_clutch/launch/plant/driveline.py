"""Engine, clutch, gearbox in first gear, compliant drive shafts and the vehicle: slip/lock and energy.

Speeds at the disc (gearbox input): engine ``w_e``, disc ``w_d``, vehicle
``w_v = v i / r``; the shafts' twist ``phi`` (rad, at the disc). With the
stiffness and damping at the wheels ``k_w``, ``c_w`` stated at the disc
(``k = k_w / i^2``, ``c = c_w / i^2``) the shaft torque is
``T_s = k phi + c (w_d - w_v)`` and

* slipping: ``J_e w_e' = T_e - T_c``, ``J_disc w_d' = T_c - T_s`` with
  ``T_c = T_cap sign(w_e - w_d)``;
* locked: ``(J_e + J_disc) w_d' = T_e - T_s``; the clutch carries
  ``(J_disc T_e + J_e T_s) / (J_e + J_disc)``; it locks when the slip speed
  crosses zero and that torque is within the capacity (the speeds are merged
  conserving momentum; the small energy of that impact counts as slip loss)
  and unlocks when it exceeds the capacity;
* vehicle: ``J_v w_v' = eta T_s - T_res - T_brake`` with ``J_v = m r^2 / i^2``.

The shaft is integrated with the implicit midpoint rule (closed form: the
shaft torque of the step solves one linear equation), every other torque is
held over the step and every power is taken at midpoint speeds, which makes
the discrete energy balance exact to round-off: engine work = kinetic +
elastic + potential energy + slip + damping + driving-resistance (rolling,
air, gearbox) + brake losses. The first (shuffle) mode of the locked
driveline is :func:`first_mode_hz`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..scenario.load import Driveline as DrivelineSection, Scenario, Vehicle

G = 9.81    #: gravity, m/s2


@dataclass
class Energy:
    """Energy terms over a run, J."""

    engine_work: float = 0.0
    kinetic: float = 0.0
    elastic: float = 0.0
    potential: float = 0.0
    slip: float = 0.0
    damping: float = 0.0
    resistance: float = 0.0
    brake: float = 0.0

    def residual(self) -> float:
        """engine work - (kinetic + elastic + potential + slip + damping + resistance + brake), J."""
        return self.engine_work - (self.kinetic + self.elastic + self.potential + self.slip + self.damping
                                   + self.resistance + self.brake)


def first_mode_hz(sc: Scenario) -> float:
    """Undamped first mode of the locked driveline (engine and disc against the vehicle), Hz.

    The two-inertia closed form ``f = sqrt(k (1/J_1 + eta/J_v)) / (2 pi)`` with
    ``J_1 = J_e + J_disc``, ``J_v = m r^2 / i^2`` and ``k`` at the disc.
    """
    dl = sc.driveline
    i = dl.gear_ratio * dl.final_drive_ratio
    j1 = sc.engine.inertia_kg_m2 + dl.disc_inertia_kg_m2
    jv = sc.vehicle.mass_kg * (dl.wheel_radius_m / i) ** 2
    return math.sqrt(dl.stiffness_Nm_per_rad / i ** 2 * (1.0 / j1 + dl.efficiency / jv)) / (2.0 * math.pi)


class Driveline:
    """State ``w_e``, ``w_d`` (rad/s), ``v`` (m/s), ``phi`` (rad), ``locked``; :meth:`step` advances ``h``.

    After a step, ``t_c`` is the clutch torque (N.m), ``slip_J`` the slip
    energy of the step (J) and ``slip_W`` the slip power at midpoint speeds (W).

    Parameters
    ----------
    driveline, vehicle : Driveline, Vehicle
        The scenario's ``[driveline]`` and ``[vehicle]`` sections.
    engine_inertia_kg_m2 : float
        The engine's inertia, kg m2.
    step_s : float
        The step :meth:`step` advances, s.
    w_e : float
        The engine's speed at the start, rad/s.
    """

    __slots__ = ("h", "i_tot", "r", "eta", "f_grade", "f_roll", "j_v", "j_d", "j_e", "j_disc", "mass", "k", "c",
                 "kappa", "air", "brake_torque", "w_e", "w_d", "v", "phi", "locked", "en", "t_c", "slip_J",
                 "slip_W", "t_load_rest")

    def __init__(self, driveline: DrivelineSection, vehicle: Vehicle, engine_inertia_kg_m2: float, step_s: float,
                 w_e: float):
        dl, veh = driveline, vehicle
        self.h = h = step_s
        self.i_tot = i = dl.gear_ratio * dl.final_drive_ratio
        self.r, self.eta = dl.wheel_radius_m, dl.efficiency
        slope = math.atan(veh.slope_percent / 100.0)
        self.f_grade = veh.mass_kg * G * math.sin(slope)
        self.f_roll = veh.rolling_resistance * veh.mass_kg * G * math.cos(slope)
        self.mass, self.j_disc = veh.mass_kg, dl.disc_inertia_kg_m2
        self.j_v = veh.mass_kg * (self.r / i) ** 2                         # vehicle at the disc
        self.j_d = self.j_disc + self.j_v / self.eta                        # disc and vehicle as the clutch feels them
        self.j_e = engine_inertia_kg_m2
        self.k, self.c = dl.stiffness_Nm_per_rad / i ** 2, dl.damping_Nm_s_per_rad / i ** 2
        self.kappa = self.k * h / 2.0 + self.c
        self.air = 0.5 * veh.air_density_kg_m3 * veh.drag_area_m2
        self.brake_torque = veh.brake_decel_m_s2 * veh.mass_kg * self.r / i
        #: clutch torque that holds the car as it starts moving (grade + rolling), N.m
        self.t_load_rest = (self.f_grade + self.f_roll) * self.r / (self.eta * i)
        self.w_e, self.w_d, self.v, self.phi, self.locked = w_e, 0.0, 0.0, 0.0, False
        self.en = Energy()
        self.t_c = self.slip_J = self.slip_W = 0.0

    def kinetic(self) -> float:
        """Kinetic energy of engine, disc and vehicle, J."""
        return 0.5 * (self.j_e * self.w_e ** 2 + self.j_disc * self.w_d ** 2 + self.mass * self.v ** 2)

    def elastic(self) -> float:
        """Energy in the twisted shafts, J."""
        return 0.5 * self.k * self.phi ** 2

    def _shaft(self, j1: float, t1: float, w_v: float, t_veh: float, held: bool) -> float:
        """Midpoint shaft torque of the step (N.m): side 1 (inertia ``j1``, torque ``t1``) against the
        vehicle (speed ``w_v``, torque ``t_veh`` against it), or a held vehicle (its speed goes to 0)."""
        h, kappa = self.h, self.kappa
        if held:
            return (self.k * self.phi + kappa * (self.w_d - 0.5 * w_v + 0.5 * h * t1 / j1)) / \
                (1.0 + 0.5 * kappa * h / j1)
        return (self.k * self.phi + kappa * (self.w_d - w_v + 0.5 * h * (t1 / j1 + t_veh / self.j_v))) / \
            (1.0 + 0.5 * kappa * h * (1.0 / j1 + self.eta / self.j_v))

    def step(self, t_e: float, t_cap: float, engaged: bool, braking: bool) -> int:
        """Advance with engine torque ``t_e`` and clutch capacity ``t_cap`` (N.m); 1 locked, -1 unlocked, else 0.

        ``engaged``: the TCU is launching or closing (lock-up allowed);
        ``braking``: the service brake stops the car.
        """
        h, en = self.h, self.en
        w_e, w_d, v = self.w_e, self.w_d, self.v
        if v == 0.0 and t_cap == 0.0 and w_d == 0.0 and self.phi == 0.0 and not self.locked:
            # at rest, clutch open, shafts relaxed: only the engine moves
            w_e_new = w_e + t_e / self.j_e * h
            if w_e_new < 0.0:
                w_e_new = 0.0
            en.engine_work += t_e * 0.5 * (w_e + w_e_new) * h
            self.w_e = w_e_new
            self.t_c = self.slip_J = self.slip_W = 0.0
            return 0
        i_tot, r, eta, j_e, j_v = self.i_tot, self.r, self.eta, self.j_e, self.j_v
        w_v = v * i_tot / r
        f_res = (self.f_roll if v > 0.0 else 0.0) + self.air * v * v + self.f_grade
        t_res = f_res * r / i_tot                                   # resistance at the disc
        locked = self.locked
        event = 0
        j_lock = j_e + self.j_disc
        t_brake = self.brake_torque if braking and v > 0.0 else 0.0
        if locked:
            t_s = self._shaft(j_lock, t_e, w_v, t_res + t_brake, False)
            t_c = (self.j_disc * t_e + j_e * t_s) / j_lock
            if abs(t_c) > t_cap:
                locked, event = False, -1
        if not locked:
            t_c = math.copysign(t_cap, w_e - w_d) if w_e != w_d else 0.0
            j1, t1 = self.j_disc, t_c
        else:
            j1, t1 = j_lock, t_e
        t_s = self._shaft(j1, t1, w_v, t_res + t_brake, False)
        w_v_new = w_v + h / j_v * (eta * t_s - t_res - t_brake)
        if w_v_new < 0.0:                                           # the brake / hill hold keeps it at rest
            t_s = self._shaft(j1, t1, w_v, 0.0, True)
            w_v_new = 0.0
            t_brake = eta * t_s - t_res + j_v * w_v / h
        w_d_new = w_d + h / j1 * (t1 - t_s)
        if locked:
            w_e_new = w_d_new
        else:
            w_e_new = w_e + (t_e - t_c) / j_e * h
            if w_e_new < 0.0:
                w_e_new = 0.0
        d_m = 0.5 * (w_d + w_d_new) - 0.5 * (w_v + w_v_new)       # midpoint twist rate
        self.phi += h * d_m
        # energy bookkeeping with midpoint speeds
        wm_e, wm_d, wm_v = 0.5 * (w_e + w_e_new), 0.5 * (w_d + w_d_new), 0.5 * (w_v + w_v_new)
        en.engine_work += t_e * wm_e * h
        slip_w = t_c * (wm_e - wm_d) if not locked else 0.0
        slip = slip_w * h
        en.damping += self.c * d_m * d_m * h
        en.resistance += ((f_res - self.f_grade) * r / i_tot + (1.0 - eta) * t_s) * wm_v * h
        en.potential += self.f_grade * r / i_tot * wm_v * h
        en.brake += t_brake * wm_v * h
        # lock-up: the slip speed crosses zero and the locked torque fits the capacity
        if not locked and t_cap > 0.0 and engaged and (w_e - w_d) * (w_e_new - w_d_new) <= 0.0:
            t_s_new = self.k * self.phi + self.c * (w_d_new - w_v_new)
            if abs((self.j_disc * t_e + j_e * t_s_new) / j_lock) <= t_cap:
                ke_before = 0.5 * (j_e * w_e_new ** 2 + self.j_disc * w_d_new ** 2)
                w_e_new = w_d_new = (j_e * w_e_new + self.j_disc * w_d_new) / j_lock
                slip += ke_before - 0.5 * j_lock * w_e_new ** 2        # the impact of merging the speeds
                locked, event = True, 1
        en.slip += slip
        self.w_e, self.w_d, self.v, self.locked = w_e_new, w_d_new, w_v_new * r / i_tot, locked
        self.t_c, self.slip_J, self.slip_W = t_c, slip, abs(slip_w)
        if (not locked and t_cap == 0.0 and w_v_new == 0.0 and abs(w_d_new) < 1e-6
                and abs(self.phi) < 1e-9):                          # rung down at rest: snap, keep the books
            en.damping += 0.5 * self.j_disc * w_d_new ** 2 + 0.5 * self.k * self.phi ** 2
            self.w_d = self.phi = 0.0
        return event

    def restart_engine(self, w_idle: float) -> None:
        """After a stall: the starter brings the engine to idle (its work counts as engine work)."""
        self.en.engine_work += 0.5 * self.j_e * (w_idle ** 2 - self.w_e ** 2)
        self.w_e = w_idle
