"""Cover assembly of a push-type diaphragm clutch: Almen-Laszlo diaphragm, finger lever, clamp load.

Pure Python (math only): the pythonfmu slave, the Python API and the native C core
(``clutch_core.c``, ``cc_cover_*``) implement exactly these equations; the native FMU is
tested against this module.

Geometry and symbols (SI)
-------------------------
Diaphragm (Belleville) section: outer radius ``a``, inner radius ``b`` (finger roots),
thickness ``t``, free cone height ``h`` (between the edges), Young's modulus ``E(theta)``,
Poisson ratio ``nu``. Load circles: pressure-plate contact ``r_pp`` and cover fulcrum ``r_f``
with ``b <= r_f < r_pp <= a``; the fingers carry the release bearing at
``r_b = r_f - i (r_pp - r_f)`` (``i`` = ``lever_ratio``, rigid-finger bearing travel per
pressure-plate travel, paper: 3). Arms ``L_pp = r_pp - r_f``, ``L_b = r_f - r_b = i L_pp``,
``e = a - b``.

1. Almen-Laszlo (the section turns rigidly about its neutral circle by ``psi``; the edge
   deflection from the free cone is ``s = e psi``)::

       F_AL(s) = 4 E / (1 - nu^2) * t^4 / (K1 D_e^2) * (s/t) * [(h/t - s/t)(h/t - s/(2t)) + 1]
       K1 = (1/pi) ((delta - 1)/delta)^2 / ((delta + 1)/(delta - 1) - 2/ln(delta)),
       delta = a/b,  D_e = 2a.

   ``F_AL`` is the force of a pair of edge loads; the elastic moment of the section is
   ``M(s) = F_AL(s) e`` (virtual work: ``F_AL ds = M dpsi``). With ``h/t < 2 sqrt(2)`` the
   valley force stays positive (``min (h-s)(h-s/2) = -h^2/8``).
2. Moment balance of the diaphragm about the fulcrum circle (pressure-plate reaction ``F_pp``
   at ``r_pp``, bearing force ``F_to`` at ``r_b``, both turning it the same way)::

       M(s) = F_pp L_pp + F_to L_b.

   The fulcrum carries ``F_pp - F_to``. Open clutch: ``F_pp = 0``, ``F_to = M/L_b`` (the release
   force, with the diaphragm's rise-peak-fall shape). Closed, bearing lifted: ``F_pp = M/L_pp``.
3. Pressure-plate kinematics. The plate moves ``L_pp/e`` per unit of ``s``. Its kiss point and
   its solid (cushion fully compressed) position, in ``s``::

       s_kiss(theta, w)  = s_inst + (u_full(theta_ref) + Delta_stack(theta) - w) e / L_pp
       s_solid(theta, w) = s_kiss - u_full(theta) e / L_pp
       Delta_stack = delta_kiss(theta_cs) + growth_facing + growth_pp + growth_flywheel
       u(s) = (s_kiss - s) L_pp / e   (cushion compression from its kiss point, s >= s_solid)

   ``s_inst`` (``installed_deflection_m``) is the diaphragm deflection of the closed clutch
   with new facings at the reference temperature; ``w`` is the facing wear (total axial loss
   of the facings). Growth, wear and the cushion's free-height growth ``delta_kiss`` all move
   the pressure plate's kiss and solid positions, hence both the kiss point at the bearing and
   the diaphragm's installed deflection (so the closed clamp load). Thermal growth is
   ``alpha_k L_k (theta_cm - theta_ref)`` for the facings, the pressure plate and the
   flywheel, all taken at the facing temperature ``theta_cm`` (an upper bound: the bulk of the
   plates lags the friction interface); ``delta_kiss`` and ``E`` use ``theta_cs``, the model's
   slow thermal node (the diaphragm sits in the cover, away from the interface).
4. Cushion phase (``s_solid <= s``): ``F_pp = F_c(u(s), theta_cs)`` (the FE table; paper
   Fig. 2: ``F_pp(x_to) = F_fc(u_f)``) and ``F_to = (M(s) - F_pp L_pp) / L_b``.
5. Bearing kinematics with release-system compliance ``c`` (fingers + bearing + hydraulics,
   m/N, in series)::

       x_to = X_c - (L_b/e) s - c F_to(s)

   ``x_to`` = bearing travel from the open position towards engagement; ``X_c`` is fixed by
   ``x_kiss_ref``: the kiss point (``u = 0``) lies at ``x_to = x_kiss_ref`` at the reference
   state (``delta_kiss = 0``, no growth, no wear, ``E = E_ref``). With ``c = 0`` this is the
   paper's constant lever, ``x_pp = x_to / i``. ``x_to(s)`` decreases strictly if
   ``L_b/e + c e min F_AL'/L_b > 0`` (``min F_AL'`` at ``s = h``); otherwise the release snaps
   through and the parameters are refused.
6. Solid phase (``x_to >= x_solid = x_to(s_solid)``): the plate cannot move, ``s = s_solid``;
   ``F_to = max(0, F_to(s_solid) - (x_to - x_solid)/c)`` falls to zero (the bearing lifts off)
   and ``F_pp = (M(s_solid) - F_to L_b)/L_pp`` rises continuously from the cushion's
   full-compression force to the diaphragm's installed load ``M(s_solid)/L_pp``. (``c = 0``:
   the step is immediate.) The torque is then ``n mu R_eq F_pp``, non-decreasing in ``x_to``.

The forward map (``x_to`` -> ``s``) is solved by a safeguarded Newton iteration on ``s``
bracketed by ``[s_solid, s_rigid]`` (``s_rigid`` = the ``c = 0`` answer), started from the chord
between the kiss and solid points; the inverse (clamp force -> ``x_to``) is explicit once the
cushion table is inverted for ``u``: a bracketed Newton iteration on ``u`` started from each table
curve's own inverse (its cubic solved in the interval where the force is reached), blended as the
curves are. Both starts depend on the inputs only; a frame (everything that depends on the
temperatures and the wear) is kept by the exact inputs (``clutch_model.cover_frame``), so an answer
never depends on the calls before it (``tests/test_cover_exact.py``).

7. What the cover can hold (:func:`hold_problem`, :func:`wear_limit`). The balance needs
   ``F_to >= 0`` while the cushion compresses, i.e. ``M(s) >= F_c(u(s)) L_pp`` from the kiss to
   the solid position. Facing wear lowers ``s_solid`` by ``w e / L_pp`` onto the diaphragm's
   falling branch; past the *wear limit* the diaphragm can no longer compress the cushion
   fully. The limit is the smallest over the temperature box ``[THETA_MIN_K, THETA_MAX_K]^2``
   of ``(theta_cs, theta_cm)`` (grid: every table temperature, the box edges and 25 K steps).
   The *wear reserve* is the wear at which the closed capacity at the reference temperature,
   ``n mu R_eq F_pp,closed``, falls below ``RESERVE_FACTOR`` times ``ENGINE_TORQUE_NM``.

Release compliance (:func:`finger_compliance`): the default ``c = 1.0e-6 m/N`` is derived, not
fitted. The diaphragm fingers' bending at the bearing gives 0.69 um/N for the default cover: each
of ``N_FINGERS`` = 18 fingers is a cantilever clamped at ``b`` and loaded at ``r_b``, its width
tapering linearly from ``2 pi b / N - slot`` to ``2 pi r_b / N - slot`` (slot 3 mm), thickness ``t``:
``c_f = (1/N) int_0^L x^2 / (E I(x)) dx``, ``x`` from the load, ``I = w t^3 / 12``. The remaining
0.31 um/N is an assumed allowance for the release bearing and the hydraulic line (a release
system of about 3 N/um); with a different release system, set the parameter.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields

try:                                    # inside the pythonfmu FMU the modules are siblings
    from ..number_check import is_finite_number, unit_hint
except ImportError:
    from number_check import is_finite_number, unit_hint

__all__ = ["range_problems", "finger_compliance", "hold_problem", "wear_limit", "wear_reserve",
           "ENGINE_TORQUE_NM", "RESERVE_FACTOR", "CoverParameters", "CoverState", "k1", "almen_laszlo_force", "almen_laszlo_slope", "CoverMap"]


@dataclass(frozen=True)
class CoverParameters:
    """Diaphragm-spring cover, finger lever and axial stack (SI; temperatures in K).

    The default is a 240 mm passenger-car cover sized (by its geometry) for about 6.3 kN of
    clamp load with new facings at 20 degC. Its installed deflection puts the diaphragm's
    force peak mid-way through the wear reserve (issue 28): the clamp load rises with wear to
    its peak near 0.8 mm and is back at the new load near 1.5 mm (``docs/cover_wear.png``,
    written by ``python -m cushion_clutch.benchmarks.cover_wear``).
    """

    diaphragm_outer_radius_m: float = 0.1125            #: diaphragm outer radius a, m
    diaphragm_inner_radius_m: float = 0.085             #: diaphragm inner radius b (finger roots), m
    diaphragm_thickness_m: float = 0.00265              #: diaphragm sheet thickness t, m
    diaphragm_cone_height_m: float = 0.0052             #: free cone height h between the edges, m
    diaphragm_youngs_modulus_Pa: float = 206e9          #: E at reference_temperature_K, Pa
    diaphragm_modulus_drop_per_K: float = 2.7e-4  #: E(theta) = E_ref (1 - k (theta - theta_ref)), 1/K
    diaphragm_poisson_ratio: float = 0.3                #: nu, 1
    pressure_plate_radius_m: float = 0.111    #: load circle on the pressure plate r_pp, m
    fulcrum_radius_m: float = 0.089           #: cover fulcrum (pivot ring) radius r_f, m
    installed_deflection_m: float = 0.0041    #: edge deflection s of the closed clutch, new facings, at theta_ref, m
    release_compliance_m_per_N: float = 1.0e-6  #: finger + bearing + release-system compliance c, m/N (see module)
    facing_thickness_m: float = 0.007         #: both facings together, m
    facing_expansion_per_K: float = 3.0e-5    #: facings' through-thickness expansion, 1/K
    pressure_plate_thickness_m: float = 0.016  #: pressure plate, friction face to diaphragm contact, m
    pressure_plate_expansion_per_K: float = 1.1e-5  #: grey cast iron, 1/K
    flywheel_length_m: float = 0.010          #: flywheel, cover mounting face to friction face, m
    flywheel_expansion_per_K: float = 1.1e-5  #: grey cast iron, 1/K
    reference_temperature_K: float = 293.15   #: temperature of E_ref and of zero growth, K

    #: allowed ranges: (low, high, low_open, high_open)
    RANGES = {
        "diaphragm_outer_radius_m": (0.0, 1.0, True, False),
        "diaphragm_inner_radius_m": (0.0, 1.0, True, False),
        "diaphragm_thickness_m": (0.0, 0.05, True, False),
        "diaphragm_cone_height_m": (0.0, 0.1, True, False),
        "diaphragm_youngs_modulus_Pa": (1e9, 1e12, False, False),
        "diaphragm_modulus_drop_per_K": (0.0, 4e-4, False, False),
        "diaphragm_poisson_ratio": (0.0, 0.5, False, True),
        "pressure_plate_radius_m": (0.0, 1.0, True, False),
        "fulcrum_radius_m": (0.0, 1.0, True, False),
        "installed_deflection_m": (0.0, 0.1, True, False),
        "release_compliance_m_per_N": (0.0, 1e-3, False, False),
        "facing_thickness_m": (0.0, 0.05, False, False),
        "facing_expansion_per_K": (0.0, 1e-3, False, False),
        "pressure_plate_thickness_m": (0.0, 0.2, False, False),
        "pressure_plate_expansion_per_K": (0.0, 1e-3, False, False),
        "flywheel_length_m": (0.0, 0.2, False, False),
        "flywheel_expansion_per_K": (0.0, 1e-3, False, False),
        "reference_temperature_K": (200.0, 1000.0, False, False),
    }

    def problems(self, lever_ratio: float | None = None) -> list[str]:
        """Every parameter outside its range and every inconsistent geometry, with the rule."""
        out = range_problems(self, self.RANGES)
        if out:
            return out
        a, b, r_pp, r_f = self.diaphragm_outer_radius_m, self.diaphragm_inner_radius_m, self.pressure_plate_radius_m, self.fulcrum_radius_m
        if not b < r_f < r_pp <= a:
            out.append(f"radii must satisfy diaphragm_inner_radius_m < fulcrum_radius_m < pressure_plate_radius_m <= "
                       f"diaphragm_outer_radius_m (got {b:g} < {r_f:g} < {r_pp:g} <= {a:g})")
        if not self.diaphragm_cone_height_m < 2.0 * math.sqrt(2.0) * self.diaphragm_thickness_m:
            out.append(f"diaphragm_cone_height_m / diaphragm_thickness_m = {self.diaphragm_cone_height_m / self.diaphragm_thickness_m:g} must be < 2 sqrt(2) "
                       "(above, the diaphragm's valley force is negative: it snaps through)")
        if self.installed_deflection_m > 2.0 * self.diaphragm_cone_height_m:
            out.append(f"installed_deflection_m = {self.installed_deflection_m:g} must be <= 2 diaphragm_cone_height_m "
                       f"= {2.0 * self.diaphragm_cone_height_m:g} m (past that the diaphragm is turned inside out)")
        if self.diaphragm_modulus_drop_per_K * (2000.0 - self.reference_temperature_K) >= 1.0:
            out.append("diaphragm_modulus_drop_per_K: E(theta) must stay > 0 up to 2000 K")
        if lever_ratio is not None and not out and not lever_ratio * (r_pp - r_f) < r_f:
            out.append(f"lever_ratio = {lever_ratio:g} puts the bearing at r_b = r_f - i (r_pp - r_f) = "
                       f"{r_f - lever_ratio * (r_pp - r_f):g} m; must be > 0")
        if lever_ratio is not None and not out:
            g = CoverMap(self, lever_ratio)
            e_max = self.diaphragm_youngs_modulus_Pa * (1.0 + self.diaphragm_modulus_drop_per_K * self.reference_temperature_K)
            if not g.x_slope_bound(e_max) > 0.0:
                c_max = g.kb * g.L_b / -g.moment_slope(self.diaphragm_cone_height_m, e_max)
                out.append(f"release_compliance_m_per_N = {self.release_compliance_m_per_N:g} must be < "
                           f"L_b^2 / (e |M'(h)|) = {c_max:.4g} m/N with the lever arm L_b = lever_ratio "
                           f"(pressure_plate_radius_m - fulcrum_radius_m) = {lever_ratio:g} x ({r_pp:g} - {r_f:g}) m "
                           "(above, the release snaps through: x_to(s) not monotone on the diaphragm's falling "
                           "branch); reduce it or lengthen the lever arm")
        return out


def range_problems(params, ranges: dict, units: dict | None = None) -> list[str]:
    """Every field of the dataclass ``params`` named in ``ranges`` that is not a finite number in its range.

    ``ranges`` maps a field name to ``(low, high, low_open, high_open)``; ``units`` a field name to its unit
    (the message then ends with the hint for the likely unit mistake, :func:`number_check.unit_hint`; default:
    a name ending in ``_m`` is in m, one ending in ``_K`` in K).
    """
    out = []
    for f in fields(params):
        if f.name not in ranges:
            continue
        v = getattr(params, f.name)
        lo, hi, lo_open, hi_open = ranges[f.name]
        ok = is_finite_number(v) and (v > lo if lo_open else v >= lo) and (v < hi if hi_open else v <= hi)
        if not ok:
            unit = (units or {}).get(f.name) or ("m" if f.name.endswith("_m") else "K" if f.name.endswith("_K") else "")
            hint = unit_hint(v, unit, lo, hi)
            out.append(f"{f.name} = {v!r} is out of range {'(' if lo_open else '['}{lo:g}, "
                       f"{hi:g}{')' if hi_open else ']'}" + (f": {hint}" if hint else ""))
    return out


def k1(a: float, b: float) -> float:
    """Almen-Laszlo shape factor K1 of an annulus with radii ``a > b`` (1)."""
    d = a / b
    return ((d - 1.0) / d) ** 2 / ((d + 1.0) / (d - 1.0) - 2.0 / math.log(d)) / math.pi


def almen_laszlo_force(s: float, a: float, b: float, t: float, h: float, e_mod: float, nu: float) -> float:
    """Almen-Laszlo edge load (N) of a disc spring deflected ``s`` (m) from its free cone."""
    return (4.0 * e_mod / (1.0 - nu * nu) * t ** 4 / (k1(a, b) * 4.0 * a * a)
            * (s / t) * ((h - s) * (h - 0.5 * s) / (t * t) + 1.0))


def almen_laszlo_slope(s: float, a: float, b: float, t: float, h: float, e_mod: float, nu: float) -> float:
    """dF_AL/ds (N/m) of :func:`almen_laszlo_force`."""
    c = 4.0 * e_mod / (1.0 - nu * nu) * t ** 4 / (k1(a, b) * 4.0 * a * a) / t
    # d/ds { s [(h-s)(h-s/2)/t^2 + 1] } = (h-s)(h-s/2)/t^2 + 1 + s (-(h-s/2) - (h-s)/2)/t^2
    return c * ((h - s) * (h - 0.5 * s) / (t * t) + 1.0 - s * (1.5 * h - s) / (t * t))


@dataclass(slots=True)
class CoverState:
    """The cover at one bearing position (SI)."""

    clamp_force: float    #: pressure-plate (clamp) force F_pp, N
    bearing_force: float  #: release-bearing force F_to, N
    cushion_force: float  #: cushion-spring force F_c(u), N
    u: float              #: cushion compression from its kiss point, m (<= u_full; < 0: gap)
    s: float              #: diaphragm edge deflection from its free cone, m
    x_kiss: float         #: bearing position of the kiss point (u = 0), m
    x_solid: float        #: bearing position where the cushion is fully compressed, m
    x_lift: float         #: bearing position where the bearing lifts off the fingers, m


class CoverMap:
    """The force balance of :mod:`cover` for one cover and lever ratio (geometry prepared once)."""

    def __init__(self, cover: CoverParameters, lever_ratio: float):
        self.c = cover
        self.a, self.b = cover.diaphragm_outer_radius_m, cover.diaphragm_inner_radius_m
        self.e = self.a - self.b
        self.L_pp = cover.pressure_plate_radius_m - cover.fulcrum_radius_m
        self.L_b = lever_ratio * self.L_pp
        self.r_b = cover.fulcrum_radius_m - self.L_b
        self.i = lever_ratio
        self.kb = self.L_b / self.e              # bearing travel per unit of s (rigid fingers)
        self.kp = self.L_pp / self.e             # pressure-plate travel per unit of s
        self.comp = cover.release_compliance_m_per_N
        t, nu = cover.diaphragm_thickness_m, cover.diaphragm_poisson_ratio
        #: F_AL(s) / E / (s/t) / [...]: the Almen-Laszlo factor without E, 1/Pa * N
        self._fal = 4.0 / (1.0 - nu * nu) * t ** 4 / (k1(self.a, self.b) * 4.0 * self.a * self.a)
        self._t, self._h, self._tt = t, cover.diaphragm_cone_height_m, t * t
        self._xc: tuple = (None, None, None)     # (table, x_kiss_ref, X_c) of the last call: holds one table only
        self._u_full_ref: tuple = (None, 0.0)     # (table, full compression at the reference temperature)

    # ---- pieces ---------------------------------------------------------------------------
    def youngs_modulus(self, theta_K: float) -> float:
        """E(theta), Pa."""
        c = self.c
        return c.diaphragm_youngs_modulus_Pa * (1.0 - c.diaphragm_modulus_drop_per_K * (theta_K - c.reference_temperature_K))

    def moment(self, s: float, e_mod: float) -> float:
        """Elastic moment M(s) = F_AL(s) e of the diaphragm section, N.m (:func:`almen_laszlo_force` times e)."""
        return self.moment_pair(s, self._fal * e_mod)[0]

    def moment_slope(self, s: float, e_mod: float) -> float:
        """dM/ds, N (:func:`almen_laszlo_slope` times e)."""
        return self.moment_pair(s, self._fal * e_mod)[1]

    def moment_pair(self, s: float, fe: float) -> tuple[float, float]:
        """(M(s), dM/ds) (N.m, N) with ``fe`` = the Almen-Laszlo factor times E (``_fal * e_mod``, kept by a frame)."""
        t, h, tt = self._t, self._h, self._tt
        hs = h - s
        q = hs * (h - 0.5 * s) / tt + 1.0
        return fe * (s / t) * q * self.e, fe / t * (q - s * (1.5 * h - s) / tt) * self.e

    def x_slope_bound(self, e_mod: float) -> float:
        """-(dx_to/ds) at its largest, open phase, 1 (> 0: no snap-through)."""
        return self.kb + self.comp * self.moment_slope(self.c.diaphragm_cone_height_m, e_mod) / self.L_b

    def growth(self, theta_cm: float) -> dict:
        """Axial thermal growth of the stack parts at facing temperature ``theta_cm`` (K), m each."""
        c, dT = self.c, theta_cm - self.c.reference_temperature_K
        return {"facing": c.facing_thickness_m * c.facing_expansion_per_K * dT,
                "pressure_plate": c.pressure_plate_thickness_m * c.pressure_plate_expansion_per_K * dT,
                "flywheel": c.flywheel_length_m * c.flywheel_expansion_per_K * dT}

    def x_c(self, table, x_kiss_ref: float) -> float:
        """The bearing-system constant X_c that puts the reference kiss point at ``x_kiss_ref``, m."""
        if self._xc[0] is table and self._xc[1] == x_kiss_ref:
            return self._xc[2]
        c = self.c
        theta_ref_c = c.reference_temperature_K - 273.15
        s_k0 = c.installed_deflection_m + table.full_compression(theta_ref_c) / self.kp
        f_to = (self.moment(s_k0, c.diaphragm_youngs_modulus_Pa) - table.force(0.0, theta_ref_c) * self.L_pp) / self.L_b
        xc = x_kiss_ref + self.kb * s_k0 + self.comp * f_to
        self._xc = (table, x_kiss_ref, xc)
        return xc

    # ---- the map ----------------------------------------------------------------------------
    def prepare(self, theta_cs: float, theta_cm: float, wear: float, table, x_kiss_ref: float) -> "_Frame":
        """Everything of the balance that depends on temperature and wear, not on ``x_to``."""
        theta_c = theta_cs - 273.15
        br = table.bracket(theta_c)
        s_kiss = self._s_kiss(br.delta_kiss, theta_cm, wear, table)
        return _Frame(self, table, theta_c, self.youngs_modulus(theta_cs), self.x_c(table, x_kiss_ref), s_kiss,
                      s_kiss - br.full / self.kp, theta_cs, wear, br)

    def s_kiss(self, theta_cs: float, theta_cm: float, wear: float, table) -> float:
        """Diaphragm deflection (m) at the kiss point: installed deflection, cushion shift, stack growth, wear."""
        return self._s_kiss(table.delta_kiss(theta_cs - 273.15), theta_cm, wear, table)

    def _s_kiss(self, delta_kiss: float, theta_cm: float, wear: float, table) -> float:
        """:meth:`s_kiss` with the cushion's kiss shift ``delta_kiss`` (m) at theta_cs given."""
        c = self.c
        g = theta_cm - c.reference_temperature_K
        stack = delta_kiss + (
            c.facing_thickness_m * c.facing_expansion_per_K * g
            + c.pressure_plate_thickness_m * c.pressure_plate_expansion_per_K * g
            + c.flywheel_length_m * c.flywheel_expansion_per_K * g)        # = sum(self.growth(theta_cm).values())
        if self._u_full_ref[0] is not table:        # the cushion's full compression at the reference temperature
            self._u_full_ref = (table, table.full_compression(c.reference_temperature_K - 273.15))
        return c.installed_deflection_m + (self._u_full_ref[1] + stack - wear) / self.kp

    def x_kiss(self, theta_cs: float, theta_cm: float, wear: float, table, x_kiss_ref: float) -> float:
        """Bearing position of the kiss point (m); the same number as ``prepare(...).x_kiss``, without the frame.

        Unlike :meth:`prepare` it does not check that the diaphragm holds the fully compressed cushion.
        """
        br = table.bracket(theta_cs - 273.15)
        s = self._s_kiss(br.delta_kiss, theta_cm, wear, table)
        f_to = (self.moment(s, self.youngs_modulus(theta_cs)) - br.force_slope(0.0)[0] * self.L_pp) / self.L_b
        return self.x_c(table, x_kiss_ref) - self.kb * s - self.comp * f_to

    def state(self, x_to: float, theta_cs: float, theta_cm: float, wear: float, table, x_kiss_ref: float,
              tol: float = 1e-15) -> CoverState:
        """Solve the force balance at bearing position ``x_to`` (m), temperatures in K, wear in m.

        Raises
        ------
        ValueError
            If the diaphragm cannot hold the cushion (bearing force < 0 before the cushion is solid).
        """
        return self.prepare(theta_cs, theta_cm, wear, table, x_kiss_ref).state(x_to, tol)

    def kiss_budget(self, theta_cs: float, theta_cm: float, wear: float, table, x_kiss_ref: float) -> dict:
        """Kiss-point shift at the bearing (m, + = later engagement) split by cause, and the closed clamp load.

        ``cushion``, ``facing``, ``pressure_plate``, ``flywheel``, ``wear``: lever ratio times each part's
        move of the pressure plate's kiss position; ``compliance``: the release system's deflection change
        (bearing force at the kiss point differs from the reference); ``total`` = their sum =
        ``x_kiss - x_kiss_ref``; ``clamp_closed_N``: the diaphragm's installed load (bearing lifted).
        """
        fr = self.prepare(theta_cs, theta_cm, wear, table, x_kiss_ref)
        grow = self.growth(theta_cm)
        out = {"cushion": -self.i * table.delta_kiss(theta_cs - 273.15), "facing": -self.i * grow["facing"],
               "pressure_plate": -self.i * grow["pressure_plate"], "flywheel": -self.i * grow["flywheel"],
               "wear": self.i * wear}
        out["compliance"] = fr.x_kiss - x_kiss_ref - sum(out.values())
        out["total"] = fr.x_kiss - x_kiss_ref
        out["clamp_closed_N"] = fr.clamp_installed()
        return out

    def x_for_clamp(self, clamp_force: float, theta_cs: float, theta_cm: float, wear: float, table,
                    x_kiss_ref: float, tol_m: float = 1e-12) -> float:
        """Smallest bearing position (m) whose clamp force reaches ``clamp_force`` (N); the inverse map.

        At or below zero: the cushion's first contact; above the installed load: the lift-off position.
        """
        return self.prepare(theta_cs, theta_cm, wear, table, x_kiss_ref).x_for_clamp(clamp_force, tol_m)


