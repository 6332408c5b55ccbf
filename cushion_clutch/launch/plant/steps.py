"""The launch's plant as one object: the steps from a TCU cycle to the next, in Python or compiled.

Between two TCU cycles the plant runs alone: the actuator's first-order lag, the clutch FMU (inputs held over
a step), the engine and its idle governor, the compliant driveline, the facings' temperature (the plant's
thermal network every TCU period, a prescribed profile, or the lumped facing) and the launch record's
per-step metrics. :class:`PythonPlant` writes these steps out in Python (the reference); :class:`NativeSteps`
runs the same steps in one compiled call per block (:mod:`.plant_block`, ``fmu_src/launch_plant.c``: the
Python expressions' order of operations, the same results to the last bit). Both answer one interface:

* :meth:`Plant.block` -- the steps to the next TCU cycle (or the slot's switch, or the run's end);
* :meth:`Plant.quiet` -- one quiet TCU period in one step (the car braked at rest, the clutch open and
  retracted: only the idle engine and the temperatures move);
* :meth:`Plant.new_slot`, :meth:`Plant.finish` -- a launch slot's end, the run's end;

and both keep the state the TCU reads (:attr:`Plant.x_act`, :attr:`Plant.theta_cm`, :attr:`Plant.t_e`, ...,
and the driveline's speeds) up to date after every call. A block returns the rows it recorded as
``(step index, time, plant part)``; the plant part is the series' plant columns
(:data:`~..results.series.PLANT_COLUMNS`).
"""
from __future__ import annotations

import logging
import math
from typing import Callable

import numpy as np

from ...model import KELVIN
from ...model.thermal_network import SURFACES, ThermalNetwork
from .driveline import Driveline
from .engine import EngineGovernor
from .fmu_client import ClutchFmu
from .thermal import FacingModel

log = logging.getLogger(__name__)

#: the plant loop: compiled blocks between TCU cycles (:class:`NativeSteps`) or the Python loop (the reference)
PLANTS = ("native", "python")

#: bearing positions closer to zero than this count as retracted (quiet steps), m
X_RETRACTED_M = 1e-6


def facing_profile(path: str) -> Callable[[float], float]:
    """A prescribed facing temperature ``theta_cm(t)`` (K) from a CSV of (time s, theta K) rows."""
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    t, th = data[:, 0].tolist(), data[:, 1].tolist()
    return lambda x: float(np.interp(x, t, th))


def retracted_error(t: float, t_cap: float, x_act: float, x_kiss: float) -> RuntimeError:
    """A quiet period's clutch FMU returned a torque with the bearing retracted."""
    return RuntimeError(f"t = {t:g} s: the clutch FMU returned {t_cap:g} N.m with the bearing "
                        f"retracted to {x_act:g} m (kiss point {x_kiss:g} m)")


