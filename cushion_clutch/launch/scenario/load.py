"""Launch scenario parameters (TOML), checked like the spring parameters.

SI units unless a name says otherwise (``_rpm``, ``_percent``, ``_degC``).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

from ...config import Checked, build_checked, load_toml, range_problem
from ...data import DEFAULT_SCENARIO
from ...errors import ParameterError
from .tcu_params import (Adaptation, EkfParams, MassGrade, Observer, ProductionSensors, Protection, Sensors, Standstill,
                         TcuNetworkParams, TcuStore)
from ...model.thermal_network import PlantThermal



@dataclass(frozen=True)
class Engine(Checked):
    """Engine and flywheel: ``T = throttle T_max(w) - drag_Nm_per_rad_s w``.

    The throttle is the driver's pedal or, when that is less, the engine
    control's idle governor (PI on the speed, anti-windup), which holds
    ``idle_speed_rpm``; no fuel above ``max_speed_rpm`` or after a stall.
    """

    inertia_kg_m2: float = 0.25
    torque_curve_rpm: tuple[float, ...] = (800.0, 1500.0, 2500.0, 4000.0, 5500.0, 6500.0)
    torque_curve_Nm: tuple[float, ...] = (130.0, 190.0, 230.0, 240.0, 210.0, 170.0)
    drag_Nm_per_rad_s: float = 0.05
    idle_speed_rpm: float = 800.0
    governor_kp_Nm_per_rad_s: float = 3.0
    governor_ki_Nm_per_rad: float = 15.0
    stall_speed_rpm: float = 400.0
    max_speed_rpm: float = 6500.0

    _section = "engine"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "inertia_kg_m2": (0.0, 10.0, True), "drag_Nm_per_rad_s": (0.0, 10.0),
            "idle_speed_rpm": (100.0, 3000.0), "governor_kp_Nm_per_rad_s": (0.0, 1e3),
            "governor_ki_Nm_per_rad": (0.0, 1e4), "stall_speed_rpm": (0.0, 3000.0),
            "max_speed_rpm": (1000.0, 20000.0)})
        if len(self.torque_curve_rpm) < 2 or len(self.torque_curve_rpm) != len(self.torque_curve_Nm):
            yield (f"engine.torque_curve_Nm: {len(self.torque_curve_Nm)} values for {len(self.torque_curve_rpm)} "
                   "torque_curve_rpm values; need equal lengths >= 2")
        elif list(self.torque_curve_rpm) != sorted(set(self.torque_curve_rpm)):
            yield "engine.torque_curve_rpm: must be strictly increasing"
        for i, v in enumerate(self.torque_curve_Nm):
            msg = range_problem(f"engine.torque_curve_Nm[{i}]", v, 0.0, 5000.0)
            if msg:
                yield msg


@dataclass(frozen=True)
class Driveline(Checked):
    """Clutch disc side: gearbox in launch gear, final drive, compliant shafts and tyres, wheels.

    The torsional stiffness and damping of the drive shafts and tyres are
    lumped between the gearbox output and the vehicle, stated at the wheels
    (both wheels together).
    """

    disc_inertia_kg_m2: float = 0.03
    gear_ratio: float = 3.8
    final_drive_ratio: float = 4.1
    efficiency: float = 0.95
    wheel_radius_m: float = 0.31
    stiffness_Nm_per_rad: float = 50000.0
    damping_Nm_s_per_rad: float = 300.0

    _section = "driveline"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "disc_inertia_kg_m2": (0.0, 10.0, True), "gear_ratio": (0.1, 20.0),
            "final_drive_ratio": (0.5, 20.0), "efficiency": (0.5, 1.0), "wheel_radius_m": (0.1, 1.0),
            "stiffness_Nm_per_rad": (100.0, 1e7), "damping_Nm_s_per_rad": (0.0, 1e5)})


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
    """The launch controller shared by every TCU variant (see :mod:`.tcu`).

    Every ``period_s``: before a launch (``prefill_s``) the bearing goes to
    the believed first contact; in the launch the clutch-torque demand is the
    engine torque minus the engine inertia times the reference's acceleration
    plus a PI on the engine speed against a reference that rises with time
    constant ``engine_speed_time_constant_s`` from the speed at the start to
    ``idle + pedal (engine_speed_full_pedal_rpm - idle)`` (a creep launch: the
    driver's creep torque instead); below ``sync_slip_rad_s`` of slip the PI
    follows a slip trajectory that meets zero at ``lockup_slip_rate_rad_s2``
    around the locked-driveline torque;
    the demand rises at most at ``torque_ramp_Nm_per_s``. The believed
    characteristic is inverted and the actuator's first-order lag
    (``actuator_time_constant_s``, known to the TCU) inverted over one period.
    After lock-up the bearing closes at ``close_rate_m_per_s`` to ``x_to_closed_m``.

    The calibration's friction (every TCU variant's): the nominal mu of the clutch parameters at the slip
    speed ``facing_mu_reference_slip_rad_s``, falling by ``facing_mu_slope_per_100_rad_s`` of it per
    100 rad/s of slip (the facing supplier's nominal slip-speed shape; 0: mu constant, the default facing),
    ``mu(w) = mu (1 + slope (|w| - w_ref) / 100 rad/s)`` at the measured slip.
    """

    period_s: float = 0.01
    torque_ramp_Nm_per_s: float = 400.0
    engine_speed_full_pedal_rpm: float = 2200.0
    engine_speed_time_constant_s: float = 0.3
    speed_kp_Nm_per_rad_s: float = 1.0
    speed_ki_Nm_per_rad: float = 5.0
    sync_slip_rad_s: float = 30.0
    lockup_slip_rate_rad_s2: float = 10.0
    x_to_closed_m: float = 0.015
    close_rate_m_per_s: float = 0.01
    actuator_time_constant_s: float = 0.02
    drive_time_s: float = 8.0
    prefill_s: float = 0.3
    facing_mu_slope_per_100_rad_s: float = 0.0
    """the calibration's relative change of mu per 100 rad/s of slip (the facing's nominal shape), 1"""
    facing_mu_reference_slip_rad_s: float = 190.0
    """slip speed at which the calibration's mu is the nominal mu, rad/s"""
    lockup_deadline_s: float = 5.5
    """pedal launches: this long after the launch's start (after the pre-fill) the TCU closes the slip that is
    left within ``forced_sync_s`` (it enters the sync from any slip, or shortens a slower sync), provided the
    disc turns at least at the engine's idle speed and the engine's torque at the pedal there carries the
    holding torque the TCU believes (locked, the engine runs on and the car does not roll back), s"""
    forced_sync_s: float = 1.5
    """the longest sync after ``lockup_deadline_s``, s (a deadline later than ``drive_time_s - forced_sync_s``
    leaves the forced sync less time than this: the driver lifts off first)"""

    _section = "tcu"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges(spec := {
            "period_s": (1e-4, 1.0), "torque_ramp_Nm_per_s": (1.0, 1e5),
            "engine_speed_full_pedal_rpm": (500.0, 8000.0), "engine_speed_time_constant_s": (1e-3, 10.0),
            "speed_kp_Nm_per_rad_s": (0.0, 100.0), "speed_ki_Nm_per_rad": (0.0, 1e4),
            "sync_slip_rad_s": (1.0, 500.0), "lockup_slip_rate_rad_s2": (0.1, 1000.0),
            "x_to_closed_m": (0.0, 0.05),
            "close_rate_m_per_s": (1e-4, 1.0), "actuator_time_constant_s": (0.0, 1.0),
            "drive_time_s": (0.5, 100.0), "prefill_s": (0.0, 5.0),
            "facing_mu_slope_per_100_rad_s": (-0.2, 0.2), "facing_mu_reference_slip_rad_s": (0.0, 1000.0),
            "lockup_deadline_s": (0.5, 100.0), "forced_sync_s": (0.1, 10.0)})
        k, w_ref = self.facing_mu_slope_per_100_rad_s, self.facing_mu_reference_slip_rad_s
        if not self._passed(spec, "facing_mu_slope_per_100_rad_s", "facing_mu_reference_slip_rad_s"):
            return
        low = min(1.0 + k * (w - w_ref) / 100.0 for w in (0.0, 1000.0))
        if low < 0.5:
            yield (f"tcu.facing_mu_slope_per_100_rad_s = {k!r}: the calibration's mu falls to {low:.3g} of the "
                   f"nominal between 0 and 1000 rad/s of slip (reference {w_ref:g} rad/s); must stay >= 0.5")

    def mu_calibration(self, w_slip_rad_s: float) -> float:
        """The calibration's friction at the slip speed ``w_slip_rad_s`` (rad/s) relative to the nominal mu, 1
        (exactly 1 when the calibration's mu is constant)."""
        k = self.facing_mu_slope_per_100_rad_s
        return 1.0 + k * (abs(w_slip_rad_s) - self.facing_mu_reference_slip_rad_s) / 100.0 if k else 1.0


