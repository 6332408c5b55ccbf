"""The carrier joint: the far-edge tab and the clamp rivets as one circumferential stiffness.

The paddle's far edge is held in the carrier's plane by a finger (tab) of the
carrier sheet, and its clamp zone by rivets; both are in series with the
paddle's own in-plane path, which the paddle FE (:mod:`.deck`) models. The
paddle FE takes the joint as one stiffness over the far edge
(:func:`.deck.far_end_anchors`); since the circumferential force is the same
at both ends of the paddle (frictionless plates), the rivets' compliance can sit
at the far end in series with the tab's.

- **Tab**: a small CalculiX solid model (C3D8I bricks) of the finger and the
  carrier body around its root (:func:`tab_deck`), loaded at its tip by the
  paddle's edge; checked against a Timoshenko cantilever with a clamped root
  (:func:`timoshenko_tab_stiffness`, the same FE with the root clamped) and by
  mesh refinement (``tests/test_joint.py``).
- **Rivets**: Huth's fastener flexibility (H. Huth, "Influence of fastener
  flexibility on the prediction of load transfer and fatigue life for
  multiple-row joints", ASTM STP 927, 1986, pp. 221-250; riveted metallic
  joints a = 2/3, b = 2.2), one shear plane per paddle; Swift's (Douglas)
  formula (T. Swift, "Repairs to damage tolerant aircraft", 1984) as the
  second closed form.

SI in and out; the deck is in mm, N, MPa like the paddle deck.
"""
from __future__ import annotations

import functools
import math
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .ccx import run_ccx
from .params import Joint, SpringParams
from .results import read_dat

MM = 1e3
#: the carrier body modelled around the tab's root, in tab widths on each side and behind it; its outer faces
#: are held (a larger body changed the stiffness by under 1 %, tests/test_joint.py)
ROOT_BODY_WIDTHS = 5.0
#: elements across the tab's width (tests/test_joint.py refines it)
TAB_ELEMENTS_PER_WIDTH = 8


@dataclass(frozen=True)
class JointStiffness:
    """The joint's stiffnesses, N/m: the tab, all rivets of one paddle, and the two in series."""

    tab_N_per_m: float
    rivets_N_per_m: float

    @property
    def series_N_per_m(self) -> float:
        """Tab and rivets in series: the far-edge stiffness the paddle FE takes, N/m."""
        return 1.0 / (1.0 / self.tab_N_per_m + 1.0 / self.rivets_N_per_m)


def _grid(segments: list[tuple[float, float]], h: float) -> np.ndarray:
    """Node coordinates along one axis: each segment (a, b) cut into ceil((b - a) / h) equal parts."""
    out = [segments[0][0]]
    for a, b in segments:
        n = max(1, math.ceil((b - a) / h - 1e-9))
        out += list(np.linspace(a, b, n + 1)[1:])
    return np.array(out)


def tab_mesh(joint: Joint, elements_per_width: int = TAB_ELEMENTS_PER_WIDTH, root: str = "carrier",
             layers: int = 2) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """Brick mesh of the tab (and the carrier body at its root), m.

    x runs along the tab from its root (x = 0) to its tip (x = ``tab_length_m``), y across its width
    (the load's direction), z through the sheet. ``root = "carrier"`` adds the carrier body,
    ``ROOT_BODY_WIDTHS`` tab widths behind the root and on each side, held on its outer faces;
    ``"clamped"`` holds the root section itself (the cantilever of the closed form).

    Returns nodes (n, 3), elements (m, 8) 0-based, and node sets ``HELD`` and ``TIP`` (the tip face).
    """
    w, length, t = joint.tab_width_m, joint.tab_length_m, joint.carrier_thickness_m
    h = w / elements_per_width
    b = ROOT_BODY_WIDTHS * w if root == "carrier" else 0.0
    xs = _grid([(-b, 0.0), (0.0, length)] if b else [(0.0, length)], h)
    ys = _grid([(-b, 0.0), (0.0, w), (w, w + b)] if b else [(0.0, w)], h)
    zs = np.linspace(0.0, t, layers + 1)
    ix = {(i, j, k): n for n, (i, j, k) in enumerate(np.ndindex(len(xs), len(ys), len(zs)))}
    nodes = np.array([(xs[i], ys[j], zs[k]) for (i, j, k) in ix])
    tol = 1e-9 * w
    elems = []
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            xc, yc = 0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1])
            if xc > 0 and not (0 < yc < w):
                continue                                # the slots on each side of the tab
            for k in range(len(zs) - 1):
                elems.append([ix[(i, j, k)], ix[(i + 1, j, k)], ix[(i + 1, j + 1, k)], ix[(i, j + 1, k)],
                              ix[(i, j, k + 1)], ix[(i + 1, j, k + 1)], ix[(i + 1, j + 1, k + 1)],
                              ix[(i, j + 1, k + 1)]])
    elems = np.array(elems)
    used = np.unique(elems)
    x, y = nodes[:, 0], nodes[:, 1]
    if root == "carrier":
        held = (np.abs(x + b) < tol) | (np.abs(y + b) < tol) | (np.abs(y - w - b) < tol)
    else:
        held = np.abs(x) < tol
    sets = {"HELD": np.intersect1d(np.flatnonzero(held), used),
            "TIP": np.intersect1d(np.flatnonzero(np.abs(x - length) < tol), used)}
    return nodes, elems, sets


