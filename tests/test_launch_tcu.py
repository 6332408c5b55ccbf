"""The TCU variants: facing-temperature observer, kiss-point adaptation, FMU client errors."""
import dataclasses
import math

import numpy as np
import pytest

from cushion_clutch.errors import FmuCallError
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import load_table
from cushion_clutch.launch.plant.fmu_client import ClutchFmu
from cushion_clutch.launch.scenario import load_scenario, scenario_path
from cushion_clutch.model.thermal_network import NetworkParams
from cushion_clutch.launch.scenario.tcu_params import Observer
from cushion_clutch.launch.simulate import simulate_launches

from test_launch import short

pytestmark = pytest.mark.fmu


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    return build_fmu(DEFAULT_TABLES, tmp_path_factory.mktemp("fmu") / "CushionClutch.fmu")


def quiet(sc):
    return dataclasses.replace(sc, sensors=dataclasses.replace(sc.sensors, speed_noise_rad_s=0.0,
                                                               speed_resolution_rad_s=0.0))


def matched(sc):
    """The observer's network and cushion-spring heat path with the plant's parameters."""
    p, spring = sc.plant_thermal, sc.spring_thermal_set()
    return dataclasses.replace(sc, observer=Observer(**{f.name: getattr(p, f.name)
                                                        for f in dataclasses.fields(NetworkParams)},
                                                     spring_U_W_per_K=spring.U_W_per_K,
                                                     spring_H_W_per_K=spring.H_W_per_K,
                                                     spring_C_J_per_K=spring.C_J_per_K))


def test_observer_with_matched_parameters_reproduces_theta_cm(fmu):
    sc = quiet(matched(short(load_scenario(scenario_path("trailer")), launches=3)))
    s = simulate_launches(fmu, sc, load_table(), "aware_estimated").series
    rise = s["theta_cm_K"].max() - s["theta_cm_K"][0]
    assert rise > 30.0                                    # it did heat up
    assert np.max(np.abs(s["theta_cm_tcu_K"] - s["theta_cm_K"])) < 0.5
    assert np.max(np.abs(s["theta_cs_tcu_K"] - s["theta_cs_K"])) < 0.5


def test_observer_with_mismatch_stays_bounded_and_is_reported(fmu):
    sc = short(load_scenario(), launches=4)               # shipped mismatch (C +15 %, G -20 %) and noise
    assert sc.observer.flywheel_capacity_J_per_K != sc.plant_thermal.flywheel_capacity_J_per_K
    res = simulate_launches(fmu, sc, load_table(), "aware_estimated")
    s = res.series
    err = np.abs(s["theta_cm_tcu_K"] - s["theta_cm_K"])
    rise = s["theta_cm_K"].max() - s["theta_cm_K"][0]
    assert 0.5 < err.max() < 0.2 * rise
    reported = [m["theta_cs_error_K"] for m in res.metrics]
    assert all(math.isfinite(e) for e in reported) and max(map(abs, reported[1:])) > 0.1
    naive = simulate_launches(fmu, sc, load_table(), "naive").metrics
    assert max(abs(m["theta_cs_error_K"]) for m in res.metrics) < max(abs(m["theta_cs_error_K"]) for m in naive)


def test_adaptation_converges_to_the_true_kiss_point_at_constant_temperature(fmu, tmp_path):
    profile = tmp_path / "theta.csv"
    profile.write_text("time_s,theta_cm_K\n0,293.15\n1e6,293.15\n")
    sc = short(load_scenario(), launches=5, profile_csv=str(profile))
    sc = dataclasses.replace(sc, clutch=dataclasses.replace(sc.clutch, x_kiss_offset_m=0.2e-3))
    adaptive = simulate_launches(fmu, sc, load_table(), "adaptive").metrics
    naive = simulate_launches(fmu, sc, load_table(), "naive").metrics
    assert abs(adaptive[0]["kiss_point_error_mm"] + 0.2) < 1e-6        # first launch: nothing learned yet
    assert abs(adaptive[-1]["kiss_point_error_mm"]) < 0.02
    assert abs(naive[-1]["kiss_point_error_mm"] + 0.2) < 1e-6
    assert adaptive[-1]["characteristic_error_rms_Nm"] < naive[-1]["characteristic_error_rms_Nm"]


def test_compensated_adaptation_follows_the_temperature_between_adaptations(fmu):
    sc = short(load_scenario(scenario_path("trailer")), launches=4)
    comp = simulate_launches(fmu, sc, load_table(), "adaptive_aware_estimated")
    plain = simulate_launches(fmu, sc, load_table(), "adaptive")
    worst = lambda res: max(abs(m["kiss_point_error_mm"]) for m in res.metrics)
    assert worst(comp) < worst(plain)
    # the uncompensated kiss point is constant between adaptations, the compensated one moves with theta_cs
    s_plain, s_comp = plain.series, comp.series
    cool = (s_plain["launch"] == 2) & (s_plain["time_s"] % 20.0 > 10.0) & (s_plain["time_s"] % 20.0 < 19.0)
    assert np.ptp(s_plain["x_kiss_tcu_m"][cool]) == 0.0 and np.ptp(s_comp["x_kiss_tcu_m"][cool]) > 1e-6


def test_fmu_client_raises_a_typed_error_naming_the_function(fmu):
    c = ClutchFmu(fmu, {"theta_a": 293.15})
    try:
        t, theta_cs, x_kiss = c.step(0.0, 1e-3, 0.005, 300.0, 0.0)
        assert t > 0.0 and theta_cs > 293.15 and x_kiss > 0.0
        with pytest.raises(FmuCallError) as info:
            c.step(1e-3, 1e-3, float("nan"), 300.0, 0.0)
        assert info.value.function in ("fmi2SetReal", "fmi2DoStep") and info.value.status >= 2
        assert info.value.function in str(info.value)
    finally:
        c.close()
