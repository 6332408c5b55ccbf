"""The TCU variants: one production-like launch controller, five ways of knowing the clutch.

Every ``tcu.period_s`` the controller (shared by all variants):

1. **pre-fill** (the first ``prefill_s`` of every launch slot, the first
   launch included): bearing to the believed first contact;
2. **launch**, from the driver's pedal (``[driver]``): the clutch-torque
   demand is a feed-forward plus a PI (its integral corrects what the
   characteristic gets wrong):

   * pedal launches: engine-speed trajectory control,
     ``T = T_e - J_e w_ref' + PI(w_e - w_ref)``, ``w_ref`` rising with a
     first-order lag to the pedal's engine speed (``T_e`` is the engine's
     torque signal);
   * creep: the driver's creep torque (the idle governor holds the engine);
   * sync, once the slip is below ``sync_slip_rad_s``: slip-speed trajectory
     whose rate falls linearly from the rate the present demand gives to
     ``lockup_slip_rate_rad_s2`` as the slip reaches zero, ``T = T_lock - s_ref' / K + PI(s - s_ref)`` with the
     locked-driveline torque ``T_lock = (J_d T_e + J_e T_load) / (J_e + J_d)``
     and ``K = 1/J_e + 1/J_d``: at the meeting the clutch torque is within
     ``lockup_slip_rate_rad_s2 / K`` of the torque it carries once locked (no lurch);

   the demand rises at most at ``torque_ramp_Nm_per_s``; it is extrapolated
   one period ahead, turned into a bearing position through the believed
   characteristic and the actuator's first-order lag is inverted over the
   period (the command that brings the bearing there at the period's end);
3. **close** after lock-up: the bearing ramps to ``x_to_closed_m``.

The variants differ only in the cushion-spring temperature they assume and
in whether they learn the kiss point:

============================  ===============================================  ==========
variant                        theta_cs used                                    kiss point
============================  ===============================================  ==========
``naive``                      table reference (20 degC)                        model
``aware``                      ideal: true theta_cm through the exact model     model
``aware_estimated``            observer (:mod:`.observer`), mismatched          model
``adaptive``                   table reference                                  learned
``adaptive_aware_estimated``   observer                                         learned, shifted by delta_kiss(theta estimate)
``production``                 EKF on its own thermal network (:mod:`.production`:   EKF state, with mu
                               its own sensors, ECU torque, estimated mass/grade)
============================  ===============================================  ==========

The learned kiss point is kept as an offset to the model's kiss point at the
temperature assumed when it was learned, so the compensated variant moves it
with the table's ``delta_kiss(theta_cs estimate)`` between adaptations and the
uncompensated one keeps it fixed.
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass, replace

from ...model import KELVIN, ClutchParameters, SpringTable, kiss_point, outputs, x_to_for_torque
from ..scenario.load import Driver, Engine, Tcu
from ..scenario.tcu_params import Adaptation, Observer, Protection
from .knowledge import (CLOSE, LAUNCH, OPEN, PREFILL, EkfEstimate, LearnedKiss, ModelKiss, Observed, TableReference,
                        Told)
from .protection import LIMIT, ThermalProtection


@dataclass(frozen=True)
class Variant:
    """A TCU variant, composed of what it knows (:mod:`.knowledge`): how it knows the temperatures
    (``temperature``, a strategy class) and whether it learns the kiss point (``kiss``)."""

    name: str
    temperature: type
    kiss: type


VARIANTS = {v.name: v for v in (
    Variant("naive", TableReference, ModelKiss),
    Variant("aware", Told, ModelKiss),
    Variant("aware_estimated", Observed, ModelKiss),
    Variant("adaptive", TableReference, LearnedKiss),
    Variant("adaptive_aware_estimated", Observed, LearnedKiss),
    Variant("production", EkfEstimate, ModelKiss),  # see .production: sensors, EKF, adaptations, mass and grade
)}

__all__ = ["CLOSE", "LAUNCH", "OPEN", "PREFILL", "VARIANTS", "TcuController", "Variant"]

#: entries a memo of the TCU's model keeps before it starts afresh
MEMO_SIZE = 64


#: a launch's engine-speed target is raised above the pedal's only when the TCU believes it locks up after
#: this many times the lock-up deadline (``tcu.lockup_deadline_s + tcu.forced_sync_s``): see
#: :meth:`TcuController.launch_target_rad_s`
RAISE_FACTOR = 2.0


def _full_load_Nm(engine, w_rad_s: float) -> float:
    """The engine's full-load torque at ``w_rad_s`` (the scenario's curve, linear, clamped at its ends), N.m."""
    w = [x * math.pi / 30.0 for x in engine.torque_curve_rpm]
    t = engine.torque_curve_Nm
    if w_rad_s <= w[0]:
        return float(t[0])
    for i in range(1, len(w)):
        if w_rad_s <= w[i]:
            return t[i - 1] + (t[i] - t[i - 1]) * (w_rad_s - w[i - 1]) / (w[i] - w[i - 1])
    return float(t[-1])


def _memo(memo: dict, key: tuple, compute):
    """``memo[key]``, computed by ``compute()`` the first time: exact inputs, so exactly the value computed.

    A key starting with -0.0 is not remembered (it compares equal to 0.0); NaN never compares equal, so
    it is computed every time.
    """
    hit = memo.get(key)
    if hit is None:
        hit = compute()
        if key[0] != 0.0 or math.copysign(1.0, key[0]) > 0.0:
            if len(memo) >= MEMO_SIZE:
                memo.clear()
            memo[key] = hit
    return hit


class TcuController:
    """One TCU variant; :meth:`cycle` runs once per TCU period.

    Parameters
    ----------
    variant : Variant
    table : SpringTable
        The TCU's characteristic (its friction table, if any, is ignored: mu nominal).
    p : ClutchParameters
        The TCU's clutch parameters (nominal mu, lever ratio, kiss point at reference).
    theta0 : float
        Temperature at the start, K (the car is thermally soaked).
    j_d_kg_m2, t_load_Nm : float
        Disc and vehicle inertia as the clutch feels it (kg m2) and the clutch torque
        holding the car (N.m): known to the TCU (lock-up torque, kiss-point learner).
    j_e_kg_m2, w_idle_rad_s : float
        Engine inertia (kg m2) and idle speed (rad/s).
    tcu, driver, engine : Tcu, Driver, Engine
        Its scenario sections: the controller's settings, the driver's pedal and creep torque, the engine's
        full-load curve as the engine control reports it.
    observer, adaptation, protection : Observer, Adaptation, Protection
        The sections of the observer, the kiss-point learner and the thermal protection (defaults: the
        sections' defaults); each used by the variants that have one.
    """

    def __init__(self, variant: Variant, table: SpringTable, p: ClutchParameters, theta0: float,
                 j_d_kg_m2: float, t_load_Nm: float, j_e_kg_m2: float = 0.25, w_idle_rad_s: float = 83.78, *,
                 tcu: Tcu, driver: Driver, engine: Engine, observer: Observer | None = None,
                 adaptation: Adaptation | None = None, protection: Protection | None = None):
        if table.friction is not None:          # the TCU's model has the nominal, constant mu
            table = copy.copy(table)
            table.friction = None
        self.v, self.table, self.p = variant, table, p
        self.tc, self.driver, self.engine = tcu, driver, engine
        self.period = tcu.period_s
        # the characteristic a temperature-blind TCU believes: the table's reference temperature (its kiss point,
        # delta_kiss = 0; 20 degC), not its first row (-40 degC since the tables run from a winter start)
        self.theta_ref = next((t for t, d in zip(table.theta_degC, table.delta_kiss_m) if d == 0.0),
                              table.theta_degC[0]) + KELVIN
        #: how it knows the temperatures, whether it learns the kiss point (:mod:`.knowledge`)
        self.know = know = variant.temperature(self, observer or Observer(), theta0)
        # its answers, bound once (the methods below say what they are; asked several times a TCU cycle)
        self.theta_used, self.theta_cm_used = know.theta_cs, know.theta_cm_model
        self.theta_cm_estimate, self.theta_facing_protect = know.estimate, know.protect
        self.kiss_learning = variant.kiss(adaptation or Adaptation(), self.period, j_d_kg_m2, t_load_Nm)
        self.learner = self.kiss_learning.learner
        self.offset = 0.0               #: learned kiss point minus the model's at the assumed temperature, m
        self.phase, self.t_dem, self.x_cmd = OPEN, 0.0, 0.0
        #: demand rate over the coming period (the TCU's extrapolation), N.m/s
        self.t_rate = 0.0
        self.launch = 0
        self.j_d, self.t_load, self.j_e, self.w_idle = j_d_kg_m2, t_load_Nm, j_e_kg_m2, w_idle_rad_s
        tc = tcu
        self.act = math.exp(-tc.period_s / tc.actuator_time_constant_s) if tc.actuator_time_constant_s > 0 else 0.0
        self.w_ref = self.s_ref = self.integral = 0.0
        self.sync = False
        self.rate = self.t_sync = self.jerk = 0.0
        self.x_close = 0.0
        self.t_closed = math.inf
        self._kiss_key: tuple = ()
        self._kiss_value = math.nan
        self._command_memo: dict = {}
        self._torque_memo: dict = {}
        #: thermal protection by the facing-temperature estimate (:mod:`.protection`), TCUs that have one
        protection = protection or Protection()
        if know.told:                   # the ideal TCU knows the true temperatures: no allowance for an estimate's error
            protection = replace(protection, estimate_error_K=0.0)
        self.protection = ThermalProtection(protection) if protection.enabled and know.protects else None
        self.inhibited = self.limited = False
        #: the launch's engine-speed target (:meth:`launch_target_rad_s`, decided at its start), rad/s
        self.w_target = w_idle_rad_s
        #: time since the launch's start (after the pre-fill), s
        self.t_launch = 0.0
        #: the protection level the current launch runs at (decided at its start; 3: inhibited)
        self.launch_level = 0
        #: the calibration's friction at the last measured slip speed, relative to the nominal mu
        #: (``tcu.facing_mu_slope_per_100_rad_s``; 1: mu constant)
        self.mu_cal = 1.0
        #: the assumed theta_cs (K) and believed kiss point (m) after the last cycle
        self.theta_now, self.kiss_now = self.theta_used(), self.kiss()

    @property
    def name(self) -> str:
        return self.v.name

    def theta_used(self) -> float:
        """The cushion-spring temperature the TCU assumes, K."""
        return self.know.theta_cs()

    def theta_cm_estimate(self) -> float:
        """Its facing-temperature estimate (observer, EKF), K (NaN without one)."""
        return self.know.estimate()

    def theta_facing_protect(self) -> float:
        """The facing temperature the thermal protection acts on (the TCU's estimate; ``aware``: the true), K."""
        return self.know.protect()

    def theta_cm_used(self) -> float | None:
        """The facing temperature the TCU's clutch model assumes (the stack's growth), K; None: theta_cs.

        Held within the model's range (:func:`~cushion_clutch.model.clutch_model.hold_theta_cm`), as the
        production TCU's EKF holds it: an estimate past it must not stop the TCU."""
        return self.know.theta_cm_model()

    def learned_kiss(self) -> list[tuple[int, float]]:
        """(launch, learned kiss point m) of every adaptation (none if it does not learn)."""
        return self.kiss_learning.estimates()

    def model_kiss(self, theta: float) -> float:
        """The model's kiss point at ``theta`` (K), m (the cover's balance: cushion, growth, wear).

        The last result is kept: an estimator's temperatures change less often than the TCU cycles.
        """
        key = (theta, self.theta_cm_used())
        if key != self._kiss_key:
            self._kiss_key, self._kiss_value = key, kiss_point(theta, self.table, self.p, key[1])
        return self._kiss_value

    def kiss(self) -> float:
        """The kiss point the TCU believes, m."""
        return self.model_kiss(self.theta_used()) + self.offset

    def x_for_torque(self, torque_Nm: float, theta: float, theta_cm: float | None) -> float:
        """The model's bearing position for ``torque_Nm`` (N.m) at ``theta`` and ``theta_cm`` (K), m
        (:func:`~cushion_clutch.model.x_to_for_torque` on the TCU's table and parameters).

        Remembered per exact inputs (:func:`_memo`): a creep demand held at its level, or the pre-fill's
        0 N.m, repeats them from cycle to cycle while the temperature estimate stands.
        """
        return _memo(self._command_memo, (torque_Nm, theta, theta_cm), lambda: x_to_for_torque(
            torque_Nm, theta, self.table, self.p, theta_cm=theta_cm))

    def command(self, torque_Nm: float) -> float:
        """Bearing position for ``torque_Nm`` (the calibration's friction at the measured slip, :attr:`mu_cal`), m."""
        return self.x_for_torque(torque_Nm / self.mu_cal, self.theta_used(), self.theta_cm_used()) + self.offset

    def model_torque(self, x_m: float) -> float:
        """Torque the TCU's model expects at bearing position ``x_m`` (the calibration's friction at the
        measured slip, :attr:`mu_cal`), N.m.

        Remembered per exact inputs (:func:`_memo`): the closed position is asked every launch cycle.
        """
        theta, theta_cm = self.theta_used(), self.theta_cm_used()
        return self.mu_cal * _memo(self._torque_memo, (x_m, theta, theta_cm, self.offset), lambda: outputs(
            x_m - self.offset, theta, self.table, self.p, theta_cm).torque)

    def learn_kiss(self, torque_Nm: float, x_mean: float) -> None:
        """Move the believed kiss point towards the one that the window's clutch torque (N.m) at the mean
        bearing position ``x_mean`` (m) gives (:class:`~.knowledge.LearnedKiss`)."""
        theta = self.theta_used()
        distance = (x_to_for_torque(torque_Nm / self.mu_cal, theta, self.table, self.p, theta_cm=self.theta_cm_used())
                    - self.model_kiss(theta))
        estimate = x_mean - distance
        self.learner.estimates.append((self.launch, estimate))
        self.offset += self.learner.gain * (estimate - self.kiss())

    def _to_actuator(self, x_target: float, x_meas: float) -> float:
        """Command that brings a first-order actuator from ``x_meas`` to ``x_target`` in one period, m
        (within the actuator's travel)."""
        u = (x_target - self.act * x_meas) / (1.0 - self.act)
        hi = self.tc.x_to_closed_m
        return 0.0 if u < 0.0 else (hi if u > hi else u)

    def holds(self, level: str, w_rad_s: float) -> bool:
        """True if the engine at ``w_rad_s`` (rad/s) and the level's pedal carries the holding torque the TCU
        believes (its full-load curve less its drag): locked there, the car does not roll back."""
        eng = self.engine
        return (self.driver.pedal(level) * _full_load_Nm(eng, w_rad_s) - eng.drag_Nm_per_rad_s * w_rad_s
                > self.t_load)


    def launch_target_rad_s(self, level: str) -> float:
        """The launch's engine-speed target, rad/s: ``idle + pedal (full - idle)`` with ``full`` the pedal's
        (``tcu.engine_speed_full_pedal_rpm``), unless that does not lock up in time.

        The time to lock-up the TCU believes at a target ``w``: the engine's torque at the pedal there (its
        full-load curve, which the engine control reports, minus its drag) less the holding torque the TCU
        believes accelerates the disc and vehicle inertia it believes to ``w``,
        ``w J_d / (pedal T_max(w) - drag w - T_load)``; in time: by ``tcu.lockup_deadline_s +
        tcu.forced_sync_s``.

        * limited by the thermal protection: the lowest ``full`` from ``protection.limit_engine_speed_rpm`` up
          (50 rpm steps, below the pedal's) whose target locks up in time with the estimate ``t_load`` (a
          limit that strands the launch keeps it slipping: heat);
        * otherwise, or if none does: the pedal's target; if that is believed to lock up only after
          :data:`RAISE_FACTOR` times the time (a steep grade, a heavy car, a light pedal: the engine at that
          speed barely holds the car), the lowest faster one, in 50 rpm steps up to 500 rpm below
          ``engine.max_speed_rpm``, that locks up in time, else the quickest of them (none at all: the
          one with the engine's largest surplus). (The factor leaves the
          pedal's target to a TCU whose belief of mass and load is off: production's on the ``protection``
          duty believed 12 s where the launch locked up in 7 s; raising it there cost 131 instead of 88 kJ
          per start.)
        """
        tc, eng = self.tc, self.engine
        pedal = self.driver.pedal(level)
        budget = tc.lockup_deadline_s + tc.forced_sync_s
        rpm = math.pi / 30.0

        def lock_time(w: float) -> float:
            surplus = pedal * _full_load_Nm(eng, w) - eng.drag_Nm_per_rad_s * w - self.t_load
            return w * self.j_d / surplus if surplus > 0.0 else math.inf

        if self.limited:
            full = self.protection.p.limit_engine_speed_rpm
            while full < tc.engine_speed_full_pedal_rpm:
                w = self.w_idle + pedal * (full * math.pi / 30.0 - self.w_idle)
                if lock_time(w) <= budget:
                    return w
                full += 50.0
        w_pedal = self.w_idle + pedal * (tc.engine_speed_full_pedal_rpm * math.pi / 30.0 - self.w_idle)
        if level == "creep" or lock_time(w_pedal) <= RAISE_FACTOR * budget:
            return w_pedal
        faster = [w_pedal + k * 50.0 * rpm for k in range(1, 200)
                  if w_pedal + k * 50.0 * rpm <= (eng.max_speed_rpm - 500.0) * rpm]
        for w in faster:
            if lock_time(w) <= budget:
                return w
        # none in time: the quickest; none at all (the load believed beyond the engine): the largest surplus
        return min([w_pedal, *faster], key=lambda w: (lock_time(w), -(pedal * _full_load_Nm(eng, w)
                                                                      - eng.drag_Nm_per_rad_s * w)))

    def _demand(self, level: str, w_e: float, w_d: float, t_e: float) -> float:
        """The launch's clutch-torque demand for this period, N.m (updates references and integral)."""
        tc, drv, dt = self.tc, self.driver, self.period
        slip = w_e - w_d
        kp, ki = tc.speed_kp_Nm_per_rad_s, tc.speed_ki_Nm_per_rad
        k = 1.0 / self.j_e + 1.0 / self.j_d
        t_lock = (self.j_d * t_e + self.j_e * self.t_load) / (self.j_e + self.j_d)
        late = (level != "creep" and self.t_launch >= tc.lockup_deadline_s and w_d >= self.w_idle
                and self.holds(level, w_d))
        if not self.sync and self.t_dem > 0.0 and (slip <= tc.sync_slip_rad_s or (late and slip > 0.0)):
            # the slip rate falls linearly from the one the present demand gives (no torque step) to the
            # lock-up rate, over the time that closes the slip: a parabolic landing; after the lock-up deadline
            # (a pedal launch, the disc at idle speed or above) at least fast enough to close it in forced_sync_s
            r_end = tc.lockup_slip_rate_rad_s2
            r0 = max(r_end, k * (self.t_dem - t_lock))
            if late:
                r0 = max(r0, 2.0 * slip / tc.forced_sync_s - r_end)
            self.sync, self.s_ref, self.rate, self.t_sync = True, slip, r0, 2.0 * slip / (r0 + r_end)
            self.jerk = (r0 - r_end) / self.t_sync
        elif self.sync and late and self.t_sync > tc.forced_sync_s and self.s_ref > 0.0:
            # a slow sync at the deadline: the rest of its slip reference closed within forced_sync_s
            r_end = tc.lockup_slip_rate_rad_s2
            r0 = max(self.rate, 2.0 * self.s_ref / tc.forced_sync_s - r_end)
            self.rate, self.t_sync = r0, 2.0 * self.s_ref / (r0 + r_end)
            self.jerk = (r0 - r_end) / self.t_sync
        if self.sync:
            if self.t_sync > 0.0:
                self.rate -= self.jerk * dt
                self.t_sync -= dt
            ds = -self.rate
            self.s_ref += ds * dt
            e = slip - self.s_ref
            self.integral += ki * e * dt
            return t_lock - ds / k + kp * e + self.integral
        if level == "creep":
            return drv.creep_torque_Nm
        w_t = self.w_target                               # decided at the launch's start (limited or raised)
        dw = (w_t - self.w_ref) / tc.engine_speed_time_constant_s
        self.w_ref += dw * dt
        e = w_e - self.w_ref
        demand = t_e - self.j_e * dw + kp * e + self.integral
        if demand < min(self.t_dem + tc.torque_ramp_Nm_per_s * dt, self.t_closed):
            self.integral += ki * e * dt                     # anti-windup: not while rate- or capacity-limited
        return demand

    def read_and_cycle(self, sensors, t: float, launch: int, tl: float, locked_once: bool, w_e: float, w_d: float,
                       w_v: float, x_act: float, theta_cm: float, t_e: float, level: str) -> None:
        """One TCU period from the plant's true values: the engine, disc and wheel speeds at the disc (rad/s) as
        the ``sensors`` (:class:`~.observer.SpeedSensors`) read them, then :meth:`cycle` (``t`` in s, unused
        here; the rest as :meth:`cycle` takes them)."""
        self.cycle(launch, tl, locked_once, sensors.read(w_e), sensors.read(w_d), x_act, theta_cm, t_e, level,
                   sensors.read(w_v))

    def cycle(self, launch: int, tl: float, locked_once: bool, w_e: float, w_d: float, x_meas: float,
              theta_cm_true: float, t_e: float = 0.0, level: str = "hard", w_v: float | None = None) -> None:
        """One TCU period: update estimates, learn, set ``phase``, ``t_dem`` (N.m), ``t_rate`` and ``x_cmd`` (m).

        ``launch`` (1-based) and ``tl`` (s since its slot started, pre-fill
        first); ``locked_once``: lock-up reached in this launch; ``w_e``,
        ``w_d`` measured speeds (rad/s); ``x_meas`` measured bearing position
        (m); ``theta_cm_true`` is used by the ideal ``aware`` TCU only;
        ``t_e`` the engine's torque signal (N.m); ``level`` the driver's demand level; ``w_v`` the
        measured wheel speed at the disc (rad/s, the kiss-point learner's input; default ``w_d``).
        """
        tc = self.tc
        prot = self.protection
        self.mu_cal = tc.mu_calibration(w_e - w_d)
        self.know.update(self, theta_cm_true, x_meas, w_e, w_d)
        if launch != self.launch:
            self.launch = launch
            self.sync, self.integral, self.t_dem, self.w_ref = False, 0.0, 0.0, w_e
            self.t_closed = math.inf
            self.kiss_learning.start_launch()
            if prot is not None:
                self.inhibited = prot.launch_start(self.theta_facing_protect(), tl, launch)
                # the launch's limit is set at its start: a mid-launch switch of the engine-speed target made the
                # speed controller pull the engine down (a torque spike of 208 N.m, measured)
                self.launch_level = prot.update(self.theta_facing_protect(), tl, launch)
                self.limited = self.launch_level >= LIMIT
            self.w_target = self.launch_target_rad_s(level)
        if prot is not None:
            prot.update(self.theta_facing_protect(), tl, launch)
            if self.inhibited:                    # no launch in this slot: the clutch stays open
                self.phase, self.t_dem, self.t_rate, self.x_cmd = OPEN, 0.0, 0.0, 0.0
                self.theta_now, self.kiss_now = self.theta_used(), self.kiss()
                return
        was_launching = self.phase == LAUNCH
        t_launch = self.t_launch = tl - tc.prefill_s
        t_prev = self.t_dem
        if 0.0 <= t_launch < tc.drive_time_s and not locked_once:
            self.t_closed = self.model_torque(tc.x_to_closed_m)      # the largest torque it believes it has
        if t_launch < 0.0:
            self.phase, self.t_dem, self.w_ref = PREFILL, 0.0, w_e                 # pre-fill to first contact
            self.x_cmd = self._to_actuator(self.command(0.0), x_meas)
        elif t_launch < tc.drive_time_s and not locked_once:
            self.phase = LAUNCH
            demand = self._demand(level, w_e, w_d, t_e)
            limit = min(t_prev + tc.torque_ramp_Nm_per_s * self.period, self.t_closed)
            self.t_dem = 0.0 if demand < 0.0 else (limit if demand > limit else demand)
            self.kiss_learning.sample(self, w_d if w_v is None else w_v, x_meas)
            self.t_rate = (self.t_dem - t_prev) / self.period
            self.x_cmd = self._to_actuator(self.command(max(0.0, self.t_dem + self.t_rate * self.period)), x_meas)
            self.x_close = x_meas
        elif t_launch < tc.drive_time_s:
            self.phase, self.t_rate = CLOSE, 0.0
            self.x_close = min(tc.x_to_closed_m, self.x_close + tc.close_rate_m_per_s * self.period)
            self.x_cmd = self.x_close
        else:
            self.phase, self.t_dem, self.t_rate, self.x_cmd = OPEN, 0.0, 0.0, 0.0
        if self.phase != LAUNCH:
            self.t_rate = 0.0
            if was_launching and prot is not None:
                prot.launch_end(self.theta_facing_protect())
        self.theta_now, self.kiss_now = self.theta_used(), self.kiss()
