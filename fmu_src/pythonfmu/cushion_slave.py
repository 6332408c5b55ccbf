"""The pythonfmu slave: FMI 2.0 co-simulation of the cushion-spring clutch, hardened for bad hosts.

``CushionClutch.py`` (the module pythonfmu's binary loads) only imports the
class from here; see its docstring for why. Everything that pythonfmu's
C++ wrapper does not let a slave say is handled here as closely to FMI 2.0
as the wrapper allows:

- Any Python exception in a slave hook becomes fmi2Fatal *and* leaves the
  wrapper holding freed objects (the next call crashes the host). So no hook
  ever raises.
- The wrapper returns only fmi2OK (or fmi2Discard from a doStep that returns
  False). A call that the native FMU answers with fmi2Warning or fmi2Error
  (wrong state, unknown value reference, write to an output or to a fixed
  parameter after initialisation, bad parameters at
  fmi2ExitInitializationMode, a bad state, a step that does not start where
  the last one ended) sends that status as a message of category
  ``STATUS_CATEGORY``; the guard library in front of the wrapper
  (``pythonfmu_guard.c``) keeps it from the host and returns it. A refused
  call changes nothing and is logged, as in the native FMU. Without the guard
  (a platform it was not built for) the host sees fmi2OK and that message.
- The wrapper passes log messages to the host logger as printf format
  strings, so every ``%`` is doubled here.
- The wrapper drops every message when ``loggingOn`` is false (the guard runs
  it with true and filters as the native FMU does); errors are also written to
  the process's standard error, for hosts without the guard.
- Serialized states carry a format tag and a CRC-32 checksum; a state is
  checked (tag, checksum, every variable finite, phase, parameter ranges)
  before it is applied, and never raises.

Everything else follows the native FMU's contract (``clutch_core.c``; tested call
by call against it by ``tests/test_differential.py``):

- Outputs are computed on read: ``fmi2SetReal`` marks them stale, and
  ``fmi2GetReal`` recomputes them from the current inputs and state first
  (in Initialization Mode with ``theta_cs = theta_cs_start``). Inputs that are
  not finite or out of range, or a cover that cannot hold the cushion, leave
  the outputs at their last values and they stay stale, so the next valid
  input recovers them; a get of such an output (not theta_cs) returns
  fmi2Discard with a message, as the native FMU (docs/reference/statuses.md).
- ``fmi2DoStep`` refuses (fmi2Discard) bad step sizes, bad inputs and a step
  after which the cover cannot hold the cushion, with the state, the time and
  the outputs unchanged (as the native FMU; fmi2LastSuccessfulTime is the
  step's start in both). A later step with valid inputs goes on: nothing of a
  Discard is remembered.
"""
from __future__ import annotations

import json
import math
import sys
import zlib
from pathlib import Path

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Status

from clutch_model import (INPUT_RANGES, OUTPUT_RANGES, VARIABLES, ClutchParameters, SpringTable, outputs,
                          range_message, start_values, thermal_step)
from clutch_model import table_problems, validity_warning  # issue 28 (validity): the shared model decides
from table_format import table_set_x_kiss_ref
from slave_table_sets import more_sets  # issue 42: several table sets, the enumeration spring

from number_check import is_finite_number


CAUSALITY = {"input": (Fmi2Causality.input, Fmi2Variability.continuous),
             "output": (Fmi2Causality.output, Fmi2Variability.continuous),
             "parameter": (Fmi2Causality.parameter, Fmi2Variability.fixed)}
PARAMETERS = [name for name, causality, _, _ in VARIABLES if causality == "parameter"]
UNITS = {name: unit for name, _, unit, _ in VARIABLES}
#: the outputs that clutch_model.outputs() returns (fields of Outputs): every output but the state theta_cs
OUTPUTS = [name for name, causality, _, _ in VARIABLES if causality == "output" and name != "theta_cs"]
#: tag of a serialized state; bump when the state's content changes
STATE_FORMAT = "cushion_clutch.pythonfmu.state/5"
#: "error": fmi2ExitInitializationMode refused the parameters or tables (the native FMU's Error state)
#: log category of the status message the guard library returns as the call's status (pythonfmu_guard.c)
STATUS_CATEGORY = "cushionReturnStatus"
PHASES = ("instantiated", "initialization", "stepping", "terminated", "error")
#: the phases in which outputs are computed from the state (in Initialization Mode from theta_cs_start)
COMPUTED_PHASES = ("initialization", "stepping", "terminated")


