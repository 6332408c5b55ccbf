"""mu(theta_cm, omega_slip) from friction.csv: the Python model, the native and the pythonfmu FMU."""
import shutil

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.model import ClutchParameters, load_table, outputs, thermal_step
from cushion_clutch.model.friction import FrictionTable

FADE = """theta_degC,omega_slip_rad_s,mu
300,0,0.20
20,0,0.30
20,100,0.28
300,100,0.18
150,0,0.29
150,100,0.27
"""


@pytest.fixture(scope="module")
def fade_tables(tmp_path_factory):
    d = tmp_path_factory.mktemp("fade")
    for f in ("force_deflection.csv", "kiss_point.csv", "metadata.json"):
        shutil.copy(DEFAULT_TABLES / f, d / f)
    (d / "friction.csv").write_text(FADE)
    return d


def test_bilinear_clamped_and_any_row_order(tmp_path):
    f = FrictionTable.from_csv(_write(tmp_path, FADE))
    assert f(20.0, 0.0) == 0.30 and f(300.0, 100.0) == 0.18
    assert f(85.0, 50.0) == pytest.approx(0.5 * (0.5 * (0.30 + 0.28) + 0.5 * (0.29 + 0.27)))
    assert f(-50.0, -500.0) == f(20.0, 100.0) == 0.28          # clamped, |omega|
    assert f(1000.0, 0.0) == 0.20


@pytest.mark.parametrize("text, match", [
    ("theta_degC,omega_slip_rad_s,mu\n20,0,0.3\n20,10,0.3\n80,0,0.3\n", "full grid"),
    ("theta_degC,omega_slip_rad_s,mu\n20,0,0.3\n20,0,0.3\n", "full grid"),
    ("theta_degC,omega_slip_rad_s,mu\n20,0,2.5\n", r"\[0, 2\]"),
    ("theta_degC,omega_slip_rad_s,mu\n20,-1,0.3\n", ">= 0"),
    ("theta,omega,mu\n20,0,0.3\n", "header"),
])
def test_malformed_friction_tables_name_the_file(tmp_path, text, match):
    with pytest.raises(ValueError, match=match) as err:
        FrictionTable.from_csv(_write(tmp_path, text))
    assert "friction.csv" in str(err.value)


def test_model_uses_the_table_and_needs_theta_cm(fade_tables):
    table, p = load_table(fade_tables), ClutchParameters()
    hot = outputs(0.006, 450.0, table, p, theta_cm=573.15, omega_slip=0.0)
    cold = outputs(0.006, 450.0, table, p, theta_cm=293.15, omega_slip=0.0)
    assert hot.force == cold.force
    assert hot.torque / cold.torque == pytest.approx(0.20 / 0.30, rel=1e-12)
    with pytest.raises(ValueError, match="theta_cm"):
        outputs(0.006, 450.0, table, p)
    plain = load_table()
    assert plain.friction is None
    assert outputs(0.006, 450.0, plain, p, theta_cm=573.15, omega_slip=50.0).torque == \
        outputs(0.006, 450.0, plain, p).torque


@pytest.mark.fmu
def test_both_backends_match_the_model_with_a_friction_table(fade_tables, tmp_path):
    table, p = load_table(fade_tables), ClutchParameters()
    rng = np.random.default_rng(3)
    n = 400
    x_to, th, om = rng.uniform(0.002, 0.009, n), rng.uniform(250.0, 700.0, n), rng.uniform(-150, 150, n)
    for backend in ("native", "python"):
        fmu = build_fmu(fade_tables, tmp_path / f"{backend}.fmu", backend=backend)
        md = read_model_description(str(fmu))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        unzip = extract(str(fmu))
        s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=backend)
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        theta = p.theta_cs_start
        for k in range(n):
            s.setReal([vr["x_to"], vr["theta_cm"], vr["omega_slip"]], [x_to[k], th[k], om[k]])
            s.doStep(k * 0.1, 0.1)
            theta = thermal_step(theta, th[k], 0.1, p)
            ref = outputs(x_to[k], theta, table, p, theta_cm=th[k], omega_slip=om[k]).torque
            assert s.getReal([vr["torque"]])[0] == pytest.approx(ref, rel=1e-9, abs=1e-12), (backend, k)
        s.terminate()
        s.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)


def _write(tmp_path, text):
    path = tmp_path / "friction.csv"
    path.write_text(text)
    return path