#: the driver's demand levels
LEVELS = ("creep", "moderate", "hard")


@dataclass(frozen=True)
class Driver(Checked):
    """The driver's pedal: one demand level per launch, ``levels`` cycled over the launches.

    ``creep``: pedal 0 (the idle governor runs the engine), the TCU gives
    ``creep_torque_Nm``; ``moderate`` and ``hard``: throttle ``moderate_pedal``
    and ``hard_pedal``. The driver lifts off when the engine passes
    ``lift_off_speed_rpm`` after lock-up.
    """

    levels: tuple[str, ...] = ("moderate", "hard")
    creep_torque_Nm: float = 20.0
    moderate_pedal: float = 0.5
    hard_pedal: float = 0.75
    lift_off_speed_rpm: float = 4000.0

    _section = "driver"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"creep_torque_Nm": (0.5, 30.0), "moderate_pedal": (0.05, 1.0),
                                 "hard_pedal": (0.05, 1.0), "lift_off_speed_rpm": (500.0, 20000.0)})
        if not self.levels:
            yield "driver.levels: need at least one level (" + ", ".join(LEVELS) + ")"
        for i, lv in enumerate(self.levels):
            if lv not in LEVELS:
                yield f"driver.levels[{i}] = {lv!r}: allowed " + ", ".join(LEVELS)

    def level(self, launch: int) -> str:
        """The demand level of launch ``launch`` (1-based)."""
        return self.levels[(launch - 1) % len(self.levels)]

    def pedal(self, level: str) -> float:
        """Throttle of a level (0 for creep)."""
        return {"creep": 0.0, "moderate": self.moderate_pedal, "hard": self.hard_pedal}[level]


