"""The production TCU in the launch co-simulation: its own sensors, EKF, learned touch point, plant network."""
import dataclasses

import numpy as np
import pytest

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.launch.scenario import load_scenario, scenario_path
from cushion_clutch.launch.simulate import simulate_launches
from cushion_clutch.model import load_table

from test_launch import short

pytestmark = pytest.mark.fmu


@pytest.fixture(scope="module")
def plant(tmp_path_factory):
    """The default-table FMU with the plant's kiss point 0.5 mm late (x_kiss_offset_m is an FMU parameter)."""
    return build_fmu(DEFAULT_TABLES, tmp_path_factory.mktemp("fmu") / "CushionClutch.fmu")


def test_production_learns_a_late_kiss_point_and_tracks_the_temperature(plant):
    sc = short(load_scenario(scenario_path("wear")), launches=4)
    sc = dataclasses.replace(sc, standstill=dataclasses.replace(sc.standstill, learn="never"))   # launches only
    r = simulate_launches(plant, sc, load_table(), "production")
    kiss = [m["kiss_point_error_mm"] for m in r.metrics]
    ch = [m["characteristic_error_max_Nm"] for m in r.metrics]
    assert kiss[0] == pytest.approx(-0.5, abs=0.05)          # believes nominal at first: 0.5 mm early
    # learned from the engine-side torque: more than half of the 0.5 mm in four launches (0.205 mm left on the
    # -40..350 degC tables, whose 0.02 mm clearance softens the curve near the kiss point; 0.2 was the bound before)
    assert abs(kiss[-1]) < 0.5 * abs(kiss[0])
    assert ch[-1] < 0.5 * ch[0]
    err = r.series["theta_cs_tcu_K"] - r.series["theta_cs_K"]
    assert np.nanmax(np.abs(err)) < 15.0                     # EKF on its own (mismatched) network
    # ... and the clutch did heat up (the default duty on the physical network: about 11 K in four short launches)
    assert r.series["theta_cs_K"].max() - r.series["theta_cs_K"][0] > 8.0


def test_a_reset_production_tcu_knows_the_worn_touch_point_before_its_first_launch(plant):
    sc = short(load_scenario(scenario_path("wear")), launches=2)
    r = simulate_launches(plant, sc, load_table(), "production")
    assert r.key_on.start == "reset" and r.key_on.standstill.ok
    assert all(abs(m["kiss_point_error_mm"]) < 0.06 for m in r.metrics)
    assert all(m["characteristic_error_max_Nm"] < 3.0 for m in r.metrics)


def test_production_with_the_plant_network_runs_and_stays_deterministic(plant):
    sc = short(load_scenario(), launches=2)
    sc = dataclasses.replace(sc, plant_thermal=dataclasses.replace(sc.plant_thermal, enabled=True))
    a = simulate_launches(plant, sc, load_table(), "production")
    b = simulate_launches(plant, sc, load_table(), "production")
    assert np.array_equal(a.series["theta_cs_tcu_K"], b.series["theta_cs_tcu_K"])
    rise = a.series["theta_cm_K"].max() - a.series["theta_cm_K"][0]
    assert 0.5 < rise < 20.0          # most slip heat goes into flywheel and pressure plate (effusivity split)


@pytest.mark.parametrize("sections", [
    {},                                                                        # default, 20 degC
    {"vehicle": {"mass_kg": 1200.0, "slope_percent": 0.0},                     # light car, flat, -10 degC
     "facing": {"ambient_degC": -10.0, "initial_degC": -10.0}}])
