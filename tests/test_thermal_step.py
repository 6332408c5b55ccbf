"""The one thermal step in C (fmu_src/core/thermal_step.c, ``tn_chain_step``) against its Python reference
(``model.thermal_network.ThermalNetwork.step``), to the bit: compiled alone with the host libraries' flags over a
scan of states and inputs, and inside the thermal FMU (CushionClutchThermal) over a run of steps. The launch
plant's library calls the same function (fmu_src/hosts/launch_plant.c); tests/test_launch_plant_block.py and
tests/test_launch_golden.py hold its series to the Python loop's."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from cushion_clutch.fmu.hostlib import EXACT_FLAGS, HostLibrary
from cushion_clutch.model.thermal_network import NODES, NetworkParams, ThermalNetwork

#: thermal_step.c alone, its function exported (the host libraries hide all but their API)
STEP = HostLibrary("thermal_step", ("thermal_step.c",), ("thermal_step.h",),
                   extra_flags=(*EXACT_FLAGS, "-fvisibility=default"))


def c_step(net: ThermalNetwork, dt: float, p_slip: float, w_engine: float, w_disc: float, clamped: bool) -> list:
    """``net.step``'s arguments through the C step: the nodes' constants as the launch plant takes them
    (``ThermalNetwork._prepare``), the convection coefficients as ``ThermalNetwork.step`` computes them."""
    ffi, lib = STEP.load()
    nodes, h0, hr, wr = net._prepare(clamped, dt)
    table = ffi.new("TnNode[]", len(nodes))
    for (i, cap, gl, gr, area, on_disc, ge_te, gfix, share, decay), q in zip(nodes, table):
        q.cap, q.gl, q.gr, q.area, q.on_disc, q.ge_te, q.gfix, q.share = cap, gl, gr, area, on_disc, ge_te, gfix, share
        q.fixed, q.decay = (0.0, 0.0) if decay is None else (1.0, decay)
    th = ffi.new("double[]", list(net.theta))
    h_engine = h0 + hr * (abs(w_engine) / wr) ** 0.8
    h_disc = h0 + hr * (abs(w_disc) / wr) ** 0.8
    lib.tn_chain_step(table, len(nodes), th, dt, p_slip, h_engine, h_disc, net.theta_a)
    return list(th)


def test_c_step_equals_the_python_step_to_the_bit_over_a_scan():
    """2000 random states (every node 250 .. 700 K), slip powers (0 .. 80 kW), engine and disc speeds
    (-700 .. 700 rad/s), clamp states and steps (1 ms .. 1 s), on the default network and on one with every
    conductance and capacity drawn anew: every node's new temperature is the same float in C and Python."""
    rng = np.random.default_rng(40)
    default = NetworkParams()
    fields = {f.name: getattr(default, f.name) for f in dataclasses.fields(default)
              if isinstance(getattr(default, f.name), float) and f.name.endswith(("W_per_K", "J_per_K", "m2"))}
    drawn = dataclasses.replace(default, **{k: v * rng.uniform(0.5, 2.0) for k, v in fields.items()})
    moved = 0
    for params in (default, drawn):
        for k in range(1000):
            net = ThermalNetwork(params, float(rng.uniform(240.0, 320.0)), 300.0)
            net.theta[:] = rng.uniform(250.0, 700.0, len(NODES)).tolist()
            start = list(net.theta)
            args = (float(rng.choice([1e-3, 1e-2, 0.1, 1.0])), float(rng.uniform(0.0, 8e4)) * (k % 5 != 0),
                    float(rng.uniform(-700.0, 700.0)), float(rng.uniform(-700.0, 700.0)), bool(k % 2))
            got = c_step(net, *args)
            net.step(*args)
            assert got == net.theta, (k, args)          # bit for bit, every node
            moved += sum(a != b for a, b in zip(start, got))
    assert moved > 0.9 * 2000 * len(NODES)              # the steps did something to compare


@pytest.mark.fmu
def test_the_thermal_fmu_steps_its_nodes_as_the_python_network_to_the_bit(tmp_path):
    """The thermal FMU's network (tn_step over the same C step), with no slip power (omega_slip = 0, so the clutch
    adds nothing that the Python model computes its own way), engine speeds changing every step and the clutch
    clamped or open: after each of 400 steps every node is the same float as ThermalNetwork.step's."""
    from cushion_clutch.benchmarks.thermal_fmu import CsInstance
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.crossbuild import HOST
    from cushion_clutch.fmu.native import build_native_fmu
    from cushion_clutch.fmu.thermal_chain import chain_of, node_output
    fmu = build_native_fmu(DEFAULT_TABLES, tmp_path / "T.fmu", 2, platforms=(HOST[2],), chain=chain_of())
    theta_a, theta0 = 300.0, 420.0
    net = ThermalNetwork(NetworkParams(), theta_a, theta0)
    s = CsInstance(fmu, {"theta_a": theta_a, "theta_cs_start": theta0, "theta_network_start": theta0})
    names = ["clamp_force", "slip_power", *(node_output(k) for k in NODES)]
    rng = np.random.default_rng(7)
    h, clamped_steps = 0.01, 0
    try:
        for k in range(400):
            x_to = 0.0 if (k // 50) % 2 == 0 else 0.009          # clamped, then open, every 50 steps
            w = float(rng.uniform(80.0, 600.0))
            got = s.step(h, names, x_to=x_to, omega_slip=0.0, omega_engine=w)
            assert got[1] == 0.0
            clamped = got[0] > 0.0
            clamped_steps += clamped
            net.step(h, 0.0, w, w, clamped)
            assert got[2:] == net.theta, k
    finally:
        s.close()
    assert 0 < clamped_steps < 400
    assert abs(net.theta[0] - theta0) > 1.0                   # the nodes moved
