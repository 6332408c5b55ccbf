"""Thermal protection: its levels on the facing-temperature estimate, and on a heavy-duty launch run."""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.launch.fleet.duty import peak_degC
from cushion_clutch.launch.tcu.protection import INHIBIT, LIMIT, OK, WARN, Protection, ThermalProtection
from cushion_clutch.model import KELVIN


def k(deg):
    return deg + KELVIN


def test_levels_rise_with_the_estimate_and_fall_with_hysteresis():
    p = ThermalProtection(Protection())
    assert p.update(k(200.0), 0.0, 1) == OK
    assert p.update(k(255.0), 0.1, 1) == WARN
    assert p.update(k(285.0), 0.2, 1) == LIMIT
    assert p.update(k(275.0), 0.3, 1) == LIMIT          # within the 10 K hysteresis
    assert p.update(k(265.0), 0.4, 1) == WARN
    assert p.update(k(239.0), 0.5, 1) == OK
    assert [e[2] for e in p.events] == [WARN, LIMIT, WARN, OK]
    assert "hot" in p.events[0][3]                       # the driver is told


def test_a_launch_is_inhibited_until_the_clutch_has_cooled():
    p = ThermalProtection(Protection())
    assert not p.launch_start(k(300.0), 0.0, 1)
    p.launch_end(k(330.0))                               # this launch raised the estimate by 30 K
    assert p.launch_start(k(312.0), 0.0, 2)              # above inhibit_degC
    assert p.level == INHIBIT
    assert p.update(k(200.0), 1.0, 2) == INHIBIT         # holds for the whole launch slot
    assert p.launch_start(k(260.0), 0.0, 3)              # not yet below resume_degC
    assert not p.launch_start(k(245.0), 0.0, 4) and p.level in (OK, WARN)


def test_the_next_launch_rise_counts():
    p = ThermalProtection(Protection())
    p.launch_start(k(200.0), 0.0, 1)
    p.launch_end(k(260.0))                               # +60 K in one launch
    assert p.launch_start(k(295.0), 0.0, 2)              # 295 + 60 reaches the 350 degC damage limit


def test_the_rise_is_taken_to_the_slot_peak_and_the_estimate_error_allowed():
    """The next launch's check takes the last launch's rise to the highest estimate in its slot (the facings and
    the friction surface peak after the slip's end, or at it), and allows ``estimate_error_K`` for the estimate's
    error: 260 + 70 reaches 350 - 25 (the rise to the launch's end, 50 K, would not)."""
    p = ThermalProtection(Protection())
    assert not p.launch_start(k(200.0), 0.0, 1)
    p.update(k(270.0), 5.0, 1)                           # the slot's peak
    p.launch_end(k(250.0))                               # the slip ended before it
    assert p.launch_start(k(260.0), 60.0, 2) and p.rise == pytest.approx(70.0)
    q = ThermalProtection(Protection(estimate_error_K=0.0))
    q.launch_start(k(200.0), 0.0, 1)
    q.update(k(270.0), 5.0, 1)
    assert not q.launch_start(k(260.0), 60.0, 2)         # 330 < 350 without the allowance
    with pytest.raises(ParameterError, match="estimate_error_K"):
        Protection(estimate_error_K=-1.0)


def test_thresholds_are_checked():
    with pytest.raises(ParameterError) as err:
        Protection(warn_degC=300.0, limit_degC=280.0)
    assert "warn_degC <= limit_degC" in str(err.value)
    with pytest.raises(ParameterError, match="resume_degC"):
        Protection(resume_degC=320.0)


