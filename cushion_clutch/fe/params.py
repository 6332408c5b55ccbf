"""Spring parameters: frozen dataclasses loaded from TOML and checked on load.

All quantities are SI (m, Pa, 1/K) unless a name says otherwise (``_deg``,
``_degC``). Every dataclass checks itself in ``__post_init__`` and reports all
problems at once through :class:`~cushion_clutch.errors.ParameterError`,
naming the key and the allowed range. Unknown keys are rejected.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

from ..config import Checked, build_checked, load_toml, range_problem
from ..number_check import is_finite_number, is_number
from ..data import DEFAULT_SPRING
from .surface import load_surface


@dataclass(frozen=True)
class Geometry(Checked):
    """Plan shape and wave of one paddle (an annular sector).

    Angles are measured along the circumference from the paddle's clamped
    end. The paddle's mid-surface height above the carrier face is
    ``t/2 + c + w(r, phi)``. Between ``wave_start_deg`` and ``wave_end_deg``
    lie ``waves`` equal waves; with ``s`` in [0, 1] the position within one
    wave, ``w = h(r) p(s)`` with the unit profile ``p``:

    - ``"cosine"``: ``p = (1 - cos(2 pi s)) / 2``;
    - ``"flat_top"``: a flat crest over the middle ``crest_flat_fraction`` of
      the wave, joined to the flat ends by half-cosine flanks (trapezoidal);
    - ``"table"``: ``p`` linear through the points
      (``profile_s``, ``profile_z``), both in [0, 1], starting and ending at 0
      and peaking at 1.

    ``h(r)`` is ``wave_height_m`` at the mean radius and varies linearly with
    the radius by ``wave_tilt_m`` (outer edge height minus inner edge height):
    a tilted wave touches first at one edge and contact spreads across.
    """

    inner_radius_m: float = 0.072
    outer_radius_m: float = 0.108
    span_deg: float = 22.0
    thickness_m: float = 0.4e-3
    wave_height_m: float = 0.7e-3
    wave_start_deg: float = 5.0
    wave_end_deg: float = 20.0
    clamp_start_deg: float = 0.0
    clamp_end_deg: float = 4.0
    carrier_clearance_m: float = 0.01e-3
    """Clearance between the paddle's underside and the carrier face (the
    back of the other paddle) outside the rivet zone, m. A few micrometres
    keep the penalty contact from chattering at zero gap."""
    waves: int = 1
    """Number of equal waves between ``wave_start_deg`` and ``wave_end_deg``."""
    wave_tilt_m: float = 0.0
    """Wave height at the outer edge minus that at the inner edge, m."""
    wave_profile: str = "cosine"
    """``"cosine"`` | ``"flat_top"`` | ``"table"`` (see the class docstring)."""
    crest_flat_fraction: float = 0.3
    """Share of one wave's span that is flat crest (``wave_profile = "flat_top"``)."""
    profile_s: tuple[float, ...] = (0.0, 0.5, 1.0)
    """Positions within one wave, 0..1, strictly increasing (``"table"``)."""
    profile_z: tuple[float, ...] = (0.0, 1.0, 0.0)
    """Heights as fractions of the wave height, 0..1, at ``profile_s`` (``"table"``)."""
    far_zone_support: str = "slot"
    """Axial support of the flat far zone (``wave_end_deg`` to ``span_deg``):
    ``"slot"`` the carrier holds it flat in a slot; ``"carrier"`` it rests on
    the carrier face, contact only, free to lift."""
    far_end: str = "elastic"
    """The flat far zone between ``wave_end_deg`` and ``span_deg`` sits in a
    slot of the carrier that holds it axially (flat) but lets it slide in its
    plane. How the carrier holds the far edge (``phi = span_deg``) in the
    circumferential direction: ``"free"`` it slides freely; ``"locked"`` it
    moves only with the carrier's thermal expansion; ``"elastic"`` it is held
    through the carrier tab and the rivets (``[joint]``, or the override
    ``carrier.far_end_stiffness_N_per_m``)."""
    surface_file: str = ""
    """A fitted mid-surface (``.npz`` written by ``cushion-clutch import-scan``)
    that replaces the analytic wave: w(r, phi) is interpolated from it and
    scaled so that its peak equals ``wave_height_m``. A relative path is
    taken from the TOML file's folder. It carries the whole shape, so
    ``wave_tilt_m``, ``wave_profile`` and ``waves`` keep their defaults.
    Empty: the analytic wave above."""

    _section = "geometry"

    _RANGES = {
        "inner_radius_m": (0.0, 0.5, True),
        "outer_radius_m": (0.0, 0.5, True),
        "span_deg": (0.0, 90.0, True),
        "thickness_m": (0.05e-3, 5e-3),
        "wave_height_m": (0.0, 5e-3),
        "carrier_clearance_m": (0.0, 0.2e-3),
        "wave_start_deg": (0.0, 90.0),
        "wave_end_deg": (0.0, 90.0),
        "clamp_start_deg": (0.0, 90.0),
        "clamp_end_deg": (0.0, 90.0),
        "crest_flat_fraction": (0.0, 0.8),
    }

    def _problems(self) -> Iterable[str]:
        spec = self._RANGES
        yield from self._ranges(spec)
        # cross-field rules only on values that passed their own range check: one mistake, one message,
        # each message led by the one key it blames
        ok = lambda *n: self._passed(spec, *n)  # noqa: E731
        if ok("inner_radius_m", "outer_radius_m") and self.outer_radius_m <= self.inner_radius_m:
            yield (f"geometry.outer_radius_m = {self.outer_radius_m!r}: must exceed "
                   f"geometry.inner_radius_m = {self.inner_radius_m!r}")
        if ok("clamp_start_deg", "clamp_end_deg") and not self.clamp_start_deg < self.clamp_end_deg:
            yield (f"geometry.clamp_end_deg = {self.clamp_end_deg!r}: must exceed "
                   f"geometry.clamp_start_deg = {self.clamp_start_deg!r}")
        elif ok("clamp_end_deg", "wave_start_deg") and not self.clamp_end_deg <= self.wave_start_deg:
            yield (f"geometry.clamp_end_deg = {self.clamp_end_deg!r}: must not exceed "
                   f"geometry.wave_start_deg = {self.wave_start_deg!r} (the clamp ends before the wave)")
        if ok("wave_start_deg", "wave_end_deg") and not self.wave_start_deg < self.wave_end_deg:
            yield (f"geometry.wave_end_deg = {self.wave_end_deg!r}: must exceed "
                   f"geometry.wave_start_deg = {self.wave_start_deg!r}")
        elif ok("wave_end_deg", "span_deg") and not self.wave_end_deg <= self.span_deg:
            yield (f"geometry.wave_end_deg = {self.wave_end_deg!r}: must not exceed "
                   f"geometry.span_deg = {self.span_deg!r}")
        if self.far_end not in ("free", "locked", "elastic"):
            yield f"geometry.far_end = {self.far_end!r}: allowed 'free', 'locked' or 'elastic'"
        if self.far_zone_support not in ("slot", "carrier"):
            yield (f"geometry.far_zone_support = {self.far_zone_support!r}: allowed 'slot' or "
                   "'carrier'")
        if not (is_number(self.waves) and isinstance(self.waves, int) and 1 <= self.waves <= 8):
            yield f"geometry.waves = {self.waves!r}: must be an integer in [1, 8]"
        if not is_finite_number(self.wave_tilt_m):
            yield f"geometry.wave_tilt_m = {self.wave_tilt_m!r}: must be a finite number"
        elif ok("wave_height_m"):
            lim = 2.0 * self.wave_height_m
            if not abs(self.wave_tilt_m) <= lim:
                yield (f"geometry.wave_tilt_m = {self.wave_tilt_m!r}: out of range, allowed "
                       f"[{-lim:g}, {lim:g}] (both edge heights >= 0)")
        if not isinstance(self.surface_file, str):
            yield f"geometry.surface_file = {self.surface_file!r}: must be a file name (string)"
        elif self.surface_file:
            yield from surface_problems(self)
            if self.wave_tilt_m != 0.0 or self.wave_profile != "cosine" or self.waves != 1:
                yield ("geometry.surface_file: the fitted surface carries the whole wave shape; leave "
                       "wave_tilt_m, wave_profile and waves at their defaults (0, 'cosine', 1)")
        if self.wave_profile not in ("cosine", "flat_top", "table"):
            yield (f"geometry.wave_profile = {self.wave_profile!r}: allowed 'cosine', 'flat_top' "
                   "or 'table'")
        elif self.wave_profile == "table":
            yield from self._profile_problems()

    def _profile_problems(self) -> Iterable[str]:
        s, z = self.profile_s, self.profile_z
        if len(s) < 3:
            yield f"geometry.profile_s: needs at least 3 values, got {len(s)}"
            return
        if len(s) != len(z):
            yield f"geometry.profile_z: needs one value per profile_s ({len(s)}), got {len(z)}"
            return
        bad = [range_problem(f"geometry.profile_s[{i}]", v, 0.0, 1.0) for i, v in enumerate(s)]
        bad += [range_problem(f"geometry.profile_z[{i}]", v, 0.0, 1.0) for i, v in enumerate(z)]
        bad = [b for b in bad if b]
        if bad:
            yield from bad
            return
        if s[0] != 0.0 or s[-1] != 1.0 or any(b <= a for a, b in zip(s[:-1], s[1:])):
            yield "geometry.profile_s: must rise strictly from 0 to 1"
        if z[0] != 0.0 or z[-1] != 0.0 or abs(max(z) - 1.0) > 1e-9:
            yield "geometry.profile_z: must start and end at 0 and peak at 1"

    def edge_heights_m(self) -> tuple[float, float]:
        """Wave height at the inner and the outer edge, m."""
        return (self.wave_height_m - 0.5 * self.wave_tilt_m,
                self.wave_height_m + 0.5 * self.wave_tilt_m)

    @property
    def max_wave_height_m(self) -> float:
        """Largest wave height of the paddle (the higher edge), m."""
        return max(self.edge_heights_m())



