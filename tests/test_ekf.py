"""The production TCU's EKF: thermal prediction against the plant network, touch-point and mu learning, gating."""
import dataclasses

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.model import load_table
from cushion_clutch.model import ClutchParameters, outputs, thermal_step, x_to_for_torque
from cushion_clutch.launch.tcu.ekf import IX_DX, IX_HEAT, IX_LOSS, ClutchEkf, EkfParams, TcuNetworkParams
from cushion_clutch.model.thermal_network import NetworkParams, ThermalNetwork

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
    with pytest.raises(ParameterError) as err:
        EkfParams(scale_min=0.0, loss_scale_sd=-0.1)
    assert "ekf.scale_min" in str(err.value) and "ekf.loss_scale_sd" in str(err.value)


def network_pair(tcu_loss_factor):
    """The plant's physical network and the TCU's copy with every heat-loss conductance (still air,
    rotating, engine block) times ``tcu_loss_factor`` (everything else matched)."""
    plant, matched = matched_network()
    tcu = dataclasses.replace(matched, still_air_W_per_m2_K=plant.still_air_W_per_m2_K * tcu_loss_factor,
                              rotating_W_per_m2_K=plant.rotating_W_per_m2_K * tcu_loss_factor,
                              engine_W_per_K=plant.engine_W_per_K * tcu_loss_factor)
    return plant, tcu


def hot_launches_then_cool_down(table, e, tcu_loss_factor, hot=8, cool=3):
    """Launches of 3 s slip at 150 rad/s (10 to 150 N.m, then 150 N.m) every 60 s, then every 300 s;
    the measured torque is the exact model at the plant's temperatures. Returns the EKF and the
    theta_cs error (estimate minus truth) at the start of every launch, K."""
    plant, tcu = network_pair(tcu_loss_factor)
    p = ClutchParameters()
    net = ThermalNetwork(plant, TA, TA)
    ekf = ClutchEkf(tcu, e, table, p, TA, TA)
    theta_cs, errors, dt, w_slip = TA, [], 0.1, 150.0
    ramp = np.concatenate([np.linspace(10.0, 150.0, 20), np.full(10, 150.0)])
    for period in [60.0] * hot + [300.0] * cool:
        errors.append(ekf.theta_cs - theta_cs)
        for k in range(int(round(period / dt))):
            launching = k < len(ramp)
            pw = 0.0
            if launching:
                x = x_to_for_torque(ramp[k] / ekf.mu_scale, ekf.theta_cs, table, p, theta_cm=ekf.theta_cm) \
                    + ekf.dx_kiss
                torque = outputs(x, theta_cs, table, p, net.theta_cm).torque
                pw = torque * w_slip
            net.step(dt, pw, 190.0, 190.0 - w_slip if launching else 190.0, launching)
            theta_cs = thermal_step(theta_cs, net.theta_cm, dt, p)
            ekf.accumulate(dt, pw)
            ekf.predict(190.0, 190.0 - w_slip if launching else 190.0, launching)
            if launching:
                ekf.correct(torque, x, w_slip, True)
    return ekf, errors


def test_augmented_ekf_learns_a_heat_loss_mismatch(table):
    """The TCU's network loses 20 % too little heat (true loss scale 1.25): the scale moves towards it from
    the torque (through the temperatures' covariance with it) and cuts the cool-down error. On the physical
    network (most heat in the metal, cooling over minutes) the error it corrects is a few kelvin only, so the
    scale is learned in part (1.10 after eight launches and three cool-downs)."""
    e = EkfParams(torque_sd_Nm=0.5)                 # the synthetic torque is exact: a good torque sensor
    ekf, err = hot_launches_then_cool_down(table, e, 0.8)
    fixed, err_fixed = hot_launches_then_cool_down(table, dataclasses.replace(e, loss_scale_sd=0.0), 0.8)
    assert fixed.loss_scale == 1.0
    assert 1.05 < ekf.loss_scale < 1.35
    assert np.sqrt(ekf.P[IX_LOSS, IX_LOSS]) < 0.85 * e.loss_scale_sd         # it was informative
    cool = slice(-3, None)                          # the cool-down launches
    assert max(abs(x) for x in err_fixed[cool]) > 4.0                      # K: the wrong losses, unlearned
    assert max(abs(x) for x in err[cool]) < 0.8 * max(abs(x) for x in err_fixed[cool])


def test_matched_network_keeps_its_scales(table):
    ekf, err = hot_launches_then_cool_down(table, EkfParams(torque_sd_Nm=0.5), 1.0, hot=4, cool=1)
    assert ekf.loss_scale == pytest.approx(1.0, abs=0.05) and ekf.heat_scale == pytest.approx(1.0, abs=0.05)
    assert max(abs(x) for x in err) < 2.0


