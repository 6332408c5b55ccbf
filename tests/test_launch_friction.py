"""The plant's friction table in the launches: constant mu unchanged, fade by the table's ratio."""
import dataclasses

import numpy as np
import pytest

from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import KELVIN, ClutchParameters, load_table, outputs
from cushion_clutch.model.friction import FrictionTable
from cushion_clutch.launch.plant.fmu_client import ClutchFmu
from cushion_clutch.launch.plant.build import build_plant_fmu
from cushion_clutch.launch.scenario import load_scenario, scenario_path
from cushion_clutch.launch.simulate import simulate_launches

from test_launch import short

pytestmark = pytest.mark.fmu


def test_constant_mu_table_gives_todays_results(tmp_path):
    flat = tmp_path / "flat.csv"
    flat.write_text("theta_degC,omega_slip_rad_s,mu\n0,0,0.28\n400,0,0.28\n0,500,0.28\n400,500,0.28\n")
    sc = short(load_scenario(), launches=2)
    with_table = dataclasses.replace(sc, clutch=dataclasses.replace(sc.clutch, friction_csv=str(flat)))
    plain_fmu = build_fmu(DEFAULT_TABLES, tmp_path / "a" / "plain.fmu")
    flat_fmu = build_plant_fmu(DEFAULT_TABLES, with_table, tmp_path / "b" / "flat.fmu")
    a = simulate_launches(plain_fmu, sc, load_table(), "aware_estimated")
    b = simulate_launches(flat_fmu, with_table, load_table(), "aware_estimated")
    # equal to round-off: the bilinear weights make mu = 0.28 within one ulp, not bit for bit, and the
    # driveline carries that ulp on through 40 s of lock-ups (measured: 4e-12 N.m in the locked torque);
    # a friction table applied wrongly moves these columns by newton-metres
    for f in a.series.dtype.names:
        # accel_m_s2 is a finite difference (v_next - v) / h over the step h (not the rows' spacing): one ulp
        # of v becomes eps |v| / h there
        # the others: round-off amplified by the closed loop, relative to the column's scale (measured on the
        # physical network with issue 28's cover: 2.7e-8 N.m on a 311 N.m capacity column, 1e-10 of its scale)
        scale = np.nanmax(np.abs(a.series[f])) if a.series[f].dtype.kind == "f" and a.series[f].size else 0.0
        atol = max(1e-9, 1e-9 * scale) if f != "accel_m_s2" else max(
            1e-9, 64 * np.finfo(float).eps * np.abs(a.series["v_m_s"]).max() / sc.run.step_s)
        np.testing.assert_allclose(b.series[f], a.series[f], rtol=1e-9, atol=atol, equal_nan=True)
    assert len(a.metrics) == len(b.metrics) > 0
    for ma, mb in zip(a.metrics, b.metrics):
        assert mb.keys() == ma.keys()
        for key, va in ma.items():          # numbers to round-off; strings and flags exactly
            if isinstance(va, float):
                # peak_jerk_m_s3 is a second difference over the 1 ms step: the series' 1e-10 becomes 1.4e-9
                rel = 1e-8 if key.startswith("peak_jerk") else 1e-9
                assert mb[key] == pytest.approx(va, rel=rel, abs=1e-9, nan_ok=True), key
            else:
                assert mb[key] == va, key


def test_fade_table_lowers_the_torque_by_its_ratio(tmp_path):
    sc = load_scenario(scenario_path("fade"))
    table = FrictionTable.from_csv(sc.friction_path())
    fmu = build_plant_fmu(DEFAULT_TABLES, sc, tmp_path / "fade.fmu")
    torque = {}
    for theta_c in (20.0, 300.0):
        c = ClutchFmu(fmu, {"theta_cs_start": 373.15})
        try:
            torque[theta_c] = c.step(0.0, 1e-9, 0.005, theta_c + KELVIN, 150.0)[0]
        finally:
            c.close()
    ratio = table(300.0, 150.0) / table(20.0, 150.0)
    assert torque[20.0] > 10.0                            # the clutch carries torque at 5 mm
    assert ratio < 0.85                                   # it does fade
    # the facing temperature also grows the stack (the cover's kiss point): the clamp force changes too
    clamp = {t: outputs(0.005, 373.15, load_table(), ClutchParameters(), t + KELVIN).clamp_force for t in torque}
    assert torque[300.0] / torque[20.0] == pytest.approx(ratio * clamp[300.0] / clamp[20.0], rel=1e-9)


