"""Repeated vehicle launches: a Python driveline and a TCU around the clutch FMU (fmpy).

Fixed communication step ``run.step_s``. Per step: the TCU (every
``tcu.period_s``) commands a bearing position, a first-order actuator moves
the bearing, the FMU (FMU2Slave) returns the transmissible torque for the
bearing position held over the step, and the driveline advances:

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
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..fmu_src.clutch_model import KELVIN, ClutchParameters, SpringTable, thermal_step, x_to_for_torque
from .scenario import Scenario

G = 9.81
RPM = math.pi / 30.0

#: columns of the time series (SI; recorded every ``record_every`` steps)
COLUMNS = ("time_s", "launch", "w_engine_rad_s", "w_disc_rad_s", "v_m_s", "accel_m_s2", "x_cmd_m",
           "x_to_m", "torque_demand_Nm", "torque_capacity_Nm", "torque_clutch_Nm", "theta_cm_K",
           "theta_cs_K", "theta_cs_tcu_K", "x_kiss_m", "x_kiss_tcu_m", "throttle", "locked")


@dataclass
class TcuController:
    """Commands the bearing from the torque demand through the model's inverse.

    ``aware``: estimates theta_cs with the thermal model from the measured
    facing temperature; naive: uses the table's reference temperature (20 degC).
    """

    table: SpringTable
    p: ClutchParameters
    aware: bool
    theta_est: float = 293.15

    @property
    def name(self) -> str:
        return "aware" if self.aware else "naive"

    def update_estimate(self, theta_cm: float, dt: float) -> None:
        if self.aware:
            self.theta_est = thermal_step(self.theta_est, theta_cm, dt, self.p)

    def theta_used(self) -> float:
        return self.theta_est if self.aware else self.table.theta_degC[0] + KELVIN

    def command(self, torque_Nm: float) -> float:
        return x_to_for_torque(torque_Nm, self.theta_used(), self.table, self.p)

    def kiss(self) -> float:
        return self.p.x_kiss_ref - self.p.lever_ratio * self.table.delta_kiss(self.theta_used() - KELVIN)


class ClutchFmu:
    """The clutch FMU through fmpy's FMU2Slave with name-based set/get."""

    def __init__(self, fmu: Path, start: dict[str, float]):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        md = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.unzip = extract(str(fmu))
        self.s = FMU2Slave(guid=md.guid, unzipDirectory=self.unzip,
                           modelIdentifier=md.coSimulation.modelIdentifier, instanceName="clutch")
        self.s.instantiate()
        self.s.setupExperiment(startTime=0.0)
        if start:
            self.s.setReal([self.vr[k] for k in start], list(start.values()))
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()
        self.vin = [self.vr["x_to"], self.vr["theta_cm"]]
        self.vout = [self.vr["torque"], self.vr["theta_cs"], self.vr["x_kiss"]]

    def step(self, t: float, h: float, x_to: float, theta_cm: float) -> list[float]:
        self.s.setReal(self.vin, [x_to, theta_cm])
        self.s.doStep(t, h)
        return self.s.getReal(self.vout)

    def close(self) -> None:
        self.s.terminate()
        self.s.freeInstance()
        shutil.rmtree(self.unzip, ignore_errors=True)


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


@dataclass
class LaunchResult:
    """Time series, per-launch metrics and energy terms of one TCU's run."""

    tcu: str
    series: np.ndarray            # structured, fields COLUMNS
    metrics: list[dict]
    energy: Energy
    lock_events: list[tuple[int, str, float]]
    wall_time_s: float


def _facing_profile(path: str) -> Callable[[float], float]:
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return lambda t: float(np.interp(t, data[:, 0], data[:, 1]))