class _Frame:
    """The cover balance at one temperature and wear (see the module docstring for the equations)."""

    __slots__ = ("g", "table", "theta_c", "e_mod", "xc", "_b", "_fs", "_fe", "s_kiss", "s_solid", "theta_cs", "wear",
                 "fto_solid", "fc_solid", "x_solid", "x_lift", "fto_kiss", "x_kiss", "m_solid")

    def __init__(self, g: CoverMap, table, theta_c: float, e_mod: float, xc: float, s_kiss: float, s_solid: float,
                 theta_cs: float, wear: float, bracket=None):
        self.g, self.table, self.theta_c, self.e_mod, self.xc = g, table, theta_c, e_mod, xc
        self._b = table.bracket(theta_c) if bracket is None else bracket   # F(u) at this temperature (table.force)
        self._fs = self._b.force_slope               # (F, dF/du) at a compression u
        self._fe = g._fal * e_mod                    # the Almen-Laszlo factor times E (CoverMap.moment_pair)
        self.s_kiss, self.s_solid, self.theta_cs, self.wear = s_kiss, s_solid, theta_cs, wear
        self.m_solid = g.moment_pair(s_solid, self._fe)[0]     # the diaphragm's moment at the solid position, N.m
        self.fc_solid = self._b.f_full                          # the cushion fully compressed, N
        self.fto_solid = (self.m_solid - self.fc_solid * g.L_pp) / g.L_b       # = f_to(s_solid)
        self.x_solid = xc - g.kb * s_solid - g.comp * self.fto_solid
        self.x_lift = self.x_solid + g.comp * max(self.fto_solid, 0.0)
        self.fto_kiss = self.f_to(s_kiss)[0]
        self.x_kiss = xc - g.kb * s_kiss - g.comp * self.fto_kiss      # = self.x_of(s_kiss)
        if self.fto_solid < 0.0:
            raise ValueError(self._weak(self.fto_solid, "the solid position"))

    def _weak(self, fto: float, where: str) -> str:
        return (f"the diaphragm cannot hold the cushion: bearing force {fto:.6g} N < 0 at {where} "
                f"(theta_cs = {self.theta_cs:g} K, facing_wear = {self.wear:g} m)")

    def cushion(self, u: float) -> float:
        """F(u, theta_cs), N (= ``table.force``, with the temperature bracket found once)."""
        return self._fs(u)[0]

    def cushion_slope(self, u: float) -> float:
        """dF/du at theta_cs, N/m (= ``table.force_slope``)."""
        return self._fs(u)[1]

    def f_to(self, s: float) -> tuple[float, float]:
        """(bearing force, cushion force) at deflection ``s`` while the bearing is on the fingers, N."""
        g = self.g
        fc = self._fs((self.s_kiss - s) * g.kp)[0]
        return (g.moment_pair(s, self._fe)[0] - fc * g.L_pp) / g.L_b, fc

    def x_of(self, s: float) -> float:
        """Bearing position at deflection ``s`` (s >= s_solid), m."""
        return self.xc - self.g.kb * s - self.g.comp * self.f_to(s)[0]

    def clamp_installed(self) -> float:
        """The diaphragm's load at the solid position, bearing lifted: the closed clamp force, N."""
        return self.m_solid / self.g.L_pp

    def state(self, x_to: float, tol: float = 1e-15) -> CoverState:
        g = self.g
        kb, kp, comp, L_pp, L_b = g.kb, g.kp, g.comp, g.L_pp, g.L_b
        s_kiss, s_solid, x_solid = self.s_kiss, self.s_solid, self.x_solid
        u_full = (s_kiss - s_solid) * kp
        if x_to >= x_solid:
            fto = max(0.0, self.fto_solid - (x_to - x_solid) / comp) if comp > 0.0 else 0.0
            fpp = (self.m_solid - fto * L_b) / L_pp
            return CoverState(fpp, fto, self.fc_solid, u_full, s_solid, self.x_kiss, x_solid, self.x_lift)
        xc = self.xc
        lo, hi = s_solid, (xc - x_to) / kb       # x_of(lo) > x_to >= x_of(hi)
        # start (as the C core's, from the inputs only): the chord of x(s) between the solid and kiss points
        # (cushion phase) or the rigid lever shifted by the kiss point's compliance (open)
        if x_to >= self.x_kiss:
            s = s_solid + (s_kiss - s_solid) * (x_solid - x_to) / (x_solid - self.x_kiss)
        else:
            s = (xc - x_to - comp * self.fto_kiss) / kb
        if not lo < s < hi:
            s = hi
        mp, fs, fe = g.moment_pair, self._fs, self._fe
        m, dm = mp(s, fe)
        fc, dfc = fs((s_kiss - s) * kp)
        fto = (m - fc * L_pp) / L_b
        r = xc - kb * s - comp * fto - x_to                  # = self.x_of(s) - x_to
        eps_r = tol * (1.0 + abs(x_to))
        for _ in range(100):
            if abs(r) <= eps_r or hi - lo <= tol * (1.0 + hi):
                break
            if r > 0.0:
                lo = s
            else:
                hi = s
            slope = -kb - comp * (dm + dfc * kp * L_pp) / L_b
            s_new = s - r / slope if slope < 0.0 else 0.5 * (lo + hi)
            s = s_new if lo < s_new < hi else 0.5 * (lo + hi)
            m, dm = mp(s, fe)
            fc, dfc = fs((s_kiss - s) * kp)
            fto = (m - fc * L_pp) / L_b
            r = xc - kb * s - comp * fto - x_to
        if fto < 0.0:
            raise ValueError(self._weak(fto, f"x_to = {x_to:g} m"))
        return CoverState(fc, fto, fc, (s_kiss - s) * kp, s, self.x_kiss, x_solid, self.x_lift)

    def x_for_clamp(self, force: float, tol_m: float = 1e-12) -> float:
        g = self.g
        if force >= self.clamp_installed():
            return self.x_lift
        if force > self.fc_solid:       # solid phase: F_to = (M(s_solid) - F L_pp) / L_b
            fto = (self.m_solid - force * g.L_pp) / g.L_b
            return self.x_solid + g.comp * (self.fto_solid - fto)
        fs = self._fs
        lo, hi = self._b.first, self._b.full
        if force <= fs(lo)[0]:
            return self.x_of(self.s_kiss - lo / g.kp)
        # the smallest compression u with F(u) >= force, to tol: a bracket F(lo) < force <= F(hi) closed by
        # Newton steps (bisection where a step leaves it); once a step is below tol the other side of the
        # root is probed, so the bracket, not the step, ends the search
        tol = tol_m / g.i
        half = 0.5 * tol
        u = self._b.u_start(force)                   # from the curves' own inverses (inputs only)
        if not lo < u < hi:
            u = 0.5 * (lo + hi)
        f_hi = self.fc_solid                         # F(hi)
        while hi - lo > tol:
            f, d = fs(u)
            r = f - force
            if r < 0.0:
                lo = u
            else:
                hi, f_hi = u, f
            u_new = u - r / d if d > 0.0 else 0.5 * (lo + hi)
            if abs(u_new - u) < half:
                u_new += half if r < 0.0 else -half
            u = u_new if lo < u_new < hi else 0.5 * (lo + hi)
        s = self.s_kiss - hi / g.kp                  # = x_of(s), with the cushion force F(hi) already known
        return self.xc - g.kb * s - g.comp * (g.moment_pair(s, self._fe)[0] - f_hi * g.L_pp) / g.L_b


