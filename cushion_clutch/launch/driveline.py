"""Engine side, clutch, first gear and vehicle: slip/lock logic and energy bookkeeping.

* slipping: ``J_e w_e' = T_e - T_c``, ``m_eq v' = eta i T_c / r - F_res`` with
  ``T_c = T_cap sign(w_e - w_d)``;
* locked (one speed): the clutch carries the torque that keeps both sides
  together; it locks when the slip speed crosses zero and that torque is
  within the capacity, and unlocks only when it exceeds the capacity, so the
  lock-up does not chatter. At lock the two speeds are merged conserving
  momentum; the (tiny) energy of that impact counts as slip loss.

Powers are integrated with step-midpoint speeds, which makes the discrete
energy balance exact: engine work = kinetic + potential energy + slip +
driving-resistance (rolling, air, gearbox) + brake losses.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .scenario import Scenario

G = 9.81    #: gravity, m/s2


@dataclass
class Energy:
    """Energy terms over a run, J."""

    engine_work: float = 0.0
    kinetic: float = 0.0
    potential: float = 0.0
    slip: float = 0.0
    resistance: float = 0.0
    brake: float = 0.0

    def residual(self) -> float:
        """engine work - (kinetic + potential + slip + resistance + brake), J."""
        return self.engine_work - (self.kinetic + self.potential + self.slip + self.resistance + self.brake)


class Driveline:
    """State ``w_e`` (rad/s), ``v`` (m/s), ``locked``; :meth:`step` advances one step ``h``.

    After a step, ``t_c`` is the clutch torque (N.m), ``slip_J`` the slip
    energy of the step (J) and ``slip_W`` the slip power at midpoint speeds (W).
    """

    __slots__ = ("h", "i_tot", "r", "eta", "f_grade", "f_roll", "m_eq", "j_kin", "j_d", "j_e", "j_disc", "mass",
                 "air", "brake_force", "w_e", "v", "locked", "en", "t_c", "slip_J", "slip_W", "t_load_rest")

    def __init__(self, sc: Scenario, w_e: float):
        dl, veh = sc.driveline, sc.vehicle
        self.h = sc.run.step_s
        self.i_tot = dl.gear_ratio * dl.final_drive_ratio
        self.r, self.eta = dl.wheel_radius_m, dl.efficiency
        slope = math.atan(veh.slope_percent / 100.0)
        self.f_grade = veh.mass_kg * G * math.sin(slope)
        self.f_roll = veh.rolling_resistance * veh.mass_kg * G * math.cos(slope)
        self.m_eq = veh.mass_kg + self.eta * dl.disc_inertia_kg_m2 * (self.i_tot / self.r) ** 2
        self.j_disc, self.mass = dl.disc_inertia_kg_m2, veh.mass_kg
        self.j_kin = dl.disc_inertia_kg_m2 + veh.mass_kg * (self.r / self.i_tot) ** 2   # at disc speed
        self.j_d = self.m_eq * self.r ** 2 / (self.eta * self.i_tot ** 2)   # as the clutch feels it
        self.j_e = sc.engine.inertia_kg_m2
        self.air = 0.5 * veh.air_density_kg_m3 * veh.drag_area_m2
        self.brake_force = veh.brake_decel_m_s2 * veh.mass_kg
        #: clutch torque that holds the car as it starts moving (grade + rolling), N.m
        self.t_load_rest = (self.f_grade + self.f_roll) * self.r / (self.eta * self.i_tot)
        self.w_e, self.v, self.locked = w_e, 0.0, False
        self.en = Energy()
        self.t_c = self.slip_J = self.slip_W = 0.0

    def kinetic(self, w_e: float, v: float) -> float:
        """Kinetic energy of engine, disc and vehicle, J."""
        w_d = v * self.i_tot / self.r
        return 0.5 * self.j_e * w_e ** 2 + 0.5 * self.j_disc * w_d ** 2 + 0.5 * self.mass * v ** 2

    def w_disc(self) -> float:
        """Disc speed, rad/s."""
        return self.v * self.i_tot / self.r

    def step(self, t_e: float, t_cap: float, engaged: bool, braking: bool) -> int:
        """Advance with engine torque ``t_e`` and clutch capacity ``t_cap`` (N.m); 1 locked, -1 unlocked, else 0.

        ``engaged``: the TCU is launching or closing (lock-up allowed);
        ``braking``: the service brake stops the car.
        """
        w_e, v, en = self.w_e, self.v, self.en
        if v == 0.0 and t_cap == 0.0 and not self.locked:
            # at rest, clutch open: the brake holds the car; only the engine moves (same
            # arithmetic as below with every vehicle term zero)
            h = self.h
            w_e_new = w_e + t_e / self.j_e * h
            if w_e_new < 0.0:
                w_e_new = 0.0
            en.engine_work += t_e * 0.5 * (w_e + w_e_new) * h
            self.w_e = w_e_new
            self.t_c = self.slip_J = self.slip_W = 0.0
            return 0
        h, i_tot, r, eta, j_e, j_d = self.h, self.i_tot, self.r, self.eta, self.j_e, self.j_d
        w_d = v * i_tot / r
        f_res = (self.f_roll if v > 0.0 else 0.0) + self.air * v * v + self.f_grade
        t_load = f_res * r / (eta * i_tot)                         # resistance felt at the clutch
        locked = self.locked
        event = 0
        if locked:
            dw = (t_e - t_load) / (j_e + j_d) * h
            t_c = t_e - j_e * dw / h
            if abs(t_c) > t_cap:
                locked, event = False, -1
        if locked:
            w_e_new = w_e + dw
            v_new = w_e_new * r / i_tot
        else:
            t_c = math.copysign(t_cap, w_e - w_d) if w_e != w_d else 0.0
            w_e_new = w_e + (t_e - t_c) / j_e * h
            drive = eta * i_tot * t_c / r
            v_new = v + (drive - f_res) / self.m_eq * h
            f_brake = 0.0
            if braking and v > 0.0:
                f_brake = min(self.brake_force, max(0.0, self.m_eq * v / h + drive - f_res))
                v_new = v + (drive - f_res - f_brake) / self.m_eq * h
            if v_new < 0.0:                                         # hill hold / brake holds at rest
                f_brake += -self.m_eq * v_new / h
                v_new = 0.0
            en.brake += f_brake * 0.5 * (v + v_new) * h
            if w_e_new < 0.0:
                w_e_new = 0.0
        # energy bookkeeping with midpoint speeds
        wm_e = 0.5 * (w_e + w_e_new)
        v_m = 0.5 * (v + v_new)
        wm_d = v_m * i_tot / r
        en.engine_work += t_e * wm_e * h
        slip_w = t_c * (wm_e - wm_d)
        slip = slip_w * h
        t_in = t_c - self.j_disc * (i_tot / r) * (v_new - v) / h
        en.resistance += (f_res - self.f_grade) * v_m * h + (1.0 - eta) * t_in * wm_d * h
        en.potential += self.f_grade * v_m * h
        # lock-up: the slip speed crosses zero and the locked torque fits the capacity
        w_d_new = v_new * i_tot / r
        if not locked and t_cap > 0.0 and engaged and (w_e - w_d) * (w_e_new - w_d_new) <= 0.0:
            if abs((j_d * t_e + j_e * t_load) / (j_e + j_d)) <= t_cap:
                ke_before = self.kinetic(w_e_new, v_new)
                w = (j_e * w_e_new + self.j_kin * w_d_new) / (j_e + self.j_kin)
                w_e_new, v_new = w, w * r / i_tot
                slip += ke_before - self.kinetic(w_e_new, v_new)   # the impact of merging the speeds
                locked, event = True, 1
        en.slip += slip
        self.w_e, self.v, self.locked = w_e_new, v_new, locked
        self.t_c, self.slip_J, self.slip_W = t_c, slip, abs(slip_w)
        return event

    def restart_engine(self, w_idle: float) -> None:
        """After a stall: the starter brings the engine to idle (its work counts as engine work)."""
        self.en.engine_work += 0.5 * self.j_e * (w_idle ** 2 - self.w_e ** 2)
        self.w_e = w_idle
