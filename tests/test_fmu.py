"""The built CushionClutch FMU, simulated with fmpy (committed default tables)."""
import math
import os
import resource
import shutil

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
from scipy.interpolate import PchipInterpolator

from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.model import load_table
from cushion_clutch.model.cover import CoverMap, CoverParameters
from cushion_clutch.model.table_format import read_tables

pytestmark = pytest.mark.fmu

OUT = ["torque", "force", "theta_cs", "u_f", "x_kiss"]


@pytest.fixture(scope="module")
def fmu(tmp_path_factory):
    path = build_fmu(DEFAULT_TABLES, tmp_path_factory.mktemp("fmu") / "CushionClutch.fmu", backend="python")
    md = read_model_description(str(path))
    unzip = extract(str(path))
    yield path, md, unzip
    shutil.rmtree(unzip, ignore_errors=True)


@pytest.fixture(scope="module")
def tables():
    return read_tables(DEFAULT_TABLES)


class Instance:
    """A started FMU instance with name-based access."""

    def __init__(self, fmu, name="clutch", **start):
        path, md, unzip = fmu
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.s = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                           modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.s.instantiate(loggingOn=True)
        self.start(**start)
        self.t = 0.0

    def start(self, **start):
        self.s.setupExperiment(startTime=0.0)
        if start:
            self.set(**start)
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()

    def set(self, **values):
        self.s.setReal([self.vr[k] for k in values], list(values.values()))

    def get(self, *names):
        vals = self.s.getReal([self.vr[n] for n in names])
        return vals[0] if len(names) == 1 else dict(zip(names, vals))

    def step(self, h):
        self.s.doStep(self.t, h)
        self.t += h

    def close(self):
        self.s.terminate()
        self.s.freeInstance()


def test_fmpy_validate_is_clean(fmu):
    assert validate_fmu(str(fmu[0])) == []


def test_units_are_declared(fmu):
    md = fmu[1]
    units = {v.name: (v.unit, v.displayUnit) for v in md.modelVariables}
    assert units["x_to"][0] == "m" and units["torque"][0] == "N.m" and units["force"][0] == "N"
    assert units["theta_cm"] == ("K", "degC") and units["theta_cs"] == ("K", "degC")
    assert units["U"][0] == "W/K" and units["C"][0] == "J/K"
    k = {u.name: u for u in md.unitDefinitions}["K"]
    assert k.displayUnits[0].name == "degC" and k.displayUnits[0].offset == -273.15
    # lengths are shown in mm (issue 41): x_to = 0.012 m reads 12 mm in a host; every K variable keeps degC
    m = {u.name: u for u in md.unitDefinitions}["m"]
    assert m.displayUnits[0].name == "mm" and m.displayUnits[0].factor == 1000.0
    assert units["x_to"] == ("m", "mm") and units["x_kiss"] == ("m", "mm") and units["facing_wear"] == ("m", "mm")
    assert all(d == ("degC" if u == "K" else "mm" if u == "m" else None) for u, d in units.values()), units


@pytest.mark.parametrize("h", [1e-3, 0.1, 5.0])
def test_theta_cm_step_matches_closed_form(fmu, h):
    inst = Instance(fmu)
    U, H, C, theta_a = 0.1, 0.04, 1.0, 293.15
    theta_cm = 493.15
    inst.set(theta_cm=theta_cm)
    gain, tau = U / (U + H), C / (U + H)
    assert tau == pytest.approx(7.142857, rel=1e-6)
    theta_inf = gain * theta_cm + (1 - gain) * theta_a
    n = int(round(30.0 / h))
    worst = 0.0
    for k in range(1, n + 1):
        inst.step(h)
        exact = theta_inf + (theta_a - theta_inf) * math.exp(-k * h / tau)
        worst = max(worst, abs(inst.get("theta_cs") / exact - 1))
    assert worst < 1e-9
    inst.close()


