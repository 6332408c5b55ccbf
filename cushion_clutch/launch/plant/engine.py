"""Engine, the driver's throttle and the idle governor: ``T_e = throttle T_max(w_e) - drag w_e``.

The throttle is the larger of the driver's pedal and the engine control's
idle governor (PI with drag feed-forward and anti-windup, holding the idle
speed). Plain-Python scalar arithmetic: it runs every step.
"""
from __future__ import annotations

import math
from bisect import bisect_right

from ..scenario.load import Engine

RPM = math.pi / 30.0          #: rad/s per rpm


class EngineGovernor:
    """Engine torque, rad/s and N.m in, N.m out; the integrator is the state.

    Parameters
    ----------
    e : Engine
        Scenario engine section.
    h : float
        Step, s.
    """

    __slots__ = ("w", "t", "drag", "kp", "ki", "h", "integral", "throttle", "w_idle",
                 "w_stall", "w_max", "n")

    def __init__(self, e: Engine, h: float):
        self.w = [x * RPM for x in e.torque_curve_rpm]
        self.t = [float(x) for x in e.torque_curve_Nm]
        self.n = len(self.w)
        self.drag, self.kp, self.ki, self.h = e.drag_Nm_per_rad_s, e.governor_kp_Nm_per_rad_s, e.governor_ki_Nm_per_rad, h
        self.w_idle = e.idle_speed_rpm * RPM
        self.w_stall, self.w_max = e.stall_speed_rpm * RPM, e.max_speed_rpm * RPM
        self.integral = 0.0
        self.throttle = 0.0

    def max_torque(self, w_e: float) -> float:
        """Full-load torque at ``w_e`` (rad/s), N.m, linear in the curve and clamped at its ends."""
        w, t = self.w, self.t
        if w_e <= w[0]:
            return t[0]
        if w_e >= w[-1]:
            return t[-1]
        i = bisect_right(w, w_e) - 1
        return t[i] + (t[i + 1] - t[i]) * (w_e - w[i]) / (w[i + 1] - w[i])

    def torque(self, w_e: float, pedal: float, stalled: bool) -> float:
        """Engine torque (N.m) over the next step at ``w_e`` (rad/s) with the driver's ``pedal`` (0..1);
        updates the idle governor and ``throttle``."""
        w, t = self.w, self.t
        if w_e <= w[0]:
            t_max = t[0]
        elif w_e >= w[-1]:
            t_max = t[-1]
        else:
            i = bisect_right(w, w_e) - 1
            t_max = t[i] + (t[i + 1] - t[i]) * (w_e - w[i]) / (w[i + 1] - w[i])
        err = self.w_idle - w_e
        gov = (self.kp * err + self.ki * self.integral + self.drag * w_e) / t_max      # drag feed-forward
        gov = 1.0 if gov > 1.0 else (0.0 if gov < 0.0 else gov)
        if pedal < gov and (gov < 1.0 or err < 0.0) and (gov > 0.0 or err > 0.0):
            self.integral += err * self.h             # anti-windup: hold when saturated or overridden
        thr = pedal if pedal > gov else gov
        if w_e > self.w_max or w_e <= self.w_stall or stalled:
            thr = 0.0
        self.throttle = thr
        return thr * t_max - self.drag * w_e
