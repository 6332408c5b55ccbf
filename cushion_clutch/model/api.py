"""Python API of the clutch model, on the same module the pythonfmu FMU runs (:mod:`.clutch_model`).

Examples
--------
>>> from cushion_clutch.model import load_table, ClutchParameters, outputs, x_to_for_torque
>>> table, p = load_table(), ClutchParameters()
>>> out = outputs(x_to=0.0055, theta_cs=468.15, table=table, p=p)      # 195 degC
>>> x = x_to_for_torque(out.torque, 468.15, table, p)                   # the TCU's inverse
"""
from __future__ import annotations

from pathlib import Path

from .clutch_model import ClutchParameters, SpringTable, outputs
from ..number_check import is_finite_number

__all__ = ["load_table", "torque", "thermal_system"]


def load_table(folder: str | Path | None = None) -> SpringTable:
    """The F(u, theta) and kiss-point tables of a table folder (default: the shipped default set)."""
    if folder is None:
        from ..data import DEFAULT_TABLES       # package data: only where the package is installed
        folder = DEFAULT_TABLES
    return SpringTable.from_dir(folder)


def torque(x_to: float, theta_cs: float, table: SpringTable | None = None,
           p: ClutchParameters | None = None) -> float:
    """Clutch torque (N.m) at bearing position ``x_to`` (m) and ``theta_cs`` (K)."""
    return outputs(x_to, theta_cs, table or load_table(), p or ClutchParameters()).torque


def thermal_system(p: ClutchParameters | None = None):
    """The cushion-spring thermal model (eq. 3) as a python-control state-space system.

    State and output: theta_cs (K); inputs: [theta_cm, theta_a] (K).
    Steady gain from theta_cm is U/(U+H), time constant C/(U+H).
    """
    import control

    p = p or ClutchParameters()
    if not (is_finite_number(p.C) and p.C > 0.0):
        raise ValueError(f"C = {p.C!r}: the cushion-spring heat capacity (J/K) must be a finite number > 0")
    g = p.U + p.H
    return control.ss([[-g / p.C]], [[p.U / p.C, p.H / p.C]], [[1.0]], [[0.0, 0.0]],
                      inputs=["theta_cm", "theta_a"], outputs=["theta_cs"], states=["theta_cs"],
                      name="cushion_spring_thermal")
