"""Scenario sections of the TCU's own knowledge: observer, speed sensors, kiss-point adaptation, the
production TCU's EKF and its thermal network, its mass-and-grade estimator, its sensors and the thermal
protection. The TCU room (:mod:`..tcu`) and the plant's sensor hardware import their section from here.

SI units unless a name says otherwise; checked like every scenario section.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

from ...config import Checked
from ...model.spring_heat import SpringHeat
from ...model.thermal_network import TcuNetworkBase


@dataclass(frozen=True)
class Observer(TcuNetworkBase, SpringHeat):
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

    _section = "observer"

    def _problems(self) -> Iterable[str]:
        yield from super()._problems()
        yield from self._ranges({"capacity_J_per_K": (1.0, 1e6), "loss_W_per_K": (0.0, 1e4), "heat_share": (0.0, 1.0)})
        yield from self._spring_problems()


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


@dataclass(frozen=True)
class TcuNetworkParams(TcuNetworkBase, SpringHeat):
    """Section ``[tcu_thermal]``: the TCU's own thermal network, the plant's physical network with the
    mismatch stated in :class:`~.thermal_network.TcuNetworkBase`, and the EKF's cushion-spring heat path
    (:class:`~cushion_clutch.model.spring_heat.SpringHeat`)."""

    _section = "tcu_thermal"

    def _problems(self) -> Iterable[str]:
        yield from super()._problems()
        yield from self._spring_problems()


@dataclass(frozen=True)
class EkfParams(Checked):
    """Section ``[ekf]``: noise, excitation conditions and the update period (SI)."""

    period_s: float = 0.1
    theta0_sd_K: float = 5.0
    heat_share_sd: float = 0.3
    """relative uncertainty of each node's slip heat"""
    theta_walk_K2_per_s: float = 0.01
    kiss_sd_m: float = 0.4e-3
    """prior sd of the touch-point offset"""
    kiss_walk_m2_per_s: float = 1e-12
    mu_sd: float = 0.1
    mu_walk_per_s: float = 1e-6
    mu_walk_per_K: float = 5e-4
    """variance of the friction scale's random walk per kelvin the estimated facings heat above
    ``mu_reference_max_degC``, 1/K (a facing's friction changes with its temperature, by an amount the
    calibration does not know: fade)"""
    mu_reference_max_degC: float = 80.0
    """friction updates while the estimated facings are below this temperature (degC) reference the engine
    torque estimate's gain and offset (the nominal mu holds on cool facings); above, the friction is judged
    relative to that reference and follows the facings' temperature (``mu_fade_sd``)"""
    mu_slope_sd: float = 0.03
    """prior sd of the friction's slip-speed slope, 1 per 100 rad/s (0: mu does not depend on the slip)"""
    mu_slope_walk_per_s: float = 1e-7
    """random walk of the slip-speed slope, 1/s"""
    mu_slope_evidence_sd: float = 1.0
    """the slope is applied only beyond this many of its standard deviations (by the excess)"""
    mu_fade_sd: float = 0.1
    """prior sd of the friction's temperature slope above ``mu_reference_max_degC``, 1 per 100 K of the
    estimated facings (0: ``mu_scale`` does not follow the estimated facing temperature)"""
    mu_fade_walk_per_K: float = 1e-3
    """variance of the temperature slope's random walk per kelvin the estimated facings heat above
    ``mu_reference_max_degC``, 1/(100 K)^2/K (a fade curve steepens as the facings heat)"""
    torque_sd_Nm: float = 8.0
    """measurement noise of the engine-side clutch torque"""
    slip_min_rad_s: float = 10.0
    touch_torque_min_Nm: float = 8.0
    touch_torque_max_Nm: float = 80.0
    mu_torque_min_Nm: float = 40.0
    gate_sd: float = 4.0
    mu_deadband: float = 0.05
    """the engine torque estimate's stated gain accuracy: a learned mu_scale within 1 +- this is not applied"""
    torque_offset_accuracy_Nm: float = 3.0
    """the engine torque estimate's stated offset accuracy, N.m: the evidence envelope and the prior sd of
    the offset state"""
    offset_walk_Nm2_per_s: float = 1e-4
    """random walk of the torque estimate's offset (it drifts with the engine's state), N.m2/s"""
    position_accuracy_m: float = 20e-6
    """the position sensor's stated offset accuracy, m (the evidence envelope)"""
    evidence_threshold: float = 1.0
    """the learned characteristic is applied once its difference from the prior exceeds this multiple of the
    bias envelope (the touch point and the friction scale fit a gain and offset error of the torque only
    approximately: with a bias at the envelope the ratio overshot 1 by 4 % in a synthetic launch)"""
    evidence_release: float = 0.7
    """the learned characteristic stays applied until its difference from the prior falls below this
    fraction of the bias envelope"""
    evidence_confirm: int = 5
    """... and is applied once the difference has exceeded the envelope in this many consecutive touch-point
    or friction updates (a transient of the filter within a launch is no evidence)"""
    temperature_update: bool = True
    loss_scale_sd: float = 0.5
    """prior sd of the heat-loss scale (every node's sink conductance: convection and engine block), 1;
    0 keeps the network's losses as given"""
    loss_walk_per_s: float = 1e-7
    """random walk of the heat-loss scale, 1/s (its variance grows by this per second)"""
    heat_scale_sd: float = 0.15
    """prior sd of the heat scale (the network's heat per J/K, its inverse heat capacity relative to the TCU's: the
    slip heat, conduction and losses alike), 1;
    0 keeps the slip power as measured"""
    heat_walk_per_s: float = 1e-7
    """random walk of the heat-input scale, 1/s"""
    theta_torque_min_Nm: float = 40.0
    """the temperatures and both thermal scales are corrected only above this model torque, N.m"""
    loss_excitation_K: float = 30.0
    """the heat-loss scale is corrected only while the estimated facings are this far above the ambient, K"""
    scale_min: float = 0.25
    scale_max: float = 4.0
    """both scales are kept within [scale_min, scale_max] (a physical network)"""

    _section = "ekf"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges(spec := {
            "period_s": (1e-3, 10.0), "theta0_sd_K": (0.0, 500.0), "heat_share_sd": (0.0, 10.0),
            "theta_walk_K2_per_s": (0.0, 1e4), "kiss_sd_m": (0.0, 0.01), "kiss_walk_m2_per_s": (0.0, 1e-3),
            "mu_sd": (0.0, 1.0), "mu_walk_per_s": (0.0, 1.0),
            "mu_walk_per_K": (0.0, 1.0), "mu_reference_max_degC": (-50.0, 1000.0), "mu_slope_sd": (0.0, 1.0),
            "mu_slope_walk_per_s": (0.0, 1.0),
            "mu_slope_evidence_sd": (0.0, 100.0), "mu_fade_sd": (0.0, 2.0), "mu_fade_walk_per_K": (0.0, 1.0),
            "torque_sd_Nm": (1e-3, 1e3),
            "slip_min_rad_s": (0.0, 1e3), "touch_torque_min_Nm": (0.0, 1e4), "touch_torque_max_Nm": (0.0, 1e4),
            "mu_torque_min_Nm": (0.0, 1e4), "gate_sd": (1.0, 100.0, True),
            "mu_deadband": (0.0, 0.5), "torque_offset_accuracy_Nm": (0.0, 100.0),
            "position_accuracy_m": (0.0, 1e-3), "evidence_release": (0.0, 1.0), "evidence_threshold": (1.0, 100.0),
            "offset_walk_Nm2_per_s": (0.0, 100.0),
            "evidence_confirm": (1, 1000), "loss_scale_sd": (0.0, 2.0), "loss_walk_per_s": (0.0, 1.0),
            "heat_scale_sd": (0.0, 2.0), "heat_walk_per_s": (0.0, 1.0), "loss_excitation_K": (0.0, 500.0), "theta_torque_min_Nm": (0.0, 1e4),
            "scale_min": (0.0, 1.0, True), "scale_max": (1.0, 100.0)})
        yield from self._integers("evidence_confirm")
        if self._passed(spec, "touch_torque_max_Nm", "touch_torque_min_Nm") and \
                self.touch_torque_max_Nm <= self.touch_torque_min_Nm:
            yield "ekf.touch_torque_max_Nm: must exceed ekf.touch_torque_min_Nm"


