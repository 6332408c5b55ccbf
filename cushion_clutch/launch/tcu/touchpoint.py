"""Touch-point learning at standstill: neutral, engine idling, close slowly until the input shaft turns.

What production AMT and DCT controllers do at key-on when they have no stored
touch point (a new or reset TCU, a changed clutch) or at an interval: with the
gearbox in neutral the input shaft (the clutch disc and the gearbox input) is
free but for the gearbox's drag, so the first clutch torque above the drag
spins it up, and its Hall sensor sees it.

**Routine** (``[standstill]``, TCU period ``tcu.period_s``):

1. *Excitation conditions*, checked before it starts: car standing (wheel
   speed 0), gearbox in neutral, engine idling (the idle governor holds it;
   the few N.m the routine takes are within its reserve), input shaft at rest
   (reads 0), the clutch temperature estimate within the TCU's tables. The
   routine reports what it found; it does not start otherwise.
2. Bearing to the believed kiss point less ``start_margin_m`` (the clutch open),
   hold ``settle_s``.
3. Close at ``ramp_rate_m_per_s``. The shaft spins up under
   ``J_disc dw/dt = T_c - T_drag``; the Hall sensor reads 0 below one tooth per
   ``timeout`` (1.96 rad/s with 32 teeth and 0.1 s), then the edge-timed speed.
   Once it reads ``detect_speed_rad_s`` the routine records, every period, the
   measured speed and bearing position until the shaft reaches
   ``fit_speed_rad_s`` (below idle: the clutch still slips), then opens.
4. *Coast-down*: with the clutch open the shaft slows down on the gearbox's
   drag alone; ``-J dw/dt = d0 + d1 w`` fitted to its readings gives the drag
   (the TCU does not assume it: oil temperature changes it several-fold).
5. *Estimate*: the shaft's acceleration by a centred difference over
   ``2 * HALF_WINDOW`` periods gives the clutch torque, ``T = J a + d0 + d1 w``
   (the TCU's ``disc_inertia_kg_m2``: its error scales ``J a`` and the drag
   alike); each sample with
   ``T >= min_torque_Nm`` gives a touch-point offset
   ``dx = x_meas - x_nominal(T)`` (the nominal characteristic at the TCU's
   temperature estimate, inverted); the median is the result. The offset is in
   the position sensor's frame, so the sensor's own offset is learned with it.

**Accuracy** (what limits it): near the kiss point the characteristic is flat
(about 7 N.m/mm at 2-6 N.m on the default spring), so a torque error of 0.7 N.m
is 0.1 mm: with an assumed instead of a measured drag, a drag 0.5 N.m off moved
the result by 70-100 um (measured), hence the coast-down; then the disc
inertia (a 5 % error of the clutch torque), the position
sensor's noise and quantisation (5 um, averaged by the median) and the Hall
sensor's timing at low speed. The routine's result carries its error against
the plant's true kiss point (the plant FMU's ``x_kiss``); tests check it.

The plant here is the clutch FMU (a second instance, at the soaked
temperature: the routine's slip energy, reported, is below 1 kJ), the idle
engine held at idle speed, the free input shaft with the scenario's disc
inertia and the gearbox drag ``plant_drag_Nm + plant_drag_Nm_per_rad_s w``,
the actuator's first-order lag, and the TCU's own sensors (a fresh copy of
its sensor set, same offsets).
"""
from __future__ import annotations

import dataclasses
import math
import statistics
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from ...model import ClutchParameters, SpringTable, kiss_point, x_to_for_torque
from ..plant.fmu_client import ClutchFmu
from ..plant.sensors import ProductionSensors, TcuSensors
from ..scenario.tcu_params import Standstill

#: periods on either side of a sample for the shaft's acceleration
HALF_WINDOW = 3
#: after opening, the coast-down is sampled from this delay on (actuator lag, clutch fully open), s
COAST_DELAY_S = 0.15


