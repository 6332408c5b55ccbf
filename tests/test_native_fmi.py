"""Native FMU, both FMI versions: ME vs CS vs the closed form, FMI 3 vs FMI 2, the state machine,
validated saved states, tables in any order, the resource URI conversion."""
import dataclasses
import math
import shutil
import struct
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2LastSuccessfulTime, fmi2Terminated
from fmpy.fmi3 import FMU3Slave

from cushion_clutch.data import fmu_source
from cushion_clutch.model import VARIABLES, ClutchParameters, load_table, outputs, thermal_step
from native_builds import native_fmus

pytestmark = pytest.mark.fmu
G = ClutchParameters().U + ClutchParameters().H


def _signal():
    """x_to ramp 3 -> 8 mm over 10 s; theta_cm step 300 -> 600 K at t = 2 s."""
    t = np.array([0.0, 2.0, 2.0, 10.0])
    rows = [(tk, 0.003 + 0.0005 * tk, 300.0 if k < 2 else 600.0, 0.0) for k, tk in enumerate(t)]
    return np.array(rows, dtype=[("time", float), ("x_to", float), ("theta_cm", float), ("omega_slip", float)])


def _closed_form(t):
    p = ClutchParameters()
    inf1 = (p.U * 300.0 + p.H * p.theta_a) / G
    inf2 = (p.U * 600.0 + p.H * p.theta_a) / G
    th2 = inf1 + (p.theta_cs_start - inf1) * math.exp(-G * 2.0 / p.C)
    return np.where(t <= 2.0, inf1 + (p.theta_cs_start - inf1) * np.exp(-G * t / p.C),
                    inf2 + (th2 - inf2) * np.exp(-G * (t - 2.0) / p.C))


def _simulate(fmu, kind, **kw):
    """Result rows on the output grid (ME records the input event at t = 2 s twice: the first is kept)."""
    res = simulate_fmu(str(fmu), fmi_type=kind, input=_signal(), stop_time=10.0, output_interval=0.01,
                        output=["theta_cs", "torque", "force", "u_f", "x_kiss"], relative_tolerance=1e-11, **kw)
    return res[np.r_[True, np.diff(res["time"]) > 0]]


@pytest.fixture(scope="module")
def runs():
    return {(v, k): _simulate(native_fmus()[v], k) for v in (2, 3) for k in ("CoSimulation", "ModelExchange")}


def _cs_master(fmu):
    """CS through a master that sets the inputs at each communication point, then reads the outputs
    (direct feedthrough) and steps: outputs at the same inputs as ME's."""
    s, vr = _slave(fmu, name="master")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    rows = []
    for k in range(1001):
        t = k * 0.01
        s.setReal([vr["x_to"], vr["theta_cm"]], [0.003 + 0.0005 * t, 300.0 if k < 200 else 600.0])
        rows.append(s.getReal([vr[n] for n in OUT]))
        if k < 1000:
            s.doStep(t, 0.01)
    s.terminate()
    s.freeInstance()
    return np.array(rows)


OUT = ("theta_cs", "torque", "force", "u_f", "x_kiss")


def test_me_and_cs_match_each_other_and_the_closed_form(runs):
    cs, me = runs[(2, "CoSimulation")], runs[(2, "ModelExchange")]
    assert np.array_equal(cs["time"], me["time"])
    exact = _closed_form(cs["time"])
    assert np.max(np.abs(cs["theta_cs"] - exact) / exact) < 1e-12        # CS: exact step solution
    assert np.max(np.abs(me["theta_cs"] - exact) / exact) < 1e-8         # ME: CVode
    master = _cs_master(native_fmus()[2])
    # at the theta_cm step (t = 2 s) ME keeps the pre-event output, the CS master the post-event one:
    # the outputs depend directly on theta_cm (the stack's thermal growth), so that one instant differs
    keep = cs["time"] != 2.0
    for j, name in enumerate(OUT):
        scale = max(np.max(np.abs(master[:, j])), 1e-12)
        assert np.max(np.abs(me[name][keep] - master[keep, j])) / scale < 1e-6, name
    table, p = load_table(), ClutchParameters()
    for k in (400, 750, 1000):                                           # engaged; ME vs the Python model
        ref = outputs(0.003 + 0.0005 * me["time"][k], exact[k], table, p, 600.0)
        assert me["torque"][k] > 5.0     # engaged, so not 0 = 0
        assert me["torque"][k] == pytest.approx(ref.torque, rel=1e-6)
        assert master[k, 1] == pytest.approx(ref.torque, rel=1e-11)


