"""The production TCU's clutch model torque through the native clutch model (cushion_clutch/launch/tcu/tcu_model.py,
fmu_src/hosts/tcu_model.c) against the Python model, the reference: the same torque to round-off over a scan of the
bearing position and both temperatures, the same inverse (bearing position for a torque) within its tolerance over
a scan of torque and both temperatures, the round trip torque(x(T)) = T, the same errors outside the ranges, a
logged fallback, and the same figures of a production launch run."""
import dataclasses
import logging
import math
from pathlib import Path

import numpy as np
import pytest

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.launch.tcu import tcu_model
from cushion_clutch.launch.tcu.tcu_model import TcuClutchModel
from cushion_clutch.model import ClutchParameters, load_table, outputs, x_to_for_torque
from cushion_clutch.model.clutch_model import THETA_MAX_K, X_TO_MAX

pytestmark = pytest.mark.fmu
#: relative agreement of the two paths' torque (floor 1 N.m: below it, 1e-9 N.m absolute; the cover's solvers
#: agree to about 1e-11 relative, tests/test_native_speed.py)
REL = 1e-9
SCENARIOS = Path(__file__).parent.parent / "cushion_clutch" / "launch" / "scenarios"


def _scan(table, p):
    """The worst |native - Python| / max(|Python|, 1 N.m) over positions and temperatures, and the count."""
    m = TcuClutchModel(table, p, native=True)
    assert m.native
    worst, n = 0.0, 0
    for x in np.linspace(-1e-3, 12e-3, 53):
        for cs in np.linspace(table.theta_min_K, table.theta_max_K, 9):
            for cm in (253.15, 293.15, 373.15, 473.15, 623.15, 800.0):
                ref = outputs(float(x), float(cs), table, p, cm).torque
                got = m.torque(float(x), float(cs), cm)
                worst = max(worst, abs(got - ref) / max(abs(ref), 1.0))
                n += 1
    return worst, n


@pytest.mark.parametrize("folder, wear", [(None, 0.0), (None, 1.0e-3),
                                          (SCENARIOS / "tables" / "default_nominal_2mm", 0.0)])
def test_native_torque_equals_the_python_model_over_a_scan(folder, wear):
    table = load_table(folder or Path(DEFAULT_TABLES))
    p = ClutchParameters(facing_wear=wear)
    worst, n = _scan(table, p)
    assert n == 53 * 9 * 6 and worst <= REL, worst


#: the inverse's agreement (m): both paths find the cushion's compression to within tol_m / lever ratio of the
#: smallest root (the same bracket; the native one then finds its position through the forward map to tol_m / 100),
#: so they lie within about 2 tol_m of each other (measured: 6e-13 m with tol_m = 1e-12 m)
X_TOL = 1e-11
#: torques of the inverse's scan (N.m): below zero, zero, the cushion phase, the solid phase and above the capacity
TORQUES = (-50.0, -1e-9, 0.0, 1e-6, 0.3, 2.0, 10.0, 25.0, 60.0, 120.0, 180.0, 220.0, 260.0, 300.0, 330.0, 1e4)


@pytest.mark.parametrize("folder, wear", [(None, 0.0), (None, 1.0e-3),
                                          (SCENARIOS / "tables" / "default_nominal_2mm", 0.0)])
def test_native_inverse_equals_the_python_model_over_a_scan(folder, wear):
    """x_to_for_torque's definition: the smallest position reaching the torque; at or below zero the first contact
    (on a cold cushion below the kiss point's u = 0); above the closed capacity the lift-off position."""
    table = load_table(folder or Path(DEFAULT_TABLES))
    p = ClutchParameters(facing_wear=wear)
    m = TcuClutchModel(table, p, native=True)
    assert m.native
    worst, n, phases = 0.0, 0, set()
    for cs in np.linspace(table.theta_min_K, table.theta_max_K, 7):
        for cm in (253.15, 373.15, 623.15, 800.0):
            cs = float(cs)
            st_lift = outputs(X_TO_MAX, cs, table, p, cm)
            for t in TORQUES:
                ref = x_to_for_torque(t, cs, table, p, theta_cm=cm)
                got = m.x_for_torque(t, cs, cm)
                worst = max(worst, abs(got - ref))
                n += 1
                phases.add("lift" if t >= st_lift.torque else "kiss" if t <= 0.0 else "slip")
    assert n == 7 * 4 * len(TORQUES) and phases == {"lift", "kiss", "slip"}
    assert worst <= X_TOL, worst


def test_native_inverse_honours_the_tolerance():
    table, p = load_table(), ClutchParameters()
    m = TcuClutchModel(table, p)
    for t in (5.0, 60.0, 150.0):
        ref = x_to_for_torque(t, 350.0, table, p, tol_m=1e-8, theta_cm=360.0)
        got = m.x_for_torque(t, 350.0, 360.0, tol_m=1e-8)
        fine = x_to_for_torque(t, 350.0, table, p, theta_cm=360.0)
        assert abs(got - ref) <= 2e-8 and abs(got - fine) <= 2e-8


