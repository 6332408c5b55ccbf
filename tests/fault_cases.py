"""The fault catalogue's case runner (issue 12): one misuse case against one FMU, in this process.

Run by ``tests/test_faults.py`` in a subprocess per case, so that a host
crash is a failing row, never a failing test session::

    python tests/fault_cases.py CASE FMU_FILE WORK_DIR

It prints one line ``RESULT {json}`` with the observations: statuses of the
probed calls, the log messages the FMU sent through the logger (formatted by
fmpy's native proxy, as a C host's printf-style logger would) and flags
computed by the case. ``test_faults.py`` holds the expectations.
"""
from __future__ import annotations

import ctypes
import json
import math
import os
import shutil
import sys
import threading
import zipfile
from ctypes import byref, c_size_t, create_string_buffer
from pathlib import Path

from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2CallbackAllocateMemoryTYPE,
                       fmi2CallbackFreeMemoryTYPE, fmi2FMUstate, fmi2Real, fmi2True, fmi2ValueReference,
                       fmi2Terminated, fmi2LastSuccessfulTime)

VR = {"x_to": 0, "theta_cm": 1, "torque": 2, "force": 3, "theta_cs": 4, "u_f": 5, "x_kiss": 6,
      "n_surfaces": 7, "mu": 8, "R_eq": 9, "U": 10, "H": 11, "C": 12, "theta_a": 13, "theta_cs_start": 14,
      "x_kiss_ref": 15, "lever_ratio": 16, "omega_slip": 17}
OUTS = [VR[n] for n in ("torque", "force", "theta_cs", "u_f", "x_kiss")]

LOGS: list[tuple[str, int, str]] = []
_lock = threading.Lock()


def _log(env, instance, status, category, message):
    with _lock:
        LOGS.append(((instance or b"").decode("utf-8", "replace"), int(status),
                     (message or b"").decode("utf-8", "replace")))


CALLBACKS = fmi2CallbackFunctions()
_LOGGER = fmi2CallbackLoggerTYPE(_log)
from fmpy import calloc, free  # noqa: E402
CALLBACKS.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
CALLBACKS.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
from fmpy.logging import addLoggerProxy  # noqa: E402


def install_logger() -> None:
    """Route fmpy's native printf-formatting proxy to ``_log`` (like a C host's logger).

    The proxy keeps one global Python logger; ``fmpy.simulate_fmu`` installs its
    own and drops it when it returns, so this is redone before every case.
    """
    CALLBACKS.logger = _LOGGER
    addLoggerProxy(byref(CALLBACKS))


def status(fn, *args) -> int:
    """The FMI status of a call (fmpy raises above Warning)."""
    try:
        res = fn(*args)
        return int(res) if isinstance(res, int) else 0
    except FMICallException as exc:
        return int(exc.status)


