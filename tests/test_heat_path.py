"""The disc-sector thermal FE (cushion-clutch heat-path): mesh invariants, a lumped closed form through the
same deck writer and ccx runner, and the coarse run's checks (C against mass x c, energy, mesh, tau)."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cushion_clutch.fe.heat_deck import Phase, Schedule, write_deck, parse_temperatures
from cushion_clutch.fe.heat_mesh import HeatMesh, sector_mesh
from cushion_clutch.fe.heat_params import STEEL_C_RANGE_J_PER_KG_K, HeatPathParams
from cushion_clutch.fe.heat_fit import first_order
from cushion_clutch.fe.heat_path import schedule_for
from cushion_clutch.fe.params import load_params


@pytest.fixture(scope="module")
def spring():
    return load_params()


def test_paddle_mass_is_the_spring_files_sector(spring):
    """The mesh's paddle steel equals the annular sector of the spring file (radii, span, thickness)."""
    g = spring.geometry
    hp = HeatPathParams()
    m = sector_mesh(spring, hp, 6e-3)
    analytic = 0.5 * (g.outer_radius_m ** 2 - g.inner_radius_m ** 2) * math.radians(g.span_deg) * g.thickness_m \
        * hp.steel_density_kg_m3
    assert m.mass_kg("PADDLE") == pytest.approx(analytic, rel=2e-3)       # chords instead of arcs
    assert m.disc_factor == 2 * spring.n_pairs


def test_interface_conductance_does_not_depend_on_the_mesh(spring):
    """Cell conductances are area means of the local h: the layer's total conductance is mesh-independent."""
    hp = HeatPathParams()
    totals = []
    for e in (8e-3, 4e-3, 2e-3):
        m = sector_mesh(spring, hp, e)
        s = m.element_sets["INTERFACE"]
        t = m.nodes[m.elements[s, 4], 2] - m.nodes[m.elements[s, 0], 2]
        totals.append(np.sum(m.conductivity_W_per_m_K[s] * m.volume_m3[s] / t ** 2))
    assert max(totals) / min(totals) - 1 < 0.02


def test_schedule_puts_the_launch_energy_in_exactly(spring):
    hp = HeatPathParams()
    m = sector_mesh(spring, hp, 8e-3)
    for dt in (0.25, 0.5, 1.0):
        s = schedule_for(m, hp, dt)
        t = s.increment_times()
        heat = np.sum(np.diff(np.r_[0.0, t]) * s.flux(t)) * m.face_area_m2["FRICTION"].sum() * m.disc_factor
        assert heat == pytest.approx(hp.launches * hp.slip_energy_J * hp.facing_heat_share, rel=1e-9)


def test_first_order_matches_the_exponential():
    """The backward-Euler ODE converges to the closed form of a step in theta_cm."""
    dt = np.full(4000, 0.005)
    t = np.cumsum(dt)
    y = first_order(np.full_like(t, 120.0), dt, 20.0, 7.0, 0.7)
    exact = 20.0 + 0.7 * 100.0 * (1.0 - np.exp(-t / 7.0))
    assert np.max(np.abs(y - exact)) < 0.02


def _slab(n: int = 2, size: float = 0.01, thick: float = 1e-3) -> HeatMesh:
    """n x n x 1 steel bricks, top faces FRICTION."""
    xs = np.linspace(0.0, size, n + 1)
    nodes = np.array([(x, y, z) for x in xs for y in xs for z in (0.0, thick)])
    idx = lambda i, j, k: (i * (n + 1) + j) * 2 + k  # noqa: E731
    el = np.array([[idx(i, j, 0), idx(i + 1, j, 0), idx(i + 1, j + 1, 0), idx(i, j + 1, 0),
                    idx(i, j, 1), idx(i + 1, j, 1), idx(i + 1, j + 1, 1), idx(i, j + 1, 1)]
                   for i in range(n) for j in range(n)])
    ne = len(el)
    vol = np.full(ne, (size / n) ** 2 * thick)
    faces = {"FRICTION": np.column_stack([np.arange(ne), np.full(ne, 2)])}
    return HeatMesh(nodes, el, np.full(ne, 45.0), np.full(ne, 7850.0), np.full(ne, 477.0), vol, {"ALL": np.arange(ne)},
                    faces, {"FRICTION": np.full(ne, (size / n) ** 2)}, 1, size / n)


