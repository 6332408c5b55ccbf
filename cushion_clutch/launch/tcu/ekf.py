"""The production TCU's estimator: an extended Kalman filter on its own thermal network, with touch-point,
mu and thermal-parameter adaptation.

State (K for each network node and the cushion spring, m, 1, 1, 1)::

    s = [theta_node for the network's NODES..., theta_cs, dx_kiss, mu_scale, k_loss, k_heat]

* **Prediction**: the TCU's own :class:`~.thermal_network.ThermalNetwork`
  (parameters ``[tcu_thermal]``, deliberately not the plant's) heated by
  ``P = T_est w_slip``, the engine control unit's torque estimate times the
  measured slip speed, and losing heat to the air and the engine block through
  ``k_loss`` times its sink conductances, the whole network's heat balance per
  J/K scaled by ``k_heat``: ``dtheta/dt = k_heat (A_link theta + k_loss (a_sink
  theta + b_sink) + q)``; plus the cushion-spring ODE with the TCU's U, H, C
  (``C dtheta_cs/dt = U (theta_cm - theta_cs) + H (theta_a - theta_cs)``,
  ``theta_cm`` the mean of the facings; not scaled: they are the clutch
  model's). ``dx_kiss`` (touch-point offset at the bearing), ``mu_scale``
  (friction relative to the nominal mu) and the two thermal scales are random
  walks. Process noise: ``heat_share_sd`` of each node's slip heat, plus the
  random walks.
* **Thermal scales** (what a production TCU adapts instead of being given the
  plant's values): ``k_loss`` (prior sd ``loss_scale_sd``) stands for the
  heat-transfer coefficients the network gets wrong (convection, engine block),
  ``k_heat`` (prior sd ``heat_scale_sd``) for its heat capacities: the
  network's inverse heat capacity relative to the TCU's, so it scales
  conduction and losses as it scales the slip heat (and absorbs the torque
  estimate's gain and offset error in the heat). A capacity error changes how
  fast the clutch cools as much as how fast it heats: with ``k_heat`` scaling
  the slip heat alone, a ``k_heat`` learned on the heat-up left the cooling
  wrong by the same factor, and the cool-downs between and after hot launches
  went uncorrected (``docs/explanation/tcu_thermal_estimate.md``). Their effect on
  the temperatures accumulates in the prediction: the covariance between a
  scale and the temperatures grows while heat flows (``k_heat``) or flows
  out (``k_loss``, in proportion to ``theta - theta_sink``), and a torque residual
  at the next launch corrects the scale through it. Besides learning, the
  scales make the filter honest: a network that may lose half as much heat or half again
  as much is uncertain by tens of kelvin after a five-minute cool-down, so the torque
  residuals move the temperatures, which a filter sure of its network ignores.
  Both scales are kept within ``[scale_min, scale_max]``.
* **Measurement** (during slip): the clutch torque from the engine side,
  ``T_c = T_est - J_e dw_e/dt``, against the model
  ``h(s) = mu_scale T_model(x_meas - dx_kiss, theta_cs, theta_cm) + b`` (the TCU's
  characteristic, nominal mu; ``theta_cm`` sets the stack's thermal growth; ``b``
  the engine control unit's torque offset, a state of prior sd
  ``torque_offset_accuracy_Nm``, its stated accuracy, and a slow random walk,
  ``mu_scale`` carrying the gain error: without it the offset had nowhere to go
  but into the touch point, the temperatures and the thermal scales);
  the Jacobian is taken numerically in ``theta_cs``, the facings and
  ``dx_kiss``. The facings' column matters: on the default characteristic
  ``dT/dtheta_cm`` is about +0.05 N.m/K at 60-150 N.m, where ``dT/dtheta_cs``
  changes sign (+0.03 at 30 N.m, -0.03 at 150 N.m).
* **Excitation conditions** (each parameter is corrected only while its own
  condition holds; the others' gains are set to zero and the covariance
  update uses the Joseph form, which stays valid for any gain):

  - all: slip speed above ``slip_min_rad_s`` and the TCU in its launch phase;
  - touch point ``dx_kiss``: model torque in ``[touch_torque_min_Nm, touch_torque_max_Nm]``
    (near the kiss point the torque is most sensitive to the position, and a
    friction error matters least);
  - friction ``mu_scale``: model torque above ``mu_torque_min_Nm`` (there a
    relative friction error is large in N.m and the position error small).

  The bands overlap by default (8-80 and above 40 N.m): on a progressive
  characteristic ``dT/dx`` grows almost in proportion to ``T``, so a kiss
  offset and a friction scale look alike (their Jacobian columns are nearly
  collinear) and are separated only by the curve's shape over the whole
  ramp. Disjoint bands make the two parameters trade errors and converge
  slowly over many launches; the characteristic itself (what the TCU
  commands through) converges within a launch either way;
  - temperatures and ``k_heat``: all of the above and a model torque of at
    least ``theta_torque_min_Nm`` (``temperature_update = false`` leaves the
    thermal states and scales to the prediction alone). Near the kiss point a
    temperature error moves the characteristic like a touch-point offset
    (``dT/dtheta`` and ``dT/dx_kiss`` nearly collinear); at higher torque the
    temperature has its own signature (the facings' growth, the spring's
    softening changing sign along the curve). Without this condition, in the
    ``creep`` scenario (20 N.m launches only) the two traded errors and the worst
    characteristic error doubled;
  - ``k_loss``: in addition, the estimated facings at least
    ``loss_excitation_K`` above the ambient (the losses are proportional to
    the temperature rise: near ambient a residual says nothing about them).
    The scale is observable only across launches with a cooling in between
    whose length the TCU knows: repeated launches and a cool-down.

A torque residual larger than ``gate_sd`` standard deviations is rejected.

**Friction that depends on slip speed and fades** (docs/explanation/production_tcu.md, section 5).
The friction is the calibration's at the measured slip (``calibration``, the facing's nominal slip-speed
shape, ``[tcu] facing_mu_slope_per_100_rad_s``; 1 for a constant mu) times
``mu_scale + slope (|slip| - SLIP_REF_RAD_S) / SLIP_UNIT_RAD_S``:
the slope is a state (prior 0, sd ``mu_slope_sd``), corrected with ``mu_scale`` and applied beyond
``mu_slope_evidence_sd`` of its standard deviation. ``mu_scale`` follows the estimated facings above
``mu_reference_max_degC``: the prediction adds ``k_fade d(theta_cm) / FADE_UNIT_K``, with the fade slope
``k_fade`` a state (prior 0, sd ``mu_fade_sd``; its variance grows by ``mu_fade_walk_per_K`` per kelvin the
facings heat), learned through its covariance with ``mu_scale``, so the friction falls while a launch heats
the facings and recovers while they cool before the next (a random walk lags a launch behind); and
``mu_scale``'s variance grows by ``mu_walk_per_K`` per kelvin of heating. Below that temperature the nominal
mu is taken to hold: the torque the filter expects the engine control unit to report at the prior's
position for :data:`FRICTION_TORQUE_NM`, over that torque (:meth:`ClutchEkf.ecu_ratio`, the ECU's gain,
offset and the clutch's friction together), is referenced there (``ecu_ratio_ref``); above, its change
(:meth:`ClutchEkf.friction_ratio`) beyond twice ``mu_scale``'s sd at referencing (at most ``mu_deadband``)
is friction evidence of its own, and the friction applied is the prior's times that change, with the
prior's touch point. Judging the friction by the filter's whole characteristic at one torque, not by
``mu_scale`` alone, cancels the trade between the nearly collinear friction scale, touch point and ECU
offset states (in ``fade`` the scale drifted 4 % below the ECU-view friction while the touch point and
the offset took up the torque, and the old test applied it). The friction evidence is applied in
``evidence_confirm`` consecutive updates beyond the threshold and released as it is applied, in as many
consecutive updates below ``evidence_release`` of it: released on one update, a change hovering near the
threshold switched the friction applied between the prior's and the change within a launch, an error of the
whole change (``fade``, ``--seed 7``, launch 12: 8.74 N.m, kept 5.83).

**The nominal calibration as the prior** (what the TCU *applies*). The torque
the EKF learns against is the engine control unit's estimate, whose stated
accuracy is ``mu_deadband`` in gain and ``torque_offset_accuracy_Nm`` in offset,
and the bearing position reads within ``position_accuracy_m``. Through the touch
band such biases are indistinguishable from a touch-point offset: on the default
clutch at 20 degC the ECU's +4 % and +3 N.m move ``dx_kiss`` to about -0.11 mm
within 0.2 s of the first launch, and the characteristic the TCU then believes
is 5.3 N.m above the true one at 90 N.m (the naive TCU: 2.1). The learned
state therefore moves the characteristic the TCU applies only on *evidence*: the
learned characteristic differs from the nominal one (same temperatures) at one of
the torques :data:`EVIDENCE_TORQUES_NM` by more than the envelope the known biases
can produce there, ``g T + o + (dT/dx) x_acc``, times ``evidence_threshold``, in
``evidence_confirm`` consecutive updates. The evidence is kept until the
difference falls below ``evidence_release`` times the envelope (hysteresis).
Without evidence the TCU applies the prior (``dx = 0`` and ``mu = 1``, or a
stored or standstill-learned touch point, :meth:`ClutchEkf.set_prior`, whose
accuracy is then ``x_acc``); the filter's own state keeps learning (its
residuals stay consistent with the biased torque).
"""
from __future__ import annotations