@dataclass(frozen=True)
class StandstillResult:
    """Outcome of one standstill learning (SI)."""

    ok: bool
    reason: str
    """"" when learned, else why not"""
    dx_kiss_m: float
    """learned touch-point offset, position sensor's frame, m (NaN if not learned)"""
    kiss_error_m: float
    """believed minus the plant's true kiss point at the bearing after learning, m"""
    kiss_error_before_m: float
    """the same before learning (the prior), m"""
    samples: int
    torque_range_Nm: tuple[float, float]
    duration_s: float
    slip_energy_J: float
    spread_m: float
    """half the interquartile range of the samples' offsets, m"""
    drag_Nm: float = math.nan
    drag_Nm_per_rad_s: float = math.nan
    """the gearbox drag the routine measured in the coast-down, ``d0 + d1 w``"""


def learn_touch_point(fmu: Path, start: dict[str, float], st: Standstill, sens: ProductionSensors,
                      table: SpringTable, p: ClutchParameters, theta_cs: float, theta_cm: float,
                      dx_prior_m: float, j_disc_kg_m2: float, w_idle_rad_s: float, period_s: float,
                      actuator_time_constant_s: float, step_s: float = 1e-3,
                      mu_calibration: Callable[[float], float] | None = None) -> StandstillResult:
    """Run the standstill routine on the plant FMU and return the learned touch-point offset.

    Parameters
    ----------
    fmu, start
        The plant clutch FMU and its start values (as the launch run uses them).
    st, sens
        The routine's settings and the TCU's sensors.
    table, p
        The TCU's nominal characteristic.
    theta_cs, theta_cm
        The TCU's temperature estimates (the plant is soaked at the same start), K.
    dx_prior_m
        The touch-point offset the TCU believes before (its start position), m.
    j_disc_kg_m2, w_idle_rad_s
        The plant's disc-side inertia in neutral (kg m2) and the engine's idle speed (rad/s).
    period_s, actuator_time_constant_s, step_s
        TCU period, actuator lag and simulation step, s.
    mu_calibration
        The calibration's friction at a slip speed (rad/s) relative to the nominal mu
        (:meth:`~.scenario.Tcu.mu_calibration`); each sample is inverted at its measured slip
        (idle speed less the shaft's); default: mu constant.
    """
    th = min(max(theta_cs, table.theta_min_K), table.theta_max_K)
    nominal_kiss = kiss_point(th, table, p, theta_cm)
    s = TcuSensors(dataclasses.replace(sens, seed=sens.seed + 1))
    clutch = ClutchFmu(fmu, start)
    act = math.exp(-step_s / actuator_time_constant_s) if actuator_time_constant_s > 0 else 0.0
    every = max(1, int(round(period_s / step_s)))
    x_start = nominal_kiss + dx_prior_m - st.start_margin_m        # in the sensor's frame
    x_act = x_cmd = 0.0
    w = 0.0
    t = 0.0
    t_ramp = None
    energy = 0.0
    rec: list[tuple[float, float, float]] = []            # (t, w measured, x measured)
    x_kiss_true = math.nan
    reason = ""
    coast: list[tuple[float, float]] = []                # (t, w measured) after opening
    t_open = None
    try:
        # excitation conditions: the engine idles, the shaft stands (the run starts so)
        k = 0
        while True:
            if k % every == 0:
                w_meas = s.shaft.read(t)
                x_meas = s.position(x_act)
                if t_ramp is None:
                    x_cmd = x_start
                    if t >= st.settle_s:
                        if w_meas != 0.0:
                            reason = "input shaft turning before the ramp (clutch not open)"
                            break
                        t_ramp = t
                elif t_open is None:
                    x_cmd = x_start + st.ramp_rate_m_per_s * (t - t_ramp)
                    if w_meas >= st.detect_speed_rad_s:
                        rec.append((t, w_meas, x_meas))
                    if w_meas >= st.fit_speed_rad_s:
                        t_open, x_cmd = t, 0.0
                    elif t - t_ramp > st.timeout_s:
                        reason = f"input shaft did not reach {st.fit_speed_rad_s} rad/s within {st.timeout_s} s"
                        break
                else:                                   # open: the shaft coasts down on the drag alone
                    if t - t_open >= COAST_DELAY_S:
                        if w_meas < st.detect_speed_rad_s or t - t_open > st.timeout_s:
                            break
                        coast.append((t, w_meas))
                # the servo drives the measured position to the command
                x_target = x_cmd - sens.position_offset_m
            x_act = x_target + (x_act - x_target) * act
            slip = w_idle_rad_s - w
            t_c, _, x_kiss_true = clutch.step(t, step_s, x_act, theta_cm, slip)
            drag = st.plant_drag_Nm + st.plant_drag_Nm_per_rad_s * w
            net = t_c - drag if w > 0.0 or t_c > drag else 0.0
            w = max(0.0, w + net / j_disc_kg_m2 * step_s)
            energy += t_c * slip * step_s
            s.shaft.advance(t + step_s, w, step_s)
            t += step_s
            k += 1
    finally:
        clutch.close()
    believed_before = nominal_kiss + dx_prior_m - sens.position_offset_m
    before = believed_before - x_kiss_true
    if reason or len(rec) < 2 * HALF_WINDOW + 1:
        return StandstillResult(False, reason or "too few samples", math.nan, before, before, len(rec),
                                (math.nan, math.nan), t, energy, math.nan)
    drag = _coast_drag(coast, st.disc_inertia_kg_m2)
    if drag is None:
        return StandstillResult(False, "too few coast-down samples for the drag", math.nan, before, before,
                                len(rec), (math.nan, math.nan), t, energy, math.nan)
    dxs, torques = [], []
    for i in range(HALF_WINDOW, len(rec) - HALF_WINDOW):
        t0, w0, _ = rec[i - HALF_WINDOW]
        t1, w1, _ = rec[i + HALF_WINDOW]
        torque = st.disc_inertia_kg_m2 * (w1 - w0) / (t1 - t0) + drag[0] + drag[1] * rec[i][1]
        if torque < st.min_torque_Nm:
            continue
        x_mean = sum(r[2] for r in rec[i - HALF_WINDOW:i + HALF_WINDOW + 1]) / (2 * HALF_WINDOW + 1)
        cal = mu_calibration(w_idle_rad_s - rec[i][1]) if mu_calibration is not None else 1.0
        dxs.append(x_mean - x_to_for_torque(torque / cal, th, table, p, theta_cm=theta_cm))
        torques.append(torque)
    if not dxs:
        return StandstillResult(False, f"no sample reached {st.min_torque_Nm} N.m", math.nan, before, before,
                                len(rec), (math.nan, math.nan), t, energy, math.nan)
    dx = statistics.median(dxs)
    q = statistics.quantiles(dxs, n=4) if len(dxs) >= 4 else [min(dxs), 0.0, max(dxs)]
    after = nominal_kiss + dx - sens.position_offset_m - x_kiss_true
    return StandstillResult(True, "", dx, after, before, len(dxs), (min(torques), max(torques)), t, energy,
                            0.5 * (q[2] - q[0]), drag[0], drag[1])


def _coast_drag(coast: list[tuple[float, float]], j: float) -> tuple[float, float] | None:
    """Drag ``(d0 N.m, d1 N.m s/rad)`` from the coast-down, ``-J dw/dt = d0 + d1 w`` (least squares on
    centred differences over ``2 HALF_WINDOW`` periods); None with too few samples."""
    pts = []
    for i in range(HALF_WINDOW, len(coast) - HALF_WINDOW):
        (t0, w0), (t1, w1) = coast[i - HALF_WINDOW], coast[i + HALF_WINDOW]
        pts.append((coast[i][1], -j * (w1 - w0) / (t1 - t0)))
    if len(pts) < 5:
        return None
    n = len(pts)
    mw = sum(p[0] for p in pts) / n
    md = sum(p[1] for p in pts) / n
    sww = sum((p[0] - mw) ** 2 for p in pts)
    d1 = sum((p[0] - mw) * (p[1] - md) for p in pts) / sww if sww > 0.0 else 0.0
    d1 = max(d1, 0.0)                       # a drag that falls with speed is noise here
    return md - d1 * mw, d1
