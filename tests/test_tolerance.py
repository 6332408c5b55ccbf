"""Tolerance studies: sampling, the [tolerances] table, and a study on a Dask LocalCluster."""
import json

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError
from cushion_clutch.fe.params import DEFAULT_SPRING, Tolerances, load_params, params_from_dict
from cushion_clutch.fe.cases import case_key
from cushion_clutch.fe.studies.tolerance import apply_deviations, draw, make_samples


def test_default_spring_declares_the_issue_tolerances():
    assert load_params().tolerances.declared() == {"thickness_m": 5e-6, "wave_height_m": 20e-6,
                                                   "youngs_modulus_scale": 0.01}


def test_bad_tolerances_are_named_with_their_range():
    with pytest.raises(ParameterError) as info:
        params_from_dict({"tolerances": {"thickness_m": {"sd": -1e-6}, "wave_height_m": 2e-5,
                                         "youngs_modulus_scale": {"sd": 0.01, "mean": 1.0}, "colour": {}}})
    msg = str(info.value)
    assert "tolerances.thickness_m.sd = -1e-06: out of range, allowed [0, 5e-05]" in msg
    assert "tolerances.wave_height_m = 2e-05: must be a table {sd = <standard deviation>}" in msg
    assert "tolerances.youngs_modulus_scale = {'sd': 0.01, 'mean': 1.0}" in msg
    assert "tolerances.colour: unknown key" in msg
    with pytest.raises(ParameterError, match="no tolerance declared"):
        draw(Tolerances(), 4)
    with pytest.raises(ParameterError, match="--method 'sobol'"):
        draw(load_params().tolerances, 4, "sobol")


def test_latin_hypercube_is_stratified_seeded_and_truncated():
    from scipy.stats import norm
    tol = load_params().tolerances
    n = 50
    a, b = draw(tol, n, "lhs", seed=3), draw(tol, n, "lhs", seed=3)
    assert all(np.array_equal(a[k], b[k]) for k in a)
    assert not np.array_equal(a["thickness_m"], draw(tol, n, "lhs", seed=4)["thickness_m"])
    for key, sd in tol.declared().items():
        # one sample in each of the n equal-probability strata of the truncated normal
        lo, hi = norm.cdf(-3), norm.cdf(3)
        u = (norm.cdf(a[key] / sd) - lo) / (hi - lo)
        assert sorted(np.floor(u * n).astype(int)) == list(range(n))
        assert np.all(np.abs(a[key]) <= 3 * sd * (1 + 1e-12))
    mc = draw(tol, 4000, "mc", seed=1)["wave_height_m"]
    assert np.std(mc) == pytest.approx(20e-6 * 0.9866, rel=0.05)     # sd of a normal truncated at 3 sd


def test_deviations_apply_and_never_enter_the_cache_key():
    base = load_params()
    p = apply_deviations(base, {"thickness_m": 2e-6, "wave_height_m": -10e-6, "youngs_modulus_scale": 0.02})
    assert p.geometry.thickness_m == pytest.approx(base.geometry.thickness_m + 2e-6)
    assert p.geometry.wave_height_m == pytest.approx(base.geometry.wave_height_m - 10e-6)
    assert p.material.youngs_modulus_Pa[list(base.material.temperatures_degC).index(20.0)] == pytest.approx(206e9 * 1.02)
    no_tol = base.replace(tolerances=Tolerances())
    assert case_key(no_tol, 20.0, 1, "x") == case_key(base, 20.0, 1, "x")
    assert case_key(p, 20.0, 1, "x") != case_key(base, 20.0, 1, "x")
    samples = make_samples(base, 3, seed=2)
    assert [s.index for s in samples] == [0, 1, 2, 3] and samples[0].params == base