@pytest.mark.parametrize("cs, cm", [(253.15, 253.15), (300.0, 330.0), (420.0, 520.0), (THETA_MAX_K, 800.0)])
def test_native_inverse_round_trip(cs, cm):
    """torque(x(T)) = T within the tolerance's torque (1e-6 N.m: the slope, below 1e5 N.m/m, times 1e-11 m) in the
    slipping range, and x(T) is the smallest such position: 1e-9 m before it the torque is below T; above the
    capacity the lift-off position, whose torque is the capacity; at or below zero the first contact, where the
    torque leaves zero."""
    table, p = load_table(), ClutchParameters()
    m = TcuClutchModel(table, p)
    cap = m.torque(X_TO_MAX, cs, cm)
    assert cap > 200.0
    for t in np.linspace(0.05, cap, 41)[:-1]:
        x = m.x_for_torque(float(t), cs, cm)
        assert abs(m.torque(x, cs, cm) - t) <= 1e-6 * max(1.0, t), t
        assert m.torque(x - 1e-9, cs, cm) < t
    x_lift = m.x_for_torque(cap * 1.001, cs, cm)
    assert m.torque(x_lift, cs, cm) == pytest.approx(cap, rel=1e-12)
    assert m.torque(x_lift - 1e-6, cs, cm) < cap
    for t in (-10.0, 0.0):
        x0 = m.x_for_torque(t, cs, cm)
        assert abs(m.torque(x0, cs, cm)) <= 1e-6 and m.torque(x0 + 1e-6, cs, cm) > 0.0
        assert m.torque(x0 - 1e-6, cs, cm) == 0.0


def test_the_torque_is_not_trivially_equal():
    """The scan covers open, slipping and closed positions (the comparison is not of zeros)."""
    table, p = load_table(), ClutchParameters()
    m = TcuClutchModel(table, p)
    torques = [m.torque(x, 293.15, 293.15) for x in np.linspace(-1e-3, 12e-3, 53)]
    assert min(torques) < 1.0 and max(torques) > 200.0


def test_outside_the_ranges_the_native_path_raises_the_python_models_error():
    table, p = load_table(), ClutchParameters()
    m = TcuClutchModel(table, p)
    for args in ((X_TO_MAX + 1e-3, 300.0, 300.0), (5e-3, THETA_MAX_K + 1.0, 300.0), (5e-3, 300.0, math.nan)):
        with pytest.raises(ValueError) as native:
            m.torque(*args)
        with pytest.raises(ValueError) as python:
            outputs(args[0], args[1], table, p, args[2])
        assert str(native.value) == str(python.value)


def test_python_path_is_the_reference_and_the_fallback(monkeypatch, caplog):
    table, p = load_table(), ClutchParameters()
    assert not TcuClutchModel(table, p, native=False).native

    def broken():
        raise RuntimeError("no compiler (test)")

    monkeypatch.setattr(tcu_model.LIBRARY, "_loaded", None)
    monkeypatch.setattr(tcu_model.LIBRARY, "path", broken)
    with caplog.at_level(logging.WARNING, logger="cushion_clutch.launch.tcu.tcu_model"):
        m = TcuClutchModel(table, p)
    assert not m.native and "no compiler (test)" in caplog.text
    assert m.torque(5e-3, 320.0, 350.0) == outputs(5e-3, 320.0, table, p, 350.0).torque
    assert m.x_for_torque(80.0, 320.0, 350.0) == x_to_for_torque(80.0, 320.0, table, p, theta_cm=350.0)


def test_the_inverse_outside_the_ranges_raises_the_python_models_error():
    table, p = load_table(), ClutchParameters()
    m = TcuClutchModel(table, p)
    for args in ((2e9, 300.0, 300.0), (50.0, THETA_MAX_K + 1.0, 300.0), (50.0, 300.0, math.nan)):
        with pytest.raises(ValueError) as native:
            m.x_for_torque(*args)
        with pytest.raises(ValueError) as python:
            x_to_for_torque(args[0], args[1], table, p, theta_cm=args[2])
        assert str(native.value) == str(python.value)


def test_the_production_command_goes_through_the_ekfs_model(monkeypatch):
    """ProductionTcu.x_for_torque is the EKF's model's inverse: native by default, the Python x_to_for_torque to
    the bit with tcu_model.NATIVE = False."""
    from cushion_clutch.launch.tcu.production import ProductionTcu
    calls = []
    for native in (True, False):
        monkeypatch.setattr(tcu_model, "NATIVE", native)
        table, p = load_table(), ClutchParameters()
        clutch = TcuClutchModel(table, p)
        assert clutch.native == native
        fake = type("Tcu", (), {"ekf": type("Ekf", (), {"clutch": clutch})(), "_command_memo": {}})()
        x = ProductionTcu.x_for_torque(fake, 70.0, 330.0, 345.0)
        ref = x_to_for_torque(70.0, 330.0, table, p, theta_cm=345.0)
        calls.append((x, ref))
        assert fake._command_memo == {(70.0, 330.0, 345.0): x}
    (xn, ref), (xp, ref2) = calls
    assert xp == ref2 and abs(xn - ref) <= X_TOL


