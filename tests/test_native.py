"""The native C FMU: conformance, agreement with the pythonfmu FMU and the model, C host, sanitizers."""
import math
import shutil
import subprocess
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from cushion_clutch.data import DEFAULT_TABLES, fmu_source
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.fmu.descriptions import sources
from cushion_clutch.fmu.native import fmi2_header_dir
from cushion_clutch.model import VARIABLES, ClutchParameters, load_table, outputs, thermal_step
from native_builds import assert_final_matches_model

pytestmark = pytest.mark.fmu

HOST_SRC = fmu_source("fmi2_host.c")
OUT = ["torque", "force", "theta_cs", "u_f", "x_kiss", "clamp_force", "bearing_force"]


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    d = tmp_path_factory.mktemp("fmus")
    return {"native": build_fmu(DEFAULT_TABLES, d / "native.fmu", backend="native"),
            "python": build_fmu(DEFAULT_TABLES, d / "python.fmu", backend="python")}


def open_slave(path, unzip=None, name="i", **start):
    md = read_model_description(str(path))
    unzip = unzip or extract(str(path))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName=name)
    s.instantiate(loggingOn=True)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s.setupExperiment(startTime=0.0)
    if start:
        s.setReal([vr[k] for k in start], list(start.values()))
    s.enterInitializationMode()
    s.exitInitializationMode()
    return s, vr


def test_validate_and_sources(fmus):
    assert validate_fmu(str(fmus["native"])) == []
    names = zipfile.ZipFile(fmus["native"]).namelist()
    for f in ("binaries/linux64/CushionClutch.so", "sources/clutch_core.c", "sources/fmi2_frontend.c",
              "sources/cushion_guid.h", "sources/fmi2Functions.h",
              "resources/tables/force_deflection.csv", "resources/tables/kiss_point.csv"):
        assert f in names
    md = read_model_description(str(fmus["native"]))
    assert md.buildConfigurations[0].sourceFileSets[0].sourceFiles == list(sources(2))
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    assert md.modelExchange.canGetAndSetFMUstate and md.modelExchange.canSerializeFMUstate
    py = read_model_description(str(fmus["python"]))
    same = lambda m: [(v.name, v.valueReference, v.causality, v.unit, v.displayUnit,  # noqa: E731
                       None if v.start is None else float(v.start)) for v in m.modelVariables[:len(VARIABLES)]]
    assert same(md) == same(py)
    assert [v.name for v in md.modelVariables[len(VARIABLES):]] == ["der(theta_cs)"]


@pytest.mark.skipif(shutil.which("cmake") is None, reason="fmpy compile needs CMake")
def test_sources_build_with_fmpy_compile(fmus, tmp_path):
    """Another platform can rebuild the binary from sources/ (here: fmpy compile, CMake)."""
    src_only = tmp_path / "src_only.fmu"
    with zipfile.ZipFile(fmus["native"]) as zin, zipfile.ZipFile(src_only, "w") as zout:
        for item in zin.infolist():
            if not item.filename.startswith("binaries/"):
                zout.writestr(item, zin.read(item.filename))
    subprocess.run(["fmpy", "compile", str(src_only)], check=True, capture_output=True)
    assert "binaries/linux64/CushionClutch.so" in zipfile.ZipFile(src_only).namelist()
    s, vr = open_slave(src_only, name="rebuilt", theta_cs_start=468.15)
    s.setReal([vr["x_to"]], [0.005])
    s.doStep(0.0, 0.0)
    table, p = load_table(), ClutchParameters()
    # theta_cm keeps its start value theta_a (the stack's growth is taken at the facing temperature input)
    assert s.getReal([vr["torque"]])[0] == pytest.approx(outputs(0.005, 468.15, table, p, theta_cm=p.theta_a).torque,
                                                         rel=1e-12)


