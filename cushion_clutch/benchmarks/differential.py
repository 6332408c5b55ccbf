"""Differential test of the FMU backends: the same seeded random FMI call sequences through each FMU.

Every sequence instantiates each FMU, sets start parameters (valid ones: wear, start temperature,
thermal constants), initialises, then runs random calls: ``set`` of the inputs (in and out of
range, NaN and inf among them), ``get`` of any variables, ``doStep`` (valid, zero, negative and
NaN step sizes), ``getFMUstate``/``setFMUstate`` and ``reset`` (followed by a new initialisation).
At every call the FMUs must return the same status, and every value read must agree to
``REL_TOL`` (relative; NaN equals NaN). The first difference of a sequence is reported with the
call that made it. The reference is the native FMI 2.0 Co-Simulation FMU; compared with it are the
pythonfmu FMU (FMI 2.0 CS) and, optionally, the native FMI 3.0 CS FMU (the same calls in FMI 3.0:
no setupExperiment, the start time at enterInitializationMode).

Run at a larger size than CI does::

    python3 -m cushion_clutch.benchmarks.differential --sequences 400 [--calls 60] [--fmi3]

``tests/test_differential.py`` runs 40 sequences of the same generator in CI.
"""
from __future__ import annotations

import argparse
import math
import random
import shutil
import tempfile
import time
from ctypes import byref
from dataclasses import dataclass, field
from pathlib import Path

#: relative tolerance of every value compared; absolute floor by unit (values that should be 0)
REL_TOL = 1e-9
ABS_TOL = {"m": 1e-15, "rad/s": 1e-12}
ABS_TOL_DEFAULT = 1e-9

INPUTS = ("x_to", "theta_cm", "omega_slip")
STATUS = ("OK", "Warning", "Discard", "Error", "Fatal", "Pending")


# ------------------------------------------------------------------------------------------ generator
def _input_value(rng: random.Random, name: str) -> float:
    """An input value: mostly in range, sometimes at or past a bound, NaN or inf."""
    r = rng.random()
    if r < 0.05:
        return math.nan
    if r < 0.08:
        return rng.choice((math.inf, -math.inf))
    if r < 0.16:                      # out of range: past the FMU's accepted bounds
        return {"x_to": rng.choice((1.5, -2.0, 1.0 + 1e-9)), "theta_cm": rng.choice((0.0, -5.0, 2000.0, 2500.0)),
                "omega_slip": rng.choice((1e4 * (1 + 1e-9), -2e4))}[name]
    if name == "x_to":
        return rng.choice((rng.uniform(0.0, 0.014), rng.uniform(-0.002, 0.02), 0.0, 0.008, 0.004, 1.0))
    if name == "theta_cm":              # up to 1700 K: the hot cover that cannot hold the cushion
        return rng.choice((rng.uniform(280.0, 700.0), rng.uniform(250.0, 1800.0), 293.15))
    return rng.choice((0.0, rng.uniform(-300.0, 300.0)))


def _parameters(rng: random.Random) -> dict[str, float]:
    """Valid start parameters: wear, start and ambient temperatures, thermal constants (or none)."""
    if rng.random() < 0.3:
        return {}
    out = {}
    if rng.random() < 0.5:
        out["facing_wear"] = rng.choice((0.0, 0.5e-3, 1.5e-3, 2.5e-3, rng.uniform(0.0, 3e-3)))
    if rng.random() < 0.5:
        out["theta_cs_start"] = rng.choice((293.15, 573.15, rng.uniform(250.0, 800.0)))
    if rng.random() < 0.3:
        out["C"] = rng.uniform(0.05, 5.0)
        out["U"] = rng.uniform(0.0, 2.0)
    return out


def _step_size(rng: random.Random) -> float:
    r = rng.random()
    if r < 0.04:
        return math.nan
    if r < 0.08:
        return -rng.uniform(1e-3, 1.0)
    if r < 0.14:
        return 0.0
    return rng.choice((1e-3, 0.01, 0.1, rng.uniform(1e-4, 2.0), 30.0))


