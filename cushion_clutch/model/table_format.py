"""The table-set format, owned here once: file names, columns, units, metadata keys; numpy only.

A table set is a folder (``lookup_tables/<spring>/``, an FMU's ``resources/tables/``):

``force_deflection.csv`` (required)
    ``theta_degC,u_m,force_N``: cushion-spring temperature (degC), compression
    of one paddle pair from that temperature's own kiss point (m), force of the
    whole spring (N).
``kiss_point.csv`` (required)
    ``theta_degC,delta_kiss_m``: kiss-point shift (growth of the free height) (m).
``crest_growth.csv`` (optional, FE output only)
    ``theta_degC,crest_growth_m``: growth of the pair's free height at the wave crest (m).
``friction.csv`` (optional)
    ``theta_degC,omega_slip_rad_s,mu``: facing temperature (degC), slip speed
    (rad/s), friction coefficient (1).
``metadata.json`` (optional for readers)
    Parameters, mesh, solver, statistics and progressivity of the sweep that
    made the set (:data:`METADATA_KEYS`).

The Python readers (:class:`~.spring_table.SpringTable`,
:class:`~.friction.FrictionTable`, :func:`cushion_clutch.fe.tables.read_tables`)
and writer (:func:`cushion_clutch.fe.tables.write_tables`) take every name
from here; the pythonfmu FMU carries this module beside the model.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

FORCE_DEFLECTION = "force_deflection.csv"
KISS_POINT = "kiss_point.csv"
CREST_GROWTH = "crest_growth.csv"
FRICTION = "friction.csv"
METADATA = "metadata.json"

#: header of each CSV file of a table set (units in the names)
COLUMNS = {
    FORCE_DEFLECTION: ("theta_degC", "u_m", "force_N"),
    KISS_POINT: ("theta_degC", "delta_kiss_m"),
    CREST_GROWTH: ("theta_degC", "crest_growth_m"),
    FRICTION: ("theta_degC", "omega_slip_rad_s", "mu"),
}
#: unit of each column
UNITS = {"theta_degC": "degC", "u_m": "m", "force_N": "N", "delta_kiss_m": "m", "crest_growth_m": "m",
         "omega_slip_rad_s": "rad/s", "mu": "1"}
#: files every table set has
REQUIRED_FILES = (FORCE_DEFLECTION, KISS_POINT)
#: files an FMU carries in ``resources/tables`` (those present)
FMU_FILES = (FORCE_DEFLECTION, KISS_POINT, METADATA, FRICTION)
#: top-level keys of ``metadata.json`` that readers use: per-temperature progressivity and kiss-point growth;
#: a tolerance study's P5/P95 set adds ``tolerance_study`` (its own ``x_kiss_ref_m``)
METADATA_KEYS = ("progressivity", "kiss_point", "tolerance_study")


def load_csv(path: Path, columns: tuple[str, ...]) -> np.ndarray:
    """Rows of a table CSV with exactly ``columns`` as header; ValueError names the file."""
    try:
        with open(path) as fh:
            header = fh.readline().strip().split(",")
            data = np.loadtxt(fh, delimiter=",", ndmin=2)
    except (OSError, ValueError) as exc:
        raise ValueError(f"{path}: {exc}") from exc
    if tuple(h.strip() for h in header) != columns or data.shape[1] != len(columns):
        raise ValueError(f"{path}: header must be {','.join(columns)}")
    if not np.all(np.isfinite(data)):
        raise ValueError(f"{path}: non-finite value")
    return data


def table_set_x_kiss_ref(folder: str | Path) -> float | None:
    """The FMU parameter ``x_kiss_ref`` (m) a table set asks for, or None for the model default.

    A tolerance study's P5/P95 set measures u from its own spring's kiss point;
    ``metadata.json`` then holds ``tolerance_study.x_kiss_ref_m``, the bearing
    position of that kiss point against the nominal spring's.

    Raises
    ------
    ValueError
        A value that is not a number in -1..1 m (the file named).
    """
    path = Path(folder) / METADATA
    if not path.exists():
        return None
    try:                            # imported here: number_check imports spring_table, which imports this module
        from ..number_check import is_finite_number
    except ImportError:
        from number_check import is_finite_number
    value = json.loads(path.read_text()).get("tolerance_study", {}).get("x_kiss_ref_m")
    if value is None:
        return None
    if not (is_finite_number(value) and -1.0 <= value <= 1.0):      # a JSON true is no 1 m
        raise ValueError(f"{path}: tolerance_study.x_kiss_ref_m = {value!r}: allowed -1..1 m")
    return float(value)
