"""Export a table set for Simulink (MATLAB .mat) and Modelica (CombiTable text).

Lookup blocks need a rectangular grid, while each temperature's FE curve has
its own u points. The grid is the union of all table u points; each
temperature's force is evaluated on it with the model's own interpolation
(the PCHIP curve through that temperature's points, held constant outside
them), so at every original table point the exported value equals the table.
Use the blocks with linear (or PCHIP) interpolation in u and linear in theta,
and clipping at the ends, to match the FMU.

The cover's map is exported too: clamp force F_pp and bearing force F_to over
the bearing position x_to (0-20 mm: a 0.05 mm grid plus every temperature's
kiss, solid and lift-off positions) at each table temperature (theta_cs =
theta_cm, default cover and facing_wear); torque = n mu R_eq F_pp. Numbers are
written at full precision (``%.17g``), so no two grid values merge. In
Modelica set ``smoothness = LinearSegments`` and ``extrapolation =
HoldLastPoint`` (the default LastTwoPoints extrapolates past the table and
does not reproduce the model's clamping); in Simulink use linear
interpolation with "Clip" extrapolation.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..model import ClutchParameters, SpringTable, outputs
from ..model.cover import CoverMap
from .tables import read_tables

UNITS_NOTE = "u_m [m] compression from the kiss point; theta_degC [degC]; force_N [N] whole spring; delta_kiss_m [m]"


def grid(table_dir: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(u_m, theta_degC, force_N[u, theta], delta_kiss_m) on the common grid."""
    tables = read_tables(table_dir)
    model = SpringTable(tables.theta_degC, tables.u_m, tables.force_N, tables.delta_kiss_m)
    u = np.unique(np.concatenate(tables.u_m))
    force = np.array([[c(x) for c in model.curves] for x in u])
    return u, np.asarray(tables.theta_degC, float), force, np.asarray(tables.delta_kiss_m, float)


def cover_grid(table_dir: Path, p: ClutchParameters | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(x_to_m, theta_degC, clamp_force_N[x, theta], bearing_force_N[x, theta]) of the cover's map."""
    p = p or ClutchParameters()
    table = SpringTable.from_dir(table_dir)
    theta = np.asarray(table.theta_degC, float)
    g = CoverMap(p.cover, p.lever_ratio)
    marks = []
    for t in theta:
        fr = g.prepare(t + 273.15, t + 273.15, p.facing_wear, table, p.x_kiss_ref)
        marks += [fr.x_kiss, fr.x_solid, fr.x_lift]
    x = np.unique(np.concatenate([np.linspace(0.0, 0.02, 401), [m for m in marks if 0.0 <= m <= 0.02]]))
    out = [[outputs(float(v), t + 273.15, table, p, t + 273.15) for t in theta] for v in x]
    return (x, theta, np.array([[o.clamp_force for o in row] for row in out]),
            np.array([[o.bearing_force for o in row] for row in out]))


def export_mat(table_dir: Path, path: Path) -> Path:
    """MATLAB file for Simulink's 2-D Lookup Table (breakpoints u_m, theta_degC)."""
    from scipy.io import savemat

    u, theta, force, delta = grid(table_dir)
    x, _, clamp, bearing = cover_grid(table_dir)
    savemat(path, {
        "u_m": u, "theta_degC": theta, "force_N": force, "delta_kiss_m": delta,
        "x_to_m": x, "clamp_force_N": clamp, "bearing_force_N": bearing,
        "units": UNITS_NOTE + "; x_to_m [m] bearing position, 0 = open; clamp_force_N, bearing_force_N [N]",
        "usage": "2-D Lookup Table: Table data force_N, Breakpoints 1 u_m, Breakpoints 2 theta_degC; "
                 "1-D Lookup Table: delta_kiss_m over theta_degC; 2-D Lookup Tables clamp_force_N and "
                 "bearing_force_N over x_to_m, theta_degC (linear, Clip); torque = n_surfaces mu R_eq clamp_force_N",
    }, do_compression=True, oned_as="column")
    return Path(path)


def export_modelica(table_dir: Path, path: Path) -> Path:
    """Modelica text table file (``#1`` format) for CombiTable2Ds and CombiTable1Ds.

    ``force_N``: first row the temperatures (degC), first column u (m), the
    rest force (N); the top-left entry is unused. ``delta_kiss_m``: columns
    theta (degC), delta_kiss (m).
    """
    u, theta, force, delta = grid(table_dir)
    x, _, clamp, bearing = cover_grid(table_dir)
    lines = ["#1", f"# cushion_clutch table export. {UNITS_NOTE}",
             "# Use smoothness = LinearSegments and extrapolation = HoldLastPoint (clamping, as the model).",
             "# CombiTable2Ds(tableName=\"force_N\"): u1 = u_m [m], u2 = theta_degC [degC], y = force [N]",
             *_matrix("force_N", u, theta, force),
             "# CombiTable1Ds(tableName=\"delta_kiss_m\"): u = theta_degC [degC], y = delta_kiss [m]",
             f"double delta_kiss_m({len(theta)},2)"]
    lines += [f"{t:.17g} {d:.17g}" for t, d in zip(theta, delta)]
    for name, what in (("clamp_force_N", "clamp force F_pp [N]"), ("bearing_force_N", "bearing force F_to [N]")):
        lines.append(f"# CombiTable2Ds(tableName=\"{name}\"): u1 = x_to [m] (0 = open), u2 = theta_degC [degC], "
                     f"y = {what}; default cover, theta_cs = theta_cm")
        lines += _matrix(name, x, theta, clamp if name == "clamp_force_N" else bearing)
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def _matrix(name: str, rows: np.ndarray, cols: np.ndarray, values: np.ndarray) -> list[str]:
    """A ``#1`` matrix: first row the column values, first column the row values, full precision."""
    out = [f"double {name}({len(rows) + 1},{len(cols) + 1})", " ".join(["0"] + [f"{c:.17g}" for c in cols])]
    return out + [" ".join([f"{r:.17g}"] + [f"{v:.17g}" for v in row]) for r, row in zip(rows, values)]


def read_modelica(path: Path) -> dict[str, np.ndarray]:
    """Read the matrices of a ``#1`` Modelica table file (for checks)."""
    out: dict[str, np.ndarray] = {}
    name, rows, n = None, [], 0
    for line in Path(path).read_text().splitlines():
        if not line.strip() or line.startswith("#"):
            continue
        if line.startswith("double "):
            decl = line.split()[1]
            name, shape = decl.split("(")
            n = int(shape.split(",")[0])
            rows = []
            continue
        rows.append([float(v) for v in line.split()])
        if name and len(rows) == n:
            out[name] = np.array(rows)
    return out