class Host:
    """One FMU unpacked in a work folder, with helpers for raw FMI 2.0 calls."""

    def __init__(self, fmu: Path, work: Path):
        self.fmu, self.work = Path(fmu), Path(work)
        self.md = read_model_description(str(fmu))
        self.dir = self.work / "unzipped"
        if not self.dir.exists():
            with zipfile.ZipFile(fmu) as z:
                z.extractall(self.dir)
        self.guid = self.md.guid
        self.native = not (self.dir / "resources" / "slavemodule.txt").exists()

    def slave(self, name="c", logging=True, resource_uri="default", guid=None, unzip=None) -> FMU2Slave:
        s = FMU2Slave(guid=self.guid, unzipDirectory=str(unzip or self.dir),
                      modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        uri = (Path(unzip or self.dir) / "resources").as_uri() if resource_uri == "default" else resource_uri
        s.component = s.fmi2Instantiate(name.encode(), 1, (guid or self.guid).encode(),
                                        None if uri is None else uri.encode(), byref(CALLBACKS), 0,
                                        fmi2True if logging else 0)
        s.callbacks = CALLBACKS
        return s

    @staticmethod
    def set(s, names, values) -> int:
        vrs = [VR[n] if isinstance(n, str) else n for n in names]
        return status(s.fmi2SetReal, s.component, (fmi2ValueReference * len(vrs))(*vrs), len(vrs),
                      (fmi2Real * len(vrs))(*values))

    @staticmethod
    def get(s, names) -> tuple[int, list[float]]:
        vrs = [VR[n] if isinstance(n, str) else n for n in names]
        out = (fmi2Real * len(vrs))()
        st = status(s.fmi2GetReal, s.component, (fmi2ValueReference * len(vrs))(*vrs), len(vrs), out)
        return st, list(out)

    @staticmethod
    def step(s, t, h) -> int:
        return status(s.fmi2DoStep, s.component, t, h, fmi2True)

    def ready(self, s, params=None) -> list[int]:
        sts = [status(s.fmi2SetupExperiment, s.component, 0, 0.0, 0.0, 0, 0.0),
               status(s.fmi2EnterInitializationMode, s.component)]
        if params:
            sts.append(self.set(s, list(params), list(params.values())))
        sts.append(status(s.fmi2ExitInitializationMode, s.component))
        return sts

    def run(self, s, n, t0=0.0, h=0.01) -> float:
        """n steps with a repeatable input sequence; returns the end time."""
        t = t0
        for k in range(n):
            self.set(s, ["x_to", "theta_cm"], [0.003 + 0.005 * ((k * 7919) % 1000) / 1000,
                                              300.0 + 300.0 * ((k * 104729) % 1000) / 1000])
            self.step(s, t, h)
            t += h
        return t

    def outs(self, s) -> list[float]:
        return self.get(s, OUTS)[1]

    @staticmethod
    def free(s) -> None:
        s.fmi2FreeInstance(s.component)

    # -- states (raw calls, bytes in and out) --
    @staticmethod
    def get_state(s):
        st = fmi2FMUstate()
        return status(s.fmi2GetFMUstate, s.component, byref(st)), st

    @staticmethod
    def serialize(s, st) -> tuple[int, bytes]:
        size = c_size_t()
        a = status(s.fmi2SerializedFMUstateSize, s.component, st, byref(size))
        buf = create_string_buffer(size.value)
        b = status(s.fmi2SerializeFMUstate, s.component, st, buf, size)
        return max(a, b), buf.raw[:size.value]

    @staticmethod
    def deserialize(s, data: bytes):
        st = fmi2FMUstate()
        buf = create_string_buffer(data, len(data))
        return status(s.fmi2DeSerializeFMUstate, s.component, buf, len(data), byref(st)), st

    @staticmethod
    def set_state(s, st) -> int:
        return status(s.fmi2SetFMUstate, s.component, st)

    def unzip_copy(self, name: str) -> Path:
        """A private copy of the unpacked FMU (to corrupt its resources)."""
        dst = self.work / name
        shutil.copytree(self.dir, dst)
        return dst


# ---------------------------------------------------------------------------------------------
# cases: each takes a Host and returns a dict of observations
def c_step_before_init(h):
    s = h.slave()
    return {"probe": h.step(s, 0.0, 0.1)}


def c_step_after_terminate(h):
    s = h.slave()
    h.ready(s)
    h.run(s, 10)
    t = status(s.fmi2Terminate, s.component)
    return {"terminate": t, "probe": h.step(s, 0.1, 0.1)}


def c_exit_init_after_steps(h):
    s = h.slave()
    h.ready(s)
    h.set(s, ["theta_cm"], [700.0])
    for k in range(200):
        h.step(s, k * 1.0, 1.0)
    before = h.outs(s)
    probe = status(s.fmi2ExitInitializationMode, s.component)
    return {"probe": probe, "unchanged": h.outs(s) == before, "theta_cs_K": before[2]}


def c_enter_init_midrun(h):
    s = h.slave()
    h.ready(s)
    h.run(s, 10)
    probe = status(s.fmi2EnterInitializationMode, s.component)
    set_mu = h.set(s, ["mu"], [0.56])
    return {"probe": probe, "set_mu": set_mu, "mu_unchanged": h.get(s, ["mu"])[1][0] == 0.28}


def c_terminate_before_init(h):
    s = h.slave()
    return {"probe": status(s.fmi2Terminate, s.component)}


def c_set_output(h):
    s = h.slave()
    h.ready(s)
    h.run(s, 10)
    before = h.outs(s)
    probe = h.set(s, ["torque"], [123.0])
    return {"probe": probe, "unchanged": h.outs(s) == before, "next_step": h.step(s, 0.1, 0.01)}


def c_set_theta_cs(h):
    s = h.slave()
    h.ready(s)
    h.run(s, 10)
    before = h.outs(s)
    probe = h.set(s, ["theta_cs"], [500.0])
    return {"probe": probe, "unchanged": h.outs(s) == before}


def c_set_fixed_param_after_init(h):
    s = h.slave()
    h.ready(s)
    h.set(s, ["x_to"], [0.006])
    h.step(s, 0.0, 0.01)
    torque = h.outs(s)[0]
    probe = h.set(s, ["mu"], [0.56])
    mu = h.get(s, ["mu"])[1][0]
    return {"probe": probe, "mu_unchanged": mu == 0.28, "torque_before": torque}


def c_set_param_in_init(h):
    """Positive control: a parameter set in initialisation mode is used (torque doubles with mu)."""
    a, b = h.slave("a"), h.slave("b")
    h.ready(a)
    sts = h.ready(b, {"mu": 0.56})
    for s in (a, b):
        h.set(s, ["x_to"], [0.006])
        h.step(s, 0.0, 0.01)
    ta, tb = h.outs(a)[0], h.outs(b)[0]
    return {"probe": max(sts), "ratio_ok": ta > 0 and abs(tb / ta - 2.0) < 1e-12}


def c_set_partially_bad(h):
    s = h.slave()
    h.ready(s)
    h.run(s, 5)
    before = h.get(s, ["x_to"])[1][0]
    probe = h.set(s, ["x_to", "torque"], [0.0055, 1.0])
    return {"probe": probe, "unchanged": h.get(s, ["x_to"])[1][0] == before}


def c_set_unknown_vr(h):
    s = h.slave()
    h.ready(s)
    return {"probe": h.set(s, [999], [1.0]), "next_step": h.step(s, 0.0, 0.01)}


def c_get_unknown_vr(h):
    s = h.slave()
    h.ready(s)
    st, vals = h.get(s, [999])
    return {"probe": st, "value_not_plausible": not math.isfinite(vals[0]) or st >= 3}


def c_set_integer(h):
    s = h.slave()
    h.ready(s)
    vr = (fmi2ValueReference * 1)(0)
    return {"probe": status(s.fmi2SetInteger, s.component, vr, 1, (ctypes.c_int * 1)(1))}


def c_negative_step(h):
    s = h.slave()
    h.ready(s)
    return {"probe": h.step(s, 0.0, -0.1)}


def c_nan_step(h):
    s = h.slave()
    h.ready(s)
    return {"probe": h.step(s, 0.0, math.nan)}


def c_nan_input(h):
    s = h.slave()
    h.ready(s)
    h.set(s, ["x_to"], [math.nan])
    return {"probe": h.step(s, 0.0, 0.01)}


def c_inf_input(h):
    s = h.slave()
    h.ready(s)
    h.set(s, ["theta_cm"], [math.inf])
    return {"probe": h.step(s, 0.0, 0.01)}


def c_time_backwards(h):
    s = h.slave()
    h.ready(s)
    h.step(s, 0.0, 0.1)
    probe = h.step(s, 0.05, 0.1)
    return {"probe": probe}


def c_n_surfaces_fraction(h):
    s = h.slave()
    sts = h.ready(s, {"n_surfaces": 2.5})
    return {"probe": max(sts[2:]), "next_step": h.step(s, 0.0, 0.01)}


def c_c_zero(h):
    s = h.slave()
    sts = h.ready(s, {"C": 0.0})
    return {"probe": max(sts[2:]), "next_step": h.step(s, 0.0, 0.01)}


def c_state_roundtrip(h):
    s = h.slave()
    h.ready(s)
    t = h.run(s, 2000)
    a, st = h.get_state(s)
    b, data = h.serialize(s, st)
    h.run(s, 500, t)
    ref = h.outs(s)
    c, st2 = h.deserialize(s, data)
    d = h.set_state(s, st2)
    h.run(s, 500, t)
    return {"probe": max(a, b, c, d), "identical": h.outs(s) == ref}


def _saved(h, s, n=100):
    h.ready(s)
    t = h.run(s, n)
    _, st = h.get_state(s)
    return t, h.serialize(s, st)[1]


def c_state_truncated(h):
    s = h.slave()
    t, data = _saved(h, s)
    before = h.outs(s)
    a, st = h.deserialize(s, data[: len(data) // 2])
    b = h.set_state(s, st) if a < 3 else a
    return {"probe": max(a, b), "unchanged": h.outs(s) == before, "next_step": h.step(s, t, 0.01)}


def c_state_corrupted(h):
    s = h.slave()
    t, data = _saved(h, s)
    before = h.outs(s)
    bad = bytearray(data)
    bad[len(bad) // 2] ^= 0x5A
    a, st = h.deserialize(s, bytes(bad))
    b = h.set_state(s, st) if a < 3 else a
    return {"probe": max(a, b), "unchanged": h.outs(s) == before}


def _with_nan_C(h, data: bytes) -> bytes:
    """The state with C (set to 1.2345678 J/K) replaced by NaN; the envelope re-signed where we can."""
    if h.native:
        import struct
        key = struct.pack("<d", 1.2345678)
        assert key in data, "C not found in the native state"
        return data.replace(key, struct.pack("<d", math.nan))
    outer = json.loads(data)
    state = json.loads(outer["state"])
    state["C"] = math.nan
    return _resign(outer, state)


def _resign(outer: dict, state: dict) -> bytes:
    """A pythonfmu state envelope around ``state`` with a correct checksum."""
    import zlib
    outer["state"] = json.dumps(state, sort_keys=True)
    outer["crc32"] = format(zlib.crc32(outer["state"].encode("utf-8")), "08x")
    return json.dumps(outer).encode()


def c_state_nan_parameter(h):
    s = h.slave()
    h.ready(s, {"C": 1.2345678})
    t = h.run(s, 50)
    _, st = h.get_state(s)
    data = h.serialize(s, st)[1]
    before = h.outs(s)
    a, st2 = h.deserialize(s, _with_nan_C(h, data))
    b = h.set_state(s, st2) if a < 3 else a
    nxt = h.step(s, t, 0.01)
    outs = h.outs(s)
    return {"probe": max(a, b), "no_nan_output": all(math.isfinite(v) for v in outs),
            "unchanged": outs == before or nxt == 0, "next_step": nxt}


def c_state_bad_phase(h):
    if h.native:
        return {"skip": "native state layout is the fmu engineer's; covered by the checksum rows"}
    s = h.slave()
    t, data = _saved(h, s)
    outer = json.loads(data)
    state = json.loads(outer["state"])
    state["_phase"] = "bogus"
    before = h.outs(s)
    a, st = h.deserialize(s, _resign(outer, state))
    b = h.set_state(s, st)
    return {"probe": max(a, b), "unchanged": h.outs(s) == before}


def _table_case(h, name, mutate):
    d = h.unzip_copy(name)
    mutate(d / "resources" / "tables")
    s = h.slave(unzip=d)
    if not s.component:
        return {"instantiated": False, "probe": 3}
    sts = h.ready(s)
    return {"instantiated": True, "probe": max(sts), "next_step": h.step(s, 0.0, 0.01),
            "torque": h.outs(s)[0]}


def _rows(path):
    lines = path.read_text().splitlines()
    return lines[0], lines[1:]


def c_table_one_row(h):
    def mutate(t):
        head, rows = _rows(t / "force_deflection.csv")
        seen, keep = set(), []
        for r in rows:
            if r.split(",")[0] not in seen:
                seen.add(r.split(",")[0])
                keep.append(r)
        (t / "force_deflection.csv").write_text("\n".join([head, *keep]) + "\n")
    return _table_case(h, "one_row", mutate)


def c_table_missing(h):
    return _table_case(h, "missing", lambda t: (t / "force_deflection.csv").unlink())


def c_table_descending(h):
    def mutate(t):
        head, rows = _rows(t / "force_deflection.csv")
        groups: dict[str, list[str]] = {}
        for r in rows:
            groups.setdefault(r.split(",")[0], []).append(r)
        out = [r for k in sorted(groups, key=float, reverse=True) for r in groups[k]]
        (t / "force_deflection.csv").write_text("\n".join([head, *out]) + "\n")
        head, rows = _rows(t / "kiss_point.csv")
        (t / "kiss_point.csv").write_text("\n".join([head, *reversed(rows)]) + "\n")
    res = _table_case(h, "descending", mutate)
    s = h.slave("ref")
    h.ready(s)
    h.step(s, 0.0, 0.01)
    res["same_torque"] = res.get("torque") == h.outs(s)[0]
    return res


def c_table_format_chars(h):
    def mutate(t):
        head, rows = _rows(t / "force_deflection.csv")
        rows[3] = rows[3].rsplit(",", 1)[0] + ",%s%n%s%n"
        (t / "force_deflection.csv").write_text("\n".join([head, *rows]) + "\n")
    return _table_case(h, "format_chars", mutate)


def c_table_huge_force(h):
    def mutate(t):
        head, rows = _rows(t / "force_deflection.csv")
        last = [i for i, r in enumerate(rows) if r.split(",")[0] == rows[0].split(",")[0]][-1]
        rows[last] = rows[last].rsplit(",", 1)[0] + ",1e308"
        (t / "force_deflection.csv").write_text("\n".join([head, *rows]) + "\n")
    return _table_case(h, "huge_force", mutate)


def c_path_format_chars(h):
    d = h.unzip_copy("dir %s%n %d")
    s = h.slave(unzip=d)
    if not s.component:
        return {"instantiated": False, "probe": 3}
    sts = h.ready(s)
    h.set(s, ["x_to"], [0.006])
    return {"instantiated": True, "probe": max(sts + [h.step(s, 0.0, 0.01)]), "torque_ok": h.outs(s)[0] > 0}


def _ready_and_step(h, s):
    """A refused instantiation is probe 3; else initialise, take one step and give the worst status."""
    if not s.component:
        return {"instantiated": False, "probe": 3}
    sts = h.ready(s)
    return {"instantiated": True, "probe": max(sts + [h.step(s, 0.0, 0.01)])}


def c_resources_null(h):
    return _ready_and_step(h, h.slave(resource_uri=None))


def c_resources_missing(h):
    d = h.unzip_copy("nores")
    shutil.rmtree(d / "resources")
    (d / "resources").mkdir()
    return _ready_and_step(h, h.slave(unzip=d))


def c_wrong_guid(h):
    s = h.slave(guid="{00000000-0000-0000-0000-000000000000}")
    return {"instantiated": bool(s.component), "probe": 0 if s.component else 3}


def c_logging_off(h):
    s = h.slave(logging=False)
    return {"probe": h.step(s, 0.0, 0.1)}


def c_discard_status(h):
    s = h.slave()
    h.ready(s)
    h.step(s, 0.0, 0.01)
    h.set(s, ["x_to"], [math.nan])
    probe = h.step(s, 0.01, 0.01)
    term, last = ctypes.c_int(0), ctypes.c_double(math.nan)
    a = status(s.fmi2GetBooleanStatus, s.component, fmi2Terminated, byref(term))
    b = status(s.fmi2GetRealStatus, s.component, fmi2LastSuccessfulTime, byref(last))
    return {"probe": probe, "bool_status": a, "real_status": b, "last_time": last.value,
            "terminated": bool(term.value)}


def c_simulate_refused(h):
    from fmpy import simulate_fmu
    try:
        res = simulate_fmu(str(h.fmu), start_values={"C": 0.0}, stop_time=2.0, output_interval=0.1,
                           logger=lambda *a: None)
        return {"probe": 0, "rows": len(res)}
    except Exception as exc:  # noqa: BLE001 - the point: the run must not end silently
        return {"probe": 3, "error": str(exc)[:200]}


def c_reset_after_fault(h):
    s = h.slave()
    h.ready(s)
    h.set(s, ["torque"], [1.0])
    r = status(s.fmi2Reset, s.component)
    sts = h.ready(s)
    h.set(s, ["x_to"], [0.006])
    return {"probe": max([r, *sts, h.step(s, 0.0, 0.01)]), "torque_ok": h.outs(s)[0] > 0}


def c_fifty_instances(h):
    ss = [h.slave(f"i{k}") for k in range(50)]
    ok = all(s.component for s in ss)
    for s in ss:
        h.ready(s)
    ends = [h.outs(s) for s in ss if h.run(s, 20) is not None]
    for s in ss:
        h.free(s)
    return {"probe": 0 if ok else 3, "identical": all(e == ends[0] for e in ends)}


def _rss_mb():
    return int(Path("/proc/self/statm").read_text().split()[1]) * 4096 / 1e6


def c_cycles_1000(h):
    def cycle(k):
        s = h.slave(f"c{k}")
        h.ready(s)
        h.step(s, 0.0, 0.01)
        status(s.fmi2Terminate, s.component)
        h.free(s)
    for k in range(50):
        cycle(k)
    r0 = _rss_mb()
    for k in range(1000):
        cycle(k)
    return {"probe": 0, "rss_growth_MB": round(_rss_mb() - r0, 2), "sys_path_entries": len(sys.path)}


def c_threads_8(h):
    serial = h.slave("serial")
    h.ready(serial)
    h.run(serial, 2000)
    ref = h.outs(serial)
    results = {}

    def work(k):
        s = h.slave(f"t{k}")
        h.ready(s)
        h.run(s, 2000)
        results[k] = h.outs(s)
    threads = [threading.Thread(target=work, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return {"probe": 0, "identical": len(results) == 8 and all(r == ref for r in results.values())}


CASES = {name[2:]: fn for name, fn in list(globals().items())
         if name.startswith("c_") and getattr(fn, "__module__", None) == __name__ and callable(fn)}


def main(argv):
    """``CASE FMU WORK``: one case; ``all FMU WORK``: every case in this process (sanitizer runs)."""
    case, fmu, work = argv[1], Path(argv[2]).resolve(), Path(argv[3]).resolve()
    native = True
    for name in (CASES if case == "all" else [case]):
        (work / name).mkdir(parents=True, exist_ok=True)
        del LOGS[:]
        install_logger()
        host = Host(fmu, work / name)
        native = host.native
        obs = CASES[name](host)
        obs["logs"] = LOGS[-40:]
        obs["case"] = name
        print("RESULT " + json.dumps(obs), flush=True)
    if not native and case != "all":
        # pythonfmu's wrapper can abort in its own teardown at process exit ("corrupted double-linked
        # list", README "Teardown in C hosts"): the row judges what the FMU did, which is printed and
        # flushed; the process ends without running the exit handlers that reach the abort
        sys.stderr.flush()
        os._exit(0)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
