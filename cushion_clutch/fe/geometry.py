"""Geometry and mesh: a neutral shell mesh with named sets, no solver in sight.

Coordinates are in metres; the disc axis is z, the carrier face (the plane
between the two paddles of a pair) is z = 0. Set names are the contract with
the deck writer:

element sets
    ``PADDLE`` every paddle shell element; ``CONTACT_A`` (and ``CONTACT_B`` in
    a pair) the elements of paddle A (B) outside the clamped zone, which may
    touch a plate or the other paddle.
node sets
    ``CLAMP`` nodes riveted to the carrier; ``GUIDE`` nodes of the flat far
    zone (``wave_end <= phi <= span``) that the carrier's slot holds axially;
    ``FAR_END`` nodes on the far edge (``phi = span``); ``CREST`` the crest
    node of paddle A at mid radius.

Plates are rigid planes given by the height of their contact face.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .params import Geometry


@dataclass(frozen=True)
class ShellMesh:
    """Four- or eight-node shell mesh.

    Attributes
    ----------
    nodes : ndarray, shape (n, 3)
        Mid-surface node coordinates, m.
    elements : ndarray of int, shape (m, 4) or (m, 8)
        Node indices (0-based), counter-clockwise seen from +z for paddle A
        (eight-node elements: corners, then mid-side nodes).
    thickness_m : float
        Shell thickness, m.
    node_sets, element_sets : dict of str to ndarray of int
        Named 0-based index sets.
    """

    nodes: np.ndarray
    elements: np.ndarray
    thickness_m: float
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    element_sets: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def n_nodes(self) -> int:
        return len(self.nodes)

    @property
    def n_elements(self) -> int:
        return len(self.elements)


@dataclass(frozen=True)
class Plate:
    """A rigid flat plate.

    Attributes
    ----------
    name : str
        ``UPPER`` (pressure-plate side facing) or ``LOWER``.
    z_face_m : float
        Height of the contact face, m.
    faces_up : bool
        True if the contact face looks towards +z.
    xy_min_m, xy_max_m : tuple of float
        Plan extent, m.
    """

    name: str
    z_face_m: float
    faces_up: bool
    xy_min_m: tuple[float, float]
    xy_max_m: tuple[float, float]


@dataclass(frozen=True)
class Assembly:
    """Paddle(s) between rigid plates; ``paddles`` is 1 (half pair) or 2 (pair)."""

    mesh: ShellMesh
    plates: tuple[Plate, ...]
    paddles: int


def wave_height(r_m: np.ndarray, phi_deg: np.ndarray, geom: Geometry) -> np.ndarray:
    """Wave offset w(r, phi) of the paddle's mid-surface above its flat position, m.

    Parameters
    ----------
    r_m : array_like
        Radius, m (broadcast against ``phi_deg``).
    phi_deg : array_like
        Angle from the paddle's clamped end, degrees.
    geom : Geometry
        Paddle shape: ``waves`` waves of the unit profile ``wave_profile``
        between ``wave_start_deg`` and ``wave_end_deg``, scaled by the local
        height ``h(r)`` (``wave_height_m`` at the mean radius, tilted by
        ``wave_tilt_m`` across the radius). With ``surface_file`` set, the
        fitted scanned surface instead (scaled to ``wave_height_m``).
    """
    if geom.surface_file:   # a fitted scan (cushion-clutch import-scan)
        from .surface import surface_height
        return surface_height(r_m, phi_deg, geom)
    r = np.asarray(r_m, dtype=float)
    phi = np.asarray(phi_deg, dtype=float) + 0.0 * r
    x = (phi - geom.wave_start_deg) / (geom.wave_end_deg - geom.wave_start_deg)
    inside = (x >= 0.0) & (x <= 1.0)
    s = np.clip(x * geom.waves, 0.0, geom.waves)
    s = s - np.minimum(np.floor(s), geom.waves - 1)          # position within its wave, 0..1
    return np.where(inside, local_height(r, geom) * unit_profile(s, geom), 0.0)


def local_height(r_m: np.ndarray, geom: Geometry) -> np.ndarray:
    """Wave height h(r) at radius ``r_m``, m: linear between the edge heights."""
    h_in, h_out = geom.edge_heights_m()
    xi = (np.asarray(r_m, dtype=float) - geom.inner_radius_m) / (geom.outer_radius_m - geom.inner_radius_m)
    return h_in + (h_out - h_in) * xi


def unit_profile(s: np.ndarray, geom: Geometry) -> np.ndarray:
    """Unit wave profile p(s) for s in [0, 1] within one wave: p(0) = p(1) = 0, max 1."""
    s = np.asarray(s, dtype=float)
    if geom.wave_profile == "table":
        return np.interp(s, geom.profile_s, geom.profile_z)
    if geom.wave_profile == "flat_top":
        flank = 0.5 * (1.0 - geom.crest_flat_fraction)       # each flank's share of the wave
        rise = np.clip(s / flank, 0.0, 1.0)
        fall = np.clip((1.0 - s) / flank, 0.0, 1.0)
        return 0.5 * (1.0 - np.cos(np.pi * np.minimum(rise, fall)))
    return 0.5 * (1.0 - np.cos(2.0 * np.pi * s))


def wave_breaks_deg(geom: Geometry) -> list[float]:
    """Angles the mesh must pass through: wave ends, crests and crest-flat corners, deg."""
    a, b = geom.wave_start_deg, geom.wave_end_deg
    if geom.wave_profile == "table":
        knots = list(geom.profile_s)
    elif geom.wave_profile == "flat_top":
        f = 0.5 * (1.0 - geom.crest_flat_fraction)
        knots = [0.0, f, 0.5, 1.0 - f, 1.0]
    else:
        knots = [0.0, 0.5, 1.0]
    span = (b - a) / geom.waves
    return sorted({a + span * (i + k) for i in range(geom.waves) for k in knots})


def _graded_axis(breaks: list[float], size: float) -> np.ndarray:
    """Points through every break with spacing at most ``size``."""
    breaks = sorted(set(breaks))
    pts = [breaks[0]]
    for a, b in zip(breaks[:-1], breaks[1:]):
        n = max(1, math.ceil((b - a) / size - 1e-9))
        pts.extend(np.linspace(a, b, n + 1)[1:])
    return np.array(pts)


def paddle_mesh(geom: Geometry, element_size_m: float, mirror: bool = False,
                element_type: str = "S4") -> ShellMesh:
    """Mesh one paddle as a structured (r, phi) grid of shells.

    Parameters
    ----------
    geom : Geometry
        Paddle shape.
    element_size_m : float
        Largest element edge, m (along the arc at mean radius).
    mirror : bool
        False: paddle A, above the carrier face, wave bulging to +z.
        True: paddle B, its mirror image below.
    element_type : str
        ``"S4"``/``"S4R"``: four-node quads; ``"S8R"``: eight-node quads
        (corners, then mid-side nodes, counter-clockwise).

    Returns
    -------
    ShellMesh
        With sets ``PADDLE``, ``CONTACT``, ``CLAMP``, ``FAR_END``, ``GUIDE``, ``CREST``.
        ``GUIDE`` is empty when the far zone rests on the carrier
        (``far_zone_support = "carrier"``); its elements then join ``CONTACT``.
    """
    r_mean = 0.5 * (geom.inner_radius_m + geom.outer_radius_m)
    size_deg = math.degrees(element_size_m / r_mean)
    phis = _graded_axis([0.0, geom.clamp_start_deg, geom.clamp_end_deg, *wave_breaks_deg(geom),
                         geom.span_deg], size_deg)
    radii = _graded_axis([geom.inner_radius_m, r_mean, geom.outer_radius_m], element_size_m)
    quadratic = element_type == "S8R"
    if quadratic:
        phis = _with_midpoints(phis)
        radii = _with_midpoints(radii)
    nr, nphi = len(radii), len(phis)
    rr, pp = np.meshgrid(radii, phis, indexing="ij")          # (nr, nphi)
    sign = -1.0 if mirror else 1.0
    z = sign * (0.5 * geom.thickness_m + geom.carrier_clearance_m + wave_height(rr, pp, geom))
    rad = np.radians(pp)
    nodes = np.column_stack([(rr * np.cos(rad)).ravel(), (rr * np.sin(rad)).ravel(), z.ravel()])

    idx = np.arange(nr * nphi).reshape(nr, nphi)
    # counter-clockwise in (r, phi) gives a +z normal; keep the same orientation for B
    # so that its "top" face (POS) looks towards paddle A.
    if quadratic:
        c = np.s_[0:-2:2]
        m = np.s_[1:-1:2]
        e = np.s_[2::2]
        quads = np.column_stack([idx[c, c].ravel(), idx[e, c].ravel(), idx[e, e].ravel(),
                                 idx[c, e].ravel(), idx[m, c].ravel(), idx[e, m].ravel(),
                                 idx[m, e].ravel(), idx[c, m].ravel()])
        corner_phis = phis[::2]
    else:
        quads = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(),
                                 idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
        corner_phis = phis
    n_er = (nr - 1) // 2 if quadratic else nr - 1
    phi_mid = 0.5 * (corner_phis[:-1] + corner_phis[1:])
    elem_phi = np.broadcast_to(phi_mid, (n_er, len(corner_phis) - 1)).ravel()
    guided = geom.far_zone_support == "slot" and geom.span_deg > geom.wave_end_deg + 1e-9
    clamped = (elem_phi > geom.clamp_start_deg) & (elem_phi < geom.clamp_end_deg)
    if guided:
        clamped |= elem_phi > geom.wave_end_deg
    node_phi = pp.ravel()
    tol = 1e-9
    i_mid = int(np.argmin(np.abs(radii - r_mean)))
    crest = idx[i_mid, int(np.argmax(np.abs(z[i_mid])))]
    node_sets = {
        "CLAMP": np.flatnonzero((node_phi >= geom.clamp_start_deg - tol)
                                & (node_phi <= geom.clamp_end_deg + tol)),
        "FAR_END": np.flatnonzero(node_phi >= geom.span_deg - tol),
        "GUIDE": np.flatnonzero(node_phi >= geom.wave_end_deg - tol) if guided
        else np.array([], dtype=np.int64),
        "CREST": np.array([crest]),
    }
    mesh = ShellMesh(nodes=nodes, elements=quads.astype(np.int64), thickness_m=geom.thickness_m,
                     node_sets=node_sets,
                     element_sets={"PADDLE": np.arange(len(quads)),
                                   "CONTACT": np.flatnonzero(~clamped)})
    return _drop_unused(mesh) if quadratic else mesh


def _with_midpoints(axis: np.ndarray) -> np.ndarray:
    """The axis with the midpoint of every interval inserted."""
    out = np.empty(2 * len(axis) - 1)
    out[::2] = axis
    out[1::2] = 0.5 * (axis[:-1] + axis[1:])
    return out


def _drop_unused(mesh: ShellMesh) -> ShellMesh:
    """Remove nodes no element uses (the centres of an eight-node grid) and renumber."""
    used = np.zeros(mesh.n_nodes, dtype=bool)
    used[mesh.elements.ravel()] = True
    new = np.cumsum(used) - 1
    sets = {k: new[v[used[v]]] for k, v in mesh.node_sets.items()}
    return ShellMesh(mesh.nodes[used], new[mesh.elements], mesh.thickness_m, sets,
                     dict(mesh.element_sets))


def _merge(a: ShellMesh, b: ShellMesh) -> ShellMesh:
    """Join paddle A and B meshes; sets of B get suffix handling by the caller."""
    off = a.n_nodes
    eoff = a.n_elements
    return ShellMesh(
        nodes=np.vstack([a.nodes, b.nodes]),
        elements=np.vstack([a.elements, b.elements + off]),
        thickness_m=a.thickness_m,
        node_sets={
            "CLAMP": np.concatenate([a.node_sets["CLAMP"], b.node_sets["CLAMP"] + off]),
            "FAR_END": np.concatenate([a.node_sets["FAR_END"], b.node_sets["FAR_END"] + off]),
            "GUIDE": np.concatenate([a.node_sets["GUIDE"], b.node_sets["GUIDE"] + off]),
            "CREST": a.node_sets["CREST"],
        },
        element_sets={
            "PADDLE": np.arange(a.n_elements + b.n_elements),
            "CONTACT_A": a.element_sets["CONTACT"],
            "CONTACT_B": b.element_sets["CONTACT"] + eoff,
        },
    )


def _plates(geom: Geometry, z_upper: float, z_lower: float) -> tuple[Plate, Plate]:
    margin = 0.2 * (geom.outer_radius_m - geom.inner_radius_m) + 2e-3
    r_o = geom.outer_radius_m
    span = math.radians(geom.span_deg)
    xs = [geom.inner_radius_m * math.cos(span), r_o]
    ys = [0.0, r_o * math.sin(span)]
    lo = (min(xs) - margin, min(ys) - margin)
    hi = (max(xs) + margin, max(ys) + margin)
    return (Plate("UPPER", z_upper, False, lo, hi), Plate("LOWER", z_lower, True, lo, hi))


def half_pair_assembly(geom: Geometry, element_size_m: float, gap_m: float,
                       element_type: str = "S4") -> Assembly:
    """One paddle (A) between the carrier plane z = 0 and the upper plate.

    By mirror symmetry of the pair, the carrier plane stands for paddle B:
    the pair's travel is twice this model's at the same force.
    """
    pad = paddle_mesh(geom, element_size_m, element_type=element_type)
    mesh = ShellMesh(pad.nodes, pad.elements, pad.thickness_m, dict(pad.node_sets),
                     {"PADDLE": pad.element_sets["PADDLE"], "CONTACT_A": pad.element_sets["CONTACT"]})
    z_top = geom.thickness_m + geom.carrier_clearance_m + geom.max_wave_height_m + gap_m
    return Assembly(mesh, _plates(geom, z_top, 0.0), paddles=1)


def pair_assembly(geom: Geometry, element_size_m: float, gap_m: float,
                  element_type: str = "S4") -> Assembly:
    """Both paddles of a pair, back to back on the carrier, between two plates."""
    a = paddle_mesh(geom, element_size_m, element_type=element_type)
    b = paddle_mesh(geom, element_size_m, mirror=True, element_type=element_type)
    z_top = geom.thickness_m + geom.carrier_clearance_m + geom.max_wave_height_m + gap_m
    return Assembly(_merge(a, b), _plates(geom, z_top, -z_top), paddles=2)


def strip_mesh(length_m: float, width_m: float, thickness_m: float,
               element_size_m: float) -> ShellMesh:
    """A flat rectangular strip in the xy-plane, x along its length.

    Sets: ``PADDLE`` (all elements), ``END0`` (nodes at x = 0), ``END1``
    (nodes at x = L), ``ORIGIN`` (node at x = y = 0), ``CORNER_Y`` (node at
    x = 0, y = width).
    """
    xs = _graded_axis([0.0, length_m], element_size_m)
    ys = _graded_axis([0.0, width_m], element_size_m)
    xx, yy = np.meshgrid(xs, ys, indexing="ij")
    nodes = np.column_stack([xx.ravel(), yy.ravel(), np.zeros(xx.size)])
    nx, ny = len(xs), len(ys)
    idx = np.arange(nx * ny).reshape(nx, ny)
    quads = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(),
                             idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    return ShellMesh(
        nodes=nodes, elements=quads.astype(np.int64), thickness_m=thickness_m,
        node_sets={"END0": idx[0], "END1": idx[-1], "ORIGIN": np.array([idx[0, 0]]),
                   "CORNER_Y": np.array([idx[0, -1]])},
        element_sets={"PADDLE": np.arange(len(quads))},
    )
