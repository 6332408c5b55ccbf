"""cushion-clutch calibrate: bad inputs, and recovery of known parameters from an FE "measurement"."""
from __future__ import annotations

import numpy as np
import pytest

from cushion_clutch.cli import main
from cushion_clutch.errors import ParameterError
from cushion_clutch.fe.studies.calibrate import calibrate, check_bounds, fit_keys, parse_bounds, with_values
from cushion_clutch.fe.studies.measured import Measured
from cushion_clutch.fe.studies.calibration_report import params_toml
from cushion_clutch.fe.params import load_params, params_from_dict
from cushion_clutch.fe.sweep import run_sweep
from cushion_clutch.fe.tables import curve_from_case

#: the coarsest model that still recovers parameters: one temperature, a 3 mm mesh, 30 increments
RECOVERY = {"mesh": {"element_size_m": 3e-3}, "solver": {"compression_increments": 30},
            "sweep": {"temperatures_degC": (20.0,)}}


def write_csv(path, text):
    path.write_text(text)
    return path


def _fake_calibration(values, bounds, std, corr, residual):
    """A Calibration with the given fit statistics (no FE), to check the warnings."""
    from cushion_clutch.fe.studies.calibrate import Calibration, runs_test
    u = np.linspace(0, 1e-3, len(residual))
    runs, expected, p = runs_test([np.asarray(residual)])
    m = Measured(u, 1000 * u, "pair", 20.0, "bench.csv")
    return Calibration(load_params(), ["geometry.thickness_m", "geometry.wave_height_m"], np.array(values),
                       np.array(values), bounds, np.array(std), np.array(corr), np.zeros(2), [m], [m.force_N],
                       [m.force_N + residual], 1.0, 2.0, 0.1, 0.2, runs, expected, p, 0.0, 3, 0, 1.0, "ok")


def test_warnings_name_bounds_identifiability_and_a_systematic_residual():
    noise = np.random.default_rng(3).standard_normal(40)
    ok = _fake_calibration([0.42e-3, 0.7e-3], [(0.3e-3, 0.5e-3), (0.5e-3, 0.9e-3)], [1e-6, 1e-5],
                           [[1, 0.2], [0.2, 1]], noise)
    assert ok.warnings() == []
    bad = _fake_calibration([0.42e-3, 0.9e-3], [(0.3e-3, 0.5e-3), (0.5e-3, 0.9e-3)], [1e-4, 1e-5],
                            [[1, -0.97], [-0.97, 1]], np.sin(np.linspace(0, 2 * np.pi, 40)))
    text = "\n".join(bad.warnings())
    assert "geometry.wave_height_m = 0.0009 ends at its upper bound" in text
    assert "geometry.thickness_m is not identifiable: 1-sigma 0.0001 = 24%" in text
    assert "not identifiable apart: correlation -0.970" in text
    assert "the residual is systematic, not noise" in text


def test_calibrated_spring_has_its_own_name_and_description():
    from cushion_clutch.fe.studies.calibration_report import calibrated_params
    cal = _fake_calibration([0.42e-3, 0.7e-3], [(0.3e-3, 0.5e-3), (0.5e-3, 0.9e-3)], [1e-6, 1e-5],
                            [[1, 0], [0, 1]], np.zeros(10))
    p = calibrated_params(cal, "bench7")
    assert p.name == "bench7" and "bench.csv (20 degC, 10 points)" in p.description
    assert "geometry.thickness_m = 0.00042" in p.description


def test_unknown_parameter_and_bad_bounds_are_named():
    p = load_params()
    with pytest.raises(ParameterError, match="wave_hieght_m.*unknown parameter"):
        fit_keys(p, ["wave_hieght_m"])
    with pytest.raises(ParameterError, match="far_end"):      # a string key cannot be fitted
        fit_keys(p, ["far_end"])
    keys = fit_keys(p, ["thickness_m"])
    with pytest.raises(ParameterError, match=r"thickness_m.*allowed \[5e-05, 0.005\]"):
        check_bounds(p, keys, {"thickness_m": (0.3e-3, 9e-3)})
    with pytest.raises(ParameterError, match="start value"):
        check_bounds(p, keys, {"thickness_m": (0.5e-3, 0.6e-3)})
    with pytest.raises(ParameterError, match="NAME=LOWER:UPPER"):
        parse_bounds("thickness_m=0.3e-3")


