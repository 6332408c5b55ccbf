"""Parse CalculiX ``.dat`` output of a paddle case into plate force vs travel.

The ``.dat`` file holds, for every converged increment, blocks like::

     displacements (vx,vy,vz) for set REF_UPPER and time  0.1000000E+01
           251  0.000000E+00  0.000000E+00 -4.166667E-03
     forces (fx,fy,fz) for set REF_UPPER and time  0.1000000E+01
           251  0.000000E+00  0.000000E+00 -1.234567E+01

with the total time (step 1 spans (0, 1], step 2 (1, 2]). Values are mm, N.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ResultError

_HEAD = re.compile(r"^\s*(displacements|forces)\s+\(\w+,\w+,\w+\)\s+for set\s+(\S+)\s+and time\s+(\S+)")
MM = 1e-3  # mm -> m


@dataclass(frozen=True)
class CaseResult:
    """Raw FE results of one temperature case, SI units.

    Attributes
    ----------
    theta_degC : float
        Case temperature.
    paddles : int
        1 for the half-pair model (pair travel = 2 x plate travel), 2 for the pair.
    crest_rise_m : float
        Axial rise of paddle A's crest during heating (step 1), m.
    travel_m : ndarray
        Closing of the gap between the plates during step 2 (>= 0), m, per increment.
    force_N : ndarray
        Axial plate force during step 2 (compression > 0), N, per increment.
    thermal_force_N : float
        Plate force at the end of heating (contact during heating), N.
    thermal_force_lower_N : float
        Force on the lower plate (the carrier plane in the half-pair model) at
        the end of heating, N; heating alone should leave it at zero.
    """

    theta_degC: float
    paddles: int
    crest_rise_m: float
    travel_m: np.ndarray
    force_N: np.ndarray
    thermal_force_N: float
    thermal_force_lower_N: float = 0.0

    @property
    def pair_travel_m(self) -> np.ndarray:
        """Closing of one paddle pair (both paddles), m."""
        return self.travel_m * (2 if self.paddles == 1 else 1)


def read_dat(path: Path) -> dict[tuple[str, str], list[tuple[float, np.ndarray]]]:
    """All node-print blocks of a ``.dat`` file.

    Returns
    -------
    dict
        ``(quantity, set name)`` to a list of ``(time, values)``, values of
        shape (nodes, 3) in the deck's units.
    """
    blocks: dict[tuple[str, str], list[tuple[float, np.ndarray]]] = {}
    key = None
    rows: list[list[float]] = []

    def flush():
        if key is not None:
            blocks.setdefault(key[:2], []).append((key[2], np.array(rows, dtype=float)[:, 1:4]))

    for line in Path(path).read_text(errors="replace").splitlines():
        m = _HEAD.match(line)
        if m:
            flush()
            key = (m.group(1), m.group(2), float(m.group(3)))
            rows = []
        elif key is not None and line.strip():
            parts = line.split()
            try:
                rows.append([float(v) for v in parts])
            except ValueError:
                flush()
                key = None
    flush()
    return blocks


def parse_case(dat_path: Path, theta_degC: float, paddles: int) -> CaseResult:
    """Plate force against travel from a paddle case's ``.dat`` file.

    Raises
    ------
    ResultError
        If the expected blocks are missing or step 2 produced no increments.
    """
    blocks = read_dat(dat_path)
    try:
        up_u = blocks[("displacements", "REF_UPPER")]
        up_f = blocks[("forces", "REF_UPPER")]
        lo_u = blocks[("displacements", "REF_LOWER")]
        lo_f = blocks[("forces", "REF_LOWER")]
        crest = blocks[("displacements", "CREST")]
    except KeyError as exc:
        raise ResultError(f"{dat_path}: missing output block {exc}") from exc
    times = np.array([t for t, _ in up_u])
    step1 = times <= 1.0 + 1e-9
    if not step1.any() or step1.all():
        raise ResultError(f"{dat_path}: need increments in both steps, got times {times}")
    uz_up = np.array([v[0, 2] for _, v in up_u])
    uz_lo = np.array([v[0, 2] for _, v in lo_u])
    fz_up = np.array([v[0, 2] for _, v in up_f])
    crest_z = np.array([v[0, 2] for _, v in crest])
    i1 = np.flatnonzero(step1)[-1]
    travel = (uz_lo - uz_up)[~step1] * MM
    force = -fz_up[~step1]              # RF3 < 0 is compression of the paddle
    return CaseResult(
        theta_degC=theta_degC, paddles=paddles, crest_rise_m=float(crest_z[i1]) * MM,
        travel_m=np.concatenate([[0.0], travel]),
        force_N=np.concatenate([[-fz_up[i1]], force]),
        thermal_force_N=float(-fz_up[i1]),
        thermal_force_lower_N=float(lo_f[i1][1][0, 2]),
    )