def test_native_pythonfmu_and_model_agree_over_a_long_random_sequence(fmus):
    rng = np.random.default_rng(7)
    n = 20_000
    x_to = rng.uniform(-0.001, 0.014, n)            # open, cushion, solid, bearing lifted
    theta_cm = rng.uniform(250.0, 750.0, n)           # beyond the table range too
    h = rng.choice([1e-4, 1e-3, 0.01, 0.1, 1.0, 5.0], n)
    nat, vr = open_slave(fmus["native"], name="native")
    pyf, _ = open_slave(fmus["python"], name="python")
    table, p = load_table(), ClutchParameters()
    theta, t, worst = p.theta_cs_start, 0.0, 0.0
    vin, vout = [vr["x_to"], vr["theta_cm"]], [vr[k] for k in OUT]
    for k in range(n):
        for s in (nat, pyf):
            s.setReal(vin, [x_to[k], theta_cm[k]])
            s.doStep(t, h[k])
        theta = thermal_step(theta, theta_cm[k], h[k], p)
        o = outputs(x_to[k], theta, table, p, theta_cm[k])
        ref = np.array([o.torque, o.force, theta, o.u_f, o.x_kiss, o.clamp_force, o.bearing_force])
        a, b = np.array(nat.getReal(vout)), np.array(pyf.getReal(vout))
        scale = np.maximum(np.abs(ref), [1.0, 1.0, 1.0, 1e-3, 1e-3, 1.0, 1.0])     # N.m, N, K, m, m, N, N
        worst = max(worst, float(np.max(np.abs(a - ref) / scale)), float(np.max(np.abs(b - ref) / scale)))
        t += h[k]
    assert worst < 1e-9, worst


COVER = {"facing_wear": 0.0005, "installed_deflection_m": 0.0033, "release_compliance_m_per_N": 1.5e-6,
         "diaphragm_thickness_m": 0.0027, "lever_ratio": 2.8, "facing_expansion_per_K": 4e-5}


def test_native_follows_the_cover_parameters_and_the_issue_bar(fmus):
    """Non-default cover and wear through the FMU's parameters: native = Python model; issue 19's bar."""
    from cushion_clutch.model import CoverParameters
    table = load_table()
    p = ClutchParameters.from_flat({**ClutchParameters().flat(), **COVER})
    assert p.cover != CoverParameters() and p.problems() == []
    for theta in (293.15, 468.15, 573.15):
        nat, vr = open_slave(fmus["native"], name="cover", theta_cs_start=theta, **COVER)
        pyf, _ = open_slave(fmus["python"], name="cover_py", theta_cs_start=theta, **COVER)
        for x in np.linspace(0.0, 0.02, 161):
            o = outputs(float(x), theta, table, p, theta)
            for s in (nat, pyf):
                s.setReal([vr["x_to"], vr["theta_cm"]], [float(x), theta])
                s.doStep(0.0, 0.0)
                got = dict(zip(OUT, s.getReal([vr[k] for k in OUT])))
                assert got["clamp_force"] == pytest.approx(o.clamp_force, rel=1e-9, abs=1e-9)
                assert got["bearing_force"] == pytest.approx(o.bearing_force, rel=1e-9, abs=1e-9)
                assert got["torque"] == pytest.approx(o.torque, rel=1e-9, abs=1e-9)
                assert got["x_kiss"] == pytest.approx(o.x_kiss, rel=1e-12)
        nat.terminate(), pyf.terminate()
    # issue 19's bar, default parameters, native FMU
    for theta in (293.15, 468.15, 573.15):
        s, vr = open_slave(fmus["native"], name=f"bar{theta}", theta_cs_start=theta)
        torque = []
        for x in np.linspace(0.0, 0.02, 2001):                  # direct feedthrough: no step needed
            s.setReal([vr["x_to"], vr["theta_cm"]], [float(x), theta])
            torque.append(s.getReal([vr["torque"]])[0])
        assert np.all(np.diff(torque) >= 0.0), theta
    s, vr = open_slave(fmus["native"], name="bar")
    worn, _ = open_slave(fmus["native"], name="worn", facing_wear=0.0005)
    s.setReal([vr["x_to"], vr["theta_cm"]], [0.020, 293.15])
    assert 300.0 <= s.getReal([vr["torque"]])[0] <= 360.0 and s.getReal([vr["bearing_force"]])[0] == 0.0
    mid = 0.007
    s.setReal([vr["x_to"]], [mid])
    worn.setReal([vr["x_to"]], [mid])
    assert s.getReal([vr["torque"]])[0] - worn.getReal([vr["torque"]])[0] > 5.0


