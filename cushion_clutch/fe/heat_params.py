"""Inputs of the disc-sector thermal FE (``cushion-clutch heat-path``): materials, joints, films, the heating.

SI units (m, W, J, kg, K; temperatures in degC where a name says so). The
spring's geometry (radii, span, thickness, wave, clamp zone, number of pairs)
is NOT here: it comes from the spring parameter file
(:func:`cushion_clutch.fe.params.load_params`). What is here is what the
spring file does not describe: the facings, the carrier, the rivets, the
contact conductances and the films, each with its source and an uncertainty
range (:data:`UNCERTAIN`), which ``heat-path`` propagates by re-solving at each
bound on the coarse mesh.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Iterable

from ..config import Checked

#: the steel specific heat range the result is checked against, J/(kg K) (carbon and spring steels, 20-300 degC)
STEEL_C_RANGE_J_PER_KG_K = (430.0, 520.0)


@dataclass(frozen=True)
class HeatPathParams(Checked):
    """Everything of the thermal FE that the spring file does not give.

    Sources (the docs page ``docs/explanation/heat_path.md`` repeats them):

    - lining: Gkinis et al., Appl. Sci. 9(20):4287 (2019), Table A2 (measured organic
      dry-clutch lining): k 0.652 W/(m K), c 542 J/(kg K), rho about 1450 kg/m^3;
      thickness 3.5 mm, a common passenger-car facing (the thermal network's value);
    - steel (paddles, carrier): rho 7850 kg/m^3 (as the structural FE), c 477 J/(kg K) and
      k 45 W/(m K) (plain carbon/spring steel near 100 degC, e.g. Incropera, Fundamentals of
      Heat and Mass Transfer, Table A.1, AISI 1010: 434-487 J/(kg K), 64-58 W/(m K); alloyed
      spring steels lower: 40-50 W/(m K));
    - rivets: brass (CuZn37) k 113 W/(m K), rho 8440 kg/m^3, c 377 J/(kg K) (Incropera Table A.1,
      cartridge brass); shank 3 mm, head 5.5 mm, two per paddle on its crest;
    - contact conductances: order-of-magnitude values of the contact-conductance literature
      (Madhusudana, Thermal Contact Conductance, 2nd ed., Springer 2014; Yovanovich, IEEE Trans.
      Comp. Pack. Technol. 28(2), 2005: metal-to-metal joints 1e3-1e4 W/(m^2 K) at 0.1-10 MPa;
      a polymer-bound lining on steel at the light pressure of a riveted, open facing lower),
      each with a factor-of-3 or 4 band; none was measured on this disc;
    - air gap: k_air 0.030 W/(m K) at about 80 degC (VDI Heat Atlas), over the gap the wave leaves
      between paddle and facing, plus a linearised radiation term;
    - convection: a clutch disc in a closed bell housing, standing or turning (rotating-disc
      correlation Nu = 0.33 Re^0.5 gives about 30 W/(m^2 K) at 2000 rpm; still air 5-10), a
      cycle mean of 15 W/(m^2 K) with a band 5-40.
    """

    facing_thickness_m: float = 3.5e-3
    lining_conductivity_W_per_m_K: float = 0.652
    lining_specific_heat_J_per_kg_K: float = 542.0
    lining_density_kg_m3: float = 1450.0
    steel_conductivity_W_per_m_K: float = 45.0
    steel_specific_heat_J_per_kg_K: float = 477.0
    steel_density_kg_m3: float = 7850.0
    carrier_thickness_m: float = 1.5e-3
    """the carrier disc (hub flange) the paddle pairs are riveted to, m; it lies between the two paddles
    of a pair in the rivet zone (the model's mid-plane is its middle)"""
    carrier_inner_radius_m: float = 0.045
    """where the carrier meets the hub (splines, damper), m: its cut edge carries the hub film"""
    rivet_conductivity_W_per_m_K: float = 113.0
    rivet_density_kg_m3: float = 8440.0
    rivet_specific_heat_J_per_kg_K: float = 377.0
    rivet_shank_diameter_m: float = 3.0e-3
    rivet_head_diameter_m: float = 5.5e-3
    rivets_per_paddle: int = 2
    counterbore_depth_fraction: float = 0.5
    """the rivet head sits this far down from the friction surface, as a share of the facing thickness:
    the shank crosses the rest of the lining to the paddle"""
    crest_contact_W_per_m2_K: float = 2000.0
    """paddle crest on the lining (light pressure of a riveted facing), W/(m^2 K)"""
    crest_contact_gap_m: float = 20e-6
    """where the wave leaves less than this between paddle and facing, the two touch (roughness scale), m"""
    rivet_head_contact_W_per_m2_K: float = 3000.0
    """rivet head on the lining (clinched), W/(m^2 K), over the head's annulus"""
    rivet_clinch_contact_W_per_m2_K: float = 5000.0
    """clinched rivet shank and head on the paddle (metal-metal), W/(m^2 K), over the shank's section"""
    joint_contact_W_per_m2_K: float = 3000.0
    """riveted paddle-to-carrier joint over the clamp zone (steel on steel), W/(m^2 K)"""
    air_conductivity_W_per_m_K: float = 0.030
    radiation_W_per_m2_K: float = 6.0
    """linearised radiation across the paddle-facing gap, 4 sigma eps_eff T^3 with eps_eff 0.5 at 100 degC"""
    convection_W_per_m2_K: float = 15.0
    """exposed faces of paddles, carrier and the facings' sides, cycle mean"""
    hub_W_per_m2_K: float = 2000.0
    """the carrier's inner cut edge to ambient: the hub, damper and shaft as a sink, W/(m^2 K) over the edge"""
    friction_surface_W_per_m2_K: float = 100.0
    """friction surface to ambient: flywheel and pressure plate as a sink; shapes theta_cm's history only"""
    ambient_degC: float = 20.0
    launches: int = 4
    launch_period_s: float = 60.0
    slip_time_s: float = 1.5
    slip_energy_J: float = 20000.0
    """friction work of one launch on the whole disc, J (a loaded uphill launch)"""
    facing_heat_share: float = 0.05
    """share of the friction work that enters the facings (the thermal network's share with the measured
    lining); the rest goes into flywheel and pressure plate, outside this model"""
    cooldown_s: float = 360.0
    """after the last launch's period: the decay of theta_cs and theta_cm"""

    _section = "heat_path"

    def _problems(self) -> Iterable[str]:
        positive = {f.name: (0.0, 1e7, True) for f in dataclasses.fields(self)
                    if f.name.endswith(("_m", "_W_per_m_K", "_J_per_kg_K", "_kg_m3", "_W_per_m2_K", "_s", "_J"))}
        yield from self._ranges(positive)
        yield from self._ranges({"facing_heat_share": (0.0, 1.0, True), "counterbore_depth_fraction": (0.0, 1.0, True, True),
                                 "ambient_degC": (-60.0, 200.0), "launches": (1, 50), "rivets_per_paddle": (0, 10)})
        yield from self._integers("launches", "rivets_per_paddle")
        if self.rivet_head_diameter_m <= self.rivet_shank_diameter_m:
            yield "heat_path.rivet_head_diameter_m: must exceed rivet_shank_diameter_m"
        if self.slip_time_s >= self.launch_period_s:
            yield "heat_path.slip_time_s: must be shorter than launch_period_s"


#: the uncertain inputs and their bands (low, high): ``heat-path`` re-solves the coarse mesh at each bound
UNCERTAIN: dict[str, tuple[float, float]] = {
    "crest_contact_W_per_m2_K": (500.0, 8000.0),
    "rivet_head_contact_W_per_m2_K": (1000.0, 10000.0),
    "joint_contact_W_per_m2_K": (1000.0, 10000.0),
    "convection_W_per_m2_K": (5.0, 40.0),
    "hub_W_per_m2_K": (500.0, 8000.0),
    "air_conductivity_W_per_m_K": (0.026, 0.034),
}