def surface_problems(geom: Geometry):
    """Problems of ``geom.surface_file`` as parameter messages (file, content, sector coverage)."""
    key = f"geometry.surface_file = {geom.surface_file!r}"
    try:
        surf = load_surface(geom.surface_file)
    except FileNotFoundError:
        yield f"{key}: file not found (a relative path is taken from the TOML file's folder)"
        return
    except (OSError, ValueError) as exc:
        yield f"{key}: not a fitted surface (.npz from cushion-clutch import-scan): {exc}"
        return
    tol = 1e-9
    try:
        covers = (surf.r_m[0] <= geom.inner_radius_m + tol and surf.r_m[-1] >= geom.outer_radius_m - tol
                  and surf.phi_deg[0] <= tol and surf.phi_deg[-1] >= geom.span_deg - tol)
    except TypeError:
        return          # the radii themselves are wrong; reported with their keys
    if not covers:
        yield (f"{key}: covers r = {surf.r_m[0]:g}..{surf.r_m[-1]:g} m, phi = {surf.phi_deg[0]:g}.."
               f"{surf.phi_deg[-1]:g} deg; the paddle needs r = {geom.inner_radius_m:g}.."
               f"{geom.outer_radius_m:g} m, phi = 0..{geom.span_deg:g} deg")
    if surf.peak_m <= 0:
        yield f"{key}: the surface has no height above its rivet zone (peak {surf.peak_m:g} m)"