def simulate_launches(fmu: Path, sc: Scenario, table: SpringTable, aware: bool,
                      record_every: int = 10, progress: Callable[[float], None] | None = None) -> LaunchResult:
    """Run the scenario's launches with one TCU; see the module docstring."""
    import time as _time

    e, dl, veh, fac, tc, run = sc.engine, sc.driveline, sc.vehicle, sc.facing, sc.tcu, sc.run
    h = run.step_s
    theta_a = fac.ambient_degC + KELVIN
    theta0 = fac.initial_degC + KELVIN
    p = ClutchParameters(theta_a=theta_a, theta_cs_start=theta0)
    tcu = TcuController(table, p, aware, theta_est=theta0)
    clutch = ClutchFmu(fmu, {"theta_a": theta_a, "theta_cs_start": theta0})
    profile = _facing_profile(fac.profile_csv) if fac.profile_csv else None

    i_tot = dl.gear_ratio * dl.final_drive_ratio
    r, eta = dl.wheel_radius_m, dl.efficiency
    slope = math.atan(veh.slope_percent / 100.0)
    f_grade = veh.mass_kg * G * math.sin(slope)
    f_roll = veh.rolling_resistance * veh.mass_kg * G * math.cos(slope)
    m_eq = veh.mass_kg + eta * dl.disc_inertia_kg_m2 * (i_tot / r) ** 2
    j_kin = dl.disc_inertia_kg_m2 + veh.mass_kg * (r / i_tot) ** 2         # disc side, at disc speed
    j_d = m_eq * r * r / (eta * i_tot * i_tot)     # disc side as the clutch feels it (efficiency)
    j_e = e.inertia_kg_m2
    curve_w = [x * RPM for x in e.torque_curve_rpm]
    w_idle, w_stall, w_max = e.idle_speed_rpm * RPM, e.stall_speed_rpm * RPM, e.max_speed_rpm * RPM
    w_launch = e.launch_speed_rpm * RPM
    tcu_every = max(1, int(round(tc.period_s / h)))
    act = math.exp(-h / tc.actuator_time_constant_s) if tc.actuator_time_constant_s > 0 else 0.0
    fac_decay = math.exp(-h * fac.loss_W_per_K / fac.capacity_J_per_K)

    def kinetic(w_e: float, v: float) -> float:
        w_d = v * i_tot / r
        return 0.5 * j_e * w_e ** 2 + 0.5 * dl.disc_inertia_kg_m2 * w_d ** 2 + 0.5 * veh.mass_kg * v ** 2

    w_e, v, locked = w_idle, 0.0, False
    gov_int = 0.0
    theta_cm = theta0
    x_cmd = x_act = 0.0
    t_cap = 0.0
    en = Energy()
    ke0 = kinetic(w_e, v)
    n_steps = int(round(run.launches * run.period_s / h))
    rows = []
    lock_events: list[tuple[int, str, float]] = []
    per_launch = [dict(launch=k + 1, lock_time=None, stall=False, slip_energy=0.0, err=[], jerk=0.0,
                       kiss_err=None, theta_cs=None) for k in range(run.launches)]
    a_prev = a_filt = 0.0
    jerk_alpha = h / (0.02 + h)                                  # 20 ms low-pass of the acceleration
    t_dem = 0.0
    thr = 0.0
    theta_cs = theta0
    x_kiss = p.x_kiss_ref
    phase = "open"
    wall0 = _time.perf_counter()
    for k in range(n_steps):
        t = k * h
        n = min(int(t // run.period_s), run.launches - 1)
        tl = t - n * run.period_s
        rec = per_launch[n]
        # -- TCU --------------------------------------------------------------
        if k % tcu_every == 0:
            tcu.update_estimate(theta_cm, tcu_every * h)
            if tl < tc.drive_time_s:
                if rec["lock_time"] is None:
                    phase = "launch"
                    t_dem = min(tc.torque_target_Nm, tc.torque_ramp_Nm_per_s * tl)
                    x_cmd = tcu.command(t_dem)
                else:
                    phase = "close"
                    x_cmd = min(tc.x_to_closed_m, x_cmd + tc.close_rate_m_per_s * tcu_every * h)
            elif n + 1 < run.launches and tl >= run.period_s - tc.prefill_s:
                phase, t_dem, x_cmd = "open", 0.0, tcu.command(0.0)    # pre-fill to first contact
            else:
                phase, t_dem, x_cmd = "open", 0.0, 0.0
        x_act = x_cmd + (x_act - x_cmd) * act
        theta_cm_step = theta_cm                                   # held over the step
        # -- clutch FMU -----------------------------------------------------------
        t_cap, theta_cs, x_kiss = clutch.step(t, h, x_act, theta_cm_step)
        if rec["kiss_err"] is None and phase == "launch":      # at the launch start
            rec["kiss_err"] = tcu.kiss() - x_kiss
            rec["theta_cs"] = theta_cs
        # -- engine torque ---------------------------------------------------------
        t_max = float(np.interp(w_e, curve_w, e.torque_curve_Nm))
        err_w = (w_idle if phase == "open" else w_launch) - w_e
        gov = (e.governor_kp_Nm_per_rad_s * err_w + e.governor_ki_Nm_per_rad * gov_int
               + e.drag_Nm_per_rad_s * w_e)                       # drag feed-forward
        thr = min(1.0, max(0.0, gov / t_max))
        if (thr < 1.0 or err_w < 0.0) and (thr > 0.0 or err_w > 0.0):
            gov_int += err_w * h                                  # anti-windup: hold when saturated
        if w_e > w_max or w_e <= w_stall or rec["stall"]:
            thr = 0.0
        t_e = thr * t_max - e.drag_Nm_per_rad_s * w_e
        # -- driveline ----------------------------------------------------------------
        w_d = v * i_tot / r
        f_air = 0.5 * veh.air_density_kg_m3 * veh.drag_area_m2 * v * v
        f_res = f_roll * (1.0 if v > 0 else 0.0) + f_air + f_grade
        t_load = f_res * r / (eta * i_tot)                         # resistance felt at the clutch
        braking = phase == "open" and tl >= tc.drive_time_s
        if locked:
            dw = (t_e - t_load) / (j_e + j_d) * h
            t_c = t_e - j_e * dw / h
            if abs(t_c) > t_cap:
                locked = False
                lock_events.append((n + 1, "unlock", t))
        if locked:
            w_e_new = w_e + dw
            v_new = w_e_new * r / i_tot
        else:
            t_c = math.copysign(t_cap, w_e - w_d) if w_e != w_d else 0.0
            w_e_new = w_e + (t_e - t_c) / j_e * h
            drive = eta * i_tot * t_c / r
            v_new = v + (drive - f_res) / m_eq * h
            f_brake = 0.0
            if braking and v > 0:
                f_brake = min(veh.brake_decel_m_s2 * veh.mass_kg, max(0.0, m_eq * v / h + drive - f_res))
                v_new = v + (drive - f_res - f_brake) / m_eq * h
            if v_new < 0.0:                                         # hill hold / brake holds at rest
                f_brake += -m_eq * v_new / h
                v_new = 0.0
            en.brake += f_brake * 0.5 * (v + v_new) * h
            if w_e_new < 0.0:
                w_e_new = 0.0
        # -- energy bookkeeping with midpoint speeds -------------------------------
        wm_e = 0.5 * (w_e + w_e_new)
        v_m = 0.5 * (v + v_new)
        wm_d = v_m * i_tot / r
        en.engine_work += t_e * wm_e * h
        slip_p = t_c * (wm_e - wm_d) * h
        en.slip += slip_p
        rec["slip_energy"] += slip_p
        t_in = t_c - dl.disc_inertia_kg_m2 * (i_tot / r) * (v_new - v) / h
        en.resistance += (f_res - f_grade) * v_m * h + (1 - eta) * t_in * wm_d * h
        en.potential += f_grade * v_m * h
        # -- lock-up: the slip speed crosses zero and the locked torque fits the capacity
        w_d_new = v_new * i_tot / r
        if not locked and t_cap > 0 and phase != "open" and (w_e - w_d) * (w_e_new - w_d_new) <= 0.0:
            if abs((j_d * t_e + j_e * t_load) / (j_e + j_d)) <= t_cap:
                ke_before = kinetic(w_e_new, v_new)
                w = (j_e * w_e_new + j_kin * w_d_new) / (j_e + j_kin)
                w_e_new, v_new = w, w * r / i_tot
                loss = ke_before - kinetic(w_e_new, v_new)       # the impact of merging the speeds
                en.slip += loss
                rec["slip_energy"] += loss
                locked = True
                lock_events.append((n + 1, "lock", t + h))
                if rec["lock_time"] is None:
                    rec["lock_time"] = tl + h
        # -- facing heated by the slip power -----------------------------------------
        if profile is not None:
            theta_cm = profile(t + h)
        else:
            p_slip = fac.heat_share * abs(t_c * (wm_e - wm_d))
            if fac.loss_W_per_K > 0:                               # exact for p_slip held
                theta_inf = theta_a + p_slip / fac.loss_W_per_K
                theta_cm = theta_inf + (theta_cm - theta_inf) * fac_decay
            else:
                theta_cm += p_slip * h / fac.capacity_J_per_K
        # -- metrics -------------------------------------------------------------------
        accel = (v_new - v) / h
        a_filt += jerk_alpha * (accel - a_filt)
        if phase != "open":
            rec["jerk"] = max(rec["jerk"], abs(a_filt - a_prev) / h)
        a_prev = a_filt
        if phase == "launch" and rec["lock_time"] is None and t_dem > 0:
            rec["err"].append(t_cap - t_dem)
        if w_e_new <= w_stall and phase != "open":
            rec["stall"] = True
        if rec["stall"] and tl + h >= run.period_s - h:              # restart for the next launch
            en.engine_work += 0.5 * j_e * (w_idle ** 2 - w_e_new ** 2)   # the starter's work
            w_e_new = w_idle
        w_e, v = w_e_new, v_new
        if phase == "open" and locked:
            locked = False
            lock_events.append((n + 1, "unlock", t + h))
        if k % record_every == 0:
            rows.append((t, n + 1, w_e, v * i_tot / r, v, accel, x_cmd, x_act, t_dem, t_cap, t_c,
                         theta_cm_step, theta_cs, tcu.theta_used(), x_kiss, tcu.kiss(), thr, float(locked)))
        if progress is not None and k % 10000 == 0:
            progress(t)
    en.kinetic = kinetic(w_e, v) - ke0
    clutch.close()
    wall = _time.perf_counter() - wall0
    series = np.array(rows, dtype=[(c, float) for c in COLUMNS])
    metrics = [_metrics(r_) for r_ in per_launch]
    return LaunchResult(tcu.name, series, metrics, en, lock_events, wall)


def _metrics(rec: dict) -> dict:
    err = np.asarray(rec["err"])
    return {
        "launch": rec["launch"],
        "theta_cs_start_degC": (rec["theta_cs"] or KELVIN) - KELVIN,
        "torque_error_rms_Nm": float(np.sqrt(np.mean(err ** 2))) if len(err) else float("nan"),
        "torque_error_max_Nm": float(np.max(np.abs(err))) if len(err) else float("nan"),
        "kiss_point_error_mm": (rec["kiss_err"] or 0.0) * 1e3,
        "engagement_time_s": rec["lock_time"] if rec["lock_time"] is not None else float("nan"),
        "slip_energy_kJ": rec["slip_energy"] / 1e3,
        "peak_jerk_m_s3": rec["jerk"],
        "engine_stall": bool(rec["stall"]),
    }
