"""Temperature-aware dry-clutch torque model (paper eqs. 2-5), numpy only.

One implementation of the physics, used by the FMU slave (``CushionClutch``)
and by the Python API (:mod:`cushion_clutch.model`). SI units throughout;
temperatures in K except where a name says ``_degC`` (the tables).

- Cushion-spring temperature: ``C dtheta_cs/dt = U (theta_cm - theta_cs) +
  H (theta_a - theta_cs)``, advanced with its exact solution for an input
  held over the step, so any step size is stable and exact.
- Cover (:mod:`cover`, equations there): Almen-Laszlo diaphragm spring, finger lever
  (``lever_ratio``), release compliance and the moment balance
  ``M(s) = F_pp L_pp + F_to L_b`` give the clamp force ``F_pp``, the bearing force ``F_to``
  and the cushion compression ``u`` at bearing position ``x_to``; the kiss point moves with
  the cushion's ``delta_kiss(theta_cs)`` (times the lever, as in the paper), the stack's
  thermal growth at ``theta_cm`` and ``facing_wear``. Once the cushion is solid the clamp
  force rises to the diaphragm's installed load.
- Cushion force ``F(u, theta_cs)``: shape-preserving (PCHIP, Fritsch-Carlson) cubic in u
  per table temperature, linear between temperatures; u below the table's
  first contact gives its first force (zero); temperatures outside the table are clamped.
- Torque ``T = n_surfaces mu R_eq F_pp``; ``mu`` is the parameter, or
  ``mu(theta_cm, omega_slip)`` from the table set's optional ``friction.csv``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from functools import lru_cache

try:                                    # inside the pythonfmu FMU the modules are siblings
    from .cover import CoverMap, CoverParameters, hold_problem, range_problems, wear_limit
    from .friction import FrictionTable
    from ..number_check import any_bool, is_finite_number, is_number, unit_hint
    from .spring_table import KELVIN, Curve, SpringTable, pchip_slopes
    from .table_format import load_csv
except ImportError:
    from cover import CoverMap, CoverParameters, hold_problem, range_problems, wear_limit
    from friction import FrictionTable
    from number_check import any_bool, is_finite_number, is_number, unit_hint
    from spring_table import KELVIN, Curve, SpringTable, pchip_slopes
    from table_format import load_csv

__all__ = ["KELVIN", "VARIABLES", "ClutchParameters", "CoverParameters", "CoverMap", "cover_frame", "Outputs", "SpringTable", "FrictionTable", "Curve",
           "load_csv", "pchip_slopes", "thermal_step", "friction_coefficient", "outputs", "x_to_for_torque", "kiss_point",
           "OMEGA_SLIP_START", "OMEGA_SLIP_LIMIT", "start_values", "INPUT_RANGES", "X_TO_MIN", "X_TO_MAX",
           "THETA_MIN_K", "THETA_MAX_K", "validity", "validity_warning", "table_problems", "variable_bounds",
           "range_message", "declared_ranges", "heat_path_problem", "facing_wear_max", "OUTPUT_RANGES"]

#: The FMU interface, in value-reference order: (name, causality, unit, description).
#: Both FMUs (pythonfmu and native C) expose exactly these; parameters take
#: their defaults from :class:`ClutchParameters`.
VARIABLES = (
    ("x_to", "input", "m", "throwout-bearing position, 0 = open"),
    ("theta_cm", "input", "K", "clutch facing temperature"),
    ("torque", "output", "N.m", "transmissible clutch torque n*mu*R_eq*clamp_force"),
    ("force", "output", "N", "cushion-spring force F(u, theta_cs); the clamp force is clamp_force"),
    ("theta_cs", "output", "K", "cushion-spring temperature"),
    ("u_f", "output", "m", "cushion compression from the kiss point, clipped at 0"),
    ("x_kiss", "output", "m", "kiss point at the bearing at theta_cs (u_f = 0); torque starts before it"),
    ("n_surfaces", "parameter", "1", "number of friction surfaces"),
    ("mu", "parameter", "1", "dynamic friction coefficient"),
    ("R_eq", "parameter", "m", "equivalent friction radius"),
    ("U", "parameter", "W/K", "facing-to-cushion-spring thermal conductance"),
    ("H", "parameter", "W/K", "cushion-spring-to-ambient heat transfer coefficient"),
    ("C", "parameter", "J/K", "cushion-spring heat capacity"),
    ("theta_a", "parameter", "K", "ambient temperature"),
    ("theta_cs_start", "parameter", "K", "initial cushion-spring temperature"),
    ("x_kiss_ref", "parameter", "m", "kiss point at the bearing at the table reference temperature"),
    ("lever_ratio", "parameter", "1", "diaphragm-spring lever ratio, bearing / pressure-plate travel"),
    ("omega_slip", "input", "rad/s", "clutch slip speed; selects mu from the friction table, if any"),
    ("clamp_force", "output", "N", "pressure-plate (clamp) force F_pp from the cover's force balance"),
    ("bearing_force", "output", "N", "release-bearing force F_to on the diaphragm fingers (0: lifted off)"),
    ("facing_wear", "parameter", "m", "axial wear of both facings since new (moves the kiss point and the "
                                      "diaphragm's installed deflection)"),
    # the cover (cover.CoverParameters, in its field order; the native core finds each through CC_COVER_VR, so a new
    # cover parameter is appended at the end of this table like any other)
    ("diaphragm_outer_radius_m", "parameter", "m", "diaphragm spring outer radius a"),
    ("diaphragm_inner_radius_m", "parameter", "m", "diaphragm spring inner radius b (finger roots)"),
    ("diaphragm_thickness_m", "parameter", "m", "diaphragm spring sheet thickness t"),
    ("diaphragm_cone_height_m", "parameter", "m", "diaphragm spring free cone height h between the edges"),
    ("diaphragm_youngs_modulus_Pa", "parameter", "Pa", "diaphragm Young's modulus at reference_temperature_K"),
    ("diaphragm_modulus_drop_per_K", "parameter", "1/K", "E(theta_cs) = E_ref (1 - k (theta_cs - theta_ref))"),
    ("diaphragm_poisson_ratio", "parameter", "1", "diaphragm Poisson ratio"),
    ("pressure_plate_radius_m", "parameter", "m", "diaphragm load circle on the pressure plate r_pp"),
    ("fulcrum_radius_m", "parameter", "m", "cover fulcrum (pivot ring) radius r_f"),
    ("installed_deflection_m", "parameter", "m", "diaphragm edge deflection of the closed clutch, new facings, "
                                                 "reference temperature"),
    ("release_compliance_m_per_N", "parameter", "m/N", "finger + bearing + release-system compliance"),
    ("facing_thickness_m", "parameter", "m", "both facings together (thermal growth)"),
    ("facing_expansion_per_K", "parameter", "1/K", "facings' through-thickness expansion coefficient"),
    ("pressure_plate_thickness_m", "parameter", "m", "pressure plate, friction face to diaphragm contact"),
    ("pressure_plate_expansion_per_K", "parameter", "1/K", "pressure plate expansion coefficient"),
    ("flywheel_length_m", "parameter", "m", "flywheel, cover mounting face to friction face"),
    ("flywheel_expansion_per_K", "parameter", "1/K", "flywheel expansion coefficient"),
    ("reference_temperature_K", "parameter", "K", "temperature of E_ref and of zero thermal growth"),
    # validity (issue 28): appended, so the value references above keep their numbers
    ("facing_damage_temperature_K", "parameter", "K", "facing temperature above which the facings are damaged "
                                                      "(validity = 2); seed paper: 350-400 degC"),
    ("validity", "output", "1", "0: inside the tables; 1: a temperature beyond the tables (clamped, see docs); "
                                "2: facing temperature above facing_damage_temperature_K"),
)
#: The table-set selector of an FMU that carries several spring table sets (cushion_clutch.fmu.table_sets):
#: (name, causality, unit, description) as in VARIABLES; an enumeration (one item per set), value reference
#: after the others (and after FMI 3's time), declared only when more than one set is carried.
TABLE_SET_VARIABLE = ("spring", "parameter", "1", "spring table set the model uses (fixed after initialisation)")
#: start value of the optional slip-speed input, rad/s (mu does not depend on it without a friction table)
OMEGA_SLIP_START = 0.0
#: largest |omega_slip| accepted, rad/s: 1500 rad/s = 14300 rpm, twice a passenger-car engine's speed limit
#: (the gearbox input may spin against the engine)
OMEGA_SLIP_LIMIT = 1500.0
#: bearing stroke accepted, m: 2 mm behind the open position (actuator backlash) up to 25 mm. The default cover
#: lifts the bearing off at 10.7 mm new and later with wear; at its wear limit over [THETA_MIN_K, THETA_MAX_K] the
#: stroke still leaves at least 5 mm past the latest lift-off (tests/test_validity.py measures it)
X_TO_MIN = -0.002
X_TO_MAX = 0.025
#: temperatures accepted, K: below 200 K (-73 degC) a value is taken for degC typed into a kelvin input; above
#: 800 K (527 degC) no dry-clutch facing survives (organic facings are damaged from 623 K, the seed paper; sintered
#: ones char by about 800 K), and the diaphragm's modulus, extrapolated linearly, would let a stiff cushion
#: (a tolerance study's P95 spring on a coarse mesh) push the default cover past its hold at 950 K
THETA_MIN_K = 200.0
THETA_MAX_K = 800.0


def hold_theta_cm(theta_cm: float) -> float:
    """``theta_cm`` (K) held within the model's range ``[THETA_MIN_K, THETA_MAX_K]``: what a TCU's model is
    evaluated at when its own facing estimate runs past the range (far beyond the facings' damage limit);
    a characteristic holds its last point there, and the estimate itself is kept unclamped."""
    return min(max(theta_cm, THETA_MIN_K), THETA_MAX_K)


#: the inputs' ranges: (low, high, low_open, high_open)
INPUT_RANGES = {
    "x_to": (X_TO_MIN, X_TO_MAX, False, False),
    "theta_cm": (THETA_MIN_K, THETA_MAX_K, False, False),
    "omega_slip": (-OMEGA_SLIP_LIMIT, OMEGA_SLIP_LIMIT, False, False),
}
#: the bounded outputs' ranges (the modelDescription's min/max): theta_cs lies between theta_cm and theta_a
#: (the exact solution of eq. 3), both in [THETA_MIN_K, THETA_MAX_K]
OUTPUT_RANGES = {
    "theta_cs": (THETA_MIN_K, THETA_MAX_K, False, False),
}
#: nominal values (FMI ``nominal``) where the default is 0 or not a scale: the rest use |default|
NOMINAL_OVERRIDES = {"x_to": 0.01, "theta_cm": 373.15, "omega_slip": 100.0, "facing_wear": 0.001,
                     "x_kiss_ref": 0.004, "diaphragm_modulus_drop_per_K": 1e-4}
#: validity codes of the output ``validity``
VALID, BEYOND_TABLES, ABOVE_DAMAGE = 0, 1, 2


def heat_path_problem(u_W_per_K: float, h_W_per_K: float, u_name: str = "U", h_name: str = "H",
                      key: str = "") -> str | None:
    """The rule ``U + H > 0``: None if it holds, else the message.

    Parameters
    ----------
    u_W_per_K, h_W_per_K : float
        U and H, W/K (numbers: check their ranges first).
    u_name, h_name : str
        Their names where they are given (``U``/``H`` for the FMU, ``spring_U_W_per_K``/... in a section).
    key : str
        The key the message names first (a section's ``observer.spring_H_W_per_K``); "" for none.
    """
    total = u_W_per_K + h_W_per_K
    if total > 0.0:
        return None
    if not key:
        return f"{u_name} + {h_name} must be > 0 (the cushion spring needs a heat path)"
    return f"{key}: {u_name} + {h_name} = {total:g} W/K; must be > 0 (the cushion spring needs a heat path)"


@dataclass
class ClutchParameters:
    """Clutch and thermal parameters (SI; temperatures in K)."""

    n_surfaces: float = 2.0       #: number of friction surfaces (pairs of contact), 1
    mu: float = 0.28              #: dynamic friction coefficient, 1
    R_eq: float = 0.089           #: equivalent friction radius, m
    U: float = 0.1                #: facing-to-cushion-spring conductance, W/K
    H: float = 0.04               #: cushion-spring-to-ambient transfer coefficient, W/K
    C: float = 1.0                #: cushion-spring heat capacity, J/K
    theta_a: float = 293.15       #: ambient temperature, K
    theta_cs_start: float = 293.15  #: initial cushion-spring temperature, K
    x_kiss_ref: float = 0.004     #: kiss point at the bearing at the table's reference temperature, m
    lever_ratio: float = 3.0      #: diaphragm-spring lever ratio, bearing travel / pressure-plate travel, 1
    facing_wear: float = 0.0      #: axial wear of the facings (both together) since new, m
    facing_damage_temperature_K: float = 623.15   #: facing damage above (validity 2): 350 degC, seed paper, K
    cover: CoverParameters = field(default_factory=CoverParameters)  #: diaphragm-spring cover and axial stack

    #: allowed ranges: (low, high, low_open, high_open)
    RANGES = {
        "n_surfaces": (1.0, 16.0, False, False),
        "mu": (0.0, 2.0, False, False),
        "R_eq": (0.0, 1.0, True, False),
        "U": (0.0, 1e4, False, False),
        "H": (0.0, 1e4, False, False),
        "C": (0.0, 1e6, True, False),
        "theta_a": (THETA_MIN_K, THETA_MAX_K, False, False),
        "theta_cs_start": (THETA_MIN_K, THETA_MAX_K, False, False),
        "x_kiss_ref": (-1.0, 1.0, False, False),
        "lever_ratio": (0.0, 100.0, True, False),
        "facing_wear": (0.0, 0.004, False, False),
        **CoverParameters.RANGES,
        "facing_damage_temperature_K": (373.15, THETA_MAX_K, False, False),
    }

    def flat(self) -> dict[str, float]:
        """Every parameter by its FMU name (the cover's fields are FMU parameters too)."""
        out = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "cover"}
        out.update({f.name: getattr(self.cover, f.name) for f in fields(CoverParameters)})
        return out

    @classmethod
    def from_flat(cls, values: dict[str, float]) -> "ClutchParameters":
        """The parameters from FMU names (as :meth:`flat` gives them); missing names keep their default."""
        cover_names = {f.name for f in fields(CoverParameters)}
        return cls(cover=CoverParameters(**{k: v for k, v in values.items() if k in cover_names}),
                   **{k: v for k, v in values.items() if k not in cover_names})

    def problems(self) -> list[str]:
        """Every parameter outside its allowed range, with the range."""
        out = range_problems(self, self.RANGES, {name: unit for name, _, unit, _ in VARIABLES})
        if not out and self.n_surfaces != int(self.n_surfaces):
            out.append(f"n_surfaces = {self.n_surfaces!r} must be a positive integer in [1, 16]")
        if not out and (msg := heat_path_problem(self.U, self.H)):
            out.append(msg)
        return out + self.cover.problems(self.lever_ratio if "lever_ratio" not in " ".join(out) else None)


def facing_wear_max(table: SpringTable, p: ClutchParameters | None = None) -> float:
    """The declared maximum of ``facing_wear`` with ``table``, m: the wear limit of ``p``'s cover (default: the
    default cover) over [THETA_MIN_K, THETA_MAX_K] (:func:`cover.wear_limit`, what initialisation accepts), rounded
    down to 1 um so that the C check (a second implementation of the same balance) accepts it too, and at most
    ``ClutchParameters.RANGES``' maximum; 0.0 if the cover cannot hold even new facings."""
    p = p or ClutchParameters()
    limit = wear_limit(p.cover, p.lever_ratio, table, p.x_kiss_ref, THETA_MIN_K, THETA_MAX_K)
    return min(max(math.floor(limit * 1e6) / 1e6, 0.0), ClutchParameters.RANGES["facing_wear"][1])


def declared_ranges(table: SpringTable | None = None) -> dict[str, tuple]:
    """The one range table of the FMU interface: ``(low, high, low_open, high_open)`` of every input
    (:data:`INPUT_RANGES`), parameter (``ClutchParameters.RANGES``) and bounded output (:data:`OUTPUT_RANGES`) of
    :data:`VARIABLES`, in their order. The FMUs' modelDescription min/max (:func:`variable_bounds`), their C checks
    (the generated variable table), the pythonfmu slave's checks and the docs' "allowed" column all come from it.
    With ``table`` (the FMU's table set) ``facing_wear``'s maximum is the default cover's wear limit
    (:func:`facing_wear_max`): initialisation refuses more with that cover.

    Raises
    ------
    KeyError
        Naming an input or parameter without a range.
    """
    out = {}
    for name, causality, _, _ in VARIABLES:
        if causality in ("input", "parameter") or name in OUTPUT_RANGES:
            table_ = {"input": INPUT_RANGES, "parameter": ClutchParameters.RANGES}.get(causality, OUTPUT_RANGES)
            out[name] = tuple(table_[name])
    if table is not None:
        lo, _, lo_open, hi_open = out["facing_wear"]
        out["facing_wear"] = (lo, facing_wear_max(table), lo_open, hi_open)
    return out


def variable_bounds(table: SpringTable | None = None) -> dict[str, tuple[float, float, float]]:
    """``(min, max, nominal)`` of every input, parameter and bounded output of :data:`VARIABLES` (the FMU's
    modelDescription) from :func:`declared_ranges` (``table``: the FMU's table set); an open bound is given as its
    value (FMI min/max are inclusive; the model refuses the bound itself), nominal |default| or
    :data:`NOMINAL_OVERRIDES`.

    Raises
    ------
    KeyError
        Naming an input or parameter without a range.
    """
    defaults = start_values()
    return {name: (float(lo), float(hi), float(NOMINAL_OVERRIDES.get(name, abs(defaults[name]) or 1.0)))
            for name, (lo, hi, _, _) in declared_ranges(table).items()}


def start_values(p: ClutchParameters | None = None) -> dict[str, float]:
    """Value of every variable of :data:`VARIABLES` before initialisation, in their order.

    Parameters take theirs from ``p`` (default: :class:`ClutchParameters`'s
    defaults); the inputs x_to = 0, theta_cm = theta_a and omega_slip =
    ``OMEGA_SLIP_START``; the outputs theta_cs = theta_cs_start, x_kiss =
    x_kiss_ref and 0 otherwise. Both FMUs start from these values.

    Raises
    ------
    KeyError
        Naming an input of ``VARIABLES`` that has no start value here.
    """
    p = p or ClutchParameters()
    inputs = {"x_to": 0.0, "theta_cm": p.theta_a, "omega_slip": OMEGA_SLIP_START}
    outputs_ = {"theta_cs": p.theta_cs_start, "x_kiss": p.x_kiss_ref}
    out = {}
    for name, causality, _, _ in VARIABLES:
        if causality == "parameter":
            out[name] = float(p.flat()[name])
        elif causality == "input":
            if name not in inputs:
                raise KeyError(f"input {name!r} has no start value in clutch_model.start_values")
            out[name] = float(inputs[name])
        else:
            out[name] = float(outputs_.get(name, 0.0))
    return out


#: allowed ranges of the function arguments: (low, high, low_open, high_open)
ARGUMENT_RANGES = {
    **INPUT_RANGES,
    "theta_cs": INPUT_RANGES["theta_cm"],
    "dt": (0.0, 1e9, False, False),
    "torque": (-1e9, 1e9, False, False),
    "tol_m": (0.0, 1.0, True, False),
}


def _range_text(lo: float, hi: float, lo_open: bool, hi_open: bool) -> str:
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"


#: units of the function arguments (messages)
ARGUMENT_UNITS = {"x_to": "m", "theta_cs": "K", "theta_cm": "K", "omega_slip": "rad/s", "dt": "s", "torque": "N.m",
                  "tol_m": "m"}


def range_message(name: str, value, unit: str, rng: tuple) -> str:
    """``name = value unit is outside [lo, hi] unit``, plus the hint for the likely unit mistake
    (:func:`number_check.unit_hint`: mm typed as m, degC typed as K)."""
    lo, hi, lo_open, hi_open = rng[:4]
    if isinstance(value, float):
        value = float(value)                # numpy's float64 repr would name its type
    text = f"{name} = {value!r} {unit} is outside {_range_text(lo, hi, lo_open, hi_open)} {unit}"
    hint = unit_hint(value, unit, lo, hi)
    return f"{text}: {hint}" if hint else text


def _argument_error(args: dict, p: ClutchParameters | None, names: tuple[str, ...]) -> ValueError:
    """The ValueError naming every bad argument and parameter (slow path, only on failure)."""
    problems = []
    for name, v in args.items():
        lo, hi, lo_open, hi_open = ARGUMENT_RANGES[name]
        ok = is_finite_number(v) and (v > lo if lo_open else v >= lo) and (v < hi if hi_open else v <= hi)
        if not ok:
            problems.append(range_message(name, v, ARGUMENT_UNITS.get(name, ""), (lo, hi, lo_open, hi_open)))
    if p is not None:
        # the function's own parameters (names), and, where it uses the cover (lever_ratio in names), every
        # problem of the cover: its ranges and its rules (they name their parameters, not always first)
        own = {f.name for f in fields(ClutchParameters)}
        for q in p.problems():
            first = q.split(" ", 1)[0]
            if first in names or q.startswith("U + H"):
                problems.append(f"p.{q}")
            elif "lever_ratio" in names and first not in own:
                problems.append(f"p.cover.{q}" if first in p.RANGES else f"p.cover: {q}")
    return ValueError("; ".join(problems) or f"invalid arguments {args!r}")


def thermal_step(theta_cs: float, theta_cm: float, dt: float, p: ClutchParameters) -> float:
    """Exact cushion-spring temperature after ``dt`` s with ``theta_cm`` held, K.

    Raises
    ------
    ValueError
        Naming the argument or parameter if one is not finite or outside its range
        (``dt`` in [0, 1e9] s, temperatures in [THETA_MIN_K, THETA_MAX_K] = [200, 800] K, ``C`` > 0,
        ``U + H`` > 0).
    """
    if not (THETA_MIN_K <= theta_cs <= THETA_MAX_K and THETA_MIN_K <= theta_cm <= THETA_MAX_K and 0.0 <= dt <= 1e9
            and 0.0 <= p.U <= 1e4 and 0.0 <= p.H <= 1e4 and 0.0 < p.C <= 1e6
            and THETA_MIN_K <= p.theta_a <= THETA_MAX_K and p.U + p.H > 0.0 and not any_bool(dt, p.U, p.H, p.C)):
        raise _argument_error({"theta_cs": theta_cs, "theta_cm": theta_cm, "dt": dt}, p,
                              ("U", "H", "C", "theta_a"))
    g = p.U + p.H
    theta_inf = (p.U * theta_cm + p.H * p.theta_a) / g
    return theta_inf + (theta_cs - theta_inf) * math.exp(-dt * g / p.C)


@dataclass(slots=True)
class Outputs:
    """Model outputs at one instant (SI)."""

    torque: float     #: transmissible clutch torque n mu R_eq F_pp, N.m
    force: float      #: cushion-spring force F(u, theta_cs), N
    u_f: float        #: cushion compression from the kiss point, clipped at 0, m
    x_kiss: float     #: kiss point at the bearing, m
    clamped: bool     #: theta_cs was outside the table and was clamped
    clamp_force: float = 0.0    #: pressure-plate (clamp) force F_pp from the cover's force balance, N
    bearing_force: float = 0.0  #: release-bearing force F_to, N
    validity: float = 0.0       #: 0 inside the tables, 1 beyond them, 2 facings above their damage limit (validity())


@lru_cache(maxsize=32)
def _cover_map_cached(cover: CoverParameters, lever_ratio: float) -> CoverMap:
    return CoverMap(cover, lever_ratio)


def _last_cover(slot: list, compute, cover: CoverParameters, lever_ratio: float):
    """``compute(cover, lever_ratio)``, kept in ``slot`` for the last cover object (CoverParameters is frozen,
    so its identity suffices and the dataclass hash behind ``compute``'s lru_cache is skipped)."""
    if cover is slot[0] and lever_ratio == slot[1]:
        return slot[2]
    out = compute(cover, lever_ratio)
    slot[:] = [cover, lever_ratio, out]
    return out


_LAST_MAP: list = [None, None, None]        # cover, lever ratio, map


def _cover_map(cover: CoverParameters, lever_ratio: float) -> CoverMap:
    return _last_cover(_LAST_MAP, _cover_map_cached, cover, lever_ratio)


#: frames kept (exact keys; all dropped when full): the TCUs evaluate a few temperature pairs per control cycle
FRAME_CACHE_SIZE = 64
_FRAMES: dict = {}
_FRAMES_OWNER: list = [None, None]      # the table and cover the kept frames belong to


def cover_frame(table: SpringTable, p: ClutchParameters, theta_cs: float, theta_cm: float):
    """The cover's force balance at ``theta_cs``, ``theta_cm`` (K) and ``p.facing_wear``.

    Kept for the last :data:`FRAME_CACHE_SIZE` exact (lever ratio, x_kiss_ref, wear, theta_cs, theta_cm) of the
    last table and cover: a frame depends on these alone, so the answer never depends on what was asked before.

    Raises
    ------
    ValueError
        If the diaphragm cannot hold the cushion at this temperature and wear.
    """
    key = (p.lever_ratio, p.x_kiss_ref, p.facing_wear, theta_cs, theta_cm)
    if _FRAMES_OWNER[0] is table and _FRAMES_OWNER[1] is p.cover:
        frame = _FRAMES.get(key)
        if frame is not None:
            return frame
    else:
        _FRAMES.clear()
        _FRAMES_OWNER[:] = [table, p.cover]
    frame = _cover_map(p.cover, p.lever_ratio).prepare(theta_cs, theta_cm, p.facing_wear, table, p.x_kiss_ref)
    if len(_FRAMES) >= FRAME_CACHE_SIZE:
        _FRAMES.clear()
    _FRAMES[key] = frame
    return frame


#: the parameters that outputs() and x_to_for_torque() use
CLUTCH_PARAMETERS = ("n_surfaces", "mu", "R_eq", "x_kiss_ref", "lever_ratio", "facing_wear")


def _clutch_ok(p: ClutchParameters) -> bool:
    """Cheap range check of the parameters in CLUTCH_PARAMETERS (False for NaN)."""
    return (1.0 <= p.n_surfaces <= 16.0 and p.n_surfaces == int(p.n_surfaces) and 0.0 <= p.mu <= 2.0
            and 0.0 < p.R_eq <= 1.0 and -1.0 <= p.x_kiss_ref <= 1.0 and 0.0 < p.lever_ratio <= 100.0
            and 0.0 <= p.facing_wear <= 0.004 and not any_bool(*(getattr(p, n) for n in CLUTCH_PARAMETERS))
            and not _cover_problems(p.cover, p.lever_ratio))


_LAST_HOLD: list = [None, None, None, None]     # table, cover, (lever, x_kiss_ref, wear), problem


def table_problems(table: SpringTable, p: ClutchParameters) -> list[str]:
    """The rules the parameters break together with the table: the diaphragm must hold the fully compressed
    cushion at ``p.facing_wear`` for every temperature pair in [THETA_MIN_K, THETA_MAX_K] (:func:`cover.hold_problem`,
    the message names the wear limit). Cached for the last table, cover and wear. Assumes ``p.problems()`` is empty."""
    key = (p.lever_ratio, p.x_kiss_ref, p.facing_wear)
    if not (_LAST_HOLD[0] is table and (_LAST_HOLD[1] is p.cover or _LAST_HOLD[1] == p.cover)
            and _LAST_HOLD[2] == key):
        problem = hold_problem(p.cover, p.lever_ratio, table, p.x_kiss_ref, p.facing_wear, THETA_MIN_K, THETA_MAX_K)
        _LAST_HOLD[:] = [table, p.cover, key, problem]
    return [] if _LAST_HOLD[3] is None else [_LAST_HOLD[3]]


def _check_table_parameters(table: SpringTable, p: ClutchParameters) -> None:
    problems = table_problems(table, p)
    if problems:
        raise ValueError("p: " + "; ".join(problems))


_CHECKED: list = [None, None, None]     # table, cover, values of CLUTCH_PARAMETERS that passed every check


def _parameters_checked(table: SpringTable, p: ClutchParameters) -> tuple | None:
    """None if ``p`` (CLUTCH_PARAMETERS and its cover) passed :func:`_clutch_ok` and :func:`table_problems` with
    ``table`` in the last check, else the key to record with :func:`_passed` once they do (exact values: a NaN
    never matches)."""
    key = (p.n_surfaces, p.mu, p.R_eq, p.x_kiss_ref, p.lever_ratio, p.facing_wear)
    if _CHECKED[0] is table and _CHECKED[1] is p.cover and _CHECKED[2] == key:
        return None
    return key


def _passed(table: SpringTable, p: ClutchParameters, key: tuple) -> None:
    _CHECKED[:] = [table, p.cover, key]


def validity(theta_cs: float, theta_cm: float | None, table: SpringTable, p: ClutchParameters) -> int:
    """The ``validity`` output: 2 if the facings (``theta_cm``, K) are above ``p.facing_damage_temperature_K``,
    else 1 if ``theta_cs`` (K) is outside the cushion table's temperatures (or ``theta_cm`` outside the friction
    table's, if the set has one), else 0. The model answers in all three (clamped tables, module docstring)."""
    if theta_cm is not None and theta_cm > p.facing_damage_temperature_K:
        return ABOVE_DAMAGE
    if not table.theta_min_K <= theta_cs <= table.theta_max_K:
        return BEYOND_TABLES
    fr = table.friction
    if fr is not None and theta_cm is not None and not (
            float(fr.theta_degC[0]) + KELVIN <= theta_cm <= float(fr.theta_degC[-1]) + KELVIN):
        return BEYOND_TABLES
    return VALID


def validity_warning(previous: int, current: int, theta_cs: float, theta_cm: float | None, table: SpringTable,
                     p: ClutchParameters) -> str | None:
    """The warning to log when ``validity`` changes from ``previous`` to a non-zero ``current`` (once per entry
    into a region), else None."""
    if current == previous or current == VALID:
        return None
    if current == ABOVE_DAMAGE:
        return (f"facing temperature theta_cm = {theta_cm:.2f} K is above facing_damage_temperature_K = "
                f"{p.facing_damage_temperature_K:.2f} K: the facings are being damaged; the model keeps answering "
                "with clamped tables (validity = 2)")
    return (f"temperature beyond the tables: theta_cs = {theta_cs:.2f} K (table [{table.theta_min_K:.2f}, "
            f"{table.theta_max_K:.2f}] K){'' if theta_cm is None else f', theta_cm = {theta_cm:.2f} K'}; F, the kiss "
            "shift and mu are clamped to the nearest table temperature (validity = 1; warned once per entry)")


@lru_cache(maxsize=32)
def _cover_problems_cached(cover: CoverParameters, lever_ratio: float) -> tuple[str, ...]:
    return tuple(cover.problems(lever_ratio))


_LAST_PROBLEMS: list = [None, None, ()]     # cover, lever ratio, problems


def _cover_problems(cover: CoverParameters, lever_ratio: float) -> tuple[str, ...]:
    return _last_cover(_LAST_PROBLEMS, _cover_problems_cached, cover, lever_ratio)


def friction_coefficient(table: SpringTable, p: ClutchParameters, theta_cm: float | None,
                         omega_slip: float) -> float:
    """mu: the parameter, or the table's ``friction(theta_cm, |omega_slip|)`` if it has one.

    ``theta_cm`` is the facing temperature (K); it is required when the table
    set carries a friction table.
    """
    if table.friction is None:
        return p.mu
    if theta_cm is None:
        raise ValueError("theta_cm (K) is required: this table set has a friction table mu(theta_cm, omega_slip)")
    return table.friction(theta_cm - KELVIN, omega_slip)


def outputs(x_to: float, theta_cs: float, table: SpringTable, p: ClutchParameters,
            theta_cm: float | None = None, omega_slip: float = OMEGA_SLIP_START) -> Outputs:
    """Torque and forces from bearing position ``x_to`` (m) and ``theta_cs`` (K).

    The clamp force comes from the cover's force balance (:mod:`cover`): the cushion
    force while the cushion compresses, then up to the diaphragm's installed load.
    ``theta_cm`` (K, the facing temperature; None: ``theta_cs``) sets the stack's thermal
    growth and, with ``omega_slip`` (rad/s), mu when the table set has a friction table;
    otherwise mu is ``p.mu``.

    Raises
    ------
    ValueError
        Naming the argument or parameter if one is not finite or outside its range.
    """
    key = _parameters_checked(table, p)
    if not (X_TO_MIN <= x_to <= X_TO_MAX and THETA_MIN_K <= theta_cs <= THETA_MAX_K
            and -OMEGA_SLIP_LIMIT <= omega_slip <= OMEGA_SLIP_LIMIT and not any_bool(x_to, omega_slip)
            and (theta_cm is None or THETA_MIN_K <= theta_cm <= THETA_MAX_K) and (key is None or _clutch_ok(p))):
        raise _argument_error({"x_to": x_to, "theta_cs": theta_cs, "omega_slip": omega_slip,
                               **({} if theta_cm is None else {"theta_cm": theta_cm})}, p, CLUTCH_PARAMETERS)
    if key is not None:
        _check_table_parameters(table, p)
        _passed(table, p, key)
    st = cover_frame(table, p, theta_cs, theta_cs if theta_cm is None else theta_cm).state(x_to)
    clamped = not (table.theta_min_K <= theta_cs <= table.theta_max_K)
    mu = friction_coefficient(table, p, theta_cm, omega_slip)
    return Outputs(p.n_surfaces * mu * p.R_eq * st.clamp_force, st.cushion_force, max(st.u, 0.0), st.x_kiss, clamped,
                   st.clamp_force, st.bearing_force, float(validity(theta_cs, theta_cm, table, p)))


def kiss_point(theta_cs: float, table: SpringTable, p: ClutchParameters, theta_cm: float | None = None) -> float:
    """Kiss point at the bearing (m) at ``theta_cs`` and ``theta_cm`` (K; None: ``theta_cs``).

    The same value as ``outputs(x_to, ...).x_kiss`` for any ``x_to``, without solving the
    cover's balance: the kiss point depends on the temperatures and the wear alone. It does
    not check that the diaphragm holds the fully compressed cushion (:func:`outputs` does).
    The kiss point is where the cushion carries its kiss force (u_f = 0), not where torque begins:
    the first contact, the torque onset, is ``x_to_for_torque(0.0, theta_cs, table, p, theta_cm=theta_cm)``,
    earlier by the cushion's travel from first contact to the kiss force times the lever.

    Raises
    ------
    ValueError
        Naming the argument or parameter if one is not finite or outside its range.
    """
    if not (THETA_MIN_K <= theta_cs <= THETA_MAX_K and (theta_cm is None or THETA_MIN_K <= theta_cm <= THETA_MAX_K)
            and _clutch_ok(p)):
        raise _argument_error({"theta_cs": theta_cs, **({} if theta_cm is None else {"theta_cm": theta_cm})}, p,
                              CLUTCH_PARAMETERS)
    return _cover_map(p.cover, p.lever_ratio).x_kiss(theta_cs, theta_cs if theta_cm is None else theta_cm,
                                                     p.facing_wear, table, p.x_kiss_ref)


def x_to_for_torque(torque: float, theta_cs: float, table: SpringTable, p: ClutchParameters,
                    tol_m: float = 1e-12, theta_cm: float | None = None,
                    omega_slip: float = OMEGA_SLIP_START) -> float:
    """Bearing position (m) giving ``torque`` (N.m) at ``theta_cs`` (K): the TCU's inverse.

    The clamp force is non-decreasing in x_to, so the smallest position reaching the torque
    is found explicitly from the cover's balance (the cushion table inverted by bisection).
    A torque at or below zero returns the first-contact position; above the closed capacity,
    the position where the bearing lifts off. ``theta_cm`` (K) and ``omega_slip`` (rad/s) as in
    :func:`outputs`.

    Raises
    ------
    ValueError
        Naming the argument or parameter if one is not finite or outside its range
        (``torque`` in [-1e9, 1e9] N.m).
    """
    key = _parameters_checked(table, p)
    if not (-1e9 <= torque <= 1e9 and THETA_MIN_K <= theta_cs <= THETA_MAX_K and 0.0 < tol_m <= 1.0
            and -OMEGA_SLIP_LIMIT <= omega_slip <= OMEGA_SLIP_LIMIT and not any_bool(torque, tol_m, omega_slip)
            and (theta_cm is None or THETA_MIN_K <= theta_cm <= THETA_MAX_K) and (key is None or _clutch_ok(p))):
        raise _argument_error({"torque": torque, "theta_cs": theta_cs, "tol_m": tol_m, "omega_slip": omega_slip,
                               **({} if theta_cm is None else {"theta_cm": theta_cm})}, p, CLUTCH_PARAMETERS)
    if key is not None:
        _check_table_parameters(table, p)
        _passed(table, p, key)
    gain = p.n_surfaces * friction_coefficient(table, p, theta_cm, omega_slip) * p.R_eq
    frame = cover_frame(table, p, theta_cs, theta_cs if theta_cm is None else theta_cm)
    return frame.x_for_clamp(torque / gain if gain > 0.0 else 0.0, tol_m)