#: the engine torque the wear reserve is stated against (the default launch engine's peak), N.m
ENGINE_TORQUE_NM = 240.0
#: the wear reserve ends where the closed capacity at the reference temperature falls below this multiple
RESERVE_FACTOR = 1.25
#: diaphragm fingers of the default cover and the slot between two fingers (finger_compliance)
N_FINGERS = 18
FINGER_SLOT_M = 0.003


def finger_compliance(cover: CoverParameters, lever_ratio: float, n_fingers: int = N_FINGERS,
                      slot_m: float = FINGER_SLOT_M, steps: int = 400) -> float:
    """Bending compliance of the diaphragm fingers at the release bearing, m/N (the derivation of the default
    ``release_compliance_m_per_N``; see the module docstring).

    Each finger is a cantilever clamped at the finger roots ``b`` and loaded at the bearing radius
    ``r_b = r_f - i (r_pp - r_f)``, width tapering linearly from ``2 pi b / n - slot`` to
    ``2 pi r_b / n - slot``, thickness ``t``, modulus ``E_ref``; the bearing force is shared by the ``n``
    fingers: ``c = (1/n) int_0^L x^2 / (E w(x) t^3 / 12) dx`` (midpoint rule, ``x`` from the load).
    """
    c = cover
    r_b = c.fulcrum_radius_m - lever_ratio * (c.pressure_plate_radius_m - c.fulcrum_radius_m)
    length = c.diaphragm_inner_radius_m - r_b
    w_root = 2.0 * math.pi * c.diaphragm_inner_radius_m / n_fingers - slot_m
    w_tip = 2.0 * math.pi * r_b / n_fingers - slot_m
    if not (length > 0.0 and w_tip > 0.0):
        raise ValueError(f"fingers of length {length:g} m and tip width {w_tip:g} m: no cantilever")
    total = 0.0
    for k in range(steps):
        x = (k + 0.5) * length / steps                  # from the load point
        w = w_tip + (w_root - w_tip) * x / length
        total += x * x / (c.diaphragm_youngs_modulus_Pa * w * c.diaphragm_thickness_m ** 3 / 12.0)
    return total * length / steps / n_fingers