def test_fmi3_matches_fmi2_in_both_interfaces(runs):
    for kind in ("CoSimulation", "ModelExchange"):
        a, b = runs[(2, kind)], runs[(3, kind)]
        assert np.array_equal(a["time"], b["time"])
        for name in ("theta_cs", "torque", "force", "u_f", "x_kiss"):
            scale = np.maximum(np.abs(a[name]), 1e-300)
            assert np.max(np.abs(a[name] - b[name]) / scale) <= 1e-12, (kind, name)


def test_model_descriptions_declare_both_interfaces_and_dependencies():
    for v, fmu in native_fmus().items():
        assert subprocess.run(["fmpy", "validate", str(fmu)], capture_output=True, text=True).returncode == 0
        md = read_model_description(str(fmu))
        assert md.coSimulation and md.modelExchange
        names = {sv.name: sv for sv in md.modelVariables}
        assert names["der(theta_cs)"].derivative is names["theta_cs"]
        deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
        assert deps["torque"] == ["theta_cm", "theta_cs", "x_to"] and deps["x_kiss"] == ["theta_cm", "theta_cs"]
        assert deps["clamp_force"] == deps["bearing_force"] == ["theta_cm", "theta_cs", "x_to"]
        assert [d.name for d in md.derivatives[0].dependencies] == ["theta_cm", "theta_cs"]
    assert "sources/buildDescription.xml" in zipfile.ZipFile(native_fmus()[3]).namelist()


def test_lengths_display_in_mm_and_temperatures_in_degc():
    """Both FMI versions: the unit m carries an mm DisplayUnit (factor 1000), K a degC one (offset -273.15), and
    every variable in m names displayUnit mm, every variable in K degC (hosts show x_to = 0.012 as 12 mm)."""
    from xml.etree import ElementTree as ET

    for v, fmu in native_fmus().items():
        root = ET.fromstring(zipfile.ZipFile(fmu).read("modelDescription.xml"))
        units = {u.get("name"): u.find("DisplayUnit") for u in root.iter("Unit")}
        assert units["m"].attrib == {"name": "mm", "factor": "1000"}, v
        assert units["K"].attrib == {"name": "degC", "offset": "-273.15"}, v
        typed = root.iter("Real") if v == 2 else root.find("ModelVariables")
        seen = {}
        for el in typed:
            name = el.get("name") if v == 3 else None
            seen[name or len(seen)] = (el.get("unit"), el.get("displayUnit"))
        assert all(d == {"m": "mm", "K": "degC"}.get(u) for u, d in seen.values()), (v, seen)
        assert sum(u == "m" for u, _ in seen.values()) >= 5 and sum(u == "K" for u, _ in seen.values()) >= 4
        if v == 3:
            assert seen["x_to"] == ("m", "mm") and seen["theta_cm"] == ("K", "degC")


