"""Export a table set for Simulink (MATLAB .mat) and Modelica (CombiTable text), to be used without our docs.

Every table holds the model's own values (:func:`cushion_clutch.model.outputs`, the same code as the FMU)
on a grid; a lookup block that interpolates linearly between breakpoints then differs from the model only
between them, by at most the interpolation error measured on every cell's midpoint when the export is
written, and stated in the files. What the exports hold:

* ``force_N`` (u_m, theta_degC): the cushion spring's force. Its u axis is the union of the table's own
  compressions (so every FE table point is a breakpoint and exact), its theta axis the table temperatures
  plus intermediate ones at most :data:`THETA_STEP_K` apart, because between table temperatures the model
  blends the neighbouring curves on a normalised compression (:mod:`cushion_clutch.model.spring_table`),
  which a lookup block's linear interpolation in theta at fixed u does not reproduce.
* ``delta_kiss_m`` (theta): the cushion spring's own free-height growth, m, + = the spring grows (contact
  comes earlier). ``x_kiss_m`` (theta): the kiss point at the bearing, m, bearing travel from the open
  position towards engagement, so a smaller value = earlier contact; it includes the spring's growth times
  the lever, the facing/pressure-plate/flywheel growth and the release compliance (theta_cs = theta_cm).
* ``clamp_force_N`` and ``bearing_force_N`` (x_to_m, theta_degC): the cover's force balance with the
  default cover and facing wear, theta_cs = theta_cm. Torque = n_surfaces mu R_eq clamp_force.
  Temperatures :data:`COVER_THETA_DEGC`: beyond the spring tables the model holds the cushion's curve at
  the nearest table but goes on with the stack's thermal growth and the diaphragm's modulus drop, and so
  do these tables; outside their range a lookup holds the last column.
* ``clamp_force_3d_N`` (x_to_m, theta_cs_degC, theta_cm_degC), .mat only, for Simulink's n-D Lookup Table
  (Modelica's standard library has no 3-D table): the cover without the theta_cs = theta_cm assumption.
  The error of that assumption (reading the 2-D table at theta_cs or at theta_cm) is measured on this
  grid and stated.

Breakpoints are strictly increasing in float32 (Simulink code generation for a TCU target): points of the
x_to axis closer than :data:`MERGE_M` are merged (the kiss, solid and lift-off marks kept). Numbers are
written at full precision (``%.17g``). In Modelica set ``smoothness = LinearSegments`` and
``extrapolation = HoldLastPoint``; in Simulink use linear interpolation and "Clip".
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..model import KELVIN, ClutchParameters, SpringTable, kiss_point, outputs
from ..model.clutch_model import INPUT_RANGES
from ..model.cover import CoverMap

#: largest step of the force table's temperature axis between table temperatures, K
THETA_STEP_K = 5.0
#: temperature axis of the cover tables and of x_kiss_m, degC (table temperatures are added)
COVER_THETA_DEGC = np.arange(-40.0, 400.0 + 1e-9, 10.0)
#: temperature axes of the 3-D table, degC (theta_cs and theta_cm alike; table temperatures are added)
THETA_3D_DEGC = np.arange(-40.0, 400.0 + 1e-9, 40.0)
#: largest step of the force table's u axis, m (the FE points are added; the curves are steep at the solid end)
U_STEP_M = 5e-6
#: x_to axis: 0-20 mm every 0.05 mm, plus every temperature's kiss, solid and lift-off position, m
X_TO_RANGE_M = (0.0, 0.02)
#: breakpoints closer than this are merged, m (float32 resolves 2e-9 m at 20 mm)
MERGE_M = 1e-7
#: realistic facing-to-cushion temperature differences for the cost of theta_cs = theta_cm, K
THETA_DIFFERENCES_K = (25.0, 50.0, 100.0)

UNITS_NOTE = ("u_m [m] cushion compression from its kiss point; theta_degC [degC]; force_N [N] whole spring; "
              "delta_kiss_m [m] the spring's free-height growth (+ = grows, contact earlier); x_kiss_m [m] kiss "
              "point at the bearing (bearing travel from open towards engagement, smaller = earlier contact, "
              "the cushion at its kiss force at u_m = 0, torque begins earlier at the first contact); "
              "x_to_m [m] bearing position, 0 = open; clamp_force_N, bearing_force_N [N]")


@dataclass
class Export:
    """Everything the exports hold (SI; temperatures in degC where the name says so)."""

    p: ClutchParameters
    u_m: np.ndarray
    theta_degC: np.ndarray                 #: force table temperatures
    force_N: np.ndarray                    #: [u, theta]
    table_theta_degC: np.ndarray           #: the FE tables' temperatures (a subset of theta_degC)
    delta_kiss_m: np.ndarray               #: at table_theta_degC
    cover_theta_degC: np.ndarray
    x_kiss_m: np.ndarray                   #: at cover_theta_degC
    x_to_m: np.ndarray
    clamp_force_N: np.ndarray              #: [x_to, cover_theta]
    bearing_force_N: np.ndarray            #: [x_to, cover_theta]
    theta_3d_degC: np.ndarray
    clamp_force_3d_N: np.ndarray           #: [x_to, theta_cs, theta_cm]
    errors: dict = field(default_factory=dict)   #: measured interpolation and assumption errors

    @property
    def torque_gain_m(self) -> float:
        """n_surfaces mu R_eq, m (torque N.m = this times the clamp force N)."""
        return self.p.n_surfaces * self.p.mu * self.p.R_eq

    def assumptions(self) -> list[str]:
        """The model values the tables assume, one sentence each."""
        p = self.p
        return [f"torque [N.m] = n_surfaces * mu * R_eq * clamp_force_N with n_surfaces = {p.n_surfaces:g}, "
                f"mu = {p.mu:g}, R_eq = {p.R_eq:g} m (= {self.torque_gain_m:.17g} m)",
                f"lever_ratio = {p.lever_ratio:g} (bearing travel / pressure-plate travel), "
                f"x_kiss_ref = {p.x_kiss_ref:g} m (kiss point at the bearing at the reference temperature "
                f"{p.cover.reference_temperature_K - KELVIN:g} degC), facing_wear = {p.facing_wear:g} m, default cover",
                "cover tables: theta_cs = theta_cm (cushion spring and facings at one temperature)"]


def _temperature_axis(nodes: np.ndarray, step: float) -> np.ndarray:
    """The nodes plus evenly spaced points between them, at most ``step`` apart."""
    out = [nodes[0]]
    for a, b in zip(nodes, nodes[1:]):
        n = int(np.ceil((b - a) / step))
        out += list(a + (b - a) * np.arange(1, n + 1) / n)
    return np.array(out)


def _merge(values: np.ndarray, keep: np.ndarray, tol: float) -> np.ndarray:
    """Sorted unique ``values`` without points closer than ``tol`` to a kept neighbour (``keep`` wins)."""
    values = np.unique(np.concatenate([values, keep]))
    keep = set(keep.tolist())
    out: list[float] = []
    for v in values:
        if out and v - out[-1] < tol:
            if v in keep and out[-1] not in keep:
                out[-1] = v
            continue
        out.append(v)
    return np.array(out)


def build(table_dir: Path, p: ClutchParameters | None = None) -> Export:
    """Evaluate the model on every export grid and measure the lookup errors (a few seconds)."""
    p = p or ClutchParameters()
    table = SpringTable.from_dir(table_dir)
    nodes = np.asarray(table.theta_degC, float)
    fe_u = np.unique(np.concatenate([c.x for c in table.curves]))
    u = _merge(np.arange(fe_u[0], fe_u[-1], U_STEP_M), fe_u, 1e-9)
    theta = _temperature_axis(nodes, THETA_STEP_K)
    force = np.array([[table.force(float(x), float(t)) for t in theta] for x in u])

    cover_theta = np.unique(np.concatenate([COVER_THETA_DEGC, nodes]))
    g = CoverMap(p.cover, p.lever_ratio)
    marks = []
    for t in cover_theta:
        fr = g.prepare(t + KELVIN, t + KELVIN, p.facing_wear, table, p.x_kiss_ref)
        marks += [m for m in (fr.x_kiss, fr.x_solid, fr.x_lift) if X_TO_RANGE_M[0] <= m <= X_TO_RANGE_M[1]]
    x = _merge(np.linspace(*X_TO_RANGE_M, 401), np.array(marks), MERGE_M)

    def cover(xv, t_cs, t_cm):
        o = outputs(float(xv), t_cs + KELVIN, table, p, t_cm + KELVIN)
        return o.clamp_force, o.bearing_force

    cf = np.array([[cover(xv, t, t) for t in cover_theta] for xv in x])
    t3 = np.unique(np.concatenate([THETA_3D_DEGC, nodes]))
    c3 = np.array([[[cover(xv, tcs, tcm)[0] for tcm in t3] for tcs in t3] for xv in x])
    ex = Export(p, u, theta, force, nodes, np.asarray(table.delta_kiss_m, float), cover_theta,
                np.array([kiss_point(t + KELVIN, table, p) for t in cover_theta]), x, cf[..., 0], cf[..., 1],
                t3, c3)
    ex.errors = _errors(ex, table)
    return ex


def _bilinear_midpoints(v: np.ndarray) -> np.ndarray:
    """A linear lookup's value at every cell's midpoint of the 2-D array ``v`` (the mean of the four corners)."""
    return 0.25 * (v[1:, 1:] + v[:-1, 1:] + v[1:, :-1] + v[:-1, :-1])


def _errors(ex: Export, table: SpringTable) -> dict:
    """Largest differences between a linear lookup and the model, measured on every cell's midpoint (N, N.m)."""
    p = ex.p

    def clamp(x, t_cs, t_cm):
        return outputs(float(x), t_cs + KELVIN, table, p, t_cm + KELVIN).clamp_force

    um, tm = 0.5 * (ex.u_m[1:] + ex.u_m[:-1]), 0.5 * (ex.theta_degC[1:] + ex.theta_degC[:-1])
    model = np.array([[table.force(float(x), float(t)) for t in tm] for x in um])
    xm, cm = 0.5 * (ex.x_to_m[1:] + ex.x_to_m[:-1]), 0.5 * (ex.cover_theta_degC[1:] + ex.cover_theta_degC[:-1])
    clamp_err = np.max(np.abs(_bilinear_midpoints(ex.clamp_force_N) - np.array([[clamp(x, t, t) for t in cm]
                                                                                  for x in xm])))
    # the 3-D table: trilinear lookup at the midpoints of 3000 random cells (seeded)
    rng = np.random.default_rng(0)
    t3, c3 = ex.theta_3d_degC, ex.clamp_force_3d_N
    cells = np.column_stack([rng.integers(0, len(a) - 1, 3000) for a in (ex.x_to_m, t3, t3)])
    err3 = max(abs(c3[i:i + 2, j:j + 2, k:k + 2].mean()
                   - clamp(0.5 * (ex.x_to_m[i] + ex.x_to_m[i + 1]), 0.5 * (t3[j] + t3[j + 1]), 0.5 * (t3[k] + t3[k + 1])))
               for i, j, k in cells)
    # theta_cs != theta_cm: the model against the 2-D table's assumption, read at theta_cs or at theta_cm
    xs, ts = np.linspace(*X_TO_RANGE_M, 101), np.arange(-40.0, 400.0 + 1e-9, 20.0)
    lo_K, hi_K = INPUT_RANGES["theta_cm"][:2]
    cost = {}
    for d in THETA_DIFFERENCES_K:
        worst_cs = worst_cm = 0.0
        for t in ts:
            for t_cm in [v for v in (t - d, t + d) if lo_K <= v + KELVIN <= hi_K]:    # what the model accepts
                for x in xs:
                    f = clamp(x, t, t_cm)
                    worst_cs = max(worst_cs, abs(f - clamp(x, t, t)))
                    worst_cm = max(worst_cm, abs(f - clamp(x, t_cm, t_cm)))
        cost[d] = (worst_cs * ex.torque_gain_m, worst_cm * ex.torque_gain_m)
    return {"force_N": float(np.max(np.abs(_bilinear_midpoints(ex.force_N) - model))),
            "clamp_force_N": float(clamp_err), "torque_Nm": float(clamp_err) * ex.torque_gain_m,
            "clamp_force_3d_N": float(err3), "assumption_torque_Nm": cost}


