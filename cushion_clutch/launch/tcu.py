"""The TCU variants: one launch strategy, five ways of knowing the clutch.

All variants share the clutch-torque demand (ramp to the target, hold to
lock-up, then close the bearing) and command the bearing every
``tcu.period_s`` through the inverse of their model of the characteristic
(nominal mu, the shipped cushion-spring table), pre-filling to their believed
first contact before each launch. They differ in the cushion-spring
temperature they assume and in whether they learn the kiss point:

============================  ===============================================  ==========
variant                        theta_cs used                                    kiss point
============================  ===============================================  ==========
``naive``                      table reference (20 degC)                        model
``aware``                      ideal: true theta_cm through the exact model     model
``aware_estimated``            observer (:mod:`.observer`), mismatched          model
``adaptive``                   table reference                                  learned
``adaptive_aware_estimated``   observer                                         learned, shifted by delta_kiss(theta estimate)
============================  ===============================================  ==========

The learned kiss point is kept as an offset to the model's kiss point at the
temperature assumed when it was learned, so the compensated variant moves it
with the table's ``delta_kiss(theta_cs estimate)`` between adaptations and the
uncompensated one keeps it fixed.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass

from ..model import KELVIN, ClutchParameters, SpringTable, outputs, thermal_step, x_to_for_torque
from .adaptation import KissLearner
from .observer import FacingObserver
from .scenario import Scenario


@dataclass(frozen=True)
class Variant:
    """How a TCU knows the clutch: ``temperature`` in {"none", "ideal", "estimated"}, ``adaptive``."""

    name: str
    temperature: str
    adaptive: bool


VARIANTS = {v.name: v for v in (
    Variant("naive", "none", False),
    Variant("aware", "ideal", False),
    Variant("aware_estimated", "estimated", False),
    Variant("adaptive", "none", True),
    Variant("adaptive_aware_estimated", "estimated", True),
)}

OPEN, LAUNCH, CLOSE = 0, 1, 2     #: TCU phases


class TcuController:
    """One TCU variant; :meth:`cycle` runs once per TCU period.

    Parameters
    ----------
    variant : Variant
    sc : Scenario
    table : SpringTable
        The TCU's characteristic (its friction table, if any, is ignored: mu nominal).
    p : ClutchParameters
        The TCU's clutch parameters (nominal mu, lever ratio, kiss point at reference).
    theta0 : float
        Temperature at the start, K (the car is thermally soaked).
    j_d_kg_m2, t_load_Nm : float
        For the kiss-point learner (see :mod:`.adaptation`).
    """

    def __init__(self, variant: Variant, sc: Scenario, table: SpringTable, p: ClutchParameters, theta0: float,
                 j_d_kg_m2: float, t_load_Nm: float):
        if table.friction is not None:          # the TCU's model has the nominal, constant mu
            table = copy.copy(table)
            table.friction = None
        self.v, self.sc, self.table, self.p = variant, sc, table, p
        self.period = sc.tcu.period_s
        self.theta_ref = table.theta_degC[0] + KELVIN
        self.theta_ideal = theta0
        self.observer = (FacingObserver(sc.observer, p.theta_a, theta0, self.period)
                         if variant.temperature == "estimated" else None)
        self.learner = (KissLearner(sc.adaptation, self.period, j_d_kg_m2, t_load_Nm)
                        if variant.adaptive else None)
        self.offset = 0.0               #: learned kiss point minus the model's at the assumed temperature, m
        self.phase, self.t_dem, self.x_cmd = OPEN, 0.0, 0.0
        self.launch = 0
        #: the assumed theta_cs (K) and believed kiss point (m) after the last cycle
        self.theta_now, self.kiss_now = self.theta_used(), self.kiss()

    @property
    def name(self) -> str:
        return self.v.name

    def theta_used(self) -> float:
        """The cushion-spring temperature the TCU assumes, K."""
        if self.v.temperature == "ideal":
            return self.theta_ideal
        if self.observer is not None:
            return self.observer.theta_cs
        return self.theta_ref

    def theta_cm_estimate(self) -> float:
        """The observer's facing temperature, K (NaN without an observer)."""
        return self.observer.theta_cm if self.observer is not None else float("nan")

    def model_kiss(self, theta: float) -> float:
        """The model's kiss point at ``theta`` (K), m."""
        return self.p.x_kiss_ref - self.p.lever_ratio * self.table.delta_kiss(theta - KELVIN)

    def kiss(self) -> float:
        """The kiss point the TCU believes, m."""
        return self.model_kiss(self.theta_used()) + self.offset

    def command(self, torque_Nm: float) -> float:
        """Bearing position for ``torque_Nm``, m."""
        return x_to_for_torque(torque_Nm, self.theta_used(), self.table, self.p) + self.offset

    def model_torque(self, x_m: float) -> float:
        """Torque the TCU's model expects at bearing position ``x_m``, N.m."""
        return outputs(x_m - self.offset, self.theta_used(), self.table, self.p).torque

    def _learn(self, torque_Nm: float, x_mean: float) -> None:
        theta = self.theta_used()
        distance = x_to_for_torque(torque_Nm, theta, self.table, self.p) - self.model_kiss(theta)
        estimate = x_mean - distance
        self.learner.estimates.append((self.launch, estimate))
        self.offset += self.learner.gain * (estimate - self.kiss())

    def cycle(self, launch: int, tl: float, slot_s: float, has_next: bool, locked_once: bool,
              w_e: float, w_d: float, x_meas: float, theta_cm_true: float) -> None:
        """One TCU period: update estimates, learn, set ``phase``, ``t_dem`` (N.m) and ``x_cmd`` (m).

        ``launch`` (1-based) and ``tl`` (s since its start, slot length
        ``slot_s``); ``locked_once``: lock-up reached in this launch;
        ``w_e``, ``w_d`` measured speeds (rad/s); ``x_meas`` measured bearing
        position (m); ``theta_cm_true`` is used by the ideal ``aware`` TCU only.
        """
        tc = self.sc.tcu
        if self.v.temperature == "ideal":
            self.theta_ideal = thermal_step(self.theta_ideal, theta_cm_true, self.period, self.p)
        elif self.observer is not None:
            slip = abs(w_e - w_d)
            self.observer.update(self.model_torque(x_meas) * slip if self.phase == LAUNCH else 0.0)
        if launch != self.launch:
            self.launch = launch
            if self.learner is not None:
                self.learner.start_launch()
        if tl < tc.drive_time_s:
            if not locked_once:
                self.phase = LAUNCH
                self.t_dem = min(tc.torque_target_Nm, tc.torque_ramp_Nm_per_s * tl)
                if self.learner is not None:
                    torque = self.learner.sample(w_d, x_meas)
                    if torque is not None:
                        self._learn(torque, self.learner.mean_position())
                self.x_cmd = self.command(self.t_dem)
            else:
                self.phase = CLOSE
                self.x_cmd = min(tc.x_to_closed_m, self.x_cmd + tc.close_rate_m_per_s * self.period)
        elif has_next and tl >= slot_s - tc.prefill_s:
            self.phase, self.t_dem, self.x_cmd = OPEN, 0.0, self.command(0.0)    # pre-fill to first contact
        else:
            self.phase, self.t_dem, self.x_cmd = OPEN, 0.0, 0.0
        self.theta_now, self.kiss_now = self.theta_used(), self.kiss()