def _tip_forces(nodes: np.ndarray, elems: np.ndarray, tip: np.ndarray) -> np.ndarray:
    """Consistent nodal shares of a uniform traction on the tip face (bilinear faces: a quarter each)."""
    share = np.zeros(len(nodes))
    on_tip = np.zeros(len(nodes), bool)
    on_tip[tip] = True
    for conn in elems:
        face = [n for n in conn if on_tip[n]]
        if len(face) == 4:
            ys, zs = nodes[face, 1], nodes[face, 2]
            area = (ys.max() - ys.min()) * (zs.max() - zs.min())
            share[face] += area / 4
    return share[tip] / share[tip].sum()


def tab_deck(joint: Joint, force_N: float = 1.0, elements_per_width: int = TAB_ELEMENTS_PER_WIDTH,
             root: str = "carrier") -> str:
    """CalculiX deck of the tab loaded at its tip in +y by ``force_N`` (linear, one step); prints U of ``TIP``."""
    nodes, elems, sets = tab_mesh(joint, elements_per_width, root)
    f = _tip_forces(nodes, elems, sets["TIP"]) * force_N
    lines = ["** cushion_clutch: carrier tab (finger) in in-plane bending, units mm N MPa",
             "*NODE, NSET=NALL"]
    lines += [f"{i + 1}, {x * MM:.9g}, {y * MM:.9g}, {z * MM:.9g}" for i, (x, y, z) in enumerate(nodes)]
    lines.append("*ELEMENT, TYPE=C3D8I, ELSET=TAB")
    lines += [f"{e + 1}, " + ", ".join(str(n + 1) for n in conn) for e, conn in enumerate(elems)]
    for name, ids in sets.items():
        lines.append(f"*NSET, NSET={name}")
        lines += [", ".join(str(i + 1) for i in ids[k:k + 12]) + "," for k in range(0, len(ids), 12)]
    lines += ["*MATERIAL, NAME=CARRIER", "*ELASTIC",
              f"{joint.carrier_youngs_modulus_Pa * 1e-6:.9g}, {joint.carrier_poisson_ratio:.9g}",
              "*SOLID SECTION, ELSET=TAB, MATERIAL=CARRIER", "*BOUNDARY", "HELD, 1, 3",
              "*STEP", "*STATIC", "*CLOAD"]
    lines += [f"{n + 1}, 2, {fn:.9g}" for n, fn in zip(sets["TIP"], f)]
    lines += ["*NODE PRINT, NSET=TIP", "U", "*END STEP"]
    return "\n".join(lines) + "\n"


def tab_stiffness_fe(joint: Joint, elements_per_width: int = TAB_ELEMENTS_PER_WIDTH, root: str = "carrier",
                     workdir: Path | None = None) -> float:
    """The tab's stiffness at its tip, N/m, from CalculiX: load / mean tip displacement along the load.

    The mean over the tip face's nodes weighted by their share of the face (the load's own weights).
    """
    nodes, elems, sets = tab_mesh(joint, elements_per_width, root)
    weights = _tip_forces(nodes, elems, sets["TIP"])
    force = 1.0
    with tempfile.TemporaryDirectory(prefix="tab_") as tmp:
        work = Path(workdir) if workdir is not None else Path(tmp)
        run_ccx(tab_deck(joint, force, elements_per_width, root), work, job="tab")
        (_, u), = read_dat(work / "tab.dat")[("displacements", "TIP")]
    uy_m = float(weights @ u[:, 1]) / MM
    return force / uy_m


