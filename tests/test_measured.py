"""Measured curves: read as measured (noise, non-monotone, zero offset), bad files named."""
from __future__ import annotations

import numpy as np
import pytest

from cushion_clutch.errors import ParameterError, TableError
from cushion_clutch.fe.studies.measured import parse_measured, read_measured


def write_csv(path, text):
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, match", [
    ("u,F\n0,10\n1,20\n2,30\n3,40\n", "header"),
    ("u_m,force_N\n0,10\n1e-4,abc\n2e-4,30\n3e-4,40\n", "line 3"),
    ("u_m,force_N\n0,10\n1e-4,20\n", "at least 4"),
    ("u_m,force_N\n-1e-3,10\n1e-4,30\n2e-4,40\n3e-4,50\n", "line 2: u_m = -0.001 m.*>= -0.0002 m"),
    ("u_m,force_N\n0,-10\n1e-4,30\n2e-4,40\n3e-4,50\n", "line 2: force_N = -10 N, below the allowed zero"),
    ("u_m,force_N\n0,0\n1e-4,0\n2e-4,0\n3e-4,0\n", "never rises above 0"),
    ("u_m,force_N\n0,10\n1e-4,nan\n2e-4,20\n3e-4,40\n", "finite"),
])
def test_bad_measured_csv_is_named(tmp_path, text, match):
    with pytest.raises(TableError, match=match):
        read_measured(write_csv(tmp_path / "bench.csv", text))


def test_a_raw_curve_is_kept_as_measured(tmp_path):
    """Noise, a falling force, a repeated and a backward u, a small zero offset: read as they are."""
    text = "u_m,force_N\n-2e-5,-3\n0,11\n1e-4,40\n1e-4,38\n2e-4,70\n1.9e-4,66\n3e-4,64\n4e-4,120\n"
    m = read_measured(write_csv(tmp_path / "raw.csv", text))
    np.testing.assert_array_equal(m.force_N, [-3, 11, 40, 38, 70, 66, 64, 120])
    np.testing.assert_array_equal(m.u_m, [-2e-5, 0, 1e-4, 1e-4, 2e-4, 1.9e-4, 3e-4, 4e-4])
    assert m.theta_degC == 20.0 and m.source.endswith("raw.csv")


def test_measured_at_several_temperatures(tmp_path):
    a = write_csv(tmp_path / "a.csv", "u_m,force_N\n0,10\n1e-4,20\n2e-4,30\n3e-4,40\n")
    b = write_csv(tmp_path / "b.csv", "u_m,force_N\n0,15\n1e-4,25\n2e-4,30\n3e-4,35\n")
    ms = parse_measured([f"20={a}", f"195={b}"])
    assert [m.theta_degC for m in ms] == [20.0, 195.0] and ms[1].force_N[0] == 15
    assert parse_measured([str(a)])[0].theta_degC == 20.0
    with pytest.raises(ParameterError) as e:
        parse_measured([f"195={b}", f"195={a}", f"hot={a}"])
    msg = str(e.value)
    assert "195 degC given twice" in msg and "'hot=" in msg and "no curve at the reference temperature 20" in msg
