"""import-scan: frame fit, outliers, mid-surface fit, malformed scans, and the scanned spring swept."""
import numpy as np
import pytest

from cushion_clutch.cli import main
from cushion_clutch.errors import ParameterError, ScanError
from cushion_clutch.fe.geometry import paddle_mesh, wave_height
from cushion_clutch.fe.params import DEFAULT_SPRING, load_params
from cushion_clutch.fe.scan.fit import read_scan
from cushion_clutch.fe.surface import load_surface
from cushion_clutch.fe.scan.importer import import_scan
from cushion_clutch.fe.cases import case_key

from scan_synthetic import rigid, synthetic_scan, write_csv

TILT = 1e-3


@pytest.fixture(scope="module")
def scanned(tmp_path_factory):
    """The default paddle scanned on its top face: 5 um noise, 1 mrad tilt, 2.5 mm offset, 40 spikes."""
    d = tmp_path_factory.mktemp("scan")
    geom = load_params().geometry
    write_csv(d / "paddle.csv", synthetic_scan(geom, tilt_rad=TILT, offset_m=2.5e-3, outliers=40))
    return import_scan(d / "paddle.csv", DEFAULT_SPRING, d / "spring" / "scanned.toml")


def _grid_error(res):
    geom = load_params().geometry
    rr, pp = np.meshgrid(res.fit.r_m, res.fit.phi_deg, indexing="ij")
    return wave_height(rr, pp, res.params.geometry) - wave_height(rr, pp, geom)


def test_synthetic_scan_recovers_the_analytic_wave(scanned):
    res = scanned
    assert res.frame.tilt_rad == pytest.approx(TILT, abs=0.15e-3)     # noise-limited (4 mm baseline)
    # the offset removed: the scanned top face of the rivet zone (t + clearance) at its centroid
    g = load_params().geometry
    r_c = 2 / 3 * (g.outer_radius_m ** 3 - g.inner_radius_m ** 3) / (g.outer_radius_m ** 2 - g.inner_radius_m ** 2)
    centre = [r_c * np.cos(np.radians(2.0)), r_c * np.sin(np.radians(2.0)),
              g.thickness_m + g.carrier_clearance_m]
    assert res.frame.offset_m == pytest.approx(-rigid(centre, TILT, 30.0, 2.5e-3)[0, 2], abs=5e-6)
    assert 40 <= res.n_rejected <= 80                                 # every spike, few good points
    assert 4e-6 < res.fit.rms_m < 6e-6                                # the scan's 5 um noise
    err = _grid_error(res)
    assert np.sqrt(np.mean(err ** 2)) < 3e-6
    assert np.abs(err).max() < 25e-6
    # the surface replaces the tilted wave: its peak (the outer edge's crest) is the new wave_height_m
    assert res.params.geometry.wave_height_m == pytest.approx(g.max_wave_height_m, abs=10e-6)
    assert res.params.geometry.wave_tilt_m == 0.0
    assert res.params.name == "scanned"


def test_written_files_and_relative_surface_path(scanned, tmp_path, monkeypatch):
    res = scanned
    assert res.surface.name == "scanned_surface.npz" and res.plot.stat().st_size > 20000
    text = res.toml.read_text()
    assert 'surface_file = "scanned_surface.npz"' in text and "residual RMS" in text
    monkeypatch.chdir(tmp_path)                       # any folder: the path is the TOML's
    p = load_params(res.toml)
    assert p.geometry.surface_file == str(res.surface.resolve())
    with np.load(res.surface) as data:
        assert float(data["rms_m"]) == pytest.approx(res.fit.rms_m)
        assert float(data["tilt_rad"]) == pytest.approx(res.frame.tilt_rad)
    # the mesh takes the scanned wave: crest height matches the analytic paddle's
    z_scan = paddle_mesh(p.geometry, 2e-3).nodes[:, 2].max()
    z_ref = paddle_mesh(load_params().geometry, 2e-3).nodes[:, 2].max()
    assert z_scan == pytest.approx(z_ref, abs=15e-6)