def timoshenko_tab_stiffness(joint: Joint) -> float:
    """Tip stiffness of the tab as a Timoshenko cantilever with a clamped root, N/m.

    ``1 / k = L^3 / (3 E I) + L / (kappa_s G A)``, I = t w^3 / 12 (bending in the sheet's plane),
    A = w t, kappa_s = 10 (1 + nu) / (12 + 11 nu) (rectangle, Cowper 1966).
    """
    e, nu = joint.carrier_youngs_modulus_Pa, joint.carrier_poisson_ratio
    w, length, t = joint.tab_width_m, joint.tab_length_m, joint.carrier_thickness_m
    inertia, area = t * w ** 3 / 12, w * t
    kappa_s = 10 * (1 + nu) / (12 + 11 * nu)
    g = e / (2 * (1 + nu))
    return 1.0 / (length ** 3 / (3 * e * inertia) + length / (kappa_s * g * area))


def huth_rivet_stiffness(joint: Joint, paddle_thickness_m: float, paddle_youngs_modulus_Pa: float) -> float:
    """Stiffness of one rivet joining the paddle to the carrier, N/m (Huth 1986, riveted metal, single shear).

    ``C = ((t1 + t2) / (2 d))^a (b / n) (1/(t1 E1) + 1/(n t2 E2) + 1/(2 t1 E3) + 1/(2 n t2 E3))``,
    a = 2/3, b = 2.2, n = 1; t1, E1 the paddle, t2, E2 the carrier, E3 the rivet.
    """
    t1, t2, d = paddle_thickness_m, joint.carrier_thickness_m, joint.rivet_diameter_m
    e1, e2, e3 = paddle_youngs_modulus_Pa, joint.carrier_youngs_modulus_Pa, joint.rivet_youngs_modulus_Pa
    a, b, n = 2.0 / 3.0, 2.2, 1
    c = ((t1 + t2) / (2 * d)) ** a * (b / n) * (1 / (t1 * e1) + 1 / (n * t2 * e2) + 1 / (2 * t1 * e3)
                                                 + 1 / (2 * n * t2 * e3))
    return 1.0 / c


def swift_rivet_stiffness(joint: Joint, paddle_thickness_m: float, paddle_youngs_modulus_Pa: float) -> float:
    """Stiffness of one rivet by Swift's (Douglas) formula, N/m: ``C = 5 / (d E3) + 0.8 (1/(t1 E1) + 1/(t2 E2))``."""
    c = (5.0 / (joint.rivet_diameter_m * joint.rivet_youngs_modulus_Pa)
         + 0.8 / (paddle_thickness_m * paddle_youngs_modulus_Pa)
         + 0.8 / (joint.carrier_thickness_m * joint.carrier_youngs_modulus_Pa))
    return 1.0 / c


@functools.lru_cache(maxsize=32)
def _joint_stiffness(joint: Joint, paddle_thickness_m: float, paddle_youngs_modulus_Pa: float) -> JointStiffness:
    rivet = huth_rivet_stiffness(joint, paddle_thickness_m, paddle_youngs_modulus_Pa)
    return JointStiffness(tab_N_per_m=tab_stiffness_fe(joint), rivets_N_per_m=joint.rivets * rivet)


def joint_stiffness(params: SpringParams) -> JointStiffness:
    """The predicted joint of ``params`` (CalculiX tab, Huth rivets), at the reference temperature's E."""
    mat = params.material
    return _joint_stiffness(params.joint, float(params.geometry.thickness_m),
                            mat.youngs_modulus(mat.reference_temperature_degC))


def far_end_stiffness(params: SpringParams) -> float:
    """The far edge's circumferential stiffness, N/m: the override if given, else the predicted joint's."""
    if params.carrier.far_end_stiffness_N_per_m is not None:
        return float(params.carrier.far_end_stiffness_N_per_m)
    return joint_stiffness(params).series_N_per_m


def resolve_far_end(params: SpringParams) -> SpringParams:
    """``params`` with ``carrier.far_end_stiffness_N_per_m`` set (predicted when not given) for the deck.

    Only an ``"elastic"`` far end needs it; other springs are returned unchanged.
    """
    if params.geometry.far_end != "elastic" or params.carrier.far_end_stiffness_N_per_m is not None:
        return params
    return params.replace(carrier={"far_end_stiffness_N_per_m": far_end_stiffness(params)})
