"""The thermal clutch FMU (``build-fmu --thermal``, CushionClutchThermal) through fmpy: interface, the bar's
twelve slips, a launch replayed in lock-step against the Python plant's network and clutch model, ME vs CS,
FMI 3.0 vs 2.0, and the errors it reports."""
from __future__ import annotations

import functools
import shutil
import tempfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.validation import validate_fmu

from cushion_clutch.benchmarks.thermal_fmu import CsInstance, recorded_launch
from cushion_clutch.cli import main
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.fmu.thermal_chain import chain_of, node_output
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model.thermal_network import NODES, ThermalNetwork
from cushion_clutch.model import ClutchParameters, clutch_model, load_table, outputs, thermal_step

pytestmark = pytest.mark.fmu

NODE_OUTPUTS = [node_output(k) for k in NODES]


@functools.cache
def thermal_fmus() -> dict[int, Path]:
    """{2: FMI 2.0, 3: FMI 3.0} thermal FMUs, built once per session (FMI 2.0 through the CLI)."""
    tmp = Path(tempfile.mkdtemp(prefix="cushion_thermal_tests_"))
    assert main(["build-fmu", "--thermal", "-o", str(tmp / "T2.fmu")]) == 0
    return {2: tmp / "T2.fmu", 3: build_fmu(DEFAULT_TABLES, tmp / "T3.fmu", fmi_version=3, thermal=True)}


@pytest.fixture(scope="module")
def fmus():
    out = thermal_fmus()
    yield out
    shutil.rmtree(out[2].parent, ignore_errors=True)
    thermal_fmus.cache_clear()


def Slave(fmu: Path, start: dict[str, float] | None = None) -> CsInstance:
    """An FMI 2.0 Co-Simulation instance of the thermal FMU, stepped with held inputs."""
    return CsInstance(fmu, start, name="thermal")


def test_interface_and_validation(fmus):
    for version, fmu in fmus.items():
        md = read_model_description(str(fmu))
        causality = {v.name: v.causality for v in md.modelVariables}
        assert causality["omega_slip"] == "input" and causality["x_to"] == "input"
        assert causality["omega_engine"] == "input"
        assert causality["theta_cm"] == "output"
        assert not [v for v in md.modelVariables if v.name == "theta_cm" and v.causality == "input"]
        assert all(causality[n] == "output" for n in ["torque", "theta_cs", *NODE_OUTPUTS])
        assert md.coSimulation.modelIdentifier == md.modelExchange.modelIdentifier == "CushionClutchThermal"
        assert len(md.derivatives) == 1 + len(NODES)            # theta_cs and the nodes are the ME states
        assert validate_fmu(str(fmu)) == [], version


def test_twelve_slips_heat_the_facings_by_a_physical_amount(fmus):
    """The bar: twelve 3 s slips at x_to = 7 mm and 100 rad/s, 60 s apart: theta_cm rises 0.05-0.5 K per kJ
    of slip energy, and falls while the clutch is open."""
    s = Slave(fmus[2])
    h, energy, open_cm = 0.01, 0.0, []
    theta0 = s.step(0.0, ["theta_cm"], x_to=0.0, omega_slip=0.0, omega_engine=100.0)[0]
    try:
        for k in range(int(round(12 * 60.0 / h))):
            slipping = (k * h) % 60.0 < 3.0 - 1e-9
            th, torque, power = s.step(h, ["theta_cm", "torque", "slip_power"], x_to=0.007 if slipping else 0.0,
                                       omega_slip=100.0 if slipping else 0.0, omega_engine=100.0)
            energy += power * h
            if slipping:
                assert torque > 50.0 and power == pytest.approx(torque * 100.0, rel=1e-12)
            else:
                open_cm.append(th)
                assert power == 0.0
            if not slipping and (k * h) % 60.0 > 3.0 + h:   # open: the facings cool, step by step
                assert th < open_cm[-2]
    finally:
        s.close()
    rise_per_kJ = (th - theta0) / (energy / 1e3)
    assert 200e3 < energy < 300e3                          # 12 x 3 s x ~70 N.m x 100 rad/s
    assert 0.05 <= rise_per_kJ <= 0.5, rise_per_kJ