@pytest.mark.ccx
def test_lumped_slab_closed_form(tmp_path):
    """A thin steel slab (Biot 2e-5) under a constant flux with a film on the same face is a lumped body:
    T(t) = Ta + q/h (1 - exp(-t h A / (rho c V))). Same deck writer, runner and reader as heat-path."""
    from cushion_clutch.fe.ccx import run_ccx
    mesh = _slab()
    q, h, ta = 5000.0, 500.0, 20.0
    sched = Schedule((0.0, 1e3), (q, q), (Phase(40.0, 400, 1),), ta)
    run_ccx(write_deck(mesh, sched, {"FRICTION": h}), tmp_path, "slab")
    times, temps = parse_temperatures((tmp_path / "slab.dat").read_text(), len(mesh.nodes))
    tau = 7850.0 * 477.0 * 1e-3 / h
    exact = ta + q / h * (1.0 - np.exp(-times / tau))
    mean = temps.mean(axis=1)
    assert np.max(np.abs(mean - exact)) / (q / h) < 0.01               # backward Euler, dt = tau / 75
    # and the backward-Euler recursion of the lumped body (the rest: the through-thickness gradient)
    be = first_order(np.full_like(times, ta + q / h), np.full_like(times, 0.1), ta, tau, 1.0)
    assert np.max(np.abs(mean - be)) / (q / h) < 2e-3


@pytest.mark.ccx
def test_coarse_heat_path_meets_the_bars(tmp_path, spring):
    from cushion_clutch.fe.heat_path import run_heat_path
    res = run_heat_path(spring, HeatPathParams(), tmp_path, coarse=True, uncertainty=False)
    on_disk = json.loads((tmp_path / "heat_path.json").read_text())
    for key in ("U_W_per_K", "H_W_per_K", "C_J_per_K", "tau_s", "steel_mass_kg", "energy_balance_error",
                "tau_mesh_change"):
        assert on_disk[key] == pytest.approx(res[key])
        assert math.isfinite(res[key])
    lo, hi = (res["steel_mass_kg"] * c for c in STEEL_C_RANGE_J_PER_KG_K)
    assert 0.9 * lo <= res["C_J_per_K"] <= 1.1 * hi
    assert res["energy_balance_error"] < 0.01
    assert res["tau_mesh_change"] < 0.05
    assert 0 < res["tau_s"] < 1e3
    assert res["tau_s"] == pytest.approx(res["C_J_per_K"] / (res["U_W_per_K"] + res["H_W_per_K"]))
    # 16 paddles of 0.42 mm steel on the spring file's sector
    g = spring.geometry
    assert res["steel_mass_kg"] == pytest.approx(2 * spring.n_pairs * 7850 * g.thickness_m * 0.5 * math.radians(
        g.span_deg) * (g.outer_radius_m ** 2 - g.inner_radius_m ** 2), rel=2e-3)
    assert res["ode_rms_error_K"] < 0.1 * res["theta_cs_max_rise_K"]
    assert all(res["checks"].values())
    for f in ("heat_path.png", "heat_path_series.csv", "heat_path_set.toml", "heat_path_numbers.md"):
        assert (tmp_path / f).stat().st_size > 0
    from cushion_clutch.model.thermal_set import load_thermal_set
    s = load_thermal_set(tmp_path / "heat_path_set.toml")
    assert s.tau_s == pytest.approx(res["tau_s"], rel=1e-9)


DOCS = __import__("pathlib").Path(__file__).resolve().parents[1] / "docs"


def test_docs_numbers_are_the_shipped_sets():
    """The docs page's numbers block is what heat-path wrote for the shipped fe_default set."""
    from cushion_clutch.fe.heat_report import numbers_markdown
    from cushion_clutch.model.thermal_set import load_thermal_set, sets_folder
    res = json.loads((sets_folder() / "fe_default.json").read_text())
    text = (DOCS / "explanation" / "heat_path.md").read_text(encoding="utf-8")
    block = text.split("<!-- heat-path numbers: begin -->", 1)[1].split("<!-- heat-path numbers: end -->", 1)[0]
    assert block.strip() == numbers_markdown(res).strip()
    s = load_thermal_set("fe_default")
    assert (s.U_W_per_K, s.H_W_per_K, s.C_J_per_K) == (res["U_W_per_K"], res["H_W_per_K"], res["C_J_per_K"])
    assert s.provenance["commit"] == res["commit"] and not res["coarse"]
    assert all(res["checks"].values())


def test_fmu_default_stays_the_papers_set():
    from cushion_clutch.model.clutch_model import start_values
    from cushion_clutch.model.thermal_set import load_thermal_set
    sv = start_values()
    assert (sv["U"], sv["H"], sv["C"]) == (0.1, 0.04, 1.0)
    assert load_thermal_set("paper").parameters() == {"U": 0.1, "H": 0.04, "C": 1.0}


