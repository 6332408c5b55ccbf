"""Disc-sector hexahedral mesh for the thermal FE: a neutral mesh with named sets, no solver in sight.

The sector is one paddle pair's share of the disc (360/n_pairs degrees), cut
again at the pair's mid-plane (z = 0): the two paddles of a pair, the two
facings and the carrier between them are mirror images when both facings heat
alike (the paper's assumption), so the model holds one facing, one paddle and
half the carrier's thickness, with z = 0 adiabatic; the sector's two radial
cut planes are adiabatic by rotational periodicity. Values for the whole disc
are the model's times ``2 n_pairs`` (:attr:`HeatMesh.disc_factor`).

Layers from z = 0 up, on one structured (r, phi) grid:

``CARRIER``
    steel, half the carrier thickness, from the hub edge to the facing's inner
    radius and, under the paddle's rivet zone, out to the outer radius;
``JOINT``
    a thin interface layer over the rivet zone: the riveted paddle-to-carrier
    joint, conductivity = h_joint * layer thickness;
``PADDLE``
    the paddle's steel sheet, flat (the wave enters only as the gap it leaves
    under the facing);
``INTERFACE``
    a thin layer over the paddle between it and the facing: per cell the
    area mean of the local conductance - the crest's contact where the wave
    leaves less than the roughness gap, air conduction plus radiation across
    the gap elsewhere, the clinched rivet shank inside the rivet's section;
``FACING``
    the lining, graded towards the friction surface; below the rivet head
    (counterbore depth) the cells inside the shank's section carry the brass
    shank and the head's contact with the lining (series conductance spread
    over the shank's length, ``RIVET`` cells, blended by area share).

Every element carries its conductivity, density and specific heat (arrays);
exterior faces are grouped ``FRICTION`` (flux and the plates' film),
``HUB`` (the carrier's cut edge at the hub) and ``CONVECTION`` (every other
exposed face); faces of the interface layers and on the symmetry planes are
adiabatic and listed nowhere. Face numbers follow the usual eight-node brick
convention (1 bottom, 2 top, 3 phi-low, 4 r-outer, 5 phi-high, 6 r-inner).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .geometry import wave_breaks_deg, wave_height
from .heat_params import HeatPathParams
from .params import SpringParams

#: schematic thickness of the interface layers, m (their conductivity is h times this)
INTERFACE_THICKNESS_M = 50e-6
#: air properties of the interface layers' (negligible) heat capacity
_AIR_RHO, _AIR_C = 1.0, 1000.0
#: sub-samples per cell edge for the area means of conductance and rivet share
_SUBSAMPLES = 8


@dataclass(frozen=True)
class HeatMesh:
    """Eight-node brick mesh of the sector with per-element properties.

    Attributes
    ----------
    nodes : ndarray, shape (n, 3)
        Node coordinates, m.
    elements : ndarray of int, shape (m, 8)
        0-based node indices, bottom face counter-clockwise seen from +z, then the top face.
    conductivity_W_per_m_K, density_kg_m3, specific_heat_J_per_kg_K : ndarray, shape (m,)
        Element properties.
    volume_m3 : ndarray, shape (m,)
        Element volumes, m^3.
    element_sets : dict of str to ndarray of int
        ``CARRIER``, ``JOINT``, ``PADDLE``, ``INTERFACE``, ``FACING`` (``RIVET`` a subset of ``FACING``).
    faces : dict of str to ndarray of int, shape (k, 2)
        Exterior faces (element, face number 1-6): ``FRICTION``, ``HUB``, ``CONVECTION``.
    face_area_m2 : dict of str to ndarray, shape (k,)
        Their areas, m^2.
    disc_factor : int
        Copies of this model in the whole disc (2 n_pairs).
    element_size_m : float
        In-plane element size the mesh was made with, m.
    """

    nodes: np.ndarray
    elements: np.ndarray
    conductivity_W_per_m_K: np.ndarray
    density_kg_m3: np.ndarray
    specific_heat_J_per_kg_K: np.ndarray
    volume_m3: np.ndarray
    element_sets: dict[str, np.ndarray] = field(default_factory=dict)
    faces: dict[str, np.ndarray] = field(default_factory=dict)
    face_area_m2: dict[str, np.ndarray] = field(default_factory=dict)
    disc_factor: int = 16
    element_size_m: float = 1e-3

    def face_nodes(self, faces: np.ndarray) -> np.ndarray:
        """Node indices (k, 4) of faces given as (element, face number 1-6)."""
        return self.elements[faces[:, 0]][np.arange(len(faces))[:, None], _FACE_LOCAL[faces[:, 1] - 1]]

    def mass_kg(self, name: str) -> float:
        """Mass of an element set, kg (this model, not the disc)."""
        e = self.element_sets[name]
        return float(np.sum(self.density_kg_m3[e] * self.volume_m3[e]))


#: local node positions of faces 1-6 of an eight-node brick
_FACE_LOCAL = np.array([[0, 1, 2, 3], [4, 7, 6, 5], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])


def _cell_samples(r_axis: np.ndarray, phi_axis: np.ndarray, n: int = _SUBSAMPLES):
    """Sub-sample points (r, phi_deg) and area weights of every cell, shape (nr-1, nphi-1, n*n)."""
    u = (np.arange(n) + 0.5) / n
    r = r_axis[:-1, None] + np.diff(r_axis)[:, None] * u[None, :]              # (nr-1, n)
    p = phi_axis[:-1, None] + np.diff(phi_axis)[:, None] * u[None, :]          # (nphi-1, n)
    rr = np.broadcast_to(r[:, None, :, None], (len(r), len(p), n, n)).reshape(len(r), len(p), n * n)
    pp = np.broadcast_to(p[None, :, None, :], (len(r), len(p), n, n)).reshape(len(r), len(p), n * n)
    w = rr / rr.sum(axis=2, keepdims=True)                                     # area element r dr dphi
    return rr, pp, w


def _rivet_share(rr: np.ndarray, pp: np.ndarray, centres: list[tuple[float, float]], radius: float) -> np.ndarray:
    """1 where a sub-sample lies inside a rivet's circle of ``radius``, else 0."""
    x, y = rr * np.cos(np.radians(pp)), rr * np.sin(np.radians(pp))
    inside = np.zeros_like(rr, dtype=bool)
    for rc, pc in centres:
        xc, yc = rc * math.cos(math.radians(pc)), rc * math.sin(math.radians(pc))
        inside |= (x - xc) ** 2 + (y - yc) ** 2 <= radius ** 2
    return inside.astype(float)


