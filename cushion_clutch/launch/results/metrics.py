"""Per-launch metrics of a TCU and their summary over groups of launches.

Each metric measures one cause (SI units unless a name says otherwise):

``characteristic_error_rms_Nm``, ``characteristic_error_max_Nm``
    The torque the TCU's model believes at the *actual* bearing position
    minus the true (plant FMU) torque there, sampled every TCU period while
    the clutch is pre-filled or slipping in the launch (before lock-up).
    Only what the TCU believes about the clutch enters (temperature, kiss
    point, friction): not the actuator, not the controller.
``tracking_error_rms_Nm``, ``tracking_error_max_Nm``
    Delivered (clutch capacity while slipping) minus demanded torque, every
    step while launching with a demand > 0, before lock-up: the characteristic
    error plus what the actuator lag and its compensation leave.
``creep_error_Nm``
    Mean signed ``delivered - demanded`` while the demand is at most
    :data:`CREEP_NM` (negative: the car creeps with less torque than asked).
``lockup_accel_step_m_s2``
    Vehicle acceleration averaged over the :data:`LOCKUP_WINDOW_S` after
    lock-up minus the average over the window before (signed). The window is
    a quarter of a 5 Hz shuffle period: short enough not to count the
    planned fall of the acceleration during the sync as a step, long enough
    to average out the disc-against-vehicle mode (13 Hz) and step noise.
``shuffle_amplitude_m_s2``
    Peak-to-peak vehicle acceleration in the :data:`SHUFFLE_WINDOW_S` after
    lock-up (driveline shuffle; it includes any acceleration trend there).

``protection_level``
    The level of the TCU's thermal protection the launch ran at, decided at its start (0 ok,
    1 warn, 2 limit, 3 inhibited: no launch; :mod:`.protection`).

``launch_possible``, ``stranded``
    Whether the vehicle can make the launch at all (:func:`launch_possible`: the engine's largest
    torque at the launch's pedal, over its speed range, exceeds the torque that holds the car on the
    grade, both at the disc, and at best it gets the car to a speed where the engine holds it within the
    driver's pedal time), and a *stranded* launch: possible, not inhibited by the protection
    (``protection_level`` below 3), and no lock-up while the driver pressed the pedal. A launch that
    is not possible and does not lock up is not counted as stranded.

``peak_theta_cm_degC``, ``peak_theta_cs_degC``, ``beyond_tables_s``, ``above_damage_s``
    Where the plant model leaves what it knows (issue 28; :func:`temperature_metrics`, from the
    recorded time series): the peak facing and cushion-spring temperatures, the time with
    ``theta_cs`` outside the cushion table's temperatures (the model clamps the table there) and
    the time with the facings above ``facing_damage_temperature_K`` (validity 2).

Also: cushion-spring temperature at the start and the TCU's error in it,
kiss-point error (believed minus true, at the start), engagement time, slip
energy, peak jerk (acceleration low-passed at 20 ms), engine stall.
"""
from __future__ import annotations

import math

from ...model import KELVIN

METRIC_COLUMNS = ("tcu", "launch", "demand_level", "theta_cs_start_degC", "characteristic_error_rms_Nm",
                  "characteristic_error_max_Nm", "tracking_error_rms_Nm", "tracking_error_max_Nm",
                  "creep_error_Nm", "lockup_accel_step_m_s2", "shuffle_amplitude_m_s2", "kiss_point_error_mm",
                  "engagement_time_s", "slip_energy_kJ", "peak_jerk_m_s3", "engine_stall", "theta_cs_error_K",
                  "hot", "phase", "protection_level", "launch_possible", "stranded", "peak_theta_cm_degC", "peak_theta_cs_degC",
                  "beyond_tables_s", "above_damage_s")
#: the temperature columns added by temperature_metrics
TEMPERATURE_COLUMNS = METRIC_COLUMNS[-4:]
#: demand up to which the creep error is taken, N.m
CREEP_NM = 30.0
#: windows before and after lock-up for the acceleration step, s
LOCKUP_WINDOW_S = 0.05
#: window after lock-up for the shuffle amplitude, s
SHUFFLE_WINDOW_S = 1.0
JERK_FILTER_S = 0.02


