"""Issue 28: the model says when it is outside what it knows.

Ranges in the FMUs' descriptions, refusals naming input/value/range/unit, the ``validity`` output and its
warnings (once per entry), the cover's wear limit refused at initialisation, the re-chosen default cover,
through the Python API and through fmpy with its default logger, both backends, FMI 2 and 3, CS and ME.
"""
import functools
import math
import shutil
import tempfile
import atexit
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.launch.results.metrics import temperature_metrics
from cushion_clutch.model import ClutchParameters, CoverParameters, kiss_point, load_table, outputs, thermal_step, \
    x_to_for_torque
from cushion_clutch.model import clutch_model as cm
from cushion_clutch.model.cover import (CoverMap, ENGINE_TORQUE_NM, RESERVE_FACTOR, finger_compliance, hold_problem,
                                        temperature_grid, wear_limit, wear_reserve)
from native_builds import native_fmus

GAIN = 2 * 0.28 * 0.089             # n mu R_eq of the default clutch, m


@pytest.fixture(scope="module")
def table():
    return load_table()


@functools.cache
def python_fmu() -> Path:
    tmp = Path(tempfile.mkdtemp(prefix="cushion_validity_tests_"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    return build_fmu(DEFAULT_TABLES, tmp / "python.fmu", backend="python")


#: (label, FMU getter, fmi_type): every backend, FMI version and interface
VARIANTS = [("native2-CS", lambda: native_fmus()[2], "CoSimulation"),
            ("native2-ME", lambda: native_fmus()[2], "ModelExchange"),
            ("native3-CS", lambda: native_fmus()[3], "CoSimulation"),
            ("native3-ME", lambda: native_fmus()[3], "ModelExchange"),
            ("python2-CS", python_fmu, "CoSimulation")]


def _run(capsys, variant, start, stop=0.05, signal=None):
    """simulate_fmu with fmpy's default logger: (result or the exception, everything printed)."""
    _, get, kind = variant
    capsys.readouterr()
    try:
        res = simulate_fmu(str(get()), start_values=start, stop_time=stop, output_interval=0.01, fmi_type=kind,
                           input=signal, output=["torque", "validity", "clamp_force"])
    except FMICallException as exc:
        res = exc
    out = capsys.readouterr()
    return res, out.out + out.err


# ---- the one table, in the descriptions ---------------------------------------------------------------------
@pytest.mark.fmu
@pytest.mark.parametrize("get", [lambda: native_fmus()[2], lambda: native_fmus()[3], python_fmu],
                         ids=["native-fmi2", "native-fmi3", "python-fmi2"])
def test_every_input_and_parameter_has_min_max_nominal(get, table):
    """Every input and parameter declares min, max and nominal of the one range table (facing_wear's max: the
    default cover's wear limit with the FMU's tables, the default ones here)."""
    md = read_model_description(str(get()))
    bounds = {k: v for k, v in cm.variable_bounds(table).items() if k not in cm.OUTPUT_RANGES}
    seen = set()
    for v in md.modelVariables:
        if v.causality not in ("input", "parameter"):
            continue
        seen.add(v.name)
        lo, hi, nominal = bounds[v.name]
        assert (float(v.min), float(v.max), float(v.nominal)) == (lo, hi, nominal), v.name
        assert lo <= float(v.start) <= hi and nominal > 0.0, v.name
    assert seen == set(bounds) and len(seen) == sum(c in ("input", "parameter") for _, c, _, _ in cm.VARIABLES)


def test_bounds_come_from_the_ranges_and_inputs_are_physical():
    b = cm.variable_bounds()
    assert b["x_to"][:2] == (-0.002, 0.025) and b["theta_cm"][:2] == (200.0, 800.0)
    assert b["omega_slip"][:2] == (-1500.0, 1500.0)
    for name, (lo, hi, _, _) in cm.ClutchParameters.RANGES.items():
        assert b[name][:2] == (lo, hi)


def test_stroke_reaches_past_lift_off_at_the_wear_limit(table):
    """x_to's 25 mm cover the latest lift-off (default cover at its wear limit, every temperature of the box)
    with at least 5 mm to spare."""
    p = ClutchParameters()
    lim = wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, cm.THETA_MIN_K, cm.THETA_MAX_K)
    g = CoverMap(p.cover, p.lever_ratio)
    latest = max(g.prepare(a, b, lim, table, p.x_kiss_ref).x_lift
                 for a in temperature_grid(table, 200.0, 800.0, 100.0) for b in (200.0, 600.0, 800.0))
    assert 0.015 < latest <= cm.X_TO_MAX - 0.005


# ---- refusals and warnings through fmpy's default logger ----------------------------------------------------
@pytest.mark.fmu
@pytest.mark.parametrize("variant", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_celsius_in_a_kelvin_input_is_refused_naming_kelvin(capsys, variant):
    res, log = _run(capsys, variant, {"theta_cm": 100.0})
    assert "theta_cm = 100" in log and "[200, 800] K" in log and "did you mean 373.15 K (100 degC)?" in log, log
    assert isinstance(res, FMICallException) or np.all(res["torque"] == 0.0)   # refused: never an answer


@pytest.mark.fmu
@pytest.mark.parametrize("variant", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_bearing_position_outside_the_stroke_is_refused(capsys, variant):
    res, log = _run(capsys, variant, {"x_to": 0.1})
    assert "x_to = 0.1" in log and "0.025" in log and " m" in log, log
    assert isinstance(res, FMICallException) or np.all(res["torque"] == 0.0)


@pytest.mark.fmu
@pytest.mark.parametrize("variant", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_slip_faster_than_an_engine_is_refused(capsys, variant):
    res, log = _run(capsys, variant, {"omega_slip": 2000.0})
    assert "omega_slip = 2000" in log and "1500" in log and "rad/s" in log, log
    assert isinstance(res, FMICallException) or np.all(res["torque"] == 0.0)


@pytest.mark.fmu
@pytest.mark.parametrize("variant", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_facings_above_the_damage_limit_run_with_validity_2_and_one_warning(capsys, variant):
    res, log = _run(capsys, variant, {"theta_cm": 700.0, "x_to": 0.008})
    assert not isinstance(res, FMICallException), res
    assert np.all(res["validity"] == 2.0) and np.all(res["torque"] > 0.0)
    assert log.count("above facing_damage_temperature_K = 623.15 K") == 1, log


@pytest.mark.fmu
@pytest.mark.parametrize("variant", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_warning_once_per_entry_into_a_region(capsys, variant):
    """theta_cm 300 -> 700 -> 300 -> 700 K: two entries above the damage limit, two warnings; validity follows."""
    t = [0.0, 0.1, 0.1, 0.2, 0.2, 0.3, 0.3, 0.4]
    th = [300.0, 300.0, 700.0, 700.0, 300.0, 300.0, 700.0, 700.0]
    sig = np.array([(a, b, 0.008) for a, b in zip(t, th)], dtype=[("time", float), ("theta_cm", float),
                                                                   ("x_to", float)])
    res, log = _run(capsys, variant, {}, stop=0.4, signal=sig)
    assert log.count("above facing_damage_temperature_K") == 2, log
    v = dict(zip(np.round(res["time"], 6), res["validity"]))
    assert v[0.05] == 0.0 if 0.05 in v else True
    assert v[0.15] == 2.0 and v[0.25] == 0.0 and v[0.35] == 2.0


@pytest.mark.fmu
@pytest.mark.parametrize("variant", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_hot_cushion_beyond_the_tables_is_flagged_1(capsys, variant):
    """theta_cs_start 370 degC (above the 350 degC table), theta_cm 340 degC (below the damage limit): validity 1
    and a warning."""
    res, log = _run(capsys, variant, {"theta_cs_start": 643.15, "theta_cm": 613.15, "x_to": 0.008})
    assert not isinstance(res, FMICallException), res
    assert np.all(res["validity"] == 1.0) and log.count("temperature beyond the tables") == 1, log


@pytest.mark.fmu
@pytest.mark.parametrize("variant", VARIANTS, ids=[v[0] for v in VARIANTS])
def test_wear_beyond_the_limit_is_refused_at_initialisation_naming_it(capsys, variant):
    res, log = _run(capsys, variant, {"facing_wear": 0.003})
    import re
    printed = re.search(r"facing_wear = ([0-9.e+-]+) m", log)      # the value exactly: %.17g native, repr python
    assert printed and float(printed.group(1)) == 0.003 and "the wear limit of this cover is 0.00238441" in log, log   # the predicted joint's tables (2.38945 mm before)
    if variant[0].startswith("native"):        # pythonfmu's wrapper cannot return Error: it refuses every step
        assert isinstance(res, FMICallException) and "ExitInitializationMode" in str(res)
    else:
        assert isinstance(res, FMICallException) or np.all(res["torque"] == 0.0)


@pytest.mark.fmu
@pytest.mark.parametrize("start, rule", [
    ({"installed_deflection_m": 0.0}, "installed_deflection_m = 0"),
    ({"installed_deflection_m": 0.0104 * 5}, "must be <= 2 diaphragm_cone_height_m"),
    ({"diaphragm_youngs_modulus_Pa": 1e9}, "the diaphragm cannot hold"),
    # past its hump the diaphragm cannot hold the hot cushion's full compression (issue 37's tables, clamped at
    # 350 degC: bearing force -5.1 N at theta_cs 775 K; 0.0078 held with them, 0.0076 to 0.0072 do not)
    ({"installed_deflection_m": 0.0074}, "the diaphragm cannot hold"),
])
@pytest.mark.parametrize("version", [2, 3])
def test_covers_that_cannot_hold_are_errors_at_initialisation(capsys, start, rule, version):
    res, log = _run(capsys, ("native", lambda: native_fmus()[version], "CoSimulation"), start)
    assert isinstance(res, FMICallException) and "ExitInitializationMode" in str(res), res
    assert rule in log, log


@pytest.mark.fmu
def test_default_fmu_meets_the_bar_at_wear(capsys):
    """20 mm, 20 degC, facing_wear 1.5 mm: at least 300 N.m, native and pythonfmu, same number."""
    got = []
    for variant in VARIANTS[0], VARIANTS[4]:
        res, _ = _run(capsys, variant, {"facing_wear": 0.0015, "x_to": 0.020})
        got.append(float(res["torque"][-1]))
    assert got[0] >= 300.0 and got[1] == pytest.approx(got[0], rel=1e-12)


# ---- the Python API applies the same table --------------------------------------------------------------------
def test_api_refuses_celsius_naming_kelvin(table):
    p = ClutchParameters()
    for call in (lambda: outputs(0.008, 100.0, table, p), lambda: thermal_step(300.0, 100.0, 0.1, p),
                 lambda: kiss_point(100.0, table, p), lambda: x_to_for_torque(50.0, 100.0, table, p)):
        with pytest.raises(ValueError, match=r"= 100.0 K is outside \[200, 800\] K: did you mean 373.15 K \(100 degC\)\?"):
            call()
    with pytest.raises(ValueError, match=r"x_to = 0.1 m is outside \[-0.002, 0.025\] m"):
        outputs(0.1, 300.0, table, p)


def test_api_refuses_wear_beyond_the_limit(table):
    p = ClutchParameters(facing_wear=0.003)
    for call in (lambda: outputs(0.008, 300.0, table, p), lambda: x_to_for_torque(50.0, 300.0, table, p)):
        with pytest.raises(ValueError, match="the wear limit of this cover is 0.00238441"):   # 2.38945 mm before the joint
            call()


def test_api_validity_codes(table):
    p = ClutchParameters()
    assert outputs(0.008, 400.0, table, p, 400.0).validity == 0.0
    # the default tables run from -40 degC (a winter start) to 350 degC (the facings' damage limit), both ends in
    assert outputs(0.008, 233.15, table, p, 233.15).validity == 0.0
    assert outputs(0.008, 623.15, table, p, 623.15).validity == 0.0       # damage is strictly above 350 degC
    assert outputs(0.008, 623.15, table, p, np.nextafter(623.15, 1e3)).validity == 2.0
    assert outputs(0.008, 653.15, table, p, 600.0).validity == 1.0        # cushion above the 350 degC table
    assert outputs(0.008, 230.0, table, p, 230.0).validity == 1.0         # below the -40 degC table
    assert outputs(0.008, 400.0, table, p, 700.0).validity == 2.0         # facings damaged
    assert outputs(0.008, 400.0, table, ClutchParameters(facing_damage_temperature_K=750.0), 700.0).validity == 0.0
    assert cm.validity_warning(2, 2, 400.0, 700.0, table, p) is None
    assert "validity = 2" in cm.validity_warning(0, 2, 400.0, 700.0, table, p)
    assert cm.validity_warning(1, 0, 400.0, 400.0, table, p) is None


# ---- the cover: wear limit, reserve, the re-chosen default ---------------------------------------------------
def _closed(table, wear, theta=293.15):
    p = ClutchParameters()
    return CoverMap(p.cover, p.lever_ratio).prepare(theta, theta, wear, table, p.x_kiss_ref).clamp_installed()


def test_default_cover_wear_reserve_and_hump(table):
    new = _closed(table, 0.0)
    assert _closed(table, 0.001) >= new                         # clamp load at 1.0 mm wear >= new
    w = np.linspace(0.0, 0.0015, 31)
    cap = np.array([GAIN * _closed(table, float(x)) for x in w])
    assert cap.min() >= RESERVE_FACTOR * ENGINE_TORQUE_NM       # >= 1.25 x 240 N.m up to 1.5 mm
    hump = w[int(np.argmax(cap))]
    assert 0.0005 <= hump <= 0.001                              # the hump mid-way through the reserve
    p = ClutchParameters()
    reserve = wear_reserve(p.cover, p.lever_ratio, table, p.x_kiss_ref, GAIN)
    assert 0.0015 <= reserve < wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, 200.0, 800.0)
    assert GAIN * _closed(table, reserve) == pytest.approx(300.0, abs=0.05)
    assert outputs(0.020, 293.15, table, ClutchParameters(facing_wear=0.0015)).torque >= 300.0


def test_wear_limit_is_where_the_diaphragm_lets_go(table):
    p = ClutchParameters()
    lim = wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, 200.0, 800.0)
    assert hold_problem(p.cover, p.lever_ratio, table, p.x_kiss_ref, lim, 200.0, 800.0) is None
    msg = hold_problem(p.cover, p.lever_ratio, table, p.x_kiss_ref, lim + 2e-7, 200.0, 800.0)
    assert msg and f"{lim:.6g} m" in msg
    # a narrower temperature box is never stricter
    assert wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, 293.15, 573.15) >= lim


def test_release_compliance_is_derived_from_the_fingers():
    c = CoverParameters()
    fingers = finger_compliance(c, 3.0)
    assert 0.6e-6 < fingers < c.release_compliance_m_per_N     # fingers 0.69 um/N + bearing/line allowance
    # the midpoint rule against the closed form of the linearly tapered cantilever:
    # int_0^L x^2 / (a + k x) dx = [(a + k x)^2 / 2 - 2 a (a + k x) + a^2 ln(a + k x)]_0^L / k^3
    r_b = c.fulcrum_radius_m - 3.0 * (c.pressure_plate_radius_m - c.fulcrum_radius_m)
    length, n = c.diaphragm_inner_radius_m - r_b, 18
    a = 2 * math.pi * r_b / n - 0.003
    k = (2 * math.pi * c.diaphragm_inner_radius_m / n - 0.003 - a) / length

    def prim(x):
        y = a + k * x
        return y * y / 2 - 2 * a * y + a * a * math.log(y)

    closed = 12 / (c.diaphragm_youngs_modulus_Pa * c.diaphragm_thickness_m ** 3 * n) * (prim(length) - prim(0)) / k ** 3
    assert fingers == pytest.approx(closed, rel=1e-5)


# ---- launch metrics -------------------------------------------------------------------------------------------
def test_temperature_metrics_count_time_beyond_the_tables_and_above_damage():
    dt = [("time_s", float), ("launch", float), ("theta_cm_K", float), ("theta_cs_K", float)]
    rows = [(0.0, 1, 300.0, 300.0), (1.0, 1, 650.0, 580.0), (3.0, 1, 640.0, 590.0), (4.0, 2, 400.0, 400.0),
            (4.5, 2, 400.0, 400.0)]
    got = temperature_metrics(np.array(rows, dtype=dt), 293.15, 573.15, 623.15)
    assert got[1]["beyond_tables_s"] == pytest.approx(3.0)      # rows at 1 s (2 s) and 3 s (1 s)
    assert got[1]["above_damage_s"] == pytest.approx(3.0)
    assert got[1]["peak_theta_cm_degC"] == pytest.approx(650.0 - 273.15)
    assert got[1]["peak_theta_cs_degC"] == pytest.approx(590.0 - 273.15)
    assert got[2]["beyond_tables_s"] == 0.0 and got[2]["above_damage_s"] == 0.0


@pytest.mark.fmu
def test_a_winter_launch_runs_inside_the_tables(table, tmp_path):
    """Issue 37: a launch at -10 degC ambient (every node and the cushion spring soaked at -10 degC) spends none
    of its time beyond the default tables (-40 to 350 degC) and never reports validity 1."""
    import dataclasses
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import load_scenario
    from cushion_clutch.launch.simulate import simulate_launches
    sc = load_scenario()
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=1),
                             facing=dataclasses.replace(sc.facing, ambient_degC=-10.0, initial_degC=-10.0))
    fmu = build_plant_fmu(Path(DEFAULT_TABLES), sc, tmp_path / "CushionClutch.fmu")
    res = simulate_launches(fmu, sc, table, "naive", record_every=1)
    s = res.series
    assert s["theta_cs_K"].min() == pytest.approx(263.15, abs=0.01) and s["theta_cm_K"].min() >= 263.15 - 1e-9
    got = temperature_metrics(s, table.theta_min_K, table.theta_max_K, ClutchParameters().facing_damage_temperature_K)
    assert got[1]["beyond_tables_s"] == 0.0 and got[1]["above_damage_s"] == 0.0
    assert res.lock_events and not any(m["engine_stall"] for m in res.metrics)