@dataclass(frozen=True)
class MassGrade(Checked):
    """Section ``[mass_grade]``: the TCU's RLS estimator of mass and grade (SI)."""

    mass_prior_kg: float = 1600.0
    mass_prior_sd_kg: float = 500.0
    load_prior_sd_N: float = 3000.0
    forgetting: float = 0.999
    """per TCU period"""
    noise_sd_N: float = 200.0
    """expected equation error (torque estimate, acceleration noise), N"""
    torque_min_Nm: float = 20.0
    speed_min_m_s: float = 0.3
    ready_sd: float = 0.2
    """a parameter counts as estimated once its sd is below this fraction of its prior sd"""

    _section = "mass_grade"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "mass_prior_kg": (100.0, 1e5), "mass_prior_sd_kg": (1.0, 1e5), "load_prior_sd_N": (1.0, 1e6),
            "forgetting": (0.9, 1.0), "noise_sd_N": (1e-3, 1e5), "torque_min_Nm": (0.0, 1e4),
            "speed_min_m_s": (0.0, 50.0), "ready_sd": (0.0, 1.0, True)})


@dataclass(frozen=True)
class ProductionSensors(Checked):
    """Section ``[tcu_sensors]``: the production TCU's sensors (SI)."""

    crank_teeth: int = 60
    crank_missing_teeth: int = 2
    input_teeth: int = 32
    tooth_pitch_error_rad: float = 0.002
    """standard deviation of each tooth's angular position error, rad"""
    timer_s: float = 1e-6
    """edge time-stamp resolution, s"""
    timeout_s: float = 0.1
    """no edge for this long: the speed reads 0"""
    torque_gain_error: float = 0.04
    torque_offset_Nm: float = 3.0
    torque_noise_Nm: float = 1.0
    position_noise_m: float = 5e-6
    position_offset_m: float = 20e-6
    position_resolution_m: float = 5e-6
    ambient_offset_K: float = 1.0
    ambient_resolution_K: float = 0.5
    seed: int = 7

    _section = "tcu_sensors"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges(spec := {
            "crank_teeth": (4, 1000), "crank_missing_teeth": (0, 10), "input_teeth": (1, 1000),
            "tooth_pitch_error_rad": (0.0, 0.05), "timer_s": (0.0, 1e-3), "timeout_s": (1e-3, 10.0),
            "torque_gain_error": (-0.2, 0.2), "torque_offset_Nm": (-100.0, 100.0), "torque_noise_Nm": (0.0, 100.0),
            "position_noise_m": (0.0, 1e-3), "position_offset_m": (-1e-3, 1e-3),
            "position_resolution_m": (0.0, 1e-3), "ambient_offset_K": (-20.0, 20.0),
            "ambient_resolution_K": (0.0, 10.0), "seed": (0, 2 ** 31 - 1)})
        yield from self._integers("crank_teeth", "crank_missing_teeth", "input_teeth", "seed")
        if self._passed(spec, "crank_teeth", "crank_missing_teeth") and \
                isinstance(self.crank_teeth, int) and isinstance(self.crank_missing_teeth, int) and \
                self.crank_missing_teeth >= self.crank_teeth - 2:
            yield "tcu_sensors.crank_missing_teeth: must leave at least 2 teeth on the wheel"


