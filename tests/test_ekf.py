"""The production TCU's EKF: thermal prediction against the plant network, touch-point and mu learning, gating."""
import dataclasses

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.model import load_table
from cushion_clutch.model import ClutchParameters, outputs, thermal_step, x_to_for_torque
from cushion_clutch.launch.ekf import ClutchEkf, EkfParams, TcuNetworkParams
from cushion_clutch.launch.thermal_network import NetworkParams, ThermalNetwork

TA = 293.15


@pytest.fixture(scope="module")
def table():
    return load_table()


def matched_network():
    plant = NetworkParams()
    fields = {f.name: getattr(plant, f.name) for f in dataclasses.fields(NetworkParams)}
    return plant, TcuNetworkParams(**fields)


def test_prediction_with_matched_network_follows_the_plant(table):
    plant, tcu = matched_network()
    p = ClutchParameters()
    net = ThermalNetwork(plant, TA, TA)
    ekf = ClutchEkf(tcu, EkfParams(), table, p, TA, TA)
    theta_cs = TA
    worst = 0.0
    for k in range(60000):                       # 60 s: a 2 s slip at 15 kW, then cooling, 1 ms plant steps
        slip = k < 2000
        pw = 15e3 if slip else 0.0
        net.step(1e-3, pw, 190.0, 60.0 if slip else 190.0, True)
        theta_cs = thermal_step(theta_cs, net.theta_cm, 1e-3, p)
        if (k + 1) % 10 == 0:
            ekf.accumulate(0.01, pw)
            if ekf.due():
                ekf.predict(190.0, 60.0 if slip else 190.0, True)
                worst = max(worst, abs(ekf.theta_cs - theta_cs), abs(ekf.theta_cm - net.theta_cm))
    assert net.theta_cm - TA > 5.0           # most of the heat goes into the metal (effusivity split)
    assert worst < 0.5                           # K: only the 50 ms held-power discretisation differs


def synthetic_launch(ekf, table, p, true_dx, true_mu, torques, theta_cs=TA):
    """Measurements from the exact model with a kiss offset and a friction scale, bearing set by the TCU."""
    for t in torques:
        x_cmd = x_to_for_torque(t / ekf.mu_scale, ekf.theta_cs, table, p) + ekf.dx_kiss
        meas = true_mu * outputs(x_cmd - true_dx, theta_cs, table, p).torque
        ekf.accumulate(0.05, 0.0)
        ekf.predict(190.0, 60.0, True)
        ekf.correct(meas, x_cmd, 100.0, True)


def test_touch_point_and_mu_are_learned_in_their_torque_bands(table):
    p = ClutchParameters()
    e = EkfParams(temperature_update=False)
    ekf = ClutchEkf(TcuNetworkParams(), e, table, p, TA, TA)
    ramp = np.concatenate([np.linspace(10, 150, 40), np.full(20, 150.0)])
    def worst_characteristic_error():
        return max(abs(ekf.model_torque(x_to_for_torque(t, TA, table, p) + 0.3e-3) - 0.85 * t)
                   for t in np.linspace(5.0, 150.0, 30))

    before = worst_characteristic_error()
    synthetic_launch(ekf, table, p, 0.3e-3, 0.85, ramp)
    one = worst_characteristic_error()
    for _ in range(3):
        synthetic_launch(ekf, table, p, 0.3e-3, 0.85, ramp)
    assert before > 20.0 and one < 5.0 and worst_characteristic_error() < 2.0     # N.m
    # the two parameters trade errors (nearly collinear on a progressive curve, see ekf's docstring)
    assert ekf.dx_kiss == pytest.approx(0.3e-3, abs=0.1e-3)
    assert ekf.mu_scale == pytest.approx(0.85, abs=0.05)
    assert ekf.accepted > 100


def test_no_update_without_slip_or_outside_the_launch(table):
    ekf = ClutchEkf(TcuNetworkParams(), EkfParams(), table, ClutchParameters(), TA, TA)
    s0, p0 = ekf.s.copy(), ekf.P.copy()
    assert not ekf.correct(200.0, 0.0055, 2.0, True)        # slip below slip_min_rad_s
    assert not ekf.correct(200.0, 0.0055, 100.0, False)     # not launching
    assert np.array_equal(ekf.s, s0) and np.array_equal(ekf.P, p0)


def test_outliers_are_gated(table):
    ekf = ClutchEkf(TcuNetworkParams(), EkfParams(), table, ClutchParameters(), TA, TA)
    x = 0.0052
    h = ekf.model_torque(x)
    assert 8.0 <= h <= 60.0
    assert not ekf.correct(h + 500.0, x, 100.0, True)
    assert ekf.rejected == 1 and ekf.dx_kiss == 0.0


def test_parameters_are_checked():
    with pytest.raises(ParameterError) as err:
        EkfParams(touch_torque_min_Nm=50.0, touch_torque_max_Nm=40.0)
    assert "ekf.touch_torque_max_Nm" in str(err.value)
    with pytest.raises(ParameterError) as err:
        TcuNetworkParams(spring_C_J_per_K=0.0)
    assert "tcu_thermal.spring_C_J_per_K" in str(err.value)