def test_cli_bad_inputs_exit_2_with_one_message(tmp_path, capsys):
    good = write_csv(tmp_path / "ok.csv", "u_m,force_N\n0,10\n1e-4,20\n2e-4,30\n3e-4,40\n")
    bad = write_csv(tmp_path / "bad.csv", "u_m,force_N\n0,-10\n1e-4,30\n2e-4,20\n3e-4,40\n")
    for argv in (["--measured", str(bad), "--fit", "thickness_m"],
                 ["--measured", str(good), "--fit", "thickness_mm"],
                 ["--measured", str(good), "--fit", "thickness_m", "--bounds", "thickness_m=0:1"]):
        assert main(["calibrate", *argv, "--out", str(tmp_path / "c.toml")]) == 2
        err = capsys.readouterr().err
        assert err.startswith("error:") and "Traceback" not in err
    assert not (tmp_path / "c.toml").exists()


def test_calibrated_toml_reads_back_unchanged(tmp_path):
    p = load_params()
    q = with_values(p, fit_keys(p, ["wave_height_m", "thickness_m"]), [0.75e-3, 0.41e-3])
    from cushion_clutch.config import load_toml
    path = tmp_path / "c.toml"
    path.write_text(params_toml(q, "header"))
    assert params_from_dict(load_toml(path)) == q


@pytest.mark.ccx
@pytest.mark.xfail(strict=True, reason=(
    "known regression of the -40..350 degC re-sweep (issue 37, open): with the carrier clearance at 0.02 mm the "
    "20 degC curve hardly depends on the wave height (d ln F / d ln p about -0.1) and the fit misses it by +2.7 % "
    "at the 3 mm mesh (2.9 of its own 1-sigma) and by +13.7 % at 2 mm; the thickness is recovered within 0.1 %. "
    "Strict: the day it passes again, this mark must go"))
def test_parameter_recovery_from_noisy_fe_measurement(tmp_path):
    """wave height +8 %, thickness -5 %, 1.5 % noise fitted as measured (no running maximum): within 2 %."""
    base = load_params().replace(**RECOVERY)
    keys = fit_keys(base, ["wave_height_m", "thickness_m"])
    true = np.array([base.geometry.wave_height_m * 1.08, base.geometry.thickness_m * 0.95])
    truth = with_values(base, keys, true)
    case = next(iter(run_sweep(truth, cache_dir=tmp_path / "cache", jobs=1).values()))
    c = curve_from_case(case.result, 1, truth.sweep.kiss_force_N)
    u = np.linspace(0.0, 0.95 * c.u_m[-1], 25)
    u = np.concatenate([u[:15], u[13:15] - 0.3 * (u[1] - u[0]), u[15:]])   # the bench backs off and reloads
    rng = np.random.default_rng(11)
    f = np.interp(u, c.u_m, c.force_N) * (1 + 0.015 * rng.standard_normal(len(u))) + 0.5
    assert np.any(np.diff(f) < 0) and np.any(np.diff(u) < 0)    # a raw curve, with a small zero offset
    cal = calibrate(base, Measured(u, f, "pair"), ["wave_height_m", "thickness_m"],
                    cache_dir=tmp_path / "cache", jobs=2)
    err = cal.values / true - 1
    assert np.all(np.abs(err) < 0.02), (cal.values, true, err)
    assert cal.rms_pct < 2.0
    assert not any("bound" in w for w in cal.warnings()), cal.warnings()
    from cushion_clutch.fe.studies.calibration_report import report_text
    assert "runs test" in report_text(cal) and "1-sigma %" in report_text(cal)
    start_err = np.max(np.abs(cal.fe_start_N[0] - f)) / f.max()
    assert start_err > 0.05          # the start was really off


