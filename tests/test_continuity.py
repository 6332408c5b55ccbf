"""Torque, clamp force and bearing force are continuous in temperature (issue 30) and in the temperature
parameters (issue 31): scans of the Python model and of the native FMU (FMI 2 and 3, CS and ME) across every
table temperature, not only at the table nodes.

The bound of a crossing (theta -/+ 1e-4 K) comes from the model's own temperature slope: the torque moves
by less than 1 N.m/K anywhere (stack growth and the modulus drop), so 2e-4 K may move it by 2e-4 N.m. The
former step (the max/min of the active curves' full compressions) was 11.6-27.7 N.m.
"""
from __future__ import annotations

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model, FMU2Slave
from fmpy.fmi3 import FMU3Model, FMU3Slave

from cushion_clutch.model import KELVIN, ClutchParameters, CoverParameters, load_table, outputs
from native_builds import native_fmus

X_GRID = np.round(np.arange(0.0, 12.0e-3 + 1e-9, 0.05e-3), 12)      # the grid: 0-12 mm, 0.05 mm
DELTA_K = 1e-4
#: a jump bound per crossing: torque 1e-3 N.m, forces 0.02 N (each > 4x the slope-given change, << the old steps)
BOUND = {"torque": 1e-3, "clamp_force": 0.02, "bearing_force": 0.02}
NAMES = tuple(BOUND)


@pytest.fixture(scope="module")
def table():
    return load_table()


def _model_scan(table, p, theta_K, x=X_GRID):
    rows = [outputs(float(xk), theta_K, table, p, theta_K) for xk in x]
    return {n: np.array([getattr(o, n) for o in rows]) for n in NAMES}


def test_python_model_has_no_jump_at_any_table_temperature(table):
    p = ClutchParameters()
    for t in table.theta_degC:
        lo, hi = (_model_scan(table, p, t + KELVIN + s * DELTA_K) for s in (-1, 1))
        for n in NAMES:
            assert np.max(np.abs(hi[n] - lo[n])) <= BOUND[n], (t, n)


def test_python_model_is_continuous_over_the_whole_temperature_range(table):
    """Every 0.5 K from -50 to 370 degC (the tables' -40-350 degC and beyond them): no change larger than a steep
    but smooth slope allows (the old steps were 11.6-27.7 N.m at single temperatures)."""
    p = ClutchParameters()
    assert table.theta_degC[0] == -40.0 and table.theta_degC[-1] == 350.0
    thetas = np.arange(-50.0, 370.0, 0.5) + KELVIN
    x = X_GRID[::4]
    torque = np.array([_model_scan(table, p, th, x)["torque"] for th in thetas])
    step = np.max(np.abs(np.diff(torque, axis=0)))
    assert step <= 0.5, step                    # N.m per 0.5 K: < 1 N.m/K everywhere
    median = np.median(np.abs(np.diff(torque, axis=0)))
    assert median < 0.05


def test_reference_temperature_parameter_is_continuous(table):
    """reference_temperature_K on a table temperature (the default 293.15 K = 20 degC) -/+ 1e-4 K: the reference
    full compression no longer switches curves (issue 31: 208.868 -> 209.652 N.m for one ulp)."""
    for t in (20.0, 80.0, 195.0):
        ps = [ClutchParameters(cover=CoverParameters(reference_temperature_K=t + KELVIN + s * DELTA_K))
              for s in (-1, 1)]
        for theta in (20.0, 137.5, 260.0):
            lo, hi = (_model_scan(table, p, theta + KELVIN) for p in ps)
            for n in NAMES:
                assert np.max(np.abs(hi[n] - lo[n])) <= BOUND[n], (t, theta, n)


def test_one_ulp_of_the_reference_temperature_changes_nothing_visible(table):
    base = ClutchParameters()
    ulp = ClutchParameters(cover=CoverParameters(reference_temperature_K=np.nextafter(293.15, 1e3)))
    a, b = (outputs(0.010, 293.15, table, p) for p in (base, ulp))
    assert abs(a.torque - b.torque) < 1e-9


# ------------------------------------------------------------------------------------ the native FMU
def _fmu_torques(version: int, kind: str, theta_K: float, unzip: str, md) -> dict[str, np.ndarray]:
    """Outputs over X_GRID of one native FMU instance initialised with theta_cs_start = theta_cm = theta_K."""
    vr = {v.name: v.valueReference for v in md.modelVariables}
    cls = {(2, "cs"): FMU2Slave, (2, "me"): FMU2Model, (3, "cs"): FMU3Slave, (3, "me"): FMU3Model}[version, kind]
    f = cls(guid=md.guid, unzipDirectory=unzip, modelIdentifier="CushionClutch", instanceName=f"scan{version}{kind}")
    f.instantiate(loggingOn=False)
    put = f.setReal if version == 2 else f.setFloat64
    get = f.getReal if version == 2 else f.getFloat64
    put([vr["theta_cs_start"], vr["theta_cm"]], [theta_K, theta_K])
    if version == 2:
        f.setupExperiment(startTime=0.0)
        f.enterInitializationMode()
    else:
        f.enterInitializationMode(startTime=0.0)
    f.exitInitializationMode()
    out = {n: np.empty(len(X_GRID)) for n in NAMES}
    refs = [vr[n] for n in NAMES]
    for k, x in enumerate(X_GRID):
        put([vr["x_to"]], [float(x)])
        for n, v in zip(NAMES, get(refs)):
            out[n][k] = v
    assert get([vr["theta_cs"]])[0] == theta_K
    f.terminate()
    f.freeInstance()
    return out


@pytest.mark.fmu
@pytest.mark.parametrize("version", [2, 3])
def test_native_fmu_has_no_jump_at_any_table_temperature(version, table):
    """The issue's bar: theta_cs_start = theta_cm = theta -/+ 1e-4 K at each table temperature, x_to 0-12 mm
    every 0.05 mm; CS and ME instances; and the FMU equals the Python model there."""
    fmu = native_fmus()[version]
    md, unzip = read_model_description(str(fmu)), extract(str(fmu))
    p = ClutchParameters()
    for t in table.theta_degC:
        scans = {}
        for s in (-1, 1):
            th = t + KELVIN + s * DELTA_K
            cs = _fmu_torques(version, "cs", th, unzip, md)
            me = _fmu_torques(version, "me", th, unzip, md)
            py = _model_scan(table, p, th)
            for n in NAMES:
                assert np.array_equal(cs[n], me[n]), (t, n)
                assert cs[n] == pytest.approx(py[n], rel=1e-12, abs=1e-9), (t, n)
            scans[s] = cs
        for n in NAMES:
            assert np.max(np.abs(scans[1][n] - scans[-1][n])) <= BOUND[n], (version, t, n)
