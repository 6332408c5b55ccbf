"""The compiled plant steps (launch/plant/plant_block.py, fmu_src/hosts/launch_plant.c) against the Python loop, the reference.

Both paths must give the same time series, per-launch metrics, energy terms, lock events and TCU estimates
(the plant's thermal network steps in C too, in the blocks and in the quiet periods: its temperatures are in
the series and, through theta_cm, in everything else).
The C step keeps the Python expressions' order of operations and is built without FMA contraction, so on
this machine they agree bit for bit; the test allows 1e-12 relative (a compiler on another platform may
round a libm call differently) and reports the largest difference.
"""
import dataclasses
import math

import numpy as np
import pytest

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.launch.plant.build import build_plant_fmu
from cushion_clutch.launch.scenario import load_scenario, scenario_path
from cushion_clutch.launch.simulate import simulate_launches
from cushion_clutch.model import load_table

pytestmark = pytest.mark.fmu
REL = 1e-12


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    sc = load_scenario(scenario_path("creep"))
    return build_plant_fmu(DEFAULT_TABLES, sc, tmp_path_factory.mktemp("plant") / "CushionClutch.fmu")


def _scenario(name, launches, period_s=20.0, **changes):
    sc = load_scenario(scenario_path(name))
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=launches, period_s=period_s))
    return dataclasses.replace(sc, **changes)


def _close(a, b) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or abs(a - b) <= REL * max(abs(a), abs(b))
    return a == b


def _assert_same(py, nat):
    assert py.plant == "python" and nat.plant == "native"
    assert len(py.series) == len(nat.series) > 0
    for col in py.series.dtype.names:
        a, b = py.series[col], nat.series[col]
        nan = np.isnan(a)
        assert np.array_equal(nan, np.isnan(b)), col
        assert np.allclose(a[~nan], b[~nan], rtol=REL, atol=0.0), (col, np.max(np.abs(a[~nan] - b[~nan])))
    assert len(py.metrics) == len(nat.metrics)
    for m, n in zip(py.metrics, nat.metrics):
        bad = {k: (m[k], n[k]) for k in m if not _close(m[k], n[k])}
        assert not bad, bad
    bad = {k: v for k, v in vars(py.energy).items() if not _close(v, vars(nat.energy)[k])}
    assert not bad, bad
    assert [(a, e) for a, e, _ in py.lock_events] == [(a, e) for a, e, _ in nat.lock_events]
    assert all(_close(x[2], y[2]) for x, y in zip(py.lock_events, nat.lock_events))
    assert py.kiss_estimates == nat.kiss_estimates and py.quiet_s == nat.quiet_s


@pytest.mark.parametrize("tcu", ["naive", "production"])
def test_creep_native_equals_python(fmu, tcu):
    sc = _scenario("creep", 1)
    table = load_table()
    py = simulate_launches(fmu, sc, table, tcu, plant="python")
    nat = simulate_launches(fmu, sc, table, tcu, plant="native")
    _assert_same(py, nat)
    assert py.lock_events and not any(m["engine_stall"] for m in py.metrics)
    assert py.quiet_s > 5.0                    # quiet periods (the network stepped in lp_run_quiet) are covered