@dataclass(frozen=True)
class Carrier(Checked):
    """The clutch-disc carrier that holds the rivet (clamp) zone and the far end.

    ``temperature_ratio`` (kappa, dimensionless) states how much of the
    paddle's temperature rise the carrier sees: the carrier is at
    ``theta_ref + kappa (theta - theta_ref)`` and expands freely in its plane,
    carrying the clamped nodes and the anchor of the far edge with it.
    kappa = 1: carrier as hot as the paddle, no mismatch; kappa = 0: a cold
    carrier. The paddle expands more than its carrier because it sits between
    the hot facings while the carrier is further from them.

    ``far_end_stiffness_N_per_m`` (used with ``geometry.far_end =
    "elastic"``) is the circumferential stiffness that holds the paddle's far
    edge against the carrier, N/m over the whole edge: the carrier tab in
    series with the clamp zone's rivets. ``None`` (the default, and the
    default spring's): it is predicted from the ``[joint]`` section by
    :mod:`cushion_clutch.fe.joint` (a CalculiX model of the tab and a fastener
    formula for the rivets). A number is an explicit override, for a user with
    a measured value. 0 is a free end (a few micrometres of growth), infinity a
    locked end (tenths of a millimetre, and snap-through under compression).
    """

    temperature_ratio: float = 0.3
    far_end_stiffness_N_per_m: float | None = None

    _section = "carrier"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"temperature_ratio": (0.0, 1.0)})
        if self.far_end_stiffness_N_per_m is not None:
            yield from self._ranges({"far_end_stiffness_N_per_m": (0.0, 1e12)})


