"""Populations of vehicles, drivers and clutches for the fleet study (:mod:`.fleet`): TOML, checked on load.

A population extends a launch scenario (``scenario``: a shipped name or a file) and draws, per sample, one
vehicle, driver and clutch from distributions; each sample is a sequence of ``launches`` launches of the
scenario with the drawn values. The drawn quantities (SI unless a name says otherwise):

=========================  ==============================================================================
key                        what a sample sets in the scenario
=========================  ==============================================================================
``mass_kg``                ``vehicle.mass_kg`` (car and load, without a trailer)
``trailer``                with ``probability`` a trailer: its ``mass_kg`` (a distribution) added to the
                           vehicle's mass, ``drag_area_m2`` added to its drag area
``grade_percent``          ``vehicle.slope_percent``
``ambient_degC``           ``facing.ambient_degC``
``start_above_ambient_K``  ``facing.initial_degC = ambient + this`` (0: a soaked clutch; a physical
                           coupling: the start temperature follows the ambient)
``pedal``                  the driver's throttle: every launch of the sample at this pedal (``hard``)
``interval_s``             ``run.period_s``, the time from one launch's start to the next
``kiss_offset_m``          ``clutch.x_kiss_offset_m`` (the spring's kiss-point tolerance, at the bearing)
``facing_wear_m``          ``clutch.facing_wear_m`` (the TCUs believe new facings)
``spring``                 ``sets``: table sets with weights, each ``plant_tables``/``tcu_tables``
                           ("" = the scenario's; relative to the population file's folder)
=========================  ==============================================================================

and the noise seeds of the speed sensors (``sensors.seed``) and of the production TCU's sensors
(``tcu_sensors.seed``), drawn from the sample's random stream.

A distribution is a table: ``{distribution = "fixed", value = v}``, ``"uniform"`` (``low``, ``high``),
``"triangular"`` (``low``, ``mode``, ``high``) or ``"normal"`` (``mean``, ``sd``, truncated to ``low``,
``high``). ``[correlation]`` gives rank correlations (a Gaussian copula) between the continuous draws, as
``"mass_kg:pedal" = 0.4``; the matrix must be positive definite.

Sample ``i`` of seed ``s`` draws from its own stream ``numpy.random.default_rng([s, i])``: the same sample
is the same whatever other samples run, in which order or on which worker.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

from statistics import NormalDist

import numpy as np

from ...config import load_toml, range_problem
from ...errors import ParameterError
from ..scenario.load import Scenario, load_scenario, scenario_path

_PHI = NormalDist()
#: the folder of the shipped populations
POPULATIONS = Path(__file__).parent.parent / "populations"

#: continuous draws: key -> (allowed low, allowed high) of the values
CONTINUOUS = {"mass_kg": (300.0, 60000.0), "grade_percent": (-30.0, 30.0), "ambient_degC": (-50.0, 60.0),
              "start_above_ambient_K": (0.0, 300.0), "pedal": (0.05, 1.0), "interval_s": (14.0, 3600.0),
              "kiss_offset_m": (-0.005, 0.005), "facing_wear_m": (0.0, 0.004), "trailer_mass_kg": (0.0, 30000.0)}
KINDS = {"fixed": ("value",), "uniform": ("low", "high"), "triangular": ("low", "mode", "high"),
         "normal": ("mean", "sd", "low", "high")}
TOP_KEYS = {"name", "description", "scenario", "launches", "trailer", "spring", "correlation",
            *(k for k in CONTINUOUS if k != "trailer_mass_kg")}


@dataclass(frozen=True)
class Dist:
    """One distribution: ``kind`` and its parameters (``a``, ``b``, ``c``, ``d`` as in :data:`KINDS`)."""

    kind: str
    params: tuple[float, ...]

    def ppf(self, u: float) -> float:
        """The value at the probability ``u`` in (0, 1) (inverse CDF)."""
        p = self.params
        if self.kind == "fixed":
            return p[0]
        if self.kind == "uniform":
            return p[0] + u * (p[1] - p[0])
        if self.kind == "triangular":
            lo, mode, hi = p
            if hi == lo:
                return lo
            f = (mode - lo) / (hi - lo)
            return (lo + math.sqrt(u * (hi - lo) * (mode - lo)) if u < f
                    else hi - math.sqrt((1.0 - u) * (hi - lo) * (hi - mode)))
        mean, sd, lo, hi = p
        a, b = _PHI.cdf((lo - mean) / sd), _PHI.cdf((hi - mean) / sd)
        q = min(max(a + u * (b - a), 1e-15), 1.0 - 1e-15)
        return float(min(max(mean + sd * _PHI.inv_cdf(q), lo), hi))     # the bounds against round-off

    @property
    def bounds(self) -> tuple[float, float]:
        """(lowest, highest) value it draws."""
        p = self.params
        if self.kind == "fixed":
            return p[0], p[0]
        return (p[0], p[1]) if self.kind == "uniform" else (p[0], p[2]) if self.kind == "triangular" else (p[2], p[3])


@dataclass(frozen=True)
class SpringSet:
    """A spring tolerance class: its table sets and weight."""

    name: str
    weight: float
    plant_tables: str
    tcu_tables: str


@dataclass(frozen=True)
class Population:
    """A checked population (see the module's docstring)."""

    name: str
    description: str
    scenario: Scenario
    launches: int
    dists: dict
    trailer_probability: float
    trailer_mass: Dist
    trailer_drag_area_m2: float
    springs: tuple[SpringSet, ...]
    correlation: dict
    folder: str
    source: str


def _dist(key: str, value, problems: list[str]) -> Dist | None:
    if not isinstance(value, dict):
        problems.append(f"{key} = {value!r}: must be a table {{distribution = ..., ...}}")
        return None
    kind = value.get("distribution")
    if kind not in KINDS:
        problems.append(f"{key}.distribution = {kind!r}: allowed {', '.join(KINDS)}")
        return None
    need = KINDS[kind]
    for extra in sorted(set(value) - {"distribution", *need}):
        problems.append(f"{key}.{extra}: unknown key (a {kind} distribution has {', '.join(need)})")
    lo, hi = CONTINUOUS[key.split(".")[-1] if key != "trailer.mass_kg" else "trailer_mass_kg"]
    params = []
    for name in need:
        v = value.get(name)
        if v is None:
            problems.append(f"{key}.{name}: missing (a {kind} distribution needs {', '.join(need)})")
            return None
        bound = (1e-12 * max(abs(lo), abs(hi), 1.0), hi - lo) if name == "sd" else (lo, hi)
        msg = range_problem(f"{key}.{name}", v, *bound)
        if msg:
            problems.append(msg)
            return None
        params.append(float(v))
    order = {"uniform": (0, 1), "triangular": (0, 1, 2), "normal": (2, 3)}.get(kind, ())
    vals = [params[i] for i in order]
    if vals != sorted(vals):
        problems.append(f"{key}: need " + " <= ".join(need[i] for i in order) + f" (got {vals})")
        return None
    if kind == "normal" and not params[2] <= params[0] <= params[3]:
        problems.append(f"{key}.mean = {params[0]!r}: must lie in [low, high] = [{params[2]}, {params[3]}]")
        return None
    return Dist(kind, tuple(params))


def population_path(name: str | Path) -> Path:
    """A population file: ``name`` itself, or the shipped ``<name>.toml``."""
    path = Path(name)
    shipped = POPULATIONS / f"{name}.toml"
    return shipped if not path.is_file() and path.suffix == "" and shipped.is_file() else path


def shipped_populations() -> list[str]:
    return sorted(p.stem for p in POPULATIONS.glob("*.toml"))


def load_population(path: str | Path) -> Population:
    """Load and check a population TOML: every problem (unknown key, bad range) is named at once.

    Raises
    ------
    ParameterError
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError([f"population file {path} not found (shipped: {', '.join(shipped_populations())})"])
    data = load_toml(path)
    problems: list[str] = []
    for key in sorted(set(data) - TOP_KEYS):
        problems.append(f"{key}: unknown key (allowed: {', '.join(sorted(TOP_KEYS))})")
    sc_name = data.get("scenario", "default")
    sc = None
    if not isinstance(sc_name, str) or not sc_name:
        problems.append(f"scenario = {sc_name!r}: must be a shipped scenario name or a scenario file")
    else:
        sp = Path(sc_name)
        sp = sp if sp.is_absolute() or not (path.parent / sp).is_file() else path.parent / sp
        try:
            sc = load_scenario(scenario_path(sp))
        except ParameterError as exc:
            problems += [f"scenario {sc_name!r}: {p}" for p in exc.problems]
    launches = data.get("launches", 5)
    if isinstance(launches, bool) or not isinstance(launches, int) or not 1 <= launches <= 1000:
        problems.append(f"launches = {launches!r}: must be an integer in [1, 1000]")
    dists = {}
    for key in CONTINUOUS:
        if key in data:
            d = _dist(key, data[key], problems)
            if d is not None:
                dists[key] = d
    trailer = data.get("trailer", {})
    t_prob, t_mass, t_drag = 0.0, Dist("fixed", (0.0,)), 0.0
    if not isinstance(trailer, dict):
        problems.append(f"trailer = {trailer!r}: must be a table")
    else:
        for extra in sorted(set(trailer) - {"probability", "mass_kg", "drag_area_m2"}):
            problems.append(f"trailer.{extra}: unknown key (allowed: probability, mass_kg, drag_area_m2)")
        t_prob = trailer.get("probability", 0.0)
        msg = range_problem("trailer.probability", t_prob, 0.0, 1.0)
        if msg:
            problems.append(msg)
        t_drag = trailer.get("drag_area_m2", 0.0)
        msg = range_problem("trailer.drag_area_m2", t_drag, 0.0, 20.0)
        if msg:
            problems.append(msg)
        if "mass_kg" in trailer:
            t_mass = _dist("trailer.mass_kg", trailer["mass_kg"], problems) or t_mass
        elif t_prob:
            problems.append("trailer.mass_kg: missing (a distribution of the trailer's mass)")
    springs = _springs(data.get("spring", {}), path, problems)
    corr = _correlation(data.get("correlation", {}), dists, problems)
    for key in ("name", "description"):
        if key in data and not isinstance(data[key], str):
            problems.append(f"{key} = {data[key]!r}: must be a string")
    if problems:
        raise ParameterError(problems, str(path))
    return Population(data.get("name", path.stem), data.get("description", ""), sc, launches, dists,
                      float(t_prob), t_mass, float(t_drag), springs, corr, str(path.parent.resolve()),
                      path.read_text())


def _springs(spring, path: Path, problems: list[str]) -> tuple[SpringSet, ...]:
    if not isinstance(spring, dict):
        problems.append(f"spring = {spring!r}: must be a table with sets = [...]")
        return (SpringSet("scenario", 1.0, "", ""),)
    for extra in sorted(set(spring) - {"sets"}):
        problems.append(f"spring.{extra}: unknown key (allowed: sets)")
    sets = spring.get("sets", [{"name": "scenario", "weight": 1.0}])
    out = []
    if not isinstance(sets, list) or not sets:
        problems.append(f"spring.sets = {sets!r}: must be a non-empty list of tables")
        return (SpringSet("scenario", 1.0, "", ""),)
    for i, s in enumerate(sets):
        key = f"spring.sets[{i}]"
        if not isinstance(s, dict):
            problems.append(f"{key} = {s!r}: must be a table (name, weight, plant_tables, tcu_tables)")
            continue
        for extra in sorted(set(s) - {"name", "weight", "plant_tables", "tcu_tables"}):
            problems.append(f"{key}.{extra}: unknown key (allowed: name, weight, plant_tables, tcu_tables)")
        w = s.get("weight", 1.0)
        msg = range_problem(f"{key}.weight", w, 0.0, 1e6, lo_open=True)
        if msg:
            problems.append(msg)
            continue
        folders = []
        for which in ("plant_tables", "tcu_tables"):
            v = s.get(which, "")
            if not isinstance(v, str):
                problems.append(f"{key}.{which} = {v!r}: must be a folder name or \"\"")
                v = ""
            if v:
                full = Path(v) if Path(v).is_absolute() else path.parent / v
                if not full.is_dir():
                    problems.append(f"{key}.{which} = {v!r}: folder {full} not found")
                v = str(full.resolve())
            folders.append(v)
        name = s.get("name", f"set{i}")
        if not isinstance(name, str) or not name:
            problems.append(f"{key}.name = {name!r}: must be a non-empty string")
            name = f"set{i}"
        out.append(SpringSet(name, float(w), *folders))
    names = [s.name for s in out]
    if len(set(names)) != len(names):
        problems.append(f"spring.sets: names must differ ({', '.join(names)})")
    return tuple(out) or (SpringSet("scenario", 1.0, "", ""),)


def _correlation(corr, dists: dict, problems: list[str]) -> dict:
    if not isinstance(corr, dict):
        problems.append(f"correlation = {corr!r}: must be a table of \"a:b\" = rho")
        return {}
    out = {}
    for key, rho in corr.items():
        a, _, b = key.partition(":")
        if a not in dists or b not in dists or a == b:
            problems.append(f"correlation.{key!r}: must name two different drawn keys as \"a:b\" "
                            f"(drawn: {', '.join(dists)})")
            continue
        msg = range_problem(f"correlation.{key!r}", rho, -1.0, 1.0, True, True)
        if msg:
            problems.append(msg)
            continue
        out[(a, b)] = float(rho)
    if out:
        keys = list(dists)
        m = np.eye(len(keys))
        for (a, b), rho in out.items():
            i, j = keys.index(a), keys.index(b)
            m[i, j] = m[j, i] = rho
        if np.linalg.eigvalsh(m).min() <= 1e-9:
            problems.append("correlation: the matrix is not positive definite")
    return out


@dataclass(frozen=True)
class Sample:
    """The drawn values of one sample (what :func:`sample_scenario` sets)."""

    sample: int
    mass_kg: float
    trailer: bool
    trailer_mass_kg: float
    grade_percent: float
    ambient_degC: float
    start_degC: float
    pedal: float
    interval_s: float
    kiss_offset_m: float
    facing_wear_m: float
    spring: str
    sensor_seed: int
    tcu_seed: int


def draw(pop: Population, seed: int, i: int) -> Sample:
    """Sample ``i`` of the population with ``seed`` (its own random stream)."""
    rng = np.random.default_rng([int(seed), int(i)])
    keys = list(pop.dists)
    z = rng.standard_normal(len(keys))
    if pop.correlation:
        m = np.eye(len(keys))
        for (a, b), rho in pop.correlation.items():
            ia, ib = keys.index(a), keys.index(b)
            m[ia, ib] = m[ib, ia] = rho
        z = np.linalg.cholesky(m) @ z
    vals = {k: pop.dists[k].ppf(min(max(_PHI.cdf(float(z[n])), 1e-12), 1.0 - 1e-12)) for n, k in enumerate(keys)}
    sc = pop.scenario
    trailer = bool(rng.random() < pop.trailer_probability)
    t_mass = pop.trailer_mass.ppf(float(rng.random())) if trailer else 0.0
    weights = np.array([s.weight for s in pop.springs])
    spring = pop.springs[int(np.searchsorted(np.cumsum(weights) / weights.sum(), rng.random(), side="right"))
                         if len(pop.springs) > 1 else 0]
    seeds = rng.integers(0, 2 ** 31 - 1, size=2)
    ambient = vals.get("ambient_degC", sc.facing.ambient_degC)
    return Sample(int(i), vals.get("mass_kg", sc.vehicle.mass_kg), trailer, t_mass,
                  vals.get("grade_percent", sc.vehicle.slope_percent), ambient,
                  ambient + vals["start_above_ambient_K"] if "start_above_ambient_K" in vals
                  else sc.facing.initial_degC,
                  vals.get("pedal", sc.driver.hard_pedal), vals.get("interval_s", sc.run.period_s),
                  vals.get("kiss_offset_m", sc.clutch.x_kiss_offset_m),
                  vals.get("facing_wear_m", sc.clutch.facing_wear_m), spring.name, int(seeds[0]), int(seeds[1]))


def sample_scenario(pop: Population, s: Sample) -> Scenario:
    """The population's scenario with the sample's values (checked like any scenario)."""
    sc = pop.scenario
    r = dataclasses.replace
    spring = next(x for x in pop.springs if x.name == s.spring)
    clutch = r(sc.clutch, x_kiss_offset_m=s.kiss_offset_m, facing_wear_m=s.facing_wear_m,
               plant_tables=spring.plant_tables or sc.clutch.plant_tables,
               tcu_tables=spring.tcu_tables or sc.clutch.tcu_tables)
    if spring.plant_tables or spring.tcu_tables:          # absolute folders, the scenario's others kept
        clutch = r(clutch, plant_tables=spring.plant_tables or str(sc.tables_path("plant") or ""),
                   tcu_tables=spring.tcu_tables or str(sc.tables_path("tcu") or ""))
    return r(sc, name=f"{pop.name}#{s.sample}",
             vehicle=r(sc.vehicle, mass_kg=s.mass_kg + s.trailer_mass_kg, slope_percent=s.grade_percent,
                       drag_area_m2=sc.vehicle.drag_area_m2 + (pop.trailer_drag_area_m2 if s.trailer else 0.0)),
             facing=r(sc.facing, ambient_degC=s.ambient_degC, initial_degC=s.start_degC),
             driver=r(sc.driver, levels=("hard",), hard_pedal=s.pedal),
             run=r(sc.run, launches=pop.launches, period_s=s.interval_s, cool_launches=0),
             clutch=clutch,
             sensors=r(sc.sensors, seed=s.sensor_seed),
             tcu_sensors=r(sc.tcu_sensors, seed=s.tcu_seed))
