"""Repeated vehicle launches: a Python driveline and a TCU around the clutch FMU.

Communication step ``run.step_s``, except in *quiet* TCU periods (``run.quiet_steps``): while the car
stands braked with the clutch open and retracted, only the idle engine and the temperatures move, and the
master, the engine and the clutch FMU advance one TCU period per step with the facing temperature held
(the FMU's theta_cs step is its ODE's exact exponential; a held input over 10 instead of 1 ms moves
theta_cs by about 1 mK). Rows recorded inside a quiet period carry the state at its end.

Each launch slot starts with the pre-fill, then the driver presses the pedal (the slot's demand level,
``[driver]``) for ``tcu.drive_time_s`` (lifting off above
``driver.lift_off_speed_rpm`` once locked), then the clutch opens and the
brake stops the car. Per step: the TCU (every ``tcu.period_s``,
:mod:`.tcu`) commands a bearing position from measured speeds
(:mod:`.observer`) and the engine's torque signal, a first-order actuator
moves the bearing, the clutch FMU (:mod:`.fmu_client`) returns the
transmissible torque for the bearing position, facing temperature and slip
speed held over the step, the engine (:mod:`.engine`) and the compliant
driveline (:mod:`.driveline`) advance, the facings heat up
(:mod:`.thermal`) and the metrics are collected (:mod:`.metrics`).

With the plant's thermal network (every shipped scenario) the steps from one TCU cycle to the next, the
network's step among them, and each quiet period run in one compiled call by default (``plant="native"``,
:mod:`.plant_block`; the plant's state stays in C over the run): the same steps, written out in C with the
Python expressions' order of operations; the Python per-step code below stays the reference
(``plant="python"``) and both give the same results (``tests/test_launch_plant_block.py``).
"""
from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..model import KELVIN, ClutchParameters, SpringTable
from .driveline import Driveline, Energy
from .engine import EngineGovernor
from ..errors import FmuCallError
from .fmu_client import ClutchFmu
from .metrics import LaunchRecord, launch_possible
from .observer import SpeedSensors
from .scenario import Scenario
from .engine import RPM
from .production import KeyOn, ProductionTcu, key_off, key_on
from .tcu import CLOSE, LAUNCH, OPEN, PREFILL, VARIANTS, TcuController
from .thermal import FacingModel
from ..model.thermal_network import SURFACES, ThermalNetwork

#: fmi2Discard: the status of a step the plant FMU refuses for an input outside its range
DISCARD = 2

__all__ = ["COLUMNS", "Energy", "LaunchResult", "PLANTS", "simulate_launches"]

log = logging.getLogger(__name__)

#: the plant loop: compiled blocks between TCU cycles (plant_block) or the Python loop (the reference)
PLANTS = ("native", "python")

#: bearing positions closer to zero than this count as retracted (quiet steps), m
X_RETRACTED_M = 1e-6

#: columns of the time series (SI; recorded every ``record_every`` steps)
COLUMNS = ("time_s", "launch", "w_engine_rad_s", "w_disc_rad_s", "v_m_s", "accel_m_s2", "x_cmd_m",
           "x_to_m", "torque_demand_Nm", "torque_capacity_Nm", "torque_clutch_Nm", "theta_cm_K",
           "theta_cs_K", "theta_cs_tcu_K", "x_kiss_m", "x_kiss_tcu_m", "throttle", "locked", "theta_cm_tcu_K",
           "torque_believed_Nm", "torque_shaft_Nm", "theta_surface_K", "theta_pressure_plate_K", "protection_level")
#: theta_surface_K: the hotter metal friction surface (1 mm layer), theta_pressure_plate_K: the pressure plate's
#: bulk node, both from the plant's thermal network (NaN with the lumped facing or a prescribed profile);
#: protection_level: the TCU's thermal protection (0 ok, 1 warn, 2 limit, 3 inhibited)


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
    quiet_s: float = 0.0
    """simulated time advanced in quiet steps (``run.quiet_steps``), s"""
    key_on: KeyOn | None = None
    """production TCU: how it started (reset or learned) and its standstill touch-point learning"""
    protection_events: list = field(default_factory=list)
    """(s into the launch slot, launch, level, message): what the thermal protection told the driver"""
    plant: str = "python"
    """the plant loop that ran: ``native`` (compiled blocks, :mod:`.plant_block`) or ``python``"""
    stopped: str = ""
    """why and where the run ended early ("" for a complete run): the plant FMU refused a step because the plant
    left the model's domain (e.g. a facing past 800 K); ``metrics`` then hold the launches up to that one"""