import math

import numpy as np

from ...model import ClutchParameters, SpringTable
from ...model.clutch_model import hold_theta_cm
from ...model.thermal_network import FACINGS, N_NODES, ThermalNetwork
from ..scenario.tcu_params import EkfParams, TcuNetworkParams
from .tcu_model import TcuClutchModel

#: state indices: the network's nodes, then these
IX_CS, IX_DX, IX_MU, IX_LOSS, IX_HEAT = N_NODES, N_NODES + 1, N_NODES + 2, N_NODES + 3, N_NODES + 4
N_STATE = N_NODES + 5
N_T = N_NODES + 1          #: temperatures (the nodes and the cushion spring)
F1, F2 = FACINGS
#: speed band of the cached discretisation (convection), rad/s
SPEED_BAND = 10.0

#: the engine control unit's torque offset: the last state, after the temperatures, the touch point, mu and
#: the two thermal scales
IX_OFF = N_STATE
#: the friction's slip-speed slope (per :data:`SLIP_UNIT_RAD_S` of slip, about :data:`SLIP_REF_RAD_S`): the last state
IX_SLOPE = IX_OFF + 1
#: the friction's temperature slope (fade, per :data:`FADE_UNIT_K` of the estimated facings above
#: ``mu_reference_max_degC``): the last state
IX_FADE = IX_SLOPE + 1
N_STATE = IX_FADE + 1
#: slip speed about which the friction scale is stated, and the unit of the slope, rad/s
SLIP_REF_RAD_S = 150.0
SLIP_UNIT_RAD_S = 100.0
#: the unit of the friction's temperature slope, K
FADE_UNIT_K = 100.0
#: nominal torques at which the learned characteristic is compared with the nominal one, N.m
EVIDENCE_TORQUES_NM = (10.0, 20.0, 40.0, 80.0, 120.0)
#: nominal torque at which the friction is referenced and judged (the top of the evidence torques), N.m
FRICTION_TORQUE_NM = 120.0


