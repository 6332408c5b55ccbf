"""Standstill touch-point learning against the plant FMU's true kiss point, and the stored adapted state."""
import dataclasses
import json
import math

import pytest

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.errors import ParameterError
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.launch.scenario import load_scenario, scenario_path
from cushion_clutch.launch.plant.sensors import ProductionSensors
from cushion_clutch.launch.simulate import simulate_launches
from cushion_clutch.launch.tcu.store import AdaptedState, load_state, save_state
from cushion_clutch.launch.scenario.tcu_params import Standstill, TcuStore
from cushion_clutch.launch.tcu.touchpoint import learn_touch_point
from cushion_clutch.model import ClutchParameters, load_table

pytestmark = pytest.mark.fmu
TA = 293.15


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    return build_fmu(DEFAULT_TABLES, tmp_path_factory.mktemp("fmu") / "CushionClutch.fmu")


def learn(fmu, wear=0.0, **kw):
    p = ClutchParameters(theta_a=TA, theta_cs_start=TA)
    start = {"theta_a": TA, "theta_cs_start": TA, "x_kiss_ref": p.x_kiss_ref, **({"facing_wear": wear} if wear else {})}
    st = Standstill(**{k: v for k, v in kw.items() if k != "sensors"})
    return learn_touch_point(fmu, start, st, kw.get("sensors", ProductionSensors()), load_table(), p, TA, TA, 0.0,
                             0.03, 83.78, 0.01, 0.02)


@pytest.mark.parametrize("wear, drag, drag_w", [(0.0, 1.2, 0.004), (0.0, 0.5, 0.0), (0.00019, 2.5, 0.01)])
def test_standstill_learning_finds_the_plant_kiss_point(fmu, wear, drag, drag_w):
    r = learn(fmu, wear, plant_drag_Nm=drag, plant_drag_Nm_per_rad_s=drag_w)
    assert r.ok, r.reason
    assert abs(r.kiss_error_m) < 20e-6                     # the stated accuracy is 40 um
    assert abs(r.kiss_error_before_m) > 15e-6              # the +20 um position-sensor offset at least
    assert r.drag_Nm == pytest.approx(drag, abs=0.5)       # the coast-down measured the drag
    assert r.slip_energy_J < 1e3 and r.duration_s < 10.0


def test_a_wrong_disc_inertia_costs_accuracy_in_proportion(fmu):
    r = learn(fmu, disc_inertia_kg_m2=0.0315)               # the TCU's value 5 % high
    assert r.ok and 15e-6 < abs(r.kiss_error_m) < 60e-6


def test_standstill_learning_reports_a_failure(fmu):
    r = learn(fmu, start_margin_m=3e-3, ramp_rate_m_per_s=1e-4, timeout_s=1.0)   # never reaches the kiss point
    assert not r.ok and "did not reach" in r.reason and math.isnan(r.dx_kiss_m)


def test_state_round_trip_and_bad_files(tmp_path):
    s = AdaptedState(0.5e-3, 30e-6, 1.02, 1.3, 0.98, True, 3)
    assert load_state(save_state(s, tmp_path / "a.json")) == s
    bad = tmp_path / "b.json"
    bad.write_text(json.dumps({"version": 1, "dx_kiss_m": 0.1, "colour": 1}))
    with pytest.raises(ParameterError) as err:
        load_state(bad)
    assert "colour: unknown key" in str(err.value)
    bad.write_text(json.dumps({"version": 1, "dx_kiss_m": 0.1}))
    with pytest.raises(ParameterError, match="dx_kiss_m"):
        load_state(bad)
    with pytest.raises(ParameterError, match="tcu_store.file"):
        TcuStore(start="learned")


def short(sc, launches=1, **sections):
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=launches, period_s=20.0),
                             tcu=dataclasses.replace(sc.tcu, drive_time_s=6.0))
    return dataclasses.replace(sc, **sections)


def test_reset_tcu_learns_at_standstill_and_a_learned_one_starts_from_its_file(fmu, tmp_path):
    sc = load_scenario(scenario_path("wear"))
    saved = tmp_path / "learned.json"
    r = simulate_launches(fmu, short(sc, tcu_store=TcuStore(save=str(saved))), load_table(), "production")
    assert r.key_on.start == "reset" and r.key_on.standstill.ok
    assert abs(r.key_on.standstill.kiss_error_m) < 40e-6
    # the worn plant's touch point (0.5 mm late) is known before the first launch
    assert abs(r.metrics[0]["kiss_point_error_mm"]) < 0.05
    state = load_state(saved)
    assert state.touch_point_learned and state.starts_since_standstill == 0
    # a learned TCU: no standstill routine within the interval, the stored touch point applied from launch 1
    moved = AdaptedState(state.dx_kiss_m + 0.2e-3, 30e-6, 1.0, state.loss_scale, state.heat_scale, True, 1)
    save_state(moved, tmp_path / "moved.json")
    r2 = simulate_launches(fmu, short(sc, tcu_store=TcuStore(start="learned", file=str(tmp_path / "moved.json"))),
                           load_table(), "production")
    assert r2.key_on.start == "learned: moved.json" and r2.key_on.standstill is None
    assert r2.metrics[0]["kiss_point_error_mm"] == pytest.approx(0.2, abs=0.05)


@pytest.mark.parametrize("key", ["dx_kiss_m", "mu_scale", "loss_scale", "heat_scale", "dx_kiss_sd_m",
                                 "starts_since_standstill"])
def test_stored_state_refuses_a_boolean(tmp_path, key):
    """Issue 43: a JSON true/false is no number in the stored TCU state (mu_scale = true was taken for 1)."""
    data = {"version": 1, "dx_kiss_m": 0.5e-3, "dx_kiss_sd_m": 30e-6, "mu_scale": 1.0, "loss_scale": 1.0,
            "heat_scale": 1.0, "touch_point_learned": True, "starts_since_standstill": 1, key: True}
    bad = tmp_path / "b.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(ParameterError) as err:
        load_state(bad)
    assert [p for p in err.value.problems if p.startswith(f"{key} = True")] == err.value.problems, err.value.problems