@pytest.mark.fmu
def test_protected_tcus_keep_their_estimate_below_the_damage_limit(tmp_path):
    """The protection scenario with every threshold lowered (a short run reaches them; the estimate's allowance
    too, or the rise check would inhibit before any launch is limited)."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.model import load_table

    fmu = build_fmu(DEFAULT_TABLES, tmp_path / "CushionClutch.fmu")
    sc = load_scenario(scenario_path("protection"))
    sc = dataclasses.replace(
        sc, run=dataclasses.replace(sc.run, launches=7),
        protection=Protection(enabled=True, warn_degC=60.0, limit_degC=80.0, inhibit_degC=100.0, resume_degC=60.0,
                              damage_degC=130.0, estimate_error_K=5.0))
    naive = simulate_launches(fmu, sc, load_table(), "naive")
    assert naive.series["theta_cm_K"].max() - KELVIN > 130.0          # unprotected: past the (lowered) limit
    for name in ("production", "aware"):
        r = simulate_launches(fmu, sc, load_table(), name)
        est = r.series["theta_cm_tcu_K"] if name == "production" else r.series["theta_cm_K"]
        assert np.nanmax(est) - KELVIN < 130.0
        levels = [m["protection_level"] for m in r.metrics]
        assert max(levels) == INHIBIT and levels[0] == OK
        limited = [m["slip_energy_kJ"] for m in r.metrics if m["protection_level"] == LIMIT]
        assert limited
        if name == "aware":         # it knows mass and grade: a lower engine speed that still locks up in time
            assert max(limited) < 0.8 * r.metrics[0]["slip_energy_kJ"]
        # production's mass and grade estimate leaves no lower speed that surely locks up: the pedal's target
        # (a limit that strands the launch is no protection)
        for m in r.metrics:         # every launch it does not inhibit locks up
            assert m["protection_level"] == INHIBIT or math.isfinite(m["engagement_time_s"]), m
            assert not m["stranded"] and m["launch_possible"]
        assert np.nanmax(r.series["protection_level"]) == INHIBIT


@pytest.mark.fmu
def test_every_production_launch_of_the_protection_scenario_locks_up_or_is_inhibited(tmp_path):
    """Issue 38's bar: in the shipped `protection` scenario (30 hill starts, 3500 kg, 12 %) every production
    launch not inhibited at its start locks up; none is stranded; every launch is physically possible."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.model import load_table

    fmu = build_fmu(DEFAULT_TABLES, tmp_path / "CushionClutch.fmu")
    sc = load_scenario(scenario_path("protection"))
    r = simulate_launches(fmu, sc, load_table(), "production", record_every=100)
    assert len(r.metrics) == 30
    levels = [m["protection_level"] for m in r.metrics]
    assert max(levels) == INHIBIT and levels.count(INHIBIT) < 30
    for m in r.metrics:
        assert m["launch_possible"] and not m["stranded"], m
        assert m["protection_level"] == INHIBIT or math.isfinite(m["engagement_time_s"]), m
        assert m["protection_level"] < INHIBIT or math.isnan(m["engagement_time_s"]), m
    # the true facings and friction surfaces stay below the damage limit (with the protection on the facings'
    # estimate alone the surface reached 372 degC in launch 17)
    assert peak_degC(r.series) < sc.protection.damage_degC


@pytest.mark.fmu
@pytest.mark.parametrize("name", ["aware", "aware_estimated", "production"])
def test_protection_on_the_fade_duty_keeps_the_friction_surface_below_damage_and_strands_nothing(tmp_path, name):
    """``fade``'s duty with the protection on (``protection``'s thresholds): mu fades with the friction surface, so a
    protection that watches the facings alone let a launch start on a faded surface that could not hold the
    engine (aware and aware_estimated: stranded, 410-430 kJ of slip, the facings past 380 degC). On the friction
    system's temperature (the hotter of facings and surface), every launch that is not inhibited locks up, the
    true facings and surfaces stay below the damage limit and the run does not stop."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.model import load_table

    sc = load_scenario(scenario_path("fade"))
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, period_s=60.0),
                             protection=load_scenario(scenario_path("protection")).protection)
    fmu = build_plant_fmu(Path(DEFAULT_TABLES), sc, tmp_path / "CushionClutch.fmu")
    r = simulate_launches(fmu, sc, load_table(), name, record_every=20)
    assert not r.stopped and len(r.metrics) == sc.run.launches
    for m in r.metrics:
        assert not m["stranded"] and m["launch_possible"], m
        assert m["protection_level"] == INHIBIT or math.isfinite(m["engagement_time_s"]), m
    assert max(m["protection_level"] for m in r.metrics) >= LIMIT
    assert peak_degC(r.series) < sc.protection.damage_degC


def test_launch_capability_is_the_engine_at_the_pedal_against_the_holding_torque():
    """Closed forms: the holding torque m g (sin a + c_r cos a) r / (eta i) and the engine's best net torque
    at the pedal over its curve's nodes; a launch on a grade the engine cannot hold is not possible."""
    from cushion_clutch.launch.results.metrics import launch_capability, launch_possible
    from cushion_clutch.launch.scenario import load_scenario, scenario_path

    sc = load_scenario(scenario_path("protection"))
    v, d, e = sc.vehicle, sc.driveline, sc.engine
    a = math.atan(v.slope_percent / 100.0)
    hold = v.mass_kg * 9.81 * (math.sin(a) + v.rolling_resistance * math.cos(a)) * d.wheel_radius_m / (
        d.efficiency * d.gear_ratio * d.final_drive_ratio)
    pedal = sc.driver.hard_pedal
    best = max(pedal * t - e.drag_Nm_per_rad_s * w * math.pi / 30.0
               for w, t in zip(e.torque_curve_rpm, e.torque_curve_Nm) if e.idle_speed_rpm <= w <= e.max_speed_rpm)
    engine, load = launch_capability(sc, "hard")
    assert load == pytest.approx(hold, rel=1e-9) and engine == pytest.approx(best, rel=1e-9)
    assert launch_possible(sc, "hard")
    steep = dataclasses.replace(sc, vehicle=dataclasses.replace(v, slope_percent=30.0),
                                driver=dataclasses.replace(sc.driver, hard_pedal=0.3))
    assert not launch_possible(steep, "hard")
    creep_engine, _ = launch_capability(sc, "creep")       # the idle governor at full throttle, idle speed
    assert creep_engine == pytest.approx(e.torque_curve_Nm[0] - e.drag_Nm_per_rad_s * e.idle_speed_rpm * math.pi / 30)