def test_fade_scenario_delivers_less_torque_when_hot(tmp_path):
    sc = load_scenario(scenario_path("fade"))
    drive = sc.tcu.drive_time_s               # trailer duty: the constant-mu launches lock up after 4-6.5 s
    sc = short(sc, launches=2, initial_degC=300.0)
    sc = dataclasses.replace(sc, tcu=dataclasses.replace(sc.tcu, drive_time_s=drive))
    fmu = build_plant_fmu(DEFAULT_TABLES, sc, tmp_path / "fade.fmu")
    plain = build_fmu(DEFAULT_TABLES, tmp_path / "p" / "plain.fmu")
    fade = simulate_launches(fmu, sc, load_table(), "aware").metrics
    const = simulate_launches(plain, sc, load_table(), "aware").metrics
    for f, c in zip(fade, const):
        assert f["characteristic_error_rms_Nm"] > c["characteristic_error_rms_Nm"] + 5.0
        # the closed slip loop pushes the bearing further; the engine does not stall (a faded clutch may
        # not hold a hard launch's engine torque at all: then no lock-up, reported as NaN)
        assert not f["engine_stall"] and c["engagement_time_s"] < drive


def test_a_friction_surface_outside_the_table_is_said(caplog):
    """The plant holds mu at the friction table's edge beyond its temperatures: the run says so (a warning naming
    the range and the time), and is silent while the surface stays inside."""
    import logging

    from cushion_clutch.launch.simulate import _say_beyond_friction_table
    from cushion_clutch.model.friction import FrictionTable

    mu = FrictionTable([-40.0, 20.0, 350.0], [0.0, 100.0], [[0.3, 0.29], [0.3, 0.29], [0.18, 0.17]])
    t = np.arange(0.0, 1.0, 0.1)
    series = np.zeros(len(t), dtype=[("time_s", float), ("theta_surface_K", float)])
    series["time_s"] = t
    series["theta_surface_K"] = KELVIN + 300.0
    with caplog.at_level(logging.WARNING):
        assert _say_beyond_friction_table("naive", series, mu) == 0.0
    assert not caplog.records
    series["theta_surface_K"][4:7] = KELVIN + 400.0            # three rows of 0.1 s above 350 degC
    with caplog.at_level(logging.WARNING):
        assert _say_beyond_friction_table("naive", series, mu) == pytest.approx(0.3)
    assert "outside its friction table (-40 to 350 degC) for 0.3 s" in caplog.text and "400 degC" in caplog.text


def test_a_tcu_estimate_outside_its_model_is_said(caplog):
    """A TCU's facing estimate past the clutch model's range (held at its edge) is said, with the time; a run
    inside it (or a TCU without a facing estimate, NaN) is silent."""
    import logging

    from cushion_clutch.launch.simulate import _say_tcu_beyond_model
    from cushion_clutch.model.clutch_model import THETA_MAX_K

    table = load_table()
    t = np.arange(0.0, 1.0, 0.1)
    series = np.zeros(len(t), dtype=[("time_s", float), ("theta_cm_tcu_K", float), ("theta_cs_tcu_K", float)])
    series["time_s"] = t
    series["theta_cm_tcu_K"] = np.nan
    series["theta_cs_tcu_K"] = KELVIN + 100.0
    with caplog.at_level(logging.WARNING):
        assert _say_tcu_beyond_model("naive", series, table) == 0.0
    assert not caplog.records
    series["theta_cm_tcu_K"] = KELVIN + 300.0
    series["theta_cm_tcu_K"][2:4] = THETA_MAX_K + 40.0
    with caplog.at_level(logging.WARNING):
        assert _say_tcu_beyond_model("production", series, table) == pytest.approx(0.2)
    assert "left its clutch model's range for 0.2 s" in caplog.text
