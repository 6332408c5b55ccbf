"""The kiss shift under the thermal FE's temperature field against a uniform paddle temperature.

Sequential: the disc-sector heat transfer (:mod:`.heat_path`) gives the paddle's
temperature-rise field and the carrier's rise, both averaged over the last launch
period (a hot clutch in repeated launches); the existing paddle FE (:mod:`.deck`,
the sweep's model with the spring file's tab) is then heated with that field,
scaled to a paddle mean of ``theta_degC``, and compressed. Cases at ``theta_degC``:

- ``uniform, kappa spring``: the sweep's case (uniform paddle, carrier at the spring file's ``temperature_ratio``);
- ``uniform, kappa FE``: uniform paddle, carrier at the FE's ratio of carrier to paddle rise;
- ``field, kappa FE``: the FE's field on the paddle, carrier at the FE's ratio.

All three hold the paddle's far edge with the same stiffness: the joint predicted from the spring file's
``[joint]`` (the carrier tab's CalculiX model in series with the clamp rivets, :mod:`.joint`), or the
spring's ``carrier.far_end_stiffness_N_per_m`` if it gives one. Nothing is fitted to the paper's 0.1 mm. The
table sets (one uniform paddle temperature per row) are not changed here.
"""
from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Callable

import numpy as np
from scipy.interpolate import LinearNDInterpolator, NearestNDInterpolator

from ..errors import CalculixError, ResultError
from .ccx import run_ccx
from .deck import paddle_deck
from .joint import far_end_stiffness, resolve_far_end
from .geometry import half_pair_assembly
from .heat_mesh import HeatMesh
from .params import SpringParams
from .results import parse_case
from .tables import curve_from_case

#: structural mesh of the kiss-shift cases, m (the sweep's committed mesh is 1 mm; 2 mm agreed within
#: about 3.5 % in the feasibility runs, see the CalculiX notes)
KISS_MESH_M = 2e-3


def field_shape(mesh: HeatMesh, times_s: np.ndarray, temps: np.ndarray, ambient_degC: float,
                window_s: tuple[float, float]) -> tuple[np.ndarray, np.ndarray, float]:
    """Paddle element centres (r m, phi deg), their rise / the paddle's mean rise, and carrier / paddle rise.

    All averaged over the increments inside ``window_s``.
    """
    sel = (times_s > window_s[0]) & (times_s <= window_s[1])
    te = temps[sel][:, mesh.elements].mean(axis=2).mean(axis=0) - ambient_degC
    rc = mesh.density_kg_m3 * mesh.specific_heat_J_per_kg_K * mesh.volume_m3
    pad, car = mesh.element_sets["PADDLE"], mesh.element_sets["CARRIER"]
    mean_pad = float(te[pad] @ rc[pad] / rc[pad].sum())
    mean_car = float(te[car] @ rc[car] / rc[car].sum())
    xy = mesh.nodes[mesh.elements[pad]].mean(axis=1)
    centres = np.column_stack([np.hypot(xy[:, 0], xy[:, 1]), np.degrees(np.arctan2(xy[:, 1], xy[:, 0]))])
    return centres, te[pad] / mean_pad, mean_car / mean_pad


def _kiss_travel(spring: SpringParams, theta_degC: float, workdir: Path, field: np.ndarray | None) -> float:
    asm = half_pair_assembly(spring.geometry, KISS_MESH_M, spring.solver.initial_gap_m, spring.mesh.element_type)
    temps = None
    if field is not None:
        centres, shape, _ = field
        pts = np.column_stack([np.hypot(asm.mesh.nodes[:, 0], asm.mesh.nodes[:, 1]),
                               np.degrees(np.arctan2(asm.mesh.nodes[:, 1], asm.mesh.nodes[:, 0]))])
        scale = np.array([1.0, math.radians(1.0) * 0.09])           # phi in degrees to metres at r = 90 mm
        lin = LinearNDInterpolator(centres * scale, shape)(pts * scale)
        near = NearestNDInterpolator(centres * scale, shape)(pts * scale)
        s = np.where(np.isfinite(lin), lin, near)
        s = s / s.mean()                                              # node mean = theta (uniform node spacing)
        ref = spring.material.reference_temperature_degC
        temps = ref + (theta_degC - ref) * s
    deck, _ = paddle_deck(asm, resolve_far_end(spring), theta_degC, temps)
    run_ccx(deck, workdir, threads=1, theta_degC=theta_degC)
    case = parse_case(workdir / "case.dat", theta_degC, asm.paddles)
    return curve_from_case(case, spring.n_pairs, spring.sweep.kiss_force_N).kiss_travel_m


def kiss_shift_study(spring: SpringParams, field: tuple[np.ndarray, np.ndarray, float], out: Path,
                     theta_degC: float = 195.0, jobs: int = 2, say: Callable[[str], None] | None = None) -> dict:
    """delta_kiss at ``theta_degC`` (pair, m) for the three cases of the module docstring; failures named."""
    say = say or (lambda m: None)
    centres, shape, kappa_fe = field
    ref_t = spring.material.reference_temperature_degC
    fe_spring = spring.replace(carrier={"temperature_ratio": kappa_fe})
    cases = {"reference": (spring, ref_t, None), "uniform_kappa_spring": (spring, theta_degC, None),
             "uniform_kappa_fe": (fe_spring, theta_degC, None), "field_kappa_fe": (fe_spring, theta_degC, field)}

    def one(item):
        name, (sp, t, f) = item
        try:
            travel = _kiss_travel(sp, t, out / "work" / f"kiss_{name}", f)
            say(f"kiss case {name}: kiss travel {travel * 1e3:.4f} mm")
            return name, travel, ""
        except (CalculixError, ResultError) as exc:
            say(f"kiss case {name} failed: {exc}")
            return name, math.nan, str(exc).splitlines()[0]

    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        done = {n: (t, e) for n, t, e in pool.map(one, cases.items())}
    ref = done["reference"][0]
    shift = {n: (ref - t) for n, (t, _) in done.items() if n != "reference"}
    return {
        "theta_degC": theta_degC, "mesh_m": KISS_MESH_M,
        "kappa_spring": spring.carrier.temperature_ratio, "kappa_fe": kappa_fe,
        "far_end_stiffness_N_per_m": far_end_stiffness(spring),
        "far_end_source": ("predicted joint (fe/joint.py)" if spring.carrier.far_end_stiffness_N_per_m is None
                           else "carrier.far_end_stiffness_N_per_m (override)"),
        "field_min_over_mean": float(shape.min()), "field_max_over_mean": float(shape.max()),
        "delta_kiss_m": {n: (None if math.isnan(v) else v) for n, v in shift.items()},
        "errors": {n: e for n, (_, e) in done.items() if e},
        "paper_delta_kiss_m": 1e-4,
        "note": ("pair travel of the kiss point at theta minus at the reference temperature; the far edge held "
                 "by the same joint stiffness in every case; structural mesh "
                 f"{KISS_MESH_M * 1e3:g} mm"),
    }