def test_issue37_bar_from_a_winter_start_to_the_damage_limit(fmus):
    """Issue 37's bar: the default native FMU at theta_cm = theta_cs = 233.15 K (-40 degC) and 623.15 K (350 degC)
    is inside its tables (validity 0; damage is strictly above 350 degC) with a finite, non-zero closed torque,
    the Python model's."""
    table = load_table()
    assert table.theta_min_K <= 233.15 and table.theta_max_K >= 623.15
    for theta in (233.15, 623.15):
        s, vr = open_slave(fmus["native"], name=f"bar37_{theta}", theta_cs_start=theta, theta_a=theta)
        s.setReal([vr["x_to"], vr["theta_cm"]], [0.020, theta])
        s.doStep(0.0, 1.0)
        torque, validity, theta_cs = s.getReal([vr["torque"], vr["validity"], vr["theta_cs"]])
        assert theta_cs == theta and validity == 0.0, (theta, validity)
        assert math.isfinite(torque) and torque > 100.0, (theta, torque)
        assert torque == pytest.approx(outputs(0.020, theta, table, ClutchParameters(), theta).torque, rel=1e-9)
        s.terminate()


def test_shared_object_does_not_need_python(fmus, tmp_path):
    with zipfile.ZipFile(fmus["native"]) as z:
        z.extract("binaries/linux64/CushionClutch.so", tmp_path)
    so = tmp_path / "binaries/linux64/CushionClutch.so"
    ldd = subprocess.run(["ldd", str(so)], capture_output=True, text=True, check=True).stdout
    assert "python" not in ldd.lower()
    undefined = subprocess.run(["nm", "-D", "--undefined-only", str(so)], capture_output=True, text=True,
                               check=True).stdout
    assert not [ln for ln in undefined.splitlines() if " Py" in ln or "_Py" in ln]
    exported = subprocess.run(["nm", "-D", "--defined-only", str(so)], capture_output=True, text=True,
                              check=True).stdout
    assert "fmi2DoStep" in exported and "table_load" not in exported       # only the FMI API


def _host(tmp_path, fmus, flags=()):
    unzip = tmp_path / "fmu"
    zipfile.ZipFile(fmus["native"]).extractall(unzip)
    cc = shutil.which("gcc")
    host = tmp_path / "host"
    subprocess.run([cc, "-std=c99", "-D_POSIX_C_SOURCE=199309L", "-O1", "-g", *flags, f"-I{fmi2_header_dir()}",
                    str(HOST_SRC), "-o", str(host), "-ldl"], check=True)
    lib = unzip / "binaries/linux64/CushionClutch.so"
    if flags:   # rebuild the FMU library with the same instrumentation
        subprocess.run([cc, "-std=c99", "-O1", "-g", "-fPIC", "-shared", *flags, f"-I{unzip / 'sources'}",
                        *(str(unzip / "sources" / f) for f in sources(2)), "-o", str(lib), "-lm"], check=True)
    guid = read_model_description(str(fmus["native"])).guid
    return [str(host), str(lib), (unzip / "resources").as_uri(), guid]


def test_c_host_drives_a_simulation(fmus, tmp_path):
    cmd = _host(tmp_path, fmus)
    out = subprocess.run(cmd + ["20000", "0.01"], capture_output=True, text=True, check=True).stdout
    got = [float(v) for v in out.splitlines()[0].split()[1:]]
    # the C (Halley) and Python (Newton) cover solves stop at their own 1e-15 m residual: the helper's
    # tolerances say what that leaves
    assert_final_matches_model(got, 20000, 0.01)