def _facing_profile(path: str) -> Callable[[float], float]:
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    t, th = data[:, 0].tolist(), data[:, 1].tolist()
    return lambda x: float(np.interp(x, t, th))


def _native_plant(clutch, engine, dl, net, h, act, w_lift, prefill, tcu_every, net_every, alpha, mu_surface=None,
                  n_surfaces=0.0, r_eq=0.0):
    """The compiled plant steps (:mod:`.plant_block`), or None (logged) if the library cannot be built."""
    from .metrics import CREEP_NM
    from .plant_block import NativePlant
    try:
        return NativePlant(clutch, engine, dl, net, h, act, w_lift, prefill, tcu_every, net_every, alpha, CREEP_NM,
                           mu_surface, n_surfaces, r_eq)
    except (RuntimeError, ValueError, OSError) as exc:
        log.warning("the native launch plant is not available, running the Python loop: %s", exc)
        return None


def _retracted_error(t: float, t_cap: float, x_act: float, x_kiss: float) -> RuntimeError:
    """A quiet period's clutch FMU returned a torque with the bearing retracted."""
    return RuntimeError(f"t = {t:g} s: the clutch FMU returned {t_cap:g} N.m with the bearing "
                        f"retracted to {x_act:g} m (kiss point {x_kiss:g} m)")


