"""Clutch thermal network v2: effusivity split, energy conservation, semi-infinite surface rise, exact linear
solution, chain arrays, checked parameters."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from cushion_clutch.errors import ParameterError
from cushion_clutch.model.thermal_network import (FACINGS, N_NODES, NODES, SURFACES, NetworkParams,
                                                   TcuNetworkBase, ThermalNetwork, chain, coefficients,
                                                   node_time_constants, time_constants)

TA = 293.15


def test_effusivity_partition_of_the_slip_heat():
    p = NetworkParams()
    net = ThermalNetwork(p, TA, TA)
    q = net.heat_inputs(1000.0)
    assert sum(q) == pytest.approx(1000.0, rel=1e-14)
    f1, f2 = FACINGS
    s1, s2 = SURFACES
    assert q[f1] == q[f2] and q[s1] == q[s2]
    assert q[f1] / (q[f1] + q[s1]) == pytest.approx(p.facing_share)              # per interface
    assert all(q[i] == 0.0 for i in range(N_NODES) if i not in FACINGS + SURFACES)   # only at the interfaces
    assert 0.05 < p.facing_share < 0.12       # organic facing against cast iron: most heat goes into the metal


def test_chain_arrays_and_derived_values():
    p = NetworkParams()
    caps, links, sink_g, sink_t, shares = chain(p, TA, 300.0, 0.0, True)
    assert len(caps) == len(sink_g) == len(sink_t) == len(shares) == N_NODES == len(NODES)
    assert len(links) == N_NODES - 1
    area = math.pi * (0.12 ** 2 - 0.06 ** 2)
    assert caps[SURFACES[0]] == pytest.approx(7200.0 * 500.0 * area * 1e-3)
    assert sum(caps[:3]) == pytest.approx(p.flywheel_capacity_J_per_K)
    assert sum(caps[5:]) == pytest.approx(p.pressure_plate_capacity_J_per_K)
    # the measured lining (Gkinis et al. 2019, Table A2): k 0.652, c 542, alpha 8.3e-7 -> rho = k / (alpha c)
    rho = 0.652 / (8.3e-7 * 542.0)
    assert rho == pytest.approx(1449.3, abs=0.1)
    assert caps[FACINGS[0]] == pytest.approx(rho * 542.0 * area * 3.5e-3)
    assert caps[FACINGS[0]] == pytest.approx(93.3, abs=0.05)          # issue 37: about 93 J/K, not 261
    e_f, e_m = math.sqrt(0.652 * rho * 542.0), math.sqrt(50.0 * 7200.0 * 500.0)
    assert p.facing_share == pytest.approx(e_f / (e_f + e_m)) and p.facing_share == pytest.approx(0.051, abs=5e-4)
    # facing to metal while clamped: facing half thickness, contact, surface half layer in series
    r = 1.75e-3 / (0.652 * area) + 1.0 / (3000.0 * area) + 0.5e-3 / (50.0 * area)
    assert links[2] == pytest.approx(1.0 / r) and links[4] == pytest.approx(1.0 / r)
    assert chain(p, TA, 300.0, 0.0, False)[1][2] == 0.0
    # the pressure plate turns with the engine, the facings with the disc (0 here: still air)
    assert sink_g[-1] == pytest.approx(0.06 * (10.0 + 50.0))
    assert sink_g[FACINGS[0]] == pytest.approx(0.01 * 10.0)
    assert sink_t[0] == pytest.approx((2.0 * 363.15 + 0.06 * 60.0 * TA) / (2.0 + 0.06 * 60.0))
    assert set(coefficients(p)) == {"caps", "link_always", "link_clamped", "area_cooled", "engine", "shares"}


def test_energy_conservation_heat_in_is_stored_plus_lost():
    """Heat in = stored + lost. The continuous system conserves energy exactly (next test); the Gauss-Seidel
    step does to its splitting error, first order in the step: adiabatic, 40 kJ in, the stored heat is off by
    3.9e-5 (relative) at 10 ms and 1.6e-6 at 1 ms, shrinking with the step towards round-off."""
    p = NetworkParams(engine_W_per_K=0.0, still_air_W_per_m2_K=0.0, rotating_W_per_m2_K=0.0)
    errors = []
    for dt in (1e-2, 1e-3):
        net = ThermalNetwork(p, TA, TA)
        n = int(round(3.0 / dt))
        for k in range(n):
            net.step(dt, 20e3 if k < 2 * n // 3 else 0.0, 190.0, 50.0, k < 5 * n // 6)
        errors.append(abs(net.stored_J / 40e3 - 1.0))
    assert errors[0] < 1e-4 and errors[1] < 1e-5 and errors[1] < errors[0] / 5.0
    # with losses (the engine block at 90 degC feeds heat in): 0.2 ms steps, trapezoidal integral of the
    # sink flows; balance closes to 1.7e-6 of the heat in
    p = NetworkParams()
    net = ThermalNetwork(p, TA, TA)
    lost, dt = 0.0, 2e-4
    _, sink_g, sink_t = net.conductances(190.0, 50.0, True)
    flow = lambda: sum(g * (t - s) for g, t, s in zip(sink_g, net.theta, sink_t))   # noqa: E731
    before = flow()
    for _ in range(10000):
        net.step(dt, 10e3, 190.0, 50.0, True)
        after = flow()
        lost += 0.5 * (before + after) * dt
        before = after
    heat_in = 10e3 * 2.0
    # the engine block at 90 degC feeds heat in: 'lost' includes it (negative flow)
    assert net.stored_J + lost == pytest.approx(heat_in, rel=1e-5)
    assert lost != 0.0


def test_energy_conservation_of_the_linear_system_exact():
    """The continuous system conserves energy exactly: C dtheta/dt summed is P minus the sink flows."""
    p = NetworkParams()
    net = ThermalNetwork(p, TA, TA)
    net.theta = list(np.linspace(300.0, 420.0, N_NODES))
    a, b = net.matrices(150.0, 40.0, True)
    th = np.array(net.theta)
    q = np.array(net.heat_inputs(7e3))
    caps = np.array(net.caps)
    _, sink_g, sink_t = net.conductances(150.0, 40.0, True)
    d_stored = float(caps @ (a @ th + b) + q.sum())
    lost = float(np.dot(sink_g, th - np.array(sink_t)))
    assert d_stored == pytest.approx(7e3 - lost, rel=1e-12, abs=1e-9)


@pytest.mark.parametrize("dt", [1e-3, 1e-2])
def test_surface_rise_matches_the_semi_infinite_body(dt):
    """Constant flux into one metal surface: the 1 mm surface node rises like the semi-infinite body's
    surface, dT = 2 q'' sqrt(t) / (e sqrt(pi)), within 8 % from 0.25 to 5 s (the penetration depth
    sqrt(alpha t) stays within the 1 + 5 mm layers; the node is the layer's mean)."""
    p = NetworkParams()
    net = ThermalNetwork(p, TA, TA)
    net.shares = [0.0] * N_NODES
    net.shares[SURFACES[1]] = 1.0
    q = 10e3
    flux = q / p.area_m2
    worst = 0.0
    n = int(round(5.0 / dt))
    for k in range(1, n + 1):
        net.step(dt, q, 0.0, 0.0, False)
        t = k * dt
        if t >= 0.25 - 1e-12:
            closed = 2.0 * flux * math.sqrt(t) / (p.metal_effusivity_W_s05_per_m2_K * math.sqrt(math.pi))
            worst = max(worst, abs(net.theta[SURFACES[1]] - TA - closed) / closed)
    assert worst < 0.08
    assert net.theta[SURFACES[1]] - TA > 40.0          # the test moves the surface


@pytest.mark.parametrize("clamped", [False, True])
def test_step_matches_solve_ivp_of_the_linear_system(clamped):
    p = NetworkParams()
    net = ThermalNetwork(p, TA, 400.0)
    a, b = net.matrices(190.0, 60.0, clamped)
    q = np.array(net.heat_inputs(5e3)) / np.array(net.caps)
    ref = solve_ivp(lambda t, y: a @ y + b + q, (0.0, 30.0), [400.0] * N_NODES, method="LSODA",
                    rtol=1e-10, atol=1e-8).y[:, -1]
    for _ in range(3000):
        net.step(0.01, 5e3, 190.0, 60.0, clamped)
    assert np.max(np.abs(np.array(net.theta) - ref)) < 0.3       # K, splitting error at 10 ms
    assert np.max(np.abs(ref - 400.0)) > 30.0                    # the test moves the temperatures


def test_steady_state_and_speed_dependent_convection():
    p = NetworkParams()
    net = ThermalNetwork(p, TA, TA)
    a, b = net.matrices(0.0, 0.0, False)
    steady = np.linalg.solve(a, -b)
    assert TA < steady[0] < p.engine_degC + 273.15                   # flywheel between air and block
    assert steady[FACINGS[0]] == pytest.approx(TA)
    assert np.all(steady[5:] == pytest.approx(TA))
    assert p.convection(1.0, 300.0) == pytest.approx(60.0)
    assert p.convection(1.0, 0.0) == 10.0
    slow, fast = time_constants(p, 0.0, 0.0), time_constants(p, 300.0, 300.0)
    assert fast.max() < slow.max()


def test_time_constants_surface_fast_bulk_slow():
    p = NetworkParams()
    nodes = node_time_constants(p, 84.0, 0.0, clamped=False)
    assert nodes["pressure_plate_surface"] < 0.5 < 100.0 < nodes["facing_plate_side"]
    taus = time_constants(p, 84.0, 0.0, clamped=False)
    assert len(taus) == N_NODES and taus.min() > 0 and 600.0 < taus.max() < 5000.0   # cooling: minutes


def test_tcu_network_mismatch_is_the_stated_one():
    p, t = NetworkParams(), TcuNetworkBase()
    assert t.flywheel_capacity_J_per_K / p.flywheel_capacity_J_per_K == pytest.approx(1.15)
    assert t.facing_capacity_J_per_K / p.facing_capacity_J_per_K == pytest.approx(1.15)
    assert t.still_air_W_per_m2_K / p.still_air_W_per_m2_K == pytest.approx(0.8)
    assert t.engine_W_per_K / p.engine_W_per_K == pytest.approx(0.8)


def test_parameters_are_checked():
    with pytest.raises(ParameterError) as err:
        NetworkParams(metal_density_kg_m3=0.0, still_air_W_per_m2_K=-1.0)
    text = str(err.value)
    assert "plant_thermal.metal_density_kg_m3" in text and "plant_thermal.still_air_W_per_m2_K" in text
    with pytest.raises(ParameterError) as err:
        NetworkParams(pressure_plate_capacity_J_per_K=500.0)
    assert "needs a bulk" in str(err.value)
    with pytest.raises(ParameterError) as err:
        NetworkParams(friction_inner_radius_m=0.2)
    assert "friction_inner_radius_m" in str(err.value)