def _notes(ex: Export) -> list[str]:
    e = ex.errors
    lines = [*ex.assumptions(),
             f"linear interpolation between breakpoints differs from the model by at most {e['force_N']:.3g} N "
             f"(force_N) and at most {e['clamp_force_N']:.3g} N (clamp_force_N; {e['torque_Nm']:.3g} N.m of torque), measured on "
             "every cell's midpoint; at the breakpoints the tables are the model; the 3-D table (.mat) by at most "
             f"{e['clamp_force_3d_N']:.3g} N (3000 random cells)",
             f"force_N: at theta outside {ex.table_theta_degC[0]:g}-{ex.table_theta_degC[-1]:g} degC the model holds "
             "the nearest table's curve (HoldLastPoint / Clip is exact there)",
             f"clamp_force_N, bearing_force_N, x_kiss_m: theta {ex.cover_theta_degC[0]:g}-"
             f"{ex.cover_theta_degC[-1]:g} degC; the model goes on with the stack's growth and the diaphragm's "
             "modulus drop beyond any range, a lookup holds the last column: outside this range it is not the model"]
    for d, (cs, cm) in e["assumption_torque_Nm"].items():
        lines.append(f"cost of theta_cs = theta_cm when |theta_cm - theta_cs| = {d:g} K: torque error up to "
                     f"{cs:.3g} N.m reading the 2-D table at theta_cs, {cm:.3g} N.m at theta_cm "
                     "(theta_cs -40-400 degC, x_to 0-20 mm; clamp_force_3d_N in the .mat has no such error)")
    return lines


