"""The ``production`` TCU: only what a production TCU has.

It shares the launch strategy of the other variants (:class:`~.tcu.TcuController`)
and differs in what it knows:

* **sensors** (:mod:`.sensors`): engine speed from the 60-2 crank wheel,
  input-shaft speed from the Hall sensor, both read every TCU period; the
  engine control unit's torque estimate (gain error, offset, noise); the
  bearing position sensor (offset, noise, quantisation); ambient temperature.
  The actuator's servo drives the *measured* position to the command, so the
  bearing sits at ``command - position offset``.
* **clutch torque** from the engine side: ``T_c = T_est - J_e dw_e/dt`` over a
  window of ``WINDOW`` TCU periods (speed difference of the crank readings,
  mean torque estimate and bearing position over the same window);
* **slip power** for the thermal model: ``T_c`` over the torque signal's gain as the EKF
  referenced it on cool facings (``gain_ref``; 1 before a reference) times the measured slip speed.
  ``k_heat`` is the network's inverse heat capacity and scales its cooling as much as its heating:
  a gain error left in the heat would be learned into ``k_heat`` on the heat-up and then bias every
  cool-down (``docs/explanation/tcu_thermal_estimate.md``). The learned offset is not taken out: its
  torque signature is nearly that of the facings' temperature, and its errors would feed back into the
  heat;
* **temperatures, touch point and friction** from the EKF (:mod:`.ekf`) on
  the TCU's own thermal network, whose heat-loss and heat-input scales the
  EKF learns from the torque across launches (the network stays mismatched
  with the plant as shipped);
* **mass and grade** from the RLS (:mod:`.mass_grade`); once the load is
  estimated, the vehicle-side clutch torque ``(m_eq a + F_load) r / (eta i)``
  while the car moves in slip is a second EKF measurement (its noise
  ``vehicle_torque_sd_Nm``), independent of the engine inertia term.

The characteristic the TCU believes at a bearing position ``x`` is
``mu_scale T_model(x + offset - dx_kiss, theta_cs)``; the torque scale it
learns is the engine control unit's, so a gain error of the torque
estimate is a gain error of the learned characteristic (no sensor of a
production TCU measures the clutch torque otherwise).
"""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from collections import deque
from pathlib import Path

from ..model import ClutchParameters, SpringTable
from ..model.thermal_network import SURFACES
from .ekf import IX_DX, ClutchEkf, EkfParams, TcuNetworkParams
from .mass_grade import MassGrade, MassGradeEstimator
from .sensors import ProductionSensors, TcuSensors
from .store import AdaptedState, load_state, save_state
from .tcu import LAUNCH, OPEN, TcuController, Variant, _memo
from .touchpoint import StandstillResult, learn_touch_point

#: TCU periods over which speeds are differentiated
WINDOW = 5
#: noise of the vehicle-side clutch torque measurement, N.m
VEHICLE_TORQUE_SD_NM = 6.0


