"""Scenario sections of the TCU's own knowledge: observer, speed sensors, kiss-point adaptation.

SI units unless a name says otherwise; checked like every scenario section.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from ..config import Checked
from .thermal_network import TcuNetworkBase


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
        yield from self._ranges({
            "capacity_J_per_K": (1.0, 1e6), "loss_W_per_K": (0.0, 1e4), "heat_share": (0.0, 1.0),
            "spring_U_W_per_K": (0.0, 1e4), "spring_H_W_per_K": (0.0, 1e4), "spring_C_J_per_K": (0.0, 1e6, True)})
        if self.spring_U_W_per_K + self.spring_H_W_per_K <= 0.0:
            yield "observer.spring_U_W_per_K + spring_H_W_per_K: must be > 0"


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