@dataclass(frozen=True)
class Clutch(Checked):
    """The plant clutch's friction: ``friction_csv`` = "" keeps mu = 0.28 constant (the paper's model).

    Otherwise a ``theta_degC,omega_slip_rad_s,mu`` table, relative to the
    scenario file's folder (or absolute), put into the plant FMU's resources.
    The TCUs do not know it: their model keeps the nominal mu.
    """

    friction_csv: str = ""
    x_kiss_offset_m: float = 0.0
    """the plant's kiss point minus the TCU's nominal one, at the bearing (tolerances), m"""
    facing_wear_m: float = 0.0
    """the plant's facing wear (the clutch FMU's ``facing_wear``), m; the TCUs believe new facings"""
    plant_tables: str = ""
    """table-set folder of the plant (relative to the scenario's folder); "" = the command's --tables"""
    tcu_tables: str = ""
    """table-set folder the TCUs believe; "" = the command's --tables"""
    spring_thermal: str = "paper"
    """the cushion spring's heat path (U, H, C of eq. 2) in the plant clutch FMU and, unless [observer] or
    [tcu_thermal] give their own, in the TCUs' models: a named set (``paper``: the paper's 0.1 W/K, 0.04 W/K,
    1 J/K, the FMU's defaults; ``fe_default``: identified by ``cushion-clutch heat-path``) or a set TOML
    relative to the scenario's folder (:mod:`cushion_clutch.model.thermal_set`)"""

    _section = "clutch"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"x_kiss_offset_m": (-0.005, 0.005), "facing_wear_m": (0.0, 0.004)})
        for key in ("friction_csv", "plant_tables", "tcu_tables", "spring_thermal"):
            if not isinstance(getattr(self, key), str):
                yield f"clutch.{key} = {getattr(self, key)!r}: must be a file or folder name or \"\""


