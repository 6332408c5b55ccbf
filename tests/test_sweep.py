"""Coarse-mesh sweeps of the default spring through the whole FE pipeline."""
import numpy as np
import pytest

from cushion_clutch.errors import ConvergenceError, SweepError
from cushion_clutch.fe.cases import solve_case
from cushion_clutch.fe.sweep import build_tables, run_sweep
from cushion_clutch.fe.tables import curve_from_case, progressivity
from cushion_clutch.model.table_format import read_tables

pytestmark = pytest.mark.ccx


@pytest.fixture(scope="module")
def two_temps(coarse):
    return coarse.replace(sweep={"temperatures_degC": (20.0, 195.0)})


@pytest.fixture(scope="module")
def coarse_tables(two_temps, case_cache, tmp_path_factory):
    out = tmp_path_factory.mktemp("tables") / "default"
    outcomes = run_sweep(two_temps, cache_dir=case_cache)
    build_tables(two_temps, outcomes, out)
    return read_tables(out)


def test_tables_have_the_paper_properties(coarse_tables):
    t = coarse_tables
    assert list(t.theta_degC) == [20.0, 195.0]
    for u, f in zip(t.u_m, t.force_N):
        assert np.all(np.diff(f) >= 0), "F must be non-decreasing in u"
        assert np.count_nonzero(u > 0) >= 30
        # the kiss point row: 10 N per pair, 8 pairs
        assert np.interp(0.0, u, f) == pytest.approx(80.0)
        # full compression of a passenger-car spring: 3-8 kN
        assert 3e3 <= f[-1] <= 8e3
        # up to 2 x 0.97 x 1.0 mm (the outer edge's wave) from the kiss point to full compression
        assert 1.0e-3 < u[-1] < 2.0e-3
    # paper: about 0.1 mm axial kiss-point shift at 195 degC
    assert t.delta_kiss_m[0] == 0.0
    assert 0.07e-3 <= t.delta_kiss_m[1] <= 0.14e-3
    # Young's modulus drops: at equal compression well past the toe, less force when hot
    u_mid = 0.8e-3
    assert np.interp(u_mid, t.u_m[1], t.force_N[1]) < np.interp(u_mid, t.u_m[0], t.force_N[0])
    # a progressive spring (issue 11): k(90 %)/k(20 %) >= 3 at 20 degC, in the metadata too
    prog = t.metadata["progressivity"]["20"]
    assert prog["k90_over_k20"] >= 3.0
    assert prog == pytest.approx(progressivity(t.u_m[0], t.force_N[0]))


def test_crest_growth_is_reported_beside_the_kiss_shift(coarse_tables, tmp_path_factory):
    kp = coarse_tables.metadata["kiss_point"]
    assert kp["20"] == {"delta_kiss_m": 0.0, "crest_growth_m": 0.0}
    # heating grows the crests; the 10 N point moves less because the hot spring is softer
    assert kp["195"]["crest_growth_m"] > 0.05e-3
    assert kp["195"]["delta_kiss_m"] == pytest.approx(coarse_tables.delta_kiss_m[1])


def test_metadata_records_provenance(coarse_tables):
    m = coarse_tables.metadata
    assert m["solver"]["name"] == "CalculiX ccx" and m["solver"]["version"] != "unknown"
    assert m["mesh"]["nodes"] > 0 and m["mesh"]["elements"] > 0
    assert m["spring"]["geometry"]["thickness_m"] == pytest.approx(0.42e-3)
    for case in m["cases"].values():
        assert case["increments"] > 30 and case["iterations"] > 0 and case["wall_time_s"] > 0


def test_rerun_is_served_from_cache(two_temps, case_cache, coarse_tables):
    events = []
    run_sweep(two_temps, cache_dir=case_cache, progress=lambda t, e, v: events.append((t, e)))
    assert not [e for e in events if e[1] == "start"]
    assert sorted(events) == [(20.0, "done"), (195.0, "done")]


