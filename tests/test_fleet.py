"""The fleet study: populations checked on load, samples drawn reproducibly, runs on a real local Dask cluster
equal to serial runs, resumed runs, and failing workers named."""
from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest

from cushion_clutch.errors import ClusterError, ParameterError
from cushion_clutch.launch.fleet.population import draw, load_population, population_path, sample_scenario

SMALL = """
name = "small"
scenario = "default"
launches = 2

[mass_kg]
distribution = "uniform"
low = 1500.0
high = 2200.0

[trailer]
probability = 0.3
drag_area_m2 = 0.9
mass_kg = { distribution = "uniform", low = 500.0, high = 1300.0 }

[grade_percent]
distribution = "triangular"
low = 0.0
mode = 4.0
high = 15.0

[ambient_degC]
distribution = "uniform"
low = 20.0
high = 35.0

[start_above_ambient_K]
distribution = "uniform"
low = 0.0
high = 30.0

[pedal]
distribution = "normal"
mean = 0.6
sd = 0.15
low = 0.3
high = 1.0

[interval_s]
distribution = "fixed"
value = 20.0

[facing_wear_m]
distribution = "uniform"
low = 0.0
high = 0.0002

[correlation]
"mass_kg:pedal" = 0.5
"""


def _small(tmp_path, text=SMALL):
    path = tmp_path / "small.toml"
    path.write_text(text)
    return load_population(path)


def test_the_shipped_default_population_loads_and_draws_inside_its_ranges():
    pop = load_population(population_path("default"))
    assert pop.scenario.name == "default" and pop.launches >= 1 and {s.name for s in pop.springs} == {"nominal", "p95"}
    samples = [draw(pop, 1, i) for i in range(400)]
    for key in ("mass_kg", "grade_percent", "ambient_degC", "pedal", "interval_s", "facing_wear_m"):
        lo, hi = pop.dists[key].bounds
        vals = [getattr(s, key) for s in samples]
        assert lo <= min(vals) and max(vals) <= hi, key
    assert 0.03 < np.mean([s.trailer for s in samples]) < 0.2          # probability 0.1
    assert 0.04 < np.mean([s.spring == "p95" for s in samples]) < 0.18  # weight 0.1
    assert all(s.start_degC >= s.ambient_degC for s in samples)          # the start temperature follows ambient
    rho = np.corrcoef(np.argsort(np.argsort([s.mass_kg for s in samples])),
                      np.argsort(np.argsort([s.pedal for s in samples])))[0, 1]
    assert 0.15 < rho < 0.45                                             # the stated rank correlation 0.3


def test_a_sample_is_its_own_random_stream(tmp_path):
    pop = _small(tmp_path)
    assert draw(pop, 3, 7) == draw(pop, 3, 7)
    assert draw(pop, 3, 7) != draw(pop, 3, 8) and draw(pop, 3, 7) != draw(pop, 4, 7)
    s = draw(pop, 3, 7)
    sc = sample_scenario(pop, s)
    assert sc.vehicle.mass_kg == s.mass_kg + s.trailer_mass_kg and sc.vehicle.slope_percent == s.grade_percent
    assert sc.facing.initial_degC == s.start_degC and sc.driver.hard_pedal == s.pedal
    assert sc.run.launches == 2 and sc.run.period_s == 20.0 and sc.clutch.facing_wear_m == s.facing_wear_m
    assert sc.tcu_sensors.seed == s.tcu_seed and sc.sensors.seed == s.sensor_seed


@pytest.mark.parametrize("edit, expect", [
    ('\nlaunchez = 3\n', "launchez: unknown key"),
    ('\n[ambient_degC]\ndistribution = "uniform"\nlow = -80.0\nhigh = 0.0\n', "ambient_degC.low = -80.0: out of range"),
    ('\n[grade_percent]\ndistribution = "beta"\n', "grade_percent.distribution = 'beta': allowed fixed, uniform"),
    ('\n[pedal]\ndistribution = "uniform"\nlow = 0.9\nhigh = 0.4\n', "pedal: need low <= high"),
    ('\n[trailer]\nprobability = 1.5\n', "trailer.probability = 1.5: out of range"),
    ('\n[spring]\nsets = [{ name = "x", plant_tables = "nowhere" }]\n', "spring.sets[0].plant_tables = 'nowhere'"),
    ('\n[correlation]\n"mass_kg:wheels" = 0.2\n', "correlation.'mass_kg:wheels'"),
])
def test_bad_populations_name_the_key_and_range(tmp_path, edit, expect):
    base = 'scenario = "default"\n[mass_kg]\ndistribution = "uniform"\nlow = 1500.0\nhigh = 2000.0\n' \
           '[pedal]\ndistribution = "uniform"\nlow = 0.4\nhigh = 0.9\n'
    if edit.lstrip().startswith("[pedal]"):
        base = base.split("[pedal]")[0]
    with pytest.raises(ParameterError) as exc:
        _small(tmp_path, base + edit)
    assert expect in str(exc.value), str(exc.value)


def test_a_correlation_matrix_must_be_positive_definite(tmp_path):
    text = ('[mass_kg]\ndistribution = "uniform"\nlow = 1500.0\nhigh = 2000.0\n[pedal]\ndistribution = "uniform"\n'
            'low = 0.4\nhigh = 0.9\n[grade_percent]\ndistribution = "uniform"\nlow = 0.0\nhigh = 9.0\n'
            '[correlation]\n"mass_kg:pedal" = 0.9\n"mass_kg:grade_percent" = 0.9\n"pedal:grade_percent" = -0.9\n')
    with pytest.raises(ParameterError, match="not positive definite"):
        _small(tmp_path, text)