@dataclass(frozen=True)
class Run(Checked):
    """Repetition and co-simulation step.

    ``launches`` every ``period_s`` (the hot phase), then ``cool_launches``
    every ``cool_period_s`` (a cool-down). Launches starting with the cushion
    spring at or above ``hot_degC`` count as hot in the summary.
    """

    launches: int = 12
    period_s: float = 60.0
    step_s: float = 0.001
    cool_launches: int = 0
    cool_period_s: float = 300.0
    hot_degC: float = 100.0
    quiet_steps: bool = True
    """while the car stands braked, the clutch open and retracted (only the engine idles), the master, the
    idle engine and the clutch FMU advance one TCU period per step (false: ``step_s`` throughout)"""

    _section = "run"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"launches": (1, 1000), "period_s": (5.0, 3600.0), "step_s": (1e-5, 0.1),
                                 "cool_launches": (0, 1000), "cool_period_s": (5.0, 3600.0),
                                 "hot_degC": (-50.0, 400.0)})
        yield from self._integers("launches", "cool_launches")
        if not isinstance(self.quiet_steps, bool):
            yield f"run.quiet_steps = {self.quiet_steps!r}: must be true or false"

    def starts(self) -> list[float]:
        """Start time of every launch, s."""
        hot = [i * self.period_s for i in range(self.launches)]
        last = hot[-1]
        return hot + [last + (j + 1) * self.cool_period_s for j in range(self.cool_launches)]

    def duration(self) -> float:
        """Simulated time, s: the last launch gets its own period."""
        return self.starts()[-1] + (self.cool_period_s if self.cool_launches else self.period_s)


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
    driver: Driver = field(default_factory=Driver)
    run: Run = field(default_factory=Run)
    clutch: Clutch = field(default_factory=Clutch)
    observer: Observer = field(default_factory=Observer)
    sensors: Sensors = field(default_factory=Sensors)
    adaptation: Adaptation = field(default_factory=Adaptation)
    plant_thermal: PlantThermal = field(default_factory=PlantThermal)
    tcu_sensors: ProductionSensors = field(default_factory=ProductionSensors)
    tcu_thermal: TcuNetworkParams = field(default_factory=TcuNetworkParams)
    ekf: EkfParams = field(default_factory=EkfParams)
    mass_grade: MassGrade = field(default_factory=MassGrade)
    standstill: Standstill = field(default_factory=Standstill)
    tcu_store: TcuStore = field(default_factory=TcuStore)
    protection: Protection = field(default_factory=Protection)
    folder: str = ""
    """folder of the scenario file (set by :func:`load_scenario`), for relative file names"""

    def _problems(self) -> Iterable[str]:
        for key, period in (("period_s", self.run.period_s), ("cool_period_s", self.run.cool_period_s)):
            if period <= self.tcu.prefill_s + self.tcu.drive_time_s + 5.0:
                yield (f"run.{key} = {period!r}: must exceed tcu.prefill_s + tcu.drive_time_s + 5 s "
                       "(time to brake to a stop)")

    def tables_path(self, which: str) -> Path | None:
        """``clutch.plant_tables`` or ``clutch.tcu_tables`` (``which`` = "plant" | "tcu") as a folder, or None."""
        name = getattr(self.clutch, f"{which}_tables")
        if not name:
            return None
        path = Path(name)
        return path if path.is_absolute() else Path(self.folder or ".") / path

    def tcu_sections(self) -> dict:
        """The sections a TCU controller takes (:class:`~..tcu.controller.TcuController`'s keywords): ``tcu``,
        ``driver``, ``engine``, ``observer``, ``adaptation``, ``protection``."""
        return {"tcu": self.tcu, "driver": self.driver, "engine": self.engine, "observer": self.observer,
                "adaptation": self.adaptation, "protection": self.protection}

    def driveline_sections(self) -> dict:
        """What the plant's driveline takes (:class:`~..plant.driveline.Driveline`'s keywords but ``w_e``): the
        ``[driveline]`` and ``[vehicle]`` sections, the engine's inertia (kg m2) and the step (s)."""
        return {"driveline": self.driveline, "vehicle": self.vehicle,
                "engine_inertia_kg_m2": self.engine.inertia_kg_m2, "step_s": self.run.step_s}

    def spring_thermal_set(self):
        """The plant's cushion-spring heat path (:class:`~cushion_clutch.model.thermal_set.ThermalSet`)."""
        return _thermal_set(self.clutch.spring_thermal, self.folder)

    def friction_path(self) -> Path | None:
        """The plant's friction table file, or None (mu constant)."""
        if not self.clutch.friction_csv:
            return None
        path = Path(self.clutch.friction_csv)
        return path if path.is_absolute() else Path(self.folder or ".") / path