def temperature_grid(table, theta_min_K: float, theta_max_K: float, step_K: float = 25.0) -> list[float]:
    """Temperatures (K) at which :func:`hold_problem` checks the cover: the box edges, every table temperature
    inside and ``step_K`` steps."""
    n = int(math.ceil((theta_max_K - theta_min_K) / step_K))
    grid = {theta_min_K + (theta_max_K - theta_min_K) * k / n for k in range(n + 1)}
    grid |= {float(t) + 273.15 for t in table.theta_degC if theta_min_K <= float(t) + 273.15 <= theta_max_K}
    return sorted(grid)


#: points of the cushion phase checked by the hold rule: the solid point and 8 more towards the kiss point
HOLD_POINTS = 9


def _hold_forces(g: CoverMap, table, theta_cs: float) -> tuple:
    """What the hold rule needs at one cushion temperature: (E, delta_kiss, u_full, [(u_k, F_c(u_k))]) with
    ``u_k = u_full (HOLD_POINTS - k) / HOLD_POINTS`` (k = 0: the solid point)."""
    th = theta_cs - 273.15
    u_full = table.full_compression(th)
    pts = []
    for k in range(HOLD_POINTS):
        u = u_full * (HOLD_POINTS - k) / HOLD_POINTS
        pts.append((u, table.force(u, th)))
    return g.youngs_modulus(theta_cs), table.delta_kiss(th), pts