@dataclass(frozen=True)
class Joint(Checked):
    """What holds the paddle in the carrier's plane: the carrier tab at the far edge and the clamp rivets.

    Used when ``geometry.far_end = "elastic"`` and no ``carrier.far_end_stiffness_N_per_m`` is
    given (:mod:`cushion_clutch.fe.joint` turns it into that stiffness).

    - The **tab** is a finger of the carrier sheet, in the carrier's plane, that the paddle's far edge
      bears on circumferentially: ``tab_length_m`` from its root in the carrier body to the paddle's
      edge (radial), ``tab_width_m`` wide (circumferential, the direction of the load) and
      ``carrier_thickness_m`` thick. It bends in its plane (about the disc's axis) and shears; its
      root turns in the carrier body around it.
    - The **rivets** of the clamp zone (``rivets`` of ``rivet_diameter_m``, Young's modulus
      ``rivet_youngs_modulus_Pa``) join the paddle (``geometry.thickness_m``, E of ``[material]`` at the
      reference temperature) to the carrier; shank shear, bending and bearing in both sheets (Huth's
      fastener flexibility, single shear per paddle).

    The two are in series with the paddle's own in-plane path (which the paddle FE models). Lengths
    in m, moduli in Pa.
    """

    carrier_thickness_m: float = 1.5e-3
    carrier_youngs_modulus_Pa: float = 206e9
    carrier_poisson_ratio: float = 0.3
    tab_length_m: float = 8e-3
    tab_width_m: float = 5e-3
    rivets: int = 2
    rivet_diameter_m: float = 4e-3
    rivet_youngs_modulus_Pa: float = 206e9

    _section = "joint"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "carrier_thickness_m": (1e-4, 0.02), "carrier_youngs_modulus_Pa": (1e9, 1e12),
            "carrier_poisson_ratio": (0.0, 0.5, False, True),
            "tab_length_m": (5e-4, 0.05), "tab_width_m": (5e-4, 0.05),
            "rivets": (1, 20), "rivet_diameter_m": (5e-4, 0.02), "rivet_youngs_modulus_Pa": (1e9, 1e12)})
        yield from self._integers("rivets")


