"""FMI 2.0 co-simulation slave (pythonfmu): cushion-spring clutch torque.

Imports only numpy (through the sibling ``clutch_model``), which the Python
API uses too. The tables travel in the FMU's ``resources/tables``.
"""
from __future__ import annotations

import math
from dataclasses import fields
from pathlib import Path

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

from clutch_model import (OMEGA_SLIP_LIMIT, OMEGA_SLIP_START, THETA_CM_LIMIT, VARIABLES, X_TO_LIMIT,
                          ClutchParameters, SpringTable, outputs, thermal_step)

CAUSALITY = {"input": (Fmi2Causality.input, Fmi2Variability.continuous),
             "output": (Fmi2Causality.output, Fmi2Variability.continuous),
             "parameter": (Fmi2Causality.parameter, Fmi2Variability.fixed)}
PARAMETERS = [name for name, causality, _, _ in VARIABLES if causality == "parameter"]


class CushionClutch(Fmi2Slave):
    """Temperature-aware dry-clutch torque from bearing position and facing temperature."""

    author = "cushion_clutch"
    description = ("Dry-clutch torque T = n*mu*R_eq*F(u_f(x_to, theta_cs), theta_cs) with the "
                   "cushion-spring thermal ODE (Cappetti, Pisaturo, Senatore); F from CalculiX tables")
    version = "0.1.0"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        defaults = ClutchParameters()
        self.x_to = 0.0
        self.theta_cm = defaults.theta_a
        self.omega_slip = OMEGA_SLIP_START
        for name in PARAMETERS:
            setattr(self, name, float(getattr(defaults, name)))
        self.theta_cs = defaults.theta_cs_start
        self.torque = self.force = self.u_f = 0.0
        self.x_kiss = defaults.x_kiss_ref
        self._range_warned = False
        self._params = defaults
        self._problems: list[str] = []
        self._table = None
        self._table_error = None
        for name, causality, unit, desc in VARIABLES:
            kind, variability = CAUSALITY[causality]
            self.register_variable(Real(name, causality=kind, variability=variability,
                                        description=f"{desc} [{unit}]"))
        if self.resources is not None:
            try:
                self._table = SpringTable.from_dir(Path(self.resources) / "tables")
            except Exception as exc:  # noqa: BLE001 - reported at initialisation
                self._table_error = f"cannot load the F(u, theta) tables: {exc}"

    # -- life cycle ---------------------------------------------------------
    def exit_initialization_mode(self):
        # pythonfmu turns an exception here into fmi2Fatal, which kills the instance for
        # good; instead bad parameters are logged now and every doStep is refused with
        # fmi2Discard (and the message again) until the instance is reset.
        problems = []
        if self._table is None:
            problems.append(self._table_error or "no resources folder: tables missing")
        params = ClutchParameters(**{f.name: getattr(self, f.name) for f in fields(ClutchParameters)})
        problems += [f"parameter {p}" for p in params.problems()]
        self._problems = problems
        for p in problems:
            self.log(p, Fmi2Status.error)
        self.theta_cs = params.theta_cs_start
        if problems:
            self.torque = self.force = self.u_f = 0.0
            return
        self._params = params
        if not self._input_problems():
            self._update_outputs()

    def do_step(self, current_time: float, step_size: float) -> bool:
        problems = self._problems + self._input_problems()
        if not (math.isfinite(step_size) and step_size >= 0.0):
            problems.append(f"step size {step_size!r} must be finite and >= 0")
        if problems:
            for p in problems:
                self.log(f"t = {current_time:g} s: {p}; step refused", Fmi2Status.error)
            return False
        self.theta_cs = thermal_step(self.theta_cs, self.theta_cm, step_size, self._params)
        self._update_outputs()
        return True

    # -- helpers -------------------------------------------------------------
    def _input_problems(self) -> list[str]:
        out = []
        if not (isinstance(self.x_to, float) and math.isfinite(self.x_to) and abs(self.x_to) <= X_TO_LIMIT):
            out.append(f"input x_to = {self.x_to!r} m is not finite or |x_to| > {X_TO_LIMIT:g} m")
        if not (isinstance(self.theta_cm, float) and math.isfinite(self.theta_cm)
                and 0.0 < self.theta_cm < THETA_CM_LIMIT):
            out.append(f"input theta_cm = {self.theta_cm!r} K is not finite or outside (0, {THETA_CM_LIMIT:g}) K")
        if not (isinstance(self.omega_slip, float) and math.isfinite(self.omega_slip)
                and abs(self.omega_slip) <= OMEGA_SLIP_LIMIT):
            out.append(f"input omega_slip = {self.omega_slip!r} rad/s is not finite or |omega_slip| > "
                       f"{OMEGA_SLIP_LIMIT:g} rad/s")
        return out

    def _update_outputs(self) -> None:
        out = outputs(self.x_to, self.theta_cs, self._table, self._params, self.theta_cm, self.omega_slip)
        self.torque, self.force, self.u_f, self.x_kiss = out.torque, out.force, out.u_f, out.x_kiss
        if out.clamped and not self._range_warned:
            self._range_warned = True
            self.log(f"theta_cs = {self.theta_cs:.2f} K is outside the table range "
                     f"[{self._table.theta_min_K:.2f}, {self._table.theta_max_K:.2f}] K; "
                     "F and the kiss point are clamped to the nearest table temperature "
                     "(warned once)", Fmi2Status.warning)

    # -- state: everything that matters is registered, plus the warning flag --
    def _get_fmu_state(self):
        state = super()._get_fmu_state()
        state["_range_warned"] = self._range_warned
        return state