@pytest.mark.ccx
def test_a_hot_curve_is_read_from_the_reference_kiss_point(coarse, case_cache):
    """u of a hot curve counts from the 20 degC kiss point: the hot spring, grown by delta_kiss,
    carries the kiss force delta_kiss before it (same cases as tests/test_sweep.py's two_temps)."""
    from cushion_clutch.fe.studies.calibrate import _Model
    from cushion_clutch.fe.tables import kiss_shift
    p = coarse.replace(sweep={"temperatures_degC": (20.0, 195.0)})
    outcomes = run_sweep(p, cache_dir=case_cache)
    shift = kiss_shift([curve_from_case(o.result, 1, p.sweep.kiss_force_N) for o in outcomes.values()], 20.0)[195.0]
    assert shift > 20e-6
    u = np.array([-shift, 0.0, 0.3e-3])
    measured = [Measured(u, np.zeros(3), "pair", 20.0), Measured(u, np.zeros(3), "pair", 195.0)]
    cold, hot = _Model(p, fit_keys(p, ["thickness_m"]), measured, case_cache, 1, None, None).forces(
        [p.geometry.thickness_m])
    kiss = p.sweep.kiss_force_N
    assert hot[0] == pytest.approx(kiss, rel=1e-6) and cold[1] == pytest.approx(kiss, rel=1e-6)
    assert cold[0] < kiss < hot[1]


def test_hot_curve_may_start_earlier_by_its_kiss_shift(tmp_path):
    """Issue 28: the allowed negative zero offset is the FE kiss shift at the curve's temperature plus 0.2 mm."""
    from cushion_clutch.fe.studies.calibrate import offset_problems
    from cushion_clutch.fe.studies.measured import parse_measured
    cold = write_csv(tmp_path / "cold.csv", "u_m,force_N\n-0.0001,0\n0,10\n0.0005,300\n0.001,900\n")
    hot = write_csv(tmp_path / "hot.csv", "u_m,force_N\n-0.000375,0\n-0.00019,10\n0.0005,350\n0.001,950\n")
    ms = parse_measured([f"20={cold}", f"195={hot}"])            # read: the hot curve's -0.375 mm is kept
    assert offset_problems(ms, [0.0, 0.19e-3]) == []               # 0.19 mm shift + 0.2 mm >= 0.375 mm
    text = "; ".join(offset_problems(ms, [0.0, 0.1e-3]))
    assert "at 195 degC starts at u_m = -0.000375 m; allowed >= -0.0003 m (the FE kiss shift 0.0001 m" in text
    assert "20 degC" not in text
    too_early = write_csv(tmp_path / "cold2.csv", "u_m,force_N\n-0.00025,0\n0,10\n0.0005,300\n0.001,900\n")
    with pytest.raises(Exception, match=r"allowed >= -0.0002 m"):
        parse_measured([str(too_early)])                           # the reference curve keeps 0.2 mm


@pytest.mark.ccx
def test_calibrate_refuses_a_curve_before_the_hot_first_touch(coarse, case_cache):
    """The FE's kiss shift at 195 degC decides: from -(shift + 0.2 mm) the curve is fitted, before it refused."""
    from cushion_clutch.fe.studies.calibrate import _Model, offset_problems
    p = coarse.replace(sweep={"temperatures_degC": (20.0, 195.0)})
    u = np.linspace(0.0, 0.5e-3, 6)
    measured = [Measured(u, 1e3 * u + 1, "pair", 20.0), Measured(u, 1e3 * u + 1, "pair", 195.0)]
    model = _Model(p, fit_keys(p, ["thickness_m"]), measured, case_cache, 1, None, None)
    model.forces([p.geometry.thickness_m])
    shift = model.shifts[(p.geometry.thickness_m,)][1]
    assert shift > 20e-6 and model.shifts[(p.geometry.thickness_m,)][0] == 0.0
    ok = Measured(np.r_[-(shift + 0.19e-3), u], np.r_[0.0, 1e3 * u + 1], "pair", 195.0)
    bad = Measured(np.r_[-(shift + 0.21e-3), u], np.r_[0.0, 1e3 * u + 1], "pair", 195.0)
    assert offset_problems([measured[0], ok], [0.0, shift]) == []
    assert offset_problems([measured[0], bad], [0.0, shift])
    with pytest.raises(ParameterError, match="FE kiss shift"):
        calibrate(p, [measured[0], bad], ["thickness_m"], cache_dir=case_cache, jobs=1)