@dataclass(frozen=True)
class Material(Checked):
    """Isotropic linear elastic material, E(theta) piecewise linear (paper Table 1).

    The thermal strain is ``alpha(theta) (theta - reference_temperature_degC)``
    with ``alpha`` the secant (mean) coefficient from the reference temperature,
    as CalculiX's ``*EXPANSION, ZERO=`` takes it: ``expansion_coefficient_per_K``
    at every temperature, or, with ``expansion_coefficients_per_K`` (one value
    per ``temperatures_degC``), linear between the table points and constant
    outside; the table's value at the reference temperature must then equal
    ``expansion_coefficient_per_K``.
    """

    temperatures_degC: tuple[float, ...] = (20.0, 80.0, 200.0, 350.0)
    youngs_modulus_Pa: tuple[float, ...] = (206e9, 202e9, 196e9, 186e9)
    poisson_ratio: float = 0.3
    expansion_coefficient_per_K: float = 1.12e-5
    reference_temperature_degC: float = 20.0
    expansion_coefficients_per_K: tuple[float, ...] = ()
    """Secant expansion coefficients from the reference temperature at
    ``temperatures_degC``, 1/K; empty: ``expansion_coefficient_per_K`` throughout."""

    _section = "material"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "poisson_ratio": (0.0, 0.5, False, True),
            "expansion_coefficient_per_K": (0.0, 1e-3),
            "reference_temperature_degC": (-273.15, 1500.0, True),
        })
        temps, moduli = self.temperatures_degC, self.youngs_modulus_Pa
        if len(temps) == 0:
            yield "material.temperatures_degC: needs at least one temperature, got none"
        elif len(temps) != len(moduli):
            yield (f"material.youngs_modulus_Pa: needs one value per temperatures_degC ({len(temps)}), "
                   f"got {len(moduli)}")
        for i, t in enumerate(temps):
            msg = range_problem(f"material.temperatures_degC[{i}]", t, -273.15, 1500.0, True)
            if msg:
                yield msg
        for i, e in enumerate(moduli):
            msg = range_problem(f"material.youngs_modulus_Pa[{i}]", e, 1e6, 1e13)
            if msg:
                yield msg
        if all(is_finite_number(t) for t in temps) and list(temps) != sorted(set(temps)):
            yield "material.temperatures_degC: must be strictly increasing"
        alphas = self.expansion_coefficients_per_K
        if alphas:
            if len(alphas) != len(temps):
                yield (f"material.expansion_coefficients_per_K: needs one value per temperatures_degC "
                       f"({len(temps)}), got {len(alphas)}")
                return
            bad = [msg for i, a in enumerate(alphas)
                   if (msg := range_problem(f"material.expansion_coefficients_per_K[{i}]", a, 0.0, 1e-3))]
            yield from bad
            if not bad and all(is_finite_number(t) for t in temps) and \
                    is_finite_number(self.expansion_coefficient_per_K) and \
                    is_finite_number(self.reference_temperature_degC):
                at_ref = self.expansion_coefficient(self.reference_temperature_degC)
                if abs(at_ref - self.expansion_coefficient_per_K) > 1e-9 * abs(at_ref):
                    yield (f"material.expansion_coefficient_per_K = {self.expansion_coefficient_per_K!r}: must equal "
                           f"expansion_coefficients_per_K at reference_temperature_degC ({at_ref:.6g})")

    def youngs_modulus(self, theta_degC: float) -> float:
        """E at ``theta_degC`` in Pa, linear between table points, constant outside."""
        import numpy as np
        return float(np.interp(theta_degC, self.temperatures_degC, self.youngs_modulus_Pa))

    def expansion_coefficient(self, theta_degC: float) -> float:
        """Secant expansion coefficient from the reference temperature at ``theta_degC``, 1/K.

        Linear between table points and constant outside, as CalculiX interpolates it.
        """
        if not self.expansion_coefficients_per_K:
            return float(self.expansion_coefficient_per_K)
        import numpy as np
        return float(np.interp(theta_degC, self.temperatures_degC, self.expansion_coefficients_per_K))

    def expansion_table(self) -> list[tuple[float, float]]:
        """``(alpha 1/K, theta degC)`` rows for ``*EXPANSION`` (one row without a table)."""
        if not self.expansion_coefficients_per_K:
            return [(float(self.expansion_coefficient_per_K), float(self.reference_temperature_degC))]
        return [(float(a), float(t)) for a, t in zip(self.expansion_coefficients_per_K, self.temperatures_degC)]


@dataclass(frozen=True)
class Sweep(Checked):
    """Temperatures to compute and the kiss-point definition."""

    temperatures_degC: tuple[float, ...] = (20.0, 80.0, 195.0, 250.0, 300.0)
    kiss_force_N: float = 10.0
    """Force of one paddle pair at which the kiss point (first contact) is taken."""
    thermal_distortion: bool = True
    """False sets the expansion coefficient to zero (stiffness change only)."""

    _section = "sweep"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"kiss_force_N": (0.0, 1e4, True)})
        if len(self.temperatures_degC) == 0:
            yield "sweep.temperatures_degC: needs at least one temperature"
        for i, t in enumerate(self.temperatures_degC):
            msg = range_problem(f"sweep.temperatures_degC[{i}]", t, -60.0, 600.0)
            if msg:
                yield msg
        if not isinstance(self.thermal_distortion, bool):
            yield f"sweep.thermal_distortion = {self.thermal_distortion!r}: must be true or false"


@dataclass(frozen=True)
class Mesh(Checked):
    """Target shell element edge length, m."""

    element_size_m: float = 0.5e-3
    element_type: str = "S4"
    """CalculiX shell element: ``"S4"`` (4 nodes, full integration), ``"S4R"``
    (reduced integration) or ``"S8R"`` (8 nodes, quadratic, reduced)."""

    _section = "mesh"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({"element_size_m": (0.1e-3, 10e-3)})
        if self.element_type not in ("S4", "S4R", "S8R"):
            yield f"mesh.element_type = {self.element_type!r}: allowed 'S4', 'S4R' or 'S8R'"


