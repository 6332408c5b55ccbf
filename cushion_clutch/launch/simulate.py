"""Repeated vehicle launches: a Python driveline and a TCU around the clutch FMU.

Fixed communication step ``run.step_s``. Per step: the TCU (every
``tcu.period_s``, :mod:`.tcu`) commands a bearing position from measured
speeds (:mod:`.observer`), a first-order actuator moves the bearing, the
clutch FMU (:mod:`.fmu_client`) returns the transmissible torque for the
bearing position, facing temperature and slip speed held over the step, the
engine (:mod:`.engine`) and the driveline (:mod:`.driveline`) advance, the
facings heat up (:mod:`.thermal`) and the metrics are collected
(:mod:`.metrics`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..model import KELVIN, ClutchParameters, SpringTable
from .driveline import Driveline, Energy
from .engine import EngineGovernor
from .fmu_client import ClutchFmu
from .metrics import LaunchRecord
from .observer import SpeedSensors
from .scenario import Scenario
from .tcu import OPEN, LAUNCH, VARIANTS, TcuController
from .thermal import FacingModel

__all__ = ["COLUMNS", "Energy", "LaunchResult", "simulate_launches"]

#: columns of the time series (SI; recorded every ``record_every`` steps)
COLUMNS = ("time_s", "launch", "w_engine_rad_s", "w_disc_rad_s", "v_m_s", "accel_m_s2", "x_cmd_m",
           "x_to_m", "torque_demand_Nm", "torque_capacity_Nm", "torque_clutch_Nm", "theta_cm_K",
           "theta_cs_K", "theta_cs_tcu_K", "x_kiss_m", "x_kiss_tcu_m", "throttle", "locked", "theta_cm_tcu_K")


@dataclass
class LaunchResult:
    """Time series, per-launch metrics and energy terms of one TCU's run."""

    tcu: str
    series: np.ndarray            # structured, fields COLUMNS
    metrics: list[dict]
    energy: Energy
    lock_events: list[tuple[int, str, float]]
    wall_time_s: float
    sim_time_s: float
    cpu_time_s: float
    """CPU time of this process in the loop, s (on a shared machine a steadier figure than the wall time)"""
    kiss_estimates: list[tuple[int, float]]


def _facing_profile(path: str) -> Callable[[float], float]:
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    t, th = data[:, 0].tolist(), data[:, 1].tolist()
    return lambda x: float(np.interp(x, t, th))


