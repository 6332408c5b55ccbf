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

The one reader of a table set is :func:`read_tables` (:class:`~.spring_table.SpringTable` builds the model
from it, the FMU build and the FE stage check with it); it and :class:`~.friction.FrictionTable` raise one
exception type, :class:`~cushion_clutch.errors.TableError` (a ``ValueError``), naming the file. The writer
(:func:`cushion_clutch.fe.tables.write_tables`) takes every name from here; the pythonfmu FMU carries this module
beside the model.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

try:                                    # inside the pythonfmu FMU the modules are siblings
    from ..errors import TableError
except ImportError:
    from errors import TableError

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
    """Rows of a table CSV with exactly ``columns`` as header; :class:`TableError` names the file."""
    try:
        with open(path) as fh:
            header = fh.readline().strip().split(",")
            data = np.loadtxt(fh, delimiter=",", ndmin=2)
    except (OSError, ValueError) as exc:
        raise TableError(f"{path}: {exc}") from exc
    if tuple(h.strip() for h in header) != columns or data.shape[1] != len(columns):
        raise TableError(f"{path}: header must be {','.join(columns)}")
    if not np.all(np.isfinite(data)):
        raise TableError(f"{path}: non-finite value")
    return data


@dataclass(frozen=True)
class TableSet:
    """A table set read and checked by :func:`read_tables`: per-temperature curves and kiss shifts (SI)."""

    theta_degC: np.ndarray                   #: table temperatures, ascending, degC
    u_m: tuple[np.ndarray, ...]              #: per temperature: compression from its kiss point, m
    force_N: tuple[np.ndarray, ...]          #: per temperature: the whole spring's force, N
    delta_kiss_m: np.ndarray                 #: kiss-point shift per temperature, m
    metadata: dict                           #: ``metadata.json`` ({} without one)


def read_metadata(folder: str | Path) -> dict:
    """``metadata.json`` of a table set ({} if it has none).

    Raises
    ------
    TableError
        If the file is not readable JSON holding an object (the file named).
    """
    path = Path(folder) / METADATA
    try:
        meta = json.loads(path.read_text(encoding="utf-8")) if path.exists() else {}
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise TableError(f"{path}: not a readable JSON file: {exc}") from exc
    if not isinstance(meta, dict):
        raise TableError(f"{path}: must hold a JSON object")
    return meta


def read_tables(folder: str | Path) -> TableSet:
    """Read and check a table set: the one reader (the model, the FMU build and the FE stage use it).

    Raises
    ------
    TableError
        A missing folder or file, wrong columns, non-finite, negative or non-monotone data, or temperatures
        that differ between the files (the file and, where it is one, the row named).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise TableError(f"{folder}: table folder does not exist (it must hold {FORCE_DEFLECTION} "
                         f"and {KISS_POINT})")
    fd = load_csv(folder / FORCE_DEFLECTION, COLUMNS[FORCE_DEFLECTION])
    kp = load_csv(folder / KISS_POINT, COLUMNS[KISS_POINT])
    metadata = read_metadata(folder)
    negative = np.flatnonzero(fd[:, 2] < 0.0)
    if negative.size:
        k = int(negative[0])
        raise TableError(f"{folder / FORCE_DEFLECTION}: row {k + 1} (line {k + 2}): force_N = {float(fd[k, 2])!r} "
                         f"< 0 (a clamp force cannot be negative; {negative.size} such row(s))")
    thetas = np.unique(fd[:, 0])
    us, fs = [], []
    for t in thetas:
        rows = fd[fd[:, 0] == t]
        if len(rows) < 2 or np.any(np.diff(rows[:, 1]) <= 0) or np.any(np.diff(rows[:, 2]) < 0):
            raise TableError(f"{folder / FORCE_DEFLECTION}: theta = {t:g} needs >= 2 rows, "
                             "u strictly increasing and force non-decreasing")
        us.append(rows[:, 1])
        fs.append(rows[:, 2])
    order = np.argsort(kp[:, 0])
    if not np.array_equal(kp[order, 0], thetas):
        raise TableError(f"{folder}: {KISS_POINT} temperatures {kp[order, 0]} differ from "
                         f"{FORCE_DEFLECTION} temperatures {thetas}")
    return TableSet(thetas, tuple(us), tuple(fs), kp[order, 1], metadata)


def table_set_x_kiss_ref(folder: str | Path) -> float | None:
    """The FMU parameter ``x_kiss_ref`` (m) a table set asks for, or None for the model default.

    A tolerance study's P5/P95 set measures u from its own spring's kiss point;
    ``metadata.json`` then holds ``tolerance_study.x_kiss_ref_m``, the bearing
    position of that kiss point against the nominal spring's.

    Raises
    ------
    TableError
        A value that is not a number in -1..1 m, or a metadata file that is no JSON object (the file named).
    """
    path = Path(folder) / METADATA
    try:                            # imported here: number_check imports spring_table, which imports this module
        from ..number_check import is_finite_number
    except ImportError:
        from number_check import is_finite_number
    study = read_metadata(folder).get("tolerance_study", {})
    if not isinstance(study, dict):
        raise TableError(f"{path}: tolerance_study must be a JSON object")
    value = study.get("x_kiss_ref_m")
    if value is None:
        return None
    if not (is_finite_number(value) and -1.0 <= value <= 1.0):      # a JSON true is no 1 m
        raise TableError(f"{path}: tolerance_study.x_kiss_ref_m = {value!r}: allowed -1..1 m")
    return float(value)