def _rms_max(n: int, sq: float, mx: float) -> tuple[float, float]:
    return (math.sqrt(sq / n), mx) if n else (math.nan, math.nan)


class LaunchRecord:
    """Collects one launch's metrics.

    :meth:`step` is called every step while the clutch is engaged,
    :meth:`characteristic` at every TCU cycle before lock-up.

    Parameters
    ----------
    launch : int
        1-based launch number.
    cool : bool
        A cool-down launch.
    h : float
        Step, s.
    level : str
        The driver's demand level of this launch.
    """

    __slots__ = ("launch", "cool", "lock_time", "stall", "slip_J", "n_err", "sq_err", "max_err", "jerk",
                 "n_ch", "sq_ch", "max_ch", "n_creep", "sum_creep", "kiss_err", "theta_cs", "theta_err",
                 "a_filt", "alpha", "h", "started", "acc", "t_first", "window", "level", "protection", "possible")

    def __init__(self, launch: int, cool: bool, h: float, level: str = "", possible: bool = True):
        self.launch, self.cool, self.h, self.level, self.possible = launch, cool, h, level, possible
        self.window = LOCKUP_WINDOW_S
        self.lock_time = None
        self.stall = False
        self.slip_J = 0.0
        self.n_err, self.sq_err, self.max_err = 0, 0.0, 0.0
        self.n_ch, self.sq_ch, self.max_ch = 0, 0.0, 0.0
        self.n_creep, self.sum_creep = 0, 0.0
        self.jerk = 0.0
        self.kiss_err = self.theta_cs = self.theta_err = None
        self.a_filt = 0.0
        self.alpha = h / (JERK_FILTER_S + h)
        self.started = False
        self.acc: list[float] = []
        self.t_first = math.nan
        #: the thermal-protection level the launch ran at (0 ok ... 3 inhibited, .protection)
        self.protection = 0

    def start(self, kiss_err_m: float, theta_cs_K: float, theta_err_K: float) -> None:
        """At the first engaged step: the TCU's kiss-point and temperature errors."""
        self.started = True
        self.kiss_err, self.theta_cs, self.theta_err = kiss_err_m, theta_cs_K, theta_err_K

    def characteristic(self, believed_Nm: float, true_Nm: float) -> None:
        """One TCU-cycle sample: the TCU's model torque and the true torque at the actual bearing position."""
        if believed_Nm == 0.0 and true_Nm == 0.0:          # both open: nothing to compare
            return
        e = believed_Nm - true_Nm
        self.n_ch += 1
        self.sq_ch += e * e
        if abs(e) > self.max_ch:
            self.max_ch = abs(e)

    def step(self, accel: float, tl: float, t_dem: float, t_cap: float, launching: bool) -> None:
        """One engaged step: vehicle acceleration (m/s2) at the end of the step, time in launch (s),
        demanded and delivered torque (N.m)."""
        if not self.acc:
            self.t_first = tl
        self.acc.append(accel)
        a_prev = self.a_filt
        self.a_filt += self.alpha * (accel - a_prev)
        jerk = abs(self.a_filt - a_prev) / self.h
        if jerk > self.jerk:
            self.jerk = jerk
        if launching and self.lock_time is None and t_dem > 0.0:
            e = t_cap - t_dem
            self.n_err += 1
            self.sq_err += e * e
            if abs(e) > self.max_err:
                self.max_err = abs(e)
            if t_dem <= CREEP_NM:
                self.n_creep += 1
                self.sum_creep += e

    def _lockup(self) -> tuple[float, float]:
        """(acceleration step, shuffle peak-to-peak) across lock-up, m/s2; NaN without lock-up."""
        if self.lock_time is None or not self.acc:
            return math.nan, math.nan
        k = int(round((self.lock_time - self.t_first) / self.h))      # first sample after lock-up
        m = max(1, int(round(self.window / self.h)))
        before, after = self.acc[max(0, k - m):k], self.acc[k:k + m]
        step = sum(after) / len(after) - sum(before) / len(before) if before and after else math.nan
        shuffle = self.acc[k:k + int(round(SHUFFLE_WINDOW_S / self.h))]
        return step, (max(shuffle) - min(shuffle)) if shuffle else math.nan

    def metrics(self, hot_degC: float) -> dict:
        """The launch's row (without ``tcu``)."""
        nan = math.nan
        theta = (self.theta_cs or KELVIN) - KELVIN
        ch_rms, ch_max = _rms_max(self.n_ch, self.sq_ch, self.max_ch)
        tr_rms, tr_max = _rms_max(self.n_err, self.sq_err, self.max_err)
        step, shuffle = self._lockup()
        return {
            "launch": self.launch,
            "demand_level": self.level,
            "theta_cs_start_degC": theta,
            "characteristic_error_rms_Nm": ch_rms,
            "characteristic_error_max_Nm": ch_max,
            "tracking_error_rms_Nm": tr_rms,
            "tracking_error_max_Nm": tr_max,
            "creep_error_Nm": self.sum_creep / self.n_creep if self.n_creep else nan,
            "lockup_accel_step_m_s2": step,
            "shuffle_amplitude_m_s2": shuffle,
            "kiss_point_error_mm": (self.kiss_err or 0.0) * 1e3,
            "engagement_time_s": self.lock_time if self.lock_time is not None else nan,
            "slip_energy_kJ": self.slip_J / 1e3,
            "peak_jerk_m_s3": self.jerk,
            "engine_stall": bool(self.stall),
            "theta_cs_error_K": self.theta_err if self.theta_err is not None else nan,
            "hot": bool(theta >= hot_degC),
            "phase": "cool-down" if self.cool else "repeated",
            "protection_level": self.protection,
            "launch_possible": bool(self.possible),
            "stranded": bool(self.possible and self.protection < 3 and self.lock_time is None),
        }