def test_non_convergence_names_case_keeps_finished_and_resumes(two_temps, tmp_path):
    """A 4 mm mesh (same 60 increments, 20 and 195 degC both converge on it): the failure handling,
    the cache and the resume are under test here, not the mesh."""
    two_temps = two_temps.replace(mesh={"element_size_m": 4e-3})
    cache, out = tmp_path / "cache", tmp_path / "tables"
    run_sweep(two_temps.replace(sweep={"temperatures_degC": (20.0,)}), cache_dir=cache)
    # 60 compression increments cannot fit under a cap of 30
    capped = two_temps.replace(solver={"max_increments": 30})
    with pytest.raises(SweepError) as info:
        run_sweep(capped, cache_dir=cache)
    err = info.value.failures[195.0]
    assert isinstance(err, ConvergenceError)
    assert (err.theta_degC, err.step, err.increment) == (195.0, 2, 30)
    assert "195 degC" in str(err) and "step 2, increment 30" in str(err) and err.log_tail
    assert 20.0 not in info.value.failures and not out.exists()
    events = []
    outcomes = run_sweep(two_temps, cache_dir=cache, progress=lambda t, e, v: events.append((t, e)))
    assert [t for t, e in events if e == "start"] == [195.0]
    build_tables(two_temps, outcomes, out)
    assert (out / "force_deflection.csv").exists()


def test_half_pair_in_series_matches_full_pair(two_temps, case_cache, tmp_path):
    """The series composition of one paddle equals the back-to-back pair within 2 %.

    At 195 degC only: the composition is a kinematic principle, independent of the temperature, and
    the hot case (thermally distorted paddle, softer steel) is the harder one. The half pair is the
    sweep's own 195 degC case (shared through the session cache with ``coarse_tables``); only the full
    pair is solved here. Measured on the 2 mm mesh: 0.04 % at 195 degC and at 20 degC (limit 2 %).
    """
    theta = 195.0
    half = run_sweep(two_temps, cache_dir=case_cache)[theta].result
    assert half.paddles == 1
    pair = solve_case(two_temps, theta, tmp_path / "pair", paddles=2).result
    s = pair.pair_travel_m
    f_half = np.interp(s, half.pair_travel_m, half.force_N)
    loaded = pair.force_N > 0.05 * pair.force_N.max()
    assert np.abs(f_half[loaded] / pair.force_N[loaded] - 1).max() < 0.02


def test_mesh_refinement_2mm_vs_1_5mm(two_temps, case_cache, tmp_path):
    """The 2 mm test mesh is close to converged: refined to 1.5 mm, the curve moves by less than 7.5 %.

    1.5 mm instead of 1 mm keeps this affordable (the 1 mm case alone took about a minute). The limit is
    the former one (15 % between 2 mm and 1 mm) scaled to the smaller refinement step: for a
    first-order error e(h) ~ h, e(2) - e(1.5) = e(2)/4 while e(2) - e(1) = e(2)/2, so a 7.5 % change
    bounds the 2 mm error as the 15 % did. Measured at 20 degC: 4 mm vs 2 mm 8.3 %, 3 mm vs 2 mm 5.3 %,
    2 mm vs 1.5 mm 2.9 % (each step smaller: converging). The 2 mm case is the sweep's own, shared
    through the session cache with ``coarse_tables``.
    """
    c2 = run_sweep(two_temps, cache_dir=case_cache)[20.0].result
    fine = two_temps.replace(mesh={"element_size_m": 1.5e-3}, sweep={"temperatures_degC": (20.0,)})
    c1 = solve_case(fine, 20.0, tmp_path / "m1.5").result
    s = c1.pair_travel_m
    mid = (c1.force_N > 0.1 * c1.force_N.max()) & (s < 0.9 * s.max())
    rel = np.abs(np.interp(s[mid], c2.pair_travel_m, c2.force_N) / c1.force_N[mid] - 1)
    assert rel.max() < 0.075, f"2 mm vs 1.5 mm differ by {rel.max():.1%}"