class Plant:
    """The plant of one run: the parts, the per-step constants and the state the TCU reads.

    Parameters
    ----------
    clutch : ClutchFmu
    engine : EngineGovernor
    dl : Driveline
    net : ThermalNetwork or None
        The plant's thermal network; None: the lumped ``facing`` or the ``profile``.
    facing, facing_quiet : FacingModel
        The lumped facing at the step and at the quiet period's step.
    profile : callable or None
        A prescribed facing temperature ``theta_cm(t)`` (K), overriding the rest.
    h, act, w_lift, prefill, drive_end : float
        Step (s), the actuator's decay per step, the driver's lift-off speed (rad/s), the pre-fill's end and
        the driving's end in a slot (s).
    tcu_every, net_every, record_every : int
        Steps per TCU period, per network step and per recorded row.
    theta0 : float
        The soaked start temperature, K.
    x_kiss0 : float
        The plant's kiss point at the start (the model's reference, before the first clutch step), m.
    mu_surface : FrictionTable or None
        mu read at the network's friction-surface temperature (issue 37); None: the FMU's torque.
    n_surfaces, r_eq : float
        The clutch's friction surfaces (1) and equivalent radius (m), for ``mu_surface``.
    """

    #: the compiled engine runs (``native``) or the Python one (``python``)
    kind = "python"

    def __init__(self, clutch: ClutchFmu, engine: EngineGovernor, dl: Driveline, net: ThermalNetwork | None,
                 facing: FacingModel, facing_quiet: FacingModel, profile: Callable[[float], float] | None,
                 h: float, act: float, w_lift: float, prefill: float, drive_end: float, tcu_every: int,
                 net_every: int, record_every: int, theta0: float, x_kiss0: float, mu_surface=None,
                 n_surfaces: float = 0.0, r_eq: float = 0.0):
        self.clutch, self.engine, self.dl, self.net = clutch, engine, dl, net
        self.facing, self.facing_quiet, self.profile = facing, facing_quiet, profile
        self.h, self.act, self.w_lift, self.prefill, self.drive_end = h, act, w_lift, prefill, drive_end
        self.tcu_every, self.net_every, self.record_every = tcu_every, net_every, record_every
        self.mu_surface, self.n_surfaces, self.r_eq = mu_surface, n_surfaces, r_eq
        self.h_quiet = tcu_every * h
        self.act_quiet = act ** tcu_every
        # the state the TCU and the loop read
        self.x_act = 0.0
        self.theta_cm = theta0
        self.theta_cs, self.x_kiss = theta0, x_kiss0
        self.t_cap = self.t_e = 0.0
        self.stalled = self.lifted = False
        # the network's accumulated steps and slip energy, and the friction surface's temperature
        self.net_n, self.net_e = 0, 0.0
        self.theta_fs = net.theta_friction if net is not None else theta0

    def at_rest_retracted(self) -> bool:
        """The car stands (no speed, no shaft twist, not locked, the engine not stalled) and the clutch is open:
        no torque, the bearing retracted; a quiet period may run."""
        dl = self.dl
        return (self.t_cap == 0.0 and -X_RETRACTED_M < self.x_act < X_RETRACTED_M and not self.stalled
                and not dl.locked and dl.v == 0.0 and dl.w_d == 0.0 and dl.phi == 0.0)

    def net_temps(self) -> tuple[float, float]:
        """The network's hotter friction surface and its last node (the pressure plate), K; NaN without it."""
        net = self.net
        return (net.theta_surface, net.theta[-1]) if net is not None else (math.nan, math.nan)

    def theta_surface(self) -> float:
        """The network's hotter friction surface now, K; NaN without it."""
        return self.net_temps()[0]

    def start(self, rec) -> None:
        """The run starts with launch record ``rec``."""

    def new_slot(self, done, rec) -> None:
        """Launch slot ``done`` ends, ``rec`` starts: the engine neither stalled nor lifted."""
        self.stalled = self.lifted = False

    def finish(self, rec) -> None:
        """The run ends (or stopped) in launch record ``rec``: the Python objects hold the plant's state."""

    def quiet(self, t: float) -> tuple:
        """One quiet TCU period from ``t`` (s) in one step of :attr:`h_quiet`; its rows' plant part.

        Raises
        ------
        RuntimeError
            The clutch FMU returned a torque with the bearing retracted.
        """
        raise NotImplementedError

    def block(self, k: int, n_steps: int, next_switch: float, slot_start: float, slot_end: float, countdown: int,
              rec_countdown: int, ctl, rec, pedal_level: float, engaged: bool, braking: bool, launching: bool,
              believed: float | None, events: list, launch: int) -> tuple[int, list]:
        """The steps from ``k`` to the next TCU cycle (``countdown`` steps), the slot's switch or the run's end.

        Parameters
        ----------
        k, n_steps : int
            The first step and the run's steps.
        next_switch, slot_start, slot_end : float
            When the next slot starts (``inf``: none), this slot's start and end, s.
        countdown, rec_countdown : int
            Steps to the next TCU cycle and to the next recorded row.
        ctl : TcuController
            The TCU: its command ``x_cmd`` (m), demand ``t_dem`` (N.m) and its rate ``t_rate`` (N.m/s) and
            its beliefs for the launch record's start.
        rec : LaunchRecord
            This slot's record (per-step metrics).
        pedal_level : float
            The driver's pedal, 1.
        engaged, braking, launching : bool
            The TCU's phase as the plant sees it.
        believed : float or None
            The torque the TCU's model expects at the first step's bearing position (a sampling cycle), N.m,
            for the record's characteristic; None: not sampled.
        events : list
            Lock and unlock events are appended: ``(launch, "lock"|"unlock", t)``.
        launch : int
            The slot's launch, 1-based.

        Returns
        -------
        m : int
            Steps run.
        recorded : list of (int, float, tuple)
            Each recorded step's index in the block, its time (s) and its plant part.
        """
        raise NotImplementedError