@pytest.fixture(scope="module")
def launch_inputs():
    """Per-step x_to (m), slip and engine speeds (rad/s) of one launch of the default scenario with the plant's
    thermal network on (the plain clutch FMU in the loop), from ``simulate_launches`` recording every step."""
    sc, res = recorded_launch()
    s = res.series
    return sc, s["x_to_m"], s["w_engine_rad_s"] - s["w_disc_rad_s"], s["w_engine_rad_s"], s["theta_cm_K"]


def test_launch_replay_matches_the_python_plant_in_lock_step(fmus, launch_inputs):
    """A launch's inputs through the thermal FMU (CS, the plant's 1 ms step) and through the Python plant's
    own ThermalNetwork and clutch model in the FMU's order: theta_cm, the nodes, theta_cs and the torque
    agree to 1e-9 relative at every step."""
    sc, x_to, w_slip, w_engine, _ = launch_inputs
    h = sc.run.step_s
    theta_a = sc.facing.ambient_degC + 273.15
    theta0 = sc.facing.initial_degC + 273.15
    p = ClutchParameters(theta_a=theta_a, theta_cs_start=theta0)
    table = load_table()
    net = ThermalNetwork(sc.plant_thermal, theta_a, theta0)
    s = Slave(fmus[2], {"theta_a": theta_a, "theta_cs_start": theta0, "theta_network_start": theta0})
    names = ["theta_cm", "theta_cs", "torque", *NODE_OUTPUTS]
    theta_cs, theta_cm = theta0, net.theta_cm
    worst, heat = dict.fromkeys(names, 0.0), 0.0
    try:
        for x, w, we in zip(x_to.tolist(), w_slip.tolist(), w_engine.tolist()):
            got = s.step(h, names, x_to=x, omega_slip=w, omega_engine=we)
            theta_cs = thermal_step(theta_cs, theta_cm, h, p)                  # the plant's order
            o = outputs(x, theta_cs, table, p, theta_cm=theta_cm, omega_slip=w)
            net.step(h, o.torque * abs(w), we, we - w, o.clamp_force > 0.0)
            heat += o.torque * abs(w) * h
            theta_cm = net.theta_cm
            want = [theta_cm, theta_cs, outputs(x, theta_cs, table, p, theta_cm=theta_cm, omega_slip=w).torque,
                    *net.theta]
            for name, g, e in zip(names, got, want):
                worst[name] = max(worst[name], abs(g - e) / max(abs(e), 1.0))
    finally:
        s.close()
    assert heat > 5e3                                         # a real launch: kilojoules of slip
    assert theta_cm > theta0 + 1.0
    print(f"lock-step replay of {len(x_to)} steps: worst relative difference",
          ", ".join(f"{k} {v:.2g}" for k, v in worst.items()))
    assert max(worst.values()) <= 1e-9, worst


def test_model_exchange_follows_co_simulation(fmus):
    """ME (fmpy's CVode on the states theta_cs and the nodes) and CS (exact-exponential steps of 1 ms) on a
    3 s slip and 7 s open: theta_cm and the nodes agree within the CS splitting's first-order error."""
    rows = [(0.0, 0.007, 100.0, 150.0), (3.0, 0.007, 100.0, 150.0), (3.0, 0.0, 0.0, 80.0), (10.0, 0.0, 0.0, 80.0)]
    signals = np.array(rows, dtype=[("time", float), ("x_to", float), ("omega_slip", float), ("omega_engine", float)])
    out = ["theta_cm", "theta_cs", *NODE_OUTPUTS]
    for version, fmu in fmus.items():
        me = simulate_fmu(str(fmu), fmi_type="ModelExchange", input=signals, stop_time=10.0, output_interval=0.5,
                          relative_tolerance=1e-9, output=out)
        cs = simulate_fmu(str(fmu), fmi_type="CoSimulation", input=signals, stop_time=10.0, output_interval=1e-3,
                          output=out)
        for name in out:
            ref = np.interp(me["time"], cs["time"], cs[name])
            assert np.max(np.abs(me[name] - ref)) < 2e-3 * max(1.0, np.ptp(cs[name])), (version, name)
        assert cs["theta_cm"][np.searchsorted(cs["time"], 3.0)] > cs["theta_cm"][0] + 2.0