@pytest.mark.parametrize("learn", ["never", "missing"])
def test_on_a_nominal_clutch_production_is_never_worse_than_naive(plant, sections, learn):
    """The ECU's torque bias (+4 %, +3 N.m) and the position offset (+20 um) are no evidence of a change."""
    sc = short(load_scenario(), launches=1)
    for sec, vals in sections.items():
        sc = dataclasses.replace(sc, **{sec: dataclasses.replace(getattr(sc, sec), **vals)})
    sc = dataclasses.replace(sc, standstill=dataclasses.replace(sc.standstill, learn=learn))
    naive = simulate_launches(plant, sc, load_table(), "naive").metrics[0]["characteristic_error_max_Nm"]
    prod = simulate_launches(plant, sc, load_table(), "production")
    # with standstill learning (every shipped scenario) the position sensor's offset is learned with the touch
    # point; without it (learn = never) nothing can reveal it, and the characteristic read at the offset
    # position differs by up to the torque's slope times the offset (the sensors' stated +20 um): allowed on top
    allowed = naive + 0.5 + (0.0 if learn == "missing" else _offset_torque_Nm(sc.tcu_sensors.position_offset_m))
    assert prod.metrics[0]["characteristic_error_max_Nm"] <= allowed


def _offset_torque_Nm(offset_m: float) -> float:
    """The largest torque change over ``offset_m`` of bearing travel below 200 N.m (20 degC, nominal clutch)."""
    from cushion_clutch.model import ClutchParameters, outputs
    table, p = load_table(), ClutchParameters()
    x = np.arange(0.0, 0.015, 5e-6)
    t = np.array([outputs(float(v), 293.15, table, p).torque for v in x])
    x, t = x[t <= 200.0], t[t <= 200.0]
    return float(np.max(np.interp(x + offset_m, x, t) - t))


def test_the_temperature_estimate_holds_on_heavy_duty(plant):
    """3500 kg hill starts on the plant network (the protection duty, unprotected) until the plant's facings pass
    the damage limit (350 degC, at start 23): the issue's target is 25 K up to it, 15 K in the shipped scenarios.
    Before the ECU-offset state and the RLS readiness fix the theta_cs estimate was 33-64 K high after twelve
    starts; with the heat scale on the slip heat only it was 13.1 K off up to the damage limit, with it the
    network's inverse heat capacity 9.1 K (main f0e6b1a / branch thermest, 2026-11-26); with the slip heat over the
    torque signal's referenced gain 6.4 K (branch coolest, 2026-11-26)."""
    sc = load_scenario(scenario_path("protection"))
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=23),
                             protection=dataclasses.replace(sc.protection, enabled=False))
    r = simulate_launches(plant, sc, load_table(), "production")
    start = r.series["launch"] == 23
    assert r.series["theta_cm_K"][start].max() > 623.15                  # the facings reach the damage limit
    assert max(abs(m["theta_cs_error_K"]) for m in r.metrics) < 15.0


def test_the_slip_heat_the_tcu_books_is_the_clutchs_not_the_torque_signals_gain(plant, monkeypatch):
    """The EKF's network is heated by the engine-side clutch torque over the torque signal's gain as referenced on
    cool facings: the ECU's +4 % gain is not heat (``k_heat``, the network's inverse heat capacity, would learn it on
    the heat-up and then cool every cool-down too slowly). What remains is the ECU's +3 N.m offset, about 1-2 % of
    the trailer's launch torque. Measured (2026-11-26): booked / plant slip energy 1.013 (1.053 with the raw torque)."""
    from cushion_clutch.launch.tcu.ekf import ClutchEkf

    booked = []
    accumulate = ClutchEkf.accumulate

    def spy(self, dt, p_slip_W):
        booked.append(p_slip_W * dt)
        accumulate(self, dt, p_slip_W)

    monkeypatch.setattr(ClutchEkf, "accumulate", spy)
    sc = short(load_scenario(scenario_path("trailer")), launches=2)
    r = simulate_launches(plant, sc, load_table(), "production")
    ratio = sum(booked) / r.energy.slip
    assert r.energy.slip > 1e5                       # two hill starts with a caravan: over 100 kJ each
    assert 1.0 < ratio < 1.03, ratio