def _holds(g: CoverMap, wear: float, theta_cm: float, forces: tuple) -> float:
    """The smallest bearing force (N) of the cushion phase at one temperature pair (``forces`` from
    :func:`_hold_forces` at theta_cs): ``(M(s_k) - F_c(u_k) L_pp) / L_b`` at ``s_k = s_kiss - u_k e / L_pp``
    (< 0: the diaphragm cannot hold the cushion)."""
    c = g.c
    e_mod, delta, pts = forces
    d = theta_cm - c.reference_temperature_K
    stack = delta + (c.facing_thickness_m * c.facing_expansion_per_K * d
                     + c.pressure_plate_thickness_m * c.pressure_plate_expansion_per_K * d
                     + c.flywheel_length_m * c.flywheel_expansion_per_K * d)
    s_kiss = c.installed_deflection_m + (g._u_full_ref[1] + stack - wear) / g.kp
    return min((g.moment(s_kiss - u / g.kp, e_mod) - f * g.L_pp) / g.L_b for u, f in pts)


def _hold_setup(cover, lever_ratio, table, theta_min_K, theta_max_K):
    g = CoverMap(cover, lever_ratio)
    g.s_kiss(cover.reference_temperature_K, cover.reference_temperature_K, 0.0, table)   # caches u_full(theta_ref)
    grid = temperature_grid(table, theta_min_K, theta_max_K)
    forces = {a: _hold_forces(g, table, a) for a in grid}
    return g, [(a, b, forces[a]) for a in grid for b in grid]


