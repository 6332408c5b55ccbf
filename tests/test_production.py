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
    r = simulate_launches(plant, sc, load_table(), "production")
    kiss = [m["kiss_point_error_mm"] for m in r.metrics]
    ch = [m["characteristic_error_max_Nm"] for m in r.metrics]
    assert kiss[0] == pytest.approx(-0.5, abs=0.05)          # believes nominal at first: 0.5 mm early
    assert abs(kiss[-1]) < 0.2                               # learned from the engine-side torque
    assert ch[-1] < 0.5 * ch[0]
    err = r.series["theta_cs_tcu_K"] - r.series["theta_cs_K"]
    assert np.nanmax(np.abs(err)) < 15.0                     # EKF on its own (mismatched) network
    # ... and the clutch did heat up (the default duty on the physical network: about 11 K in four short launches)
    assert r.series["theta_cs_K"].max() - r.series["theta_cs_K"][0] > 8.0


def test_production_with_the_plant_network_runs_and_stays_deterministic(plant):
    sc = short(load_scenario(), launches=2)
    sc = dataclasses.replace(sc, plant_thermal=dataclasses.replace(sc.plant_thermal, enabled=True))
    a = simulate_launches(plant, sc, load_table(), "production")
    b = simulate_launches(plant, sc, load_table(), "production")
    assert np.array_equal(a.series["theta_cs_tcu_K"], b.series["theta_cs_tcu_K"])
    rise = a.series["theta_cm_K"].max() - a.series["theta_cm_K"][0]
    assert 0.5 < rise < 20.0          # most slip heat goes into flywheel and pressure plate (effusivity split)