def simulate_launches(fmu: Path, sc: Scenario, table: SpringTable, tcu: str | bool = "naive",
                      record_every: int = 10, progress: Callable[[float], None] | None = None) -> LaunchResult:
    """Run the scenario's launches with one TCU variant (a name of :data:`VARIANTS`).

    ``tcu`` True/False are the ``aware``/``naive`` variants. ``table`` is
    the TCU's characteristic; the plant is the FMU (with its own friction
    table, if any). ``progress(t)`` is called every 10,000 steps.
    """
    name = {True: "aware", False: "naive"}.get(tcu, tcu) if isinstance(tcu, bool) else tcu
    if name not in VARIANTS:
        raise ValueError(f"tcu = {tcu!r}: allowed {', '.join(VARIANTS)}")
    fac, tc, run = sc.facing, sc.tcu, sc.run
    h = run.step_s
    theta_a, theta0 = fac.ambient_degC + KELVIN, fac.initial_degC + KELVIN
    p = ClutchParameters(theta_a=theta_a, theta_cs_start=theta0)
    engine = EngineGovernor(sc.engine, h)
    dl = Driveline(sc, engine.w_idle)
    ctl = TcuController(VARIANTS[name], sc, table, p, theta0, dl.j_d, dl.t_load_rest)
    sensors = SpeedSensors(sc.sensors)
    facing = FacingModel(fac.capacity_J_per_K, fac.loss_W_per_K, fac.heat_share, theta_a, h)
    profile = _facing_profile(fac.profile_csv) if fac.profile_csv else None
    starts = run.starts()
    total = run.duration()
    ends = starts[1:] + [total]
    recs = [LaunchRecord(i + 1, i >= run.launches, h) for i in range(len(starts))]
    tcu_every = max(1, int(round(tc.period_s / h)))
    act = math.exp(-h / tc.actuator_time_constant_s) if tc.actuator_time_constant_s > 0 else 0.0
    w_idle, w_stall = engine.w_idle, engine.w_stall
    r_to_disc = dl.i_tot / dl.r

    clutch = ClutchFmu(fmu, {"theta_a": theta_a, "theta_cs_start": theta0,
                             "x_kiss_ref": p.x_kiss_ref + sc.clutch.x_kiss_offset_m})
    theta_cm = theta0
    x_act = 0.0
    theta_cs, x_kiss = theta0, p.x_kiss_ref
    t_cap = t_e = 0.0
    ke0 = dl.kinetic(dl.w_e, dl.v)
    n_steps = int(round(total / h))
    rows = []
    events: list[tuple[int, str, float]] = []
    n, rec, slot_start, slot_end = 0, recs[0], starts[0], ends[0]
    engaged = braking = launching = False
    countdown = 0
    clutch_step, engine_torque, dl_step, facing_step = clutch.step, engine.torque, dl.step, facing.step
    n_slots = len(starts)
    next_switch = slot_end - 0.5 * h if n_slots > 1 else math.inf
    stalled = False
    rec_countdown = 0
    cool_free = profile is None and facing.g > 0.0        # no slip: exact decay towards ambient, inlined
    fac_decay = facing.decay
    wall0, cpu0 = time.perf_counter(), time.process_time()
    try:
        for k in range(n_steps):
            t = k * h
            if t >= next_switch:
                n += 1
                rec, slot_start, slot_end = recs[n], starts[n], ends[n]
                next_switch = slot_end - 0.5 * h if n + 1 < n_slots else math.inf
                stalled = False
            tl = t - slot_start
            if countdown == 0:                                   # -- TCU cycle
                countdown = tcu_every
                ctl.cycle(n + 1, tl, slot_end - slot_start, n + 1 < len(starts), rec.lock_time is not None,
                          sensors.read(dl.w_e), sensors.read(dl.v * r_to_disc), x_act, theta_cm)
                engaged = ctl.phase != OPEN
                launching = ctl.phase == LAUNCH
                braking = not engaged and tl >= tc.drive_time_s
            countdown -= 1
            x_cmd = ctl.x_cmd
            x_act = x_cmd + (x_act - x_cmd) * act
            w_e, v = dl.w_e, dl.v
            # -- clutch FMU, inputs held over the step
            t_cap, theta_cs, x_kiss = clutch_step(t, h, x_act, theta_cm, w_e - v * r_to_disc)
            if engaged and not rec.started:
                rec.start(ctl.kiss_now - x_kiss, theta_cs, ctl.theta_now - theta_cs)
            t_e = engine_torque(w_e, engaged, stalled)
            ev = dl_step(t_e, t_cap, engaged, braking)
            if ev:
                events.append((n + 1, "lock" if ev > 0 else "unlock", t + h if ev > 0 else t))
                if ev > 0 and rec.lock_time is None:
                    rec.lock_time = tl + h
            slip_J = dl.slip_J
            theta_cm_step = theta_cm
            if slip_J != 0.0:
                rec.slip_J += slip_J
                theta_cm = profile(t + h) if profile is not None else facing_step(theta_cm, dl.slip_W)
            elif cool_free:
                theta_cm = theta_a + (theta_cm - theta_a) * fac_decay
            else:
                theta_cm = profile(t + h) if profile is not None else facing_step(theta_cm, 0.0)
            accel = (dl.v - v) / h
            if engaged:
                rec.step(accel, tl + h, ctl.t_dem, t_cap, launching)
                if dl.w_e <= w_stall:
                    rec.stall = stalled = True
            elif dl.locked:
                dl.locked = False
                events.append((n + 1, "unlock", t + h))
            if stalled and tl + h >= slot_end - slot_start - h:     # restart for the next launch
                dl.restart_engine(w_idle)
            if rec_countdown == 0:
                rec_countdown = record_every
                rows.append((t, n + 1, dl.w_e, dl.v * r_to_disc, dl.v, accel, x_cmd, x_act, ctl.t_dem, t_cap,
                             dl.t_c, theta_cm_step, theta_cs, ctl.theta_now, x_kiss, ctl.kiss_now,
                             engine.throttle, float(dl.locked), ctl.theta_cm_estimate()))
                if progress is not None and k % 10000 == 0:
                    progress(t)
            rec_countdown -= 1
    finally:
        clutch.close()
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    dl.en.kinetic = dl.kinetic(dl.w_e, dl.v) - ke0
    series = np.array(rows, dtype=[(c, float) for c in COLUMNS])
    metrics = [r.metrics(run.hot_degC) for r in recs]
    learned = ctl.learner.estimates if ctl.learner is not None else []
    return LaunchResult(name, series, metrics, dl.en, events, wall, total, cpu, learned)