def _failing(g, wear, pairs):
    """The first (theta_cs, theta_cm, bearing force) of ``pairs`` where the diaphragm cannot hold, or None."""
    for a, b, f in pairs:
        fto = _holds(g, wear, b, f)
        if fto < 0.0:
            return a, b, fto
    return None


def hold_problem(cover: CoverParameters, lever_ratio: float, table, x_kiss_ref: float, wear: float,
                 theta_min_K: float, theta_max_K: float) -> str | None:
    """None if the diaphragm holds the cushion at ``wear`` (m) for every ``(theta_cs, theta_cm)`` of the
    temperature box (:func:`temperature_grid`); otherwise the rule broken, with the wear limit."""
    g, pairs = _hold_setup(cover, lever_ratio, table, theta_min_K, theta_max_K)
    bad = _failing(g, wear, pairs)
    if bad is None:
        return None
    limit = wear_limit(cover, lever_ratio, table, x_kiss_ref, theta_min_K, theta_max_K)
    where = (f"the wear limit of this cover is {limit:.6g} m" if limit >= 0.0 else
             "this cover cannot hold the cushion even with new facings")
    return (f"facing_wear = {wear:g} m: the diaphragm cannot hold the fully compressed cushion "
            f"(bearing force {bad[2]:.4g} N < 0 at theta_cs = {bad[0]:g} K, theta_cm = {bad[1]:g} K); "
            f"{where} over theta in [{theta_min_K:g}, {theta_max_K:g}] K")


