"""What the TCU measures and infers: speed sensors and the facing-temperature observer.

The observer uses only what a TCU has: the engine and disc speeds (through
:class:`SpeedSensors`), the clutch torque its own model expects at the
measured bearing position, the ambient temperature and time. Its thermal network
and cushion-spring model have their own parameters (scenario ``[observer]``):
the plant's physical network with a stated mismatch (:class:`~.thermal_network.TcuNetworkBase`).
"""
from __future__ import annotations

import random

from ...model import ClutchParameters, thermal_step
from ...model.clutch_model import hold_theta_cm
from ..scenario.tcu_params import Observer, Sensors
from ..plant.thermal import FacingModel
from ...model.thermal_network import ThermalNetwork


class SpeedSensors:
    """A speed as the TCU reads it: plus Gaussian noise (std, rad/s), then quantised (step, rad/s).

    Deterministic for a given ``seed``.
    """

    __slots__ = ("noise", "step", "rng")

    def __init__(self, s: Sensors):
        self.noise, self.step = s.speed_noise_rad_s, s.speed_resolution_rad_s
        self.rng = random.Random(s.seed)

    def read(self, w: float) -> float:
        """Measured value of the speed ``w`` (rad/s)."""
        if self.noise > 0.0:
            w += self.rng.gauss(0.0, self.noise)
        if self.step > 0.0:
            w = self.step * round(w / self.step)
        return w


class FacingObserver:
    """Estimates theta_cm and theta_cs (K) from the slip power the TCU computes.

    Its thermal model is its own copy of the physical network (:class:`~.thermal_network.ThermalNetwork`
    with the ``[observer]`` parameters, mismatched with the plant's), or with ``network = false`` the
    lumped facing. Call :meth:`update` once per TCU period with the slip power (W) sampled at this
    cycle (and the measured speeds and clamp state); it first advances both temperatures over the period
    that just ended with the power sampled at the previous cycle (causal, held).
    """

    __slots__ = ("facing", "net", "p", "dt", "theta_cm", "theta_cs", "p_prev", "prev")

    def __init__(self, obs: Observer, theta_a: float, theta0: float, dt: float):
        self.net = ThermalNetwork(obs, theta_a, theta0) if obs.network else None
        self.facing = None if obs.network else FacingModel(obs.capacity_J_per_K, obs.loss_W_per_K, obs.heat_share,
                                                           theta_a, dt)
        self.p = ClutchParameters(**obs.spring_parameters(), theta_a=theta_a, theta_cs_start=theta0)
        self.dt = dt
        self.theta_cm = self.theta_cs = theta0
        self.p_prev = 0.0
        self.prev = (0.0, 0.0, False)

    def update(self, p_slip_W: float, w_engine: float = 0.0, w_disc: float = 0.0, clamped: bool = False) -> None:
        """Advance over the last period; remember ``p_slip_W`` (W), the speeds (rad/s) and the clamp state."""
        # the spring's ODE is driven by the facing estimate held within the model's range (hold_theta_cm)
        self.theta_cs = thermal_step(self.theta_cs, hold_theta_cm(self.theta_cm), self.dt, self.p)
        if self.net is not None:
            self.net.step(self.dt, self.p_prev, *self.prev)
            self.theta_cm = self.net.theta_cm
        else:
            self.theta_cm = self.facing.step(self.theta_cm, self.p_prev)
        self.p_prev = p_slip_W
        self.prev = (w_engine, w_disc, clamped)
