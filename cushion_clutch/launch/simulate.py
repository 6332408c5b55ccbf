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
:mod:`.tcu.controller`) commands a bearing position from measured speeds
(:mod:`.tcu.observer`) and the engine's torque signal, a first-order actuator
moves the bearing, the clutch FMU (:mod:`.plant.fmu_client`) returns the
transmissible torque for the bearing position, facing temperature and slip
speed held over the step, the engine (:mod:`.plant.engine`) and the compliant
driveline (:mod:`.plant.driveline`) advance, the facings heat up
(:mod:`.plant.thermal`) and the metrics are collected (:mod:`.results.metrics`).

With the plant's thermal network (every shipped scenario) the steps from one TCU cycle to the next, the
network's step among them, and each quiet period run in one compiled call by default (``plant="native"``,
:mod:`.plant.plant_block`; the plant's state stays in C over the run): the same steps, written out in C with the
Python expressions' order of operations; the Python steps (:class:`.plant.steps.PythonPlant`) stay the reference
(``plant="python"``) and both give the same results (``tests/test_launch_plant_block.py``). The loop below has
one path through a TCU period: the slot's switch, the TCU's cycle, then the plant to the next cycle (a quiet
period in one step, or a block of steps), whichever engine runs the plant (:mod:`.plant.steps`).
"""
from __future__ import annotations

import logging
import math
import time
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import FmuCallError
from ..model import KELVIN, ClutchParameters, SpringTable
from ..model.thermal_network import ThermalNetwork
from .plant.driveline import Driveline, Energy
from .plant.engine import RPM, EngineGovernor
from .plant.fmu_client import ClutchFmu
from .plant.steps import PLANTS, Plant, facing_profile, open_plant
from .plant.thermal import FacingModel
from .results.metrics import CREEP_NM, LaunchRecord, launch_possible
from .results.series import COLUMNS, LaunchResult, row, series
from .scenario import Scenario
from .tcu.controller import CLOSE, LAUNCH, OPEN, PREFILL, VARIANTS, TcuController
from .tcu.observer import SpeedSensors
from .tcu.production import ProductionTcu, key_off, key_on

#: fmi2Discard: the status of a step the plant FMU refuses for an input outside its range
DISCARD = 2

log = logging.getLogger(__name__)

__all__ = ["COLUMNS", "Energy", "LaunchResult", "PLANTS", "simulate_launches"]


def _variant(tcu: str | bool) -> str:
    """The TCU variant's name (``tcu`` True/False: ``aware``/``naive``), checked."""
    name = {True: "aware", False: "naive"}.get(tcu, tcu) if isinstance(tcu, bool) else tcu
    if name not in VARIANTS:
        raise ValueError(f"tcu = {tcu!r}: allowed {', '.join(VARIANTS)}")
    return name


def _tcu(name: str, sc: Scenario, table: SpringTable, p: ClutchParameters, theta0: float, dl: Driveline,
         engine: EngineGovernor) -> TcuController:
    """The TCU of variant ``name``: the production TCU with its own sensors, network, EKF and estimators."""
    if name != "production":
        return TcuController(VARIANTS[name], table, p, theta0, dl.j_d, dl.t_load_rest, dl.j_e, engine.w_idle,
                             **sc.tcu_sections())
    return ProductionTcu(VARIANTS[name], table, p, theta0, dl.j_d, dl.t_load_rest, dl.j_e, engine.w_idle,
                         sc.tcu_sensors, sc.tcu_thermal, sc.ekf, sc.mass_grade,
                         (dl.i_tot, dl.r, dl.eta, sc.driveline.disc_inertia_kg_m2, sc.vehicle.rolling_resistance,
                          dl.air), **sc.tcu_sections())


def _slots(sc: Scenario) -> tuple[list[float], list[float], list[str], list[LaunchRecord]]:
    """The launch slots' starts and ends (s), demand levels and launch records (``run.launches`` hot ones, then
    the cool-down ones)."""
    run, h = sc.run, sc.run.step_s
    starts = run.starts()
    ends, levels = starts[1:] + [run.duration()], [sc.driver.level(i + 1) for i in range(len(starts))]
    possible = {lv: launch_possible(sc, lv) for lv in set(levels)}
    recs = [LaunchRecord(i + 1, i >= run.launches, h, levels[i], possible[levels[i]]) for i in range(len(starts))]
    return starts, ends, levels, recs


def _clutch_start(sc: Scenario, p: ClutchParameters, spring: dict[str, float], plant_start: dict | None) -> dict:
    """The plant FMU's start values: ambient and soak (K), the kiss point with the scenario's offset (m), the
    cushion spring's heat path (``U``, ``H``, ``C``) and the facing wear (m) if any; with an SSP parameter set
    (``plant_start``) its values and the scenario's duty (:func:`plant_start_values`)."""
    start = {"theta_a": p.theta_a, "theta_cs_start": p.theta_cs_start,
             "x_kiss_ref": p.x_kiss_ref + sc.clutch.x_kiss_offset_m, **spring,
             **({"facing_wear": sc.clutch.facing_wear_m} if sc.clutch.facing_wear_m else {})}
    return plant_start_values(plant_start, start, p.x_kiss_ref, sc) if plant_start else start