def wear_limit(cover: CoverParameters, lever_ratio: float, table, x_kiss_ref: float, theta_min_K: float,
               theta_max_K: float, tol_m: float = 1e-7) -> float:
    """The largest facing wear (m, to ``tol_m``) the cover holds at every temperature pair of the box;
    -1.0 if it cannot hold the cushion even new. Bisection on the wear (the bearing force at the solid point
    falls with wear on the diaphragm's rising branch). ``x_kiss_ref`` does not enter (kept for the signature)."""
    g, pairs = _hold_setup(cover, lever_ratio, table, theta_min_K, theta_max_K)
    if _failing(g, 0.0, pairs):
        return -1.0
    # bisect on the binding pairs only, then check the answer on the whole grid: both predicates are monotone in
    # the wear, so once the whole grid holds at the result, the full bisection ends in the same dyadic interval
    active = [min(pairs, key=lambda p: _holds(g, 0.005, p[1], p[2]))]
    while True:
        lo, hi = 0.0, 0.01
        while hi - lo > tol_m:
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if _failing(g, mid, active) is None else (lo, mid)
        bad = _failing(g, lo, pairs)
        if bad is None:
            return lo
        active.append(next(p for p in pairs if p[:2] == bad[:2]))


def wear_reserve(cover: CoverParameters, lever_ratio: float, table, x_kiss_ref: float, gain_m: float,
                 engine_torque_Nm: float = ENGINE_TORQUE_NM, factor: float = RESERVE_FACTOR,
                 limit_m: float | None = None, tol_m: float = 1e-7) -> float:
    """The facing wear (m) at which the closed capacity ``gain_m * F_pp,closed`` (``gain_m = n mu R_eq``) at the
    reference temperature first falls below ``factor * engine_torque_Nm`` (scanned in 0.01 mm steps up to
    ``limit_m``, then bisected); ``limit_m`` if it never does, 0.0 if new facings are already below."""
    g = CoverMap(cover, lever_ratio)
    theta = cover.reference_temperature_K
    need = factor * engine_torque_Nm
    top = limit_m if limit_m is not None else 0.01

    def cap(w):
        try:
            return gain_m * g.prepare(theta, theta, w, table, x_kiss_ref).clamp_installed()
        except ValueError:
            return -math.inf

    if cap(0.0) < need:
        return 0.0
    w = 0.0
    while w < top:
        nxt = min(w + 1e-5, top)
        if cap(nxt) < need:
            lo, hi = w, nxt
            while hi - lo > tol_m:
                mid = 0.5 * (lo + hi)
                lo, hi = (mid, hi) if cap(mid) >= need else (lo, mid)
            return lo
        w = nxt
    return top
