"""Clutch thermal network: flywheel, pressure plate and both facings (the plant's truth, and the TCU's own model).

Four lumped nodes, temperatures in K::

    flywheel (fw) -- facing 1 (f1) -- [disc] -- facing 2 (f2) -- pressure plate (pp)

* **Slip heat.** Both friction faces carry the same torque at the same slip
  speed, so each interface gets half of the slip power ``P = T w_slip``. At an
  interface the heat divides between the two bodies in proportion to their
  thermal effusivities ``e = sqrt(k rho c)`` (two semi-infinite bodies in
  perfect contact, the Blok/Charron partition): the facing takes
  ``e_f / (e_f + e_metal)``, the metal part the rest.
* **Conduction.** While the clutch is clamped each facing conducts into its
  metal partner through ``contact_W_per_K``; the two facings exchange heat
  through the disc (``disc_W_per_K``, always). The flywheel conducts into the
  engine block (``engine_W_per_K``, block at ``engine_degC``).
* **Convection** to the bell-housing air (at ambient) grows with the speed
  of the part: ``G(w) = G0 + (G_ref - G0) (|w| / w_ref)^0.8`` (turbulent
  forced convection, Nu ~ Re^0.8); flywheel and pressure plate turn with the
  engine, the facings with the disc.

The facing temperature handed to the clutch model, ``theta_cm``, is the mean
of the two facing nodes; the cushion spring between them stays the clutch
model's own ODE ``C dtheta_cs/dt = U (theta_cm - theta_cs) + H (theta_a - theta_cs)``
with the user's U, H, C (the FMU integrates it).

:meth:`ThermalNetwork.step` advances node by node with the exact exponential
solution for the node's neighbours held (Gauss-Seidel exponential splitting):
stable for any step, first-order accurate in the coupling (a test compares it
with scipy's ``solve_ivp`` on the full linear system).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Iterable

import numpy as np

from ..config import Checked
from ..model import KELVIN

#: node order of every state vector
NODES = ("flywheel", "facing_flywheel_side", "facing_plate_side", "pressure_plate")


@dataclass(frozen=True)
class NetworkParams(Checked):
    """Parameters of the thermal network (SI; section ``[plant_thermal]``, and ``[tcu_thermal]`` for the TCU's own).

    Defaults: a 240 mm passenger-car clutch. Heat capacities are the parts
    that take part over a one-minute launch cycle (the flywheel's friction
    ring, the pressure plate, one organic facing each); effusivities of cast
    iron (k 50 W/(m K), rho 7200 kg/m3, c 500 J/(kg K)) and an organic facing
    (k 0.6, rho 2000, c 1100).
    """

    flywheel_capacity_J_per_K: float = 2500.0
    pressure_plate_capacity_J_per_K: float = 1500.0
    facing_capacity_J_per_K: float = 190.0
    """each of the two facings"""
    metal_effusivity_W_s05_per_m2_K: float = 13400.0
    facing_effusivity_W_s05_per_m2_K: float = 1150.0
    contact_W_per_K: float = 8.0
    """facing to its metal partner while clamped"""
    disc_W_per_K: float = 0.5
    """facing to facing through the disc and cushion spring"""
    engine_W_per_K: float = 2.0
    engine_degC: float = 90.0
    flywheel_convection_W_per_K: float = 1.0
    pressure_plate_convection_W_per_K: float = 1.5
    facing_convection_W_per_K: float = 0.3
    """each facing, at rest"""
    convection_gain_at_reference: float = 4.0
    """G(w_ref) / G(0) of every node"""
    convection_reference_rad_s: float = 300.0

    _section = "plant_thermal"

    def _problems(self) -> Iterable[str]:
        yield from self._ranges({
            "flywheel_capacity_J_per_K": (1.0, 1e6), "pressure_plate_capacity_J_per_K": (1.0, 1e6),
            "facing_capacity_J_per_K": (1.0, 1e6), "metal_effusivity_W_s05_per_m2_K": (1.0, 1e6),
            "facing_effusivity_W_s05_per_m2_K": (1.0, 1e6), "contact_W_per_K": (0.0, 1e4),
            "disc_W_per_K": (0.0, 1e4), "engine_W_per_K": (0.0, 1e4), "engine_degC": (-50.0, 150.0),
            "flywheel_convection_W_per_K": (0.0, 1e4), "pressure_plate_convection_W_per_K": (0.0, 1e4),
            "facing_convection_W_per_K": (0.0, 1e4), "convection_gain_at_reference": (1.0, 100.0),
            "convection_reference_rad_s": (1.0, 2000.0)})

    @property
    def facing_share(self) -> float:
        """Share of an interface's heat that goes into the facing (effusivity partition), 1."""
        ef, em = self.facing_effusivity_W_s05_per_m2_K, self.metal_effusivity_W_s05_per_m2_K
        return ef / (ef + em)

    @property
    def capacities(self) -> np.ndarray:
        """Heat capacity of each node in :data:`NODES` order, J/K."""
        return np.array([self.flywheel_capacity_J_per_K, self.facing_capacity_J_per_K,
                         self.facing_capacity_J_per_K, self.pressure_plate_capacity_J_per_K])

    def convection(self, g0: float, w: float) -> float:
        """Convective conductance of a node with still-air value ``g0`` (W/K) turning at ``w`` (rad/s)."""
        return g0 * (1.0 + (self.convection_gain_at_reference - 1.0)
                     * (abs(w) / self.convection_reference_rad_s) ** 0.8)


class ThermalNetwork:
    """State of the four nodes (K); :meth:`step` advances it.

    Parameters
    ----------
    p : NetworkParams
    theta_a : float
        Bell-housing air (ambient) temperature, K.
    theta0 : float
        Temperature of every node at the start, K.
    """

    __slots__ = ("p", "theta_a", "theta_e", "theta", "share_f", "caps")

    def __init__(self, p: NetworkParams, theta_a: float, theta0: float):
        self.p, self.theta_a = p, theta_a
        self.theta_e = p.engine_degC + KELVIN
        self.theta = [theta0] * 4
        self.share_f = 0.5 * p.facing_share
        self.caps = p.capacities.tolist()

    @property
    def theta_cm(self) -> float:
        """Facing temperature for the clutch model: mean of the two facings, K."""
        return 0.5 * (self.theta[1] + self.theta[2])

    def conductances(self, w_engine: float, w_disc: float, clamped: bool) -> tuple[list[float], float, list[float]]:
        """(coupling fw-f1, f1-f2, f2-pp; sink conductance per node; sink temperature per node) in W/K and K."""
        p = self.p
        gc = p.contact_W_per_K if clamped else 0.0
        sink_g = [p.convection(p.flywheel_convection_W_per_K, w_engine) + p.engine_W_per_K,
                  p.convection(p.facing_convection_W_per_K, w_disc),
                  p.convection(p.facing_convection_W_per_K, w_disc),
                  p.convection(p.pressure_plate_convection_W_per_K, w_engine)]
        ta = self.theta_a
        sink_t = [(p.engine_W_per_K * self.theta_e + (sink_g[0] - p.engine_W_per_K) * ta) / sink_g[0]
                  if sink_g[0] > 0 else ta, ta, ta, ta]
        return [gc, p.disc_W_per_K, gc], sink_g, sink_t

    def heat_inputs(self, p_slip_W: float) -> list[float]:
        """Slip power into each node, W (half per interface, split by effusivity)."""
        qf = self.share_f * p_slip_W
        qm = 0.5 * p_slip_W - qf
        return [qm, qf, qf, qm]

    def matrices(self, w_engine: float, w_disc: float, clamped: bool) -> tuple[np.ndarray, np.ndarray]:
        """Continuous-time ``dtheta/dt = A theta + b`` for the slip power held at 0 W: (A 1/s, b K/s).

        The slip power adds ``heat_inputs(P) / capacities``.
        """
        links, sink_g, sink_t = self.conductances(w_engine, w_disc, clamped)
        c = np.array(self.caps)
        g = np.zeros((4, 4))
        for i, gl in enumerate(links):
            g[i, i + 1] = g[i + 1, i] = gl
        a = g.copy()
        a[np.diag_indices(4)] = -(g.sum(axis=1) + np.array(sink_g))
        return a / c[:, None], np.array(sink_g) * np.array(sink_t) / c

    def step(self, dt: float, p_slip_W: float, w_engine: float, w_disc: float, clamped: bool) -> None:
        """Advance ``dt`` s with the slip power (W), speeds (rad/s) and clamp state held."""
        links, sink_g, sink_t = self.conductances(w_engine, w_disc, clamped)
        q = self.heat_inputs(p_slip_W)
        th, caps = self.theta, self.caps
        for i in range(4):
            gl = links[i - 1] if i > 0 else 0.0
            gr = links[i] if i < 3 else 0.0
            gs = gl + gr + sink_g[i]
            flow = q[i] + sink_g[i] * sink_t[i] + (gl * th[i - 1] if i > 0 else 0.0) + \
                (gr * th[i + 1] if i < 3 else 0.0)
            if gs > 0.0:
                inf = flow / gs
                th[i] = inf + (th[i] - inf) * math.exp(-dt * gs / caps[i])
            else:
                th[i] += flow * dt / caps[i]


@dataclass(frozen=True)
class PlantThermal(NetworkParams):
    """Section ``[plant_thermal]``: the plant's network; ``enabled = false`` keeps the lumped ``[facing]`` model."""

    enabled: bool = False


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