def test_c_host_under_address_sanitizer_is_clean(fmus, tmp_path):
    cmd = _host(tmp_path, fmus, flags=("-fsanitize=address,undefined", "-fno-omit-frame-pointer"))
    res = subprocess.run(cmd + ["5000", "0.01"], capture_output=True, text=True,
                         env={"ASAN_OPTIONS": "detect_leaks=1:abort_on_error=0",
                              "UBSAN_OPTIONS": "halt_on_error=1", "PATH": "/usr/bin:/bin"})
    assert res.returncode == 0, res.stderr
    assert "AddressSanitizer" not in res.stderr and "runtime error" not in res.stderr


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind not installed")
def test_c_host_under_valgrind_is_clean(fmus, tmp_path):
    cmd = _host(tmp_path, fmus)
    res = subprocess.run(["valgrind", "--error-exitcode=3", "--leak-check=full", "--errors-for-leak-kinds=all",
                          *cmd, "2000", "0.01"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr[-3000:]
    assert "ERROR SUMMARY: 0 errors" in res.stderr


def test_state_reset_and_instances(fmus):
    a, vr = open_slave(fmus["native"], name="a")
    b, _ = open_slave(fmus["native"], name="b")
    vin, vout = [vr["x_to"], vr["theta_cm"]], [vr[k] for k in OUT]
    a.setReal(vin, [0.005, 600.0])
    b.setReal(vin, [0.0, 300.0])
    for k in range(5):
        a.doStep(k, 1.0)
        b.doStep(k, 1.0)
    assert a.getReal([vr["theta_cs"]])[0] > 400 > b.getReal([vr["theta_cs"]])[0]
    state = a.getFMUstate()
    blob = a.serializeFMUstate(state)
    a.doStep(5.0, 2.0)
    after = a.getReal(vout)
    a.setReal(vin, [0.0, 300.0])
    a.doStep(7.0, 9.0)
    a.setFMUstate(state)
    a.setReal(vin, [0.005, 600.0])
    a.doStep(5.0, 2.0)
    assert a.getReal(vout) == after
    b.setFMUstate(b.deSerializeFMUstate(blob))
    b.setReal(vin, [0.005, 600.0])
    b.doStep(5.0, 2.0)
    assert b.getReal(vout) == after
    a.freeFMUstate(state)
    a.reset()
    a.setupExperiment(startTime=0.0)
    a.enterInitializationMode()
    a.exitInitializationMode()
    assert a.getReal([vr["theta_cs"]]) == [293.15]
    for s in (a, b):
        s.terminate()
        s.freeInstance()


def test_bad_inputs_and_parameters_give_statuses_and_messages(fmus, capfd):
    s, vr = open_slave(fmus["native"], name="bad")
    s.setReal([vr["x_to"]], [math.nan])
    with pytest.raises(FMICallException, match="discard"):
        s.doStep(0.0, 0.1)
    assert "input x_to = nan" in capfd.readouterr().out
    s.setReal([vr["x_to"]], [0.005])
    s.doStep(0.0, 0.1)                                   # recovers
    s.terminate()
    s.freeInstance()
    with pytest.raises(FMICallException, match="error"):
        open_slave(fmus["native"], name="badC", C=0.0, mu=-1.0)
    out = capfd.readouterr().out
    assert "parameter C = 0" in out and "parameter mu = -1" in out


def test_malformed_table_is_an_error_not_a_crash(fmus, tmp_path, capfd):
    unzip = tmp_path / "fmu"
    zipfile.ZipFile(fmus["native"]).extractall(unzip)
    csv = unzip / "resources/tables/force_deflection.csv"
    lines = csv.read_text().splitlines()
    lines[5] = "20,oops,1"
    csv.write_text("\n".join(lines) + "\n")
    with pytest.raises(Exception, match="instantiate"):      # refused at instantiation, with the reason
        open_slave(fmus["native"], unzip=str(unzip), name="malformed")
    assert "force_deflection.csv line 6: expected 3 finite numbers" in capfd.readouterr().out


def _hints(text: str) -> list[str]:
    import re
    return re.findall(r"did you mean [^?]*\?", text)


@pytest.mark.parametrize("case, hint", [
    ({"input": ("x_to", 12.0)}, "did you mean 0.012 m?"),                       # mm typed as m
    ({"input": ("theta_cm", 20.0)}, "did you mean 293.15 K (20 degC)?"),          # degC typed as K
    ({"start": {"theta_cs_start": 20.0}}, "did you mean 293.15 K (20 degC)?"),    # a parameter
    ({"start": {"facing_wear": 1.0}}, "did you mean 0.001 m?"),
])
def test_unit_hints_native_and_python_agree(fmus, capfd, case, hint):
    """A value refused for its range carries the likely unit mistake, with the same text from the native C FMU
    (clutch_core.c unit_hint) and the pythonfmu FMU (number_check.unit_hint), in Co-Simulation through fmpy;
    an input refused in a step makes fmpy's next read raise (Discard, docs/reference/statuses.md), a parameter is
    refused at initialisation: either way fmpy raises, which is how a user notices it."""
    from fmpy import simulate_fmu

    got = {}
    for kind in ("native", "python"):
        capfd.readouterr()
        kw = {}
        if "input" in case:
            name, value = case["input"]
            kw["input"] = np.array([(0.0, value), (1.0, value)], dtype=[("time", float), (name, float)])
        with pytest.raises(Exception) as refused:       # fmpy's FMICallException (native) or its wrapper's
            simulate_fmu(str(fmus[kind]), fmi_type="CoSimulation", stop_time=1.0, output_interval=0.1,
                         start_values=case.get("start", {}), **kw)
        assert "status 2" in str(refused.value) or "start" in case, (kind, refused.value)
        got[kind] = _hints(capfd.readouterr().out)
        assert hint in got[kind], (kind, got[kind])
    assert set(got["native"]) == set(got["python"]), got
