"""Clutch thermal network v2: a chain of eight lumped nodes through the clutch pack (the plant's truth, and
the TCUs' own models with a stated mismatch).

Node chain (:data:`NODES`), temperatures in K, axial order::

    engine block ~ flywheel bulk -- flywheel 5 mm layer -- flywheel 1 mm surface layer
      -- facing (flywheel side) -- [disc, cushion spring] -- facing (plate side)
      -- pressure-plate 1 mm surface layer -- pressure-plate 5 mm layer -- pressure-plate bulk

* **Friction surfaces resolved.** Each metal part is a 1 mm surface layer, a 5 mm layer and the rest of
  its heat capacity (the bulk), conducting through the part's thickness over the friction annulus
  ``A = pi (r_o^2 - r_i^2)``: ``G = k A / (half-thickness + half-thickness)``. Over a 1-3 s slip the heat
  penetrates ``sqrt(alpha t)`` = 4-6 mm into cast iron, so the two layers carry the surface's rise during a
  slip (a test compares the surface layer with the semi-infinite body's closed form) and the bulk its
  rise over a duty.
* **Slip heat.** Each friction interface takes half of ``P = T w_slip``, divided between facing and metal
  by their thermal effusivities ``e = sqrt(k rho c)`` (two semi-infinite bodies in perfect contact, the
  Blok/Charron partition): the facing takes ``e_f / (e_f + e_m)`` (5.1 % with the measured lining of
  :data:`LINING`), the metal surface layer the rest.
* **Facing.** One node per facing (its mean temperature; the facing's own diffusion time
  ``t_f^2 / alpha_f`` is about 15 s (the measured lining), so its mean lags its surface). While clamped it conducts into the
  metal's surface layer through its half thickness in series with the contact conductance; the two facings
  exchange heat through the disc (``disc_W_per_K``, always).
* **Sinks.** Convection to the bell-housing air (at ambient) from the bulk nodes and the facings:
  ``G(w) = A_c (h_still + h_rot (|w| / w_ref)^0.8)`` (still air with radiation, plus the rotating disc's
  forced convection, turbulent Nu ~ Re^0.8); flywheel and pressure plate turn with the engine, the facings
  with the disc. The flywheel bulk also conducts into the engine block (``engine_W_per_K``, at
  ``engine_degC``). The cover's straps and diaphragm fulcrum (about 0.1 W/K) are neglected, which keeps
  the network a chain.
* **Cushion spring**: the clutch model's own ODE
  ``C dtheta_cs/dt = U (theta_cm - theta_cs) + H (theta_a - theta_cs)`` fed by ``theta_cm``, the mean of the
  two facing nodes (the FMU integrates it).

The chain is exposed as plain arrays by :func:`chain` (and its speed-independent parts by
:func:`coefficients`, which the thermal clutch FMU's C table is generated from).
:meth:`ThermalNetwork.step` advances node by node with the exact exponential solution for the node's
neighbours held (Gauss-Seidel exponential splitting): stable for any step, first-order accurate in the
coupling (a test compares it with scipy's ``solve_ivp`` on the full linear system).

Parameter sources and uncertainties: the docstrings of :class:`NetworkParams` and
``docs/explanation/thermal.md``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

import numpy as np

from ..config import Checked
from .spring_table import KELVIN

#: node order of every state vector
NODES = ("flywheel_bulk", "flywheel_layer", "flywheel_surface", "facing_flywheel_side",
         "facing_plate_side", "pressure_plate_surface", "pressure_plate_layer", "pressure_plate_bulk")
N_NODES = len(NODES)
#: indices of the two facing nodes (theta_cm is their mean) and of the two metal friction surfaces
FACINGS = (3, 4)
SURFACES = (2, 5)
#: which speed drives each node's convection: 0 engine, 1 disc
SPEED_OF_NODE = (0, 0, 0, 1, 1, 0, 0, 0)

#: the measured dry-clutch lining (new): Gkinis, Rahmani, Rahnejat, O'Mahony, "Integrated Thermal and Dynamic
#: Analysis of Dry Automotive Clutch Linings", Appl. Sci. 9(20):4287, 2019, doi:10.3390/app9204287, Table A2:
#: thermal conductivity 0.652 +- 0.13 W/(m K), specific heat 542 +- 35 J/(kg K), thermal diffusivity
#: (8.3 +- 0.3)e-7 m2/s; the density follows as k / (alpha c) = 1449 kg/m3 (+-21 %: the paper's uncertainties of
#: k and alpha)
LINING = {"conductivity_W_per_m_K": 0.652, "heat_J_per_kg_K": 542.0, "diffusivity_m2_per_s": 8.3e-7}
LINING_DENSITY_KG_M3 = LINING["conductivity_W_per_m_K"] / (LINING["diffusivity_m2_per_s"] * LINING["heat_J_per_kg_K"])


@dataclass(frozen=True)
class NetworkParams(Checked):
    """Parameters of the thermal network (SI; section ``[plant_thermal]``; the TCUs' copies in ``[tcu_thermal]``
    and ``[observer]``).

    A 240 mm single-plate passenger-car clutch, organic facings against grey cast iron. Sources
    (``docs/explanation/thermal.md`` gives the derivations):

    * friction annulus ``r_o`` 120 mm, ``r_i`` 60 mm: uniform-wear ``R_eq = (r_o + r_i)/2`` = 90 mm, the clutch
      model's ``R_eq`` 89 mm (+-5 % on the area);
    * grey cast iron k 50 W/(m K), rho 7200 kg/m3, c 500 J/(kg K) (pearlitic grey iron at 20-200 degC:
      k 45-55, c 460-560; +-10 %);
    * organic (resin-bonded) facing: the measured new lining of :data:`LINING` (Gkinis et al. 2019, Table A2):
      k 0.652 W/(m K) (+-20 %), c 542 J/(kg K) (+-6.5 %), rho = k / (alpha c) = 1449 kg/m3 (rho c +-20 %),
      3.5 mm thick (typical 3.2-3.5 mm, +-10 %);
    * heat capacities of the metal parts that take part over a duty of minutes: the pressure plate
      (3.5 kg cast iron, 1750 J/K, +-20 %) and the flywheel's friction ring and web within ~25 mm of the face
      (5 kg, 2500 J/K, +-30 %; a single-mass flywheel weighs 8-12 kg, its hub and starter ring warm later);
    * facing-metal contact 3000 W/(m2 K) at 0.2-0.4 MPa (dry contact of a rough polymer composite on iron:
      1-10 kW/(m2 K); it is in series with the facing's half thickness, 12 W/K, which dominates);
    * facing to facing through the cushion segments, rivets and the air between them 0.5 W/K (factor 2);
    * flywheel to engine block 2 W/K (crank flange, factor 2), block at 90 degC;
    * convection ``h_still`` 10 W/(m2 K) (natural convection ~5 plus linearised radiation ~5 at emissivity
      0.6; +-50 %), ``h_rot`` 50 W/(m2 K) at 300 rad/s (rotating disc r 0.12 m in air: Re 2.3e5, laminar
      Nu 0.36 Re^0.5 gives 40, turbulent 0.015 Re^0.8 gives 67; +-50 %), over the cooled areas (pressure
      plate's back and ribs 0.06 m2, flywheel rim and back 0.06 m2, each facing's edges and open faces
      0.01 m2; +-50 %).
    """

    friction_outer_radius_m: float = 0.12
    friction_inner_radius_m: float = 0.06
    metal_conductivity_W_per_m_K: float = 50.0
    metal_density_kg_m3: float = 7200.0
    metal_heat_J_per_kg_K: float = 500.0
    facing_conductivity_W_per_m_K: float = LINING["conductivity_W_per_m_K"]
    facing_density_kg_m3: float = LINING_DENSITY_KG_M3
    facing_heat_J_per_kg_K: float = LINING["heat_J_per_kg_K"]
    facing_thickness_m: float = 0.0035
    surface_layer_m: float = 0.001
    """thickness of each metal part's surface node"""
    subsurface_layer_m: float = 0.005
    """thickness of the layer under it; the rest of the part's capacity is its bulk node"""
    flywheel_capacity_J_per_K: float = 2500.0
    """whole flywheel node group (layers and bulk)"""
    pressure_plate_capacity_J_per_K: float = 1750.0
    """whole pressure-plate node group (layers and bulk)"""
    contact_W_per_m2_K: float = 3000.0
    """facing-metal contact conductance while clamped"""
    disc_W_per_K: float = 0.5
    """facing to facing through the disc and cushion spring"""
    engine_W_per_K: float = 2.0
    engine_degC: float = 90.0
    still_air_W_per_m2_K: float = 10.0
    """heat-transfer coefficient at rest (natural convection and radiation)"""
    rotating_W_per_m2_K: float = 50.0
    """forced convection added at ``convection_reference_rad_s``; scales with (|w| / w_ref)^0.8"""
    convection_reference_rad_s: float = 300.0
    flywheel_cooled_area_m2: float = 0.06
    pressure_plate_cooled_area_m2: float = 0.06
    facing_cooled_area_m2: float = 0.01
    """each facing"""

    _section = "plant_thermal"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges(spec := {
            "friction_outer_radius_m": (0.03, 0.5), "friction_inner_radius_m": (0.01, 0.4),
            "metal_conductivity_W_per_m_K": (1.0, 500.0), "metal_density_kg_m3": (1000.0, 20000.0),
            "metal_heat_J_per_kg_K": (100.0, 2000.0), "facing_conductivity_W_per_m_K": (0.05, 50.0),
            "facing_density_kg_m3": (500.0, 10000.0), "facing_heat_J_per_kg_K": (100.0, 3000.0),
            "facing_thickness_m": (0.5e-3, 0.02), "surface_layer_m": (0.1e-3, 0.01),
            "subsurface_layer_m": (0.1e-3, 0.03), "flywheel_capacity_J_per_K": (1.0, 1e6),
            "pressure_plate_capacity_J_per_K": (1.0, 1e6), "contact_W_per_m2_K": (0.0, 1e6),
            "disc_W_per_K": (0.0, 1e4), "engine_W_per_K": (0.0, 1e4), "engine_degC": (-50.0, 150.0),
            "still_air_W_per_m2_K": (0.0, 1e3), "rotating_W_per_m2_K": (0.0, 1e4),
            "convection_reference_rad_s": (1.0, 2000.0), "flywheel_cooled_area_m2": (0.0, 1.0),
            "pressure_plate_cooled_area_m2": (0.0, 1.0), "facing_cooled_area_m2": (0.0, 1.0)})
        if not self._passed(spec, *spec):
            return                                  # the rules below combine them all
        if self.friction_inner_radius_m >= self.friction_outer_radius_m:
            yield f"{self._key('friction_inner_radius_m')}: must be below friction_outer_radius_m"
            return
        layers = self.metal_volumetric_J_per_m3_K * self.area_m2 * (self.surface_layer_m + self.subsurface_layer_m)
        for key in ("flywheel_capacity_J_per_K", "pressure_plate_capacity_J_per_K"):
            if getattr(self, key) <= 1.5 * layers:
                yield (f"{self._key(key)} = {getattr(self, key)!r}: must exceed 1.5 x the two layers' "
                       f"{layers:.4g} J/K (the part needs a bulk)")

    # --- derived quantities ------------------------------------------------------------------------------
    @property
    def area_m2(self) -> float:
        """Friction annulus, m2."""
        return math.pi * (self.friction_outer_radius_m ** 2 - self.friction_inner_radius_m ** 2)

    @property
    def metal_volumetric_J_per_m3_K(self) -> float:
        return self.metal_density_kg_m3 * self.metal_heat_J_per_kg_K

    @property
    def metal_effusivity_W_s05_per_m2_K(self) -> float:
        return math.sqrt(self.metal_conductivity_W_per_m_K * self.metal_volumetric_J_per_m3_K)

    @property
    def facing_effusivity_W_s05_per_m2_K(self) -> float:
        return math.sqrt(self.facing_conductivity_W_per_m_K * self.facing_density_kg_m3
                         * self.facing_heat_J_per_kg_K)

    @property
    def facing_share(self) -> float:
        """Share of an interface's heat that goes into the facing (effusivity partition), 1."""
        ef, em = self.facing_effusivity_W_s05_per_m2_K, self.metal_effusivity_W_s05_per_m2_K
        return ef / (ef + em)

    @property
    def facing_capacity_J_per_K(self) -> float:
        """Each facing, J/K."""
        return self.facing_density_kg_m3 * self.facing_heat_J_per_kg_K * self.area_m2 * self.facing_thickness_m

    @property
    def capacities(self) -> np.ndarray:
        """Heat capacity of each node in :data:`NODES` order, J/K."""
        return np.array(coefficients(self)["caps"])

    def convection(self, area_m2: float, w: float) -> float:
        """Convective conductance of ``area_m2`` turning at ``w`` (rad/s), W/K."""
        return area_m2 * (self.still_air_W_per_m2_K + self.rotating_W_per_m2_K
                          * (abs(w) / self.convection_reference_rad_s) ** 0.8)


@dataclass(frozen=True)
class TcuNetworkBase(NetworkParams):
    """The same physical network as a TCU maker would parametrise it, mismatched with the plant by default.

    Stated mismatch: every metal capacity +15 % (2875 and 2012.5 J/K: the participating mass is a
    judgement), the facings +15 % through their density (1667 kg/m3), every heat-transfer coefficient
    -20 % (contact 2400, still air 8, rotating 40 W/(m2 K)) and the engine-block conductance -20 % (1.6 W/K).
    Geometry and materials' conductivities as the plant (from the drawing).
    """

    flywheel_capacity_J_per_K: float = 2875.0
    pressure_plate_capacity_J_per_K: float = 2012.5
    facing_density_kg_m3: float = 1.15 * LINING_DENSITY_KG_M3
    contact_W_per_m2_K: float = 2400.0
    engine_W_per_K: float = 1.6
    still_air_W_per_m2_K: float = 8.0
    rotating_W_per_m2_K: float = 40.0


def coefficients(p: NetworkParams) -> dict[str, list[float]]:
    """The chain's speed-independent coefficients (what the thermal FMU's C table holds), per node or link.

    ``caps`` (J/K, per node); ``link_always`` and ``link_clamped`` (W/K, per link i -- i+1; a link's
    conductance is ``link_always + link_clamped`` while clamped, else ``link_always``); ``area_cooled`` (m2,
    per node: convection ``area (h_still + h_rot (|w|/w_ref)^0.8)`` with ``w`` the engine speed or the disc
    speed by :data:`SPEED_OF_NODE`); ``engine`` (W/K, per node, to the block at ``engine_degC``); ``shares``
    (1, per node: its share of the slip power; they sum to 1).
    """
    a, k, rc = p.area_m2, p.metal_conductivity_W_per_m_K, p.metal_volumetric_J_per_m3_K
    d1, d2 = p.surface_layer_m, p.subsurface_layer_m
    c1, c2 = rc * a * d1, rc * a * d2
    cf = p.facing_capacity_J_per_K
    cfb, cpb = p.flywheel_capacity_J_per_K - c1 - c2, p.pressure_plate_capacity_J_per_K - c1 - c2
    dfb, dpb = cfb / (rc * a), cpb / (rc * a)             # equivalent thickness of the bulk nodes, m
    g12 = k * a / (0.5 * (d1 + d2))
    gfb, gpb = k * a / (0.5 * (dfb + d2)), k * a / (0.5 * (dpb + d2))
    # facing half thickness + contact + the surface layer's half thickness, in series
    r_contact = 0.5 * p.facing_thickness_m / (p.facing_conductivity_W_per_m_K * a) + 0.5 * d1 / (k * a) \
        + (1.0 / (p.contact_W_per_m2_K * a) if p.contact_W_per_m2_K > 0.0 else math.inf)
    gc = 1.0 / r_contact
    sf = 0.5 * p.facing_share
    sm = 0.5 - sf
    return {"caps": [cfb, c2, c1, cf, cf, c1, c2, cpb],
            "link_always": [gfb, g12, 0.0, p.disc_W_per_K, 0.0, g12, gpb],
            "link_clamped": [0.0, 0.0, gc, 0.0, gc, 0.0, 0.0],
            "area_cooled": [p.flywheel_cooled_area_m2, 0.0, 0.0, p.facing_cooled_area_m2, p.facing_cooled_area_m2,
                            0.0, 0.0, p.pressure_plate_cooled_area_m2],
            "engine": [p.engine_W_per_K] + [0.0] * 7,
            "shares": [0.0, 0.0, sm, sf, sf, sm, 0.0, 0.0]}


def chain(p: NetworkParams, theta_a: float, w_engine: float, w_disc: float, clamped: bool,
          coef: dict | None = None) -> tuple[list[float], list[float], list[float], list[float], list[float]]:
    """The chain at one operating point: ``(caps J/K, links W/K, sink_g W/K, sink_t K, shares 1)``.

    ``links[i]`` couples nodes i and i+1; node i loses ``sink_g[i] (theta_i - sink_t[i])``; it receives
    ``shares[i] P_slip``. ``theta_a`` is the air temperature (K), the speeds in rad/s.
    """
    c = coefficients(p) if coef is None else coef
    links = [la + lc for la, lc in zip(c["link_always"], c["link_clamped"])] if clamped else list(c["link_always"])
    theta_e = p.engine_degC + KELVIN
    speeds = (w_engine, w_disc)
    sink_g, sink_t = [], []
    for i in range(N_NODES):
        conv = p.convection(c["area_cooled"][i], speeds[SPEED_OF_NODE[i]]) if c["area_cooled"][i] > 0.0 else 0.0
        ge = c["engine"][i]
        g = conv + ge
        sink_g.append(g)
        sink_t.append((ge * theta_e + conv * theta_a) / g if g > 0.0 else theta_a)
    return list(c["caps"]), links, sink_g, sink_t, list(c["shares"])


class ThermalNetwork:
    """State of the chain's nodes (K, :data:`NODES` order); :meth:`step` advances it.

    Parameters
    ----------
    p : NetworkParams
    theta_a : float
        Bell-housing air (ambient) temperature, K.
    theta0 : float
        Temperature of every node at the start, K.
    """

    __slots__ = ("p", "theta_a", "theta", "caps", "coef", "shares", "_cache")

    def __init__(self, p: NetworkParams, theta_a: float, theta0: float):
        self.p, self.theta_a = p, theta_a
        self.coef = coefficients(p)
        self.caps = list(self.coef["caps"])
        self.shares = list(self.coef["shares"])
        self.theta = [theta0] * N_NODES
        self._cache: dict = {}

    @property
    def theta_cm(self) -> float:
        """Facing temperature for the clutch model: mean of the two facings, K."""
        return 0.5 * (self.theta[FACINGS[0]] + self.theta[FACINGS[1]])

    @property
    def theta_friction(self) -> float:
        """Friction-surface temperature, K: the mean of the two metal friction surfaces (their 1 mm layers).

        mu is read here (issue 37): the interface is at the metal's surface temperature (the metal's
        effusivity is 19 times the lining's, so the contact temperature sits within a few per cent of the
        metal side's rise), not at the facings' mean, which lags it by the lining's 15 s diffusion time.
        Each interface carries half the torque at the same clamp force, so the torque's mu is the mean of
        the two interfaces' mu; the mean of the temperatures gives it exactly where both lie between the
        same two rows of a piecewise-linear friction table."""
        return 0.5 * (self.theta[SURFACES[0]] + self.theta[SURFACES[1]])

    @property
    def theta_surface(self) -> float:
        """The hotter metal friction surface (its 1 mm surface layer), K."""
        return max(self.theta[SURFACES[0]], self.theta[SURFACES[1]])

    @property
    def stored_J(self) -> float:
        """Heat stored relative to the ambient, J."""
        return sum(c * (t - self.theta_a) for c, t in zip(self.caps, self.theta))

    def conductances(self, w_engine: float, w_disc: float, clamped: bool) -> tuple[list[float], list[float],
                                                                                     list[float]]:
        """(links W/K, sink conductance per node W/K, sink temperature per node K) at this operating point."""
        _, links, sink_g, sink_t, _ = chain(self.p, self.theta_a, w_engine, w_disc, clamped, self.coef)
        return links, sink_g, sink_t

    def heat_inputs(self, p_slip_W: float) -> list[float]:
        """Slip power into each node, W (half per interface, split by effusivity)."""
        return [s * p_slip_W for s in self.shares]

    def matrices(self, w_engine: float, w_disc: float, clamped: bool) -> tuple[np.ndarray, np.ndarray]:
        """Continuous-time ``dtheta/dt = A theta + b`` for the slip power held at 0 W: (A 1/s, b K/s).

        The slip power adds ``heat_inputs(P) / capacities``.
        """
        links, sink_g, sink_t = self.conductances(w_engine, w_disc, clamped)
        c = np.array(self.caps)
        g = np.zeros((N_NODES, N_NODES))
        for i, gl in enumerate(links):
            g[i, i + 1] = g[i + 1, i] = gl
        a = g.copy()
        a[np.diag_indices(N_NODES)] = -(g.sum(axis=1) + np.array(sink_g))
        return a / c[:, None], np.array(sink_g) * np.array(sink_t) / c

    def _table(self, clamped: bool) -> tuple:
        """Per node ``(cap, g_left, g_right, area_cooled, speed index, g_engine * theta_engine, g_fixed, share)``
        for one clamp state (``g_fixed``: links and engine, the part of the node's conductance without speed)."""
        c = self.coef
        links = [la + lc for la, lc in zip(c["link_always"], c["link_clamped"])] if clamped else c["link_always"]
        theta_e = self.p.engine_degC + KELVIN
        rows = []
        for i in range(N_NODES):
            gl = links[i - 1] if i > 0 else 0.0
            gr = links[i] if i < N_NODES - 1 else 0.0
            rows.append((self.caps[i], gl, gr, c["area_cooled"][i], SPEED_OF_NODE[i], c["engine"][i] * theta_e,
                         gl + gr + c["engine"][i], self.shares[i]))
        return tuple(rows)

    def _prepare(self, clamped: bool, dt: float) -> tuple:
        """The per-node constants of :meth:`step` for one clamp state and step: ``(i, cap, g_left, g_right,
        area_cooled, disc speed?, g_engine * theta_engine, g_fixed, share, decay or None)`` per node (the decay
        factor precomputed for a node without convection), and the convection constants."""
        p = self.p
        nodes = tuple((i, cap, gl, gr, area, sp == 1, ge_te, gfix, share,
                       math.exp(-dt * gfix / cap) if area == 0.0 and gfix > 0.0 else None)
                      for i, (cap, gl, gr, area, sp, ge_te, gfix, share) in enumerate(self._table(clamped)))
        hit = self._cache[(clamped, dt)] = (nodes, p.still_air_W_per_m2_K, p.rotating_W_per_m2_K,
                                            p.convection_reference_rad_s)
        return hit

    def step(self, dt: float, p_slip_W: float, w_engine: float, w_disc: float, clamped: bool) -> None:
        """Advance ``dt`` s with the slip power (W), speeds (rad/s) and clamp state held.

        The same conductances as :meth:`conductances`, evaluated inline (this runs every TCU period); the
        node constants and the decay factors of the nodes without convection are cached per step and clamp
        state (:meth:`_prepare`; ``shares`` and ``caps`` are read at the first step).
        """
        hit = self._cache.get((clamped, dt))
        if hit is None:
            hit = self._prepare(clamped, dt)
        nodes, h0, hr, wr = hit
        h_engine = h0 + hr * (abs(w_engine) / wr) ** 0.8
        h_disc = h0 + hr * (abs(w_disc) / wr) ** 0.8
        ta = self.theta_a
        th = self.theta
        left = 0.0
        for i, cap, gl, gr, area, on_disc, ge_te, gfix, share, decay in nodes:
            flow = share * p_slip_W + ge_te
            if gl:
                flow += gl * left
            if gr:
                flow += gr * th[i + 1]
            if decay is None:
                conv = area * (h_disc if on_disc else h_engine)
                gs = gfix + conv
                flow += conv * ta
                if gs > 0.0:
                    decay = math.exp(-dt * gs / cap)
            else:
                gs = gfix
            if gs > 0.0:
                inf = flow / gs
                left = th[i] = inf + (th[i] - inf) * decay
            else:
                left = th[i] = th[i] + flow * dt / cap


@dataclass(frozen=True)
class PlantThermal(NetworkParams):
    """Section ``[plant_thermal]``: the plant's network (on by default); ``enabled = false`` uses the lumped
    ``[facing]`` model instead (one node taking ``heat_share`` of the slip power: a calibration knob, not a
    physical part: 450 J/K is the heat capacity of about 1 kg of steel)."""

    enabled: bool = True


def time_constants(p: NetworkParams, w_engine: float = 0.0, w_disc: float = 0.0,
                   clamped: bool = False) -> np.ndarray:
    """Time constants of the network's modes (``-1/eigenvalue`` of A), s, ascending."""
    a, _ = ThermalNetwork(p, 293.15, 293.15).matrices(w_engine, w_disc, clamped)
    return np.sort(-1.0 / np.linalg.eigvals(a).real)


def node_time_constants(p: NetworkParams, w_engine: float = 0.0, w_disc: float = 0.0,
                        clamped: bool = False) -> dict[str, float]:
    """Each node's own time constant ``C_i / sum(G_i)`` with its neighbours held, s."""
    a, _ = ThermalNetwork(p, 293.15, 293.15).matrices(w_engine, w_disc, clamped)
    return {n: float(-1.0 / a[i, i]) for i, n in enumerate(NODES)}
