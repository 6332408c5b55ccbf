"""Named cushion-spring thermal parameter sets: U, H, C of the paper's eq. 2 for the whole disc.

``paper`` is the paper's example (U = 0.1 W/K, H = 0.04 W/K, C = 1.0 J/K: the
:class:`~.clutch_model.ClutchParameters` defaults, which the FMU declares). Other
names are TOML files shipped in ``cushion_clutch/thermal_sets/`` (``fe_default``:
identified by ``cushion-clutch heat-path`` from a transient FE of the disc, with
its provenance), or a path to such a file.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path
from typing import Any

from ..config import load_toml, range_problem
from ..errors import ParameterError
from .clutch_model import ClutchParameters, heat_path_problem

#: the name of the paper's set (no file: the ClutchParameters defaults)
PAPER = "paper"
_TOP = {"name", "description", "U_W_per_K", "H_W_per_K", "C_J_per_K", "tau_s", "gain", "provenance", "uncertainty",
        "fit"}


@dataclass(frozen=True)
class ThermalSet:
    """U, H, C of the whole disc's cushion spring.

    Attributes
    ----------
    name : str
    U_W_per_K, H_W_per_K, C_J_per_K : float
        Facing -> spring conductance W/K, spring -> ambient W/K, spring heat capacity J/K.
    description : str
    provenance, uncertainty, fit : dict
        What made the set (command, commit), the uncertainty bands, the ODE's error against the FE.
    """

    name: str
    U_W_per_K: float
    H_W_per_K: float
    C_J_per_K: float
    description: str = ""
    provenance: dict = field(default_factory=dict)
    uncertainty: dict = field(default_factory=dict)
    fit: dict = field(default_factory=dict)

    @property
    def tau_s(self) -> float:
        """Time constant C/(U+H), s."""
        return self.C_J_per_K / (self.U_W_per_K + self.H_W_per_K)

    @property
    def gain(self) -> float:
        """Steady gain U/(U+H) from theta_cm to theta_cs."""
        return self.U_W_per_K / (self.U_W_per_K + self.H_W_per_K)

    def parameters(self) -> dict[str, float]:
        """The FMU parameters ``U``, ``H``, ``C``."""
        return {"U": self.U_W_per_K, "H": self.H_W_per_K, "C": self.C_J_per_K}


def sets_folder() -> Path:
    """Folder of the shipped sets."""
    return Path(str(files("cushion_clutch.thermal_sets")))


def shipped_names() -> list[str]:
    """Names of the shipped sets (``paper`` first)."""
    return [PAPER] + sorted(p.stem for p in sets_folder().glob("*.toml"))


def paper_set() -> ThermalSet:
    """The paper's U, H, C (the ClutchParameters defaults)."""
    p = ClutchParameters()
    return ThermalSet(PAPER, p.U, p.H, p.C, "Cappetti et al.'s example values (eq. 2), the FMU's defaults")


def load_thermal_set(name: str | Path) -> ThermalSet:
    """A set by shipped name (``paper``, ``fe_default``, ...) or TOML path; every problem named at once."""
    if str(name) == PAPER:
        return paper_set()
    path = Path(name)
    if not path.suffix:
        path = sets_folder() / f"{name}.toml"
        if not path.is_file():
            raise ParameterError([f"thermal set {name!r} not found: shipped {', '.join(shipped_names())}, "
                                  "or give a TOML file"])
    data: dict[str, Any] = load_toml(path, required=("U_W_per_K", "H_W_per_K", "C_J_per_K"))
    problems = [f"{k}: unknown key (allowed: {', '.join(sorted(_TOP))})" for k in data if k not in _TOP]
    for key, lo_open in (("U_W_per_K", False), ("H_W_per_K", False), ("C_J_per_K", True)):
        msg = range_problem(key, data.get(key), 0.0, 1e6, lo_open)
        if msg:
            problems.append(msg)
    if not problems and (msg := heat_path_problem(data["U_W_per_K"], data["H_W_per_K"], "U_W_per_K", "H_W_per_K")):
        problems.append(msg)
    if not problems and "tau_s" in data and not math.isclose(
            data["tau_s"], data["C_J_per_K"] / (data["U_W_per_K"] + data["H_W_per_K"]), rel_tol=1e-3):
        problems.append(f"tau_s = {data['tau_s']!r}: must equal C_J_per_K / (U_W_per_K + H_W_per_K)")
    if problems:
        raise ParameterError(problems, str(path))
    return ThermalSet(str(data.get("name", path.stem)), float(data["U_W_per_K"]), float(data["H_W_per_K"]),
                      float(data["C_J_per_K"]), str(data.get("description", "")), dict(data.get("provenance", {})),
                      dict(data.get("uncertainty", {})), dict(data.get("fit", {})))


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return '"' + str(v).replace("\\", "\\\\").replace('"', '\\"') + '"'


def set_toml(result: dict, name: str = "fe_default") -> str:
    """The TOML text of a set from ``heat_path.json``'s content (``cushion-clutch heat-path`` writes it)."""
    unc = result.get("uncertainty", {})
    lines = [f"# Written by `{result.get('command') or 'cushion-clutch heat-path'}` at commit {result.get('commit')}",
             "# (ccx " + str(result.get("ccx_version")) + "). Do not edit by hand: rerun the command and copy its",
             "# heat_path_set.toml here. Whole disc; SI units.",
             f"name = {_toml_value(name)}",
             f"description = {_toml_value('cushion-spring heat path identified from a transient CalculiX FE of the disc sector (cushion-clutch heat-path)')}",
             f"U_W_per_K = {_toml_value(result['U_W_per_K'])}",
             f"H_W_per_K = {_toml_value(result['H_W_per_K'])}",
             f"C_J_per_K = {_toml_value(result['C_J_per_K'])}",
             f"tau_s = {_toml_value(result['C_J_per_K'] / (result['U_W_per_K'] + result['H_W_per_K']))}",
             f"gain = {_toml_value(result['U_W_per_K'] / (result['U_W_per_K'] + result['H_W_per_K']))}",
             "", "[provenance]",
             f"command = {_toml_value(result.get('command', ''))}",
             f"commit = {_toml_value(result.get('commit', 'unknown'))}",
             f"ccx_version = {_toml_value(result.get('ccx_version', 'unknown'))}",
             f"spring = {_toml_value(result.get('spring', ''))}",
             f"coarse = {_toml_value(bool(result.get('coarse', False)))}",
             "", "[fit]",
             f"ode_rms_error_K = {_toml_value(result['ode_rms_error_K'])}",
             f"ode_max_error_K = {_toml_value(result['ode_max_error_K'])}",
             f"theta_cs_max_rise_K = {_toml_value(result['theta_cs_max_rise_K'])}",
             f"energy_balance_error = {_toml_value(result['energy_balance_error'])}",
             f"tau_mesh_change = {_toml_value(result['tau_mesh_change'])}",
             f"C_over_mass_c = {_toml_value(result['C_over_mass_c'])}",
             f"steel_mass_kg = {_toml_value(result['steel_mass_kg'])}"]
    if unc:
        lines += ["", "[uncertainty]  # [low, high] from re-solving at the uncertain inputs' bounds"]
        lines += [f"{k} = {_toml_value([v['low'], v['high']])}" for k, v in unc.items()]
    return "\n".join(lines) + "\n"
