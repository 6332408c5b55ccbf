"""Plant thermal network: effusivity split, energy balance, exact linear solution, checked parameters."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cushion_clutch.errors import ParameterError
from cushion_clutch.launch.thermal_network import (NetworkParams, ThermalNetwork, node_time_constants,
                                                   time_constants)

TA = 293.15


def test_effusivity_partition_of_the_slip_heat():
    p = NetworkParams()
    net = ThermalNetwork(p, TA, TA)
    q = net.heat_inputs(1000.0)
    assert sum(q) == pytest.approx(1000.0)
    assert q[1] == q[2] and q[0] == q[3]
    ef, em = p.facing_effusivity_W_s05_per_m2_K, p.metal_effusivity_W_s05_per_m2_K
    assert q[1] / (q[1] + q[0]) == pytest.approx(ef / (ef + em))   # per interface
    assert 0.05 < p.facing_share < 0.12       # organic facing against cast iron: most heat goes into the metal


def test_adiabatic_network_stores_all_slip_energy():
    p = NetworkParams(engine_W_per_K=0.0, flywheel_convection_W_per_K=0.0, pressure_plate_convection_W_per_K=0.0,
                      facing_convection_W_per_K=0.0)
    net = ThermalNetwork(p, TA, TA)
    for _ in range(2000):
        net.step(1e-3, 20e3, 190.0, 50.0, True)
    stored = float(np.dot(p.capacities, np.array(net.theta) - TA))
    assert stored == pytest.approx(20e3 * 2.0, rel=1e-5)     # the splitting is not exactly conservative


@pytest.mark.parametrize("clamped", [False, True])
def test_step_matches_solve_ivp_of_the_linear_system(clamped):
    p = NetworkParams()
    net = ThermalNetwork(p, TA, 400.0)
    a, b = net.matrices(190.0, 60.0, clamped)
    q = np.array(net.heat_inputs(5e3)) / p.capacities
    ref = solve_ivp(lambda t, y: a @ y + b + q, (0.0, 30.0), [400.0] * 4, rtol=1e-10, atol=1e-8).y[:, -1]
    for _ in range(3000):
        net.step(0.01, 5e3, 190.0, 60.0, clamped)
    assert np.max(np.abs(np.array(net.theta) - ref)) < 0.05      # K, splitting error at 10 ms
    assert np.max(np.abs(ref - 400.0)) > 10.0                    # the test moves the temperatures


def test_steady_state_and_speed_dependent_convection():
    p = NetworkParams()
    net = ThermalNetwork(p, TA, TA)
    a, b = net.matrices(0.0, 0.0, False)
    steady = np.linalg.solve(a, -b)
    assert steady[0] > TA and steady[0] < p.engine_degC + 273.15      # flywheel between air and block
    assert steady[1:] == pytest.approx([TA] * 3)
    assert p.convection(1.0, 300.0) == pytest.approx(4.0)
    assert p.convection(1.0, 0.0) == 1.0
    slow, fast = time_constants(p, 0.0, 0.0), time_constants(p, 300.0, 300.0)
    assert np.all(fast < slow)


def test_time_constants_are_eigen_and_node_values():
    p = NetworkParams()
    taus = time_constants(p, 0.0, 0.0, clamped=False)
    nodes = node_time_constants(p, 0.0, 0.0, clamped=False)
    # open clutch at rest: facings decoupled from the metal: C_f / (G_conv + G_disc)
    assert nodes["facing_plate_side"] == pytest.approx(190.0 / (0.3 + 0.5))
    assert nodes["pressure_plate"] == pytest.approx(1500.0 / 1.5)
    assert len(taus) == 4 and taus.min() > 0
    assert taus.max() == pytest.approx(1500.0 / 1.5)            # the pressure plate alone is a mode


def test_parameters_are_checked():
    with pytest.raises(ParameterError) as err:
        NetworkParams(facing_capacity_J_per_K=0.0, convection_gain_at_reference=0.5)
    text = str(err.value)
    assert "plant_thermal.facing_capacity_J_per_K" in text and "plant_thermal.convection_gain_at_reference" in text