def crest_angles_deg(spring: SpringParams) -> list[float]:
    """Angles of the wave crests (where the paddle touches the facing), deg."""
    g = spring.geometry
    phi = np.linspace(g.wave_start_deg, g.wave_end_deg, 2001)
    r_mid = 0.5 * (g.inner_radius_m + g.outer_radius_m)
    w = wave_height(np.full_like(phi, r_mid), phi, g)
    span = (g.wave_end_deg - g.wave_start_deg) / g.waves
    crests = []
    for k in range(g.waves):
        sel = (phi >= g.wave_start_deg + k * span) & (phi <= g.wave_start_deg + (k + 1) * span)
        crests.append(float(phi[sel][np.argmax(w[sel])]))
    return crests


def rivet_centres(spring: SpringParams, hp: HeatPathParams) -> list[tuple[float, float]]:
    """(r, phi_deg) of the facing rivets: evenly across the radius on the first crest."""
    g = spring.geometry
    if hp.rivets_per_paddle == 0:
        return []
    phi = crest_angles_deg(spring)[0]
    width = g.outer_radius_m - g.inner_radius_m
    return [(g.inner_radius_m + (k + 0.5) / hp.rivets_per_paddle * width, phi) for k in range(hp.rivets_per_paddle)]


def interface_conductance(spring: SpringParams, hp: HeatPathParams, rr: np.ndarray, pp: np.ndarray) -> np.ndarray:
    """Local paddle-to-facing conductance at sub-sample points, W/(m^2 K), without the rivets.

    The facing rests on the crest at every radius (riveted there); the gap the
    wave leaves is the crest height at that radius minus the local height.
    """
    g = spring.geometry
    phi_fine = np.linspace(0.0, g.span_deg, 1441)
    r_unique = np.unique(rr)
    crest = np.array([wave_height(np.full_like(phi_fine, r), phi_fine, g).max() for r in r_unique])
    crest_at = np.interp(rr, r_unique, crest)
    gap = np.maximum(crest_at - wave_height(rr, pp, g), 0.0)
    air = hp.air_conductivity_W_per_m_K / np.maximum(gap, hp.crest_contact_gap_m) + hp.radiation_W_per_m2_K
    return np.where(gap < hp.crest_contact_gap_m, hp.crest_contact_W_per_m2_K + air, air)