def _plant(kind: str, sc: Scenario, clutch: ClutchFmu, engine: EngineGovernor, dl: Driveline,
           p: ClutchParameters, theta_a: float, theta0: float, record_every: int, alpha_jerk: float) -> Plant:
    """The plant of the run: the thermal network (a prescribed ``profile_csv`` overrides it; disabled: the
    lumped facing), the actuator's decay per step, and the compiled or the Python engine."""
    fac, tc, h = sc.facing, sc.tcu, sc.run.step_s
    net = (ThermalNetwork(sc.plant_thermal, theta_a, theta0) if sc.plant_thermal.enabled and not fac.profile_csv
           else None)
    tcu_every = max(1, int(round(tc.period_s / h)))
    # mu at the friction surface (issue 37): with the network and a friction table the plant's torque is
    # n mu(theta_friction, |omega_slip|) R_eq F_clamp, the clutch FMU's own torque formula with mu read at the
    # network's friction-surface temperature (ThermalNetwork.theta_friction, held over the step as theta_cm is)
    # instead of at the facings' mean; the clutch FMU still gets theta_cm (the cushion spring's ODE, the stack's
    # growth, validity); the table is the FMU's own (friction.csv in its resources). Without the network or a
    # friction table: the FMU's torque (mu at theta_cm, or constant)
    return open_plant(
        kind, alpha_jerk, CREEP_NM, clutch=clutch, engine=engine, dl=dl, net=net,
        facing=FacingModel(fac.capacity_J_per_K, fac.loss_W_per_K, fac.heat_share, theta_a, h),
        facing_quiet=FacingModel(fac.capacity_J_per_K, fac.loss_W_per_K, fac.heat_share, theta_a, tcu_every * h),
        profile=facing_profile(fac.profile_csv) if fac.profile_csv else None, h=h,
        act=math.exp(-h / tc.actuator_time_constant_s) if tc.actuator_time_constant_s > 0 else 0.0,
        w_lift=sc.driver.lift_off_speed_rpm * RPM, prefill=tc.prefill_s, drive_end=tc.prefill_s + tc.drive_time_s,
        tcu_every=tcu_every, net_every=tcu_every,     # the network's time constants are seconds: 10 ms steps
        record_every=record_every, theta0=theta0, x_kiss0=p.x_kiss_ref,
        mu_surface=clutch.friction_table() if net is not None else None, n_surfaces=p.n_surfaces, r_eq=p.R_eq)


