"""From FE case results to lookup tables, written atomically.

The table-set format (file names, columns, units) is
:mod:`cushion_clutch.model.table_format`'s, and so is its one reader (``read_tables``); this module writes sets.
"""
from __future__ import annotations

import csv
import json
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ResultError
from ..model.table_format import COLUMNS, CREST_GROWTH, FORCE_DEFLECTION, KISS_POINT, METADATA
from .results import CaseResult

#: relative force decrease (of the case's largest force) treated as solver noise
MONOTONE_TOLERANCE = 0.005


@dataclass(frozen=True)
class Curve:
    """Force-deflection curve of one temperature.

    Attributes
    ----------
    theta_degC : float
    u_m : ndarray
        Pair compression from the kiss point, m (first entry <= 0: first contact).
    force_N : ndarray
        Whole-spring force, N, non-decreasing.
    kiss_travel_m : float
        Pair travel of the plates from their start to the kiss point, m.
    removed_decrease_N : float
        Largest force decrease (whole spring) smoothed out as solver noise, N.
    """

    theta_degC: float
    u_m: np.ndarray
    force_N: np.ndarray
    kiss_travel_m: float
    removed_decrease_N: float


def curve_from_case(case: CaseResult, n_pairs: int, kiss_force_N: float) -> Curve:
    """Locate the kiss point and express the curve from it.

    The kiss point is where the force of one pair first passes
    ``kiss_force_N`` (linear between increments). The curve starts at the
    last increment before it with no contact force; force is clipped at zero
    (the penalty law's small tension can pull a few tenths of a newton).

    Raises
    ------
    ResultError
        If the force never reaches the kiss force, contact existed before
        compression, or the force falls by more than ``MONOTONE_TOLERANCE``
        of its maximum (snap-through: a table would lie).
    """
    s, f = case.pair_travel_m, case.force_N
    above = np.flatnonzero(f >= kiss_force_N)
    if len(above) == 0:
        raise ResultError(f"theta = {case.theta_degC:g} degC: force never reached the kiss force "
                          f"{kiss_force_N:g} N (max {f.max():.3g} N)")
    k = above[0]
    if k == 0:
        raise ResultError(f"theta = {case.theta_degC:g} degC: the paddle already pressed the plate "
                          f"with {f[0]:.3g} N after heating; increase solver.initial_gap_m")
    s_kiss = float(s[k - 1] + (kiss_force_N - f[k - 1]) * (s[k] - s[k - 1]) / (f[k] - f[k - 1]))
    zero = np.flatnonzero(f[:k] <= 0.0)
    start = zero[-1] if len(zero) else 0
    u = s[start:] - s_kiss
    force = np.maximum(f[start:], 0.0)
    drops = np.maximum.accumulate(force) - force
    if drops.max() > MONOTONE_TOLERANCE * force.max():
        i = int(np.argmax(drops))
        raise ResultError(
            f"theta = {case.theta_degC:g} degC: force falls by {drops.max():.3g} N at u = "
            f"{u[i] * 1e3:.4f} mm (snap-through); this curve cannot be tabulated")
    force = np.maximum.accumulate(force)
    # the kiss point itself as a row: u = 0, F = kiss force
    # (an increment exactly at the kiss force is that row: u == 0 is dropped from both columns)
    force = np.concatenate([force[u < 0], [kiss_force_N], force[u > 0]])
    u = np.concatenate([u[u < 0], [0.0], u[u > 0]])
    keep = np.concatenate([[True], np.diff(u) > 1e-12])
    return Curve(case.theta_degC, u[keep], n_pairs * force[keep], s_kiss,
                 n_pairs * float(drops.max()))


def kiss_shift(curves: list[Curve], reference_degC: float) -> dict[float, float]:
    """delta_kiss(theta) = kiss travel at reference - kiss travel at theta, m."""
    ref = [c for c in curves if abs(c.theta_degC - reference_degC) < 1e-9]
    if not ref:
        raise ResultError(f"no curve at the reference temperature {reference_degC:g} degC")
    return {c.theta_degC: ref[0].kiss_travel_m - c.kiss_travel_m for c in curves}


def write_tables(out_dir: Path, curves: list[Curve], reference_degC: float,
                 metadata: dict, crest_growth_m: dict[float, float] | None = None) -> Path:
    """Write a table set atomically: all files appear together or not at all.

    ``crest_growth_m`` (theta to m), if given, goes to ``crest_growth.csv``.

    The set is built in a temporary sibling folder and renamed into place;
    an existing set is replaced only after the new one is complete.
    """
    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    shifts = kiss_shift(curves, reference_degC)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.", dir=out_dir.parent))
    try:
        with open(tmp / FORCE_DEFLECTION, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS[FORCE_DEFLECTION])
            for c in sorted(curves, key=lambda c: c.theta_degC):
                for u, f in zip(c.u_m, c.force_N):
                    w.writerow([f"{c.theta_degC:g}", f"{u:.9e}", f"{f:.6f}"])
        with open(tmp / KISS_POINT, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(COLUMNS[KISS_POINT])
            for t in sorted(shifts):
                w.writerow([f"{t:g}", f"{shifts[t]:.9e}"])
        if crest_growth_m is not None:
            with open(tmp / CREST_GROWTH, "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(COLUMNS[CREST_GROWTH])
                for t in sorted(crest_growth_m):
                    w.writerow([f"{t:g}", f"{crest_growth_m[t]:.9e}"])
        (tmp / METADATA).write_text(json.dumps(metadata, indent=2, default=_jsonable) + "\n")
        backup = None
        if out_dir.exists():
            backup = out_dir.with_name(f".{out_dir.name}.old")
            if backup.exists():
                shutil.rmtree(backup)
            os.replace(out_dir, backup)
        os.replace(tmp, out_dir)
        if backup is not None:
            shutil.rmtree(backup)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return out_dir


def _jsonable(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (np.floating, np.integer)):
        return obj.item()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serialisable: {type(obj)}")


#: travel fractions (kiss point to full compression) at which progressivity is reported
PROGRESSIVITY_FRACTIONS = (0.2, 0.5, 0.9)


def tangent_stiffness(u_m: np.ndarray, force_N: np.ndarray, fractions=PROGRESSIVITY_FRACTIONS,
                      window: float = 0.05) -> dict[float, float]:
    """Tangent stiffness dF/du (N/m) at fractions of the travel from the kiss point to full compression.

    The slope is a secant over ``window`` of that travel centred on each
    point (clipped to the curve's ends), so that increment noise does not
    dominate it.
    """
    u = np.asarray(u_m, dtype=float)
    f = np.asarray(force_N, dtype=float)
    u_full = float(u[-1])
    out = {}
    for x in fractions:
        lo = max(0.0, (x - 0.5 * window) * u_full)
        hi = min(u_full, (x + 0.5 * window) * u_full)
        out[x] = float((np.interp(hi, u, f) - np.interp(lo, u, f)) / (hi - lo))
    return out


def progressivity(u_m: np.ndarray, force_N: np.ndarray) -> dict[str, float]:
    """k(20 %), k(50 %), k(90 %) in N/m and the ratio k(90 %)/k(20 %) of one curve."""
    k = tangent_stiffness(u_m, force_N)
    return {"k20_N_per_m": k[0.2], "k50_N_per_m": k[0.5], "k90_N_per_m": k[0.9],
            "k90_over_k20": k[0.9] / k[0.2]}