def rivet_column_conductivity(hp: HeatPathParams) -> float:
    """Effective conductivity over the shank's section of the rivet below the head, W/(m K).

    Shank conduction through the lining below the counterbore in series with the
    head's contact on the lining (the head's annulus beyond the shank).
    """
    length = hp.facing_thickness_m * (1.0 - hp.counterbore_depth_fraction)
    a_shank = math.pi / 4.0 * hp.rivet_shank_diameter_m ** 2
    a_head = math.pi / 4.0 * (hp.rivet_head_diameter_m ** 2 - hp.rivet_shank_diameter_m ** 2)
    resistance = length / (hp.rivet_conductivity_W_per_m_K * a_shank) + 1.0 / (hp.rivet_head_contact_W_per_m2_K * a_head)
    return length / (a_shank * resistance)


#: in-plane refinement factor across the crest strip and around the rivets
REFINE = 3


def _refined_axis(breaks: list[float], size: float, fine: list[tuple[float, float]]) -> np.ndarray:
    """Points through every break, spacing at most ``size``, at most ``size / REFINE`` inside the ``fine`` bands."""
    lo, hi = min(breaks), max(breaks)
    pts = set(breaks)
    for a, b in fine:
        pts.update(x for x in (a, b) if lo < x < hi)
    pts = sorted(pts)
    out = [pts[0]]
    for a, b in zip(pts[:-1], pts[1:]):
        mid = 0.5 * (a + b)
        h = size / REFINE if any(fa <= mid <= fb for fa, fb in fine) else size
        n = max(1, math.ceil((b - a) / h - 1e-9))
        out.extend(np.linspace(a, b, n + 1)[1:])
    return np.array(out)


def _sublayers(z0: float, thickness: float, n: int, grade: float = 1.0) -> list[float]:
    """Top heights of ``n`` sub-layers of a layer from ``z0``; ``grade`` > 1 thins them towards the top."""
    w = grade ** -np.arange(n, dtype=float)
    return list(z0 + thickness * np.cumsum(w) / w.sum())


@dataclass(frozen=True)
class _Plan:
    """The sector's plan grid: axes (r m, phi deg) and which cells each part occupies."""

    r_axis: np.ndarray
    phi_axis: np.ndarray
    on_facing: np.ndarray
    paddle: np.ndarray
    clamp: np.ndarray
    carrier: np.ndarray
    rivet_centres: list[tuple[float, float]]