def test_torque_equals_n_mu_r_f_from_the_table(fmu, tables):
    """At table temperatures and table u points the FMU returns the CSV force exactly."""
    n, mu, r = 2.0, 0.28, 0.089
    for theta, u, f, d in zip(tables.theta_degC, tables.u_m, tables.force_N, tables.delta_kiss_m):
        inst = Instance(fmu, theta_cs_start=theta + 273.15)
        # bearing position of cushion compression u through the cover's balance (the Python reference)
        frame = CoverMap(CoverParameters(), 3.0).prepare(theta + 273.15, theta + 273.15, 0.0, load_table(), 0.004)
        x_of_u = lambda v: frame.x_of(frame.s_kiss - v / frame.g.kp)  # noqa: E731
        for i in np.linspace(0, len(u) - 1, 9).astype(int):
            inst.set(x_to=x_of_u(u[i]) if i < len(u) - 1 else frame.x_solid, theta_cm=theta + 273.15)
            inst.step(0.0)
            got = inst.get(*OUT)
            assert got["force"] == pytest.approx(f[i], rel=1e-9, abs=1e-9)
            assert got["torque"] == pytest.approx(n * mu * r * f[i], rel=1e-9, abs=1e-9)
            assert got["u_f"] == pytest.approx(max(u[i], 0.0), abs=1e-14)
        # between table points: SciPy's PCHIP of the same rows
        um = 0.5 * (u[len(u) // 2] + u[len(u) // 2 + 1])
        inst.set(x_to=x_of_u(um))
        inst.step(0.0)
        assert inst.get("force") == pytest.approx(float(PchipInterpolator(u, f)(um)), rel=1e-9)
        # past full compression the cushion force stays at its full-compression value (the clamp rises on)
        inst.set(x_to=frame.x_solid + 1e-3)
        inst.step(0.0)
        assert inst.get("force") == pytest.approx(f[-1], rel=1e-12)
        assert inst.get("torque") == pytest.approx(n * mu * r * frame.clamp_installed(), rel=1e-12)
        inst.close()


def test_kiss_point_moves_by_lever_ratio_times_delta(fmu, tables):
    """The cushion's part of the shift is lever_ratio * delta_kiss (paper); stack growth and compliance add to it."""
    d195 = dict(zip(tables.theta_degC, tables.delta_kiss_m))[195.0]
    cold = Instance(fmu, theta_cs_start=293.15)
    hot = Instance(fmu, "hot", theta_cs_start=195.0 + 273.15, theta_cm=195.0 + 273.15)
    shift = cold.get("x_kiss") - hot.get("x_kiss")
    budget = CoverMap(CoverParameters(), 3.0).kiss_budget(468.15, 468.15, 0.0, load_table(), 0.004)
    assert budget["cushion"] == pytest.approx(-3.0 * d195, rel=1e-12)
    assert shift == pytest.approx(-budget["total"], rel=1e-9)
    assert 0.2e-3 < 3.0 * d195 < 0.42e-3          # paper: about 0.3 mm at the bearing from the cushion spring
    cold.close(), hot.close()


def test_state_save_restore_and_serialize(fmu):
    inst = Instance(fmu)
    inst.set(x_to=0.005, theta_cm=550.0)
    for _ in range(10):
        inst.step(0.5)
    state = inst.s.getFMUstate()
    blob = inst.s.serializeFMUstate(state)
    inst.step(3.0)
    after = inst.get(*OUT)
    inst.set(theta_cm=300.0, x_to=0.0)
    inst.step(7.0)
    inst.s.setFMUstate(state)
    inst.set(x_to=0.005, theta_cm=550.0)
    inst.step(3.0)
    assert inst.get(*OUT) == after
    other = Instance(fmu, "other")
    other.s.setFMUstate(other.s.deSerializeFMUstate(blob))
    other.set(x_to=0.005, theta_cm=550.0)
    other.step(3.0)
    assert other.get(*OUT) == after
    inst.s.freeFMUstate(state)
    inst.close(), other.close()


def test_reset_returns_to_start(fmu):
    inst = Instance(fmu)
    inst.set(theta_cm=600.0)
    inst.step(20.0)
    assert inst.get("theta_cs") > 400.0
    inst.s.reset()
    inst.start()
    assert inst.get("theta_cs") == 293.15
    inst.close()


def test_two_instances_are_independent(fmu):
    a, b = Instance(fmu, "a"), Instance(fmu, "b")
    a.set(theta_cm=600.0, x_to=0.006)
    b.set(theta_cm=300.0, x_to=0.0)
    for _ in range(5):
        a.step(1.0)
        b.step(1.0)
    def closed_form(theta_cm, t):
        inf = (0.1 * theta_cm + 0.04 * 293.15) / 0.14
        return inf + (293.15 - inf) * math.exp(-t * 0.14 / 1.0)

    assert a.get("theta_cs") == pytest.approx(closed_form(600.0, 5.0), rel=1e-12)
    assert b.get("theta_cs") == pytest.approx(closed_form(300.0, 5.0), rel=1e-12)
    assert a.get("torque") > 0.0 and b.get("torque") == 0.0
    a.close(), b.close()


@pytest.mark.parametrize("name,value", [("x_to", math.nan), ("x_to", math.inf),
                                        ("theta_cm", math.nan), ("theta_cm", -math.inf)])
def test_bad_input_is_refused_and_logged(fmu, capfd, name, value):
    inst = Instance(fmu)
    inst.step(0.1)
    before = inst.get("theta_cs")
    inst.set(**{name: value})
    with pytest.raises(FMICallException, match="discard|error"):
        inst.step(0.1)
    assert f"input {name} = {value!r}" in capfd.readouterr().out
    assert inst.get("theta_cs") == before            # nothing advanced
    inst.set(x_to=0.005, theta_cm=400.0)             # and the instance recovers
    inst.step(0.1)
    assert inst.get("torque") > 0
    inst.close()


@pytest.mark.parametrize("name,value", [("C", 0.0), ("mu", -0.1), ("lever_ratio", 0.0),
                                        ("R_eq", math.nan), ("U", -1.0)])
def test_bad_parameter_is_refused_and_logged(fmu, capfd, name, value):
    with pytest.raises(FMICallException, match="fmi2ExitInitializationMode failed with status 3"):
        Instance(fmu, **{name: value})              # fmi2Error, as the native FMU (issue 31)
    assert f"parameter {name} = {value!r}" in capfd.readouterr().out


def test_out_of_table_temperature_warns_once(fmu, capfd):
    # -45 degC: below the -40 degC table, above the model's 200 K (validity 1; the tables reach the facing
    # damage limit, 350 degC, so a hot cushion is beyond them only where the facings are damaged: validity 2)
    inst = Instance(fmu, theta_cs_start=228.15, theta_cm=228.15, x_to=0.006)
    for _ in range(5):
        inst.step(0.1)
    out = capfd.readouterr()
    assert out.out.count("temperature beyond the tables") == 1     # the logger (stderr carries a copy)
    assert inst.get("validity") == 1.0
    assert inst.get("torque") > 0
    inst.close()


def _rss_kB() -> int:
    """The process's resident memory now (kB): /proc/self/statm on Linux, else the peak (ru_maxrss)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024
    except OSError:
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def test_many_steps_do_not_grow_memory(fmu):
    """300 000 steps after a 20 000-step warm-up leave the resident memory within 3 MB.

    Detection limit: 3 MB / 300 000 steps = 10.5 bytes per step, so a leak of 16 bytes a step (4.8 MB of
    payload; a 16-byte malloc a step measured 22 bytes a step of resident growth) fails. The steps go
    through the launch master's cffi client (preallocated arrays, no per-call Python objects on the
    host side), and the memory is the current resident set, not the process's peak, so neither fmpy's
    wrappers nor an earlier test's peak can hide or fake a growth. The steps cost the pythonfmu slave's
    Python code (about 60 us each), hence 0.3 M instead of the former 1.1 M fmpy steps (whose 20 MB
    limit on the peak RSS was 20 bytes a step).
    """
    from cushion_clutch.launch.plant.fmu_client import ClutchFmu
    path, _, _ = fmu
    client = ClutchFmu(path, {})
    step, h = client.step, 1e-3

    def run(n, t0):
        for k in range(n):
            step(t0 + k * h, h, 0.004 + 0.003 * ((k % 1000) / 1000.0), 400.0, 0.0)
        return t0 + n * h

    try:
        t = run(20_000, 0.0)
        rss0 = _rss_kB()
        run(300_000, t)
        rss1 = _rss_kB()
    finally:
        client.close()
    assert rss1 - rss0 < 3 * 1024, f"{rss1 - rss0} kB more after 300 000 steps"