@pytest.mark.ccx
@pytest.mark.fmu
def test_study_on_a_local_cluster_equals_one_by_one_and_resumes(coarse, tmp_path, capsys):
    """2 drawn samples + nominal at 20 degC on a LocalCluster of 2 single-threaded workers.

    On a 4 mm mesh with 30 increments: the study's machinery (cluster = one by one, the cache, the
    resume, the percentile tables and their FMUs) is under test here, not the mesh."""
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu

    from cushion_clutch.cli import main
    from cushion_clutch.fe.sweep import run_sweep
    from cushion_clutch.model.table_format import read_tables
    from cushion_clutch.fe.studies.tolerance import run_study
    from cushion_clutch.fmu.build import build_fmu

    base = coarse.replace(mesh={"element_size_m": 4e-3}, solver={"compression_increments": 30},
                          sweep={"temperatures_degC": (20.0,)})
    samples = make_samples(base, 2, seed=5)
    study = run_study(samples, (20.0,), cache_dir=tmp_path / "study", workers=2)
    for s, res in zip(samples, study):
        alone = run_sweep(s.params, cache_dir=tmp_path / "alone", jobs=1)[20.0]
        assert not alone.from_cache and not res[20.0].from_cache
        np.testing.assert_allclose(res[20.0].result.force_N, alone.result.force_N, rtol=1e-12)
        np.testing.assert_allclose(res[20.0].result.travel_m, alone.result.travel_m, rtol=1e-12)
    # the samples differ: the study really varied the springs
    assert len({float(r[20.0].result.force_N[-1]) for r in study}) == 3

    # an interrupted study resumes: everything is in the cache now, and the CLI writes the outputs
    spring = tmp_path / "spring.toml"
    spring.write_text(DEFAULT_SPRING.read_text().replace("compression_increments = 60",
                                                         "compression_increments = 30"))
    out = tmp_path / "lookup_tables"
    assert main(["tolerance", "--spring", str(spring), "--samples", "2", "--seed", "5", "--temperatures", "20",
                 "--mesh-size", str(base.mesh.element_size_m), "--out", str(out),
                 "--cache", str(tmp_path / "study"), "--fmu", str(tmp_path / "band.fmu")]) == 0
    captured = capsys.readouterr()
    text = captured.out
    assert "3 FE cases (3 from the cache)" in text
    assert "warning: only 2 samples: P5 and P95" in captured.err
    meta = json.loads((out / "default_tolerance" / "study.json").read_text())
    assert meta["cases_from_cache"] == 3
    rows = (out / "default_tolerance" / "samples.csv").read_text().splitlines()
    assert len(rows) == 4 and rows[0].startswith("sample,thickness_m_deviation")
    for q in ("p05", "p95"):
        tables = read_tables(out / f"default_{q}")
        pick = tables.metadata["tolerance_study"]
        assert pick["sample"] in (1, 2) and pick["percentile"] in (5.0, 95.0)
        assert pick["warnings"] and f"its own x_kiss_ref = {pick['x_kiss_ref_m'] * 1e3:.4f} mm" in text
        fmu = build_fmu(out / f"default_{q}", tmp_path / f"{q}.fmu")
        assert validate_fmu(str(fmu)) == []
        start = {v.name: v.start for v in read_model_description(str(fmu)).modelVariables}
        assert float(start["x_kiss_ref"]) == pytest.approx(pick["x_kiss_ref_m"], abs=1e-15)
    assert (out / "default_tolerance" / "tolerance_bands.png").stat().st_size > 20000
    # one FMU for the band (issue 42): nominal, P5, P95, chosen by the enumeration spring
    assert "spring: 1 = default_nominal, 2 = default_p05, 3 = default_p95" in text
    md = read_model_description(str(tmp_path / "band.fmu"))
    (band,) = md.typeDefinitions
    assert [i.name for i in band.items] == ["default_nominal", "default_p05", "default_p95"]
    assert validate_fmu(str(tmp_path / "band.fmu")) == []


def test_cli_refuses_a_spring_without_tolerances_and_the_package_tables(tmp_path, capsys):
    from cushion_clutch.cli import main
    from cushion_clutch.data import tables_root
    spring = tmp_path / "plain.toml"
    spring.write_text(DEFAULT_SPRING.read_text().split("[tolerances]")[0])
    assert main(["tolerance", "--spring", str(spring), "--samples", "4", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "[tolerances]: no tolerance declared" in err and "Traceback" not in err
    assert main(["tolerance", "--samples", "4", "--out", str(tables_root())]) == 2
    assert "shipped with cushion-clutch" in capsys.readouterr().err
    assert main(["tolerance", "--samples", "4", "--temperatures", "195", "--out", str(tmp_path)]) == 2
    assert "must include material.reference_temperature_degC = 20" in capsys.readouterr().err


def _shifted_tables(tmp_path, x_kiss_ref_m):
    """The default tables as a tolerance P5 set whose own kiss point sits at ``x_kiss_ref_m``."""
    import shutil

    from cushion_clutch.data import DEFAULT_TABLES
    tables = tmp_path / "default_p05"
    shutil.copytree(DEFAULT_TABLES, tables)
    meta = json.loads((tables / "metadata.json").read_text())
    meta["tolerance_study"] = {"percentile": 5.0, "sample": 3, "x_kiss_ref_m": x_kiss_ref_m}
    (tables / "metadata.json").write_text(json.dumps(meta))
    return tables


@pytest.mark.fmu
@pytest.mark.parametrize("backend, version", [("native", 2), ("native", 3), ("python", 2)])
def test_a_percentile_set_builds_an_fmu_with_its_own_kiss_point(tmp_path, capsys, backend, version):
    """build-fmu takes x_kiss_ref from the set's metadata: in the description and in the running FMU."""
    from fmpy import read_model_description, simulate_fmu

    from cushion_clutch.cli import main
    tables = _shifted_tables(tmp_path, 4.22e-3)
    fmu = tmp_path / "p05.fmu"
    assert main(["build-fmu", "--tables", str(tables), "-o", str(fmu), "--backend", backend,
                 "--fmi-version", str(version)]) == 0
    assert "x_kiss_ref = 4.2200 mm (the table set's own kiss point" in capsys.readouterr().out
    md = read_model_description(str(fmu))
    start = {v.name: v.start for v in md.modelVariables}
    assert float(start["x_kiss_ref"]) == pytest.approx(4.22e-3, abs=1e-12)
    # at 20 degC (the tables' reference) the kiss point at the bearing is x_kiss_ref itself
    # a stiff release system (compliance 0): the cover's map is the paper's constant lever 3
    res = simulate_fmu(str(fmu), stop_time=0.01, output_interval=0.01, output=["x_kiss", "u_f"],
                       start_values={"x_to": 5e-3, "theta_cm": 293.15, "release_compliance_m_per_N": 0.0})
    assert res["x_kiss"][-1] == pytest.approx(4.22e-3, abs=1e-9)
    assert res["u_f"][-1] == pytest.approx((5e-3 - 4.22e-3) / 3.0, rel=1e-9)


def test_fewer_than_20_samples_warn_that_p5_p95_are_the_extremes():
    from cushion_clutch.fe.studies.tolerance_report import percentile_warnings
    assert "only 4 samples" in percentile_warnings(4)[0] and percentile_warnings(20) == []