def test_fmi3_equals_fmi2(fmus):
    rows = [(0.0, 0.006, 80.0, 120.0), (2.0, 0.006, 80.0, 120.0), (2.0, 0.0, 0.0, 90.0), (4.0, 0.0, 0.0, 90.0)]
    signals = np.array(rows, dtype=[("time", float), ("x_to", float), ("omega_slip", float), ("omega_engine", float)])
    out = ["theta_cm", "theta_cs", "torque", "slip_power", *NODE_OUTPUTS]
    a, b = (simulate_fmu(str(fmus[v]), fmi_type="CoSimulation", input=signals, stop_time=4.0, output_interval=0.01,
                         output=out) for v in (2, 3))
    for name in out:
        assert np.allclose(a[name], b[name], rtol=1e-12, atol=0.0), name


def test_parameters_from_the_chain_and_errors(fmus, capfd):
    """Start values are the plant's network; theta_cm cannot be set; shares not adding up to 1 are refused."""
    md = read_model_description(str(fmus[2]))
    start = {v.name: v.start for v in md.modelVariables}
    chain = chain_of()
    for k, c, q in zip(chain.nodes, chain.capacity_J_per_K, chain.heat_share):
        assert float(start[f"C_{k}"]) == c and float(start[f"heat_share_{k}"]) == q
    assert start["theta_cm"] is None
    s = Slave(fmus[2])
    try:
        with pytest.raises(FMICallException):
            s.s.setReal([s.vr["theta_cm"]], [400.0])
    finally:
        s.close()
    capfd.readouterr()
    with pytest.raises(FMICallException, match="fmi2ExitInitializationMode"):    # fmi2Error, logged
        Slave(fmus[2], {f"heat_share_{NODES[0]}": 0.9})
    assert "heat_share_* parameters add up to" in capfd.readouterr().out
    bounds = {v.name: (v.min, v.max) for v in md.modelVariables}
    limit = clutch_model.OMEGA_SLIP_LIMIT
    assert bounds[f"heat_share_{NODES[0]}"] == ("0.0", "1.0")
    assert tuple(map(float, bounds["omega_engine"])) == (-limit, limit)


def test_units_display_and_refusal_hints(fmus, capfd):
    """The thermal FMU shares the clutch FMU's units and hints: lengths shown in mm, K in degC, and a value refused
    for its range says what was probably meant (degC typed as K for a parameter, mm typed as m for an input)."""
    for version, fmu in fmus.items():
        md = read_model_description(str(fmu))
        shown = {v.name: (v.unit, v.displayUnit) for v in md.modelVariables}
        assert shown["x_to"] == ("m", "mm") and shown["theta_cs"] == ("K", "degC"), version
        assert all(d == {"m": "mm", "K": "degC"}.get(u) for u, d in shown.values()), (version, shown)
    capfd.readouterr()
    with pytest.raises(FMICallException, match="fmi2ExitInitializationMode"):
        Slave(fmus[2], {"theta_cs_start": 20.0})
    assert "theta_cs_start = 20 is out of range [200, 800]: did you mean 293.15 K (20 degC)?" in capfd.readouterr().out
    s = Slave(fmus[2])
    try:
        s.s.setReal([s.vr["x_to"]], [12.0])
        with pytest.raises(FMICallException):
            s.s.doStep(0.0, 0.01)
    finally:
        s.close()
    assert "did you mean 0.012 m?" in capfd.readouterr().out


def test_thermal_needs_the_native_backend(tmp_path, capsys):
    assert main(["build-fmu", "--thermal", "--backend", "python", "-o", str(tmp_path / "x.fmu")]) == 2
    assert "thermal = true needs backend 'native'" in capsys.readouterr().err
    assert not (tmp_path / "x.fmu").exists()


