"""What a production TCU reads: toothed-wheel speeds, the engine's torque estimate, the actuator position, ambient.

* **Engine speed** from a 60-2 crank wheel: the engine control unit time-stamps
  every tooth edge (``timer_s`` resolution); teeth carry a seeded pitch error.
  Speed = nominal angle between the first and last edge since the previous
  read / their time difference (the gap of the missing teeth is known).
* **Input-shaft (disc) speed** from a toothed Hall sensor read every TCU
  period the same way. At low speed fewer edges fall in a period: with one or
  none the reading is coarse, and after ``timeout_s`` without an edge the
  reading is 0 (below ``pitch / timeout_s`` the shaft reads as standing). No
  direction: the magnitude is read.
* **Engine torque estimate** of the engine control unit:
  ``T_est = (1 + gain_error) T + offset + noise``.
* **Actuator (bearing) position**: ``x + offset + noise``, quantised.
* **Ambient temperature**: ``theta_a + offset``, quantised.

All noise is Gaussian and seeded; each sensor has its own stream.
"""
from __future__ import annotations

import math
import random
from bisect import bisect_right

from ..scenario.tcu_params import ProductionSensors

TWO_PI = 2.0 * math.pi


def _quantise(x: float, step: float) -> float:
    return step * round(x / step) if step > 0.0 else x


class ToothedWheel:
    """A toothed wheel and its edge-timing speed measurement.

    Parameters
    ----------
    teeth : int
        Teeth of the full pitch (60 for a 60-2 wheel).
    missing : int
        Teeth left out at the end of the revolution (the reference gap).
    pitch_error_rad, timer_s, timeout_s : float
        See :class:`ProductionSensors`.
    rng : random.Random
        Draws each tooth's position error once.
    """

    __slots__ = ("pitch", "present", "nominal", "actual", "timer", "timeout", "phi", "next_edge",
                 "t_last", "a_last", "t_ref", "a_ref", "n_new", "speed")

    def __init__(self, teeth: int, missing: int, pitch_error_rad: float, timer_s: float, timeout_s: float,
                 rng: random.Random):
        self.pitch = 2.0 * math.pi / teeth
        self.present = teeth - missing
        self.nominal = [k * self.pitch for k in range(self.present)]
        self.actual = [a + (rng.gauss(0.0, pitch_error_rad) if pitch_error_rad > 0 and k else 0.0)
                       for k, a in enumerate(self.nominal)]
        self.timer, self.timeout = timer_s, timeout_s
        self.phi = 0.0                 # unwrapped shaft angle, rad (edge 0 at 0)
        self.next_edge = self.actual[1]
        self.t_last = self.t_ref = -math.inf
        self.a_last = self.a_ref = 0.0  # nominal (believed) unwrapped angle of an edge, rad
        self.n_new = 0
        self.speed = 0.0

    def advance(self, t_end: float, w: float, dt: float) -> None:
        """Turn the shaft at the mean speed ``w`` (rad/s, magnitude used) over ``dt`` ending at ``t_end`` (s).

        Only the last edge passed matters to :meth:`read`: it is found by
        bisection, its time interpolated with the mean speed.
        """
        dphi = abs(w) * dt
        phi = self.phi + dphi
        self.phi = phi
        if phi < self.next_edge:
            return
        turns, rem = divmod(phi, TWO_PI)
        k = bisect_right(self.actual, rem) - 1          # actual[0] = 0: k >= 0
        base = turns * TWO_PI
        t_edge = t_end - (phi - (base + self.actual[k])) * dt / dphi
        if self.timer > 0.0:
            t_edge = self.timer * math.floor(t_edge / self.timer)
        self.t_last, self.a_last = t_edge, base + self.nominal[k]
        self.n_new += 1
        self.next_edge = base + self.actual[k + 1] if k + 1 < self.present else base + TWO_PI

    def read(self, t: float) -> float:
        """The measured speed at time ``t`` (s), rad/s."""
        if self.n_new and self.t_last > self.t_ref and math.isfinite(self.t_ref):
            self.speed = (self.a_last - self.a_ref) / (self.t_last - self.t_ref)
        elif t - self.t_last > self.timeout:
            self.speed, self.t_ref = 0.0, -math.inf      # the next edge has no valid predecessor
        elif self.t_last > -math.inf and t > self.t_last:
            self.speed = min(self.speed, self.pitch / (t - self.t_last))   # no edge yet: at most this fast
        if self.n_new:
            self.t_ref, self.a_ref, self.n_new = self.t_last, self.a_last, 0
        return self.speed


class TcuSensors:
    """All production sensors of one TCU, seeded from ``s.seed``."""

    __slots__ = ("s", "crank", "shaft", "rng_t", "rng_x", "gain", "off", "noise_t", "noise_x", "x_off", "x_res")

    def __init__(self, s: ProductionSensors):
        self.s = s
        rng = random.Random(s.seed)
        self.crank = ToothedWheel(s.crank_teeth, s.crank_missing_teeth, s.tooth_pitch_error_rad, s.timer_s,
                                  s.timeout_s, random.Random(rng.random()))
        self.shaft = ToothedWheel(s.input_teeth, 0, s.tooth_pitch_error_rad, s.timer_s, s.timeout_s,
                                  random.Random(rng.random()))
        self.rng_t, self.rng_x = random.Random(rng.random()), random.Random(rng.random())
        self.gain, self.off, self.noise_t = 1.0 + s.torque_gain_error, s.torque_offset_Nm, s.torque_noise_Nm
        self.noise_x, self.x_off, self.x_res = s.position_noise_m, s.position_offset_m, s.position_resolution_m

    def advance(self, t_end: float, w_engine: float, w_disc: float, dt: float) -> None:
        """Turn both wheels over one simulation step (s, rad/s)."""
        self.crank.advance(t_end, w_engine, dt)
        self.shaft.advance(t_end, w_disc, dt)

    def engine_torque(self, torque_Nm: float) -> float:
        """The engine control unit's estimate of the engine torque ``torque_Nm``, N.m."""
        n = self.rng_t.gauss(0.0, self.noise_t) if self.noise_t > 0.0 else 0.0
        return self.gain * torque_Nm + self.off + n

    def position(self, x_m: float) -> float:
        """Measured bearing position, m."""
        n = self.rng_x.gauss(0.0, self.noise_x) if self.noise_x > 0.0 else 0.0
        return _quantise(x_m + self.x_off + n, self.x_res)

    def ambient(self, theta_a: float) -> float:
        """Measured ambient temperature, K."""
        return _quantise(theta_a + self.s.ambient_offset_K, self.s.ambient_resolution_K)