def _as_export(src, p: ClutchParameters | None) -> Export:
    return src if isinstance(src, Export) else build(Path(src), p)


def export_mat(src, path: Path, p: ClutchParameters | None = None) -> Path:
    """MATLAB file for Simulink's lookup blocks; ``src`` is a table folder or a built :class:`Export`."""
    from scipy.io import savemat

    ex = _as_export(src, p)
    pp = ex.p
    savemat(path, {
        "u_m": ex.u_m, "theta_degC": ex.theta_degC, "force_N": ex.force_N,
        "table_theta_degC": ex.table_theta_degC, "delta_kiss_m": ex.delta_kiss_m,
        "cover_theta_degC": ex.cover_theta_degC, "x_kiss_m": ex.x_kiss_m,
        "x_to_m": ex.x_to_m, "clamp_force_N": ex.clamp_force_N, "bearing_force_N": ex.bearing_force_N,
        "theta_3d_degC": ex.theta_3d_degC, "clamp_force_3d_N": ex.clamp_force_3d_N,
        "n_surfaces": pp.n_surfaces, "mu": pp.mu, "R_eq_m": pp.R_eq, "lever_ratio": pp.lever_ratio,
        "x_kiss_ref_m": pp.x_kiss_ref, "facing_wear_m": pp.facing_wear,
        "reference_temperature_degC": pp.cover.reference_temperature_K - KELVIN,
        "units": UNITS_NOTE,
        "usage": "2-D Lookup Table: force_N over u_m, theta_degC; 1-D Lookup Tables: delta_kiss_m over "
                 "table_theta_degC, x_kiss_m over cover_theta_degC; 2-D Lookup Tables clamp_force_N and "
                 "bearing_force_N over x_to_m, cover_theta_degC; n-D Lookup Table clamp_force_3d_N over x_to_m, "
                 "theta_3d_degC (theta_cs), theta_3d_degC (theta_cm). Interpolation linear, extrapolation Clip. "
                 + " ".join(s.rstrip(".") + "." for s in _notes(ex)),
    }, do_compression=True, oned_as="column")
    return Path(path)


