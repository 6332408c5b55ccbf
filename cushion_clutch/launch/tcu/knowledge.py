"""What a TCU variant knows of its clutch, as strategy objects the controller is composed of.

A :class:`~.controller.Variant` names one temperature strategy and one kiss-point strategy:

* how it knows the temperatures (cushion spring ``theta_cs`` for its characteristic, facings ``theta_cm`` for
  its model's stack growth and for the thermal protection): :class:`TableReference` (it does not: the table's
  reference temperature; it cannot protect), :class:`Told` (the true facing temperature, the spring's through
  the exact model), :class:`Observed` (its observer, :class:`~.observer.FacingObserver`) or
  :class:`EkfEstimate` (the production TCU's EKF, :mod:`.production`);
* whether it learns the kiss point: :class:`ModelKiss` (it does not) or :class:`LearnedKiss`
  (:class:`~.adaptation.KissLearner`, once per launch).

The controller asks them, never the variant's name.
"""
from __future__ import annotations

import math

from ...model import thermal_step
from ...model.clutch_model import hold_theta_cm
from ...model.thermal_network import SURFACES
from .adaptation import KissLearner
from .observer import FacingObserver

#: TCU phases (the controller's): the facings heat only while launching; clamped while launching or closed
OPEN, LAUNCH, CLOSE, PREFILL = 0, 1, 2, 3


class TableReference:
    """A temperature-blind TCU: the table's reference temperature (its kiss point, ``delta_kiss = 0``)."""

    #: no temperature to act on: no thermal protection
    protects = False
    #: told the true temperatures (no allowance for an estimate's error in its protection)
    told = False
    __slots__ = ("theta",)

    def __init__(self, ctl, observer, theta0: float):
        self.theta = ctl.theta_ref

    def theta_cs(self) -> float:
        """The cushion-spring temperature the TCU assumes, K."""
        return self.theta

    def theta_cm_model(self) -> float | None:
        """The facing temperature its clutch model assumes (held within the model's range), K; None: theta_cs."""
        return None

    def estimate(self) -> float:
        """Its facing-temperature estimate, K (NaN: none)."""
        return float("nan")

    def protect(self) -> float:
        """The friction system's temperature its thermal protection acts on: the hotter of its facings (their
        mean) and, where it knows them, its hotter metal friction surface (mu is read there, issue 37), K."""
        return self.estimate()

    def update(self, ctl, theta_cm_true: float, x_meas: float, w_e: float, w_d: float) -> None:
        """One TCU period (the true facing temperature K, the measured bearing m and speeds rad/s)."""


class Told(TableReference):
    """The ideal ``aware`` TCU: told the true facing temperature; the spring's follows through the exact model."""

    protects = told = True
    __slots__ = ("p", "period", "theta_cm", "theta_surface")

    def __init__(self, ctl, observer, theta0: float):
        self.p, self.period = ctl.p, ctl.period
        self.theta = self.theta_cm = theta0
        #: the true hotter friction surface, K (set by the simulation before each cycle; NaN: no network)
        self.theta_surface = math.nan

    def theta_cm_model(self) -> float | None:
        return hold_theta_cm(self.theta_cm)

    def protect(self) -> float:
        th, surface = self.theta_cm, self.theta_surface
        return surface if surface > th else th

    def update(self, ctl, theta_cm_true, x_meas, w_e, w_d) -> None:
        self.theta = thermal_step(self.theta, hold_theta_cm(theta_cm_true), self.period, self.p)
        self.theta_cm = theta_cm_true


class Observed(TableReference):
    """Its observer's estimates (:class:`~.observer.FacingObserver`, the ``[observer]`` section), heated by the
    slip power its own model believes while launching."""

    protects = True
    __slots__ = ("observer",)

    def __init__(self, ctl, observer, theta0: float):
        self.observer = FacingObserver(observer, ctl.p.theta_a, theta0, ctl.period)

    def theta_cs(self) -> float:
        return self.observer.theta_cs

    def theta_cm_model(self) -> float | None:
        return hold_theta_cm(self.observer.theta_cm)

    def estimate(self) -> float:
        return self.observer.theta_cm

    def protect(self) -> float:
        o = self.observer
        return max(o.theta_cm, o.net.theta_surface) if o.net is not None else o.theta_cm

    def update(self, ctl, theta_cm_true, x_meas, w_e, w_d) -> None:
        slip = abs(w_e - w_d)
        phase = ctl.phase
        self.observer.update(ctl.model_torque(x_meas) * slip if phase == LAUNCH else 0.0, w_e, w_d,
                             phase == LAUNCH or phase == CLOSE)


class EkfEstimate(TableReference):
    """The production TCU's EKF (``ctl.ekf``, updated from its own sensors before the controller's cycle)."""

    protects = True
    __slots__ = ("ekf",)

    def __init__(self, ctl, observer, theta0: float):
        self.ekf = ctl.ekf

    def theta_cs(self) -> float:
        return self.ekf.theta_cs

    def theta_cm_model(self) -> float | None:
        return self.ekf.theta_cm_model

    def estimate(self) -> float:
        return self.ekf.theta_cm

    def protect(self) -> float:
        ekf = self.ekf
        s = ekf.s
        return max(ekf.theta_cm, s.item(SURFACES[0]), s.item(SURFACES[1]))


class ModelKiss:
    """The kiss point of the TCU's model at the temperature it assumes (nothing learned)."""

    __slots__ = ()
    #: the learner (None: none)
    learner = None

    def __init__(self, adaptation, period_s: float, j_d_kg_m2: float, t_load_Nm: float):
        pass

    def start_launch(self) -> None:
        """A launch starts."""

    def sample(self, ctl, w_v: float, x_meas: float) -> None:
        """One launching TCU period: the wheel speed at the disc (rad/s) and the bearing position (m)."""

    def estimates(self) -> list[tuple[int, float]]:
        """(launch, learned kiss point m) of every adaptation."""
        return []


class LearnedKiss(ModelKiss):
    """The kiss point learned from the onset of torque transfer in each launch (``[adaptation]``)."""

    __slots__ = ("learner",)

    def __init__(self, adaptation, period_s: float, j_d_kg_m2: float, t_load_Nm: float):
        self.learner = KissLearner(adaptation, period_s, j_d_kg_m2, t_load_Nm)

    def start_launch(self) -> None:
        self.learner.start_launch()

    def sample(self, ctl, w_v: float, x_meas: float) -> None:
        torque = self.learner.sample(w_v, x_meas)
        if torque is not None:
            ctl.learn_kiss(torque, self.learner.mean_position())

    def estimates(self) -> list[tuple[int, float]]:
        return self.learner.estimates