def _plan(spring: SpringParams, hp: HeatPathParams, e: float) -> _Plan:
    """Plan axes through every part's edge, finer (REFINE x) across the crest strip and the rivets."""
    g = spring.geometry
    r_i, r_o, r_h = g.inner_radius_m, g.outer_radius_m, hp.carrier_inner_radius_m
    if not r_h < r_i:
        raise ValueError(f"heat_path.carrier_inner_radius_m = {r_h!r}: must be below the paddle's inner radius {r_i!r}")
    sector = 360.0 / spring.n_pairs
    # finer (REFINE x) across the crest's contact strip and the rivets, where the heat crowds into the lining
    centres = rivet_centres(spring, hp)
    band = 0.5 * hp.rivet_head_diameter_m + 1e-3
    r_fine = [(rc_ - band, rc_ + band) for rc_, _ in centres]
    r_axis = _refined_axis([r_h, r_i, r_o], e, r_fine)
    r_mean = 0.5 * (r_i + r_o)
    e_deg = math.degrees(e / r_mean)
    b_deg = math.degrees(band / r_mean)
    breaks = [0.0, g.clamp_start_deg, g.clamp_end_deg, *wave_breaks_deg(g), g.span_deg, sector]
    phi_axis = _refined_axis([b for b in breaks if b <= sector], e_deg,
                             [(c - b_deg, c + b_deg) for c in crest_angles_deg(spring)])
    rc = 0.5 * (r_axis[:-1] + r_axis[1:])[:, None] + 0.0 * phi_axis[None, :-1]
    pc = 0.0 * r_axis[:-1, None] + 0.5 * (phi_axis[:-1] + phi_axis[1:])[None, :]
    on_facing = (rc > r_i) & (rc < r_o)
    paddle = on_facing & (pc < g.span_deg)
    clamp = paddle & (pc > g.clamp_start_deg) & (pc < g.clamp_end_deg)
    carrier = (rc < r_i) | clamp
    return _Plan(r_axis, phi_axis, on_facing, paddle, clamp, carrier, centres)


def _layers(spring: SpringParams, hp: HeatPathParams, e: float) -> tuple[list[float], list[tuple[str, int]]]:
    """Heights of the z planes from the mid-plane up, and the sub-layers as (part, index of their top plane)."""
    n_sub = lambda t: max(1, math.ceil(t / (0.6 * e) - 1e-9))  # noqa: E731
    t_c2 = hp.carrier_thickness_m / 2.0
    low = hp.facing_thickness_m * (1.0 - hp.counterbore_depth_fraction)
    up = hp.facing_thickness_m - low
    z = [0.0]
    layers: list[tuple[str, int]] = []          # (part, index of the sub-layer's top plane)

    def add(part: str, tops: list[float]) -> None:
        for t in tops:
            z.append(t)
            layers.append((part, len(z) - 1))

    add("CARRIER", _sublayers(z[-1], t_c2, n_sub(t_c2)))
    add("JOINT", [z[-1] + INTERFACE_THICKNESS_M])
    add("PADDLE", [z[-1] + spring.geometry.thickness_m])
    add("INTERFACE", [z[-1] + INTERFACE_THICKNESS_M])
    add("FACING_LOW", _sublayers(z[-1], low, n_sub(low) + 1, grade=1 / 1.6))
    add("FACING_UP", _sublayers(z[-1], up, n_sub(up) + 1, grade=1.6))
    return z, layers


def _bricks(plan: _Plan, z: list[float], layers: list[tuple[str, int]]):
    """Nodes on the full grid and the bricks of every layer where its part has a cell.

    Returns all nodes (m), connectivity, each brick's part, layer and plan cell (i, j), and the occupancy
    (layer, i, j).
    """
    r_axis, phi_axis = plan.r_axis, plan.phi_axis
    nr, nphi, nz = len(r_axis) - 1, len(phi_axis) - 1, len(z)
    masks = {"CARRIER": plan.carrier, "JOINT": plan.clamp, "PADDLE": plan.paddle, "INTERFACE": plan.paddle,
             "FACING_LOW": plan.on_facing, "FACING_UP": plan.on_facing}
    R, P, Z = np.meshgrid(r_axis, np.radians(phi_axis), np.array(z), indexing="ij")
    all_nodes = np.stack([R * np.cos(P), R * np.sin(P), Z], axis=-1).reshape(-1, 3)
    nid = lambda i, j, k: (i * (nphi + 1) + j) * nz + k  # noqa: E731
    occ = np.zeros((len(layers), nr, nphi), dtype=bool)
    elems, parts, layer_of, cells = [], [], [], []
    I, J = np.meshgrid(np.arange(nr), np.arange(nphi), indexing="ij")
    for li, (part, ktop) in enumerate(layers):
        m = masks[part]
        occ[li] = m
        i, j = I[m], J[m]
        kb = ktop - 1
        conn = np.stack([nid(i, j, kb), nid(i + 1, j, kb), nid(i + 1, j + 1, kb), nid(i, j + 1, kb),
                         nid(i, j, ktop), nid(i + 1, j, ktop), nid(i + 1, j + 1, ktop), nid(i, j + 1, ktop)], axis=1)
        elems.append(conn)
        parts += [part] * len(i)
        layer_of.append(np.full(len(i), li))
        cells.append(np.stack([i, j], axis=1))
    return (all_nodes, np.concatenate(elems), np.array(parts), np.concatenate(layer_of), np.concatenate(cells),
            occ)