def _escape(msg: str) -> str:
    """The message as a printf format that prints it verbatim (the wrapper formats it)."""
    return str(msg).replace("%", "%%")


def _crc(text: str) -> str:
    """CRC-32 of a serialized state body (zlib: hashlib would load OpenSSL, whose exit
    handlers turn the wrapper's teardown use-after-free into an abort in C hosts)."""
    return format(zlib.crc32(text.encode("utf-8")), "08x")


def _tidy_sys_path(resources) -> None:
    """Keep one ``sys.path`` entry for the resources folder the wrapper inserts per instance.

    Without this, ``sys.path`` of the (host's) interpreter grows by one entry
    per instance; one entry per FMU folder stays (the builder removes its own).
    """
    if resources:
        while sys.path.count(resources) > 1:
            sys.path.remove(resources)


class CushionClutch(Fmi2Slave):
    """Temperature-aware dry-clutch torque from bearing position and facing temperature."""

    author = "cushion_clutch"
    description = ("Dry-clutch torque T = n*mu*R_eq*F(u_f(x_to, theta_cs), theta_cs) with the "
                   "cushion-spring thermal ODE (Cappetti, Pisaturo, Senatore); F from CalculiX tables")
    version = "0.1.0"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        _tidy_sys_path(self.resources)
        folder = Path(self.resources) / "tables" if self.resources else None
        table_error = None
        try:                                # a tolerance P5/P95 set places its own kiss point at the bearing
            x_kiss_ref = table_set_x_kiss_ref(folder) if folder is not None and folder.is_dir() else None
        except ValueError as exc:
            x_kiss_ref, table_error = None, str(exc)
        defaults = ClutchParameters() if x_kiss_ref is None else ClutchParameters(x_kiss_ref=x_kiss_ref)
        for name, value in start_values(defaults).items():
            setattr(self, name, value)
        self._range_warned = 0
        self._params = defaults
        self._dirty = True                  # outputs are stale: recomputed at the next get
        self._phase = "instantiated"
        self._time = 0.0                  # as the native FMU: 0 until fmi2SetupExperiment
        self._table = None
        self._table_error = table_error
        for name, causality, unit, desc in VARIABLES:
            kind, variability = CAUSALITY[causality]
            self.register_variable(Real(name, causality=kind, variability=variability,
                                        description=f"{desc} [{unit}]"))
        self._names = {vr: var.name for vr, var in self.vars.items()}
        self._kinds = {vr: dict((n, c) for n, c, _, _ in VARIABLES)[var.name] for vr, var in self.vars.items()}
        if folder is None or not folder.is_dir():
            self._table_error = f"resources folder {self.resources!r} has no tables/ folder"
        elif table_error is None:
            try:
                self._table = SpringTable.from_dir(folder)
            except Exception as exc:  # noqa: BLE001 - reported at initialisation, never raised
                self._table_error = f"cannot load the F(u, theta) tables: {exc}"
        # issue 42: sets 2.. (resources/tables_<k>) and the enumeration spring (1-based) that picks one
        self._sets = [(self._table, 0.0, self._table_error), *more_sets(self.resources)]
        self.spring = 1
        if len(self._sets) > 1:
            self.register_variable(Integer("spring", start=1, causality=Fmi2Causality.parameter,
                                           variability=Fmi2Variability.fixed,
                                           description="spring table set the model uses [1]"))

    # -- logging ---------------------------------------------------------------
    def log(self, msg, status=Fmi2Status.ok, category=None, debug=None):
        """Queue ``msg`` for the host logger (``%`` escaped); errors also go to stderr."""
        if status.value >= Fmi2Status.error.value:
            try:
                print(f"{self.instance_name}: {msg}", file=sys.stderr, flush=True)
            except Exception:  # noqa: BLE001 - a closed stderr must not break the instance
                pass
        super().log(_escape(msg), status, category)

    def _answer(self, status: Fmi2Status) -> None:
        """Make the current call return ``status`` (through the guard library; the wrapper cannot)."""
        Fmi2Slave.log(self, f"the call returns fmi2{status.name.capitalize()}", status, STATUS_CATEGORY)

    def _refuse(self, call: str, problems: list[str]) -> None:
        """Refuse a call with fmi2Error: nothing changes, every problem is logged."""
        for p in problems:
            self.log(f"{call} refused: {p}", Fmi2Status.error)
        self._answer(Fmi2Status.error)

    # -- life cycle ---------------------------------------------------------
    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        if self._phase != "instantiated":
            return self._refuse("fmi2SetupExperiment", [f"not allowed in phase {self._phase}"])
        if not (isinstance(start_time, float) and math.isfinite(start_time)):
            return self._refuse("fmi2SetupExperiment", [f"startTime = {start_time!r} is not finite"])
        self._time = start_time

    def enter_initialization_mode(self):
        if self._phase != "instantiated":
            return self._refuse("fmi2EnterInitializationMode", [f"not allowed in phase {self._phase} "
                                                                 "(only once, after fmi2Instantiate)"])
        self._phase = "initialization"

    def exit_initialization_mode(self):
        if self._phase != "initialization":
            return self._refuse("fmi2ExitInitializationMode", [f"not allowed in phase {self._phase} "
                                                                "(only after fmi2EnterInitializationMode)"])
        self._phase = "stepping"
        # bad parameters or tables: fmi2Error, and the instance is in the error phase until fmi2Reset
        params = self._current_parameters()         # also picks the chosen set's table (spring)
        problems = []
        if self._table is None:
            problems.append(self._table_error or "tables missing")
        problems += [f"parameter {p}" for p in params.problems()]
        if not problems:                # issue 28: what the cover cannot hold with this table (the wear limit)
            problems += [f"parameter {p}" for p in table_problems(self._table, params)]
        self._dirty = True
        if problems:                    # as the native FMU: theta_cs as it was, the outputs zero
            self._refuse("fmi2ExitInitializationMode", problems)
            self.torque = self.force = self.u_f = self.clamp_force = self.bearing_force = self.validity = 0.0
            self._phase = "error"
            return
        self.theta_cs = params.theta_cs_start
        self._params = params
        if not self._input_problems():
            self._update_outputs("fmi2ExitInitializationMode")

    def terminate(self):
        if self._phase != "stepping":
            return self._refuse("fmi2Terminate", [f"not allowed in phase {self._phase}"])
        self._phase = "terminated"

    def do_step(self, current_time: float, step_size: float) -> bool:
        if self._phase != "stepping":
            self._refuse("fmi2DoStep", [f"not allowed in phase {self._phase} (only between "
                                        "fmi2ExitInitializationMode and fmi2Terminate)"])
            return False
        problems = self._input_problems()
        if not (math.isfinite(step_size) and step_size >= 0.0 and math.isfinite(current_time)):
            problems = [f"step size {step_size!r} s must be finite and >= 0"]
        if problems:                       # refused: nothing changes (fmi2Discard, as the native FMU)
            for p in problems:
                self.log(f"t = {current_time:g} s: {p}; step refused", Fmi2Status.discard)
            return False
        if self._time is not None and abs(current_time - self._time) > 1e-9 * (1.0 + abs(current_time)):
            self.log(f"currentCommunicationPoint {current_time:.17g} s does not follow the previous "
                     f"step's end {self._time:.17g} s; accepted (the master decides)", Fmi2Status.warning)
            self._answer(Fmi2Status.warning)
        try:
            theta_cs = thermal_step(self.theta_cs, self.theta_cm, step_size, self._params)
        except ValueError as exc:           # dt > 1e9 s: the model's own limit
            self.log(f"t = {current_time:g} s: {exc}; step refused", Fmi2Status.discard)
            return False
        # a step the cover cannot take (fmi2Discard) leaves state, time and outputs where they were
        theta_old, self.theta_cs = self.theta_cs, theta_cs
        if not self._update_outputs(f"t = {current_time:g} s"):
            self.theta_cs = theta_old
            return False
        self._time = current_time + step_size
        return True

    # -- variable access: refuse instead of raising ---------------------------
    def _access_problems(self, vrs, write: bool) -> list[str]:
        out = []
        for vr in vrs:
            var = self.vars.get(vr)
            if var is None:
                out.append(f"value reference {vr} does not exist (0..{len(self.vars) - 1})")
            elif not isinstance(var, Real):
                out.append(f"value reference {vr} ({var.name}) is not a Real")
            elif write and self._phase in ("terminated", "error"):
                out.append(f"{var.name}: not allowed in phase {self._phase}")
            elif write and self._kinds[vr] == "output":
                out.append(f"{var.name} is an output and cannot be set")
            elif write and self._kinds[vr] == "parameter" and self._phase not in ("instantiated", "initialization"):
                out.append(f"{var.name} is a fixed parameter: it can only be set before "
                           "fmi2ExitInitializationMode")
        return out

    def set_real(self, vrs, values):
        problems = self._access_problems(vrs, write=True)
        if len(vrs) != len(values):
            problems.append(f"{len(vrs)} value references but {len(values)} values")
        if problems:                       # all or nothing: a refused set changes nothing
            return self._refuse("fmi2SetReal", problems)
        for vr, value in zip(vrs, values):
            setattr(self, self._names[vr], float(value))
        if len(vrs):
            self._dirty = True

    def get_real(self, vrs):
        problems = self._access_problems(vrs, write=False)
        if problems:
            self._refuse("fmi2GetReal", problems)
            return [math.nan] * len(vrs)
        if self._dirty and self._phase != "instantiated" and not self._refresh() and any(
                self._kinds[vr] == "output" and self._names[vr] != "theta_cs" for vr in vrs):
            self._answer(Fmi2Status.discard)       # stale outputs are never read with fmi2OK
        return [float(getattr(self, self._names[vr])) for vr in vrs]

    def _no_such_type(self, call: str, vrs) -> None:
        if len(vrs) == 0:
            return
        self._refuse(call, [f"value reference {vr}: this FMU has Real variables only" for vr in vrs]
                     or ["this FMU has Real variables only"])

    def _spring_problems(self, vrs) -> list[str]:
        if len(self._sets) < 2:
            return [f"value reference {vr}: this FMU has Real variables only" for vr in vrs]
        return [f"value reference {vr} is not an integer variable (spring is)" for vr in vrs
                if getattr(self.vars.get(vr), "name", None) != "spring"]

    def set_integer(self, vrs, values):
        problems = self._spring_problems(vrs)
        if not problems and self._phase not in ("instantiated", "initialization"):
            problems = [f"parameter spring (the table set) is fixed after initialization: it stays {self.spring}"]
        problems += [f"spring = {v}: allowed 1..{len(self._sets)} (the table sets this FMU carries)"
                     for v in values if not problems and not 1 <= int(v) <= len(self._sets)]
        if problems:
            return self._refuse("fmi2SetInteger", problems)
        for v in values:
            self.spring = int(v)
            self._dirty = True

    def set_boolean(self, vrs, values):
        self._no_such_type("fmi2SetBoolean", vrs)

    def set_string(self, vrs, values):
        self._no_such_type("fmi2SetString", vrs)

    def get_integer(self, vrs):
        problems = self._spring_problems(vrs)
        if problems:
            self._refuse("fmi2GetInteger", problems)
            return [0] * len(vrs)
        return [int(self.spring)] * len(vrs)

    def get_boolean(self, vrs):
        self._no_such_type("fmi2GetBoolean", vrs)
        return [False] * len(vrs)

    def get_string(self, vrs):
        self._no_such_type("fmi2GetString", vrs)
        return [""] * len(vrs)

    # -- helpers -------------------------------------------------------------
    def _input_problems(self) -> list[str]:
        """Every input outside its range (``clutch_model.INPUT_RANGES``, the native FMU's), its value exactly."""
        out = []
        for name, (lo, hi, lo_open, hi_open) in INPUT_RANGES.items():
            v = getattr(self, name)
            if not (isinstance(v, float) and math.isfinite(v) and (v > lo if lo_open else v >= lo)
                    and (v < hi if hi_open else v <= hi)):
                out.append("input " + range_message(name, v, UNITS[name], INPUT_RANGES[name]))
        return out

    def _current_parameters(self) -> ClutchParameters:
        # the chosen table set (issue 42) and its own kiss-point offset (x_kiss_ref is set 1's), as the native core
        table, offset, error = self._sets[self.spring - 1]
        self._table, self._table_error = table, error
        flat = {name: getattr(self, name) for name in PARAMETERS}
        if offset:
            flat["x_kiss_ref"] = flat["x_kiss_ref"] + offset
        return ClutchParameters.from_flat(flat)

    def _refresh(self) -> bool:
        """Outputs of the current inputs and state, computed on read (stale outputs only); False (logged) if they
        cannot be: the outputs keep their last values and stay stale."""
        problems = self._input_problems()
        if problems:
            for p in problems:
                self.log(f"fmi2GetReal: {p}; outputs not updated", Fmi2Status.discard)
            return False
        if self._phase not in COMPUTED_PHASES:
            return True
        if self._phase == "initialization":
            params = self._current_parameters()
            if self._table is None or params.problems():
                return True                # reported at fmi2ExitInitializationMode
            self._params = params
            self.theta_cs = params.theta_cs_start
        return self._update_outputs("fmi2GetReal")

    def _update_outputs(self, where: str = "") -> bool:
        """Outputs from the current inputs and state; False (logged, outputs kept) if the cover cannot hold."""
        try:
            out = outputs(self.x_to, self.theta_cs, self._table, self._params, self.theta_cm, self.omega_slip)
        except Exception as exc:  # noqa: BLE001 - never raise into the wrapper (fmi2Fatal)
            self.log(f"{where}: {exc}; outputs not updated", Fmi2Status.discard)
            return False
        self._set_outputs(out)
        self._dirty = False
        return True

    def _set_outputs(self, out) -> None:
        for name in OUTPUTS:
            setattr(self, name, getattr(out, name))
        # issue 28: _range_warned holds the last validity (0, 1, 2); a warning on each entry into 1 or 2
        msg = validity_warning(int(self._range_warned), int(out.validity), self.theta_cs, self.theta_cm,
                               self._table, self._params)
        self._range_warned = int(out.validity)
        if msg:
            self.log(msg, Fmi2Status.warning)

    # -- state -------------------------------------------------------------------
    def _get_fmu_state(self):
        state = {name: float(getattr(self, name)) for name, _, _, _ in VARIABLES}
        state.update(_phase=self._phase, _time=self._time, _range_warned=self._range_warned, _spring=self.spring)
        return state

    def _state_problems(self, state) -> list[str]:
        if not isinstance(state, dict):
            return ["not a state of this FMU"]
        if "_invalid" in state:
            return [str(state["_invalid"])]
        out = []
        for name, _, _, _ in VARIABLES:
            v = state.get(name)
            if not is_finite_number(v):
                out.append(f"{name} = {v!r} is missing or not finite")
        if state.get("_spring") not in range(1, len(self._sets) + 1):
            out.append(f"table set spring = {state.get('_spring')!r}: this FMU carries sets 1..{len(self._sets)}")
        if state.get("_phase") not in PHASES:
            out.append(f"phase {state.get('_phase')!r} is not one of {', '.join(PHASES)}")
        t = state.get("_time")
        if t is not None and not is_finite_number(t):            # a JSON true is no time
            out.append(f"time {t!r} is not finite")
        if not out and state["_phase"] in ("stepping", "terminated"):
            params = ClutchParameters.from_flat({p: float(state[p]) for p in PARAMETERS})
            out += [f"parameter {p}" for p in params.problems()]
            lo, hi = OUTPUT_RANGES["theta_cs"][:2]
            if not lo <= state["theta_cs"] <= hi:
                out.append(range_message("theta_cs", state["theta_cs"], "K", OUTPUT_RANGES["theta_cs"]))
        return out

    def _set_fmu_state(self, state):
        problems = self._state_problems(state)
        if problems:                       # the instance stays as it was
            return self._refuse("fmi2SetFMUstate", problems)
        for name, _, _, _ in VARIABLES:
            setattr(self, name, float(state[name]))
        self._phase, self._time = state["_phase"], state["_time"]
        self._range_warned = int(state.get("_range_warned") or 0)
        self.spring = int(state["_spring"])
        self._dirty = True                 # outputs of the restored inputs and state, at the next get
        params = self._current_parameters()  # the restored set's table and kiss offset
        if self._phase in ("stepping", "terminated"):
            self._params = params

    @staticmethod
    def _fmu_state_to_bytes(state) -> bytes:
        body = json.dumps(state, sort_keys=True, allow_nan=True)
        return json.dumps({"format": STATE_FORMAT, "crc32": _crc(body), "state": body}).encode("utf-8")

    @staticmethod
    def _fmu_state_from_bytes(data: bytes):
        """The state in ``data``, or ``{"_invalid": reason}`` (refused at fmi2SetFMUstate; never raises)."""
        try:
            outer = json.loads(bytes(data).decode("utf-8"))
            if not isinstance(outer, dict) or outer.get("format") != STATE_FORMAT:
                return {"_invalid": f"serialized state: not a {STATE_FORMAT} state"}
            body = outer.get("state")
            if not isinstance(body, str) or _crc(body) != outer.get("crc32"):
                return {"_invalid": "serialized state: checksum mismatch (truncated or corrupted)"}
            return json.loads(body)
        except Exception as exc:  # noqa: BLE001 - a bad state must never become fmi2Fatal
            return {"_invalid": f"serialized state: cannot be decoded ({type(exc).__name__})"}
