"""Kiss-point (touch-point) learning from the onset of torque transfer in a launch.

During the first launch phase the clutch torque rises until the car starts
to move. Once the measured wheel speed (stated at the disc: ``v i / r``) has
stayed above the onset speed for a window, its rise over the window gives the
mean clutch torque, ``T = J_d (w_end - w_start) / window + T_load`` (wheel
speeds rather than the disc speed: the disc alone spins up as the drive
shafts wind up; the window should span a shuffle period to average the
shafts' oscillation out; ``J_d`` the vehicle's
inertia at the disc, ``T_load`` grade and rolling resistance at the clutch:
the TCU is assumed to know mass and grade, as from the vehicle controller's
estimates; here they are exact). The learner inverts its own characteristic
at that torque and the window's mean measured bearing position: the kiss
point that would make its model deliver that torque there. It moves its
learned kiss point by ``gain`` times the difference, once per launch; the
value is used until the next adaptation.
"""
from __future__ import annotations

from ..scenario.tcu_params import Adaptation


class KissLearner:
    """Collects (disc speed, bearing position) samples of a launch and estimates the kiss point.

    Parameters
    ----------
    a : Adaptation
        Scenario section (gain, onset speed, window).
    period_s : float
        TCU period, s (one sample per period).
    j_d_kg_m2, t_load_Nm : float
        Vehicle inertia at the disc (kg m2) and the clutch torque holding the car (N.m).
    """

    __slots__ = ("gain", "onset", "m", "period", "j_d", "t_load", "w", "x", "done", "estimates")

    def __init__(self, a: Adaptation, period_s: float, j_d_kg_m2: float, t_load_Nm: float):
        self.gain, self.onset, self.period = a.gain, a.onset_speed_rad_s, period_s
        self.m = max(1, int(round(a.window_s / period_s)))
        self.j_d, self.t_load = j_d_kg_m2, t_load_Nm
        self.w: list[float] = []
        self.x: list[float] = []
        self.done = False
        #: (launch, estimated kiss point m) of every adaptation
        self.estimates: list[tuple[int, float]] = []

    def start_launch(self) -> None:
        """Forget the last launch's samples; learn again in this one."""
        self.w.clear()
        self.x.clear()
        self.done = False

    def sample(self, w_disc: float, x_bearing: float) -> float | None:
        """Add one sample (rad/s, m); return the clutch torque of the window (N.m) once it is complete."""
        if self.done:
            return None
        self.w.append(w_disc)
        self.x.append(x_bearing)
        m = self.m
        if len(self.w) <= m or self.w[-1 - m] < self.onset:
            return None
        self.done = True
        return self.t_load + self.j_d * (self.w[-1] - self.w[-1 - m]) / (m * self.period)

    def mean_position(self) -> float:
        """Trapezoidal mean of the bearing position over the window, m."""
        xs = self.x[-1 - self.m:]
        return (sum(xs) - 0.5 * (xs[0] + xs[-1])) / self.m