def shipped_names() -> list[str]:
    """Names of the shipped scenarios."""
    return sorted(p.stem for p in DEFAULT_SCENARIO.parent.glob("*.toml"))


def scenario_path(name: str | Path) -> Path:
    """A scenario file: ``name`` itself, or the shipped ``<name>.toml`` (default, creep, cooldown, fade, ...)."""
    path = Path(name)
    shipped = DEFAULT_SCENARIO.parent / f"{name}.toml"
    # a folder of that name (e.g. the output of an earlier `launch --scenario wear --out wear`) is no scenario
    return shipped if not path.is_file() and path.suffix == "" and shipped.is_file() else path


#: keys naming files relative to the scenario file that sets them
_RELATIVE_FILES = (("clutch", "friction_csv"), ("clutch", "plant_tables"), ("clutch", "tcu_tables"))


def _resolve_extends(value: object, child: Path) -> Path:
    """The file an ``extends`` value names: a shipped scenario's name, or a path relative to ``child``'s folder."""
    if not isinstance(value, str) or not value:
        raise ParameterError([f"extends = {value!r}: must be a shipped scenario name "
                              f"({', '.join(shipped_names())}) or a file name"], str(child))
    path = Path(value)
    if not path.is_absolute():
        local = child.parent / path
        if local.is_file():
            return local.resolve()
    if path.suffix == "" and (DEFAULT_SCENARIO.parent / f"{value}.toml").is_file():
        return (DEFAULT_SCENARIO.parent / f"{value}.toml").resolve()
    if path.is_absolute() and path.is_file():
        return path.resolve()
    raise ParameterError([f"extends = {value!r}: no such scenario (shipped: {', '.join(shipped_names())}; "
                          f"or a file relative to {child.parent})"], str(child))


def merged_data(path: str | Path, _chain: tuple[Path, ...] = ()) -> tuple[dict, dict]:
    """The TOML tables of a scenario file deep-merged over those of the scenario it ``extends`` (recursively).

    Returns ``(data, origin)``: ``origin[(section, key)]`` (``section`` "" for top-level keys) is the file
    that set the value. Tables merge key by key; any other value (numbers, strings, lists) replaces the
    parent's. File names of ``clutch.friction_csv``, ``plant_tables`` and ``tcu_tables`` set by a parent are
    made absolute, relative to the parent's folder. ``name`` and ``description`` are not inherited
    (``name`` defaults to the file's stem). A cycle of ``extends`` is refused.
    """
    path = Path(path).resolve()
    if path in _chain:
        raise ParameterError(["extends: cycle " + " -> ".join(str(p) for p in _chain + (path,))], str(path))
    data = load_toml(path)
    if "folder" in data:
        raise ParameterError(["folder: unknown key"], str(path))
    for sec, key in _RELATIVE_FILES:
        v = data.get(sec, {}).get(key) if isinstance(data.get(sec), dict) else None
        if _chain and isinstance(v, str) and v and not Path(v).is_absolute():     # a parent: its own folder
            data[sec][key] = str(path.parent / v)
    if "extends" not in data:
        origin = {(sec if isinstance(v, dict) else "", k): path
                  for sec, v in data.items() for k in (v if isinstance(v, dict) else [sec])}
        data.setdefault("name", path.stem)
        return data, origin
    parent = _resolve_extends(data.pop("extends"), path)
    base, origin = merged_data(parent, _chain + (path,))
    base.pop("name", None)
    base.pop("description", None)
    for sec, value in data.items():
        if isinstance(value, dict) and isinstance(base.get(sec), dict):
            base[sec] = {**base[sec], **value}
            origin.update({(sec, k): path for k in value})
        else:
            base[sec] = value
            origin.update({(sec, k): path for k in (value if isinstance(value, dict) else [])})
            origin[("", sec)] = path
    base.setdefault("name", path.stem)
    return base, origin


