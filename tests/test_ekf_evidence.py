"""The production TCU's EKF: the nominal calibration as the prior (evidence beyond the known sensor biases)."""
import numpy as np
import pytest

from cushion_clutch.launch.tcu.ekf import ClutchEkf, EkfParams, TcuNetworkParams
from cushion_clutch.model import ClutchParameters, load_table, outputs, x_to_for_torque

TA = 293.15


@pytest.fixture(scope="module")
def table():
    return load_table()


def biased_launch(ekf, table, p, true_dx, gain, offset, torques):
    """A launch on a clutch with touch-point offset ``true_dx`` measured through an ECU torque estimate
    ``(1 + gain) T + offset``; the bearing set through the characteristic the TCU applies."""
    for t in torques:
        x_cmd = x_to_for_torque(t / ekf.mu_used, ekf.theta_cs, table, p) + ekf.dx_used
        meas = (1.0 + gain) * outputs(x_cmd - true_dx, TA, table, p).torque + offset
        ekf.accumulate(0.05, 0.0)
        ekf.predict(190.0, 60.0, True)
        ekf.correct(meas, x_cmd, 100.0, True)


def test_nominal_clutch_keeps_the_nominal_characteristic_despite_the_ecu_bias(table):
    p = ClutchParameters()
    ekf = ClutchEkf(TcuNetworkParams(), EkfParams(temperature_update=False), table, p, TA, TA)
    ramp = np.linspace(10, 150, 40)
    for _ in range(3):
        biased_launch(ekf, table, p, 0.0, 0.04, 3.0, ramp)
    assert ekf.dx_kiss < -50e-6                 # the filter's state follows the biased torque ...
    assert not ekf.evidence and ekf.evidence_ratio < ekf.e.evidence_threshold
    assert ekf.dx_used == 0.0 and ekf.mu_used == 1.0          # ... the TCU applies the nominal calibration
    for t in (10.0, 40.0, 90.0, 150.0):
        x = x_to_for_torque(t, TA, table, p)
        assert ekf.used_torque(x) == pytest.approx(outputs(x, TA, table, p).torque, abs=1e-3)   # N.m


def test_a_shift_beyond_the_biases_is_applied_and_a_prior_is_kept(table):
    p = ClutchParameters()
    ekf = ClutchEkf(TcuNetworkParams(), EkfParams(temperature_update=False), table, p, TA, TA)
    ramp = np.linspace(10, 150, 40)
    for _ in range(6):
        biased_launch(ekf, table, p, 0.6e-3, 0.04, 3.0, ramp)
    assert ekf.evidence and ekf.dx_used == ekf.dx_kiss
    assert ekf.dx_kiss == pytest.approx(0.6e-3, abs=0.2e-3)          # with the bias absorbed
    # a standstill-learned touch point as the prior: the same biased launches leave it applied
    ekf2 = ClutchEkf(TcuNetworkParams(), EkfParams(temperature_update=False), table, p, TA, TA)
    ekf2.set_prior(0.4e-3, 40e-6)
    for _ in range(2):
        biased_launch(ekf2, table, p, 0.4e-3, 0.04, 3.0, ramp)
    assert not ekf2.evidence and ekf2.dx_used == 0.4e-3