def test_surface_changes_the_cache_key_not_its_location(scanned, tmp_path):
    p = load_params(scanned.toml)
    moved = tmp_path / "elsewhere.npz"
    moved.write_bytes(scanned.surface.read_bytes())
    q = p.replace(geometry={"surface_file": str(moved)})
    assert case_key(p, 20.0, 1, "ccx") == case_key(q, 20.0, 1, "ccx")
    with np.load(moved) as data:
        arrays = {k: data[k] for k in data.files}
    arrays["w_m"] = arrays["w_m"] * 1.01
    np.savez(moved, **arrays)
    assert case_key(p, 20.0, 1, "ccx") != case_key(q, 20.0, 1, "ccx")
    assert case_key(p, 20.0, 1, "ccx") != case_key(load_params(), 20.0, 1, "ccx")


def test_bad_surface_file_is_named(tmp_path):
    f = tmp_path / "s.toml"
    f.write_text(DEFAULT_SPRING.read_text().replace("[geometry]", '[geometry]\nsurface_file = "nope.npz"'))
    with pytest.raises(ParameterError, match=r"geometry.surface_file = .*nope.npz.*file not found"):
        load_params(f)
    np.savez(tmp_path / "small.npz", r_m=[0.08, 0.09], phi_deg=[0.0, 10.0], w_m=[[0, 1e-4], [0, 1e-4]])
    f.write_text(DEFAULT_SPRING.read_text().replace("[geometry]", '[geometry]\nsurface_file = "small.npz"'))
    with pytest.raises(ParameterError, match=r"covers r = 0.08..0.09 m.*the paddle needs r = 0.072..0.108"):
        load_params(f)


def test_stl_surface_via_meshio(tmp_path):
    """A noise-free triangulated mid-surface, read with meshio, fits the analytic wave to a micrometre."""
    import meshio
    geom = load_params().geometry
    r, phi = np.meshgrid(np.linspace(geom.inner_radius_m, geom.outer_radius_m, 40),
                         np.linspace(0.0, geom.span_deg, 221), indexing="ij")
    z = wave_height(r, phi, geom) + 1e-3
    pts = np.column_stack([(r * np.cos(np.radians(phi))).ravel(), (r * np.sin(np.radians(phi))).ravel(),
                           z.ravel()]) * 1e3
    idx = np.arange(r.size).reshape(r.shape)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    tris = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    meshio.write(tmp_path / "paddle.stl", meshio.Mesh(pts, [("triangle", tris)]))
    assert read_scan(tmp_path / "paddle.stl").shape[1] == 3
    res = import_scan(tmp_path / "paddle.stl", DEFAULT_SPRING, tmp_path / "stl.toml", face="mid")
    err = _grid_error(res)
    assert res.frame.tilt_rad < 1e-6 and np.sqrt(np.mean(err ** 2)) < 1.5e-6
    assert load_surface(res.surface).peak_m == pytest.approx(geom.max_wave_height_m, abs=3e-6)


@pytest.mark.parametrize("case, unit, message", [
    ("few", "mm", r"300 valid point\(s\); a paddle scan needs at least 1000"),
    ("outside", "mm", r"\d+% of the points lie outside the paddle sector"),
    ("nan", "mm", r"1 point\(s\) with NaN or infinite coordinates \(data rows 7\)"),
    ("units", "m", r"the paddle is 99\dx too large.*probably 'mm', not --unit 'm'"),
    ("holes", "mm", r"the points cover \d+% of the paddle sector"),
    ("inch", "mm", r"0.039\dx too small.*probably 'in', not --unit 'mm'"),
    ("cm", "mm", r"0.0\d+x too small.*probably 'cm', not --unit 'mm'"),
    ("rim", "mm", r"a gap of \d+\.\d mm\^2 \(limit 4 mm\^2\) on the wave's crest \(outer rim\) at r = 10[5-7]\.\d\.\.108\.0 mm"),
    ("crest_hole", "mm", r"a gap of \d+\.\d mm\^2 \(limit 4 mm\^2\) on the wave's crest at r = 9\d"),
    ("flank_hole", "mm", r"a gap of \d+\.\d mm\^2 \(limit 10 mm\^2\) on the wave's flank at"),
])
def test_malformed_scans_get_one_clear_message(case, unit, message, tmp_path, capsys):
    geom = load_params().geometry
    pts = synthetic_scan(geom, n=300 if case == "few" else 5000)
    if case == "outside":
        c, s = np.cos(np.radians(40)), np.sin(np.radians(40))
        pts = pts @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
    elif case == "nan":
        pts[6, 1] = np.nan
    elif case == "holes":
        pts = pts[np.degrees(np.arctan2(pts[:, 1], pts[:, 0])) < 9.0]
    r, phi = np.hypot(pts[:, 0], pts[:, 1]), np.degrees(np.arctan2(pts[:, 1], pts[:, 0]))
    if case == "rim":               # the outer 1.8 mm over the wave: 4 % of the area
        pts = pts[~((r > 0.1062) & (phi > 5) & (phi < 20))]
    elif case == "crest_hole":      # 8 mm x 5 deg over the crest: 6 % of the area
        pts = pts[~((np.abs(r - 0.100) < 4e-3) & (np.abs(phi - 12.5) < 2.5))]
    elif case == "flank_hole":      # 6 mm x 2.6 deg on the rising flank: 2 % of the area
        pts = pts[~((np.abs(r - 0.085) < 3e-3) & (np.abs(phi - 6.2) < 1.3))]
    write_csv(tmp_path / "scan.csv", pts, unit_m={"inch": 0.0254, "cm": 0.01}.get(case, 1e-3))
    code = main(["import-scan", str(tmp_path / "scan.csv"), "--out", str(tmp_path / "s.toml"), "--unit", unit])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert err.startswith(f"error: cannot import the scan {tmp_path / 'scan.csv'}")
    import re
    assert re.search(message, err), err
    assert not (tmp_path / "s.toml").exists()
    if case.endswith(("rim", "hole")):     # the coverage map shows where to rescan
        assert f"coverage map: {tmp_path / 's_coverage.png'}" in err
        assert (tmp_path / "s_coverage.png").stat().st_size > 10000


