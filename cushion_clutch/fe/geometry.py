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
    """Four-node shell mesh.

    Attributes
    ----------
    nodes : ndarray, shape (n, 3)
        Mid-surface node coordinates, m.
    elements : ndarray of int, shape (m, 4)
        Node indices (0-based), counter-clockwise seen from +z for paddle A.
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
        Paddle shape; with ``surface_file`` set, the fitted scanned surface.
    """
    if geom.surface_file:   # a fitted scan (cushion-clutch import-scan), scaled to wave_height_m
        from .surface import surface_height
        return surface_height(r_m, phi_deg, geom)
    phi = np.asarray(phi_deg, dtype=float) + 0.0 * np.asarray(r_m, dtype=float)
    s = (phi - geom.wave_start_deg) / (geom.wave_end_deg - geom.wave_start_deg)
    inside = (s >= 0.0) & (s <= 1.0)
    return np.where(inside, 0.5 * geom.wave_height_m * (1.0 - np.cos(2.0 * np.pi * s)), 0.0)


def _graded_axis(breaks: list[float], size: float) -> np.ndarray:
    """Points through every break with spacing at most ``size``."""
    breaks = sorted(set(breaks))
    pts = [breaks[0]]
    for a, b in zip(breaks[:-1], breaks[1:]):
        n = max(1, math.ceil((b - a) / size - 1e-9))
        pts.extend(np.linspace(a, b, n + 1)[1:])
    return np.array(pts)


def paddle_mesh(geom: Geometry, element_size_m: float, mirror: bool = False) -> ShellMesh:
    """Mesh one paddle as a structured (r, phi) grid of four-node shells.

    Parameters
    ----------
    geom : Geometry
        Paddle shape.
    element_size_m : float
        Largest element edge, m (along the arc at mean radius).
    mirror : bool
        False: paddle A, above the carrier face, wave bulging to +z.
        True: paddle B, its mirror image below.

    Returns
    -------
    ShellMesh
        With sets ``PADDLE``, ``CONTACT``, ``CLAMP``, ``FAR_END``, ``CREST``.
    """
    r_mean = 0.5 * (geom.inner_radius_m + geom.outer_radius_m)
    size_deg = math.degrees(element_size_m / r_mean)
    phis = _graded_axis([0.0, geom.clamp_start_deg, geom.clamp_end_deg, geom.wave_start_deg,
                         0.5 * (geom.wave_start_deg + geom.wave_end_deg), geom.wave_end_deg,
                         geom.span_deg], size_deg)
    radii = _graded_axis([geom.inner_radius_m, r_mean, geom.outer_radius_m], element_size_m)
    nr, nphi = len(radii), len(phis)
    rr, pp = np.meshgrid(radii, phis, indexing="ij")          # (nr, nphi)
    sign = -1.0 if mirror else 1.0
    z = sign * (0.5 * geom.thickness_m + geom.carrier_clearance_m + wave_height(rr, pp, geom))
    rad = np.radians(pp)
    nodes = np.column_stack([(rr * np.cos(rad)).ravel(), (rr * np.sin(rad)).ravel(), z.ravel()])

    idx = np.arange(nr * nphi).reshape(nr, nphi)
    quads = np.column_stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(),
                             idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()])
    # counter-clockwise in (r, phi) gives a +z normal; keep the same orientation for B
    # so that its "top" face (POS) looks towards paddle A.
    phi_mid = 0.5 * (phis[:-1] + phis[1:])
    elem_phi = np.broadcast_to(phi_mid, (nr - 1, nphi - 1)).ravel()
    clamped = ((elem_phi > geom.clamp_start_deg) & (elem_phi < geom.clamp_end_deg)) | (
        elem_phi > geom.wave_end_deg)
    node_phi = pp.ravel()
    tol = 1e-9
    crest_phi = 0.5 * (geom.wave_start_deg + geom.wave_end_deg)
    crest = idx[int(np.argmin(np.abs(radii - r_mean))), int(np.argmin(np.abs(phis - crest_phi)))]
    return ShellMesh(
        nodes=nodes,
        elements=quads.astype(np.int64),
        thickness_m=geom.thickness_m,
        node_sets={
            "CLAMP": np.flatnonzero((node_phi >= geom.clamp_start_deg - tol)
                                    & (node_phi <= geom.clamp_end_deg + tol)),
            "FAR_END": np.flatnonzero(node_phi >= geom.span_deg - tol),
            "GUIDE": np.flatnonzero(node_phi >= geom.wave_end_deg - tol) if geom.span_deg > geom.wave_end_deg + tol
            else np.array([], dtype=np.int64),
            "CREST": np.array([crest]),
        },
        element_sets={"PADDLE": np.arange(len(quads)), "CONTACT": np.flatnonzero(~clamped)},
    )


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


def half_pair_assembly(geom: Geometry, element_size_m: float, gap_m: float) -> Assembly:
    """One paddle (A) between the carrier plane z = 0 and the upper plate.

    By mirror symmetry of the pair, the carrier plane stands for paddle B:
    the pair's travel is twice this model's at the same force.
    """
    pad = paddle_mesh(geom, element_size_m)
    mesh = ShellMesh(pad.nodes, pad.elements, pad.thickness_m, dict(pad.node_sets),
                     {"PADDLE": pad.element_sets["PADDLE"], "CONTACT_A": pad.element_sets["CONTACT"]})
    z_top = geom.thickness_m + geom.carrier_clearance_m + geom.wave_height_m + gap_m
    return Assembly(mesh, _plates(geom, z_top, 0.0), paddles=1)


def pair_assembly(geom: Geometry, element_size_m: float, gap_m: float) -> Assembly:
    """Both paddles of a pair, back to back on the carrier, between two plates."""
    a = paddle_mesh(geom, element_size_m)
    b = paddle_mesh(geom, element_size_m, mirror=True)
    z_top = geom.thickness_m + geom.carrier_clearance_m + geom.wave_height_m + gap_m
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