@dataclass(frozen=True)
class Solver(Checked):
    """CalculiX options.

    ``initial_gap_m`` is the clearance between the paddle crest and the
    pressure plate before heating; it must exceed the thermal growth of one
    paddle. Penalty contact is linear in the overclosure, with a slope that
    means different things for the two contact kinds, hence two keys:
    ``node_penalty_N_per_m`` is the force per slave node per metre of
    penetration (node-to-surface; CalculiX reads it in N/mm),
    ``surface_penalty_Pa_per_m`` the contact pressure per metre of
    penetration (surface-to-surface; CalculiX reads MPa/mm).
    ``tension_N`` is the small tension force at large gaps (node-to-surface).
    """

    contact: str = "node_to_surface"
    node_penalty_N_per_m: float = 1e8
    surface_penalty_Pa_per_m: float = 1e14
    tension_N: float = 0.01
    initial_gap_m: float = 0.15e-3
    compression_increments: int = 60
    max_increments: int = 1000
    flatten_fraction: float = 0.97
    """Fraction of the paddle's wave height by which it is pressed (1 = flat)."""
    threads: int = 1

    _section = "solver"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "node_penalty_N_per_m": (1e5, 1e12),
            "surface_penalty_Pa_per_m": (1e9, 1e18),
            "tension_N": (0.0, 10.0),
            "initial_gap_m": (0.0, 2e-3, True),
            "compression_increments": (30, 1000),
            "max_increments": (30, 100000),
            "flatten_fraction": (0.5, 1.0, True),
            "threads": (1, 64),
        })
        if self.contact not in ("node_to_surface", "surface_to_surface"):
            yield f"solver.contact = {self.contact!r}: allowed 'node_to_surface' or 'surface_to_surface'"
        yield from self._integers("compression_increments", "max_increments", "threads")


#: tolerance keys: allowed range of the standard deviation, and its unit
TOLERANCE_KEYS = {
    "thickness_m": (0.0, 50e-6, "m, added to geometry.thickness_m"),
    "wave_height_m": (0.0, 200e-6, "m, added to geometry.wave_height_m"),
    "youngs_modulus_scale": (0.0, 0.1, "1, factor 1 + x on every material.youngs_modulus_Pa"),
}


@dataclass(frozen=True)
class Tolerances(Checked):
    """Production scatter for tolerance studies (``cushion-clutch tolerance``).

    Each key is a table ``{sd = value}``: a normal distribution around the
    nominal value with that standard deviation, truncated at
    ``TRUNCATE_SD`` standard deviations. ``thickness_m`` and ``wave_height_m``
    are in m and add to the nominal geometry; ``youngs_modulus_scale`` is
    dimensionless and scales the whole E(theta) table by ``1 + x``. A key
    left out does not vary. Tolerances never enter a sweep's result.
    """

    thickness_m: dict | None = None
    wave_height_m: dict | None = None
    youngs_modulus_scale: dict | None = None

    TRUNCATE_SD = 3.0
    _section = "tolerances"

    def _problems(self) -> Iterable[str]:
        for name, (lo, hi, unit) in TOLERANCE_KEYS.items():
            value = getattr(self, name)
            if value is None:
                continue
            key = f"tolerances.{name}"
            if not isinstance(value, dict) or set(value) != {"sd"}:
                yield f"{key} = {value!r}: must be a table {{sd = <standard deviation>}} ({unit})"
                continue
            msg = range_problem(f"{key}.sd", value["sd"], lo, hi)
            if msg:
                yield f"{msg} ({unit})"

    def declared(self) -> dict[str, float]:
        """Standard deviation of every declared, non-zero tolerance."""
        return {k: float(getattr(self, k)["sd"]) for k in TOLERANCE_KEYS
                if getattr(self, k) is not None and getattr(self, k)["sd"] > 0}