# ------------------------------------------------------------- FMI 2 state machine
def _slave(fmu=None, unzip=None, name="s", guid=None):
    fmu = fmu or native_fmus()[2]
    md = read_model_description(str(fmu))
    s = FMU2Slave(guid=guid or md.guid, unzipDirectory=unzip or extract(str(fmu)),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    return s, {v.name: v.valueReference for v in md.modelVariables}


def _status(call):
    try:
        call()
        return "ok"
    except FMICallException as e:
        return {1: "warning", 2: "discard", 3: "error", 4: "fatal"}[e.status]


def test_state_machine_refusals_are_errors_with_messages(capfd):
    s, vr = _slave()
    s.instantiate(loggingOn=False)                       # errors are logged all the same
    assert _status(lambda: s.doStep(0.0, 0.1)) == "error"
    assert "fmi2DoStep is not allowed in Instantiated" in capfd.readouterr().out
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    assert _status(lambda: s.setReal([vr["mu"], vr["torque"]], [0.5, 1.0])) == "error"
    assert "torque (value reference 2) is not an input or parameter" in capfd.readouterr().out
    assert _status(lambda: s.setReal([99], [1.0])) == "error"
    assert "unknown value reference 99" in capfd.readouterr().out
    s.exitInitializationMode()
    assert s.getReal([vr["mu"]]) == [0.28]               # the refused call applied nothing
    assert _status(lambda: s.setReal([vr["mu"]], [0.56])) == "error"
    assert "parameter mu is fixed after initialization" in capfd.readouterr().out
    s.setReal([vr["x_to"], vr["theta_cm"]], [0.006, 500.0])
    s.doStep(0.0, 1.0)
    theta = s.getReal([vr["theta_cs"]])
    assert _status(lambda: s.exitInitializationMode()) == "error"
    assert _status(lambda: s.enterInitializationMode()) == "error"
    assert s.getReal([vr["theta_cs"]]) == theta          # nothing reset
    assert _status(lambda: s.getReal([1000])) == "error"
    s.setDebugLogging(True, [])
    assert s.fmi2DoStep(s.component, 5.0, 1.0, 1) == 1  # t does not follow: fmi2Warning, accepted
    assert "does not follow the previous step" in capfd.readouterr().out
    s.setReal([vr["x_to"]], [math.inf])
    assert _status(lambda: s.doStep(6.0, 1.0)) == "discard"
    assert "input x_to = inf" in capfd.readouterr().out
    assert s.getBooleanStatus(fmi2Terminated) is False    # a recoverable Discard never terminates (issue 39)
    assert s.getRealStatus(fmi2LastSuccessfulTime) == 6.0
    s.setReal([vr["x_to"]], [0.006])
    s.doStep(6.0, 1.0)                                    # acceptable inputs: the next step proceeds
    assert s.getRealStatus(fmi2LastSuccessfulTime) == 7.0
    s.terminate()
    assert _status(lambda: s.doStep(6.0, 1.0)) == "error"
    s.freeInstance()


def test_parameters_guid_and_format_characters(tmp_path, capfd):
    s, vr = _slave()
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setReal([vr["n_surfaces"]], [2.5])
    assert _status(lambda: s.exitInitializationMode()) == "error"
    assert "n_surfaces = 2.5 must be a whole number" in capfd.readouterr().out
    s.freeInstance()
    bad, _ = _slave(guid="{00000000-0000-0000-0000-000000000000}")
    with pytest.raises(Exception, match="instantiate"):
        bad.instantiate()
    assert "GUID {00000000-0000-0000-0000-000000000000} does not match" in capfd.readouterr().out
    unzip = tmp_path / "fmu %s%n%d"                      # printf directives in the path: printed as text
    zipfile.ZipFile(native_fmus()[2]).extractall(unzip)
    (unzip / "resources/tables/kiss_point.csv").write_text("theta_degC,delta_kiss_m\n%s%n,1\n")
    s, _ = _slave(unzip=str(unzip))
    with pytest.raises(Exception, match="instantiate"):
        s.instantiate()
    out = capfd.readouterr().out
    assert "fmu %s%n%d/resources/tables/kiss_point.csv line 2: expected 2 finite numbers" in out


def test_simulate_fmu_raises_at_a_mid_run_nan(capfd):
    """What fmpy's simulate_fmu does with 0.1 s of NaN in x_to mid-run (issue 39): the step is refused (Discard,
    not Terminated, so fmpy does not end the run quietly with a short result), fmpy reads the outputs and the read
    of stale outputs is Discard too: simulate_fmu raises FMICallException (status 2) naming fmi2GetReal, and the
    FMU's message names the input and its range. docs/reference/statuses.md tells fmpy users so."""
    from fmpy.fmi1 import FMICallException
    sig = np.array([(0.0, 0.005), (0.5, 0.005), (0.5, math.nan), (0.6, math.nan), (0.6, 0.005), (2.0, 0.005)],
                   dtype=[("time", float), ("x_to", float)])
    with pytest.raises(FMICallException) as e:
        simulate_fmu(str(native_fmus()[2]), input=sig, stop_time=2.0, output_interval=0.1, timeout=60.0)
    assert e.value.status == 2 and "fmi2GetReal" in str(e.value)
    out = capfd.readouterr().out
    assert "input x_to = nan m is not finite or outside [-0.002, 0.025] m; step refused" in out
    full = simulate_fmu(str(native_fmus()[2]), input=sig[[0, 1, 4, 5]], stop_time=2.0, output_interval=0.1)
    assert full["time"][-1] == pytest.approx(2.0)         # the same run without the NaN goes to the end


# ------------------------------------------------------------------ saved states
FNV = (1469598103934665603, 1099511628211)


def _seal(blob: bytearray) -> bytes:
    h = FNV[0]
    for b in blob[:-8]:
        h = ((h ^ b) * FNV[1]) & 0xFFFFFFFFFFFFFFFF
    blob[-8:] = struct.pack("<Q", h)
    return bytes(blob)


def test_corrupted_states_are_refused_and_change_nothing(capfd):
    s, vr = _slave()
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([vr["x_to"], vr["theta_cm"]], [0.006, 600.0])
    for k in range(100):
        s.doStep(k * 0.1, 0.1)
    blob = bytearray(s.serializeFMUstate(s.getFMUstate()))
    # header, r[], the cover's warm start (6 doubles: CcWarm x, s, slope, r and the open start's s1, s2), checksum
    assert len(blob) == 40 + 8 * (len(VARIABLES) + 1) + 48 + 8 and blob[:4] == b"SFCC"
    before = s.getReal(list(range(19)))
    c_at = 40 + 8 * vr["C"]
    nan_c = bytearray(blob)
    nan_c[c_at:c_at + 8] = struct.pack("<d", math.nan)
    bad_phase = bytearray(blob)
    bad_phase[12:16] = struct.pack("<i", 12345)
    flipped = bytearray(blob)
    flipped[100] ^= 1
    cases = {"truncated": (bytes(blob[:-1]), f"{len(blob) - 1} bytes, expected {len(blob)}"),
             "checksum": (bytes(flipped), "checksum"),
             "nan C": (_seal(nan_c), "C = nan"), "phase": (_seal(bad_phase), "phase 12345")}
    for name, (data, message) in cases.items():
        with pytest.raises(FMICallException):
            s.deSerializeFMUstate(data)
        assert message in capfd.readouterr().out, name
    assert s.getReal(list(range(19))) == before
    s.doStep(10.0, 0.1)                                   # still stepping
    restored = s.deSerializeFMUstate(bytes(blob))
    s.setFMUstate(restored)
    assert s.getReal(list(range(19))) == before
    s.terminate()
    s.freeInstance()


def _stepping(version: int, name: str, logging: bool = True, start: dict | None = None, cls=None):
    """(slave, value references) of the native FMI ``version`` CS FMU, initialised, in Step Mode at t = 0.

    ``start``: parameter values (by name) set before initialisation; ``cls``: the fmpy class to
    instantiate (default: the CS slave of the version; :func:`_me_instance` passes the ME model).
    """
    fmu = native_fmus()[version]
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    cls = cls or (FMU2Slave if version == 2 else FMU3Slave)
    s = cls(guid=md.guid, unzipDirectory=extract(str(fmu)), modelIdentifier="CushionClutch", instanceName=name)
    s.instantiate(loggingOn=logging)
    if start:
        (s.setReal if version == 2 else s.setFloat64)([vr[k] for k in start], list(start.values()))
    if version == 2:
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
    else:
        s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    return s, vr


def test_fmi3_state_logging_and_statuses(capfd):
    s, vr = _stepping(3, "f3", logging=False)
    s.setFloat64([vr["x_to"], vr["theta_cm"]], [0.006, 600.0])
    s.doStep(0.0, 1.0)
    state = s.getFMUState()
    blob = s.serializeFMUState(state)
    s.doStep(1.0, 1.0)
    after = s.getFloat64([vr["torque"], vr["theta_cs"], vr["time"]])
    s.setFMUState(s.deserializeFMUState(blob))
    s.doStep(1.0, 1.0)
    assert s.getFloat64([vr["torque"], vr["theta_cs"], vr["time"]]) == after
    assert after[2] == 2.0
    with pytest.raises(FMICallException):
        s.setFloat64([vr["mu"]], [0.5])
    assert "parameter mu is fixed after initialization" in capfd.readouterr().out
    s.setFloat64([vr["theta_cm"]], [-1.0])
    with pytest.raises(FMICallException):
        s.doStep(2.0, 1.0)
    assert "input theta_cm = -1 K" in capfd.readouterr().out
    s.terminate()
    s.freeInstance()


# ------------------------------------------------------------------------ tables
def _outputs_with_tables(tmp_path, name, edit):
    unzip = tmp_path / name
    zipfile.ZipFile(native_fmus()[2]).extractall(unzip)
    edit(unzip / "resources/tables")
    s, vr = _slave(unzip=str(unzip), name=name)
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.setReal([vr["theta_cs_start"]], [400.0])
    s.enterInitializationMode()
    s.exitInitializationMode()
    got = []
    for x in (0.004, 0.005, 0.006, 0.007):
        s.setReal([vr["x_to"]], [x])
        s.doStep(len(got) * 1.0, 1.0)
        got.append(s.getReal([vr["torque"], vr["force"], vr["x_kiss"]]))
    s.freeInstance()
    return got


def _set_force(folder, line, value):
    """Replace the force of row ``line`` (0 = header) of force_deflection.csv with ``value``."""
    lines = (folder / "force_deflection.csv").read_text().splitlines()
    lines[line] = ",".join(lines[line].split(",")[:2] + [value])
    (folder / "force_deflection.csv").write_text("\n".join(lines) + "\n")


def _reverse_groups(folder):
    for name in ("force_deflection.csv", "kiss_point.csv"):
        lines = (folder / name).read_text().splitlines()
        groups = {}
        for line in lines[1:]:
            groups.setdefault(line.split(",")[0], []).append(line)
        (folder / name).write_text("\n".join([lines[0], *[r for g in reversed(groups.values()) for r in g]]) + "\n")


def test_tables_in_any_order_and_overflowing_forces(tmp_path, capfd):
    assert _outputs_with_tables(tmp_path, "reversed", _reverse_groups) == _outputs_with_tables(
        tmp_path, "as_built", lambda f: None)

    with pytest.raises(Exception, match="instantiate"):
        _outputs_with_tables(tmp_path, "huge", lambda folder: _set_force(folder, 3, "1e308"))
    assert "force_deflection.csv line 4: force_N = 1e+308 is outside" in capfd.readouterr().out


# -------------------------------------------------------------------- resource URI
URIS = [  # (windows, uri, expected)
    (1, "file:///C:/fmu/resources", "ok C:\\fmu\\resources"),
    (1, "file:/C:/fmu/resources/", "ok C:\\fmu\\resources"),
    (1, "file://C:/fmu/resources", "ok C:\\fmu\\resources"),
    (1, "file:///c|/fmu", "ok c:\\fmu"),
    (1, "file://localhost/C:/Program%20Files/FMU", "ok C:\\Program Files\\FMU"),
    (1, "file:///C:/Users/J%C3%BCrgen/r%C3%A9s%20dir", "ok C:\\Users\\Jürgen\\rés dir"),
    (1, "file://server/share/fmu/resources", "ok \\\\server\\share\\fmu\\resources"),
    (1, "file:///Z:/tmp/x/", "ok Z:\\tmp\\x"),
    (1, "file:///C:/", "ok C:\\"),
    (0, "file:///tmp/fmu/resources", "ok /tmp/fmu/resources"),
    (0, "file:/tmp/fmu/resources/", "ok /tmp/fmu/resources"),
    (0, "file://localhost/tmp/a%20b/%C3%A9", "ok /tmp/a b/é"),
    (0, "file:///", "ok /"),
    (0, "/plain/path/", "ok /plain/path"),
    (0, "file://server/share/x", "error file URI names the host 'server': only local files can be read"),
    (0, "file:///tmp/bad%zzescape", "error bad percent-encoding in resource location file:///tmp/bad%zzescape"),
    (0, "file:///tmp/nul%00", "error %00 in resource location file:///tmp/nul%00"),
]


def test_resource_uri_forms(tmp_path):
    exe = tmp_path / "uri_driver"
    src = fmu_source("resource_uri.c")
    subprocess.run([shutil.which("gcc"), "-std=c99", "-Wall", "-I", str(src.parent), str(Path(__file__).parent / "c/uri_driver.c"),
                    str(src), "-o", str(exe), "-lm"], check=True)
    for windows in (0, 1):
        cases = [c for c in URIS if c[0] == windows]
        out = subprocess.run([str(exe), str(windows), *[c[1] for c in cases]], capture_output=True, check=True)
        assert out.stdout.decode("utf-8").splitlines() == [c[2] for c in cases]


def test_fmi3_and_fmi2_match_with_a_friction_table(tmp_path):
    """omega_slip and friction.csv through both front ends (host binaries only)."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.native import build_native_fmu
    tables = tmp_path / "fade"
    shutil.copytree(DEFAULT_TABLES, tables)
    (tables / "friction.csv").write_text("theta_degC,omega_slip_rad_s,mu\n20,0,0.30\n20,100,0.28\n"
                                         "300,0,0.20\n300,100,0.18\n")
    f2 = build_native_fmu(tables, tmp_path / "f2.fmu", 2, platforms=("linux64",))
    f3 = build_native_fmu(tables, tmp_path / "f3.fmu", 3, platforms=("x86_64-linux",))
    deps = {u.variable.name: sorted(d.name for d in u.dependencies)
            for u in read_model_description(str(f3)).outputs}
    assert deps["torque"] == ["omega_slip", "theta_cm", "theta_cs", "x_to"]
    t = np.linspace(0.0, 10.0, 11)
    sig = np.array([(tk, 0.007, 300.0 + 40.0 * tk, 100.0 - 10.0 * tk) for tk in t],
                   dtype=[("time", float), ("x_to", float), ("theta_cm", float), ("omega_slip", float)])
    runs = [simulate_fmu(str(f), input=sig, stop_time=10.0, output_interval=0.1, output=["torque", "theta_cs"])
            for f in (f2, f3)]
    assert np.max(np.abs(runs[0]["torque"] - runs[1]["torque"]) / runs[0]["torque"]) <= 1e-12
    table, p = load_table(tables), ClutchParameters()
    theta = p.theta_cs_start
    for k in range(100):                                       # the Python model, inputs held per 0.1 s step
        theta = thermal_step(theta, 300.0 + 40.0 * k * 0.1, 0.1, p)
    assert runs[1]["theta_cs"][-1] == pytest.approx(theta, rel=1e-12)
    ref = outputs(0.007, theta, table, p, theta_cm=300.0 + 40.0 * 9.9, omega_slip=100.0 - 10.0 * 9.9)
    assert runs[1]["torque"][-1] == pytest.approx(ref.torque, rel=1e-12)


@pytest.mark.skipif(shutil.which("cmake") is None, reason="fmpy compile needs CMake")
def test_fmi3_sources_build_with_fmpy_compile(tmp_path):
    """sources/ and buildDescription.xml of the FMI 3.0 FMU rebuild a working binary."""
    src_only = tmp_path / "src3.fmu"
    with zipfile.ZipFile(native_fmus()[3]) as zin, zipfile.ZipFile(src_only, "w") as zout:
        for item in zin.infolist():
            if not item.filename.startswith("binaries/"):
                zout.writestr(item, zin.read(item.filename))
    subprocess.run(["fmpy", "compile", str(src_only)], check=True, capture_output=True)
    assert "binaries/x86_64-linux/CushionClutch.so" in zipfile.ZipFile(src_only).namelist()
    a, b = (simulate_fmu(str(f), stop_time=2.0, start_values={"theta_cm": 500.0}, output=["theta_cs"])
            for f in (src_only, native_fmus()[3]))
    assert a["theta_cs"][-1] == pytest.approx(b["theta_cs"][-1], rel=1e-13) and a["theta_cs"][-1] > 320.0


# ------------------------------------------------------------ Model Exchange: bad input
def _me_instance(version):
    from fmpy.fmi2 import FMU2Model
    from fmpy.fmi3 import FMU3Model
    m, vr = _stepping(version, f"me{version}", logging=False, cls=FMU2Model if version == 2 else FMU3Model)
    if version == 2:
        m.newDiscreteStates()
    else:
        m.updateDiscreteStates()
    m.enterContinuousTimeMode()
    return m, vr


@pytest.mark.parametrize("version", [2, 3])
def test_me_refuses_bad_inputs_on_output_reads_and_derivatives(version, capfd):
    m, vr = _me_instance(version)
    get = m.getReal if version == 2 else m.getFloat64
    put = m.setReal if version == 2 else m.setFloat64
    from ctypes import c_double
    buf = (c_double * 1)()
    der = (lambda: m.getDerivatives(buf, 1)) if version == 2 else (lambda: m.getContinuousStateDerivatives(buf, 1))
    put([vr["x_to"]], [0.006])
    good = get([vr["torque"]])[0]
    assert good > 0.0
    for bad in ([vr["x_to"]], [math.nan]), ([vr["theta_cm"]], [-5.0]), ([vr["x_to"]], [2.0]):
        put(*bad)
        assert _status(lambda: get([vr["torque"]])) == "discard"
        assert _status(der) == "discard"
        out = capfd.readouterr().out
        name = "x_to" if bad[0][0] == vr["x_to"] else "theta_cm"
        assert f"input {name} =" in out and "outputs not updated" in out and "no derivative" in out
        assert get([vr["x_to"], vr["mu"]])[1] == 0.28        # inputs and parameters stay readable
        put([vr["x_to"], vr["theta_cm"]], [0.006, 293.15])
        assert get([vr["torque"]])[0] == good
    for t in (math.nan, math.inf):
        assert _status(lambda: m.setTime(t)) == "error"
        assert "is not finite" in capfd.readouterr().out
    m.setTime(1.0)
    m.terminate()
    m.freeInstance()


def test_negative_table_forces_are_refused_with_the_line(tmp_path, capfd):
    with pytest.raises(Exception, match="instantiate"):
        _outputs_with_tables(tmp_path, "negative", lambda folder: _set_force(folder, 1, "-498"))
    assert "force_deflection.csv line 2: force_N = -498 < 0" in capfd.readouterr().out


# ------------------------------------------------------- outputs against the closed form
def test_der_theta_cs_output_is_the_heat_balance_in_both_versions():
    """der(theta_cs) = (U theta_cm + H theta_a - (U + H) theta_cs) / C (eq. 3), and it is the slope of theta_cs."""
    p = ClutchParameters()
    for version in (2, 3):
        s, vr = _stepping(version, f"der{version}")
        get = s.getReal if version == 2 else s.getFloat64
        put = s.setReal if version == 2 else s.setFloat64
        t = 0.0
        for theta_cm in (600.0, 600.0, 250.0):          # heating, then cooling below theta_cs
            put([vr["x_to"], vr["theta_cm"]], [0.006, theta_cm])
            theta, der = get([vr["theta_cs"], vr["der(theta_cs)"]])
            assert der == pytest.approx((p.U * theta_cm + p.H * p.theta_a - G * theta) / p.C, rel=1e-12)
            h = 1e-4
            s.doStep(t, h)
            t += h
            slope = (get([vr["theta_cs"]])[0] - theta) / h
            assert slope == pytest.approx(der, rel=1e-3)
            s.doStep(t, 2.0)
            t += 2.0
        assert der < 0.0                                 # the last row cools
        s.terminate()
        s.freeInstance()


def test_fmi3_refused_step_asks_to_terminate():
    """fmi3DoStep's terminateSimulation: false after a good step and after a recoverable Discard (issue 39: only
    what cannot be recovered would set it; every Discard of this FMU is recoverable), and the next step with
    acceptable inputs proceeds."""
    import ctypes
    s, vr = _stepping(3, "t3", logging=False)
    do_step = s.dll.fmi3DoStep
    do_step.restype = ctypes.c_int
    do_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_bool] + [ctypes.c_void_p] * 4

    def step(t):
        flags = [ctypes.c_bool(True), ctypes.c_bool(True), ctypes.c_bool(True)]
        last = ctypes.c_double(-1.0)
        status = do_step(s.component, t, 1.0, True, *[ctypes.byref(f) for f in flags], ctypes.byref(last))
        return status, [f.value for f in flags], last.value
    s.setFloat64([vr["x_to"], vr["theta_cm"]], [0.006, 500.0])
    assert step(0.0) == (0, [False, False, False], 1.0)          # OK, no event, go on, early return false
    s.setFloat64([vr["theta_cm"]], [-1.0])
    assert step(1.0) == (2, [False, False, False], 1.0)          # Discard: go on, last good time 1 s
    s.setFloat64([vr["theta_cm"]], [500.0])
    assert step(1.0) == (0, [False, False, False], 2.0)
    s.terminate()
    s.freeInstance()


def test_u_f_is_clipped_before_the_kiss_point_and_linear_after():
    """u_f = max(0, (x_to - x_kiss) / lever_ratio), by hand, in the native FMU and the Python model.

    With a stiff release system (compliance 0) the cover's balance is the paper's constant lever exactly."""
    p = ClutchParameters()
    p, table = ClutchParameters(cover=dataclasses.replace(p.cover, release_compliance_m_per_N=0.0)), load_table()
    s, vr = _stepping(2, "uf", start={"release_compliance_m_per_N": 0.0})
    for x in (0.0, 0.002, 0.0039, 0.0045, 0.006):
        s.setReal([vr["x_to"]], [x])
        u_f, x_kiss, force = s.getReal([vr["u_f"], vr["x_kiss"], vr["force"]])
        assert x_kiss == pytest.approx(p.x_kiss_ref, abs=1e-15)        # 20 degC: the reference kiss point
        # the FMU solves the cover's balance (Newton): equal to the closed form and the model to round-off
        assert u_f == pytest.approx(max(0.0, (x - x_kiss) / p.lever_ratio), rel=1e-12, abs=1e-18)
        assert u_f == pytest.approx(outputs(x, p.theta_cs_start, table, p).u_f, rel=1e-12, abs=1e-18)
        if x < x_kiss - 0.3e-3 * p.lever_ratio:                         # before the toe: no contact
            assert force == 0.0
    s.terminate()
    s.freeInstance()


def test_force_beyond_full_compression_is_the_table_s_last_row():
    """Past full compression F stays at the table's last force (hand value: the CSV's last 20 degC row).

    Stiff release system (compliance 0): the paper's lever, u = (x_to - 4 mm) / 3."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model.table_format import read_tables
    tables = read_tables(DEFAULT_TABLES)
    full_20 = tables.force_N[list(tables.theta_degC).index(20.0)][-1]       # the tables start at -40 degC
    s, vr = _stepping(2, "full", start={"release_compliance_m_per_N": 0.0})
    for x in (0.0095, 0.02):                   # u = 1.83 and 5.3 mm; full compression at 20 degC: 1.74 mm
        s.setReal([vr["x_to"]], [x])
        assert s.getReal([vr["force"]])[0] == pytest.approx(full_20, rel=1e-14)   # the cover's solve: round-off
    s.terminate()
    s.freeInstance()
