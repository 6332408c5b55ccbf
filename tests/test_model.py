"""The shared pure model (cushion_clutch/model/clutch_model.py) through the Python API."""
import math

import control
import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import (KELVIN, ClutchParameters, load_table, outputs, thermal_step, thermal_system,
                                  x_to_for_torque)
from cushion_clutch.fe.tables import read_tables

P = ClutchParameters()


@pytest.fixture(scope="module")
def table():
    return load_table()


@pytest.fixture(scope="module")
def raw():
    return read_tables(DEFAULT_TABLES)


def test_interpolation_is_scipy_pchip(table, raw):
    for t, u, f, curve in zip(raw.theta_degC, raw.u_m, raw.force_N, table.curves):
        q = np.linspace(u[0], u[-1], 997)
        ref = PchipInterpolator(u, f)(q)
        ours = np.array([table.force(x, t) for x in q])
        assert ours == pytest.approx(ref, rel=1e-12, abs=1e-9)


def test_force_is_monotone_in_u_at_and_between_table_temperatures(table):
    u = np.linspace(-0.3e-3, 1.6e-3, 4001)
    for t in (20.0, 57.0, 195.0, 222.5, 300.0):
        f = np.array([table.force(x, t) for x in u])
        assert np.all(np.diff(f) >= 0)
        assert f[0] == pytest.approx(0.0, abs=1e-9)


def test_linear_in_theta_between_tables(table, raw):
    u = 0.7e-3
    f80, f195 = table.force(u, 80.0), table.force(u, 195.0)
    assert table.force(u, 80.0 + 0.3 * 115.0) == pytest.approx(0.7 * f80 + 0.3 * f195, rel=1e-12)
    assert table.delta_kiss(137.5) == pytest.approx(np.interp(137.5, raw.theta_degC, raw.delta_kiss_m))


def test_clamped_outside_table_temperatures(table):
    hot = outputs(0.006, 400.0 + KELVIN, table, P)
    edge = outputs(0.006, table.theta_degC[-1] + KELVIN, table, P)
    assert hot.clamped and not edge.clamped
    assert hot.torque == edge.torque


def test_thermal_step_is_the_exponential_solution():
    theta0, theta_cm = 300.0, 500.0
    tau = P.C / (P.U + P.H)
    theta_inf = (P.U * theta_cm + P.H * P.theta_a) / (P.U + P.H)
    for dt in (1e-3, 0.1, 5.0, 100.0):
        expected = theta_inf + (theta0 - theta_inf) * math.exp(-dt / tau)
        assert thermal_step(theta0, theta_cm, dt, P) == pytest.approx(expected, rel=1e-14)
    assert tau == pytest.approx(7.142857142857, rel=1e-12)


def test_exact_step_equals_zero_order_hold_discretisation():
    rng = np.random.default_rng(1)
    theta_cm = 293.15 + 250 * rng.random(200)
    for dt in (1e-3, 0.1, 5.0):
        sysd = control.c2d(thermal_system(P), dt, method="zoh")
        u = np.vstack([theta_cm, np.full_like(theta_cm, P.theta_a)])
        resp = control.forced_response(sysd, U=u, X0=[P.theta_cs_start])
        theta, ours = P.theta_cs_start, []
        for k in range(len(theta_cm)):
            ours.append(theta)
            theta = thermal_step(theta, theta_cm[k], dt, P)
        assert np.array(ours) == pytest.approx(np.squeeze(resp.outputs), rel=1e-12)


def test_steady_gain_and_time_constant():
    sys = thermal_system(P)
    assert control.dcgain(sys)[0, 0] == pytest.approx(P.U / (P.U + P.H))
    assert -1 / sys.poles()[0].real == pytest.approx(P.C / (P.U + P.H))


@pytest.mark.parametrize("theta_c", [20.0, 137.0, 195.0, 300.0])
def test_inverse_gives_back_the_torque(table, theta_c):
    theta = theta_c + KELVIN
    t_full = outputs(1.0, theta, table, P).torque
    for frac in (0.02, 0.1, 0.5, 0.9, 0.99):
        x = x_to_for_torque(frac * t_full, theta, table, P)
        assert outputs(x, theta, table, P).torque == pytest.approx(frac * t_full, rel=1e-7)


def test_inverse_saturates(table):
    theta = 195.0 + KELVIN
    x_full = x_to_for_torque(1e9, theta, table, P)
    assert outputs(x_full, theta, table, P).torque == pytest.approx(outputs(1.0, theta, table, P).torque)
    assert outputs(x_to_for_torque(0.0, theta, table, P), theta, table, P).torque == 0.0


def test_parameter_problems_name_the_parameter():
    bad = ClutchParameters(C=0.0, mu=-0.1, lever_ratio=0.0, R_eq=math.nan)
    msg = "\n".join(bad.problems())
    for name in ("C = 0.0", "mu = -0.1", "lever_ratio = 0.0", "R_eq = nan"):
        assert name in msg
    assert ClutchParameters().problems() == []


def test_malformed_table_is_a_clear_error(tmp_path):
    (tmp_path / "force_deflection.csv").write_text("theta_degC,u_m,force_N\n20,0,1\n20,1e-4,x\n")
    (tmp_path / "kiss_point.csv").write_text("theta_degC,delta_kiss_m\n20,0\n")
    with pytest.raises(ValueError, match="force_deflection.csv"):
        load_table(tmp_path)
