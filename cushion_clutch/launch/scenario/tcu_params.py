"""Scenario sections of the TCU's own knowledge: observer, speed sensors, kiss-point adaptation.

SI units unless a name says otherwise; checked like every scenario section.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from ...config import Checked
from ...model.thermal_network import TcuNetworkBase


@dataclass(frozen=True)
class Observer(TcuNetworkBase):
    """The TCU's temperature observer: its own copy of the physical network (mismatched) or a lumped facing.

    ``network = true`` (default): the chain of :mod:`.thermal_network` with this section's parameters (by
    default the plant's with the mismatch of :class:`~.thermal_network.TcuNetworkBase`), heated by
    ``T_est w_slip`` with the slip speed from the speed sensors and ``T_est`` its model's torque at the
    measured bearing position. ``network = false``: the lumped facing
    ``C_f dtheta_cm/dt = share T_est w_slip - G_f (theta_cm - theta_a)``. Then the cushion-spring model
    ``C dtheta_cs/dt = U (theta_cm - theta_cs) + H (theta_a - theta_cs)``.
    """

    network: bool = True
    capacity_J_per_K: float = 517.5
    """lumped facing only"""
    loss_W_per_K: float = 1.08
    """lumped facing only"""
    heat_share: float = 1.0
    """lumped facing only"""
    spring_U_W_per_K: float = 0.1
    spring_H_W_per_K: float = 0.04
    spring_C_J_per_K: float = 1.0

    _section = "observer"

    def _problems(self) -> Iterable[str]:
        yield from super()._problems()
        yield from self._ranges(spec := {
            "capacity_J_per_K": (1.0, 1e6), "loss_W_per_K": (0.0, 1e4), "heat_share": (0.0, 1.0),
            "spring_U_W_per_K": (0.0, 1e4), "spring_H_W_per_K": (0.0, 1e4), "spring_C_J_per_K": (0.0, 1e6, True)})
        if self._passed(spec, "spring_U_W_per_K", "spring_H_W_per_K") and \
                self.spring_U_W_per_K + self.spring_H_W_per_K <= 0.0:
            yield (f"observer.spring_H_W_per_K: spring_U_W_per_K + spring_H_W_per_K = "
                   f"{self.spring_U_W_per_K + self.spring_H_W_per_K:g} W/K; must be > 0 (the spring exchanges heat)")


@dataclass(frozen=True)
class Sensors(Checked):
    """Engine and disc speed sensors as the TCU reads them: Gaussian noise, then quantisation."""

    speed_noise_rad_s: float = 0.0
    """standard deviation of the noise, rad/s (0: none)"""
    speed_resolution_rad_s: float = 0.0
    """quantisation step, rad/s (0: none)"""
    seed: int = 1

    _section = "sensors"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"speed_noise_rad_s": (0.0, 100.0), "speed_resolution_rad_s": (0.0, 100.0),
                                 "seed": (0, 2 ** 31 - 1)})
        yield from self._integers("seed")


@dataclass(frozen=True)
class Adaptation(Checked):
    """Kiss-point learning from the onset of torque transfer in each launch.

    Once the measured wheel speed (at the disc) has exceeded ``onset_speed_rad_s``
    for ``window_s``, the mean clutch torque over that window follows from its
    rise, ``J_d dw/dt + T_load`` (a window of a shuffle period averages the
    drive shafts' oscillation out); the learner compares it with
    its model's torque at the measured bearing positions and moves its kiss
    point by ``gain`` times the difference (in bearing travel).
    """

    gain: float = 0.7
    onset_speed_rad_s: float = 0.5
    window_s: float = 0.2

    _section = "adaptation"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"gain": (0.0, 1.0, True), "onset_speed_rad_s": (0.01, 100.0),
                                 "window_s": (1e-3, 1.0)})


#: when the production TCU learns its touch point at standstill
STANDSTILL_LEARN = ("missing", "always", "never")


@dataclass(frozen=True)
class Standstill(Checked):
    """Section ``[standstill]``: the production TCU's touch-point learning at key-on (:mod:`.touchpoint`).

    Gearbox in neutral, car standing, engine idling: the bearing moves to the believed kiss point less
    ``start_margin_m`` and then closes at ``ramp_rate_m_per_s`` until the input shaft's Hall sensor
    reads ``detect_speed_rad_s``; it keeps closing while the shaft spins up to ``fit_speed_rad_s`` and
    then opens. The shaft's acceleration gives the clutch torque along the way (``J a + drag``: the
    TCU's ``disc_inertia_kg_m2``, the drag measured in the coast-down after opening), each sample a
    touch-point offset through the nominal characteristic; their median is the learned value. ``learn``: ``"missing"`` (no stored
    touch point, or ``interval_starts`` key-ons since the last learning), ``"always"``, ``"never"``.
    The plant's gearbox drag in neutral is ``plant_drag_Nm + plant_drag_Nm_per_rad_s * w``.
    """

    learn: str = "missing"
    interval_starts: int = 20
    ramp_rate_m_per_s: float = 1e-3
    start_margin_m: float = 0.5e-3
    settle_s: float = 0.5
    detect_speed_rad_s: float = 5.0
    fit_speed_rad_s: float = 70.0
    min_torque_Nm: float = 2.0
    timeout_s: float = 15.0
    accuracy_m: float = 40e-6
    """the routine's stated accuracy (its touch point's sd in the EKF), m: measured within 12 um for a
    drag of 0.5-2.5 N.m and 38 um with the disc inertia 5 % off (tests/test_touchpoint.py)"""
    disc_inertia_kg_m2: float = 0.03
    """the TCU's value of the input shaft's inertia in neutral (design data), kg m2"""
    plant_drag_Nm: float = 1.2
    plant_drag_Nm_per_rad_s: float = 0.004

    _section = "standstill"

    def _problems(self) -> Iterable[str]:
        if self.learn not in STANDSTILL_LEARN:
            yield f"standstill.learn = {self.learn!r}: allowed " + ", ".join(STANDSTILL_LEARN)
        yield from self._ranges(spec := {
            "interval_starts": (1, 100000), "ramp_rate_m_per_s": (1e-6, 0.01), "start_margin_m": (0.0, 0.005),
            "settle_s": (0.0, 10.0), "detect_speed_rad_s": (0.5, 200.0), "fit_speed_rad_s": (1.0, 200.0),
            "min_torque_Nm": (0.0, 100.0), "timeout_s": (0.5, 600.0), "accuracy_m": (1e-7, 1e-3), "disc_inertia_kg_m2": (1e-4, 10.0),
            "plant_drag_Nm": (0.0, 100.0), "plant_drag_Nm_per_rad_s": (0.0, 10.0)})
        yield from self._integers("interval_starts")
        if self._passed(spec, "fit_speed_rad_s", "detect_speed_rad_s") and self.fit_speed_rad_s <= self.detect_speed_rad_s:
            yield "standstill.fit_speed_rad_s: must exceed standstill.detect_speed_rad_s"


#: how the production TCU starts a run
STORE_START = ("reset", "learned")


@dataclass(frozen=True)
class TcuStore(Checked):
    """Section ``[tcu_store]``: the production TCU's adapted state kept in non-volatile memory (:mod:`.store`).

    ``start = "reset"``: a new or reset TCU (nominal calibration, no stored touch point: it learns at
    standstill, ``[standstill]``); ``"learned"``: the state in ``file`` (JSON, relative to the
    scenario's folder). ``save``: write the state at the end of the run there ("" = not).
    """

    start: str = "reset"
    file: str = ""
    save: str = ""

    _section = "tcu_store"

    def _problems(self) -> Iterable[str]:
        if self.start not in STORE_START:
            yield f"tcu_store.start = {self.start!r}: allowed " + ", ".join(STORE_START)
        if self.start == "learned" and not self.file:
            yield "tcu_store.file: must name the stored state when tcu_store.start = \"learned\""
