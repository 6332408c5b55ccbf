"""cushion-clutch calibrate: bad inputs, and recovery of known parameters from an FE "measurement"."""
from __future__ import annotations

import numpy as np
import pytest

from cushion_clutch.cli import main
from cushion_clutch.errors import ParameterError, TableError
from cushion_clutch.fe.studies.calibrate import (calibrate, check_bounds, fit_keys, parse_bounds,
                                         read_measured, with_values, Measured)
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


@pytest.mark.parametrize("text, match", [
    ("u,F\n0,10\n1,20\n2,30\n3,40\n", "header"),
    ("u_m,force_N\n0,10\n1e-4,abc\n2e-4,30\n3e-4,40\n", "line 3"),
    ("u_m,force_N\n0,10\n1e-4,20\n", "at least 4"),
    ("u_m,force_N\n0,10\n2e-4,20\n1e-4,30\n3e-4,40\n", "increase strictly"),
    ("u_m,force_N\n0,10\n1e-4,30\n2e-4,20\n3e-4,40\n", "decreases"),
    ("u_m,force_N\n-1e-4,10\n1e-4,30\n2e-4,40\n3e-4,50\n", ">= 0"),
    ("u_m,force_N\n0,10\n1e-4,nan\n2e-4,20\n3e-4,40\n", "finite"),
])
def test_bad_measured_csv_is_named(tmp_path, text, match):
    with pytest.raises(TableError, match=match):
        read_measured(write_csv(tmp_path / "bench.csv", text))


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
    bad = write_csv(tmp_path / "bad.csv", "u_m,force_N\n0,10\n1e-4,30\n2e-4,20\n3e-4,40\n")
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
def test_parameter_recovery_from_noisy_fe_measurement(tmp_path):
    """wave height +8 %, thickness -5 %, 1 % noise: both recovered within 2 %."""
    base = load_params().replace(**RECOVERY)
    keys = fit_keys(base, ["wave_height_m", "thickness_m"])
    true = np.array([base.geometry.wave_height_m * 1.08, base.geometry.thickness_m * 0.95])
    truth = with_values(base, keys, true)
    case = next(iter(run_sweep(truth, cache_dir=tmp_path / "cache", jobs=1).values()))
    c = curve_from_case(case.result, 1, truth.sweep.kiss_force_N)
    u = np.linspace(0.0, 0.95 * c.u_m[-1], 25)
    rng = np.random.default_rng(11)
    f = np.interp(u, c.u_m, c.force_N) * (1 + 0.01 * rng.standard_normal(len(u)))
    f = np.maximum.accumulate(f)
    cal = calibrate(base, Measured(u, f, "pair"), ["wave_height_m", "thickness_m"],
                    cache_dir=tmp_path / "cache", jobs=2)
    err = cal.values / true - 1
    assert np.all(np.abs(err) < 0.02), (cal.values, true, err)
    assert cal.rms_pct < 2.0
    start_err = np.max(np.abs(cal.fe_start_N - f)) / f.max()
    assert start_err > 0.05          # the start was really off