def sequence(seed: int, calls: int, names: list[str]) -> list[tuple]:
    """The calls of sequence ``seed``: ("init", params), ("set", {name: v}), ("get", [names]),
    ("step", h, offset of the step's start from the master's time), ("save",), ("restore",), ("reset", params)."""
    rng = random.Random(seed)
    out: list[tuple] = [("init", _parameters(rng))]
    for _ in range(calls):
        r = rng.random()
        if r < 0.35:
            k = rng.choice((1, 1, 2, 3))
            out.append(("set", {n: _input_value(rng, n) for n in rng.sample(INPUTS, k)}))
        elif r < 0.65:
            out.append(("get", rng.sample(names, rng.randint(1, min(8, len(names))))))
        elif r < 0.88:                  # now and then from a time the last step did not end at (fmi2Warning)
            out.append(("step", _step_size(rng), rng.choice((-0.05, 0.02)) if rng.random() < 0.05 else 0.0))
        elif r < 0.94:
            out.append(("save",))
        elif r < 0.985:
            out.append(("restore",))
        else:
            out.append(("reset", _parameters(rng)))
    out.append(("get", list(names)))
    return out


# ------------------------------------------------------------------------------------------- backends
class _Log:
    """Messages of one FMU instance: the last few (for the report of a difference) and the worst
    status among the messages of the current call."""

    def __init__(self):
        self.lines: list[str] = []
        self.worst = 0

    def add(self, status: int, message: str) -> None:
        self.lines.append(f"[{STATUS[status] if 0 <= status < 6 else status}] {message}")
        self.worst = max(self.worst, status)
        del self.lines[:-6]


#: the logs by instance name: fmpy's printf proxy keeps one Python logger for every FMI 2.0 instance
_LOGS: dict[str, _Log] = {}


#: the ctypes logger given to fmpy's printf proxy (never freed: the proxy holds it in a C global)
_LOGGER_C = None


def _fmi2_logger(env, instance, status, category, message):
    log = _LOGS.get((instance or b"").decode("utf-8", "replace"))
    if log is not None:
        log.add(int(status), (message or b"").decode("utf-8", "replace"))


def _status(fn, *args) -> int:
    from fmpy.fmi1 import FMICallException
    try:
        return int(fn(*args))
    except FMICallException as exc:
        return int(exc.status)


class Fmi2CS:
    """One FMI 2.0 Co-Simulation FMU driven through fmpy's low-level functions, statuses kept."""

    fmi = 2

    def __init__(self, path: Path, label: str):
        from fmpy import extract, read_model_description
        self.label, self.path = label, Path(path)
        self.md = read_model_description(str(path))
        self.unzip = extract(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.units = {v.name: (v.unit or getattr(v.declaredType, "unit", None) or "") for v in self.md.modelVariables}
        self.log = _LOGS[label] = _Log()
        self.slave = None
        self.state = None

    def close(self) -> None:
        shutil.rmtree(self.unzip, ignore_errors=True)

    def _callbacks(self):
        from fmpy import calloc, free
        from fmpy.fmi2 import (fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                               fmi2CallbackLoggerTYPE)
        from fmpy.logging import addLoggerProxy

        global _LOGGER_C
        cb = fmi2CallbackFunctions()
        if _LOGGER_C is None:   # one for the process: fmpy's proxy keeps a global pointer to the last one
            _LOGGER_C = fmi2CallbackLoggerTYPE(_fmi2_logger)
        cb.logger = _LOGGER_C
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(cb))                           # fmpy formats the printf message
        return cb

    def instantiate(self) -> None:
        from fmpy.fmi2 import FMU2Slave
        self.slave = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzip,
                               modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=self.label)
        self._cb = self._callbacks()
        self.slave.instantiate(callbacks=self._cb, loggingOn=True)
        self.state = None

    def free(self) -> None:
        if self.slave is not None:
            if self.state is not None:
                _status(self.slave.fmi2FreeFMUstate, self.slave.component, byref(self.state))
            self.slave.fmi2FreeInstance(self.slave.component)
            self.slave = None

    # each call: its FMI status (and values for get)
    def init(self, t0: float, params: dict) -> list[int]:
        s = self.slave
        out = [_status(s.fmi2SetupExperiment, s.component, 0, 0.0, t0, 0, 0.0)]
        if params:
            out.append(self.set(params))
        out.append(_status(s.fmi2EnterInitializationMode, s.component))
        out.append(_status(s.fmi2ExitInitializationMode, s.component))
        return out

    def set(self, values: dict) -> int:
        from fmpy.fmi2 import fmi2Real, fmi2ValueReference
        n = len(values)
        vr = (fmi2ValueReference * n)(*(self.vr[k] for k in values))
        return _status(self.slave.fmi2SetReal, self.slave.component, vr, n, (fmi2Real * n)(*values.values()))

    def get(self, names: list[str]) -> tuple[int, list[float]]:
        from fmpy.fmi2 import fmi2Real, fmi2ValueReference
        n = len(names)
        vr = (fmi2ValueReference * n)(*(self.vr[k] for k in names))
        v = (fmi2Real * n)()
        return _status(self.slave.fmi2GetReal, self.slave.component, vr, n, v), list(v)

    def step(self, t: float, h: float) -> int:
        return _status(self.slave.fmi2DoStep, self.slave.component, t, h, 1)

    def save(self) -> int:
        from fmpy.fmi2 import fmi2FMUstate
        if self.state is None:
            self.state = fmi2FMUstate()
        return _status(self.slave.fmi2GetFMUstate, self.slave.component, byref(self.state))

    def restore(self) -> int:
        return _status(self.slave.fmi2SetFMUstate, self.slave.component, self.state)

    def reset(self) -> int:
        return _status(self.slave.fmi2Reset, self.slave.component)


