"""Numbers that the documentation quotes, each computed when the site is built by a named function here (the
``{cc}`` role of ``docs/_ext/cc_numbers.py`` calls them), so that no page carries a hand-copied figure.

A page writes ``{cc}`closed_torque_Nm(195)``` and gets ``293.1``; a format after the call overrides the
entry's (``{cc}`closed_torque_Nm(195):.0f```). Every entry is cheap (the Python reference model on the shipped
tables, milliseconds) but the thermal FMU's bar duty (one FMU build and 72 000 Co-Simulation steps, computed once
per build): figures that need a launch run live on the results pages, which their benchmarks write, and the
explanation pages link to them.

    python -m cushion_clutch.benchmarks.doc_numbers          # every entry with its value
"""
from __future__ import annotations

import ast
import functools
import re
from typing import Callable


@functools.lru_cache(maxsize=None)
def _model():
    from cushion_clutch.model import ClutchParameters, load_table
    from cushion_clutch.model.cover import CoverMap

    table, p = load_table(), ClutchParameters()
    return table, p, CoverMap(p.cover, p.lever_ratio)


@functools.lru_cache(maxsize=None)
def cover_budget(theta_degC: float = 20.0, wear_mm: float = 0.0) -> dict:
    """The default cover's kiss-point budget (m at the bearing) and closed clamp load (N) at ``theta_degC``
    (θ_cs = θ_cm) and facing wear ``wear_mm`` (:meth:`CoverMap.kiss_budget`, the Python reference model)."""
    table, p, g = _model()
    t = theta_degC + 273.15
    return g.kiss_budget(t, t, wear_mm * 1e-3, table, p.x_kiss_ref)


def closed_torque_Nm(theta_degC: float = 20.0, wear_mm: float = 0.0) -> float:
    """Closed torque capacity n·μ·R_eq·F_clamp of the default clutch, N·m."""
    _, p, _ = _model()
    return p.n_surfaces * p.mu * p.R_eq * cover_budget(theta_degC, wear_mm)["clamp_closed_N"]


def closed_over_engine(theta_degC: float = 20.0, wear_mm: float = 0.0) -> float:
    """Closed torque capacity over the default engine's peak torque (benchmarks.cover.ENGINE_PEAK_NM), 1."""
    from .cover import ENGINE_PEAK_NM
    return closed_torque_Nm(theta_degC, wear_mm) / ENGINE_PEAK_NM


def kiss_shift_mm(theta_degC: float = 20.0, wear_mm: float = 0.0) -> float:
    """Kiss-point shift at the bearing from the 20 °C, new-facing reference, mm (+ = later engagement)."""
    return cover_budget(theta_degC, wear_mm)["total"] * 1e3


def cover_mm(field: str) -> float:
    """A length of the default cover (a ``CoverParameters`` field in m), in mm."""
    _, p, _ = _model()
    return getattr(p.cover, field) * 1e3


def engine_peak_Nm() -> float:
    from .cover import ENGINE_PEAK_NM
    return ENGINE_PEAK_NM


@functools.lru_cache(maxsize=None)
def _network_modes(clamped: bool) -> tuple[float, ...]:
    import math

    from cushion_clutch.launch.scenario import load_scenario
    from cushion_clutch.model.thermal_network import NetworkParams, time_constants

    if clamped:
        w_engine = w_disc = 1800.0 * math.pi / 30.0
    else:
        w_engine, w_disc = load_scenario().engine.idle_speed_rpm * math.pi / 30.0, 0.0
    return tuple(float(x) for x in time_constants(NetworkParams(), w_engine, w_disc, clamped))


def network_mode_s(index: int, clamped: bool = False) -> float:
    """Time constant of one mode of the default plant network (``thermal_network.time_constants`` of
    ``NetworkParams()``, ascending; a negative ``index`` counts from the slowest), s: with the clutch open, the
    engine at the default scenario's idle and the disc at rest, or clamped with both at 1800 rpm."""
    return _network_modes(bool(clamped))[index]


def network_idle_rad_s() -> float:
    """The default scenario's engine idle, rad/s (the speed of :func:`network_mode_s`'s open clutch)."""
    import math

    from cushion_clutch.launch.scenario import load_scenario
    return load_scenario().engine.idle_speed_rpm * math.pi / 30.0


@functools.lru_cache(maxsize=None)
def _thermal_bar() -> dict:
    import tempfile
    from pathlib import Path

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu

    from .thermal_fmu import bar_duty
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_fmu(DEFAULT_TABLES, Path(tmp) / "CushionClutchThermal.fmu", thermal=True)
        return bar_duty(fmu)


