"""Launch scenario parameters (TOML), checked like the spring parameters.

SI units unless a name says otherwise (``_rpm``, ``_percent``, ``_degC``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

from ..config import Checked, build_checked, load_toml, range_problem
from ..data import DEFAULT_SCENARIO



@dataclass(frozen=True)
class Engine(Checked):
    """Engine and flywheel: ``T = throttle T_max(w) - drag_Nm_per_rad_s w``.

    The engine control's speed governor (PI, anti-windup) sets the throttle to
    hold ``launch_speed_rpm`` while the clutch is engaged or closed, and
    ``idle_speed_rpm`` while it is open.
    """

    inertia_kg_m2: float = 0.25
    torque_curve_rpm: tuple[float, ...] = (800.0, 1500.0, 2500.0, 4000.0, 5500.0, 6500.0)
    torque_curve_Nm: tuple[float, ...] = (130.0, 190.0, 230.0, 240.0, 210.0, 170.0)
    drag_Nm_per_rad_s: float = 0.05
    idle_speed_rpm: float = 800.0
    launch_speed_rpm: float = 1800.0
    governor_kp_Nm_per_rad_s: float = 3.0
    governor_ki_Nm_per_rad: float = 15.0
    stall_speed_rpm: float = 400.0
    max_speed_rpm: float = 6500.0

    _section = "engine"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "inertia_kg_m2": (0.0, 10.0, True), "drag_Nm_per_rad_s": (0.0, 10.0),
            "idle_speed_rpm": (100.0, 3000.0), "launch_speed_rpm": (500.0, 8000.0), "governor_kp_Nm_per_rad_s": (0.0, 1e3),
            "governor_ki_Nm_per_rad": (0.0, 1e4), "stall_speed_rpm": (0.0, 3000.0),
            "max_speed_rpm": (1000.0, 20000.0)})
        if len(self.torque_curve_rpm) < 2 or len(self.torque_curve_rpm) != len(self.torque_curve_Nm):
            yield "engine.torque_curve_rpm / torque_curve_Nm: need equal lengths >= 2"
        elif list(self.torque_curve_rpm) != sorted(set(self.torque_curve_rpm)):
            yield "engine.torque_curve_rpm: must be strictly increasing"
        for i, v in enumerate(self.torque_curve_Nm):
            msg = range_problem(f"engine.torque_curve_Nm[{i}]", v, 0.0, 5000.0)
            if msg:
                yield msg


@dataclass(frozen=True)
class Driveline(Checked):
    """Clutch disc side: gearbox in launch gear, final drive, wheels."""

    disc_inertia_kg_m2: float = 0.03
    gear_ratio: float = 3.8
    final_drive_ratio: float = 4.1
    efficiency: float = 0.95
    wheel_radius_m: float = 0.31

    _section = "driveline"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "disc_inertia_kg_m2": (0.0, 10.0, True), "gear_ratio": (0.1, 20.0),
            "final_drive_ratio": (0.5, 20.0), "efficiency": (0.5, 1.0), "wheel_radius_m": (0.1, 1.0)})


@dataclass(frozen=True)
class Vehicle(Checked):
    """Vehicle on a slope; the service brake stops it between launches."""

    mass_kg: float = 1900.0
    rolling_resistance: float = 0.012
    drag_area_m2: float = 0.7
    air_density_kg_m3: float = 1.2
    slope_percent: float = 8.0
    brake_decel_m_s2: float = 4.0

    _section = "vehicle"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "mass_kg": (100.0, 1e5), "rolling_resistance": (0.0, 0.1), "drag_area_m2": (0.0, 20.0),
            "air_density_kg_m3": (0.0, 2.0), "slope_percent": (-30.0, 30.0),
            "brake_decel_m_s2": (0.1, 15.0)})


@dataclass(frozen=True)
class Facing(Checked):
    """Lumped facing thermal model heated by the slip power.

    ``C_f dtheta_cm/dt = share T w_slip - G_f (theta_cm - theta_a)``; with
    ``profile_csv`` set (columns ``time_s,theta_cm_K``) theta_cm is prescribed
    instead (linear between rows).
    """

    capacity_J_per_K: float = 450.0
    loss_W_per_K: float = 1.35
    heat_share: float = 1.0
    ambient_degC: float = 20.0
    initial_degC: float = 20.0
    """Facing and cushion-spring temperature at the start (thermally soaked)."""
    profile_csv: str = ""

    _section = "facing"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "capacity_J_per_K": (1.0, 1e6), "loss_W_per_K": (0.0, 1e4), "heat_share": (0.0, 1.0),
            "ambient_degC": (-50.0, 60.0), "initial_degC": (-50.0, 400.0)})


@dataclass(frozen=True)
class Tcu(Checked):
    """Launch strategy shared by both TCUs: the same clutch-torque demand profile.

    The demand ramps at ``torque_ramp_Nm_per_s`` to ``torque_target_Nm`` and is
    held until lock-up; then the bearing closes at ``close_rate_m_per_s`` to
    ``x_to_closed_m``. ``prefill_s`` before each launch the bearing is moved to
    the TCU's believed first contact (zero torque). The actuator follows the
    command with a first-order lag.
    """

    period_s: float = 0.01
    torque_ramp_Nm_per_s: float = 150.0
    torque_target_Nm: float = 150.0
    x_to_closed_m: float = 0.009
    close_rate_m_per_s: float = 0.01
    actuator_time_constant_s: float = 0.02
    drive_time_s: float = 8.0
    prefill_s: float = 0.3

    _section = "tcu"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "period_s": (1e-4, 1.0), "torque_ramp_Nm_per_s": (1.0, 1e4), "torque_target_Nm": (1.0, 2000.0),
"x_to_closed_m": (0.0, 0.05),
            "close_rate_m_per_s": (1e-4, 1.0), "actuator_time_constant_s": (0.0, 1.0),
            "drive_time_s": (0.5, 100.0), "prefill_s": (0.0, 5.0)})


@dataclass(frozen=True)
class Run(Checked):
    """Repetition and co-simulation step."""

    launches: int = 12
    period_s: float = 60.0
    step_s: float = 0.001

    _section = "run"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"launches": (1, 1000), "period_s": (5.0, 3600.0), "step_s": (1e-5, 0.1)})
        yield from self._integers("launches")


@dataclass(frozen=True)
class Scenario(Checked):
    """A repeated-launch scenario."""

    name: str = "default"
    description: str = ""
    engine: Engine = field(default_factory=Engine)
    driveline: Driveline = field(default_factory=Driveline)
    vehicle: Vehicle = field(default_factory=Vehicle)
    facing: Facing = field(default_factory=Facing)
    tcu: Tcu = field(default_factory=Tcu)
    run: Run = field(default_factory=Run)

    def _problems(self) -> Iterable[str]:
        if self.run.period_s <= self.tcu.drive_time_s + 5.0:
            yield (f"run.period_s = {self.run.period_s!r}: must exceed tcu.drive_time_s + 5 s "
                   "(time to brake to a stop)")


def load_scenario(path: str | Path = DEFAULT_SCENARIO) -> Scenario:
    """Load and check a scenario TOML file (unknown keys and bad ranges rejected)."""
    return build_checked(Scenario, load_toml(path), str(path))
