"""The thermal FMU's fault catalogue (issue 39 item 8): one case per process, each judging itself.

``python tests/thermal_fault_cases.py CASE FMU`` runs one case against the thermal FMU (FMI 2.0, the CS or the ME
interface, through fmpy with a printf-formatting logger as a C host has) and prints one line
``RESULT {"case": ..., "ok": bool, "why": [...]}``: ``ok`` is the case's own verdict on what the FMU did (status,
message, state afterwards), ``why`` lists every expectation it missed. A host crash ends the process without the
line. ``tests/test_thermal_faults.py`` runs every case in its own process; ``--list`` prints the cases.

The cases: bad inputs (NaN, inf, out of range, a read after a refused input, bad step sizes), huge slip power for
minutes, bad parameters (start temperature, capacities, shares, wear), corrupted and crafted saved states, wrong
call order, and Model Exchange states beyond the nodes' range.
"""
from __future__ import annotations

import json
import math
import shutil
import struct
import sys
from ctypes import byref, c_double
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Model, FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)
from fmpy.logging import addLoggerProxy

NODE_MAX_K = 1273.15          # the bound on any node (1000 degC); the FMU must declare at most this
HOT = {"x_to": 0.012, "omega_slip": 1500.0, "omega_engine": 1500.0}     # about 470 kW of slip
OPEN = {"x_to": 0.0, "omega_slip": 0.0, "omega_engine": 100.0}
WARM = {"x_to": 0.007, "omega_slip": 100.0, "omega_engine": 100.0}


class Case:
    """One thermal FMU instance (CS or ME), its log and the case's verdict."""

    def __init__(self, fmu: str, me: bool = False):
        self.md = read_model_description(fmu)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.nodes = [v.name for v in self.md.modelVariables if v.name.startswith("theta_") and v.causality ==
                      "output" and v.name not in ("theta_cm", "theta_cs", "theta_friction")]   # the nodes only
        self.kelvin = [v.name for v in self.md.modelVariables if v.unit == "K" and v.causality == "output"]
        self.log: list[tuple[int, str]] = []
        self.why: list[str] = []
        self.cb = fmi2CallbackFunctions()
        self.cb.logger = fmi2CallbackLoggerTYPE(lambda c, n, st, cat, msg: self.log.append((st, msg.decode())))
        self.cb.allocateMemory, self.cb.freeMemory = defaultCallbacks.allocateMemory, defaultCallbacks.freeMemory
        addLoggerProxy(byref(self.cb))
        self.unzip = extract(fmu)
        self.me = me
        cls = FMU2Model if me else FMU2Slave
        self.s = cls(guid=self.md.guid, unzipDirectory=self.unzip, modelIdentifier="CushionClutchThermal",
                     instanceName="fault")
        self.s.instantiate(callbacks=self.cb)
        self.t = 0.0

    # -- calls, each returning its FMI status
    def call(self, fn, *args) -> int:
        try:
            fn(*args)
            return 0
        except FMICallException as e:
            return int(e.status)

    def start(self, params: dict | None = None) -> int:
        self.s.setupExperiment(startTime=0.0)
        if params:
            self.s.setReal([self.vr[k] for k in params], list(params.values()))
        self.s.enterInitializationMode()
        return self.call(self.s.exitInitializationMode)

    def set(self, values: dict) -> int:
        return self.call(self.s.setReal, [self.vr[k] for k in values], list(values.values()))

    def get(self, names) -> tuple[int, list[float]]:
        try:
            return 0, self.s.getReal([self.vr[k] for k in names])
        except FMICallException as e:
            return int(e.status), []

    def step(self, h: float, inputs: dict | None = None) -> int:
        """One CS step from the host's clock (which goes on whatever the FMU answers)."""
        if inputs:
            self.set(inputs)
        st = self.call(self.s.doStep, self.t, h)
        self.t += h
        return st

    def snapshot(self) -> list[float]:
        return self.s.getReal([self.vr[k] for k in ["theta_cm", "theta_cs", *self.nodes]])

    # -- verdict
    def expect(self, ok: bool, what: str) -> None:
        if not ok:
            self.why.append(what)

    def logged(self, pattern: str, since: int = 0, status: int | None = None) -> bool:
        return any(pattern in m and (status is None or st == status) for st, m in self.log[since:])

    def terminated(self) -> bool:
        return bool(self.s.getBooleanStatus(3))

    def close(self) -> None:
        try:
            self.s.freeInstance()
        finally:
            shutil.rmtree(self.unzip, ignore_errors=True)