def simulate_launches(fmu: Path, sc: Scenario, table: SpringTable, tcu: str | bool = "naive",
                      record_every: int = 10, progress: Callable[[float], None] | None = None,
                      plant: str = "native", plant_start: dict | None = None) -> LaunchResult:
    """Run the scenario's launches with one TCU variant (a name of :data:`VARIANTS`).

    ``tcu`` True/False are the ``aware``/``naive`` variants. ``table`` is
    the TCU's characteristic; the plant is the FMU (with its own friction
    table, if any). ``progress(t)`` is called every 10,000 steps.
    ``plant``: ``"native"`` runs the plant steps between two TCU cycles in one compiled call
    (:mod:`.plant.plant_block`; with the plant's thermal network, else, or if it cannot be built, the Python
    loop), ``"python"`` the Python loop (the reference). Both give the same results.
    ``plant_start``: start values of the plant FMU from an SSP parameter set (:func:`plant_start_values`).
    """
    name = _variant(tcu)
    if plant not in PLANTS:
        raise ValueError(f"plant = {plant!r}: allowed {', '.join(PLANTS)}")
    if record_every < 1:
        raise ValueError(f"record_every = {record_every!r}: must be at least 1 (steps between the series' rows)")
    run, drv, h = sc.run, sc.driver, sc.run.step_s
    theta_a, theta0 = sc.facing.ambient_degC + KELVIN, sc.facing.initial_degC + KELVIN
    spring_heat = sc.spring_thermal_set()               # the cushion spring's heat path (clutch.spring_thermal)
    p = ClutchParameters(theta_a=theta_a, theta_cs_start=theta0, **spring_heat.parameters())
    engine = EngineGovernor(sc.engine, h)
    dl = Driveline(**sc.driveline_sections(), w_e=engine.w_idle)
    ctl = _tcu(name, sc, table, p, theta0, dl, engine)
    sensors = SpeedSensors(sc.sensors)
    starts, ends, levels, recs = _slots(sc)
    total = ends[-1]
    clutch_start = _clutch_start(sc, p, spring_heat.parameters(), plant_start)
    keyed = (key_on(ctl, sc, fmu, clutch_start, sc.driveline.disc_inertia_kg_m2, engine.w_idle)
             if name == "production" else None)
    clutch = ClutchFmu(fmu, clutch_start)
    pl = _plant(plant, sc, clutch, engine, dl, p, theta_a, theta0, record_every, recs[0].alpha)
    tcu_every, n_steps, r_to_disc, drive_end = pl.tcu_every, int(round(total / h)), dl.i_tot / dl.r, pl.drive_end
    ke0 = dl.kinetic()
    rows, events = [], []
    n, rec, slot_start, slot_end = 0, recs[0], starts[0], ends[0]
    pedal_level = drv.pedal(levels[0])
    engaged = braking = launching = sampling = False
    k = countdown = rec_countdown = n_quiet = 0
    believed = 0.0
    next_switch = slot_end - 0.5 * h if len(starts) > 1 else math.inf
    pl.start(rec)
    told_surface = ctl.know.told and pl.net is not None     # (its thermal protection, knowledge.Told.protect)
    wall0, cpu0 = time.perf_counter(), time.process_time()
    stopped = ""
    try:
        while k < n_steps:
            t = k * h
            if t >= next_switch:                                 # -- the next launch slot
                n += 1
                pl.new_slot(rec, recs[n])
                rec, slot_start, slot_end = recs[n], starts[n], ends[n]
                next_switch = slot_end - 0.5 * h if n + 1 < len(starts) else math.inf
                pedal_level = drv.pedal(levels[n])
            tl = t - slot_start
            cycled = countdown == 0
            if cycled:                                           # -- TCU cycle
                countdown = tcu_every
                if told_surface:                  # the ideal TCU is told the true hotter friction surface too
                    ctl.know.theta_surface = pl.theta_surface()
                ctl.read_and_cycle(sensors, t, n + 1, tl, rec.lock_time is not None, dl.w_e, dl.w_d, dl.v * r_to_disc,
                                   pl.x_act, pl.theta_cm, pl.t_e, levels[n])
                phase = ctl.phase
                engaged, launching = phase == LAUNCH or phase == CLOSE, phase == LAUNCH
                sampling = (launching or phase == PREFILL) and rec.lock_time is None
                braking = not engaged and (tl >= drive_end or ctl.inhibited)   # inhibited: the driver brakes
                if ctl.launch_level != rec.protection:
                    rec.protection = ctl.launch_level
                    if ctl.inhibited and not rec.started:          # an inhibited launch: its start state
                        rec.start(ctl.kiss_now - pl.x_kiss, pl.theta_cs, ctl.theta_now - pl.theta_cs)
            if cycled and sampling:      # the torque it believes at the first step's bearing position
                believed = ctl.model_torque(ctl.x_cmd + (pl.x_act - ctl.x_cmd) * pl.act)
            tcu_part = (ctl.x_cmd, ctl.theta_now, ctl.kiss_now, ctl.theta_cm_estimate(),
                        believed if sampling else math.nan, ctl.protection.level if ctl.protection is not None else 0.0)
            if (run.quiet_steps and cycled and braking and ctl.phase == OPEN and ctl.x_cmd == 0.0
                    and pl.at_rest_retracted() and k + tcu_every <= n_steps and (k + tcu_every - 1) * h < next_switch):
                # -- a quiet TCU period: the car stands braked, the clutch is open and retracted, only the
                # engine's idle governor and the temperatures move: one step of h_quiet for all of them
                part = pl.quiet(t)
                recorded, m = [(j, t + j * h, part) for j in range(rec_countdown, tcu_every, record_every)], tcu_every
                countdown, n_quiet = 0, n_quiet + 1
            else:                     # -- the steps to the next TCU cycle
                m, recorded = pl.block(k, n_steps, next_switch, slot_start, slot_end, countdown, rec_countdown, ctl,
                                       rec, pedal_level, engaged, braking, launching,
                                       believed if cycled and sampling else None, events, n + 1)
                countdown -= m
            for j, t_row, part in recorded:
                rows.append(row(t_row, n + 1, part, tcu_part))
                if progress is not None and (k + j) % 10000 == 0:
                    progress(t_row)
            rec_countdown = (rec_countdown - m) % record_every
            k += m
        pl.finish(rec)
    except FmuCallError as exc:
        if exc.status != DISCARD:
            raise
        # the plant FMU refused a step: the plant left the model's domain (its log names the input, e.g. a
        # facing past THETA_MAX_K). The run ends there, honestly: the launches up to it are kept and the
        # result says where and why it stopped (LaunchResult.stopped); nothing after it is invented.
        stopped = (f"launch {n + 1}, t = {t:.2f} s: the plant left the model's domain ({exc}; the FMU's log "
                   f"names the input); the run stops there")
        pl.finish(rec)
        recs = recs[:n + 1]
    finally:
        clutch.close()
    wall, cpu = time.perf_counter() - wall0, time.process_time() - cpu0
    dl.en.kinetic = dl.kinetic() - ke0
    dl.en.elastic = dl.elastic()
    learned = ctl.learned_kiss()
    ts = series(rows)
    if pl.mu_surface is not None:
        _say_beyond_friction_table(name, ts, pl.mu_surface)
    _say_tcu_beyond_model(name, ts, table)
    if keyed is not None:
        key_off(ctl, sc, keyed)
    return LaunchResult(name, ts, [r.metrics(run.hot_degC) for r in recs], dl.en, events, wall, total, cpu,
                        learned, n_quiet * pl.h_quiet, keyed, ctl.protection.events if ctl.protection is not None else [],
                        pl.kind, stopped)


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