def test_saved_state_holds_the_network(fmus):
    """fmi2GetFMUstate / SetFMUstate restore the nodes and theta_cm: the same steps after a rollback give the
    same temperatures, bit for bit."""
    s = Slave(fmus[2])
    names = ["theta_cm", "theta_cs", *NODE_OUTPUTS]
    try:
        for _ in range(50):
            s.step(0.01, names, x_to=0.007, omega_slip=120.0, omega_engine=150.0)
        saved, t_saved = s.s.getFMUstate(), s.t
        first = [s.step(0.01, names, x_to=0.006, omega_slip=90.0, omega_engine=140.0) for _ in range(20)]
        s.s.setFMUstate(saved)
        s.t = t_saved
        again = [s.step(0.01, names, x_to=0.006, omega_slip=90.0, omega_engine=140.0) for _ in range(20)]
        s.s.freeFMUstate(saved)
    finally:
        s.close()
    assert first == again and first[-1][0] > first[0][0]


def test_every_binary_exports_exactly_the_fmi_api(fmus, tmp_path):
    """The thermal FMU's binaries (every platform) export the FMI functions and nothing of the network's glue."""
    import zipfile

    import lief
    from test_native_platforms import EXPECTED, _arch_and_exports, fmi_functions
    seen = set()
    for version, fmu in fmus.items():
        with zipfile.ZipFile(fmu) as z:
            libs = [n for n in z.namelist() if n.startswith("binaries/")]
            z.extractall(tmp_path / f"fmi{version}", libs)
        for name in libs:
            assert name.endswith(("CushionClutchThermal.so", "CushionClutchThermal.dll", "CushionClutchThermal.dylib"))
            binary = lief.parse(str(tmp_path / f"fmi{version}" / name))
            arch, exports = _arch_and_exports(binary)
            assert arch == EXPECTED[name.split("/")[1]][1], name
            assert exports == fmi_functions(version), (name, exports ^ fmi_functions(version))
            seen.add(name.split("/")[1])
    assert seen == set(EXPECTED)


def test_network_steps_do_not_depend_on_the_instance_history(fmus, launch_inputs):
    """The C network keeps its last exp/pow arguments and values between steps (thermal_network.c, TnMemo).
    A launch's second half from a state copied into a fresh instance (empty memo) gives the same bits as the
    instance that ran the whole launch (a warm memo), and a fresh instance gives the same bits as a warm one."""
    sc, x_to, w_slip, w_engine, _ = launch_inputs
    h = sc.run.step_s
    names = ["theta_cm", "theta_cs", "torque", *NODE_OUTPUTS]
    inputs = list(zip(x_to.tolist(), w_slip.tolist(), w_engine.tolist()))
    half = len(inputs) // 2
    whole, first, fresh = Slave(fmus[2]), Slave(fmus[2]), Slave(fmus[2])
    try:
        ref = [whole.step(h, names, x_to=x, omega_slip=w, omega_engine=we) for x, w, we in inputs]
        for x, w, we in inputs[:half]:
            first.step(h, names, x_to=x, omega_slip=w, omega_engine=we)
        fresh.s.setFMUstate(fresh.s.deSerializeFMUstate(first.s.serializeFMUstate(first.s.getFMUstate())))
        fresh.t = first.t
        got = [fresh.step(h, names, x_to=x, omega_slip=w, omega_engine=we) for x, w, we in inputs[half:]]
    finally:
        for s in (whole, first, fresh):
            s.close()
    assert got == ref[half:]                        # bit for bit, every output of every step