def _blame(problem: str, origin: dict, top: Path) -> str:
    """``problem`` with the file that set its key, when that is not ``top``."""
    key = problem.split(" ", 1)[0].split("[", 1)[0].rstrip(":")
    sec, _, name = key.partition(".")
    src = origin.get((sec, name)) if name else origin.get(("", sec))
    return f"{problem} (set in {src})" if src is not None and src != top else problem


def _thermal_set(name: str, folder: str):
    """A thermal set by shipped name or a TOML file relative to ``folder``."""
    from ...model.thermal_set import load_thermal_set
    path = Path(name)
    if path.suffix and not path.is_absolute():
        path = Path(folder or ".") / path
    return load_thermal_set(path if path.suffix else name)


def _spring_thermal_defaults(data: dict, origin: dict, top: Path) -> None:
    """The TCUs' cushion-spring models ([observer], [tcu_thermal] spring_*) default to the plant's set."""
    clutch = data.get("clutch", {})
    name = clutch.get("spring_thermal", "paper") if isinstance(clutch, dict) else "paper"
    if not isinstance(name, str):
        return                                      # the Clutch section's check names it
    try:
        ts = _thermal_set(name, str(top.parent))
    except ParameterError as exc:
        raise ParameterError([_blame(f"clutch.spring_thermal = {name!r}: " + "; ".join(exc.problems), origin, top)],
                             str(top)) from None
    for section in ("observer", "tcu_thermal"):
        sec = data.setdefault(section, {})
        if isinstance(sec, dict):
            for key, value in (("spring_U_W_per_K", ts.U_W_per_K), ("spring_H_W_per_K", ts.H_W_per_K),
                               ("spring_C_J_per_K", ts.C_J_per_K)):
                sec.setdefault(key, value)


def load_scenario(path: str | Path = DEFAULT_SCENARIO) -> Scenario:
    """Load and check a scenario TOML file (unknown keys and bad ranges rejected, naming the file that set them).

    ``extends = "<shipped name>"`` or ``extends = "<file>"`` (relative to this file's folder) starts from that
    scenario and applies this file's values over it (:func:`merged_data`).
    """
    if not Path(path).is_file():
        raise ParameterError([f"scenario file {path} not found (shipped: {', '.join(shipped_names())})"])
    top = Path(path).resolve()
    data, origin = merged_data(top)
    data["folder"] = str(top.parent)
    _spring_thermal_defaults(data, origin, top)
    try:
        sc = build_checked(Scenario, data, str(path))
    except ParameterError as exc:
        raise ParameterError([_blame(p, origin, top) for p in exc.problems], str(path)) from None
    fr = sc.friction_path()
    if fr is not None and not fr.is_file():
        raise ParameterError([_blame(f"clutch.friction_csv = {sc.clutch.friction_csv!r}: file {fr} not found",
                                     origin, top)], str(path))
    for which in ("plant", "tcu"):
        folder = sc.tables_path(which)
        if folder is not None and not folder.is_dir():
            raise ParameterError([_blame(f"clutch.{which}_tables = {getattr(sc.clutch, which + '_tables')!r}: "
                                         f"folder {folder} not found", origin, top)], str(path))
    return sc