class PythonPlant(Plant):
    """The plant's steps in Python: the reference."""

    def quiet(self, t: float) -> tuple:
        dl, engine, h, hq = self.dl, self.engine, self.h, self.h_quiet
        self.x_act = x_act = self.x_act * self.act_quiet
        theta_cm = self.theta_cm
        t_cap, self.theta_cs, self.x_kiss = self.clutch.step(t, hq, x_act, theta_cm, dl.w_e)
        self.t_cap = t_cap
        if t_cap != 0.0:
            raise retracted_error(t, t_cap, x_act, self.x_kiss)
        theta_cm_step = theta_cm
        engine.h = dl.h = hq
        self.t_e = engine.torque(dl.w_e, 0.0, False)
        dl.step(self.t_e, 0.0, False, True)
        engine.h = dl.h = h
        net = self.net
        if net is not None:
            self.net_n += self.tcu_every
            if self.net_n >= self.net_every:
                net.step(self.net_n * h, self.net_e / (self.net_n * h), dl.w_e, 0.0, False)
                self.theta_cm, self.net_n, self.net_e = net.theta_cm, 0, 0.0
                self.theta_fs = net.theta_friction
        elif self.profile is not None:
            self.theta_cm = self.profile(t + hq)
        else:
            self.theta_cm = self.facing_quiet.step(theta_cm, 0.0)
        return quiet_part(dl.w_e, x_act, theta_cm_step, self.theta_cs, self.x_kiss, engine.throttle,
                          *self.net_temps())

    def block(self, k, n_steps, next_switch, slot_start, slot_end, countdown, rec_countdown, ctl, rec,
              pedal_level, engaged, braking, launching, believed, events, launch):
        dl, engine, net, h = self.dl, self.engine, self.net, self.h
        clutch_step, clutch_out = self.clutch.step, self.clutch.out
        engine_torque, dl_step = engine.torque, dl.step
        facing_step, profile, theta_a = self.facing.step, self.profile, self.facing.theta_a
        cool_free = profile is None and self.facing.g > 0.0        # no slip: exact decay towards ambient, inlined
        fac_decay = self.facing.decay
        mu_surface, n_surfaces, r_eq = self.mu_surface, self.n_surfaces, self.r_eq
        act, w_lift, prefill, tcu_every, net_every = self.act, self.w_lift, self.prefill, self.tcu_every, self.net_every
        x_cmd, t_dem, t_rate = ctl.x_cmd, ctl.t_dem, ctl.t_rate
        x_act, theta_cm, theta_fs, stalled, lifted = self.x_act, self.theta_cm, self.theta_fs, self.stalled, self.lifted
        net_n, net_e = self.net_n, self.net_e
        record_every = self.record_every
        recorded = []
        k0 = k
        try:
            while True:
                t = k * h
                tl = t - slot_start
                countdown -= 1
                x_act = x_cmd + (x_act - x_cmd) * act
                w_e = dl.w_e
                # -- clutch FMU, inputs held over the step
                omega_slip = w_e - dl.w_d
                t_cap, theta_cs, x_kiss = clutch_step(t, h, x_act, theta_cm, omega_slip)
                if mu_surface is not None:
                    t_cap = n_surfaces * mu_surface(theta_fs - KELVIN, omega_slip) * r_eq * clutch_out[3]
                if engaged and not rec.started:
                    rec.start(ctl.kiss_now - x_kiss, theta_cs, ctl.theta_now - theta_cs)
                if believed is not None:
                    rec.characteristic(believed, t_cap)
                    believed = None
                if engaged and not lifted and rec.lock_time is not None and w_e > w_lift:
                    lifted = True
                t_e = engine_torque(w_e, pedal_level if engaged and not lifted else 0.0, stalled)
                v = dl.v
                ev = dl_step(t_e, t_cap, engaged, braking)
                if ev:
                    events.append((launch, "lock" if ev > 0 else "unlock", t + h if ev > 0 else t))
                    if ev > 0 and rec.lock_time is None:
                        rec.lock_time = tl + h - prefill
                slip_J = dl.slip_J
                theta_cm_step = theta_cm
                if net is not None:
                    rec.slip_J += slip_J
                    net_e += slip_J
                    net_n += 1
                    if net_n == net_every:
                        net.step(net_n * h, net_e / (net_n * h), dl.w_e, dl.w_d, engaged)
                        theta_cm, net_n, net_e = net.theta_cm, 0, 0.0
                        theta_fs = net.theta_friction
                elif slip_J != 0.0:
                    rec.slip_J += slip_J
                    theta_cm = profile(t + h) if profile is not None else facing_step(theta_cm, dl.slip_W)
                elif cool_free:
                    theta_cm = theta_a + (theta_cm - theta_a) * fac_decay
                else:
                    theta_cm = profile(t + h) if profile is not None else facing_step(theta_cm, 0.0)
                accel = (dl.v - v) / h
                t_dem_step = t_dem + t_rate * (tcu_every - countdown) * h
                if engaged:
                    rec.step(accel, tl + h - prefill, t_dem_step, t_cap, launching)
                    if dl.w_e <= engine.w_stall:
                        rec.stall = stalled = True
                elif dl.locked:
                    dl.locked = False
                    events.append((launch, "unlock", t + h))
                if stalled and tl + h >= slot_end - slot_start - h:     # restart for the next launch
                    dl.restart_engine(engine.w_idle)
                if rec_countdown == 0:
                    rec_countdown = record_every
                    recorded.append((k - k0, t, (
                        dl.w_e, dl.w_d, dl.v, accel, x_act, t_dem_step, t_cap, dl.t_c, theta_cm_step, theta_cs,
                        x_kiss, engine.throttle, float(dl.locked),
                        dl.k * dl.phi + dl.c * (dl.w_d - dl.v * dl.i_tot / dl.r), *self._temps())))
                rec_countdown -= 1
                k += 1
                if countdown == 0 or k >= n_steps or k * h >= next_switch:
                    break
        finally:                     # kept as far as the steps went (an FMU's refusal stops the run there)
            self.x_act, self.theta_cm, self.theta_fs, self.stalled, self.lifted = (x_act, theta_cm, theta_fs,
                                                                                  stalled, lifted)
            self.net_n, self.net_e = net_n, net_e
        self.t_cap, self.theta_cs, self.x_kiss, self.t_e = t_cap, theta_cs, x_kiss, t_e
        return k - k0, recorded

    def _temps(self) -> tuple[float, float]:
        return self.net_temps()


