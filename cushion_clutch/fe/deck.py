"""CalculiX deck writer: neutral mesh and parameters in, ``.inp`` text out.

The deck uses CalculiX's consistent units mm, N, MPa, degC; everything
given to these functions is SI and converted here. Nothing is run or read.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable

import numpy as np

from .geometry import Assembly, Plate, ShellMesh
from .params import Material, SpringParams

MM = 1e3          # m -> mm
MPA = 1e-6        # Pa -> MPa
PLATE_THICKNESS_MM = 1.0

#: time-incrementation controls: defaults but for 20 cut-backs per increment (I_A)
#: instead of 5, so that contact chatter at first touch is retried, not fatal
_CONTROLS = ("*CONTROLS, PARAMETERS=TIME INCREMENTATION", "4, 8, 9, 200, 10, 4, 0, 20")

#: node set names printed to the .dat file, per step, for the parser
REF_SETS = ("REF_UPPER", "REF_LOWER")


@dataclass(frozen=True)
class DeckInfo:
    """Node numbering facts the parser needs (1-based CalculiX ids)."""

    ref_upper: int
    ref_lower: int
    crest: int
    travel_per_plate_m: float


def _fmt(v: float) -> str:
    return f"{v:.9g}"


def _id_lines(ids: Iterable[int], per_line: int = 12) -> list[str]:
    ids = list(ids)
    return [", ".join(str(i) for i in ids[k:k + per_line]) + ","
            for k in range(0, len(ids), per_line)]


def _mesh_block(mesh: ShellMesh, elset: str = "PADDLE", element_type: str = "S4") -> list[str]:
    out = ["*NODE, NSET=NPADDLE"]
    out += [f"{i + 1}, {_fmt(x * MM)}, {_fmt(y * MM)}, {_fmt(z * MM)}"
            for i, (x, y, z) in enumerate(mesh.nodes)]
    out.append(f"*ELEMENT, TYPE={element_type}, ELSET={elset}")
    out += [f"{e + 1}, " + ", ".join(str(n + 1) for n in conn) for e, conn in enumerate(mesh.elements)]
    for name, ids in mesh.node_sets.items():
        out.append(f"*NSET, NSET={name}")
        out += _id_lines(np.asarray(ids) + 1)
    for name, ids in mesh.element_sets.items():
        if name == elset:
            continue
        out.append(f"*ELSET, ELSET={name}")
        out += _id_lines(np.asarray(ids) + 1)
    return out


def _material_block(material: Material, thermal_distortion: bool = True) -> list[str]:
    out = ["*MATERIAL, NAME=STEEL", "*ELASTIC"]
    out += [f"{_fmt(e * MPA)}, {_fmt(material.poisson_ratio)}, {_fmt(t)}"
            for t, e in zip(material.temperatures_degC, material.youngs_modulus_Pa)]
    out.append(f"*EXPANSION, ZERO={_fmt(material.reference_temperature_degC)}")
    if not thermal_distortion:
        out.append(_fmt(0.0))
    elif not material.expansion_coefficients_per_K:
        out.append(_fmt(material.expansion_coefficient_per_K))
    else:                                    # secant coefficients from ZERO, one per temperature
        out += [f"{_fmt(a)}, {_fmt(t)}" for a, t in material.expansion_table()]
    return out


def _plate_block(plates: tuple[Plate, ...], first_node: int, first_elem: int) -> tuple[list[str], dict]:
    """Rigid plates as one C3D8 brick each, plus reference and rotation nodes.

    (Shell plates cannot be rigid bodies in CalculiX: their expansion to
    solids already ties the nodes by equations.)
    """
    out: list[str] = []
    refs: dict[str, tuple[int, int]] = {}
    node = first_node
    elem = first_elem
    for plate in plates:
        z_face = plate.z_face_m * MM
        z_back = z_face + (-PLATE_THICKNESS_MM if plate.faces_up else PLATE_THICKNESS_MM)
        z_bot, z_top = min(z_face, z_back), max(z_face, z_back)
        (x0, y0), (x1, y1) = plate.xy_min_m, plate.xy_max_m
        corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]     # counter-clockwise from +z
        out.append(f"*NODE, NSET=N{plate.name}")
        ids = []
        for z in (z_bot, z_top):
            for x, y in corners:
                out.append(f"{node}, {_fmt(x * MM)}, {_fmt(y * MM)}, {_fmt(z)}")
                ids.append(node)
                node += 1
        ref, rot = node, node + 1
        out += ["*NODE", f"{ref}, 0, 0, {_fmt(z_face)}", f"{rot}, 0, 0, {_fmt(z_face)}"]
        out += [f"*NSET, NSET=REF_{plate.name}", f"{ref},", f"*NSET, NSET=ROT_{plate.name}", f"{rot},"]
        node += 2
        out.append(f"*ELEMENT, TYPE=C3D8, ELSET=PLATE_{plate.name}")
        out.append(f"{elem}, " + ", ".join(map(str, ids)))
        elem += 1
        out += [f"*SOLID SECTION, ELSET=PLATE_{plate.name}, MATERIAL=STEEL",
                f"*RIGID BODY, ELSET=PLATE_{plate.name}, REF NODE={ref}, ROT NODE={rot}",
                f"*SURFACE, NAME=M_{plate.name}, TYPE=ELEMENT",
                # C3D8 face S1 is the bottom (outward -z), S2 the top (outward +z)
                f"PLATE_{plate.name}, {'S2' if plate.faces_up else 'S1'}"]
        refs[plate.name] = (ref, rot)
    return out, refs


def _contact_block(assembly: Assembly, params: SpringParams) -> list[str]:
    sol = params.solver
    pairs = [("S_A_TOP", "CONTACT_A", "SPOS", "M_UPPER")]
    if assembly.paddles == 1:
        pairs.append(("S_A_BOT", "CONTACT_A", "SNEG", "M_LOWER"))
    else:
        pairs += [("S_B_BOT", "CONTACT_B", "SNEG", "M_LOWER"),
                  ("S_A_BOT", "CONTACT_A", "SNEG", "M_B_TOP")]
    out = ["*SURFACE, NAME=M_B_TOP, TYPE=ELEMENT", "CONTACT_B, SPOS"] if assembly.paddles == 2 else []
    for surf, elset, face, _ in pairs:
        out += [f"*SURFACE, NAME={surf}, TYPE=ELEMENT", f"{elset}, {face}"]
    if sol.contact == "node_to_surface":
        slope = sol.node_penalty_N_per_m / MM                 # N/m -> N/mm per slave node
        kind = "NODE TO SURFACE"
    else:
        slope = sol.surface_penalty_Pa_per_m * MPA / MM      # Pa/m -> MPa/mm
        kind = "SURFACE TO SURFACE"
    out += ["*SURFACE INTERACTION, NAME=SI",
            "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
            f"{_fmt(slope)}, {_fmt(sol.tension_N)}"]
    for surf, _, _, master in pairs:
        out += [f"*CONTACT PAIR, INTERACTION=SI, TYPE={kind}", f"{surf}, {master}"]
    return out


def carrier_displacement(nodes_m: np.ndarray, params: SpringParams, theta_degC: float) -> np.ndarray:
    """In-plane displacement (m) of carrier points at ``nodes_m`` at ``theta_degC``.

    The carrier expands freely about the disc axis at its own temperature
    ``theta_ref + kappa (theta - theta_ref)``.
    """
    mat = params.material
    theta_carrier = mat.reference_temperature_degC + params.carrier.temperature_ratio * (
        theta_degC - mat.reference_temperature_degC)
    alpha = mat.expansion_coefficient(theta_carrier) if params.sweep.thermal_distortion else 0.0
    strain = alpha * (theta_carrier - mat.reference_temperature_degC)
    return strain * np.asarray(nodes_m)[:, :2]


def paddle_deck(assembly: Assembly, params: SpringParams, theta_degC: float,
                node_temperatures_degC: np.ndarray | None = None) -> tuple[str, DeckInfo]:
    """CalculiX deck of one temperature case.

    ``node_temperatures_degC`` (one per paddle node, in the mesh's order), if given, replaces the uniform
    ``theta_degC`` of step 1 by that field (``cushion-clutch heat-path --kiss-shift``); the carrier still
    follows ``theta_degC`` through ``carrier.temperature_ratio``.

    Step 1 heats the paddle(s) uniformly from the reference temperature to
    ``theta_degC`` with both plates held, the clamped zone and the far-end
    anchors following the carrier's own thermal expansion; step 2 moves the
    plate(s) towards each other under displacement control. Each plate's
    reference node prints U and RF every increment.

    Returns
    -------
    text : str
        The deck.
    info : DeckInfo
        Ids of the reference and crest nodes and the travel of each plate.
    """
    mesh, geom, sol = assembly.mesh, params.geometry, params.solver
    lines = [f"** cushion_clutch: spring '{params.name}', theta = {theta_degC:g} degC, "
             f"{assembly.paddles} paddle(s), units mm N MPa degC"]
    lines += _mesh_block(mesh, element_type=params.mesh.element_type)
    lines += _material_block(params.material, params.sweep.thermal_distortion)
    lines += ["*SHELL SECTION, ELSET=PADDLE, MATERIAL=STEEL", _fmt(mesh.thickness_m * MM)]
    plate_lines, refs = _plate_block(assembly.plates, mesh.n_nodes + 1, mesh.n_elements + 1)
    lines += plate_lines
    anchors = far_end_anchors(assembly, params) if geom.far_end == "elastic" else []
    lines += _spring_block(anchors, mesh.n_elements + len(assembly.plates) + 1)
    lines += _contact_block(assembly, params)
    ref_t = params.material.reference_temperature_degC
    lines += ["*INITIAL CONDITIONS, TYPE=TEMPERATURE", f"NPADDLE, {_fmt(ref_t)}"]
    lines += [f"N{p.name}, {_fmt(ref_t)}" for p in assembly.plates]
    lines += ["*BOUNDARY", "CLAMP, 3, 3"]
    if len(mesh.node_sets.get("GUIDE", [])):
        lines.append("GUIDE, 3, 3")
    for ref, rot in refs.values():
        lines += [f"{ref}, 1, 3", f"{rot}, 1, 3"]
    lines += [f"{a}, 3, 3" for a, _, _, _ in anchors]

    # step 1: uniform temperature; clamp and anchors follow the carrier's expansion
    held_ids = [int(n) + 1 for n in mesh.node_sets["CLAMP"]]
    held_xyz = [mesh.nodes[n] for n in mesh.node_sets["CLAMP"]]
    if geom.far_end == "locked":
        held_ids += [int(n) + 1 for n in mesh.node_sets["FAR_END"]]
        held_xyz += [mesh.nodes[n] for n in mesh.node_sets["FAR_END"]]
    held_ids += [a for a, _, _, _ in anchors]
    held_xyz += [xyz for _, _, xyz, _ in anchors]
    disp = carrier_displacement(np.array(held_xyz), params, theta_degC) * MM
    lines += [f"*STEP, NLGEOM, INC={sol.max_increments}", *_CONTROLS, "*STATIC",
              "0.25, 1.0, 1e-6, 0.5", "*BOUNDARY"]
    for n, (ux, uy) in zip(held_ids, disp):
        lines += [f"{n}, 1, 1, {_fmt(ux)}", f"{n}, 2, 2, {_fmt(uy)}"]
    if node_temperatures_degC is None:
        lines += ["*TEMPERATURE", f"NPADDLE, {_fmt(theta_degC)}"]
    else:
        lines += ["*TEMPERATURE", *(f"{i + 1}, {_fmt(t)}" for i, t in enumerate(node_temperatures_degC))]
    lines += _print_block()
    lines.append("*END STEP")

    # step 2: displacement-controlled compression
    travel_m = sol.initial_gap_m + sol.flatten_fraction * geom.max_wave_height_m
    dt = 1.0 / sol.compression_increments
    lines += [f"*STEP, NLGEOM, INC={sol.max_increments}", *_CONTROLS, "*STATIC",
              f"{_fmt(dt)}, 1.0, {_fmt(dt * 1e-4)}, {_fmt(dt)}", "*BOUNDARY",
              f"{refs['UPPER'][0]}, 3, 3, {_fmt(-travel_m * MM)}"]
    if assembly.paddles == 2:
        lines.append(f"{refs['LOWER'][0]}, 3, 3, {_fmt(travel_m * MM)}")
    lines += _print_block()
    lines.append("*END STEP")
    info = DeckInfo(ref_upper=refs["UPPER"][0], ref_lower=refs["LOWER"][0],
                    crest=int(mesh.node_sets["CREST"][0]) + 1, travel_per_plate_m=travel_m)
    return "\n".join(lines) + "\n", info


ANCHOR_LENGTH_M = 1e-3


def far_end_anchors(assembly: Assembly, params: SpringParams) -> list[tuple[int, int, np.ndarray, float]]:
    """Carrier anchor of each far-edge node: (anchor id, node id, anchor xyz m, k N/mm).

    Each anchor sits ``ANCHOR_LENGTH_M`` further along the circumference; the
    edge's total stiffness (``carrier.far_end_stiffness_N_per_m``: the joint of
    :mod:`.joint`, tab and rivets in series, set by :func:`.joint.resolve_far_end`)
    is shared by tributary length along the edge: the far zone, 36 mm deep in its
    plane, moves as one piece against one stiffness.

    Raises
    ------
    ValueError
        The stiffness is not set (the joint not resolved): the deck writer runs nothing.
    """
    if params.carrier.far_end_stiffness_N_per_m is None:
        raise ValueError("carrier.far_end_stiffness_N_per_m is None: resolve the joint first "
                         "(cushion_clutch.fe.joint.resolve_far_end)")
    mesh = assembly.mesh
    far = np.asarray(mesh.node_sets["FAR_END"])
    first = mesh.n_nodes + 1 + 10 * len(assembly.plates)    # after plate, ref and rot nodes
    out = []
    for paddle_nodes in _split_by_paddle(mesh, far):
        xyz = mesh.nodes[paddle_nodes]
        r = np.hypot(xyz[:, 0], xyz[:, 1])
        order = np.argsort(r)
        paddle_nodes, xyz, r = paddle_nodes[order], xyz[order], r[order]
        trib = np.zeros(len(r))
        trib[:-1] += 0.5 * np.diff(r)
        trib[1:] += 0.5 * np.diff(r)
        k = params.carrier.far_end_stiffness_N_per_m / MM * trib / trib.sum()
        for n, p, kn in zip(paddle_nodes, xyz, k):
            tangent = np.array([-p[1], p[0], 0.0]) / np.hypot(p[0], p[1])
            out.append((first + len(out), int(n) + 1, p + ANCHOR_LENGTH_M * tangent, float(kn)))
    return out


def _split_by_paddle(mesh: ShellMesh, nodes: np.ndarray) -> list[np.ndarray]:
    z = mesh.nodes[nodes, 2]
    return [g for g in (nodes[z > 0], nodes[z < 0]) if len(g)]


def _spring_block(anchors, first_elem: int) -> list[str]:
    """Anchor nodes and one SPRINGA element (own stiffness) per far-edge node."""
    if not anchors:
        return []
    out = ["*NODE, NSET=NANCHOR"]
    out += [f"{a}, {_fmt(x * MM)}, {_fmt(y * MM)}, {_fmt(z * MM)}" for a, _, (x, y, z), _ in anchors]
    for i, (a, n, _, k) in enumerate(anchors):
        out += [f"*ELEMENT, TYPE=SPRINGA, ELSET=ESPRING{i + 1}", f"{first_elem + i}, {n}, {a}",
                f"*SPRING, ELSET=ESPRING{i + 1}", f"{k:.9e}"]  # needs a decimal point
    return out


def _print_block() -> list[str]:
    return ["*NODE PRINT, NSET=REF_UPPER", "U, RF", "*NODE PRINT, NSET=REF_LOWER", "U, RF",
            "*NODE PRINT, NSET=CREST", "U"]


def strip_deck(mesh: ShellMesh, material: Material, *, tip_force_N: float = 0.0,
               theta_degC: float | None = None) -> str:
    """Deck of a flat strip for closed-form checks (linear, one step).

    With ``tip_force_N`` the strip is a cantilever clamped (all six DOFs) at ``END0`` and
    loaded in -z at ``END1`` (shared equally by its nodes). With
    ``theta_degC`` it is heated uniformly, held only against rigid-body
    motion (``ORIGIN`` fixed, ``CORNER_Y`` fixed in x and z, ``END1`` in z).
    Both print U of ``END1``.
    """
    lines = ["** cushion_clutch: flat strip check, units mm N MPa degC"]
    lines += _mesh_block(mesh)
    lines += _material_block(material)
    lines += ["*SHELL SECTION, ELSET=PADDLE, MATERIAL=STEEL", _fmt(mesh.thickness_m * MM)]
    ref_t = material.reference_temperature_degC
    lines += ["*INITIAL CONDITIONS, TYPE=TEMPERATURE", f"NPADDLE, {_fmt(ref_t)}", "*BOUNDARY"]
    if theta_degC is None:
        lines.append("END0, 1, 6")          # rotations too: a shell edge held in translation is a hinge
    else:
        lines += ["ORIGIN, 1, 3", "CORNER_Y, 1, 1", "CORNER_Y, 3, 3", "END1, 3, 3"]
    lines += ["*STEP", "*STATIC"]
    if tip_force_N:
        tip = mesh.node_sets["END1"]
        lines.append("*CLOAD")
        lines += [f"{n + 1}, 3, {_fmt(-tip_force_N / len(tip))}" for n in tip]
    if theta_degC is not None:
        lines += ["*TEMPERATURE", f"NPADDLE, {_fmt(theta_degC)}"]
    lines += ["*NODE PRINT, NSET=END1", "U", "*END STEP"]
    return "\n".join(lines) + "\n"