def test_rows_off_the_tcu_period_native_equals_python(fmu):
    """Rows every 3 steps (not a divisor of the 10-step TCU period): the rows due inside a block and inside a
    quiet period are found by counting, in both loops; the network's temperatures in every row."""
    sc = _scenario("creep", 1, 14.0)
    table = load_table()
    py = simulate_launches(fmu, sc, table, "naive", record_every=3, plant="python")
    nat = simulate_launches(fmu, sc, table, "naive", record_every=3, plant="native")
    _assert_same(py, nat)
    assert len(py.series) == -(-round(sc.run.duration() / sc.run.step_s) // 3) and py.quiet_s > 0.0
    assert np.all(np.diff(py.series["time_s"]) > 0.0)
    assert not np.any(np.isnan(nat.series["theta_surface_K"]))


def test_record_every_below_one_named(fmu):
    with pytest.raises(ValueError, match="record_every = 0: must be at least 1"):
        simulate_launches(fmu, _scenario("creep", 1, 14.0), load_table(), "naive", record_every=0)


def test_stall_and_restart_native_equals_python(fmu):
    """The engine stalls on the protection hill (the plant's clutch bites 2 mm before the TCU believes, the
    stall speed raised to 760 rpm): the record's stall, the restart for the next slot, unlock events."""
    sc = _scenario("protection", 2, 14.0)
    sc = dataclasses.replace(sc, engine=dataclasses.replace(sc.engine, stall_speed_rpm=760.0),
                             clutch=dataclasses.replace(sc.clutch, x_kiss_offset_m=-2e-3))
    table = load_table()
    py = simulate_launches(fmu, sc, table, "naive", plant="python")
    nat = simulate_launches(fmu, sc, table, "naive", plant="native")
    assert any(m["engine_stall"] for m in py.metrics)
    _assert_same(py, nat)


def test_lumped_facing_runs_the_python_loop(fmu):
    sc = _scenario("creep", 1, 14.0)
    sc = dataclasses.replace(sc, plant_thermal=dataclasses.replace(sc.plant_thermal, enabled=False))
    assert simulate_launches(fmu, sc, load_table(), "naive").plant == "python"


def test_unknown_plant_named(fmu):
    with pytest.raises(ValueError, match="plant = 'c'.*native, python"):
        simulate_launches(fmu, _scenario("creep", 1, 14.0), load_table(), "naive", plant="c")


def _creep_plant(fmu, theta0_K):
    """A native plant of one ``creep`` launch with the network at ``theta0_K``, its clutch FMU (the caller closes
    it) and the step, s."""
    from cushion_clutch.launch.plant.driveline import Driveline
    from cushion_clutch.launch.plant.engine import EngineGovernor
    from cushion_clutch.launch.plant.fmu_client import ClutchFmu
    from cushion_clutch.launch.plant.plant_block import NativePlant
    from cushion_clutch.model.thermal_network import ThermalNetwork

    sc = _scenario("creep", 1)
    h = sc.run.step_s
    engine = EngineGovernor(sc.engine, h)
    dl = Driveline(**sc.driveline_sections(), w_e=engine.w_idle)
    clutch = ClutchFmu(fmu, {})
    try:
        native = NativePlant(clutch, engine, dl, ThermalNetwork(sc.plant_thermal, 293.15, theta0_K), h, 0.9, 300.0,
                             0.3, 10, 10, 0.05, 30.0)
    except BaseException:
        clutch.close()
        raise
    return native, clutch, h


def test_fmu_refusal_raises_naming_the_function(fmu):
    """An input the FMU refuses (a NaN bearing position): FmuCallError naming fmi2DoStep, as the Python path."""
    from cushion_clutch.errors import FmuCallError
    from cushion_clutch.launch.results.metrics import LaunchRecord

    native, clutch, h = _creep_plant(fmu, 400.0)
    try:
        native.start(LaunchRecord(1, False, h), 0.0, 400.0, 0.0, 0.0, 400.0, 0.0)
        args = dict(k0=0, n_steps=100, next_switch=1.0, slot_start=0.0, slot_end=1.0, countdown=10, x_cmd=1e-3,
                    pedal_level=0.5, t_dem=0.0, t_rate=0.0, engaged=True, braking=False, launching=True)
        assert native.block(**args)[0] == 10                 # ten steps to the next TCU cycle
        with pytest.raises(FmuCallError, match="fmi2DoStep"):
            native.block(**{**args, "k0": 10, "x_cmd": math.nan})
    finally:
        clutch.close()


def test_quiet_period_refusals(fmu):
    """lp_run_quiet: a torque with the bearing not retracted is reported (None: the loop raises), an input the
    FMU refuses raises FmuCallError naming the function."""
    from cushion_clutch.errors import FmuCallError
    from cushion_clutch.launch.results.metrics import LaunchRecord
    from cushion_clutch.launch.plant.plant_block import HEAD

    native, clutch, h = _creep_plant(fmu, 300.0)
    try:
        rec = LaunchRecord(1, False, h)
        native.start(rec, 0.0, 300.0, 0.0, 0.0, 300.0, 0.0)
        head = dict(zip(HEAD, native.quiet(0.0, 10 * h, 1.0)))       # retracted: no torque, the network stepped
        assert head["t_cap"] == 0.0 and head["theta_cm"] != 300.0 and head["steps"] == 1.0
        native.start(rec, 8e-3, 300.0, 0.0, 0.0, 300.0, 0.0)           # the bearing 8 mm in: the clutch grips
        assert native.quiet(0.01, 10 * h, 1.0) is None and native.s.t_cap > 0.0
        native.start(rec, math.nan, 300.0, 0.0, 0.0, 300.0, 0.0)
        with pytest.raises(FmuCallError, match="fmi2DoStep"):
            native.quiet(0.02, 10 * h, 1.0)
    finally:
        clutch.close()


def test_friction_at_the_surface_native_equals_python(tmp_path):
    """With a friction table (fade) the plant's torque is n mu(theta_friction, |omega_slip|) R_eq F_clamp (issue 37):
    mu looked up in C (launch_plant.c friction_mu) as in Python (FrictionTable), to the last bit."""
    sc = _scenario("fade", 1)
    fmu = build_plant_fmu(DEFAULT_TABLES, sc, tmp_path / "CushionClutch.fmu")
    table = load_table()
    py = simulate_launches(fmu, sc, table, "naive", plant="python")
    nat = simulate_launches(fmu, sc, table, "naive", plant="native")
    _assert_same(py, nat)
    assert py.lock_events


def test_the_ideal_tcus_protection_sees_the_same_friction_surface_native_and_python(tmp_path):
    """The ideal TCU's thermal protection is told the plant's hotter friction surface (the C state's nodes, or the
    Python network's): fade's duty 60 s apart with the protection on, where the surface makes it warn from launch
    12 and limit launch 14 (on the facings alone: ok, warn, warn); both paths the same, to the last bit."""
    sc = _scenario("fade", 14, 60.0, protection=load_scenario(scenario_path("protection")).protection)
    fmu = build_plant_fmu(DEFAULT_TABLES, sc, tmp_path / "CushionClutch.fmu")
    table = load_table()
    py = simulate_launches(fmu, sc, table, "aware", plant="python", record_every=50)
    nat = simulate_launches(fmu, sc, table, "aware", plant="native", record_every=50)
    _assert_same(py, nat)
    assert [m["protection_level"] for m in nat.metrics][11:] == [1, 1, 2]
