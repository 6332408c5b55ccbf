"""Export a table set for Simulink (MATLAB .mat) and Modelica (CombiTable text).

Lookup blocks need a rectangular grid, while each temperature's FE curve has
its own u points. The grid is the union of all table u points; each
temperature's force is evaluated on it with the model's own interpolation
(the PCHIP curve through that temperature's points, held constant outside
them), so at every original table point the exported value equals the table.
Use the blocks with linear (or PCHIP) interpolation in u and linear in theta,
and clipping at the ends, to match the FMU.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..model import SpringTable
from .tables import read_tables

UNITS_NOTE = "u_m [m] compression from the kiss point; theta_degC [degC]; force_N [N] whole spring; delta_kiss_m [m]"


def grid(table_dir: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(u_m, theta_degC, force_N[u, theta], delta_kiss_m) on the common grid."""
    tables = read_tables(table_dir)
    model = SpringTable(tables.theta_degC, tables.u_m, tables.force_N, tables.delta_kiss_m)
    u = np.unique(np.concatenate(tables.u_m))
    force = np.array([[c(x) for c in model.curves] for x in u])
    return u, np.asarray(tables.theta_degC, float), force, np.asarray(tables.delta_kiss_m, float)


def export_mat(table_dir: Path, path: Path) -> Path:
    """MATLAB file for Simulink's 2-D Lookup Table (breakpoints u_m, theta_degC)."""
    from scipy.io import savemat

    u, theta, force, delta = grid(table_dir)
    savemat(path, {
        "u_m": u, "theta_degC": theta, "force_N": force, "delta_kiss_m": delta,
        "units": UNITS_NOTE,
        "usage": "2-D Lookup Table: Table data force_N, Breakpoints 1 u_m, Breakpoints 2 theta_degC; "
                 "1-D Lookup Table: delta_kiss_m over theta_degC",
    }, do_compression=True, oned_as="column")
    return Path(path)


def export_modelica(table_dir: Path, path: Path) -> Path:
    """Modelica text table file (``#1`` format) for CombiTable2Ds and CombiTable1Ds.

    ``force_N``: first row the temperatures (degC), first column u (m), the
    rest force (N); the top-left entry is unused. ``delta_kiss_m``: columns
    theta (degC), delta_kiss (m).
    """
    u, theta, force, delta = grid(table_dir)
    lines = ["#1", f"# cushion_clutch table export. {UNITS_NOTE}",
             "# CombiTable2Ds(tableName=\"force_N\"): u1 = u_m [m], u2 = theta_degC [degC], y = force [N]",
             f"double force_N({len(u) + 1},{len(theta) + 1})",
             " ".join(["0"] + [f"{t:.12g}" for t in theta])]
    lines += [" ".join([f"{x:.12g}"] + [f"{f:.12g}" for f in row]) for x, row in zip(u, force)]
    lines += ["# CombiTable1Ds(tableName=\"delta_kiss_m\"): u = theta_degC [degC], y = delta_kiss [m]",
              f"double delta_kiss_m({len(theta)},2)"]
    lines += [f"{t:.12g} {d:.12g}" for t, d in zip(theta, delta)]
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


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