# ----------------------------------------------------------------------------------------- bad inputs
def _refused_input(c: Case, name: str, value: float) -> None:
    c.start()
    for _ in range(10):
        c.step(0.01, WARM)
    before, last = c.snapshot(), c.s.getRealStatus(2)
    n = len(c.log)
    st = c.step(0.01, {name: value})
    c.expect(st == 2, f"step with {name} = {value!r}: status {st}, expected Discard")
    c.expect(c.logged(f"input {name} = ", n, 2), f"no Discard message naming {name}")
    c.expect(not c.terminated(), "fmi2Terminated true after a recoverable Discard")
    c.expect(c.s.getRealStatus(2) == last, "LastSuccessfulTime moved with a refused step")
    c.expect(c.snapshot() == before, "a refused step changed the temperatures (the states read OK)")
    c.expect(c.get(["torque"])[0] == 2, "torque read with OK from the refused input")
    c.expect(c.step(0.01, WARM) in (0, 1), "the next step with valid inputs was refused")


def c_nan_x_to(c):
    _refused_input(c, "x_to", math.nan)


def c_inf_omega_slip(c):
    _refused_input(c, "omega_slip", math.inf)


def c_nan_omega_engine(c):
    _refused_input(c, "omega_engine", math.nan)


def c_x_to_one_metre(c):
    _refused_input(c, "x_to", 1.0)


def c_read_after_refused_input(c):
    """x_to = 1 m set after a step, torque read: not a stale value with OK."""
    c.start()
    c.step(0.01, WARM)
    c.set({"x_to": 1.0})
    st, _ = c.get(["torque"])
    c.expect(st != 0, "torque read with OK after x_to = 1 m (a stale value)")
    c.expect(c.logged("x_to = 1", 0), "no message naming x_to = 1")


def _bad_step(c, h):
    c.start()
    c.step(0.01, WARM)
    before = c.snapshot()
    st = c.call(c.s.doStep, c.t, h)
    c.expect(st == 2, f"step size {h!r}: status {st}, expected Discard")
    c.expect(c.logged("step size", 0, 2), "no message on the step size")
    c.expect(c.snapshot() == before and not c.terminated(), "state changed or terminated by a bad step size")
    c.expect(c.step(0.01, WARM) in (0, 1), "no step after a bad step size")


def c_negative_step(c):
    _bad_step(c, -0.01)


def c_nan_step(c):
    _bad_step(c, math.nan)