#: summarised columns: (column, how the worst is taken)
SUMMARY = (("characteristic_error_rms_Nm", "max"), ("characteristic_error_max_Nm", "max"),
           ("tracking_error_rms_Nm", "max"), ("tracking_error_max_Nm", "max"), ("creep_error_Nm", "absmax"),
           ("lockup_accel_step_m_s2", "absmax"), ("shuffle_amplitude_m_s2", "max"),
           ("kiss_point_error_mm", "absmax"), ("theta_cs_error_K", "absmax"), ("engagement_time_s", "max"),
           ("slip_energy_kJ", "max"), ("peak_theta_cm_degC", "max"), ("peak_theta_cs_degC", "max"),
           ("beyond_tables_s", "max"), ("above_damage_s", "max"))


def summarise(rows: list[dict], select) -> dict:
    """Mean and worst of the ``SUMMARY`` columns over the rows for which ``select(row)`` is true.

    Returns ``{"n": count, "<col>_mean": ..., "<col>_worst": ...}`` (NaN for no rows),
    plus ``stalls`` (count), ``no_lockup`` (launches without lock-up), ``stranded`` (of those, the ones the
    vehicle could make and the protection did not inhibit) and ``impossible`` (launches the vehicle cannot make).
    """
    rows = [r for r in rows if select(r)]
    out: dict = {"n": len(rows), "stalls": sum(bool(r["engine_stall"]) for r in rows),
                 "no_lockup": sum(math.isnan(r["engagement_time_s"]) for r in rows),
                 "stranded": sum(bool(r.get("stranded", False)) for r in rows),
                 "impossible": sum(not r.get("launch_possible", True) for r in rows)}
    for col, how in SUMMARY:
        vals = [r[col] for r in rows if col in r and not math.isnan(r[col])]
        if not vals:
            out[col + "_mean"] = out[col + "_worst"] = float("nan")
            continue
        out[col + "_mean"] = sum(vals) / len(vals)
        out[col + "_worst"] = max(vals, key=abs) if how == "absmax" else max(vals)
    return out