@dataclass(frozen=True)
class Protection(Checked):
    """Section ``[protection]``: thresholds on the estimated facing temperature (degC) and the limit action."""

    enabled: bool = False
    """off unless a scenario turns it on (the shipped comparisons of the TCUs' characteristics run without it;
    the ``protection`` scenario turns it on)"""
    warn_degC: float = 250.0
    limit_degC: float = 280.0
    inhibit_degC: float = 310.0
    resume_degC: float = 250.0
    damage_degC: float = 350.0
    """the seed paper: permanent damage above 350-400 degC"""
    hysteresis_K: float = 10.0
    estimate_error_K: float = 25.0
    """allowance for the estimate's error in the next launch's check: a launch is inhibited when the estimate plus
    the largest rise of a launch so far reaches ``damage_degC`` less this, K (the shipped estimators' friction
    surfaces were measured up to 22 K below the plant's at a launch's start on the ``protection`` duty; the ideal
    ``aware`` TCU, told the true temperatures, takes none)"""
    limit_engine_speed_rpm: float = 1300.0
    """the launch's engine-speed target at full pedal while limiting (the pedal scales it), rpm"""

    _section = "protection"

    def _problems(self) -> Iterable[str]:
        if not isinstance(self.enabled, bool):
            yield f"protection.enabled = {self.enabled!r}: must be true or false"
        yield from self._ranges(spec := {
            "warn_degC": (20.0, 600.0), "limit_degC": (20.0, 600.0), "inhibit_degC": (20.0, 600.0),
            "resume_degC": (20.0, 600.0), "damage_degC": (20.0, 800.0), "hysteresis_K": (0.0, 100.0),
            "estimate_error_K": (0.0, 100.0), "limit_engine_speed_rpm": (500.0, 8000.0)})
        if not self._passed(spec, "warn_degC", "limit_degC", "inhibit_degC", "damage_degC", "resume_degC"):
            return
        if not self.warn_degC <= self.limit_degC <= self.inhibit_degC < self.damage_degC:
            yield "protection: need warn_degC <= limit_degC <= inhibit_degC < damage_degC"
        if self.resume_degC >= self.inhibit_degC:
            yield "protection.resume_degC: must be below protection.inhibit_degC"