class Fmi2ME(Fmi2CS):
    """The same FMU's FMI 2.0 Model Exchange interface with the same calls but steps (a CS step has no ME
    counterpart the FMU answers by itself; :func:`compare` with ``steps=False`` leaves them out)."""

    def instantiate(self) -> None:
        from fmpy.fmi2 import FMU2Model
        self.slave = FMU2Model(guid=self.md.guid, unzipDirectory=self.unzip,
                               modelIdentifier=self.md.modelExchange.modelIdentifier, instanceName=self.label)
        self._cb = self._callbacks()
        self.slave.instantiate(callbacks=self._cb, loggingOn=True)
        self.state = None

    def step(self, t: float, h: float) -> int:
        raise TypeError("Model Exchange has no doStep: compare(..., steps=False)")


class Fmi3CS(Fmi2CS):
    """The native FMI 3.0 Co-Simulation FMU with the same calls (FMI 3.0 has no setupExperiment)."""

    fmi = 3

    def instantiate(self) -> None:
        from fmpy.fmi3 import FMU3Slave

        def logger(env, status, category, message):
            self.log.add(int(status), (message or b"").decode("utf-8", "replace"))

        self.slave = FMU3Slave(guid=self.md.guid, unzipDirectory=self.unzip,
                               modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=self.label)
        self.slave.instantiate(loggingOn=True, logMessage=logger)
        self.state = None

    def free(self) -> None:
        if self.slave is not None:
            if self.state is not None:
                _status(self.slave.fmi3FreeFMUState, self.slave.component, byref(self.state))
            self.slave.fmi3FreeInstance(self.slave.component)
            self.slave = None

    def init(self, t0: float, params: dict) -> list[int]:
        s = self.slave
        out = [0]                                       # in place of FMI 2.0's setupExperiment
        if params:
            out.append(self.set(params))
        out.append(_status(s.fmi3EnterInitializationMode, s.component, False, 0.0, t0, False, 0.0))
        out.append(_status(s.fmi3ExitInitializationMode, s.component))
        return out

    def set(self, values: dict) -> int:
        from fmpy.fmi3 import fmi3Float64, fmi3ValueReference
        n = len(values)
        vr = (fmi3ValueReference * n)(*(self.vr[k] for k in values))
        return _status(self.slave.fmi3SetFloat64, self.slave.component, vr, n, (fmi3Float64 * n)(*values.values()), n)

    def get(self, names: list[str]) -> tuple[int, list[float]]:
        from fmpy.fmi3 import fmi3Float64, fmi3ValueReference
        n = len(names)
        vr = (fmi3ValueReference * n)(*(self.vr[k] for k in names))
        v = (fmi3Float64 * n)()
        return _status(self.slave.fmi3GetFloat64, self.slave.component, vr, n, v, n), list(v)

    def step(self, t: float, h: float) -> int:
        from fmpy.fmi3 import fmi3Boolean, fmi3Float64
        ev, term, early, last = fmi3Boolean(), fmi3Boolean(), fmi3Boolean(), fmi3Float64()
        return _status(self.slave.fmi3DoStep, self.slave.component, t, h, fmi3Boolean(True), byref(ev), byref(term),
                       byref(early), byref(last))

    def save(self) -> int:
        from fmpy.fmi3 import fmi3FMUState
        if self.state is None:
            self.state = fmi3FMUState()
        return _status(self.slave.fmi3GetFMUState, self.slave.component, byref(self.state))

    def restore(self) -> int:
        return _status(self.slave.fmi3SetFMUState, self.slave.component, self.state)

    def reset(self) -> int:
        return _status(self.slave.fmi3Reset, self.slave.component)