def test_temperatures_are_corrected_only_above_their_torque(table):
    """Near the kiss point a temperature error looks like a touch-point offset: only dx moves there."""
    p = ClutchParameters()
    for torque, thermal in ((20.0, False), (120.0, True)):
        ekf = ClutchEkf(TcuNetworkParams(), EkfParams(), table, p, TA, TA + 100.0)
        for _ in range(100):                        # 10 s of cooling: the losses' covariance with the temperatures
            ekf.accumulate(0.1, 0.0)
            ekf.predict(190.0, 190.0, True)
        x = x_to_for_torque(torque, ekf.theta_cs, table, p, theta_cm=ekf.theta_cm)
        assert ekf.model_torque(x) == pytest.approx(torque, abs=0.5)
        s0 = ekf.s.copy()
        assert ekf.correct(torque + 3.0, x, 100.0, True)
        assert (not np.array_equal(ekf.s[:5], s0[:5])) == thermal
        assert (ekf.s[IX_LOSS] != s0[IX_LOSS]) == thermal          # facings 100 K above ambient
        assert ekf.s[IX_DX] != s0[IX_DX] or torque > EkfParams().touch_torque_max_Nm


def test_discretisation_matches_scipy_expm():
    """The EKF's scaling-and-squaring exponential of its network (9 temperatures, surface layers at 0.2 s)."""
    from scipy.linalg import expm

    from cushion_clutch.launch.tcu.ekf import N_T, _exp_and_integral

    table = load_table()
    ekf = ClutchEkf(TcuNetworkParams(), EkfParams(), table, ClutchParameters(), TA, TA)
    a_link, a_sink, _, _ = ekf._parts(190.0, 60.0, True)
    a = a_link + np.diag(1.3 * a_sink)
    for dt in (0.01, 0.1, 1.0):
        phi, psi = _exp_and_integral(a, dt)
        aug = np.zeros((2 * N_T, 2 * N_T))
        aug[:N_T, :N_T], aug[:N_T, N_T:] = a * dt, np.eye(N_T) * dt
        ref = expm(aug)
        assert np.max(np.abs(phi - ref[:N_T, :N_T])) < 1e-12
        assert np.max(np.abs(psi - ref[:N_T, N_T:])) < 1e-12 * dt


def capacity_mismatch_run(table, k_heat, capacity_factor=1.15):
    """Four 3 s slips at 30 kW every 60 s, then a 10 min cool-down, on a plant whose every heat capacity is
    ``1 / capacity_factor`` of the TCU's network (matched otherwise); the TCU predicts only (``k_heat`` held).
    Returns the facing-temperature error (estimate minus plant, K) every EKF period."""
    plant, tcu = matched_network()
    net = ThermalNetwork(plant, TA, TA)
    net.caps = [c / capacity_factor for c in net.caps]
    ekf = ClutchEkf(tcu, EkfParams(), table, ClutchParameters(), TA, TA)
    ekf.s[IX_HEAT] = k_heat
    errors = []
    for k in range(8400):                          # 4 x 60 s + 600 s at 0.1 s
        t = (k % 600) * 0.1 if k < 2400 else 99.0
        slip = t < 3.0
        pw, w_disc = (30e3, 40.0) if slip else (0.0, 0.0)
        for _ in range(10):                       # the plant at 10 ms
            net.step(0.01, pw, 190.0, w_disc, slip)
        ekf.accumulate(0.1, pw)
        ekf.predict(190.0, w_disc, slip)
        errors.append(ekf.theta_cm - net.theta_cm)
    return np.array(errors)


def test_the_heat_scale_is_the_networks_inverse_heat_capacity(table):
    """A heat-capacity error changes how fast the clutch cools as much as how fast it heats: with the heat scale
    at the capacity ratio the TCU's network follows the plant through four hot slips and a 10 min cool-down
    (when the scale multiplied the slip heat only, it heated right and cooled 15 % too slowly: 2.1 K off at the
    end of the cool-down, and growing)."""
    err = capacity_mismatch_run(table, 1.15)
    unscaled = capacity_mismatch_run(table, 1.0)
    assert max(abs(unscaled)) > 8.0                         # the mismatch matters (K)
    assert max(abs(err)) < 0.05                              # K: the discretisation only


def test_a_facing_estimate_beyond_the_models_range_does_not_stop_the_tcu(table):
    """On heavy duty without protection the estimate can pass the clutch model's 800 K ceiling (the plant's
    facings at 470 degC, the estimate's Jacobian step 1 K above): the model is evaluated at the ceiling,
    and the update runs."""
    p = ClutchParameters()
    ekf = ClutchEkf(TcuNetworkParams(), EkfParams(), table, p, TA, 799.5)
    assert ekf.theta_cm_model == 799.5
    ekf.s[:9] = 850.0
    assert ekf.theta_cm_model == 800.0
    x = x_to_for_torque(120.0, table.theta_max_K, table, p, theta_cm=800.0)
    assert np.isfinite(ekf.model_torque(x))
    assert ekf.correct(ekf.model_torque(x) + 1.0, x, 100.0, True)
