"""Thermal duty cycles (``hill_restart``, ``hill_fade``): restarts to damage.

The damage threshold is the lower bound of LuK's range (Symposium 2006, "Double Clutch - Wet or Dry", the
seed paper's ref. [9]: the friction system is damaged above 350-400 degC), the ``protection.damage_degC`` of
the shipped duty scenarios.
"""
from __future__ import annotations

import math

import numpy as np

from ...model import KELVIN

#: LuK 2006: damage of the friction system above 350-400 degC; the lower bound, degC
DAMAGE_DEGC = 350.0


def restarts_to_damage(series, damage_degC: float = DAMAGE_DEGC) -> int | None:
    """The first launch (1-based) in whose slot the plant's facings (``theta_cm_K``) or its hotter metal friction
    surface (``theta_surface_K``; NaN without the thermal network) pass ``damage_degC``; None if none does.

    From a recorded time series (:data:`.simulate.COLUMNS`): resolved to its recording interval.
    """
    hot = np.fmax(series["theta_cm_K"], np.nan_to_num(series["theta_surface_K"], nan=-math.inf)) - KELVIN
    over = np.nonzero(hot > damage_degC)[0]
    return int(series["launch"][over[0]]) if over.size else None


def peak_degC(series) -> float:
    """The plant's hottest facing or friction-surface temperature over the run, degC."""
    return float(np.nanmax(np.fmax(series["theta_cm_K"], np.nan_to_num(series["theta_surface_K"],
                                                                          nan=-math.inf)))) - KELVIN