# ------------------------------------------------------------------------------------------- the run
@dataclass
class Difference:
    """The first call of a sequence at which a backend differs from the reference."""

    seed: int
    index: int
    call: tuple
    what: str
    reference_log: list[str] = field(default_factory=list)
    other_log: list[str] = field(default_factory=list)

    def __str__(self) -> str:
        call = self.call if self.call[0] != "get" or len(self.call[1]) < 6 else ("get", f"{len(self.call[1])} variables")
        return (f"seed {self.seed}, call {self.index} {call}: {self.what}"
                + "".join(f"\n    reference: {m}" for m in self.reference_log[-2:])
                + "".join(f"\n    other:     {m}" for m in self.other_log[-2:]))


def _close(a: float, b: float, unit: str) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    return math.isclose(a, b, rel_tol=REL_TOL, abs_tol=ABS_TOL.get(unit, ABS_TOL_DEFAULT))


def _drive(fmu: Fmi2CS, op: tuple, clock: list[float]):
    """Apply one call; return what it gives (statuses, values). ``clock`` is the master's time."""
    kind = op[0]
    if kind in ("init", "reset"):
        pre = [fmu.reset()] if kind == "reset" else []
        if kind == "reset":
            clock[0] = 0.0
        return pre + fmu.init(clock[0], op[1]), None
    if kind == "set":
        return [fmu.set(op[1])], None
    if kind == "get":
        st, v = fmu.get(op[1])
        return [st], v
    if kind == "step":
        return [fmu.step(clock[0] + op[2], op[1])], None
    if kind == "save":
        return [fmu.save()], None
    if kind == "restore":
        return [fmu.restore()], None
    raise ValueError(kind)


@dataclass
class Outcome:
    """One sequence: its first difference (None: none), the calls compared, the statuses seen."""

    difference: Difference | None
    calls: int
    warnings: int = 0             #: calls both answered with fmi2Warning
    discards: int = 0             #: calls both answered with fmi2Discard
    errors: int = 0               #: calls both answered with fmi2Error
    gets_after_set: int = 0       #: reads right after an fmi2SetReal of an input


