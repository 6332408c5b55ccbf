"""What one TCU's run yields: the time series' row type and :class:`LaunchResult`.

A row is a record of the structured dtype :data:`SERIES_DTYPE` (every column a float, SI; the names say the
unit). Its columns come from two places: the plant (:data:`PLANT_COLUMNS`: speeds, bearing, torques,
temperatures, in the order of a plant step's figures, ``launch_plant.h``'s ``lp_step_out``) and the TCU
(:data:`TCU_COLUMNS`: what it commands and believes); :func:`row` puts them in the series' order
(:data:`COLUMNS`). Metrics, plots and reports read the series by column name and never run the loop.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: columns of the time series (SI; recorded every ``record_every`` steps)
COLUMNS = ("time_s", "launch", "w_engine_rad_s", "w_disc_rad_s", "v_m_s", "accel_m_s2", "x_cmd_m",
           "x_to_m", "torque_demand_Nm", "torque_capacity_Nm", "torque_clutch_Nm", "theta_cm_K",
           "theta_cs_K", "theta_cs_tcu_K", "x_kiss_m", "x_kiss_tcu_m", "throttle", "locked", "theta_cm_tcu_K",
           "torque_believed_Nm", "torque_shaft_Nm", "theta_surface_K", "theta_pressure_plate_K", "protection_level")
#: theta_surface_K: the hotter metal friction surface (1 mm layer), theta_pressure_plate_K: the pressure plate's
#: bulk node, both from the plant's thermal network (NaN with the lumped facing or a prescribed profile);
#: protection_level: the TCU's thermal protection (0 ok, 1 warn, 2 limit, 3 inhibited)

#: the plant's columns, in the order a plant step gives them (theta_cm_K: the facing temperature the step held)
PLANT_COLUMNS = ("w_engine_rad_s", "w_disc_rad_s", "v_m_s", "accel_m_s2", "x_to_m", "torque_demand_Nm",
                 "torque_capacity_Nm", "torque_clutch_Nm", "theta_cm_K", "theta_cs_K", "x_kiss_m", "throttle",
                 "locked", "torque_shaft_Nm", "theta_surface_K", "theta_pressure_plate_K")
#: the TCU's columns: its command, the cushion-spring temperature and kiss point it assumes, its facing
#: estimate, the torque it believed (NaN unless sampling) and its protection level
TCU_COLUMNS = ("x_cmd_m", "theta_cs_tcu_K", "x_kiss_tcu_m", "theta_cm_tcu_K", "torque_believed_Nm",
               "protection_level")
#: the row type: one float per column
SERIES_DTYPE = np.dtype([(c, float) for c in COLUMNS])

if sorted(COLUMNS) != sorted(("time_s", "launch") + PLANT_COLUMNS + TCU_COLUMNS):     # pragma: no cover
    raise RuntimeError("series: PLANT_COLUMNS and TCU_COLUMNS must split COLUMNS")


def row(t: float, launch: int, p: tuple, c: tuple) -> tuple:
    """One row in the order of :data:`COLUMNS` from the time (s), the launch (1-based), the plant part ``p``
    (:data:`PLANT_COLUMNS`) and the TCU part ``c`` (:data:`TCU_COLUMNS`)."""
    return (t, launch, p[0], p[1], p[2], p[3], c[0], p[4], p[5], p[6], p[7], p[8], p[9], c[1], p[10], c[2], p[11],
            p[12], c[3], c[4], p[13], p[14], p[15], c[5])


def series(rows: list[tuple]) -> np.ndarray:
    """The rows as a structured array of :data:`SERIES_DTYPE`."""
    return np.array(rows, dtype=SERIES_DTYPE)


@dataclass
class LaunchResult:
    """Time series, per-launch metrics and energy terms of one TCU's run."""

    tcu: str
    series: np.ndarray            # structured, SERIES_DTYPE
    metrics: list[dict]
    energy: object
    """the driveline's energy books (:class:`~..plant.driveline.Energy`), J"""
    lock_events: list[tuple[int, str, float]]
    wall_time_s: float
    sim_time_s: float
    cpu_time_s: float
    """CPU time of this process in the loop, s (on a shared machine a steadier figure than the wall time)"""
    kiss_estimates: list[tuple[int, float]]
    quiet_s: float = 0.0
    """simulated time advanced in quiet steps (``run.quiet_steps``), s"""
    key_on: object = None
    """production TCU: how it started (reset or learned) and its standstill touch-point learning
    (:class:`~..tcu.production.KeyOn`)"""
    protection_events: list = field(default_factory=list)
    """(s into the launch slot, launch, level, message): what the thermal protection told the driver"""
    plant: str = "python"
    """the plant loop that ran: ``native`` (compiled blocks, :mod:`..plant.plant_block`) or ``python``"""
    stopped: str = ""
    """why and where the run ended early ("" for a complete run): the plant FMU refused a step because the plant
    left the model's domain (e.g. a facing past 800 K); ``metrics`` then hold the launches up to that one"""