def test_mu_is_read_at_the_friction_surface(tmp_path):
    """Issue 37: with a friction table the thermal FMU reads mu at its output theta_friction, the mean of the two
    metal friction surfaces (declared in K with the nodes' range), not at theta_cm: the torque is
    n mu(theta_friction, |omega_slip|) R_eq clamp_force at every step, and during a slip the surfaces run far
    ahead of the facings' mean, so the two lookups differ."""
    from cushion_clutch.model.friction import FrictionTable
    tables = tmp_path / "tables"
    shutil.copytree(DEFAULT_TABLES, tables)
    rows = ["theta_degC,omega_slip_rad_s,mu"] + [f"{t},{w},{mu}" for t, mu in ((0, 0.30), (60, 0.25), (400, 0.20))
                                                 for w in (0, 500)]
    (tables / "friction.csv").write_text("\n".join(rows) + "\n")
    fmu = build_fmu(tables, tmp_path / "T.fmu", thermal=True)
    md = read_model_description(str(fmu))
    tf = next(v for v in md.modelVariables if v.name == "theta_friction")
    assert tf.causality == "output" and tf.unit == "K" and float(tf.min) == 200.0 and float(tf.max) == 1273.15
    table = FrictionTable.from_csv(tables / "friction.csv")
    p = ClutchParameters()
    s = Slave(fmu)
    names = ["torque", "clamp_force", "theta_friction", "theta_cm", "theta_flywheel_surface",
             "theta_pressure_plate_surface"]
    apart = 0.0
    try:
        for k in range(300):                                    # 3 s slip at 150 rad/s
            torque, clamp, tf_k, cm, fs, ps = s.step(0.01, names, x_to=0.007, omega_slip=150.0, omega_engine=200.0)
            assert tf_k == pytest.approx(0.5 * (fs + ps), rel=1e-15)
            expected = p.n_surfaces * table(tf_k - 273.15, 150.0) * p.R_eq * clamp
            assert torque == pytest.approx(expected, rel=1e-12)
            apart = max(apart, abs(table(tf_k - 273.15, 150.0) - table(cm - 273.15, 150.0)))
    finally:
        s.close()
    assert tf_k - cm > 5.0 and apart > 0.005        # 3 s at ~10 kW: the surface 9 K ahead, mu 0.0077 apart

# ------------------------------------------------------------ refusals (issue 39)
class Logged:
    """An FMI 2.0 instance of the thermal FMU (CS, or ME with ``me``) whose log messages are kept in ``messages``
    ((status, text)), initialised with ``start``; calls raise fmpy's FMICallException on Discard and worse."""

    def __init__(self, fmu: Path, start: dict[str, float] | None = None, me: bool = False):
        from ctypes import byref

        from fmpy import extract
        from fmpy.fmi2 import (FMU2Model, FMU2Slave, defaultCallbacks, fmi2CallbackFunctions,
                               fmi2CallbackLoggerTYPE)
        from fmpy.logging import addLoggerProxy
        md = read_model_description(str(fmu))
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.messages: list[tuple[int, str]] = []
        self.cb = fmi2CallbackFunctions()
        self.cb.logger = fmi2CallbackLoggerTYPE(lambda c, n, st, cat, msg: self.messages.append((st, msg.decode())))
        self.cb.allocateMemory, self.cb.freeMemory = defaultCallbacks.allocateMemory, defaultCallbacks.freeMemory
        addLoggerProxy(byref(self.cb))                     # formats the FMU's "%s" messages
        self.unzip = extract(str(fmu))
        cls = FMU2Model if me else FMU2Slave
        self.s = cls(guid=md.guid, unzipDirectory=self.unzip, modelIdentifier="CushionClutchThermal",
                     instanceName="refusals")
        self.s.instantiate(callbacks=self.cb)
        self.s.setupExperiment(startTime=0.0)
        if start:
            self.s.setReal([self.vr[k] for k in start], list(start.values()))
        self.s.enterInitializationMode()

    def get(self, names):
        return self.s.getReal([self.vr[k] for k in names])

    def close(self):
        self.s.freeInstance()
        shutil.rmtree(self.unzip, ignore_errors=True)


def _kelvin_outputs(md) -> dict[str, float]:
    return {v.name: float(v.max) for v in md.modelVariables if v.unit == "K" and v.causality == "output"}