def export_modelica(src, path: Path, p: ClutchParameters | None = None) -> Path:
    """Modelica text table file (``#1`` format) for CombiTable2Ds and CombiTable1Ds.

    Matrices: first row the column breakpoints, first column the row breakpoints (top-left unused).
    ``src`` is a table folder or a built :class:`Export`.
    """
    ex = _as_export(src, p)
    lines = ["#1", "# cushion_clutch table export, the model's own values on these grids.",
             *(f"# {s}" for s in UNITS_NOTE.split("; ")),
             "# Use smoothness = Modelica.Blocks.Types.Smoothness.LinearSegments and",
             "# extrapolation = Modelica.Blocks.Types.Extrapolation.HoldLastPoint (see the ranges below).",
             *(f"# {s}" for s in _notes(ex)),
             "# CombiTable2Ds(tableName=\"force_N\"): u1 = u_m [m], u2 = theta_degC [degC], y = force [N]",
             *_matrix("force_N", ex.u_m, ex.theta_degC, ex.force_N),
             "# CombiTable1Ds(tableName=\"delta_kiss_m\"): u = theta_degC [degC], y = delta_kiss [m] "
             "(+ = the spring grows)",
             *_columns("delta_kiss_m", ex.table_theta_degC, ex.delta_kiss_m),
             "# CombiTable1Ds(tableName=\"x_kiss_m\"): u = theta_degC [degC], y = kiss point at the bearing [m] "
             "(travel from open; smaller = earlier contact), theta_cs = theta_cm",
             *_columns("x_kiss_m", ex.cover_theta_degC, ex.x_kiss_m)]
    for name, what, values in (("clamp_force_N", "clamp force F_pp [N]", ex.clamp_force_N),
                               ("bearing_force_N", "bearing force F_to [N]", ex.bearing_force_N)):
        lines.append(f"# CombiTable2Ds(tableName=\"{name}\"): u1 = x_to [m] (0 = open), u2 = theta_degC [degC], "
                     f"y = {what}; theta_cs = theta_cm")
        lines += _matrix(name, ex.x_to_m, ex.cover_theta_degC, values)
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def _columns(name: str, x: np.ndarray, y: np.ndarray) -> list[str]:
    return [f"double {name}({len(x)},2)", *(f"{a:.17g} {b:.17g}" for a, b in zip(x, y))]


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