class ProductionTcu(TcuController):
    """The ``production`` variant; call :meth:`sense` and then :meth:`cycle` every TCU period.

    Parameters
    ----------
    variant, sc, table, p, theta0, j_d_kg_m2, t_load_Nm, j_e_kg_m2, w_idle_rad_s
        As :class:`~.tcu.TcuController`; ``j_d_kg_m2`` and ``t_load_Nm`` (the truth) are
        not used: the TCU starts from its mass prior on level ground and then uses its estimates.
    sensors, net, ekf, mass_grade
        The TCU's sensors, own thermal network, EKF and RLS settings.
    ratios : tuple of float
        ``(i_tot, r_m, eta, j_disc_kg_m2, rolling, air_N_s2_per_m2)`` of the launch gear, nominal.
    """

    def __init__(self, variant: Variant, sc, table: SpringTable, p: ClutchParameters, theta0: float,
                 j_d_kg_m2: float, t_load_Nm: float, j_e_kg_m2: float, w_idle_rad_s: float,
                 sensors: ProductionSensors, net: TcuNetworkParams, ekf: EkfParams, mass_grade: MassGrade,
                 ratios: tuple[float, ...]):
        if table.friction is not None:          # the TCU's model has the nominal, constant mu
            table = copy.copy(table)
            table.friction = None
        self.sens = TcuSensors(sensors)
        theta_a_meas = self.sens.ambient(p.theta_a)
        self.ekf = ClutchEkf(net, ekf, table, p, theta_a_meas, theta0, sc.tcu.mu_calibration)
        self.rls = MassGradeEstimator(mass_grade, *ratios)
        self.i_tot, self.r = ratios[0], ratios[1]
        self.t = 0.0
        self.t_engine = 0.0
        self.w_prev = (0.0, 0.0)
        self.hist: deque = deque(maxlen=WINDOW + 1)     # (w_e, w_v, T_est, x_meas)
        self.x_offset = sensors.position_offset_m
        self._closed_key = -1                   # the EKF revision of the closed-position torque below
        self._closed_value = 0.0
        self._kiss_rev, self._kiss_belief = -1, 0.0     # the EKF revision of the kiss point below
        self._rls_n, self._rls_load = -1, (0.0, 0.0)     # the RLS's update count and its inertia and load then
        super().__init__(variant, sc, table, p, theta0, self.rls.inertia_at_disc_kg_m2(),
                         self.rls.holding_torque_Nm(), j_e_kg_m2, w_idle_rad_s)

    # --- what the TCU believes ---------------------------------------------------------------------
    def theta_used(self) -> float:
        return self.ekf.theta_cs

    def theta_cm_estimate(self) -> float:
        return self.ekf.theta_cm

    def theta_facing_protect(self) -> float:
        """The friction system's temperature the thermal protection acts on: the hotter of the EKF's facings (their
        mean) and its hotter metal friction surface, K (:meth:`.tcu.TcuController.theta_facing_protect`)."""
        s = self.ekf.s
        return max(self.ekf.theta_cm, s.item(SURFACES[0]), s.item(SURFACES[1]))

    def theta_cm_used(self) -> float:
        """The facing temperature the TCU's clutch model assumes (the EKF's estimate, within the model's range), K."""
        return self.ekf.theta_cm_model

    def kiss(self) -> float:
        """The kiss point the TCU believes, in the true bearing frame, m (kept until the EKF's estimate changes,
        :attr:`~.ekf.ClutchEkf.revision`)."""
        e = self.ekf
        if e.revision != self._kiss_rev:
            self._kiss_rev, self._kiss_belief = e.revision, self.model_kiss(e.theta_cs) + e.dx_used - self.x_offset
        return self._kiss_belief

    def x_for_torque(self, torque_Nm: float, theta: float, theta_cm: float) -> float:
        """The model's bearing position for ``torque_Nm`` (N.m) at ``theta`` and ``theta_cm`` (K), m: the EKF's
        clutch model's inverse (:meth:`~.tcu_model.TcuClutchModel.x_for_torque`: native, or with
        ``tcu_model.NATIVE = False`` the Python :func:`~cushion_clutch.model.x_to_for_torque`, the reference),
        remembered per exact inputs as :meth:`.tcu.TcuController.x_for_torque` does."""
        return _memo(self._command_memo, (torque_Nm, theta, theta_cm),
                     lambda: self.ekf.clutch.x_for_torque(torque_Nm, theta, theta_cm))

    def command(self, torque_Nm: float) -> float:
        """Bearing position for ``torque_Nm`` (N.m) as the position sensor reads it, m."""
        th = min(max(self.ekf.theta_cs, self.table.theta_min_K), self.table.theta_max_K)
        return (self.x_for_torque(torque_Nm / max(self.ekf.mu_applied, 1e-3), th, self.theta_cm_used())
                + self.ekf.dx_used)

    def model_torque(self, x_m: float) -> float:
        """Torque the TCU believes at the true bearing position ``x_m`` (it sees it through its sensor), N.m.

        The value at the closed position (asked every launch cycle for the capacity limit) is kept
        until the EKF's estimate changes (every ``ekf.period_s`` at most, :attr:`~.ekf.ClutchEkf.revision`), and
        scaled by the friction the TCU applies at the measured slip.
        """
        e = self.ekf
        if x_m == self.sc.tcu.x_to_closed_m:
            if e.revision != self._closed_key:          # the nominal-friction torque; the friction scales it
                self._closed_key, self._closed_value = e.revision, e.used_torque(x_m + self.x_offset, mu=1.0)
            return self._closed_value * e.mu_applied
        return e.used_torque(x_m + self.x_offset)

    # --- sensing -------------------------------------------------------------------------------------
    def sense(self, t: float, w_engine: float, w_disc: float, engine_torque_Nm: float) -> None:
        """The true speeds (rad/s) and engine torque (N.m) at time ``t`` (s), once per TCU period.

        The wheels turn by the trapezoidal angle since the last call; each edge's
        time is interpolated with the period's mean speed (the speeds are smooth
        on a 10 ms scale; the edge timing within a period is what a per-step
        integration would refine).
        """
        dt = t - self.t
        if dt > 0.0:
            self.sens.advance(t, 0.5 * (self.w_prev[0] + w_engine), 0.5 * (self.w_prev[1] + w_disc), dt)
        self.t, self.t_engine, self.w_prev = t, engine_torque_Nm, (w_engine, w_disc)

    def _estimate(self, x_true: float, w_v: float) -> tuple[float, float, float, float]:
        """Read the sensors, update the RLS and the EKF; the readings ``(w_e, w_d, x, T_est)``."""
        s, e = self.sens, self.ekf
        w_e, w_d = s.crank.read(self.t), s.shaft.read(self.t)
        x_meas = s.position(x_true)
        t_est = s.engine_torque(self.t_engine)
        self.hist.append((w_e, w_v, t_est, x_meas))
        readings = (w_e, w_d, x_meas, t_est)
        launching = self.phase == LAUNCH
        slip = w_e - w_d
        e.set_slip(slip)                  # the characteristic (friction) at the measured slip speed
        if len(self.hist) <= WINDOW:
            return readings
        if self.phase == OPEN:            # clutch open: no clutch torque, no RLS update, no correction
            e.accumulate(self.period, 0.0)
            if e.due():
                e.predict(w_e, w_d, False)
            return readings
        span = WINDOW * self.period
        h0, h1 = self.hist[0], self.hist[-1]
        _, _, ts, xs = zip(*self.hist)
        t_est = sum(ts[1:]) / WINDOW
        x_mean = sum(xs[1:]) / WINDOW
        t_c = t_est - self.j_e * (h1[0] - h0[0]) / span
        v = h1[1] * self.r / self.i_tot               # wheel speed at the disc (ABS sensors)
        a = (h1[1] - h0[1]) / span * self.r / self.i_tot
        self.rls.update(t_c, v, a)
        g_ref = e.gain_ref if e.gain_ref is not None else 1.0    # the torque signal's gain, referenced cool
        e.accumulate(self.period, max(t_c, 0.0) / g_ref * abs(slip) if launching else 0.0)
        if e.due():
            e.predict(w_e, w_d, True)
            if launching:
                e.correct(t_c, x_mean, slip, True)
                if all(self.rls.ready()) and h1[1] > 0.0 and h0[1] > 0.0:    # mass and load both estimated
                    t_vehicle = self.rls.inertia_at_disc_kg_m2() * (h1[1] - h0[1]) / span \
                        + self.rls.holding_torque_Nm()
                    e.correct(t_vehicle, x_mean, slip, True, VEHICLE_TORQUE_SD_NM)
        return readings

    def cycle(self, launch: int, tl: float, locked_once: bool, w_e: float, w_d: float, x_meas: float,
              theta_cm_true: float, t_e: float = 0.0, level: str = "hard", w_v: float | None = None) -> None:
        """As :meth:`TcuController.cycle`, on the TCU's own readings.

        The speeds, the torque signal and the true ``x_meas`` given are replaced
        by the sensors' readings (:meth:`sense` fed the truth); the strategy runs
        in the position sensor's frame and the servo's target is shifted back by
        the sensor's offset (the servo drives the measured position).
        """
        w_e_m, w_d_m, x_m, t_est = self._estimate(x_meas, w_d if w_v is None else w_v)
        rls = self.rls
        if rls.updates != self._rls_n:                  # the estimates change only with an update
            self._rls_n, self._rls_load = rls.updates, (rls.inertia_at_disc_kg_m2(), rls.holding_torque_Nm())
        self.j_d, self.t_load = self._rls_load
        super().cycle(launch, tl, locked_once, w_e_m, w_d_m, x_m, theta_cm_true, t_est, level, w_d_m)
        if self.x_cmd != 0.0:
            self.x_cmd -= self.x_offset

    # --- key-on and key-off ----------------------------------------------------------------------
    def adapted_state(self, starts_since_standstill: int, touch_point_learned: bool) -> AdaptedState:
        """What the TCU stores at key-off: the characteristic it applies and its thermal scales."""
        e = self.ekf
        sd = math.sqrt(max(float(e.P[IX_DX, IX_DX]), 0.0)) if e.evidence else e.x_accuracy
        return AdaptedState(e.dx_used, min(max(sd, 1e-6), 0.009), e.mu_scale if e.evidence else e.mu_prior,
                            e.loss_scale, e.heat_scale, touch_point_learned, starts_since_standstill)