def compare(reference: Fmi2CS, other: Fmi2CS, seed: int, calls: int, steps: bool = True) -> Outcome:
    """Run sequence ``seed`` through both FMUs, call by call (``steps=False``: without its steps, for a Model
    Exchange instance)."""
    from cushion_clutch.model.clutch_model import VARIABLES
    names = [n for n, *_ in VARIABLES]          # in every backend: the same sequences in every comparison
    ops = [op for op in sequence(seed, calls, names) if steps or op[0] != "step"]
    reference.instantiate()
    other.instantiate()
    clock, saved_clock = [0.0], None
    seen = Outcome(None, 0)
    try:
        for i, op in enumerate(ops):
            if op[0] == "restore" and saved_clock is None:
                continue
            t = clock[0]
            for log in (reference.log, other.log):            # the messages of this call only
                log.worst, log.lines = 0, []
            s_ref, v_ref = _drive(reference, op, clock)
            clock[0] = t
            s_oth, v_oth = _drive(other, op, clock)
            if s_ref != s_oth:
                return Outcome(Difference(seed, i, op, f"status {[STATUS[s] for s in s_ref]} vs "
                                          f"{[STATUS[s] for s in s_oth]}", reference.log.lines, other.log.lines), i + 1)
            if v_ref is not None:
                bad = [(n, a, b) for n, a, b in zip(op[1], v_ref, v_oth) if not _close(a, b, reference.units.get(n, ""))]
                if bad:
                    text = ", ".join(f"{n} {a:.10g} vs {b:.10g}" for n, a, b in bad[:4])
                    return Outcome(Difference(seed, i, op, text, reference.log.lines, other.log.lines), i + 1)
            seen.warnings += max(s_ref) == 1
            seen.discards += max(s_ref) == 2
            seen.errors += max(s_ref) == 3
            seen.gets_after_set += op[0] == "get" and i > 0 and ops[i - 1][0] == "set"
            # the master's time: advanced by accepted steps only (a refused one is retried from t), back to
            # the saved time with a restored state
            if op[0] == "save" and s_ref[0] == 0:
                saved_clock = clock[0]
            elif op[0] == "restore" and s_ref[0] == 0:
                clock[0] = saved_clock
            elif op[0] == "step" and s_ref[0] <= 1:
                clock[0] += op[2] + op[1]
        seen.calls = len(ops)
        return seen
    finally:
        reference.free()
        other.free()


def run(reference: Fmi2CS, other: Fmi2CS, seeds, calls: int, steps: bool = True) -> list[Outcome]:
    """Every sequence of ``seeds`` through both FMUs (``steps=False``: without their steps)."""
    return [compare(reference, other, seed, calls, steps) for seed in seeds]


def build_fmus(folder: Path, fmi3: bool = False) -> dict[str, Path]:
    """The FMUs compared: native FMI 2.0 (reference), pythonfmu FMI 2.0 and, with ``fmi3``, native FMI 3.0."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu
    out = {"native2": build_fmu(DEFAULT_TABLES, folder / "native2.fmu", backend="native", fmi_version=2),
           "python2": build_fmu(DEFAULT_TABLES, folder / "python2.fmu", backend="python")}
    if fmi3:
        out["native3"] = build_fmu(DEFAULT_TABLES, folder / "native3.fmu", backend="native", fmi_version=3)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sequences", type=int, default=400)
    ap.add_argument("--calls", type=int, default=60, help="random calls per sequence (after the initialisation)")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--fmi3", action="store_true", help="also compare the native FMI 3.0 CS FMU")
    ap.add_argument("--show", type=int, default=3, help="differences printed in full")
    ap.add_argument("--fmus", type=Path, help="use native2.fmu, python2.fmu (and native3.fmu) from this folder "
                                              "instead of building them (e.g. FMUs of an older commit)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="cushion_differential_") as tmp:
        t0 = time.perf_counter()
        if args.fmus:
            fmus = {k: args.fmus / f"{k}.fmu" for k in ("native2", "python2", "native3")}
        else:
            fmus = build_fmus(Path(tmp), args.fmi3)
            print(f"built {', '.join(fmus)} in {time.perf_counter() - t0:.1f} s")
        reference = Fmi2CS(fmus["native2"], "native2")
        others = [Fmi2CS(fmus["python2"], "python2")] + ([Fmi3CS(fmus["native3"], "native3")] if args.fmi3 else [])
        seeds = range(args.first_seed, args.first_seed + args.sequences)
        failed = 0
        for other in others:
            t0 = time.perf_counter()
            outcomes = run(reference, other, seeds, args.calls)
            dt = time.perf_counter() - t0
            diffs = [o.difference for o in outcomes if o.difference is not None]
            print(f"native FMI 2.0 CS vs {other.label}: {len(diffs)} of {args.sequences} sequences differ; "
                  f"{sum(o.calls for o in outcomes)} calls compared in {dt:.1f} s")
            print(f"  statuses other than OK (where the same): {sum(o.warnings for o in outcomes)} Warning, "
                  f"{sum(o.discards for o in outcomes)} Discard, {sum(o.errors for o in outcomes)} Error; "
                  f"{sum(o.gets_after_set for o in outcomes)} reads right after an fmi2SetReal")
            for d in diffs[:args.show]:
                print(f"  {d}")
            failed += len(diffs)
        reference.close()
        for other in others:
            other.close()
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
