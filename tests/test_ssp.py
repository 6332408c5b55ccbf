"""The SSP archive (issue 42, items 2 and 3): export-ssp's SSD and SSVs validate against FMPy's SSP 1.0 schemas,
FMPy's reader reads them, a run with each parameter set equals the plain FMU run with the same start values, and
the import into ClutchParameters (and simulate/launch --fmu X.ssp) refuses bad names and values with the name
and the range."""
from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.ssp.ssd import read_ssd, read_ssv

from cushion_clutch.cli import main
from cushion_clutch.errors import ParameterError
from cushion_clutch.fmu import ssp
from cushion_clutch.model import ClutchParameters, clutch_model
from cushion_clutch.model.ssv import load_parameters, ssp_parameter_set, ssp_parameter_sets, ssv_parameters
from cushion_clutch.parameter_sets import load_set, shipped_sets
from table_set_builds import two_set_fmu

pytestmark = pytest.mark.fmu


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    return ssp.export_ssp(tmp_path_factory.mktemp("ssp") / "C.ssp", two_set_fmu(2))


def _ssv(path, name):
    return ssp_parameter_set(path, name)


def test_every_file_validates_and_fmpy_reads_it(archive):
    with zipfile.ZipFile(archive.path) as z:
        names = z.namelist()
        assert names[0] == ssp.SSD_FILE and ssp.FMU_FILE in names
        assert ssp.validate(z.read(ssp.SSD_FILE), "SystemStructureDescription.xsd") == []
        ssvs = [n for n in names if n.endswith(".ssv")]
        for n in ssvs:
            assert ssp.validate(z.read(n), "SystemStructureParameterValues.xsd") == [], n
    expected = {f"resources/parameters/{s}.ssv" for s in
                ("new", "worn_1mm", "worn_2mm", "thermal_fe_default", "thermal_paper", "spring_default",
                 "spring_soft")}
    assert expected <= set(ssvs)
    ssd = read_ssd(str(archive.path), validate=True)
    (clutch,) = ssd.system.elements
    assert clutch.name == ssp.COMPONENT and clutch.source == ssp.FMU_FILE
    assert [b.source for b in clutch.parameterBindings] == ["resources/parameters/new.ssv"]
    worn = {p.name: p for p in read_ssv(str(archive.path), resource="resources/parameters/worn_1mm.ssv").parameters}
    assert worn["facing_wear"].type == "Real" and float(worn["facing_wear"].value) == 0.001   # the bar
    assert worn["facing_wear"].unit == "m"


def test_every_value_carries_its_unit_and_every_unit_is_defined(archive):
    units = {n: u for n, c, u, _ in clutch_model.VARIABLES if c == "parameter"}
    for name in ssp_parameter_sets(archive.path):
        ps = read_ssv(str(archive.path), resource=f"resources/parameters/{name}.ssv")
        reals = [p for p in ps.parameters if p.type == "Real"]
        assert {p.name for p in reals} == set(units)            # every FMU parameter, by name
        assert all(p.unit == units[p.name] for p in reals)
        text = _ssv(archive.path, name).decode()
        assert all(f'<ssc:Unit name="{u}">' in text for u in {p.unit for p in reals})


def test_the_shipped_sets_are_data():
    sets = {s.name: s for s in shipped_sets()}
    assert {"new", "worn_1mm", "worn_2mm", "thermal_paper", "thermal_fe_default"} <= set(sets)
    assert dict(sets["worn_1mm"].values) == {"facing_wear": 0.001}
    assert sets["worn_2mm"].parameters().facing_wear == 0.002


def test_a_bad_set_file_names_key_and_range(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\nkind = "wear"\ndescription = "d"\ncolour = 1\n[parameters]\nfacing_wear = 0.01\n'
                   'mu_max = 2.0\n')
    with pytest.raises(ParameterError) as e:
        load_set(bad)
    text = str(e.value)
    assert "unknown key 'colour'" in text and "'mu_max' is not an FMU parameter" in text


def _run(fmu, start):
    """Torque, clamp force and theta_cs over a bearing ramp at 150 degC facing (fmpy, CS)."""
    t = np.linspace(0.0, 2.0, 5)
    u = np.zeros(t.size, dtype=[("time", float), ("x_to", float), ("theta_cm", float), ("omega_slip", float)])
    u["time"], u["x_to"], u["theta_cm"] = t, 0.004 + 0.003 * t, 423.15
    res = simulate_fmu(str(fmu), stop_time=2.0, output_interval=0.1, input=u, start_values=start,
                       output=["torque", "clamp_force", "theta_cs"])
    return np.column_stack([res[k] for k in ("torque", "clamp_force", "theta_cs")])


def test_a_run_with_each_set_equals_the_plain_fmu_with_the_same_start_values(archive, tmp_path):
    fmu = ssp.fmu_of(archive.path, tmp_path)
    runs = {}
    for name in ssp_parameter_sets(archive.path):
        ps = read_ssv(str(archive.path), resource=f"resources/parameters/{name}.ssv")       # fmpy's reader
        items = {"default": 1, "soft": 2}
        start = {p.name: (items[p.value] if p.type == "Enumeration" else float(p.value)) for p in ps.parameters}
        from cushion_clutch.model.thermal_set import load_thermal_set
        plain = {"worn_1mm": {"facing_wear": 0.001}, "worn_2mm": {"facing_wear": 0.002},
                 "spring_soft": {"spring": 2},
                 "thermal_fe_default": load_thermal_set("fe_default").parameters()}.get(name, {})
        runs[name] = _run(fmu, start)
        assert np.array_equal(runs[name], _run(two_set_fmu(2), plain)), name
    assert not np.array_equal(runs["worn_2mm"], runs["new"])
    assert not np.array_equal(runs["spring_soft"], runs["new"])
    assert np.array_equal(runs["thermal_paper"], runs["new"])     # the paper's set is the FMU's default
    assert not np.array_equal(runs["thermal_fe_default"], runs["new"])      # the FE's heat path: slower, hotter