@dataclass(frozen=True)
class SpringParams(Checked):
    """A whole cushion spring: ``n_pairs`` identical paddle pairs in parallel."""

    name: str = "default"
    description: str = ""
    n_pairs: int = 8
    geometry: Geometry = field(default_factory=Geometry)
    carrier: Carrier = field(default_factory=Carrier)
    joint: Joint = field(default_factory=Joint)
    material: Material = field(default_factory=Material)
    sweep: Sweep = field(default_factory=Sweep)
    mesh: Mesh = field(default_factory=Mesh)
    solver: Solver = field(default_factory=Solver)
    tolerances: Tolerances = field(default_factory=Tolerances)

    def _problems(self) -> Iterable[str]:
        if not (is_number(self.n_pairs) and isinstance(self.n_pairs, int) and 1 <= self.n_pairs <= 64):
            yield f"n_pairs = {self.n_pairs!r}: must be an integer in [1, 64]"
        ref = self.material.reference_temperature_degC
        if not any(abs(t - ref) < 1e-9 for t in self.sweep.temperatures_degC):
            yield (f"sweep.temperatures_degC = {list(self.sweep.temperatures_degC)}: must include "
                   f"material.reference_temperature_degC = {ref:g} (the kiss-point reference)")
        if not isinstance(self.name, str) or not self.name or not all(
                c.isalnum() or c in "-_." for c in self.name):
            yield f"name = {self.name!r}: must be a non-empty name of letters, digits, '-', '_', '.'"
        try:
            need, clearance = self.min_carrier_clearance_m(), float(self.geometry.carrier_clearance_m)
        except (TypeError, ValueError):
            return                                   # the sections name their own bad values
        if clearance < need:
            yield (f"geometry.carrier_clearance_m = {clearance:g}: below the sheet's thermal growth towards the "
                   f"carrier at {max(self.sweep.temperatures_degC):g} degC (alpha * (theta - theta_ref) * "
                   f"thickness / 2 = {need:.3g} m); heating alone would press the paddle on the carrier "
                   f"(a spurious force); allowed >= {need:.3g} m")

    def min_carrier_clearance_m(self) -> float:
        """Least carrier clearance heating alone does not close, m.

        The sheet thickens by ``alpha (theta_max - theta_ref) t``, half of it
        towards the carrier, at the hottest sweep temperature (0 without thermal
        distortion). The contact law reaches a little further: a case whose plates
        take a force from heating alone is refused after solving
        (:func:`cushion_clutch.fe.cases.check_heating`).
        """
        if not self.sweep.thermal_distortion:
            return 0.0
        t_max = max(float(t) for t in self.sweep.temperatures_degC)
        dt = t_max - float(self.material.reference_temperature_degC)
        return max(0.0, self.material.expansion_coefficient(t_max) * dt * 0.5 * float(self.geometry.thickness_m))

    def replace(self, **sections: Any) -> "SpringParams":
        """Return a copy with top-level fields or whole sections replaced.

        A section may be given as a dict of its fields to change, e.g.
        ``params.replace(mesh={"element_size_m": 2e-3})``.
        """
        changes = {}
        for key, value in sections.items():
            current = getattr(self, key)
            if isinstance(value, dict) and dataclasses.is_dataclass(current):
                value = dataclasses.replace(current, **value)
            changes[key] = value
        return dataclasses.replace(self, **changes)

    def to_dict(self) -> dict[str, Any]:
        """All parameters as plain TOML/JSON-able data."""
        return dataclasses.asdict(self)


def params_from_dict(data: dict[str, Any], source: str | None = None) -> SpringParams:
    """Build :class:`SpringParams` from nested dicts, rejecting unknown keys."""
    return build_checked(SpringParams, data, source)


def load_params(path: str | Path = DEFAULT_SPRING) -> SpringParams:
    """Load and check a spring parameter TOML file.

    Raises
    ------
    ParameterError
        On a missing or empty file, a TOML syntax error, a missing ``name``
        (a spring must name itself), an unknown key or an out-of-range value.
    """
    data = load_toml(path, required=("name",))
    geom = data.get("geometry")
    if isinstance(geom, dict) and isinstance(geom.get("surface_file"), str) and geom["surface_file"]:
        # relative to the TOML's folder, so that a sweep from any folder finds it
        geom["surface_file"] = str((Path(path).parent / geom["surface_file"]).resolve())
    return params_from_dict(data, str(Path(path)))