# -------------------------------------------------------------------------------- huge slip power
def _huge(c: Case, seconds: float, h: float, open_s: float, h_open: float) -> None:
    c.start()
    maxima = {k: float(c.vars[k].max) if c.vars[k].max is not None else math.inf for k in c.kelvin}
    c.expect(all(v <= NODE_MAX_K for v in maxima.values()), f"an output in K declares no max or one above "
             f"{NODE_MAX_K} K: {maxima}")
    refused = silent = over = 0
    while c.t < seconds - 1e-9:
        n = len(c.log)
        before = c.snapshot()
        st = c.step(h, HOT)
        if st >= 2:
            refused += 1
            silent += not c.logged("", n, 2)
            c.expect(st == 2, f"status {st} (expected Discard) at t = {c.t:g} s")
            if c.snapshot() != before:
                c.why.append(f"a refused step changed the state at t = {c.t:g} s")
                break
        else:
            _, vals = c.get(c.kelvin)
            over += sum(v > maxima[k] for k, v in zip(c.kelvin, vals))
    c.expect(silent == 0, f"{silent} refused steps without a message")
    c.expect(over == 0, f"{over} outputs above their declared max with OK")
    c.expect(not c.terminated(), "Terminated after a refused step")
    taken = 0
    end = c.t + open_s
    while c.t < end - 1e-9:
        taken += c.step(h_open, OPEN) in (0, 1)
    c.expect(taken == round(open_s / h_open), f"only {taken} of {round(open_s / h_open)} open steps taken: the "
             "instance does not recover after cooling")
    _, vals = c.get(c.kelvin)
    c.expect(all(v <= maxima[k] for k, v in zip(c.kelvin, vals)), "above the declared max after cooling")
    print(f"  {refused} refused steps; after cooling max node {max(vals):.1f} K", file=sys.stderr)


def c_huge_slip_10s_then_open_600s(c):
    """The bar: 470 kW for 10 s in 10 ms steps, then 600 s open."""
    _huge(c, 10.0, 0.01, 600.0, 0.1)


def c_huge_slip_3_minutes(c):
    """470 kW for 3 minutes of the host's clock (mostly refused), then 10 minutes open."""
    _huge(c, 180.0, 0.01, 600.0, 0.5)


def c_huge_slip_one_long_step(c):
    """470 kW over one 30 s step (the exact-exponential step jumps far past the range), then open."""
    _huge(c, 30.0, 30.0, 60.0, 0.1)


# -------------------------------------------------------------------------------- bad parameters
def _bad_parameter(c, params: dict, text: str):
    n = len(c.log)
    st = c.start(params)
    c.expect(st == 3, f"{params}: exitInitializationMode status {st}, expected Error")
    c.expect(c.logged(text, n, 3), f"{params}: no Error message containing {text!r}")


def _declared(c, name):
    v = c.vars[name]
    return v.min is not None and v.max is not None


def c_network_start_900K(c):
    c.expect(_declared(c, "theta_network_start"), "theta_network_start declares no min and max")
    _bad_parameter(c, {"theta_network_start": 900.0}, "theta_network_start = 900")


def c_network_start_150K(c):
    _bad_parameter(c, {"theta_network_start": 150.0}, "theta_network_start = 150")


def c_network_start_nan(c):
    _bad_parameter(c, {"theta_network_start": math.nan}, "theta_network_start = nan")


def c_capacity_zero(c):
    name = next(k for k in c.vr if k.startswith("C_"))
    c.expect(c.vars[name].min is not None and float(c.vars[name].min) > 0.0, f"{name} declares no min > 0")
    _bad_parameter(c, {name: 0.0}, f"{name} = 0")


def c_shares_not_one(c):
    name = next(k for k in c.vr if k.startswith("heat_share_"))
    _bad_parameter(c, {name: 0.9}, "add up to")


def c_wear_past_declared_max(c):
    top = float(c.vars["facing_wear"].max)
    c.expect(top <= 0.0024, f"facing_wear declares max {top} m (> 2.4 mm)")
    _bad_parameter(c, {"facing_wear": max(top, 0.0024) + 1e-5}, "facing_wear")


def c_every_declared_parameter_max_is_accepted_alone(c):
    """Each network parameter at its declared max (one at a time, the rest default) initialises: the declared
    range is what initialisation accepts (the shares excepted: they must add up to 1)."""
    names = [n for n, v in c.vars.items() if v.causality == "parameter" and v.max is not None and n in c.vr and (
        n.startswith(("C_", "A_cooled_", "G_", "h_", "theta_network", "theta_engine", "convection")))]
    c.close()
    for name in names:
        d = Case(FMU, me=False)
        try:
            st = d.start({name: float(d.vars[name].max)})
            if st != 0:
                c.why.append(f"{name} = declared max {d.vars[name].max}: status {st}")
            elif d.step(0.01, WARM) not in (0, 1, 2):
                c.why.append(f"{name} = declared max: the step answered Error")
        finally:
            d.close()
    c.s = None