def simulate_launches(fmu: Path, sc: Scenario, table: SpringTable, tcu: str | bool = "naive",
                      record_every: int = 10, progress: Callable[[float], None] | None = None,
                      plant: str = "native", plant_start: dict | None = None) -> LaunchResult:
    """Run the scenario's launches with one TCU variant (a name of :data:`VARIANTS`).

    ``tcu`` True/False are the ``aware``/``naive`` variants. ``table`` is
    the TCU's characteristic; the plant is the FMU (with its own friction
    table, if any). ``progress(t)`` is called every 10,000 steps.
    ``plant``: ``"native"`` runs the plant steps between two TCU cycles in one compiled call
    (:mod:`.plant_block`; with the plant's thermal network, else, or if it cannot be built, the Python
    loop), ``"python"`` the Python loop (the reference). Both give the same results.
    ``plant_start``: start values of the plant FMU from an SSP parameter set (:func:`plant_start_values`).
    """
    name = {True: "aware", False: "naive"}.get(tcu, tcu) if isinstance(tcu, bool) else tcu
    if name not in VARIANTS:
        raise ValueError(f"tcu = {tcu!r}: allowed {', '.join(VARIANTS)}")
    if plant not in PLANTS:
        raise ValueError(f"plant = {plant!r}: allowed {', '.join(PLANTS)}")
    if record_every < 1:
        raise ValueError(f"record_every = {record_every!r}: must be at least 1 (steps between the series' rows)")
    fac, tc, run, drv = sc.facing, sc.tcu, sc.run, sc.driver
    h = run.step_s
    theta_a, theta0 = fac.ambient_degC + KELVIN, fac.initial_degC + KELVIN
    spring_heat = sc.spring_thermal_set()               # the cushion spring's heat path (clutch.spring_thermal)
    p = ClutchParameters(theta_a=theta_a, theta_cs_start=theta0, U=spring_heat.U_W_per_K, H=spring_heat.H_W_per_K,
                         C=spring_heat.C_J_per_K)
    engine = EngineGovernor(sc.engine, h)
    dl = Driveline(sc, engine.w_idle)
    if name == "production":
        ctl = ProductionTcu(VARIANTS[name], sc, table, p, theta0, dl.j_d, dl.t_load_rest, dl.j_e, engine.w_idle,
                            sc.tcu_sensors, sc.tcu_thermal, sc.ekf, sc.mass_grade,
                            (dl.i_tot, dl.r, dl.eta, sc.driveline.disc_inertia_kg_m2, sc.vehicle.rolling_resistance,
                             dl.air))
        sense = ctl.sense
    else:
        ctl = TcuController(VARIANTS[name], sc, table, p, theta0, dl.j_d, dl.t_load_rest, dl.j_e, engine.w_idle)
        sense = None
    # the plant's thermal network (a prescribed profile_csv overrides it; disabled: the lumped facing)
    net = ThermalNetwork(sc.plant_thermal, theta_a, theta0) if sc.plant_thermal.enabled and not fac.profile_csv \
        else None
    net_temps = ((lambda: (net.theta_surface, net.theta[-1])) if net is not None
                 else (lambda: (math.nan, math.nan)))
    net_every = max(1, int(round(tc.period_s / h)))     # the network's time constants are seconds: 10 ms steps
    net_n, net_e = 0, 0.0
    sensors = SpeedSensors(sc.sensors)
    facing = FacingModel(fac.capacity_J_per_K, fac.loss_W_per_K, fac.heat_share, theta_a, h)
    profile = _facing_profile(fac.profile_csv) if fac.profile_csv else None
    starts = run.starts()
    total = run.duration()
    ends = starts[1:] + [total]
    levels = [drv.level(i + 1) for i in range(len(starts))]
    possible = {lv: launch_possible(sc, lv) for lv in set(levels)}
    recs = [LaunchRecord(i + 1, i >= run.launches, h, levels[i], possible[levels[i]]) for i in range(len(starts))]
    tcu_every = max(1, int(round(tc.period_s / h)))
    act = math.exp(-h / tc.actuator_time_constant_s) if tc.actuator_time_constant_s > 0 else 0.0
    w_idle, w_stall = engine.w_idle, engine.w_stall
    w_lift = drv.lift_off_speed_rpm * RPM
    r_to_disc = dl.i_tot / dl.r
    prefill, drive_end = tc.prefill_s, tc.prefill_s + tc.drive_time_s

    clutch_start = {"theta_a": theta_a, "theta_cs_start": theta0, "x_kiss_ref": p.x_kiss_ref + sc.clutch.x_kiss_offset_m,
                    **spring_heat.parameters(),
                    **({"facing_wear": sc.clutch.facing_wear_m} if sc.clutch.facing_wear_m else {})}
    if plant_start:
        clutch_start = plant_start_values(plant_start, clutch_start, p.x_kiss_ref, sc)
    keyed = (key_on(ctl, sc, fmu, clutch_start, sc.driveline.disc_inertia_kg_m2, engine.w_idle)
             if name == "production" else None)
    clutch = ClutchFmu(fmu, clutch_start)
    # mu at the friction surface (issue 37): with the network and a friction table the plant's torque is
    # n mu(theta_friction, |omega_slip|) R_eq F_clamp, the clutch FMU's own torque formula with mu read at the
    # network's friction-surface temperature (ThermalNetwork.theta_friction, held over the step as theta_cm is)
    # instead of at the facings' mean; the clutch FMU still gets theta_cm (the cushion spring's ODE, the stack's
    # growth, validity); the table is the FMU's own (friction.csv in its resources). Without the network or a
    # friction table: the FMU's torque (mu at theta_cm, or constant)
    mu_surface = clutch.friction_table() if net is not None else None
    theta_fs = net.theta_friction if net is not None else theta0
    n_surfaces, r_eq = p.n_surfaces, p.R_eq
    theta_cm = theta0
    x_act = 0.0
    theta_cs, x_kiss = theta0, p.x_kiss_ref
    t_cap = t_e = believed = 0.0
    ke0 = dl.kinetic()
    n_steps = int(round(total / h))
    rows = []
    events: list[tuple[int, str, float]] = []
    n, rec, slot_start, slot_end = 0, recs[0], starts[0], ends[0]
    pedal_level = drv.pedal(levels[0])
    engaged = braking = launching = sampling = lifted = False
    countdown = 0
    clutch_step, engine_torque, dl_step, facing_step = clutch.step, engine.torque, dl.step, facing.step
    clutch_out = clutch.out
    n_slots = len(starts)
    next_switch = slot_end - 0.5 * h if n_slots > 1 else math.inf
    stalled = False
    rec_countdown = 0
    cool_free = profile is None and facing.g > 0.0        # no slip: exact decay towards ambient, inlined
    fac_decay = facing.decay
    h_quiet = tcu_every * h
    quiet = run.quiet_steps
    act_quiet = act ** tcu_every
    facing_quiet = FacingModel(fac.capacity_J_per_K, fac.loss_W_per_K, fac.heat_share, theta_a, h_quiet)
    n_quiet = 0
    native = None
    if plant == "native" and net is not None:
        native = _native_plant(clutch, engine, dl, net, h, act, w_lift, prefill, tcu_every, net_every,
                               recs[0].alpha, mu_surface, n_surfaces, r_eq)
    if native is not None:               # the plant's state moves into C; where a step's figures are in its list
        native.start(rec, x_act, theta_cm, t_e, t_cap, theta_cs, x_kiss)
        native_block, native_quiet, native_row, native_accels = native.block, native.quiet, native.row, native.accels
        values, width, ix = native.values, native.width, native.ix
        o_kiss, o_theta_cs, o_t_cap, o_event = ix["x_kiss"], ix["theta_cs"], ix["t_cap"], ix["event"]
    # the ideal TCU is told the true hotter friction surface too (its thermal protection, tcu.theta_facing_protect)
    ideal_surface = net is not None and VARIANTS[name].temperature == "ideal"
    wall0, cpu0 = time.perf_counter(), time.process_time()
    stopped = ""
    try:
        k = 0
        while k < n_steps:
            t = k * h
            if t >= next_switch:
                n += 1
                if native is not None:
                    native.new_slot(rec, recs[n])
                rec, slot_start, slot_end = recs[n], starts[n], ends[n]
                next_switch = slot_end - 0.5 * h if n + 1 < n_slots else math.inf
                stalled = lifted = False
                pedal_level = drv.pedal(levels[n])
            tl = t - slot_start
            cycled = countdown == 0
            if cycled:                                           # -- TCU cycle
                countdown = tcu_every
                if ideal_surface:
                    ctl.theta_surface_ideal = (max(native.s.theta[SURFACES[0]], native.s.theta[SURFACES[1]])
                                               if native is not None else net.theta_surface)
                if sense is not None:         # production TCU: its own speed sensors, read from the truth given;
                    sense(t, dl.w_e, dl.w_d, t_e)                 # the wheel speed as the others read it (ABS)
                    ctl.cycle(n + 1, tl, rec.lock_time is not None, dl.w_e, dl.w_d, x_act, theta_cm, t_e, levels[n],
                              sensors.read(dl.v * r_to_disc))
                else:
                    ctl.cycle(n + 1, tl, rec.lock_time is not None, sensors.read(dl.w_e), sensors.read(dl.w_d),
                              x_act, theta_cm, t_e, levels[n], sensors.read(dl.v * r_to_disc))
                phase = ctl.phase
                engaged = phase == LAUNCH or phase == CLOSE
                launching = phase == LAUNCH
                sampling = (launching or phase == PREFILL) and rec.lock_time is None
                braking = not engaged and (tl >= drive_end or ctl.inhibited)   # inhibited: the driver brakes
                if ctl.launch_level != rec.protection:
                    rec.protection = ctl.launch_level
                    if ctl.inhibited and not rec.started:          # an inhibited launch: its start state
                        rec.start(ctl.kiss_now - x_kiss, theta_cs, ctl.theta_now - theta_cs)
            if (quiet and cycled and braking and ctl.phase == OPEN and ctl.x_cmd == 0.0 and t_cap == 0.0
                    and -X_RETRACTED_M < x_act < X_RETRACTED_M and not stalled and not dl.locked and dl.v == 0.0
                    and dl.w_d == 0.0 and dl.phi == 0.0 and k + tcu_every <= n_steps
                    and (k + tcu_every - 1) * h < next_switch):
                # -- a quiet TCU period: the car stands braked, the clutch is open and retracted, only the
                # engine's idle governor and the temperatures move: one step of h_quiet for all of them
                # (the clutch FMU's theta_cs and the facing decay are exact exponentials for held inputs; the
                # idle engine is the same explicit step, stable and settled long before the next launch)
                if native is not None:                  # the same period in C (plant_block)
                    head = native_quiet(t, h_quiet, act_quiet)
                    if head is None:
                        st = native.s
                        raise _retracted_error(t, st.t_cap, st.x_act, st.x_kiss)
                    (_, _, dl.w_e, _, _, _, _, t_e, x_act, theta_cm, t_cap, theta_cs, x_kiss, _, _, _, throttle,
                     theta_cm_step, theta_surface, theta_last) = head
                else:
                    x_act *= act_quiet
                    t_cap, theta_cs, x_kiss = clutch_step(t, h_quiet, x_act, theta_cm, dl.w_e)
                    if t_cap != 0.0:
                        raise _retracted_error(t, t_cap, x_act, x_kiss)
                    theta_cm_step = theta_cm
                    engine.h = dl.h = h_quiet
                    t_e = engine_torque(dl.w_e, 0.0, False)
                    dl_step(t_e, 0.0, False, True)
                    engine.h = dl.h = h
                    if net is not None:
                        net_n += tcu_every
                        if net_n >= net_every:
                            net.step(net_n * h, net_e / (net_n * h), dl.w_e, 0.0, False)
                            theta_cm, net_n, net_e = net.theta_cm, 0, 0.0
                            theta_fs = net.theta_friction
                    elif profile is not None:
                        theta_cm = profile(t + h_quiet)
                    else:
                        theta_cm = facing_quiet.step(theta_cm, 0.0)
                    throttle = engine.throttle
                    theta_surface, theta_last = net_temps()
                for j in range(rec_countdown, tcu_every, record_every):      # the rows due in the period
                    rows.append((t + j * h, n + 1, dl.w_e, 0.0, 0.0, 0.0, 0.0, x_act, 0.0, 0.0, 0.0,
                                 theta_cm_step, theta_cs, ctl.theta_now, x_kiss, ctl.kiss_now, throttle,
                                 0.0, ctl.theta_cm_estimate(), math.nan, 0.0, theta_surface, theta_last,
                                 ctl.protection.level if ctl.protection is not None else 0.0))
                    if progress is not None and (k + j) % 10000 == 0:
                        progress(t + j * h)
                rec_countdown = (rec_countdown - tcu_every) % record_every
                countdown = 0
                k += tcu_every
                n_quiet += 1
                continue
            if native is not None:
                # -- the steps to the next TCU cycle in one compiled call (plant_block; the same step as below)
                if cycled and sampling:                  # at the actual bearing position of the first step
                    x_cmd = ctl.x_cmd
                    believed = ctl.model_torque(x_cmd + (x_act - x_cmd) * act)
                (m, n_events, dl.w_e, dl.w_d, dl.v, dl.phi, locked, t_e, x_act, theta_cm, t_cap, theta_cs, x_kiss,
                 stalled, has_lock, lock_time, _, _, _, _) = native_block(
                    k, n_steps, next_switch, slot_start, slot_end, countdown, ctl.x_cmd, pedal_level, ctl.t_dem,
                    ctl.t_rate, engaged, braking, launching)
                m = int(m)
                dl.locked, stalled = locked != 0.0, stalled != 0.0
                if has_lock and rec.lock_time is None:
                    rec.lock_time = lock_time
                if engaged:
                    if not rec.started:
                        theta_cs_0 = values[o_theta_cs]            # the block's first step
                        rec.start(ctl.kiss_now - values[o_kiss], theta_cs_0, ctl.theta_now - theta_cs_0)
                    if not rec.acc:
                        rec.t_first = tl + h - prefill
                    rec.acc.extend(native_accels(m))
                if cycled and sampling:
                    rec.characteristic(believed, values[o_t_cap])
                if n_events:
                    for j in range(m):
                        ev = values[j * width + o_event]
                        if ev != 0.0:
                            events.append((n + 1, "lock" if ev > 0 else "unlock",
                                           (k + j) * h + h if ev != -1.0 else (k + j) * h))
                if rec_countdown < m:
                    theta_estimate = ctl.theta_cm_estimate()
                    protection_level = ctl.protection.level if ctl.protection is not None else 0.0
                    for j in range(rec_countdown, m, record_every):
                        t = (k + j) * h
                        (w_e_o, w_d_o, v_o, accel_o, x_act_o, t_dem_o, t_cap_o, t_c_o, theta_cm_o, theta_cs_o,
                         x_kiss_o, throttle_o, locked_o, t_shaft_o, theta_surface, theta_last) = native_row(j)
                        rows.append((t, n + 1, w_e_o, w_d_o, v_o, accel_o, ctl.x_cmd, x_act_o, t_dem_o, t_cap_o,
                                     t_c_o, theta_cm_o, theta_cs_o, ctl.theta_now, x_kiss_o, ctl.kiss_now,
                                     throttle_o, locked_o, theta_estimate, believed if sampling else math.nan,
                                     t_shaft_o, theta_surface, theta_last, protection_level))
                        if progress is not None and (k + j) % 10000 == 0:
                            progress(t)
                rec_countdown = (rec_countdown - m) % record_every
                countdown -= m
                k += m
                continue
            countdown -= 1
            x_cmd = ctl.x_cmd
            x_act = x_cmd + (x_act - x_cmd) * act
            w_e = dl.w_e
            # -- clutch FMU, inputs held over the step
            omega_slip = w_e - dl.w_d
            t_cap, theta_cs, x_kiss = clutch_step(t, h, x_act, theta_cm, omega_slip)
            if mu_surface is not None:
                t_cap = n_surfaces * mu_surface(theta_fs - KELVIN, omega_slip) * r_eq * clutch_out[3]
            if engaged and not rec.started:
                rec.start(ctl.kiss_now - x_kiss, theta_cs, ctl.theta_now - theta_cs)
            if cycled and sampling:
                believed = ctl.model_torque(x_act)
                rec.characteristic(believed, t_cap)
            if engaged and not lifted and rec.lock_time is not None and w_e > w_lift:
                lifted = True
            t_e = engine_torque(w_e, pedal_level if engaged and not lifted else 0.0, stalled)
            v = dl.v
            ev = dl_step(t_e, t_cap, engaged, braking)
            if ev:
                events.append((n + 1, "lock" if ev > 0 else "unlock", t + h if ev > 0 else t))
                if ev > 0 and rec.lock_time is None:
                    rec.lock_time = tl + h - prefill
            slip_J = dl.slip_J
            theta_cm_step = theta_cm
            if net is not None:
                rec.slip_J += slip_J
                net_e += slip_J
                net_n += 1
                if net_n == net_every:
                    net.step(net_n * h, net_e / (net_n * h), dl.w_e, dl.w_d, engaged)
                    theta_cm, net_n, net_e = net.theta_cm, 0, 0.0
                    theta_fs = net.theta_friction
            elif slip_J != 0.0:
                rec.slip_J += slip_J
                theta_cm = profile(t + h) if profile is not None else facing_step(theta_cm, dl.slip_W)
            elif cool_free:
                theta_cm = theta_a + (theta_cm - theta_a) * fac_decay
            else:
                theta_cm = profile(t + h) if profile is not None else facing_step(theta_cm, 0.0)
            accel = (dl.v - v) / h
            if engaged:
                rec.step(accel, tl + h - prefill, ctl.t_dem + ctl.t_rate * (tcu_every - countdown) * h, t_cap,
                         launching)
                if dl.w_e <= w_stall:
                    rec.stall = stalled = True
            elif dl.locked:
                dl.locked = False
                events.append((n + 1, "unlock", t + h))
            if stalled and tl + h >= slot_end - slot_start - h:     # restart for the next launch
                dl.restart_engine(w_idle)
            if rec_countdown == 0:
                rec_countdown = record_every
                rows.append((t, n + 1, dl.w_e, dl.w_d, dl.v, accel, x_cmd, x_act,
                             ctl.t_dem + ctl.t_rate * (tcu_every - countdown) * h, t_cap, dl.t_c, theta_cm_step,
                             theta_cs, ctl.theta_now, x_kiss, ctl.kiss_now, engine.throttle, float(dl.locked),
                             ctl.theta_cm_estimate(), believed if sampling else math.nan,
                             dl.k * dl.phi + dl.c * (dl.w_d - dl.v * dl.i_tot / dl.r), *net_temps(),
                             ctl.protection.level if ctl.protection is not None else 0.0))
                if progress is not None and k % 10000 == 0:
                    progress(t)
            rec_countdown -= 1
            k += 1
        if native is not None:
            native.finish(rec)
    except FmuCallError as exc:
        if exc.status != DISCARD:
            raise
        # the plant FMU refused a step: the plant left the model's domain (its log names the input, e.g. a
        # facing past THETA_MAX_K). The run ends there, honestly: the launches up to it are kept and the
        # result says where and why it stopped (LaunchResult.stopped); nothing after it is invented.
        stopped = (f"launch {n + 1}, t = {t:.2f} s: the plant left the model's domain ({exc}; the FMU's log "
                   f"names the input); the run stops there")
        if native is not None:
            native.finish(rec)
        recs = recs[:n + 1]
    finally:
        clutch.close()
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    dl.en.kinetic = dl.kinetic() - ke0
    dl.en.elastic = dl.elastic()
    series = np.array(rows, dtype=[(c, float) for c in COLUMNS])
    if mu_surface is not None:
        _say_beyond_friction_table(name, series, mu_surface)
    _say_tcu_beyond_model(name, series, table)
    metrics = [r.metrics(run.hot_degC) for r in recs]
    learned = ctl.learner.estimates if ctl.learner is not None else []
    if keyed is not None:
        key_off(ctl, sc, keyed)
    return LaunchResult(name, series, metrics, dl.en, events, wall, total, cpu, learned, n_quiet * h_quiet, keyed,
                        ctl.protection.events if ctl.protection is not None else [],
                        "native" if native is not None else "python", stopped)


