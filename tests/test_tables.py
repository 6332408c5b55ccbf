"""Table building and writing, on hand-made case results (no solver needed)."""
import numpy as np
import pytest

from cushion_clutch.errors import ResultError, TableError
from cushion_clutch.fe.results import CaseResult
from cushion_clutch.fe.tables import curve_from_case, write_tables
from cushion_clutch.model.table_format import read_tables


def case(theta, travel, force):
    return CaseResult(theta, 1, 0.0, np.asarray(travel, float), np.asarray(force, float), 0.0)


def test_kiss_point_is_interpolated_at_the_kiss_force():
    # paddle travel 0..0.5 mm; pair travel is twice that
    c = curve_from_case(case(20.0, [0, 1e-4, 2e-4, 3e-4, 5e-4], [0, 0, 5, 15, 60]), 8, 10.0)
    assert c.kiss_travel_m == pytest.approx(5e-4)            # pair: 2 x 2.5e-4
    assert c.u_m[0] == pytest.approx(2e-4 - 5e-4)            # starts at last zero-force point
    assert np.interp(0.0, c.u_m, c.force_N) == pytest.approx(80.0)
    assert c.force_N[-1] == pytest.approx(480.0)


def test_snap_through_is_refused():
    with pytest.raises(ResultError, match="snap-through"):
        curve_from_case(case(300.0, np.linspace(0, 5e-4, 6), [0, 20, 60, 40, 50, 90]), 8, 10.0)


def test_contact_before_compression_is_refused():
    with pytest.raises(ResultError, match="initial_gap_m"):
        curve_from_case(case(300.0, [0, 1e-4], [12.0, 30.0]), 8, 10.0)


def _curves():
    return [curve_from_case(case(t, [0, 1e-4, 2e-4, 4e-4], [0, 5, 20 - t / 100, 90]), 8, 10.0)
            for t in (20.0, 195.0)]


def test_written_tables_read_back(tmp_path):
    curves = _curves()
    out = write_tables(tmp_path / "set", curves, 20.0, {"solver": "test"})
    t = read_tables(out)
    assert list(t.theta_degC) == [20.0, 195.0]
    assert t.delta_kiss_m[0] == 0.0
    assert t.metadata == {"solver": "test"}
    # every value, against the curves written (u to 10 significant digits, force to 1 uN)
    for c, u, f in zip(curves, t.u_m, t.force_N):
        np.testing.assert_allclose(u, c.u_m, rtol=1e-9, atol=0.0)
        np.testing.assert_allclose(f, c.force_N, rtol=0.0, atol=1e-6)
    np.testing.assert_allclose(t.delta_kiss_m, [0.0, curves[0].kiss_travel_m - curves[1].kiss_travel_m],
                               rtol=1e-9, atol=0.0)
    assert (out / "force_deflection.csv").read_text().startswith("theta_degC,u_m,force_N\n")
    assert (out / "kiss_point.csv").read_text().startswith("theta_degC,delta_kiss_m\n")


def test_failed_write_leaves_previous_set_untouched(tmp_path):
    out = write_tables(tmp_path / "set", _curves(), 20.0, {"run": 1})
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    with pytest.raises(TypeError):
        write_tables(out, _curves(), 20.0, {"bad": object()})
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["set"]       # no half-written folder


def test_malformed_table_is_named(tmp_path):
    out = write_tables(tmp_path / "set", _curves(), 20.0, {})
    (out / "kiss_point.csv").write_text("theta,delta\n20,0\n")
    with pytest.raises(TableError, match="kiss_point.csv: header"):
        read_tables(out)


def test_tables_hold_hand_computed_values(tmp_path):
    """Hand values: force in N (whole spring, 8 pairs), u in m, the kiss shift positive when the hot
    spring touches earlier (it grew in free height), independent of the writer's own code."""
    # paddle travel; the pair travel is twice that. Kiss at 10 N per pair.
    cold = case(20.0, [0, 1e-4, 2e-4, 3e-4], [0, 0, 10, 30])      # kiss at pair travel 4e-4 m
    hot = case(195.0, [0, 1e-4, 2e-4, 3e-4], [0, 10, 30, 50])      # kiss at pair travel 2e-4 m: earlier
    curves = [curve_from_case(c, 8, 10.0) for c in (cold, hot)]
    out = write_tables(tmp_path / "hand", curves, 20.0, {})
    rows = [line.split(",") for line in (out / "force_deflection.csv").read_text().splitlines()[1:]]
    got = np.array(rows, dtype=float)
    np.testing.assert_allclose(got, [(20.0, -2e-4, 0.0), (20.0, 0.0, 80.0), (20.0, 2e-4, 240.0),
                                 (195.0, -2e-4, 0.0), (195.0, 0.0, 80.0), (195.0, 2e-4, 240.0),
                                 (195.0, 4e-4, 400.0)], rtol=0.0, atol=1e-12)
    kiss = [line.split(",") for line in (out / "kiss_point.csv").read_text().splitlines()[1:]]
    np.testing.assert_allclose(np.array(kiss, dtype=float), [(20.0, 0.0), (195.0, 2e-4)], rtol=0.0, atol=1e-15)


@pytest.mark.parametrize("value, ok", [(0.0041, True), (0, True), (True, False), (False, False), ("0.004", False),
                                       (2.0, False), (float("nan"), False)])
def test_table_set_x_kiss_ref_takes_only_a_number(tmp_path, value, ok):
    """metadata.json's tolerance_study.x_kiss_ref_m: a JSON true was float()ed to 1 m (issue 43)."""
    import json
    from cushion_clutch.model.table_format import table_set_x_kiss_ref

    (tmp_path / "metadata.json").write_text(json.dumps({"tolerance_study": {"x_kiss_ref_m": value}}))
    if ok:
        assert table_set_x_kiss_ref(tmp_path) == float(value)
    else:
        with pytest.raises(ValueError, match="tolerance_study.x_kiss_ref_m"):
            table_set_x_kiss_ref(tmp_path)