@dataclass
class KeyOn:
    """How the production TCU started: ``start`` ("reset" or "learned: <file>"), the standstill learning
    (None if not run) and the key-ons since the last standstill learning (this one counted)."""

    start: str
    standstill: StandstillResult | None
    starts_since_standstill: int
    touch_point_learned: bool


def key_on(ctl: ProductionTcu, sc, fmu: Path, clutch_start: dict[str, float], j_disc_kg_m2: float,
           w_idle_rad_s: float) -> KeyOn:
    """Load the stored state (``[tcu_store]``) and learn the touch point at standstill when due (``[standstill]``).

    A reset TCU has no stored touch point: with ``standstill.learn = "missing"`` it learns it now; a
    learned one relearns once ``standstill.interval_starts`` key-ons have passed.
    """
    st, store = sc.standstill, sc.tcu_store
    state = AdaptedState()
    start = "reset"
    if store.start == "learned":
        path = Path(store.file)
        path = path if path.is_absolute() else Path(sc.folder or ".") / path
        state = load_state(path)
        start = f"learned: {path.name}"
        ctl.ekf.set_prior(state.dx_kiss_m, state.dx_kiss_sd_m if state.dx_kiss_sd_m == state.dx_kiss_sd_m
                          else sc.ekf.kiss_sd_m, state.mu_scale, state.loss_scale, state.heat_scale)
    since = state.starts_since_standstill + 1
    due = st.learn == "always" or (st.learn == "missing" and (not state.touch_point_learned
                                                               or since > st.interval_starts))
    result = None
    learned = state.touch_point_learned
    if due:
        e = ctl.ekf
        result = learn_touch_point(fmu, clutch_start, st, sc.tcu_sensors, ctl.table, ctl.p, e.theta_cs, e.theta_cm,
                                   e.dx_used, j_disc_kg_m2, w_idle_rad_s, sc.tcu.period_s,
                                   sc.tcu.actuator_time_constant_s, sc.run.step_s, sc.tcu.mu_calibration)
        if result.ok:
            e.set_prior(result.dx_kiss_m, st.accuracy_m, e.mu_prior, e.loss_scale, e.heat_scale)
            since, learned = 0, True
    ctl.kiss_now = ctl.kiss()
    return KeyOn(start, result, since, learned)


def key_off(ctl: ProductionTcu, sc, k: KeyOn) -> Path | None:
    """Write the adapted state to ``tcu_store.save`` (relative to the scenario's folder); its path or None."""
    if not sc.tcu_store.save:
        return None
    path = Path(sc.tcu_store.save)
    path = path if path.is_absolute() else Path(sc.folder or ".") / path
    return save_state(ctl.adapted_state(k.starts_since_standstill, k.touch_point_learned), path)