def _rows_equal(a: list[dict], b: list[dict]) -> None:
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert set(x) == set(y)
        for k in x:
            if isinstance(x[k], float) and math.isnan(x[k]):
                assert isinstance(y[k], float) and math.isnan(y[k]), k
            else:
                assert x[k] == y[k], (k, x[k], y[k])


@pytest.mark.fmu
def test_dask_equals_serial_and_a_rerun_resumes(tmp_path):
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.fleet.run import COLUMNS, RUN_FILE, SUMMARY_FILE, read_samples, run_fleet

    pop = _small(tmp_path)
    tcus = ("naive", "production")
    dask = run_fleet(pop, DEFAULT_TABLES, tmp_path / "dask", 3, tcus, seed=5, jobs=2)
    assert dask.workers == 2 and dask.ran == 3 and dask.launches_run == 3 * 2 * 2
    serial = run_fleet(pop, DEFAULT_TABLES, tmp_path / "serial", 2, tcus, seed=5, serial=True)
    rows = read_samples(tmp_path / "dask" / "fleet_samples.parquet")
    assert [r["sample"] for r in rows] == [0, 0, 1, 1, 2, 2] and list(rows[0]) == list(COLUMNS)
    _rows_equal(rows[:4], read_samples(tmp_path / "serial" / "fleet_samples.parquet"))
    _rows_equal(dask.rows[:4], serial.rows)
    for r in rows:                       # the worst over the sample's launches, the counts consistent
        assert r["launches"] == 2 and 0 <= r["lockups"] <= 2 and r["stranded"] + r["lockups"] <= 2
        assert r["characteristic_error_max_Nm"] >= r["characteristic_error_rms_Nm"]
    summary = (tmp_path / "dask" / SUMMARY_FILE).read_text().splitlines()
    assert summary[0] == "tcu,metric,p50,p95,p99,max"
    line = next(s for s in summary if s.startswith("production,characteristic_error_max_Nm,"))
    p50, p95, p99, mx = map(float, line.split(",")[2:])
    errs = [r["characteristic_error_max_Nm"] for r in rows if r["tcu"] == "production"]
    assert p50 <= p95 <= p99 <= mx and mx == pytest.approx(max(errs), rel=1e-8)       # written with 9 digits
    assert p50 == pytest.approx(np.median(errs), rel=1e-8)

    # resume: one finished sample lost, a serial rerun runs only it and gives the same rows
    (tmp_path / "dask" / "fleet_parts" / "sample_000002.json").unlink()
    again = run_fleet(pop, DEFAULT_TABLES, tmp_path / "dask", 3, tcus, seed=5, serial=True)
    assert again.ran == 1 and again.kept == 2
    _rows_equal(again.rows, dask.rows)
    assert json.loads((tmp_path / "dask" / RUN_FILE).read_text())["kept"] == 2
    # another seed into the same folder is refused, naming what differs
    with pytest.raises(ParameterError, match="other seed"):
        run_fleet(pop, DEFAULT_TABLES, tmp_path / "dask", 3, tcus, seed=6, serial=True)


@pytest.mark.fmu
def test_failing_workers_are_named(tmp_path):
    from test_cluster import Cluster

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fe.cluster import open_cluster
    from cushion_clutch.launch.fleet.run import run_fleet, run_sample
    from cushion_clutch.model import load_table

    pop = _small(tmp_path)
    cluster = Cluster(tmp_path)
    try:
        cluster.worker("nopkg", package=False)      # cannot import cushion_clutch: named at the check
        with pytest.raises(ClusterError) as exc:
            run_fleet(pop, DEFAULT_TABLES, tmp_path / "out", 2, ("naive",), seed=1, scheduler=cluster.address)
        msg = str(exc.value)
        assert "cannot run the tasks" in msg and "cannot import cushion_clutch" in msg
        assert re.search(r"worker tcp://127\.0\.0\.1:\d+", msg), msg
        assert not (tmp_path / "out" / "fleet_samples.parquet").exists()
    finally:
        cluster.close()
    cluster = Cluster(tmp_path)
    try:
        cluster.worker("good")
        with open_cluster(cluster.address, need_ccx=False) as (client, info):
            assert info.ccx_version == "" and len(info.workers) == 1
            fut = client.submit(run_sample, pop, 1, 0, ("naive",), {"nominal": b"not an FMU"},
                                {"nominal": load_table(DEFAULT_TABLES)}, pure=False)
            with pytest.raises(RuntimeError, match=r"sample 0 failed on Dask worker tcp://127\.0\.0\.1:\d+ \(host"):
                fut.result(timeout=120)
    finally:
        cluster.close()


def test_the_cli_refuses_bad_arguments_with_one_message(tmp_path, capsys):
    from cushion_clutch.cli import main
    code = main(["fleet", "--samples", "2", "--tcus", "naive,psychic", "--serial", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and "psychic" in err and "allowed: naive" in err and "Traceback" not in err
    bad = tmp_path / "bad.toml"
    bad.write_text('scenario = "default"\nwheels = 3\n')
    code = main(["fleet", "--population", str(bad), "--samples", "2", "--serial", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and "wheels: unknown key" in err and "Traceback" not in err
