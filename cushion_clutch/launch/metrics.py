"""Per-launch metrics of a TCU and their summary over groups of launches.

Per launch (``METRIC_COLUMNS``): cushion-spring temperature at the start and
the TCU's error in it, torque tracking error (demanded minus delivered
capacity, RMS and max while launching), kiss-point error (believed minus
true, at the start), engagement time, slip energy, peak jerk (acceleration
low-passed at 20 ms) over the launch and within 0.2 s after lock-up, the
creep shortfall (largest ``demand - delivered`` while the demand is at most
30 N.m) and engine stall.
"""
from __future__ import annotations

import math

from ..model import KELVIN

METRIC_COLUMNS = ("tcu", "launch", "theta_cs_start_degC", "torque_error_rms_Nm", "torque_error_max_Nm",
                  "kiss_point_error_mm", "engagement_time_s", "slip_energy_kJ", "peak_jerk_m_s3",
                  "engine_stall", "theta_cs_error_K", "creep_shortfall_Nm", "lockup_jerk_m_s3", "hot", "phase")
#: demand up to which the creep shortfall is taken, N.m
CREEP_NM = 30.0
#: window after lock-up for the lock-up jerk, s
LOCKUP_WINDOW_S = 0.2
JERK_FILTER_S = 0.02


class LaunchRecord:
    """Collects one launch's metrics; :meth:`step` is called every step while the clutch is engaged."""

    __slots__ = ("launch", "cool", "lock_time", "stall", "slip_J", "n_err", "sq_err", "max_err", "jerk",
                 "lock_jerk", "creep", "kiss_err", "theta_cs", "theta_err", "a_filt", "alpha", "h", "started")

    def __init__(self, launch: int, cool: bool, h: float):
        self.launch, self.cool, self.h = launch, cool, h
        self.lock_time = None
        self.stall = False
        self.slip_J = 0.0
        self.n_err, self.sq_err, self.max_err = 0, 0.0, 0.0
        self.jerk = self.lock_jerk = self.creep = 0.0
        self.kiss_err = self.theta_cs = self.theta_err = None
        self.a_filt = 0.0
        self.alpha = h / (JERK_FILTER_S + h)
        self.started = False

    def start(self, kiss_err_m: float, theta_cs_K: float, theta_err_K: float) -> None:
        """At the first engaged step: the TCU's kiss-point and temperature errors."""
        self.started = True
        self.kiss_err, self.theta_cs, self.theta_err = kiss_err_m, theta_cs_K, theta_err_K

    def step(self, accel: float, tl: float, t_dem: float, t_cap: float, launching: bool) -> None:
        """One engaged step: acceleration (m/s2), time in launch (s), demand and capacity (N.m)."""
        a_prev = self.a_filt
        self.a_filt += self.alpha * (accel - a_prev)
        jerk = abs(self.a_filt - a_prev) / self.h
        if jerk > self.jerk:
            self.jerk = jerk
        if self.lock_time is not None and tl <= self.lock_time + LOCKUP_WINDOW_S and jerk > self.lock_jerk:
            self.lock_jerk = jerk
        if launching and self.lock_time is None and t_dem > 0.0:
            e = t_cap - t_dem
            self.n_err += 1
            self.sq_err += e * e
            if abs(e) > self.max_err:
                self.max_err = abs(e)
            if t_dem <= CREEP_NM and -e > self.creep:
                self.creep = -e

    def metrics(self, hot_degC: float) -> dict:
        """The launch's row (without ``tcu``)."""
        nan = float("nan")
        theta = (self.theta_cs or KELVIN) - KELVIN
        return {
            "launch": self.launch,
            "theta_cs_start_degC": theta,
            "torque_error_rms_Nm": math.sqrt(self.sq_err / self.n_err) if self.n_err else nan,
            "torque_error_max_Nm": self.max_err if self.n_err else nan,
            "kiss_point_error_mm": (self.kiss_err or 0.0) * 1e3,
            "engagement_time_s": self.lock_time if self.lock_time is not None else nan,
            "slip_energy_kJ": self.slip_J / 1e3,
            "peak_jerk_m_s3": self.jerk,
            "engine_stall": bool(self.stall),
            "theta_cs_error_K": self.theta_err if self.theta_err is not None else nan,
            "creep_shortfall_Nm": self.creep,
            "lockup_jerk_m_s3": self.lock_jerk,
            "hot": bool(theta >= hot_degC),
            "phase": "cool-down" if self.cool else "repeated",
        }


#: summarised columns: (column, how the worst is taken)
SUMMARY = (("torque_error_rms_Nm", "max"), ("torque_error_max_Nm", "max"), ("kiss_point_error_mm", "absmax"),
           ("theta_cs_error_K", "absmax"), ("creep_shortfall_Nm", "max"), ("engagement_time_s", "max"),
           ("slip_energy_kJ", "max"), ("lockup_jerk_m_s3", "max"))


def summarise(rows: list[dict], select) -> dict:
    """Mean and worst of the ``SUMMARY`` columns over the rows for which ``select(row)`` is true.

    Returns ``{"n": count, "<col>_mean": ..., "<col>_worst": ...}`` (NaN for no rows),
    plus ``stalls`` (count).
    """
    rows = [r for r in rows if select(r)]
    out: dict = {"n": len(rows), "stalls": sum(bool(r["engine_stall"]) for r in rows)}
    for col, how in SUMMARY:
        vals = [r[col] for r in rows if not math.isnan(r[col])]
        if not vals:
            out[col + "_mean"] = out[col + "_worst"] = float("nan")
            continue
        out[col + "_mean"] = sum(vals) / len(vals)
        out[col + "_worst"] = max(vals, key=abs) if how == "absmax" else max(vals)
    return out