def test_without_thermal_distortion_force_scales_with_youngs_modulus(coarse, tmp_path):
    """On a 4 mm mesh: the scaling with E holds on any mesh; measured worst deviation 0.62 % on 4 mm
    (limit 1 %)."""
    p = coarse.replace(sweep={"thermal_distortion": False}, mesh={"element_size_m": 4e-3})
    cold = solve_case(p, 20.0, tmp_path / "c").result
    hot = solve_case(p, 300.0, tmp_path / "h").result
    assert abs(hot.crest_rise_m) < 1e-7
    s = cold.pair_travel_m
    # above a quarter of the force: at the tilted wave's first, narrow edge contact the penalty
    # compliance (which does not scale with E) still shows by about 1 %
    loaded = (cold.force_N > 0.25 * cold.force_N.max())
    ratio = np.interp(s[loaded], hot.pair_travel_m, hot.force_N) / cold.force_N[loaded]
    e_ratio = p.material.youngs_modulus(300.0) / p.material.youngs_modulus(20.0)
    assert ratio == pytest.approx(np.full(len(ratio), e_ratio), rel=0.01)


def test_dask_local_cluster_gives_the_same_tables(two_temps, case_cache, coarse_tables, tmp_path):
    distributed = pytest.importorskip("distributed")
    p = two_temps.replace(sweep={"temperatures_degC": (20.0,)})
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        out = run_sweep(p, cache_dir=tmp_path, scheduler=client)
    local = run_sweep(p, cache_dir=case_cache)
    assert np.array_equal(out[20.0].result.force_N, local[20.0].result.force_N)


#: a cheap model that still solves every shape: 4 mm mesh, 30 increments, 80 % flat
QUICK = {"mesh": {"element_size_m": 4e-3}, "solver": {"compression_increments": 30, "flatten_fraction": 0.8}}


@pytest.mark.parametrize("geometry, mesh", [
    ({"wave_tilt_m": 0.4e-3, "far_zone_support": "carrier"}, {}),
    ({"waves": 2, "wave_profile": "flat_top", "crest_flat_fraction": 0.4, "wave_tilt_m": 0.0},
     {"element_size_m": 2e-3}),
    ({"wave_profile": "table", "profile_s": (0.0, 0.3, 0.7, 1.0), "profile_z": (0.0, 1.0, 1.0, 0.0),
      "wave_tilt_m": 0.0}, {"element_type": "S8R"}),
], ids=["tilted-resting", "two-flat-top", "table-S8R"])
def test_every_new_shape_builds_meshes_and_solves(coarse, tmp_path, geometry, mesh):
    p = coarse.replace(geometry=geometry, **{**QUICK, "mesh": {**QUICK["mesh"], **mesh}})
    # 20 degC: on this 4 mm mesh the hot (195 degC) resting and S4R cases did not converge
    out = solve_case(p, 20.0, tmp_path)
    c = curve_from_case(out.result, p.n_pairs, p.sweep.kiss_force_N)
    assert c.force_N[-1] > 1e3 and np.all(np.diff(c.force_N) >= 0)
    assert out.n_elements > 0 and abs(out.result.crest_rise_m) < 1e-9


def test_tilted_wave_is_more_progressive_than_plain_cosine(coarse, case_cache):
    """Same mean height 0.7 mm: the tilted wave touches at one edge first and stiffens later."""
    ratios = {}
    for name, tilt in (("cosine", 0.0), ("tilted", coarse.geometry.wave_tilt_m)):
        p = coarse.replace(geometry={"wave_tilt_m": tilt}, sweep={"temperatures_degC": (20.0,)})
        case = run_sweep(p, cache_dir=case_cache)[20.0]
        c = curve_from_case(case.result, p.n_pairs, p.sweep.kiss_force_N)
        ratios[name] = progressivity(c.u_m, c.force_N)["k90_over_k20"]
    assert ratios["tilted"] > 1.5 * ratios["cosine"], ratios


def test_heating_alone_loads_no_plate(two_temps, case_cache):
    """The plates are held while the paddle heats: no force on the carrier or the facing plate."""
    for theta, o in run_sweep(two_temps, cache_dir=case_cache).items():
        assert abs(o.result.thermal_force_lower_N) < 0.05 and abs(o.result.thermal_force_N) < 0.05, theta