def test_ssv_into_clutch_parameters(archive):
    p = load_parameters(archive.path, "worn_1mm")
    assert p == ClutchParameters(facing_wear=0.001)
    with pytest.raises(ParameterError, match="give the parameter set"):
        load_parameters(archive.path)
    with pytest.raises(ParameterError, match="no parameter set 'worn_9mm'"):
        load_parameters(archive.path, "worn_9mm")


def test_ssv_refuses_unknown_names_units_and_out_of_range_values(archive):
    text = _ssv(archive.path, "worn_1mm").decode()
    bad = (text.replace('name="facing_wear">\n      <ssv:Real value="0.001"', 'name="facing_wear">\n      '
                        '<ssv:Real value="0.009"')
               .replace('<ssv:Parameter name="mu">', '<ssv:Parameter name="mu_static">')
               .replace('<ssv:Real value="0.089" unit="m"', '<ssv:Real value="89.0" unit="mm"'))
    with pytest.raises(ParameterError) as e:
        ssv_parameters(bad.encode(), where="bad.ssv")
    text = str(e.value)
    assert "unknown parameter 'mu_static'" in text and "R_eq in unit 'mm': the FMU's unit is 'm'" in text
    only_range = _ssv(archive.path, "worn_1mm").decode().replace('value="0.001"', 'value="0.009"')
    with pytest.raises(ParameterError, match=r"facing_wear = 0.009 is out of range \[0, 0.004\]"):
        ssv_parameters(only_range.encode())


def test_export_ssp_cli_and_simulate_with_a_parameter_set(archive, tmp_path, capsys):
    out = tmp_path / "D.ssp"
    assert main(["export-ssp", "--fmu", str(two_set_fmu(2)), "-o", str(out)]) == 0
    said = capsys.readouterr().out
    assert "SSD and 7 SSV parameter sets validated" in said and "spring: 1 = default, 2 = soft" in said
    assert main(["export-ssp", "--fmu", str(two_set_fmu(2)), "-o", str(tmp_path / "D.zip")]) == 2
    assert "must end in .ssp" in capsys.readouterr().err
    assert main(["simulate", "--fmu", str(out), "--parameter-set", "spring_soft", "--engagements", "1",
                 "--out", str(tmp_path / "sim")]) == 0
    soft = np.loadtxt(tmp_path / "sim" / "engagements.csv", delimiter=",", skiprows=1)
    assert main(["simulate", "--fmu", str(out), "--engagements", "1", "--out", str(tmp_path / "sim_new")]) == 0
    new = np.loadtxt(tmp_path / "sim_new" / "engagements.csv", delimiter=",", skiprows=1)
    assert soft[:, 3].max() < 0.95 * new[:, 3].max()       # torque: the soft set (forces x 0.9) was simulated
    capsys.readouterr()
    assert main(["simulate", "--fmu", str(out), "--parameter-set", "worn_9mm", "--out", str(tmp_path / "x")]) == 2
    assert "no parameter set 'worn_9mm'" in capsys.readouterr().err
    assert main(["simulate", "--parameter-set", "worn_1mm", "--out", str(tmp_path / "y")]) == 2
    assert "needs --fmu with an .ssp" in capsys.readouterr().err


def test_launch_plant_start_values_keep_the_set_and_the_scenarios_duty():
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import plant_start_values
    sc = load_scenario(scenario_path("wear"))
    start = plant_start_values({"mu": 0.3, "x_kiss_ref": 0.0041, "facing_wear": 0.001, "spring": 2},
                               {"theta_a": 300.0, "theta_cs_start": 310.0}, 0.004, sc)
    assert start["spring"] == 2 and start["mu"] == 0.3 and start["theta_a"] == 300.0
    assert start["facing_wear"] == sc.clutch.facing_wear_m          # the scenario states a wear: it wins
    assert start["x_kiss_ref"] == pytest.approx(0.0041 + sc.clutch.x_kiss_offset_m, abs=0)


def test_layout_constants_match_the_files(archive):
    assert Path(ssp.FMU_FILE).name == "CushionClutch.fmu"
    assert {f"resources/parameters/{n}.ssv" for n, _ in archive.sets} <= set(archive.files)


def test_the_reference_page_s_measured_block_is_today_s():
    """docs/reference/ssp.md's generated block (the dialog view, the layout, a run per set) equals a fresh
    render from the same two-set FMU: a stale page fails here."""
    from cushion_clutch.fmu import ssp_doc
    assert ssp_doc.generated_block() == ssp_doc.render(two_set_fmu(2)), \
        "docs/reference/ssp.md is stale: python -m cushion_clutch.fmu.ssp_doc"


def test_bind_chooses_the_set_the_ssd_binds(tmp_path, capsys):
    out = tmp_path / "W.ssp"
    assert main(["export-ssp", "--fmu", str(two_set_fmu(2)), "--bind", "worn_1mm", "-o", str(out)]) == 0
    (clutch,) = read_ssd(str(out)).system.elements
    assert [b.source for b in clutch.parameterBindings] == ["resources/parameters/worn_1mm.ssv"]
    capsys.readouterr()
    assert main(["export-ssp", "--fmu", str(two_set_fmu(2)), "--bind", "worn_9mm", "-o", str(out)]) == 2
    assert "--bind worn_9mm: no such parameter set" in capsys.readouterr().err