def test_bad_thermal_set_names_the_key(tmp_path):
    from cushion_clutch.errors import ParameterError
    from cushion_clutch.model.thermal_set import load_thermal_set
    with pytest.raises(ParameterError, match="not found"):
        load_thermal_set("no_such_set")
    bad = tmp_path / "bad.toml"
    bad.write_text('U_W_per_K = -1.0\nH_W_per_K = 0.1\nC_J_per_K = 0.0\nextra = 1\n')
    with pytest.raises(ParameterError) as exc:
        load_thermal_set(bad)
    text = str(exc.value)
    assert "U_W_per_K" in text and "C_J_per_K" in text and "extra" in text


def test_default_scenario_uses_the_fe_set_and_the_tcus_follow(tmp_path):
    from cushion_clutch.errors import ParameterError
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.model.thermal_set import load_thermal_set
    sc = load_scenario(scenario_path("default"))
    fe = load_thermal_set("fe_default")
    assert sc.clutch.spring_thermal == "fe_default" and sc.spring_thermal_set() == fe
    for sec in (sc.observer, sc.tcu_thermal):
        assert (sec.spring_U_W_per_K, sec.spring_H_W_per_K, sec.spring_C_J_per_K) == \
            (fe.U_W_per_K, fe.H_W_per_K, fe.C_J_per_K)
    own = tmp_path / "own.toml"
    own.write_text('extends = "default"\n[clutch]\nspring_thermal = "paper"\n[observer]\nspring_C_J_per_K = 2.0\n')
    sc2 = load_scenario(own)
    assert sc2.spring_thermal_set().C_J_per_K == 1.0 and sc2.observer.spring_C_J_per_K == 2.0
    assert sc2.tcu_thermal.spring_C_J_per_K == 1.0
    own.write_text('extends = "default"\n[clutch]\nspring_thermal = "nope"\n')
    with pytest.raises(ParameterError, match="clutch.spring_thermal"):
        load_scenario(own)


def test_cli_heat_path_bad_input_exits_2(tmp_path, capsys):
    from cushion_clutch.cli import main
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["heat-path", "--out", str(f)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error:") and "--out" in err and "Traceback" not in err
    assert main(["heat-path", "--out", str(tmp_path / "o"), "--spring", str(tmp_path / "missing.toml")]) == 2


@pytest.mark.fmu
def test_native_fmu_takes_the_fe_set_as_start_values(tmp_path):
    """The default FMU declares the paper's U, H, C; given fe_default's as start values, its theta_cs follows
    a step of theta_cm with the set's tau and gain (a start-value set, as the launch plant applies it)."""
    import fmpy
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.model.thermal_set import load_thermal_set
    fmu = build_fmu(DEFAULT_TABLES, tmp_path / "c.fmu", backend="native")
    md = fmpy.read_model_description(str(fmu))
    starts = {v.name: float(v.start) for v in md.modelVariables if v.name in ("U", "H", "C")}
    assert starts == {"U": 0.1, "H": 0.04, "C": 1.0}
    s = load_thermal_set("fe_default")
    res = fmpy.simulate_fmu(str(fmu), stop_time=s.tau_s, output_interval=s.tau_s / 50, fmi_type="CoSimulation",
                            start_values={**s.parameters(), "theta_a": 293.15, "theta_cs_start": 293.15,
                                          "theta_cm": 393.15}, output=["theta_cs"])
    rise = res["theta_cs"][-1] - 293.15
    assert rise == pytest.approx(100.0 * s.gain * (1.0 - math.exp(-1.0)), rel=1e-3)


def test_field_shape_of_a_uniform_rise_is_one(spring):
    """A uniform rise gives the shape 1 everywhere and a carrier-to-paddle ratio of 1; a doubled carrier 2."""
    from cushion_clutch.fe.kiss_field import field_shape
    m = sector_mesh(spring, HeatPathParams(), 8e-3)
    t = np.array([10.0, 20.0, 30.0])
    temps = np.full((3, len(m.nodes)), 50.0)
    centres, shape, kappa = field_shape(m, t, temps, 20.0, (15.0, 30.0))
    assert np.allclose(shape, 1.0) and kappa == pytest.approx(1.0)
    assert centres[:, 0].min() > spring.geometry.inner_radius_m and centres[:, 1].max() < spring.geometry.span_deg
    car = np.unique(m.elements[m.element_sets["CARRIER"]])
    only = np.setdiff1d(car, np.unique(m.elements[m.element_sets["JOINT"]]))
    temps[:, only] = 80.0
    assert field_shape(m, t, temps, 20.0, (15.0, 30.0))[2] == pytest.approx(2.0, rel=0.05)