def temperature_metrics(series, theta_min_K: float, theta_max_K: float, damage_K: float) -> dict[int, dict]:
    """Per launch of a recorded time series (fields ``time_s``, ``launch``, ``theta_cm_K``, ``theta_cs_K``): the
    peak temperatures (degC) and the time (s) beyond the cushion table (``theta_cs`` outside
    [``theta_min_K``, ``theta_max_K``]) and above the facing damage limit (``theta_cm > damage_K``).

    A row stands for the time to the next recorded row (the last row of a series: none), so the times are
    resolved to the recording interval and the peaks are those of the recorded rows.
    """
    t, launch = series["time_s"], series["launch"]
    cm, cs = series["theta_cm_K"], series["theta_cs_K"]
    out: dict[int, dict] = {}
    for i in range(len(t)):
        k = int(launch[i])
        d = out.setdefault(k, {"peak_theta_cm_degC": -math.inf, "peak_theta_cs_degC": -math.inf,
                               "beyond_tables_s": 0.0, "above_damage_s": 0.0})
        dt = float(t[i + 1] - t[i]) if i + 1 < len(t) else 0.0
        d["peak_theta_cm_degC"] = max(d["peak_theta_cm_degC"], float(cm[i]) - KELVIN)
        d["peak_theta_cs_degC"] = max(d["peak_theta_cs_degC"], float(cs[i]) - KELVIN)
        if not theta_min_K <= cs[i] <= theta_max_K:
            d["beyond_tables_s"] += dt
        if cm[i] > damage_K:
            d["above_damage_s"] += dt
    return out


def add_temperature_metrics(metrics: list[dict], series, theta_min_K: float, theta_max_K: float,
                            damage_K: float) -> None:
    """Add :data:`TEMPERATURE_COLUMNS` to each launch's row of ``metrics`` (NaN for a launch not recorded)."""
    per = temperature_metrics(series, theta_min_K, theta_max_K, damage_K)
    for row in metrics:
        row.update(per.get(int(row["launch"]), dict.fromkeys(TEMPERATURE_COLUMNS, math.nan)))


def launch_capability(sc, level: str) -> tuple[float, float]:
    """What a launch at the demand ``level`` can do on the scenario's grade: ``(engine_Nm, load_Nm)``.

    ``engine_Nm``: the engine's largest net torque at the level's pedal over its speed range (idle to
    ``engine.max_speed_rpm``; a creep launch: the idle governor's full throttle at idle speed),
    ``pedal T_max(w) - drag w``; ``load_Nm``: the clutch torque that holds the car on the grade against
    rolling resistance (the driveline's ``t_load_rest``). Both at the disc, N.m. The launch is physically
    possible when ``engine_Nm > load_Nm`` (the car can be accelerated once locked).
    """
    from ..plant.driveline import Driveline
    from ..plant.engine import RPM, EngineGovernor

    eng = EngineGovernor(sc.engine, sc.run.step_s)
    load = Driveline(**sc.driveline_sections(), w_e=eng.w_idle).t_load_rest
    if level == "creep":
        return eng.max_torque(eng.w_idle) - eng.drag * eng.w_idle, load
    pedal = sc.driver.pedal(level)
    speeds = [eng.w_idle, eng.w_max] + [w for w in eng.w if eng.w_idle < w < eng.w_max]
    return max(pedal * eng.max_torque(w) - eng.drag * w for w in speeds), load


def launch_possible(sc, level: str) -> bool:
    """True if the vehicle can make a launch at ``level`` on the scenario's grade within the driver's pedal time.

    The engine's torque at the pedal must exceed the holding torque (:func:`launch_capability`), and (a pedal
    launch) the disc must reach, within ``tcu.drive_time_s``, the lowest engine speed at which the engine holds
    the car, accelerated at best by the engine's largest surplus: ``w_hold J_d / (engine - load)`` (a lower
    bound of any controller's time; ``J_d`` the disc and vehicle inertia at the disc).
    """
    engine, load = launch_capability(sc, level)
    if engine <= load:
        return False
    if level == "creep":
        return True
    from ..plant.driveline import Driveline
    from ..plant.engine import EngineGovernor

    eng = EngineGovernor(sc.engine, sc.run.step_s)
    pedal = sc.driver.pedal(level)
    n = 400
    hold = next(w for w in (eng.w_idle + (eng.w_max - eng.w_idle) * k / n for k in range(n + 1))
                if pedal * eng.max_torque(w) - eng.drag * w > load)
    return hold * Driveline(**sc.driveline_sections(), w_e=eng.w_idle).j_d / (engine - load) <= sc.tcu.drive_time_s