# -------------------------------------------------------------------------------------- saved states
def seal(blob: bytearray) -> bytes:
    """The native state with its FNV-1a 64 checksum recomputed (clutch_core.c fnv1a): a crafted state that only
    the range checks can refuse (also used by test_thermal_fmu)."""
    h = 1469598103934665603
    for b in blob[:-8]:
        h = ((h ^ b) * 1099511628211) & 0xFFFFFFFFFFFFFFFF
    blob[-8:] = struct.pack("<Q", h)
    return bytes(blob)


def _crafted(c, node_index: int, value: float, expect_refused: bool = True):
    c.start()
    for _ in range(5):
        c.step(0.01, WARM)
    before = c.snapshot()
    blob = bytearray(c.s.serializeFMUstate(c.s.getFMUstate()))
    name = c.nodes[node_index] if node_index >= 0 else "theta_cm"
    at = 40 + 8 * c.vr[name]
    blob[at:at + 8] = struct.pack("<d", value)
    n = len(c.log)
    try:
        state = c.s.deSerializeFMUstate(seal(blob))
        st = c.call(c.s.setFMUstate, state)
    except FMICallException as e:
        st = int(e.status)
    return name, st, n, before


def c_state_facing_node_minus_5K(c):
    name, st, n, before = _crafted(c, 3, -5.0)
    c.expect(st == 3, f"state with {name} = -5 K: status {st}, expected Error")
    c.expect(c.logged(name, n, 3), "no message naming the node")
    c.expect(c.snapshot() == before, "the refused state changed the instance")


def c_state_node_1e6K(c):
    name, st, n, before = _crafted(c, 0, 1e6)
    c.expect(st == 3, f"state with {name} = 1e6 K: status {st}, expected Error")
    c.expect(c.logged(name, n, 3), "no message naming the node")
    c.expect(c.step(0.01, WARM) in (0, 1) and max(c.snapshot()) < 1000.0, "runs on at a crafted temperature")


def c_state_theta_cm_inconsistent(c):
    """A state whose theta_cm disagrees with the facing nodes: theta_cm is the nodes' mean after the restore."""
    name, st, n, before = _crafted(c, -1, 5000.0)
    if st == 0:
        c.expect(c.snapshot()[0] == before[0], "theta_cm restored as 5000 K, not as the facing nodes' mean")
    else:
        c.expect(st == 3 and c.logged("", n, 3), "refused without Error and a message")


def c_state_truncated(c):
    c.start()
    c.step(0.01, WARM)
    blob = c.s.serializeFMUstate(c.s.getFMUstate())
    try:
        c.s.deSerializeFMUstate(blob[:-3])
        c.why.append("a truncated state was accepted")
    except FMICallException as e:
        c.expect(e.status == 3 and c.logged("bytes", 0, 3), "truncated: no Error with a message")


def c_state_flipped_byte(c):
    c.start()
    c.step(0.01, WARM)
    blob = bytearray(c.s.serializeFMUstate(c.s.getFMUstate()))
    blob[60] ^= 4
    try:
        c.s.deSerializeFMUstate(bytes(blob))
        c.why.append("a corrupted state was accepted")
    except FMICallException as e:
        c.expect(e.status == 3 and c.logged("checksum", 0, 3), "corrupted: no Error naming the checksum")


# -------------------------------------------------------------------------------------- call order
def c_step_before_init(c):
    st = c.call(c.s.doStep, 0.0, 0.01)
    c.expect(st == 3 and c.logged("not allowed", 0, 3), f"doStep before initialisation: status {st}")