def _properties(spring: SpringParams, hp: HeatPathParams, plan: _Plan, parts_a: np.ndarray, cell_a: np.ndarray):
    """Conductivity, density and specific heat of every brick, and the rivet-column mask.

    The joint and interface layers carry their contact conductance as a conductivity over their
    thickness; lining cells crossed by a rivet shank mix rivet and lining by its area share.
    """
    t_int = INTERFACE_THICKNESS_M
    rr, pp, w = _cell_samples(plan.r_axis, plan.phi_axis)
    h_local = interface_conductance(spring, hp, rr, pp)
    shank = _rivet_share(rr, pp, plan.rivet_centres, hp.rivet_shank_diameter_m / 2.0)
    h_iface = np.sum(w * np.where(shank > 0, hp.rivet_clinch_contact_W_per_m2_K, h_local), axis=2)
    f_rivet = np.sum(w * shank, axis=2)
    n = len(parts_a)
    k, rho, c = np.empty(n), np.empty(n), np.empty(n)
    ci, cj = cell_a[:, 0], cell_a[:, 1]
    steel = (parts_a == "CARRIER") | (parts_a == "PADDLE")
    k[steel], rho[steel], c[steel] = hp.steel_conductivity_W_per_m_K, hp.steel_density_kg_m3, \
        hp.steel_specific_heat_J_per_kg_K
    joint = parts_a == "JOINT"
    k[joint], rho[joint], c[joint] = hp.joint_contact_W_per_m2_K * t_int, _AIR_RHO, _AIR_C
    iface = parts_a == "INTERFACE"
    k[iface], rho[iface], c[iface] = h_iface[ci[iface], cj[iface]] * t_int, _AIR_RHO, _AIR_C
    lining = (parts_a == "FACING_LOW") | (parts_a == "FACING_UP")
    k[lining], rho[lining], c[lining] = hp.lining_conductivity_W_per_m_K, hp.lining_density_kg_m3, \
        hp.lining_specific_heat_J_per_kg_K
    col = (parts_a == "FACING_LOW") & (f_rivet[ci, cj] > 0)
    f = f_rivet[ci[col], cj[col]]
    k[col] = f * rivet_column_conductivity(hp) + (1 - f) * hp.lining_conductivity_W_per_m_K
    rho_c = f * hp.rivet_density_kg_m3 * hp.rivet_specific_heat_J_per_kg_K + \
        (1 - f) * hp.lining_density_kg_m3 * hp.lining_specific_heat_J_per_kg_K
    rho[col] = f * hp.rivet_density_kg_m3 + (1 - f) * hp.lining_density_kg_m3
    c[col] = rho_c / rho[col]
    return k, rho, c, col