def test_each_model_has_its_own_cover_state():
    """Two instances at other temperatures, called alternately, answer as each alone (per-instance memo)."""
    table, p = load_table(), ClutchParameters()
    a, b = TcuClutchModel(table, p), TcuClutchModel(table, p)
    alone = [a.torque(x, 300.0, 310.0) for x in (4e-3, 5e-3, 6e-3)]
    mixed = []
    for x in (4e-3, 5e-3, 6e-3):
        b.torque(x, 450.0, 520.0)
        mixed.append(a.torque(x, 300.0, 310.0))
    assert mixed == alone


def _creep_runs(tmp_path, monkeypatch, paths):
    """Two creep launches with the production TCU per (native torque, native inverse) pair: the launch metrics."""
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches

    sc = load_scenario(scenario_path("creep"))
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=2))
    table = load_table(sc.tables_path("tcu") or Path(DEFAULT_TABLES))
    fmu = build_plant_fmu(Path(DEFAULT_TABLES), sc, tmp_path / "CushionClutch.fmu")
    native_inverse = TcuClutchModel.x_for_torque

    def python_inverse(self, torque, theta_cs, theta_cm, tol_m=1e-12):
        return x_to_for_torque(torque, theta_cs, self.table, self.p, tol_m, theta_cm=theta_cm)

    runs = {}
    for native, inverse in paths:
        monkeypatch.setattr(tcu_model, "NATIVE", native)
        monkeypatch.setattr(TcuClutchModel, "x_for_torque", native_inverse if inverse else python_inverse)
        runs[native, inverse] = simulate_launches(fmu, sc, table, "production").metrics
        assert len(runs[native, inverse]) == 2
    return runs


def _compare(a_runs, b_runs, tol):
    """Every metric of both runs: equal, or within tol(key, a, b); the number of floats compared."""
    compared = 0
    for a, b in zip(a_runs, b_runs):
        for k, v in a.items():
            w = b[k]
            if isinstance(v, float) and isinstance(w, float):
                assert (math.isnan(v) and math.isnan(w)) or tol(k, v, w), (k, v, w)
                compared += 1
            else:
                assert v == w, k
    return compared


def test_a_production_run_gives_the_same_figures_on_both_paths(tmp_path, monkeypatch):
    """Two creep launches with the production TCU, the native torque against the Python model's, both with the
    Python inverse: the launch metrics agree within 1e-8 relative (the closed loop's 5 um position quantiser
    amplifies the torque's round-off; measured on this machine: at most 1.1e-10, in the worst characteristic error
    of launch 2; 1.6e-8 in the hot protection runs of test_launch_golden). With the native inverse too (it differs
    from the Python one within its 1e-12 m tolerance, at the last probe of the bracket, not to round-off) the
    quantiser takes other steps, as with another sensor-noise realisation; judged on the bar's scale (7.2 N.m) the
    figures stay put: the characteristic errors within 1e-3 N.m (measured on main 8cbfd68: 1.7e-4 in launch 2; 1.5e-5
    relative on the code before the cover's warm starts, which move the plant's trajectory), the thermal estimate
    within 1e-3 K (4e-7; 5.1e-4 on the merged physics, where the bound was 1e-4), the kiss point within 1e-5 mm
    (2.4e-6 on the merged physics of issues 37 and 38; 1e-6 was
    the bound before), the slip energy within 1e-3 relative (3.3e-5), the
    engagement within 0.1 s (0.038); the shuffle and tracking figures move more (measured: up to 5e-3 relative)."""
    runs = _creep_runs(tmp_path, monkeypatch, ((True, False), (False, False), (True, True)))
    ref = runs[False, False]
    assert _compare(runs[True, False], ref,
                    lambda k, v, w: abs(v - w) <= 1e-8 * max(abs(v), abs(w), 1e-9)) > 10
    absolute = {"theta_cs_start_degC": 1e-3, "theta_cs_error_K": 1e-3, "characteristic_error_max_Nm": 1e-3,
                "characteristic_error_rms_Nm": 1e-3, "kiss_point_error_mm": 1e-5, "engagement_time_s": 0.1}

    def near(k, v, w):
        if k in absolute:
            return abs(v - w) <= absolute[k]
        if k == "slip_energy_kJ":
            return abs(v - w) <= 1e-3 * max(abs(v), abs(w))
        return True
    assert _compare(runs[True, True], ref, near) > 10