def c_step_after_terminate(c):
    c.start()
    c.step(0.01, WARM)
    c.s.terminate()
    st = c.call(c.s.doStep, c.t, 0.01)
    c.expect(st == 3 and c.logged("not allowed", 0, 3), f"doStep after terminate: status {st}")


def c_set_theta_cm_output(c):
    c.start()
    st = c.set({"theta_cm": 400.0})
    c.expect(st == 3 and c.logged("theta_cm", 0, 3), f"setting the output theta_cm: status {st}")


def c_set_network_parameter_after_init(c):
    c.start()
    name = next(k for k in c.vr if k.startswith("C_"))
    st = c.set({name: 500.0})
    c.expect(st == 3 and c.logged("fixed after initialization", 0, 3), f"{name} after init: status {st}")
    c.expect(c.step(0.01, WARM) in (0, 1), "no step after a refused set")


def c_exit_init_twice(c):
    c.start()
    st = c.call(c.s.exitInitializationMode)
    c.expect(st == 3 and c.logged("not allowed", 0, 3), f"second exitInitializationMode: status {st}")


def c_reset_then_run(c):
    """After refused hot steps, fmi2Reset and a new start run from the start temperatures."""
    c.start()
    while c.t < 5.0:
        c.step(0.01, HOT)
    c.s.reset()
    c.t = 0.0
    st = c.start()
    c.expect(st == 0, f"restart after reset: status {st}")
    c.expect(all(abs(v - 293.15) < 1e-9 for v in c.snapshot()), "reset did not return to the start temperatures")
    c.expect(c.step(0.01, WARM) in (0, 1), "no step after reset")


# ---------------------------------------------------------------------------------- Model Exchange
def _me(c) -> tuple[list[float], int]:
    c.start()
    c.s.enterContinuousTimeMode()
    n = 1 + len(c.nodes)
    buf = (c_double * n)()
    c.s.getContinuousStates(buf, n)
    return list(buf), n


def c_me_node_past_max(c):
    x, n = _me(c)
    hot = list(x)
    hot[1] = NODE_MAX_K + 0.01
    m = len(c.log)
    st = c.call(c.s.setContinuousStates, (c_double * n)(*hot), n)
    c.expect(st == 2, f"ME state above {NODE_MAX_K} K: status {st}, expected Discard (as a refused CS step)")
    c.expect(c.logged(c.nodes[0], m, 2), "no Discard message naming the node")
    buf = (c_double * n)()
    c.s.getContinuousStates(buf, n)
    c.expect(list(buf) == x, "a refused ME state was applied")


def c_me_node_at_800K_accepted(c):
    """A node at 850 K (above the old 800 K, below the nodes' range): ME accepts it as CS does."""
    x, n = _me(c)
    x[1] = 850.0
    st = c.call(c.s.setContinuousStates, (c_double * n)(*x), n)
    c.expect(st == 0, f"ME state of 850 K in {c.nodes[0]}: status {st}, expected OK (CS accepts it)")


def c_me_nan_input_derivatives(c):
    x, n = _me(c)
    c.set({"x_to": math.nan})
    der = (c_double * n)()
    st = c.call(c.s.getDerivatives, der, n)
    c.expect(st == 2 and c.logged("x_to = nan", 0, 2), f"derivatives with x_to = NaN: status {st}")


CASES = {name[2:]: fn for name, fn in list(globals().items())
         if name.startswith("c_") and callable(fn) and getattr(fn, "__module__", None) == __name__}
FMU = ""


def main(argv) -> int:
    global FMU
    if argv[1:] == ["--list"]:
        print("\n".join(CASES))
        return 0
    case, FMU = argv[1], str(Path(argv[2]).resolve())
    c = Case(FMU, me=case.startswith("me_"))
    try:
        CASES[case](c)
    except FMICallException as e:          # a call that should have succeeded did not
        c.why.append(f"unexpected {e}")
    finally:
        if c.s is not None:
            c.close()
    print("RESULT " + json.dumps({"case": case, "ok": not c.why, "why": c.why}), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