def test_the_launch_target_locks_up_in_time():
    """A limited launch aims at the lowest speed from the limit up that locks up by the deadline (the TCU's
    beliefs), a light one at the limit itself; a launch whose pedal speed cannot lock up in time (a steep grade,
    a light pedal) aims at the lowest faster speed that can."""
    from cushion_clutch.launch.plant.driveline import Driveline
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.tcu.controller import VARIANTS, TcuController, _full_load_Nm
    from cushion_clutch.model import ClutchParameters, load_table

    sc = load_scenario(scenario_path("protection"))
    tc, rpm = sc.tcu, math.pi / 30.0
    budget = tc.lockup_deadline_s + tc.forced_sync_s

    def tcu(scen, scale=1.0):
        dl = Driveline(**scen.driveline_sections(), w_e=83.78)
        return TcuController(VARIANTS["aware"], load_table(), ClutchParameters(), 293.15, dl.j_d * scale,
                             dl.t_load_rest * scale, **scen.tcu_sections())

    def lock_time(ctl, scen, w):
        p = scen.driver.hard_pedal
        s = p * _full_load_Nm(scen.engine, w) - scen.engine.drag_Nm_per_rad_s * w - ctl.t_load
        return w * ctl.j_d / s if s > 0 else math.inf

    ctl = tcu(sc)
    pedal_w = ctl.w_idle + sc.driver.hard_pedal * (tc.engine_speed_full_pedal_rpm * rpm - ctl.w_idle)
    assert ctl.launch_target_rad_s("hard") == pedal_w                  # unlimited: the pedal's own
    ctl.limited = True
    w = ctl.launch_target_rad_s("hard")
    limit_w = ctl.w_idle + sc.driver.hard_pedal * (sc.protection.limit_engine_speed_rpm * rpm - ctl.w_idle)
    assert limit_w < w < pedal_w
    assert lock_time(ctl, sc, w) <= budget < lock_time(ctl, sc, w - 50.0 * rpm * sc.driver.hard_pedal)
    light = tcu(sc, 1.0 / 3.0)
    light.limited = True
    assert light.launch_target_rad_s("hard") == pytest.approx(limit_w, rel=1e-12)
    # 1536 kg on 16 % at pedal 0.35: the pedal's 1290 rpm barely holds the car (a fleet sample production
    # stranded): a faster target that locks up in time
    steep = dataclasses.replace(sc, vehicle=dataclasses.replace(sc.vehicle, mass_kg=1536.0, slope_percent=16.0,
                                                                drag_area_m2=0.7),
                                driver=dataclasses.replace(sc.driver, hard_pedal=0.35))
    ctl = tcu(steep)
    slow = ctl.w_idle + 0.35 * (tc.engine_speed_full_pedal_rpm * rpm - ctl.w_idle)
    assert lock_time(ctl, steep, slow) > budget
    w = ctl.launch_target_rad_s("hard")
    faster = [slow + k * 50.0 * rpm for k in range(1, 200) if slow + k * 50.0 * rpm <= 6000.0 * rpm]
    assert w > slow and lock_time(ctl, steep, w) == min(lock_time(ctl, steep, v) for v in faster)
    assert lock_time(ctl, steep, w) < lock_time(ctl, steep, slow) / 3
    assert not ctl.holds("hard", slow) and ctl.holds("hard", w)
