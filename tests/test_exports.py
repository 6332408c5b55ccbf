"""The Simulink (.mat) and Modelica (CombiTable text) exports, read back as those tools read them and checked
against the model: exact at the breakpoints, within the stated error between them, float32-safe axes, the
kiss point at the bearing, and the assumptions written into the files (issue 30)."""
from __future__ import annotations

import re

import numpy as np
import pytest
from fmpy import simulate_fmu
from scipy.interpolate import RegularGridInterpolator
from scipy.io import loadmat

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu.exports import build, export_mat, export_modelica, read_modelica
from cushion_clutch.model.table_format import read_tables
from cushion_clutch.model import KELVIN, ClutchParameters, load_table, outputs
from native_builds import native_fmus


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    d = tmp_path_factory.mktemp("export")
    ex = build(DEFAULT_TABLES)
    mat = loadmat(export_mat(ex, d / "t.mat"))
    text_path = export_modelica(ex, d / "t.txt")
    return ex, mat, read_modelica(text_path), text_path.read_text()


def _axes(mo):
    """Every breakpoint axis of the text file: (name, values)."""
    out = []
    for name, m in mo.items():
        if m.shape[1] == 2:
            out.append((name, m[:, 0]))
        else:
            out += [(name + " rows", m[1:, 0]), (name + " columns", m[0, 1:])]
    return out


def test_every_axis_is_strictly_increasing_in_float32(exported):
    _, mat, mo, _ = exported
    axes = _axes(mo) + [(k, mat[k].ravel()) for k in ("u_m", "theta_degC", "table_theta_degC", "cover_theta_degC",
                                                     "x_to_m", "theta_3d_degC")]
    for name, v in axes:
        assert np.all(np.diff(v.astype(np.float32)) > 0), name
    assert np.array_equal(mo["clamp_force_N"][1:, 0], mat["x_to_m"].ravel())     # %.17g round-trips exactly


def test_breakpoints_are_the_model_and_the_fe_points_exact(exported):
    ex, mat, mo, _ = exported
    tables = read_tables(DEFAULT_TABLES)
    u_mo, th_mo = mo["force_N"][1:, 0], mo["force_N"][0, 1:]
    for t, u, f in zip(tables.theta_degC, tables.u_m, tables.force_N):
        j = int(np.flatnonzero(th_mo == t)[0])
        i = np.searchsorted(u_mo, u)
        assert np.array_equal(u_mo[i], u)
        assert mo["force_N"][1 + i, 1 + j] == pytest.approx(f, rel=1e-12, abs=1e-12)
    assert mo["delta_kiss_m"][:, 1] == pytest.approx(tables.delta_kiss_m, rel=1e-12)
    table, p = load_table(), ClutchParameters()
    x, th = mo["clamp_force_N"][1:, 0], mo["clamp_force_N"][0, 1:]
    for k in range(0, len(x), 23):
        for j in range(0, len(th), 3):
            o = outputs(float(x[k]), th[j] + KELVIN, table, p, th[j] + KELVIN)
            assert mo["clamp_force_N"][1 + k, 1 + j] == o.clamp_force
            assert mo["bearing_force_N"][1 + k, 1 + j] == o.bearing_force
    assert np.all(np.diff(mat["clamp_force_N"], axis=0) >= 0)      # monotone in x_to at every temperature


def _lookup(mo, name):
    m = mo[name]
    return RegularGridInterpolator((m[1:, 0], m[0, 1:]), m[1:, 1:], method="linear")


def test_between_breakpoints_within_the_stated_error(exported):
    """Random points read as a linear lookup block reads them: within the error the file states."""
    ex, mat, mo, text = exported
    stated = {name: float(v) for v, name in re.findall(r"at most ([0-9.e+-]+) N \((force_N|clamp_force_N)[);]", text)}
    assert set(stated) == {"force_N", "clamp_force_N"}
    table, p = load_table(), ClutchParameters()
    rng = np.random.default_rng(3)
    fl = _lookup(mo, "force_N")
    for u, t in zip(rng.uniform(ex.u_m[0], ex.u_m[-1], 3000), rng.uniform(20.0, 300.0, 3000)):
        assert abs(fl([u, t])[0] - table.force(u, t)) <= stated["force_N"], (u, t)
    cl = _lookup(mo, "clamp_force_N")
    for x, t in zip(rng.uniform(0.0, 0.02, 1500), rng.uniform(-40.0, 400.0, 1500)):
        o = outputs(x, t + KELVIN, table, p, t + KELVIN)
        assert abs(cl([x, t])[0] - o.clamp_force) <= stated["clamp_force_N"], (x, t)


def test_kiss_point_at_the_bearing_matches_the_fmu(exported):
    """The bar: a two-column table of the kiss point at the bearing, within 1 um of the native FMU's x_kiss
    at 20, 137.5 and 300 degC (theta_cs_start = theta_cm)."""
    _, _, mo, _ = exported
    kiss = mo["x_kiss_m"]
    for t in (20.0, 137.5, 300.0):
        th = t + KELVIN
        res = simulate_fmu(str(native_fmus()[2]), stop_time=0.01, start_values={"theta_cs_start": th, "theta_cm": th},
                           output=["x_kiss"])
        assert abs(np.interp(t, kiss[:, 0], kiss[:, 1]) - res["x_kiss"][0]) < 1e-6, t
    assert kiss[-1, 1] < kiss[0, 1]          # hot: contact earlier at the bearing


def test_the_files_state_what_the_tables_assume(exported):
    ex, mat, _, text = exported
    for needle in ("n_surfaces = 2", "mu = 0.28", "R_eq = 0.089 m", "lever_ratio = 3", "x_kiss_ref = 0.004 m",
                   "facing_wear = 0 m", "theta_cs = theta_cm", "HoldLastPoint", "LinearSegments",
                   "cost of theta_cs = theta_cm", "not the model"):
        assert needle in text, needle
    assert mat["mu"].item() == 0.28 and mat["R_eq_m"].item() == 0.089 and mat["lever_ratio"].item() == 3.0
    assert "mu = 0.28" in str(mat["usage"])
    # the 3-D table is the model without the theta_cs = theta_cm assumption, at its breakpoints
    table, p = load_table(), ClutchParameters()
    t3, x = mat["theta_3d_degC"].ravel(), mat["x_to_m"].ravel()
    for k, i, j in ((100, 2, 9), (300, 8, 3), (450, 12, 12)):
        o = outputs(float(x[k]), t3[i] + KELVIN, table, p, t3[j] + KELVIN)
        assert mat["clamp_force_3d_N"][k, i, j] == o.clamp_force