def _exterior_faces(occ: np.ndarray, layer_a: np.ndarray, cell_a: np.ndarray,
                    adiabatic_part: np.ndarray) -> dict[str, list[np.ndarray]]:
    """Exterior faces (element, face 1-6) from the occupancy of neighbours, grouped by their boundary.

    The mid-plane (z = 0) and the periodic cuts (phi = 0, phi = sector) are no boundary; the joint and
    interface layers (contact conductances) have none either.
    """
    nl, nr, nphi = occ.shape
    ci, cj = cell_a[:, 0], cell_a[:, 1]
    pad = np.zeros((nl + 2, nr + 2, nphi + 2), dtype=bool)
    pad[1:-1, 1:-1, 1:-1] = occ
    li, i, j = layer_a + 1, ci + 1, cj + 1
    open_ = {1: ~pad[li - 1, i, j], 2: ~pad[li + 1, i, j], 3: ~pad[li, i, j - 1], 4: ~pad[li, i + 1, j],
             5: ~pad[li, i, j + 1], 6: ~pad[li, i - 1, j]}
    groups: dict[str, list[np.ndarray]] = {"FRICTION": [], "HUB": [], "CONVECTION": []}
    eidx = np.arange(len(layer_a))
    for face, is_open in open_.items():
        ok = is_open & ~adiabatic_part
        if face == 1:
            ok &= layer_a > 0                                   # z = 0: mirror plane
        if face == 3:
            ok &= cj > 0                                        # phi = 0: periodic cut
        if face == 5:
            ok &= cj < nphi - 1                                 # phi = sector: periodic cut
        sel = eidx[ok]
        fn = np.full(len(sel), face)
        if face == 2:
            top = layer_a[sel] == nl - 1
            groups["FRICTION"].append(np.stack([sel[top], fn[top]], axis=1))
            sel, fn = sel[~top], fn[~top]
        if face == 6:
            hub = ci[sel] == 0
            groups["HUB"].append(np.stack([sel[hub], fn[hub]], axis=1))
            sel, fn = sel[~hub], fn[~hub]
        groups["CONVECTION"].append(np.stack([sel, fn], axis=1))
    return groups


def _volumes(nodes: np.ndarray, conn: np.ndarray) -> np.ndarray:
    """Brick volumes, m^3: plan area of the bottom face (shoelace) times the height."""
    xy = nodes[conn[:, :4], :2]
    area = 0.5 * np.abs(np.sum(xy[:, :, 0] * np.roll(xy[:, :, 1], -1, axis=1)
                               - np.roll(xy[:, :, 0], -1, axis=1) * xy[:, :, 1], axis=1))
    return area * (nodes[conn[:, 4], 2] - nodes[conn[:, 0], 2])


def sector_mesh(spring: SpringParams, hp: HeatPathParams, element_size_m: float) -> HeatMesh:
    """Mesh the sector (see the module docstring).

    Parameters
    ----------
    spring : SpringParams
        The spring (radii, span, thickness, wave, clamp zone, number of pairs).
    hp : HeatPathParams
        Facing, carrier, rivets, conductances.
    element_size_m : float
        Largest in-plane element edge at the facing's mean radius, m; the layers'
        sub-division follows it.
    """
    e = element_size_m
    plan = _plan(spring, hp, e)
    z, layers = _layers(spring, hp, e)
    all_nodes, conn, parts_a, layer_a, cell_a, occ = _bricks(plan, z, layers)
    k, rho, c, col = _properties(spring, hp, plan, parts_a, cell_a)
    joint, iface = parts_a == "JOINT", parts_a == "INTERFACE"
    groups = _exterior_faces(occ, layer_a, cell_a, joint | iface)

    # drop unused nodes, renumber
    used = np.unique(conn)
    new = np.full(len(all_nodes), -1)
    new[used] = np.arange(len(used))
    nodes = all_nodes[used]
    conn = new[conn]
    eidx = np.arange(len(conn))
    lining = (parts_a == "FACING_LOW") | (parts_a == "FACING_UP")
    sets = {"CARRIER": eidx[parts_a == "CARRIER"], "JOINT": eidx[joint], "PADDLE": eidx[parts_a == "PADDLE"],
            "INTERFACE": eidx[iface], "FACING": eidx[lining], "RIVET": eidx[col]}
    mesh = HeatMesh(nodes, conn, k, rho, c, _volumes(nodes, conn), sets,
                    {n: np.concatenate(v) for n, v in groups.items()}, {}, 2 * spring.n_pairs, e)
    for name, fc in mesh.faces.items():
        q = nodes[mesh.face_nodes(fc)]
        d1, d2 = q[:, 2] - q[:, 0], q[:, 3] - q[:, 1]
        mesh.face_area_m2[name] = 0.5 * np.linalg.norm(np.cross(d1, d2), axis=1)
    return mesh