def test_a_gap_on_the_flat_far_zone_is_mapped_and_accepted(tmp_path):
    geom = load_params().geometry
    pts = synthetic_scan(geom, n=5000)
    r, phi = np.hypot(pts[:, 0], pts[:, 1]), np.degrees(np.arctan2(pts[:, 1], pts[:, 0]))
    write_csv(tmp_path / "scan.csv", pts[~((np.abs(r - 0.090) < 3e-3) & (phi > 20.5))])
    res = import_scan(tmp_path / "scan.csv", DEFAULT_SPRING, tmp_path / "s.toml")
    assert res.coverage.refused == [] and len(res.coverage.gaps) >= 1
    g = res.coverage.gaps[0]
    assert g.region.startswith("the flat zone") and g.area_m2 > 4e-6 and g.phi_deg[1] == pytest.approx(22.0)
    assert res.coverage_plot.stat().st_size > 20000


def test_unreadable_and_wrong_columns(tmp_path):
    (tmp_path / "a.csv").write_text("u,v,w\n1,2,3\n")
    with pytest.raises(ScanError, match="need a header with x,y,z"):
        read_scan(tmp_path / "a.csv")
    (tmp_path / "a.xyz").write_text("1 2 3\n")
    with pytest.raises(ScanError, match="file type '.xyz'"):
        read_scan(tmp_path / "a.xyz")
    (tmp_path / "b.stl").write_text("solid garbage\n")
    with pytest.raises(ScanError, match="cannot read the file|holds no points"):
        read_scan(tmp_path / "b.stl")


@pytest.mark.ccx
def test_scanned_spring_sweeps_within_2_percent_of_the_analytic_one(scanned, coarse, case_cache):
    """Scan (noise, tilt, offset, spikes) -> fitted surface -> ccx: F(u) at 20 degC within 2 %."""
    from cushion_clutch.fe.sweep import run_sweep
    from cushion_clutch.fe.tables import curve_from_case

    sweep = {"temperatures_degC": (20.0, 195.0)}          # the analytic case is shared with test_sweep
    analytic = coarse.replace(sweep=sweep)
    scan = load_params(scanned.toml).replace(mesh={"element_size_m": coarse.mesh.element_size_m},
                                             sweep={"temperatures_degC": (20.0,)})
    ref = curve_from_case(run_sweep(analytic, cache_dir=case_cache)[20.0].result, 8, 10.0)
    got = curve_from_case(run_sweep(scan, cache_dir=case_cache)[20.0].result, 8, 10.0)
    u = ref.u_m[(ref.u_m > 0.1e-3) & (ref.u_m <= min(ref.u_m[-1], got.u_m[-1]))]
    rel = np.interp(u, got.u_m, got.force_N) / np.interp(u, ref.u_m, ref.force_N) - 1
    assert np.abs(rel).max() < 0.02
    assert got.force_N[-1] == pytest.approx(ref.force_N[-1], rel=0.02)
    assert got.u_m[-1] == pytest.approx(ref.u_m[-1], rel=0.02)