def quiet_part(w_e: float, x_act: float, theta_cm_step: float, theta_cs: float, x_kiss: float, throttle: float,
               theta_surface: float, theta_last: float) -> tuple:
    """The plant part of a quiet period's rows: the car stands, the clutch is open and carries nothing."""
    return (w_e, 0.0, 0.0, 0.0, x_act, 0.0, 0.0, 0.0, theta_cm_step, theta_cs, x_kiss, throttle, 0.0, 0.0,
            theta_surface, theta_last)


class NativeSteps(Plant):
    """The plant's steps in C (:class:`~.plant_block.NativePlant`), a block to the next TCU cycle per call;
    the plant's state stays in C over the run and is read back after every call."""

    kind = "native"

    def __init__(self, alpha_jerk: float, creep_Nm: float, **parts):
        from .plant_block import NativePlant
        super().__init__(**parts)
        self.native = NativePlant(self.clutch, self.engine, self.dl, self.net, self.h, self.act, self.w_lift,
                                  self.prefill, self.tcu_every, self.net_every, alpha_jerk, creep_Nm,
                                  self.mu_surface, self.n_surfaces, self.r_eq)
        nat = self.native
        self.ix = nat.ix
        self.o_kiss, self.o_theta_cs, self.o_t_cap, self.o_event = (nat.ix["x_kiss"], nat.ix["theta_cs"],
                                                                    nat.ix["t_cap"], nat.ix["event"])

    def theta_surface(self) -> float:
        theta = self.native.s.theta
        return max(theta[SURFACES[0]], theta[SURFACES[1]])

    def start(self, rec) -> None:
        self.native.start(rec, self.x_act, self.theta_cm, self.t_e, self.t_cap, self.theta_cs, self.x_kiss)

    def new_slot(self, done, rec) -> None:
        self.native.new_slot(done, rec)
        self.stalled = self.lifted = False

    def finish(self, rec) -> None:
        self.native.finish(rec)

    def quiet(self, t: float) -> tuple:
        head = self.native.quiet(t, self.h_quiet, self.act_quiet)
        if head is None:
            st = self.native.s
            raise retracted_error(t, st.t_cap, st.x_act, st.x_kiss)
        dl = self.dl
        (_, _, dl.w_e, _, _, _, _, self.t_e, self.x_act, self.theta_cm, self.t_cap, self.theta_cs, self.x_kiss, _, _,
         _, throttle, theta_cm_step, theta_surface, theta_last) = head
        return quiet_part(dl.w_e, self.x_act, theta_cm_step, self.theta_cs, self.x_kiss, throttle, theta_surface,
                          theta_last)

    def block(self, k, n_steps, next_switch, slot_start, slot_end, countdown, rec_countdown, ctl, rec,
              pedal_level, engaged, braking, launching, believed, events, launch):
        nat, dl, h = self.native, self.dl, self.h
        (m, n_events, dl.w_e, dl.w_d, dl.v, dl.phi, locked, self.t_e, self.x_act, self.theta_cm, self.t_cap,
         self.theta_cs, self.x_kiss, stalled, has_lock, lock_time, _, _, _, _) = nat.block(
            k, n_steps, next_switch, slot_start, slot_end, countdown, ctl.x_cmd, pedal_level, ctl.t_dem,
            ctl.t_rate, engaged, braking, launching)
        m = int(m)
        values = nat.values
        dl.locked, self.stalled = locked != 0.0, stalled != 0.0
        if has_lock and rec.lock_time is None:
            rec.lock_time = lock_time
        if engaged:
            if not rec.started:
                theta_cs_0 = values[self.o_theta_cs]            # the block's first step
                rec.start(ctl.kiss_now - values[self.o_kiss], theta_cs_0, ctl.theta_now - theta_cs_0)
            if not rec.acc:
                rec.t_first = k * h - slot_start + h - self.prefill
            rec.acc.extend(nat.accels(m))
        if believed is not None:
            rec.characteristic(believed, values[self.o_t_cap])
        if n_events:
            width, o_event = nat.width, self.o_event
            for j in range(m):
                ev = values[j * width + o_event]
                if ev != 0.0:
                    events.append((launch, "lock" if ev > 0 else "unlock",
                                   (k + j) * h + h if ev != -1.0 else (k + j) * h))
        row = nat.row
        return m, [(j, (k + j) * h, tuple(row(j))) for j in range(rec_countdown, m, self.record_every)]


def open_plant(kind: str, alpha_jerk: float, creep_Nm: float, **parts) -> Plant:
    """The plant with the compiled engine (``kind="native"`` and a thermal network) or the Python one; the
    compiled one falls back to Python (logged) if its library cannot be built.

    ``alpha_jerk`` and ``creep_Nm`` (the launch record's jerk filter and creep threshold, N.m) are the compiled
    record's; ``parts`` are :class:`Plant`'s parameters, by name."""
    if kind not in PLANTS:
        raise ValueError(f"plant = {kind!r}: allowed {', '.join(PLANTS)}")
    if kind == "native" and parts.get("net") is not None:
        try:
            return NativeSteps(alpha_jerk, creep_Nm, **parts)
        except (RuntimeError, ValueError, OSError) as exc:
            log.warning("the native launch plant is not available, running the Python loop: %s", exc)
    return PythonPlant(**parts)