def test_every_kelvin_output_and_node_declares_one_range_at_most_1000_degC(fmus):
    from cushion_clutch.fmu.thermal_chain import NODE_RANGE
    for version, fmu in fmus.items():
        md = read_model_description(str(fmu))
        maxima = _kelvin_outputs(md)                      # float(None) would fail: every one declares a max
        assert set(NODE_OUTPUTS) | {"theta_cm", "theta_cs"} <= set(maxima)
        assert max(maxima.values()) <= 1273.15, maxima
        bounds = {v.name: (v.min, v.max) for v in md.modelVariables}
        for name in NODE_OUTPUTS:
            assert tuple(map(float, bounds[name])) == NODE_RANGE[:2], (version, name)
        assert tuple(map(float, bounds["theta_network_start"])) == (clutch_model.THETA_MIN_K, clutch_model.THETA_MAX_K)
        for k in NODES:                                   # capacities: a declared min > 0
            assert float(bounds[f"C_{k}"][0]) > 0.0 and bounds[f"C_{k}"][1] is not None, k


@pytest.mark.parametrize("theta0", [150.0, 900.0])
def test_theta_network_start_outside_its_range_is_refused_at_initialisation(fmus, theta0):
    s = Logged(fmus[2], {"theta_network_start": theta0})
    try:
        with pytest.raises(FMICallException):
            s.s.exitInitializationMode()
    finally:
        s.close()
    assert any(st == 3 and f"theta_network_start = {theta0:.17g}" in m and "[200, 800]" in m
               for st, m in s.messages), s.messages


def test_huge_slip_refused_steps_roll_back_and_the_instance_recovers(fmus):
    """The bar: 470 kW of slip (x_to 12 mm, omega_slip = omega_engine = 1500 rad/s) for 10 s of the host's clock in
    10 ms steps, then the clutch open for 600 s. A refused step returns Discard with one message, leaves every node,
    theta_cs, theta_cm, the outputs and LastSuccessfulTime at the step's start, does not set Terminated, and the
    next acceptable step proceeds; no output in K is ever reported above its declared maximum with OK."""
    s = Logged(fmus[2])
    s.s.exitInitializationMode()
    maxima = _kelvin_outputs(s.md)
    names = list(maxima)
    t, h, refused, taken, before = 0.0, 0.01, 0, 0, None
    try:
        def attempt(x_to, w, step):
            nonlocal t, refused, taken, before
            s.s.setReal([s.vr["x_to"], s.vr["omega_slip"], s.vr["omega_engine"]], [x_to, w, w or 100.0])
            n = len(s.messages)
            try:
                s.s.doStep(t, step)
            except FMICallException as e:
                assert e.status == 2                      # Discard, never Error
                refused += 1
                new = [m for st, m in s.messages[n:] if st == 2]
                assert len(new) == 1 and ("K is not finite or outside [200, 1273.15] K; step refused" in new[0]
                                          or "the facing temperature theta_cm = " in new[0]
                                          and "K (the facing nodes' mean) is outside [200, 800] K; step refused"
                                          in new[0]), new          # a node or the facings' mean: what passes first
                assert s.get(names) == before             # the whole state stays at the step's start
                assert s.s.getRealStatus(2) == last_ok_time and s.s.getBooleanStatus(3) is False
            else:
                taken += 1
                before = s.get(names)
                for name, v in zip(names, before):
                    assert v <= maxima[name], (t, name, v)
                globals_["last"] = t + step
            t += step                                     # the host's clock goes on
        globals_ = {"last": 0.0}
        last_ok_time = 0.0
        while t < 10.0 - 1e-9:
            last_ok_time = globals_["last"]
            attempt(0.012, 1500.0, h)
        hot = dict(zip(names, before))
        assert refused > 100 and taken > 100, (refused, taken)
        refused_hot, taken_hot = refused, taken
        while t < 610.0 - 1e-9:
            last_ok_time = globals_["last"]
            attempt(0.0, 0.0, 0.1)
        assert refused == refused_hot and taken - taken_hot == 6000      # every open step is taken
        cold = dict(zip(names, s.get(names)))
    finally:
        s.close()
    print("hottest node at the first refusal:", max((v, k) for k, v in hot.items() if k in NODE_OUTPUTS),
          f"; {refused} refused steps; after 600 s open:", {k: round(v, 1) for k, v in cold.items()})
    assert all(cold[k] < hot[k] - 100.0 for k in ("theta_flywheel_surface", "theta_pressure_plate_surface"))


