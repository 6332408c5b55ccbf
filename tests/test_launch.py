"""Launch co-simulation: driveline + TCU around the clutch FMU (energy, lock-up, determinism)."""
import dataclasses

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import load_table
from cushion_clutch.launch.scenario import DEFAULT_SCENARIO, load_scenario
from cushion_clutch.launch.simulate import simulate_launches

pytestmark = pytest.mark.fmu


def short(sc, launches=3, **facing):
    """A few launches 20 s apart, optionally from a thermally soaked (hot) start."""
    return dataclasses.replace(
        sc, run=dataclasses.replace(sc.run, launches=launches, period_s=20.0),
        tcu=dataclasses.replace(sc.tcu, drive_time_s=6.0),
        facing=dataclasses.replace(sc.facing, **facing))


def same(a, b):
    """Structured arrays equal field by field (NaN equal to NaN: columns a variant does not have)."""
    return a.dtype == b.dtype and all(np.array_equal(a[f], b[f], equal_nan=True) for f in a.dtype.names)


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    return build_fmu(DEFAULT_TABLES, tmp_path_factory.mktemp("fmu") / "CushionClutch.fmu")


@pytest.fixture(scope="module")
def hot_runs(fmu):
    sc = short(load_scenario(), initial_degC=250.0)
    table = load_table()
    return {aware: simulate_launches(fmu, sc, table, aware) for aware in (False, True)}


def test_energy_balance(hot_runs):
    for res in hot_runs.values():
        e = res.energy
        assert e.engine_work > 1e5
        assert abs(e.residual()) < 0.01 * e.engine_work
        # and every term is there: the car climbed, slipped, rolled and braked
        assert e.potential > 0 and e.slip > 1e4 and e.resistance > 0 and e.brake > 0
        assert abs(e.kinetic) < 1.0                  # at rest again at the end


def test_lock_up_reached_and_held_without_chatter(hot_runs):
    for res in hot_runs.values():
        for m in res.metrics:
            assert 0.5 < m["engagement_time_s"] < 5.0
            assert not m["engine_stall"]
            assert 0.0 < m["lockup_jerk_m_s3"] <= m["peak_jerk_m_s3"]
        per_launch = {}
        for launch, kind, _ in res.lock_events:
            per_launch.setdefault(launch, []).append(kind)
        assert per_launch == {1: ["lock", "unlock"], 2: ["lock", "unlock"], 3: ["lock", "unlock"]}
        locked = res.series["locked"]
        assert np.count_nonzero(np.diff(locked) != 0) == 6   # one lock and one open per launch


def test_temperature_aware_tcu_tracks_torque_better_when_hot(hot_runs):
    naive, aware = hot_runs[False].metrics, hot_runs[True].metrics
    for n, a in zip(naive, aware):
        assert n["theta_cs_start_degC"] > 150.0
        assert a["torque_error_rms_Nm"] < n["torque_error_rms_Nm"]
        assert abs(a["kiss_point_error_mm"]) < 0.01 < abs(n["kiss_point_error_mm"])


def test_same_inputs_same_results(fmu, hot_runs):
    sc = short(load_scenario(), initial_degC=250.0)
    again = simulate_launches(fmu, sc, load_table(), True)
    assert same(again.series, hot_runs[True].series)
    assert again.metrics == hot_runs[True].metrics


def test_noisy_sensors_deterministic_with_a_seed(fmu):
    sc = short(load_scenario(), launches=2)
    noisy = dataclasses.replace(sc, sensors=dataclasses.replace(sc.sensors, speed_noise_rad_s=0.5, seed=7))
    a = simulate_launches(fmu, noisy, load_table(), "adaptive_aware_estimated")
    b = simulate_launches(fmu, noisy, load_table(), "adaptive_aware_estimated")
    assert same(a.series, b.series) and a.metrics == b.metrics
    other = dataclasses.replace(noisy, sensors=dataclasses.replace(noisy.sensors, seed=8))
    c = simulate_launches(fmu, other, load_table(), "adaptive_aware_estimated")
    assert not np.array_equal(a.series["theta_cm_tcu_K"], c.series["theta_cm_tcu_K"])


def test_scenario_file_errors_name_the_key(tmp_path):
    bad = tmp_path / "s.toml"
    bad.write_text(DEFAULT_SCENARIO.read_text().replace("mass_kg = 1900.0", "mass_kg = -5.0\nmass_lb = 1")
                   .replace("gain = 0.7", "gain = 1.5").replace('friction_csv = ""', 'friction_csv = "nope.csv"'))
    with pytest.raises(ParameterError) as info:
        load_scenario(bad)
    msg = str(info.value)
    assert "vehicle.mass_lb: unknown key" in msg and "vehicle.mass_kg = -5.0" in msg and "adaptation.gain = 1.5" in msg
    bad.write_text(DEFAULT_SCENARIO.read_text().replace('friction_csv = ""', 'friction_csv = "nope.csv"'))
    with pytest.raises(ParameterError, match="clutch.friction_csv = 'nope.csv'"):
        load_scenario(bad)


def test_cool_down_schedule():
    from cushion_clutch.launch.scenario import scenario_path

    sc = load_scenario(scenario_path("cooldown"))
    starts = sc.run.starts()
    assert len(starts) == sc.run.launches + sc.run.cool_launches and sc.run.cool_launches > 0
    assert np.allclose(np.diff(starts[:sc.run.launches]), sc.run.period_s)
    assert np.allclose(np.diff(starts[sc.run.launches - 1:]), sc.run.cool_period_s)
    assert sc.run.duration() == pytest.approx(starts[-1] + sc.run.cool_period_s)
