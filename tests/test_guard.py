"""The pythonfmu FMU's guard (fmu_src/pythonfmu/pythonfmu_guard.c, cushion_clutch/fmu/guard.py): it exports the
FMI 2.0 Co-Simulation API, and refuses what would kill the host in pythonfmu's wrapper, with a
message through the host's logger, on Linux (fmpy) and on Windows (our C host under Wine)."""
import json
import subprocess
import sys
import zipfile

import lief
import pytest
from fmpy import read_model_description

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu.build import build_fmu
from conftest import WINE
from test_native_platforms import _windows_host, fmi_functions

pytestmark = pytest.mark.fmu

ME_ONLY = {"fmi2EnterEventMode", "fmi2NewDiscreteStates", "fmi2EnterContinuousTimeMode",
           "fmi2CompletedIntegratorStep", "fmi2SetTime", "fmi2SetContinuousStates", "fmi2GetDerivatives",
           "fmi2GetEventIndicators", "fmi2GetContinuousStates", "fmi2GetNominalsOfContinuousStates"}


@pytest.fixture(scope="module")
def py_fmu(tmp_path_factory):
    d = tmp_path_factory.mktemp("guard")
    fmu = build_fmu(DEFAULT_TABLES, d / "py.fmu", backend="python")
    zipfile.ZipFile(fmu).extractall(d / "unzip")
    return fmu, d / "unzip", read_model_description(str(fmu)).guid


def test_guard_takes_the_wrappers_place_and_exports_the_cs_api(py_fmu):
    fmu, unzip, _ = py_fmu
    for platform, lib in (("linux64", "CushionClutch.so"), ("win64", "CushionClutch.dll")):
        guard = lief.parse(str(unzip / "binaries" / platform / lib))
        wrapper = unzip / "binaries" / platform / lib.replace("CushionClutch", "CushionClutch_pythonfmu")
        assert wrapper.exists(), wrapper
        if guard.format == lief.Binary.FORMATS.PE:
            exports = {e.name for e in guard.get_export().entries}
        else:
            exports = {s.name for s in guard.exported_functions}
        assert exports == fmi_functions(2) - ME_ONLY, (platform, exports ^ (fmi_functions(2) - ME_ONLY))


PROBE = r"""
import json, sys
from ctypes import byref
from fmpy import calloc, free
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                       fmi2CallbackLoggerTYPE)
from fmpy.logging import addLoggerProxy
unzip, guid, uri = sys.argv[1], sys.argv[2], None if sys.argv[3] == "NULL" else sys.argv[3]
messages = []
def log(env, name, status, category, message):
    messages.append(message.decode())
cb = fmi2CallbackFunctions()
cb.logger = fmi2CallbackLoggerTYPE(log)
cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
addLoggerProxy(byref(cb))             # fmpy's printf-formatting proxy, as a C host formats
s = FMU2Slave(guid=guid, unzipDirectory=unzip, modelIdentifier="CushionClutch", instanceName="g")
c = s.fmi2Instantiate(b"g", 1, guid.encode(), None if uri is None else uri.encode(), byref(cb), 0, 0)
print(json.dumps({"instance": bool(c), "messages": messages}))
"""


def test_guard_refusals_on_linux_are_logged_and_return_null(py_fmu, tmp_path):
    """fmpy's raw binding, one process per call (a crash fails the row): NULL location, a folder
    without the slave, a wrong GUID, a malformed URI -> NULL and a message through the logger."""
    _, unzip, guid = py_fmu
    cases = [(guid, "NULL", "fmuResourceLocation is NULL"),
             (guid, tmp_path.as_uri(), "no slave module"),
             ("{0-0}", (unzip / "resources").as_uri(), "does not match"),
             (guid, "file:///tmp/bad%zz", "bad percent-encoding")]
    for g, uri, text in cases:
        res = subprocess.run([sys.executable, "-c", PROBE, str(unzip), g, uri], capture_output=True, text=True,
                             timeout=120)
        assert res.returncode == 0, (uri, res.returncode, res.stderr[-1500:])
        out = json.loads(res.stdout.splitlines()[-1])
        assert not out["instance"] and any(text in m for m in out["messages"]), (uri, out)


def test_guard_under_wine_refuses_with_a_message_and_never_crashes(py_fmu, tmp_path, wine_env):
    """The win64 guard: a wrong folder and a wrong GUID are refused; with everything right and no Windows
    Python here, loading pythonfmu's wrapper fails, and that too is a message, not a crash."""
    _, unzip, guid = py_fmu
    host = _windows_host(tmp_path, 2)
    dll = "Z:" + str(unzip / "binaries" / "win64" / "CushionClutch.dll").replace("/", "\\")
    good = "file:///Z:" + (unzip / "resources").as_uri()[len("file://"):]
    for uri, g, text in [("file:///Z:/no/such/folder", guid, "no slave module"),
                         (good, "{0-0}", "does not match"),
                         (good, guid, "cannot load CushionClutch_pythonfmu.dll")]:
        res = subprocess.run([str(WINE), str(host), dll, uri, g, "10", "0.01"], env=wine_env, capture_output=True,
                             text=True, timeout=120)
        assert res.returncode == 1, (uri, res.returncode, res.stderr[-1500:])
        assert text in res.stderr and "fmi2Instantiate failed" in res.stderr, (uri, res.stderr[-1500:])


def test_c_host_never_aborts_at_exit(py_fmu, tmp_path):
    """Issue 28: pythonfmu 0.7's wrapper released its interpreter state twice at process exit (a static
    destructor, then its library destructor reading the freed block): a C host aborted after a complete,
    correct run (12 of 12 runs before the guard's exit handler). Now every run exits 0 with its outputs."""
    import os
    import sysconfig
    from pathlib import Path

    import numpy

    from cushion_clutch.benchmarks.fmu import compile_host
    _, unzip, guid = py_fmu
    host = compile_host(tmp_path / "host")
    env = dict(os.environ, LD_PRELOAD=os.path.join(sysconfig.get_config_var("LIBDIR"),
                                                   sysconfig.get_config_var("LDLIBRARY")),
               PYTHONPATH=str(Path(numpy.__file__).parents[1]))
    for run in range(6):
        res = subprocess.run([str(host), str(unzip / "binaries" / "linux64" / "CushionClutch.so"),
                              (unzip / "resources").as_uri(), guid, "20", "0.001"], capture_output=True, text=True,
                             timeout=120, env=env)
        assert res.returncode == 0, (run, res.returncode, res.stderr[-1500:])
        assert res.stdout.startswith("outputs "), (run, res.stdout)


FMPY_RUNS = r"""
import sys
from fmpy import simulate_fmu
for k in range(3):                      # fmpy loads and unloads the library for each run
    r = simulate_fmu(sys.argv[1], stop_time=0.02, output_interval=0.01, start_values={"x_to": 0.008})
print("torque", r["torque"][-1])
"""


def test_fmpy_runs_and_exits_cleanly(py_fmu):
    fmu, _, _ = py_fmu
    for run in range(3):
        res = subprocess.run([sys.executable, "-c", FMPY_RUNS, str(fmu)], capture_output=True, text=True, timeout=300)
        assert res.returncode == 0 and "torque" in res.stdout, (run, res.returncode, res.stderr[-1500:])