def test_model_exchange_checks_the_nodes_as_co_simulation(fmus):
    """fmi2SetContinuousStates with a node past its declared maximum: Discard with the same message as a refused
    CS step, and the states stay as they were; at the maximum itself: accepted."""
    s = Logged(fmus[2], me=True)
    try:
        s.s.exitInitializationMode()
        s.s.enterContinuousTimeMode()
        import ctypes
        n = 1 + len(NODES)
        buf = (ctypes.c_double * n)()
        s.s.getContinuousStates(buf, n)
        x = list(buf)
        hot = list(x)
        hot[1 + NODES.index("flywheel_surface")] = 1273.16
        with pytest.raises(FMICallException) as e:
            s.s.setContinuousStates((ctypes.c_double * n)(*hot), n)
        assert e.value.status == 2
        assert "theta_flywheel_surface = 1273.1600000000001 K is not finite or outside [200, 1273.15] K; states " \
               "not set" in s.messages[-1][1]
        s.s.getContinuousStates(buf, n)
        assert list(buf) == x
        hot[1 + NODES.index("flywheel_surface")] = 1273.15
        s.s.setContinuousStates((ctypes.c_double * n)(*hot), n)
        s.s.getContinuousStates(buf, n)
        assert list(buf) == hot
    finally:
        s.close()


@pytest.mark.parametrize("node, value", [("theta_facing_flywheel_side", -5.0), ("theta_flywheel_bulk", 1e6)])
def test_crafted_states_with_nodes_out_of_range_are_refused(fmus, node, value):
    import struct

    from thermal_fault_cases import seal     # the checksum recomputed, as the fault catalogue crafts its states
    s = Logged(fmus[2])
    try:
        s.s.exitInitializationMode()
        s.s.setReal([s.vr["x_to"], s.vr["omega_slip"], s.vr["omega_engine"]], [0.007, 100.0, 100.0])
        s.s.doStep(0.0, 0.01)
        before = s.get(["theta_cm", *NODE_OUTPUTS])
        blob = bytearray(s.s.serializeFMUstate(s.s.getFMUstate()))
        at = 40 + 8 * s.vr[node]                          # header, then r[] by value reference
        blob[at:at + 8] = struct.pack("<d", value)
        with pytest.raises(FMICallException):
            s.s.deSerializeFMUstate(seal(blob))
        assert f"{node} = {value:.17g} K is not finite or outside [200, 1273.15] K; state refused" in s.messages[-1][1]
        assert s.get(["theta_cm", *NODE_OUTPUTS]) == before
        s.s.doStep(0.01, 0.01)                            # still stepping
    finally:
        s.close()


def test_the_docs_state_the_enforced_ranges():
    """docs/reference/thermal_fmu.md states the ranges the code declares and enforces."""
    from cushion_clutch.fmu.thermal_chain import CAPACITY_RANGE, GLOBALS, NODE_RANGE
    text = (Path(__file__).parents[1] / "docs" / "reference" / "thermal_fmu.md").read_text()
    lo, hi = GLOBALS["theta_network_start"][2][:2]
    for statement in (f"**[{NODE_RANGE[0]:g}, {NODE_RANGE[1]:g}] K**", f"`theta_network_start` must lie in [{lo:g}, "
                      f"{hi:g}] K", f"in [{CAPACITY_RANGE[0]:g}, {CAPACITY_RANGE[1]:g}] J/K",
                      f"**[{clutch_model.THETA_MIN_K:g}, {clutch_model.THETA_MAX_K:g}] K**"):
        assert statement in text, statement
    assert "(0, 2000) K" not in text