def _exp_and_integral(a: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(exp(A dt), int_0^dt exp(A s) ds)`` by scaling and squaring the augmented matrix ``[[A, I], [0, 0]] dt``."""
    n = a.shape[0]
    aug = np.zeros((2 * n, 2 * n))
    aug[:n, :n] = a * dt
    aug[:n, n:] = np.eye(n) * dt
    norm = float(np.max(np.sum(np.abs(aug), axis=1)))
    squarings = max(0, int(math.ceil(math.log2(norm / 0.25)))) if norm > 0.25 else 0
    m = aug / 2.0 ** squarings
    term = np.eye(2 * n)
    e = np.eye(2 * n)
    for k in range(1, 9):
        term = term @ m / k
        e = e + term
    for _ in range(squarings):
        e = e @ e
    return e[:n, :n], e[:n, n:]


class ClutchEkf:
    """EKF of the production TCU.

    Parameters
    ----------
    net : TcuNetworkParams
    e : EkfParams
    table : SpringTable
        The TCU's characteristic (nominal; its friction table is ignored).
    p : ClutchParameters
        The TCU's clutch parameters (nominal mu, lever ratio, kiss point at reference).
    theta_a, theta0 : float
        Measured ambient and starting temperature, K.
    calibration : callable, optional
        The calibration's friction at a slip speed (rad/s) relative to the nominal mu (the facing's nominal
        slip-speed shape, :meth:`~.scenario.Tcu.mu_calibration`); default: mu constant. The friction states
        are relative to it.
    native : bool, optional
        Evaluate the characteristic's torque with the native clutch model (:mod:`.tcu_model`; same figures to
        round-off) or, False, with the Python model (the reference); default :data:`.tcu_model.NATIVE`.
    """

    def __init__(self, net: TcuNetworkParams, e: EkfParams, table: SpringTable, p: ClutchParameters,
                 theta_a: float, theta0: float, calibration=None, native: bool | None = None):
        self.net, self.e, self.table, self.p = net, e, table, p
        #: the characteristic's torque T(x_to, theta_cs, theta_cm) (native or Python clutch model)
        self.clutch = TcuClutchModel(table, p, native)
        self.calibration = calibration if calibration is not None else (lambda w: 1.0)
        #: the calibration's friction at the measured slip (:meth:`set_slip`) and at SLIP_REF_RAD_S, 1
        self.cal = self.cal_ref = float(self.calibration(SLIP_REF_RAD_S))
        self.model = ThermalNetwork(net, theta_a, theta0)
        self._caps = np.array(self.model.caps)   # the nodes' heat capacities, J/K
        self._eye = np.eye(N_STATE)
        self.theta_a = theta_a
        self.s = np.array([theta0] * N_T + [0.0, 1.0, 1.0, 1.0])
        self.P = np.diag([e.theta0_sd_K ** 2] * N_T + [e.kiss_sd_m ** 2, e.mu_sd ** 2, e.loss_scale_sd ** 2,
                                                      e.heat_scale_sd ** 2])
        self.q_rw = np.array([e.theta_walk_K2_per_s] * N_T + [e.kiss_walk_m2_per_s, e.mu_walk_per_s,
                                                            e.loss_walk_per_s if e.loss_scale_sd > 0 else 0.0,
                                                            e.heat_walk_per_s if e.heat_scale_sd > 0 else 0.0])
        # the ECU torque offset, appended: prior sd its stated accuracy, a slow random walk
        self.s = np.append(self.s, 0.0)
        self.P = np.pad(self.P, (0, 1))
        self.P[IX_OFF, IX_OFF] = e.torque_offset_accuracy_Nm ** 2
        self.q_rw = np.append(self.q_rw, e.offset_walk_Nm2_per_s)
        # the friction's slip-speed slope, appended: prior 0 (the nominal mu is constant) with sd mu_slope_sd
        self.s = np.append(self.s, 0.0)
        self.P = np.pad(self.P, (0, 1))
        self.P[IX_SLOPE, IX_SLOPE] = e.mu_slope_sd ** 2
        self.q_rw = np.append(self.q_rw, e.mu_slope_walk_per_s if e.mu_slope_sd > 0.0 else 0.0)
        # the friction's temperature slope, appended: prior 0 (the nominal mu does not fade) with sd mu_fade_sd;
        # its variance grows in predict() as the facings heat
        self.s = np.append(self.s, 0.0)
        self.P = np.pad(self.P, (0, 1))
        self.P[IX_FADE, IX_FADE] = e.mu_fade_sd ** 2
        self.q_rw = np.append(self.q_rw, 0.0)
        #: the measured slip speed the characteristic is evaluated at (:meth:`set_slip`), rad/s
        self.slip = SLIP_REF_RAD_S
        self.energy_J = 0.0
        self.t_acc = 0.0
        self._cache: dict = {}
        self._dcache: dict = {}
        self._ev_cache: dict = {}
        #: count of accepted measurement updates, and of rejected ones (gate)
        self.accepted = self.rejected = 0
        #: the prior characteristic: touch-point offset (m), friction scale and the offset's accuracy (m)
        #: (the nominal calibration; a stored or standstill-learned one after :meth:`set_prior`)
        self.dx_prior, self.mu_prior, self.x_accuracy = 0.0, 1.0, e.position_accuracy_m
        #: the learned characteristic differs from the prior by more than the known biases (applied)
        self.evidence = False
        self._over = 0
        #: the last ratio of that difference to the bias envelope (max over EVIDENCE_TORQUES_NM), 1
        self.evidence_ratio = 0.0
        #: the engine torque estimate's gain as learned on cool facings (``mu_scale`` there, within 1 +-
        #: ``mu_deadband``), or None before any friction update on cool facings
        self.gain_ref: float | None = None
        #: the friction has changed since the gain was referenced by more than its accuracy (applied), the
        #: ratio of that change to the accuracy, and the counts of consecutive updates above it and, while
        #: applied, below ``evidence_release`` of it
        self.mu_evidence, self.mu_evidence_ratio, self._mu_over, self._mu_under = False, 0.0, 0, 0
        #: the torque the filter expects the engine control unit to report at the prior's position for
        #: :data:`FRICTION_TORQUE_NM`, over that torque (gain, offset and friction together), as referenced on
        #: cool facings (None before), and the position cache behind it
        self.ecu_ratio_ref: float | None = None
        self._ecu_cache: dict = {}
        #: the friction scale's sd when the gain was last referenced, 1
        self.gain_ref_sd = e.mu_deadband
        #: counts the changes of the estimate (state, covariance, evidence, references) made by
        #: :meth:`predict`, :meth:`correct`, :meth:`update_evidence` and :meth:`set_prior`: what is derived
        #: from the estimate alone is kept per revision (:attr:`mu_applied`'s parts, the production TCU's kiss
        #: point); code that writes :attr:`s` or :attr:`P` directly calls :meth:`changed`
        self.revision = 0
        self._mu_parts = (-1, 0.0, 0.0)

    def changed(self) -> None:
        """Mark the estimate changed (after writing :attr:`s` or :attr:`P` directly)."""
        self.revision += 1

    # --- estimates -----------------------------------------------------------------------------
    @property
    def theta_cs(self) -> float:
        """Estimated cushion-spring temperature, K."""
        return self.s.item(IX_CS)

    @property
    def theta_cm(self) -> float:
        """Estimated facing temperature (mean of both facings), K."""
        return 0.5 * (self.s.item(F1) + self.s.item(F2))

    @property
    def theta_cm_model(self) -> float:
        """The facing temperature the TCU's clutch model is evaluated at: :attr:`theta_cm` within the model's
        range ``[THETA_MIN_K, THETA_MAX_K]`` (an estimate beyond it, far past the facings' damage limit, must not
        stop the TCU), K."""
        return hold_theta_cm(self.theta_cm)

    def _model_temperatures(self, s: np.ndarray) -> tuple[float, float]:
        """The temperatures the characteristic is evaluated at for state ``s``: ``theta_cs`` within the
        table's range and the facings' mean within the model's (the stack's growth there), K."""
        return (min(max(s.item(IX_CS), self.table.theta_min_K), self.table.theta_max_K),
                hold_theta_cm(0.5 * (s.item(F1) + s.item(F2))))

    @property
    def dx_kiss(self) -> float:
        """Learned touch-point offset at the bearing, m."""
        return self.s.item(IX_DX)

    @property
    def mu_scale(self) -> float:
        """Learned friction relative to the nominal mu, 1."""
        return self.s.item(IX_MU)

    @property
    def torque_offset(self) -> float:
        """Learned offset of the engine control unit's torque estimate, N.m (not the clutch's: never applied)."""
        return self.s.item(IX_OFF)

    @property
    def loss_scale(self) -> float:
        """Learned scale of the network's heat-loss conductances (convection, engine block), 1."""
        return self.s.item(IX_LOSS)

    @property
    def heat_scale(self) -> float:
        """Learned scale of the slip heat that reaches the network, 1."""
        return self.s.item(IX_HEAT)

    def set_prior(self, dx_m: float, dx_sd_m: float, mu_scale: float = 1.0, loss_scale: float = 1.0,
                  heat_scale: float = 1.0) -> None:
        """Start from a stored or standstill-learned characteristic: it becomes the prior (and the state).

        ``dx_m`` touch-point offset (position sensor's frame) with its accuracy ``dx_sd_m`` (m; the
        state's sd and the evidence envelope's position term), the friction and thermal scales.
        The touch point's covariance with the rest is reset.
        """
        s, pm = self.s, self.P
        s[IX_DX], s[IX_MU] = dx_m, mu_scale
        s[IX_LOSS], s[IX_HEAT] = loss_scale, heat_scale
        pm[IX_DX, :] = pm[:, IX_DX] = 0.0
        pm[IX_DX, IX_DX] = dx_sd_m ** 2
        self.dx_prior, self.mu_prior, self.x_accuracy = dx_m, mu_scale, dx_sd_m
        self.evidence, self.evidence_ratio, self._over = False, 0.0, 0
        self.mu_evidence, self.mu_evidence_ratio, self._mu_over, self._mu_under = False, 0.0, 0, 0
        self.revision += 1

    @property
    def dx_used(self) -> float:
        """The touch-point offset the TCU applies: ``dx_kiss`` on evidence (module docstring), else the
        prior's, m."""
        return self.s.item(IX_DX) if self.evidence else self.dx_prior

    @property
    def mu_used(self) -> float:
        """The friction scale the TCU applies: without evidence the prior's (1 or stored); with touch-point
        evidence ``mu_scale`` over the referenced gain (before a reference: outside a dead band of
        ``mu_deadband`` around 1); with friction evidence alone the prior's times :meth:`friction_ratio`.

        ``mu_scale`` is learned against the engine control unit's torque
        estimate, so it carries that estimate's gain error; a deviation within
        the estimate's stated accuracy is not attributed to the clutch.
        """
        band = self.e.mu_deadband
        if self.evidence and self.gain_ref is not None:
            return self.s.item(IX_MU) / self.gain_ref
        if self.mu_evidence:                    # with the prior's touch point: the engine control unit's torque
            return self.mu_prior * self.friction_ratio()    # the filter expects, over its cool reference
        d = (self.s[IX_MU] if self.evidence else self.mu_prior) - 1.0
        return 1.0 + (d - band if d > band else (d + band if d < -band else 0.0))

    def ecu_ratio(self, s: np.ndarray | None = None) -> float:
        """The torque the filter (state ``s``, default the estimate) expects the engine control unit to
        report at the prior's position for :data:`FRICTION_TORQUE_NM` (nominal friction there), over that
        torque, at the reference slip: ``(mu_scale T(x + dx_prior - dx_kiss) + b) / T(x)``, 1.

        The gain, the offset and the friction enter it together, whatever share of them the filter's
        nearly collinear touch point, friction scale and offset carry; NaN beyond the closed capacity.
        """
        s = self.s if s is None else s
        th, theta_cm = self._model_temperatures(s)
        key = (round(th, 0), round(theta_cm, 0), round(s.item(IX_DX) - self.dx_prior, 7))
        hit = self._ecu_cache.get(key)
        if hit is None:
            try:
                x = self.clutch.x_for_torque(FRICTION_TORQUE_NM, th, theta_cm)
                t0 = self.clutch.torque(x, th, theta_cm)
                t1 = self.clutch.torque(x + self.dx_prior - s.item(IX_DX), th, theta_cm)
                hit = (t0, t1) if t0 >= 0.9 * FRICTION_TORQUE_NM else (math.nan, math.nan)
            except ValueError:
                hit = (math.nan, math.nan)
            if len(self._ecu_cache) > 4096:
                self._ecu_cache.clear()
            self._ecu_cache[key] = hit
        t0, t1 = hit
        c = self.cal_ref
        return (c * s.item(IX_MU) * t1 + s.item(IX_OFF)) / (c * t0)

    def friction_ratio(self) -> float:
        """The friction relative to the one on cool facings: :meth:`ecu_ratio` over its cool reference
        (the gain and the offset of the engine control unit's torque cancel), 1 (1 before a reference)."""
        r = self.ecu_ratio()
        if self.ecu_ratio_ref is None or not math.isfinite(r):
            return self._last_friction_ratio
        self._last_friction_ratio = r / self.ecu_ratio_ref
        return self._last_friction_ratio

    _last_friction_ratio = 1.0

    @property
    def mu_applied(self) -> float:
        """The friction relative to the nominal mu the TCU applies at the measured slip: the calibration's
        (:attr:`cal`) times :attr:`mu_used` plus the slip-speed slope's term (:meth:`mu_factor`), 1."""
        rev, mu, slope = self._mu_parts             # mu_used and slope_used depend on the estimate alone
        if rev != self.revision:
            mu, slope = self.mu_used, self.slope_used
            self._mu_parts = (self.revision, mu, slope)
        return self.cal * (mu + slope * (abs(self.slip) - SLIP_REF_RAD_S) / SLIP_UNIT_RAD_S)

    @property
    def slope_used(self) -> float:
        """The slip-speed slope of the friction the TCU applies (per ``SLIP_UNIT_RAD_S``): the learned slope
        beyond ``mu_slope_evidence_sd`` of its standard deviation (0 while the filter cannot tell it from
        none: the nominal mu is constant), 1."""
        d = self.s.item(IX_SLOPE)
        band = self.e.mu_slope_evidence_sd * math.sqrt(max(self.P.item(IX_SLOPE, IX_SLOPE), 0.0))
        return d - band if d > band else (d + band if d < -band else 0.0)

    def model_torque(self, x_m: float, s: np.ndarray | None = None, mu: float | None = None,
                     factor: float | None = None) -> float:
        """The TCU's torque at bearing position ``x_m`` (m) with state ``s`` (default: the estimate), N.m.

        ``mu`` replaces the state's friction scale (e.g. :attr:`mu_used`); ``factor`` the whole friction
        relative to the nominal mu (:meth:`mu_factor`).
        """
        s = self.s if s is None else s
        th, theta_cm = self._model_temperatures(s)
        f = self.mu_factor(s, mu) if factor is None else factor
        return f * self.clutch.torque(x_m - s.item(IX_DX), th, theta_cm)

    def mu_factor(self, s: np.ndarray | None = None, mu: float | None = None) -> float:
        """Friction relative to the nominal mu at the measured slip :attr:`slip`: the calibration's there
        (:attr:`cal`) times the scale (``mu`` if given) plus the slip-speed slope times
        ``(|slip| - SLIP_REF_RAD_S) / SLIP_UNIT_RAD_S``, 1."""
        s = self.s if s is None else s
        return self.cal * ((s.item(IX_MU) if mu is None else mu)
                           + s.item(IX_SLOPE) * (abs(self.slip) - SLIP_REF_RAD_S) / SLIP_UNIT_RAD_S)

    def set_slip(self, w_slip_rad_s: float) -> None:
        """The measured slip speed (rad/s) at which the characteristic is evaluated from now on."""
        self.slip = abs(w_slip_rad_s)
        self.cal = float(self.calibration(self.slip))

    def used_torque(self, x_m: float, mu: float | None = None) -> float:
        """The torque the TCU applies at the measured bearing position ``x_m`` (m): :attr:`dx_used` and
        :attr:`mu_applied` (``mu`` replaces the latter: the whole friction relative to the nominal mu), N.m."""
        # model_torque on the estimate with dx_used for dx_kiss (without a copy of the state)
        th, theta_cm = self._model_temperatures(self.s)
        f = self.mu_applied if mu is None else mu
        return f * self.clutch.torque(x_m - self.dx_used, th, theta_cm)

    def update_evidence(self) -> bool:
        """Compare the learned characteristic with the nominal one; set and return :attr:`evidence`.

        At each nominal torque ``T`` of :data:`EVIDENCE_TORQUES_NM` the nominal
        position ``x`` (the estimated temperatures) and its slope ``dT/dx`` give
        the bias envelope ``g T + o + (dT/dx) x_acc`` (``g`` = ``mu_deadband``,
        ``o`` = ``torque_offset_accuracy_Nm``, ``x_acc`` = ``position_accuracy_m``);
        the learned characteristic's difference there, over the envelope, is the
        ratio. Evidence once the largest ratio exceeds ``evidence_threshold`` in
        ``evidence_confirm`` consecutive calls, kept until it falls below ``evidence_release``.
        """
        e, s = self.e, self.s
        th, theta_cm = self._model_temperatures(s)
        key = (round(th, 0), round(theta_cm, 0))
        pts = self._ev_cache.get(key)
        if pts is None:
            pts = []
            for t in EVIDENCE_TORQUES_NM:
                try:
                    x = self.clutch.x_for_torque(t, th, theta_cm)
                except ValueError:
                    continue
                t0 = self.clutch.torque(x, th, theta_cm)
                if t0 < 0.9 * t:                    # beyond the closed capacity
                    continue
                slope = (self.clutch.torque(x + 10e-6, th, theta_cm) - t0) / 10e-6
                pts.append((x, t0, e.mu_deadband * t0 + e.torque_offset_accuracy_Nm, slope))
            if len(self._ev_cache) > 4096:
                self._ev_cache.clear()
            self._ev_cache[key] = pts
        dx0, mu0 = self.dx_prior, self.mu_prior
        # before the gain is referenced the touch point and the friction are judged together (nearly collinear,
        # module docstring); after, the friction has its own evidence (below) and this is the touch point's
        mu, dx = (s.item(IX_MU) if self.gain_ref is None else mu0), s.item(IX_DX)
        ratio = 0.0
        for x, t0, env0, slope in pts:                  # the prior's position for each nominal torque
            env = mu0 * (env0 + slope * self.x_accuracy)
            d = abs(mu * self.clutch.torque(x + dx0 - dx, th, theta_cm) - mu0 * t0)
            ratio = max(ratio, d / env if env > 0.0 else math.inf)
        self.evidence_ratio = ratio
        self._over = self._over + 1 if ratio > e.evidence_threshold else 0
        self.evidence = self._over >= e.evidence_confirm or (self.evidence and ratio > e.evidence_release)
        if self.ecu_ratio_ref is not None:              # a change of the friction since the gain was referenced
            g_res = min(e.mu_deadband, 2.0 * self.gain_ref_sd)
            mu = mu0 * self.friction_ratio()
            r = abs(mu - mu0) / (mu0 * g_res) if g_res > 0.0 else math.inf
            self.mu_evidence_ratio = r
            self._mu_over = self._mu_over + 1 if r > e.evidence_threshold else 0
            # released as it was applied: in evidence_confirm consecutive updates below the release (a transient
            # of the filter within a launch is no evidence either way)
            self._mu_under = self._mu_under + 1 if self.mu_evidence and r <= e.evidence_release else 0
            self.mu_evidence = self._mu_over >= e.evidence_confirm or (self.mu_evidence
                                                                       and self._mu_under < e.evidence_confirm)
        self.revision += 1
        return self.evidence

    # --- prediction ----------------------------------------------------------------------------
    def _parts(self, w_engine: float, w_disc: float, clamped: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A_link, a_sink, b_sink)`` of the temperatures: ``dtheta/dt = A_link theta + k_loss
        (a_sink theta + b_sink) + k_heat q``; cached per ``SPEED_BAND`` (rad/s) band of the speeds.

        ``A_link`` (1/s): conduction between the nodes and the cushion-spring ODE (its ``H`` to the
        ambient included: the spring's U, H, C are the clutch model's and are not scaled);
        ``a_sink`` (1/s, the diagonal) and ``b_sink`` (K/s): the network's losses to the air and the
        engine block at ``k_loss = 1``.
        """
        key = (clamped, round(w_engine / SPEED_BAND), round(w_disc / SPEED_BAND))
        hit = self._cache.get(key)
        if hit is None:
            links, sink_g, sink_t = self.model.conductances(key[1] * SPEED_BAND, key[2] * SPEED_BAND, clamped)
            c = np.array(self.model.caps)
            a = np.zeros((N_T, N_T))
            for i, gl in enumerate(links):
                a[i, i + 1], a[i + 1, i] = gl / c[i], gl / c[i + 1]
                a[i, i] -= gl / c[i]
                a[i + 1, i + 1] -= gl / c[i + 1]
            n = self.net
            cs = n.spring_C_J_per_K
            a[IX_CS, F1] = a[IX_CS, F2] = 0.5 * n.spring_U_W_per_K / cs
            a[IX_CS, IX_CS] = -(n.spring_U_W_per_K + n.spring_H_W_per_K) / cs
            a_sink = np.zeros(N_T)
            b_sink = np.zeros(N_T)
            a_sink[:N_NODES] = -np.array(sink_g) / c
            b_sink[:N_NODES] = np.array(sink_g) * np.array(sink_t) / c
            b_sink_cs = n.spring_H_W_per_K * self.theta_a / cs
            hit = self._cache[key] = (a, a_sink, b_sink, b_sink_cs)
        return hit

    def accumulate(self, dt: float, p_slip_W: float) -> None:
        """Add one TCU period ``dt`` (s) of slip power (W) to the heat of the next prediction."""
        self.energy_J += p_slip_W * dt
        self.t_acc += dt

    def due(self) -> bool:
        """True once a full EKF period has accumulated."""
        return self.t_acc >= self.e.period_s - 1e-12

    def _discrete(self, w_engine: float, w_disc: float, clamped: bool, dt: float,
                  k_loss: float, k_heat: float = 1.0) -> tuple[np.ndarray, np.ndarray, tuple]:
        """``(Phi, Psi, parts)``: ``exp(A dt)`` and ``int_0^dt exp(A s) ds`` of the temperatures with
        the scales held: the network's rows ``k_heat (A_link + k_loss a_sink)`` (the heat scale is the
        network's inverse heat capacity: it scales conduction and losses as it scales the heat), the cushion
        spring's row unscaled. The exponential of ``[[A, I], [0, 0]] dt`` by scaling and squaring
        (Taylor series to order 8 of the matrix scaled to a norm below 1/4, then squared back; relative
        error below 1e-10, a test compares it with scipy's ``expm``; the network's surface layers have time
        constants near the EKF period, so a short series of ``A dt`` alone would not do). Cached per speed
        band and period, recomputed when a scale has changed (only measurement updates change them).
        """
        key = (clamped, round(w_engine / SPEED_BAND), round(w_disc / SPEED_BAND), round(dt * 1e4))
        hit = self._dcache.get(key)
        if hit is None or hit[0] != (k_loss, k_heat):
            parts = self._parts(w_engine, w_disc, clamped)
            a = parts[0].copy()
            a[np.arange(N_T), np.arange(N_T)] += k_loss * parts[1]
            a[:N_NODES] *= k_heat
            phi, psi = _exp_and_integral(a, dt)
            hit = self._dcache[key] = ((k_loss, k_heat), phi, psi, parts)
        return hit[1], hit[2], hit[3]

    def predict(self, w_engine: float, w_disc: float, clamped: bool) -> None:
        """Advance the accumulated time with its mean slip power (the speeds and clamp state held).

        The augmented system is bilinear (a scale times a temperature); with
        the scales held over the period the temperatures advance exactly,
        ``theta+ = Phi theta + Psi k_heat (k_loss b_sink + q)`` (``Phi``, ``Psi``
        of the scaled matrix, :meth:`_discrete`), and the transition of the
        covariance is the linearisation at the estimate: the scales' rows are
        zero, so ``exp(J dt)`` has ``Phi`` in its temperature block and ``Psi``
        times the scales' Jacobian columns (``k_heat (a_sink theta + b_sink)``
        and the network's heat flow per J/K, ``A_link theta + k_loss (a_sink
        theta + b_sink) + q``) in their columns.
        """
        dt = self.t_acc
        if dt <= 0.0:
            return
        p_mean = self.energy_J / dt
        s = self.s
        k_loss, k_heat = s.item(IX_LOSS), s.item(IX_HEAT)
        phi, psi, (a_link, a_sink, b_sink, b_cs) = self._discrete(w_engine, w_disc, clamped, dt, k_loss, k_heat)
        th = s[:N_T]
        loss = a_sink * th + b_sink                 # the losses per J/K at k_loss = 1 (0 in the spring's row)
        if p_mean != 0.0:                           # the slip heat per J/K (without it, no zeros are added)
            q = np.zeros(N_T)
            q[:N_NODES] = np.array(self.model.heat_inputs(p_mean)) / self._caps
            rate = a_link @ th + k_loss * loss + q  # the network's heat flow per J/K at k_heat = 1
            b = k_heat * (k_loss * b_sink + q)
        else:
            q = None
            rate = a_link @ th + k_loss * loss
            b = k_heat * (k_loss * b_sink)
        rate[IX_CS] = 0.0                           # the spring's ODE is the clutch model's: not scaled
        b[IX_CS] += b_cs
        s_new = s.copy()
        s_new[:N_T] = phi @ th + psi @ b
        f = self._eye.copy()
        f[:N_T, :N_T] = phi
        f[:N_T, IX_LOSS] = psi @ (k_heat * loss)
        f[:N_T, IX_HEAT] = psi @ rate
        ref = self.e.mu_reference_max_degC + 273.15      # the friction may change as the facings heat above it
        cm_old, cm_new = 0.5 * (s.item(F1) + s.item(F2)), 0.5 * (s_new.item(F1) + s_new.item(F2))
        d_cm = max(cm_new, ref) - max(cm_old, ref)
        if self.e.mu_fade_sd > 0.0 and d_cm != 0.0:      # the friction follows the facings: mu += k d(theta_cm)
            k_fade = s.item(IX_FADE)
            s_new[IX_MU] += k_fade * d_cm / FADE_UNIT_K
            f[IX_MU, IX_FADE] = d_cm / FADE_UNIT_K
            dnew = 0.5 * (phi[F1] + phi[F2]) if cm_new > ref else np.zeros(N_T)
            dold = np.zeros(N_T)
            if cm_old > ref:
                dold[F1] = dold[F2] = 0.5
            f[IX_MU, :N_T] = k_fade * (dnew - dold) / FADE_UNIT_K
        self.s = s_new
        qn = self.q_rw * dt
        if q is not None:
            qn[:N_T] += (self.e.heat_share_sd * k_heat * q * dt) ** 2
        qn[IX_MU] += self.e.mu_walk_per_K * max(d_cm, 0.0)
        if self.e.mu_fade_sd > 0.0:
            qn[IX_FADE] += self.e.mu_fade_walk_per_K * max(d_cm, 0.0)
        p_new = f @ self.P @ f.T
        p_new.ravel()[::N_STATE + 1] += qn       # + diag(qn) (the diagonal as a strided view: the same sums)
        self.P = p_new
        self.energy_J = self.t_acc = 0.0
        self.revision += 1

    # --- measurement ---------------------------------------------------------------------------
    def correct(self, torque_meas_Nm: float, x_meas_m: float, w_slip_rad_s: float, launching: bool,
                torque_sd_Nm: float | None = None) -> bool:
        """Measurement update with a clutch torque (N.m) at the measured position (m); True if accepted.

        Applies the excitation conditions of the module docstring; ``torque_sd_Nm``
        overrides the measurement noise (another source of the torque).
        """
        e = self.e
        if not launching or abs(w_slip_rad_s) < e.slip_min_rad_s:
            return False
        self.set_slip(w_slip_rad_s)
        h0 = self.model_torque(x_meas_m)
        off = self.s.item(IX_OFF)
        mask = np.zeros(N_STATE, dtype=bool)
        if e.touch_torque_min_Nm <= h0 <= e.touch_torque_max_Nm:
            mask[IX_DX] = True
        if h0 >= e.mu_torque_min_Nm:
            mask[IX_MU] = True
            mask[IX_SLOPE] = e.mu_slope_sd > 0.0
            mask[IX_FADE] = e.mu_fade_sd > 0.0
        if not mask.any():
            return False
        mask[IX_OFF] = True
        if e.temperature_update and h0 >= e.theta_torque_min_Nm:
            mask[:N_T] = True
            mask[IX_HEAT] = e.heat_scale_sd > 0.0
            mask[IX_LOSS] = e.loss_scale_sd > 0.0 and self.theta_cm - self.theta_a >= e.loss_excitation_K
        hrow = np.zeros(N_STATE)
        for i, d in ((IX_CS, 1.0), (F1, 1.0), (IX_DX, 1e-6)):
            sp = self.s.copy()
            sp[i] += d
            hrow[i] = (self.model_torque(x_meas_m, sp) - h0) / d
        hrow[F2] = hrow[F1]                   # the stack grows with the facings' mean: both enter alike
        t_cal = h0 * self.cal / max(self.mu_factor(), 1e-6)       # the calibration's torque (mu_scale 1, no slope)
        hrow[IX_MU] = t_cal
        hrow[IX_SLOPE] = t_cal * (self.slip - SLIP_REF_RAD_S) / SLIP_UNIT_RAD_S
        hrow[IX_OFF] = 1.0
        r = (e.torque_sd_Nm if torque_sd_Nm is None else torque_sd_Nm) ** 2
        s_inn = float(hrow @ self.P @ hrow) + r
        nu = torque_meas_Nm - h0 - off
        if nu * nu > e.gate_sd ** 2 * s_inn:
            self.rejected += 1
            return False
        k = self.P @ hrow / s_inn
        k[~mask] = 0.0
        self.s = self.s + k * nu
        self.s[IX_LOSS:IX_HEAT + 1] = np.clip(self.s[IX_LOSS:IX_HEAT + 1], e.scale_min, e.scale_max)
        ikh = np.eye(N_STATE) - np.outer(k, hrow)
        self.P = ikh @ self.P @ ikh.T + r * np.outer(k, k)
        self.accepted += 1
        if mask[IX_MU] and self.theta_cm < e.mu_reference_max_degC + 273.15:
            band = e.mu_deadband
            self.gain_ref = min(max(self.mu_scale, 1.0 - band), 1.0 + band)
            self.gain_ref_sd = math.sqrt(max(self.P.item(IX_MU, IX_MU), 0.0))
            r_ref = self.ecu_ratio()
            if math.isfinite(r_ref):
                self.ecu_ratio_ref = r_ref
        if mask[IX_DX] or mask[IX_MU]:
            self.update_evidence()
        self.revision += 1
        return True