def _say_beyond_friction_table(name: str, series, mu) -> float:
    """Log (a warning) when the plant's friction surface left its friction table ``mu`` (the table holds mu at its
    edge there): the time (s) the recorded hotter surface spent outside the table's temperatures, 0 if none."""
    surface = series["theta_surface_K"] - KELVIN
    lo, hi = mu.theta_degC[0], mu.theta_degC[-1]
    outside = (surface > hi) | (surface < lo)
    if not outside.any():
        return 0.0
    dt = np.diff(series["time_s"], append=series["time_s"][-1])
    seconds = float(dt[outside].sum())
    log.warning("%s: the plant's hotter friction surface was outside its friction table (%g to %g degC) for %.1f s, "
                "from %.0f to %.0f degC: mu, read at the two surfaces' mean, is held at the table's edge there "
                "(the model answers outside its table)", name, lo, hi, seconds, float(surface.min()),
                float(surface.max()))
    return seconds


def _say_tcu_beyond_model(name: str, series, table: SpringTable) -> float:
    """Log (a warning) when the TCU's estimates left its clutch model's range, where the model holds its last
    point (the facing estimate outside ``[THETA_MIN_K, THETA_MAX_K]``, ``hold_theta_cm``; the cushion-spring
    estimate outside the table's temperatures): the recorded time (s) outside, 0 if none."""
    from ..model.clutch_model import THETA_MAX_K, THETA_MIN_K

    cm, cs = series["theta_cm_tcu_K"], series["theta_cs_tcu_K"]
    outside = (cm < THETA_MIN_K) | (cm > THETA_MAX_K) | (cs < table.theta_min_K) | (cs > table.theta_max_K)
    if not outside.any():                   # NaN (no facing estimate) compares False: inside
        return 0.0
    dt = np.diff(series["time_s"], append=series["time_s"][-1])
    seconds = float(dt[outside].sum())
    cm = cm if np.isfinite(cm).any() else np.array([math.nan])          # no facing estimate: nan, no warning
    log.warning("%s: the TCU's temperature estimates left its clutch model's range for %.1f s (facings %.0f to "
                "%.0f degC, the model's %.0f to %.0f; cushion spring up to %.0f degC, the table's %.0f to %.0f): the "
                "model holds its last point there", name, seconds, np.nanmin(cm) - KELVIN, np.nanmax(cm) - KELVIN,
                THETA_MIN_K - KELVIN, THETA_MAX_K - KELVIN, float(cs.max()) - KELVIN, table.theta_min_K - KELVIN,
                table.theta_max_K - KELVIN)
    return seconds


def plant_start_values(plant_start: dict, scenario_start: dict, x_kiss_ref_m: float, sc: Scenario) -> dict:
    """The plant FMU's start values with an SSP parameter set (``launch --fmu X.ssp --parameter-set S``): the set's
    values (every parameter, and the table set ``spring``), then the scenario's duty: its ambient and soak
    temperatures, its kiss-point offset added to the set's ``x_kiss_ref`` (m; ``x_kiss_ref_m`` without one) and
    its facing wear if it states one."""
    out = dict(plant_start)
    out.update(theta_a=scenario_start["theta_a"], theta_cs_start=scenario_start["theta_cs_start"])
    out["x_kiss_ref"] = float(plant_start.get("x_kiss_ref", x_kiss_ref_m)) + sc.clutch.x_kiss_offset_m
    if sc.clutch.facing_wear_m:
        out["facing_wear"] = sc.clutch.facing_wear_m
    return out