def thermal_bar(key: str) -> float:
    """The thermal FMU's bar duty (:func:`cushion_clutch.benchmarks.thermal_fmu.bar_duty` on a fresh build of
    the default thermal FMU): ``energy_kJ``, ``rise_K``, ``peak_rise_K``, ``K_per_kJ``."""
    d = _thermal_bar()
    return d["energy_J"] / 1e3 if key == "energy_kJ" else d[key]


def joint_MN_per_m(part: str = "far_end_stiffness_N_per_m") -> float:
    """The default tables' far-edge joint, MN/m, as the sweep that made them recorded it (``metadata.json``
    ``far_end``: ``far_end_stiffness_N_per_m``, the tab and rivets in series; ``tab_N_per_m``;
    ``rivets_N_per_m``), predicted by :mod:`cushion_clutch.fe.joint`."""
    import json

    from cushion_clutch.data import DEFAULT_TABLES
    meta = json.loads((DEFAULT_TABLES / "metadata.json").read_text(encoding="utf-8"))
    return meta["far_end"][part] / 1e6


@functools.lru_cache(maxsize=None)
def _tab_checks() -> dict:
    from cushion_clutch.fe import joint as J
    from cushion_clutch.fe.params import load_params

    p = load_params()
    j, t, e = p.joint, p.geometry.thickness_m, p.material.youngs_modulus(p.material.reference_temperature_degC)
    return {"timoshenko": J.timoshenko_tab_stiffness(j), "clamped_8": J.tab_stiffness_fe(j, 8, root="clamped"),
            "carrier_4": J.tab_stiffness_fe(j, 4), "carrier_8": J.tab_stiffness_fe(j, 8),
            "carrier_16": J.tab_stiffness_fe(j, 16),
            "huth": J.huth_rivet_stiffness(j, t, e), "swift": J.swift_rivet_stiffness(j, t, e)}


def tab_check_MN_per_m(key: str) -> float:
    """The default joint's checks, MN/m, computed at build (CalculiX, a few seconds): ``timoshenko`` (the tab
    as a clamped Timoshenko cantilever), ``clamped_8`` (the tab's FE with its root clamped, 8 elements across),
    ``carrier_4``/``carrier_8``/``carrier_16`` (the FE with the carrier body at the root, 4/8/16 elements
    across; 8 is the model's), ``huth``/``swift`` (one rivet by each formula)."""
    return _tab_checks()[key] / 1e6


#: name -> (function, default format)
NUMBERS: dict[str, tuple[Callable[..., float], str]] = {
    "closed_torque_Nm": (closed_torque_Nm, ".1f"),
    "closed_over_engine": (closed_over_engine, ".2f"),
    "kiss_shift_mm": (kiss_shift_mm, ".2f"),
    "cover_mm": (cover_mm, "g"),
    "engine_peak_Nm": (engine_peak_Nm, ".0f"),
    "thermal_bar": (thermal_bar, ".4g"),
    "network_mode_s": (network_mode_s, ".0f"),
    "network_idle_rad_s": (network_idle_rad_s, ".0f"),
    "joint_MN_per_m": (joint_MN_per_m, ".2f"),
    "tab_check_MN_per_m": (tab_check_MN_per_m, ".2f"),
}

CALL = re.compile(r"^\s*(?P<name>\w+)\s*(?:\((?P<args>.*)\))?\s*(?::(?P<spec>[^:()]+))?\s*$")


def evaluate(text: str) -> str:
    """The formatted value of ``name(args)[:format]``; :class:`KeyError` or :class:`ValueError` for an
    unknown name or a call that cannot be read."""
    m = CALL.match(text)
    if not m:
        raise ValueError(f"{text!r}: write name(arguments)[:format], e.g. closed_torque_Nm(195):.1f")
    if m["name"] not in NUMBERS:
        raise KeyError(f"{m['name']!r} is no documented number; known: {', '.join(sorted(NUMBERS))}")
    fn, spec = NUMBERS[m["name"]]
    args = ast.literal_eval(f"({m['args']},)") if m["args"] and m["args"].strip() else ()
    return format(fn(*args), m["spec"] or spec)


def main() -> None:
    for text in ("closed_torque_Nm(20)", "closed_torque_Nm(195)", "closed_torque_Nm(300)",
                 "closed_torque_Nm(20, 1)",
                 "kiss_shift_mm(195)", "kiss_shift_mm(300)", "kiss_shift_mm(20, 0.5)",
                 "cover_mm('diaphragm_thickness_m')", "cover_mm('installed_deflection_m')"):
        print(f"{text}: {evaluate(text)}")


if __name__ == "__main__":
    main()
