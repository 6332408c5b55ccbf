"""One FMU, several spring table sets chosen by the enumeration parameter ``spring`` (issue 42, item 1):
the declaration (FMI 2 and 3), the bar (set 2 of a two-set FMU = the FMU of set 2 alone, to 1e-9 N*m), the
refusals, the saved state, the GUID, and the CLI."""
from __future__ import annotations

import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from cushion_clutch.cli import main
from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.errors import ParameterError
from cushion_clutch.fmu import table_sets
from cushion_clutch.fmu.native import model_guid
from table_set_builds import scaled_tables, soft_fmu, soft_tables, two_set_fmu

pytestmark = pytest.mark.fmu
POINTS = [(x, T) for x in (0.006, 0.008, 0.009) for T in (20.0, 195.0)]   # m, degC (the bar)


def _torque(fmu, x_to, theta_degC, start=None, kind="CoSimulation"):
    """Torque (N*m) after 0.1 s at a held bearing position (m) with facing and cushion spring at theta_degC."""
    u = np.zeros(2, dtype=[("time", float), ("x_to", float), ("theta_cm", float), ("omega_slip", float)])
    u["time"], u["x_to"], u["theta_cm"] = (0.0, 0.1), x_to, theta_degC + 273.15
    res = simulate_fmu(str(fmu), fmi_type=kind, stop_time=0.1, output_interval=0.05, input=u, output=["torque"],
                       start_values={"theta_cs_start": theta_degC + 273.15, **(start or {})})
    return float(res["torque"][-1])


@pytest.mark.parametrize("version", [2, 3])
def test_the_enumeration_is_declared_with_one_item_per_set(version):
    md = read_model_description(str(two_set_fmu(version)))
    (enum,) = [t for t in md.typeDefinitions if t.name == table_sets.TYPE_NAME]
    assert [(i.name, int(i.value)) for i in enum.items] == [("default", 1), ("soft", 2)]
    assert all(i.description for i in enum.items)
    (spring,) = [v for v in md.modelVariables if v.name == "spring"]
    assert spring.type == "Enumeration" and spring.causality == "parameter" and spring.variability == "fixed"
    assert spring.valueReference == table_sets.vr_spring() and int(spring.start) == 1
    assert validate_fmu(str(two_set_fmu(version))) == []
    with zipfile.ZipFile(two_set_fmu(version)) as z:
        names = z.namelist()
    assert "resources/tables/force_deflection.csv" in names and "resources/tables_2/force_deflection.csv" in names


def test_a_one_set_fmu_declares_no_selector():
    md = read_model_description(str(soft_fmu(2)))
    assert "spring" not in [v.name for v in md.modelVariables] and not md.typeDefinitions
    with zipfile.ZipFile(soft_fmu(2)) as z:
        assert f"resources/{table_sets.MANIFEST}" not in z.namelist()


@pytest.mark.parametrize("version,kind", [(2, "CoSimulation"), (2, "ModelExchange"), (3, "CoSimulation")])
def test_set_2_is_the_fmu_of_set_2_alone(version, kind):
    points = POINTS if (version, kind) == (2, "CoSimulation") else POINTS[::3]
    for x_to, theta in points:
        chosen = _torque(two_set_fmu(version), x_to, theta, {"spring": 2}, kind)
        alone = _torque(soft_fmu(version), x_to, theta, None, kind)
        default = _torque(two_set_fmu(version), x_to, theta, None, kind)
        assert abs(chosen - alone) <= 1e-9, (x_to, theta, chosen, alone)
        assert chosen < 0.95 * default                  # the choice takes effect: set 1 is the stiffer spring


def _slave(fmu):
    md = read_model_description(str(fmu))
    s = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="sets")
    return s, {v.name: v.valueReference for v in md.modelVariables}


def _set_two_then_refuse_a_change(s, vr, capfd) -> None:
    """Choose set 2, initialise, and check that a change of ``spring`` afterwards is refused with its message
    and leaves set 2 chosen."""
    s.setInteger([vr["spring"]], [2])
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    assert s.getInteger([vr["spring"]]) == [2]
    with pytest.raises(FMICallException):
        s.setInteger([vr["spring"]], [1])
    assert "parameter spring (the table set) is fixed after initialization" in capfd.readouterr().out
    assert s.getInteger([vr["spring"]]) == [2]


def test_the_set_is_refused_out_of_range_and_after_initialisation(capfd):
    s, vr = _slave(two_set_fmu(2))
    s.instantiate(loggingOn=False)
    with pytest.raises(FMICallException):
        s.setInteger([vr["spring"]], [3])
    assert "spring = 3: allowed 1..2" in capfd.readouterr().out
    _set_two_then_refuse_a_change(s, vr, capfd)
    s.setReal([vr["x_to"], vr["theta_cm"]], [0.008, 293.15])
    s.doStep(0.0, 0.1)
    state = s.getFMUstate()
    torque = s.getReal([vr["torque"]])
    s.reset()                                           # back to the start values: set 1
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    assert s.getInteger([vr["spring"]]) == [1]
    s.setFMUstate(state)                                # the saved state carries its set
    assert s.getInteger([vr["spring"]]) == [2] and s.getReal([vr["torque"]]) == torque
    s.terminate()
    s.freeInstance()


def test_a_one_set_fmu_has_no_integer_variables(capfd):
    s, vr = _slave(soft_fmu(2))
    s.instantiate(loggingOn=False)
    with pytest.raises(FMICallException):
        s.setInteger([table_sets.vr_spring()], [1])
    assert "the model has Real variables only" in capfd.readouterr().out
    s.freeInstance()


def test_the_guid_covers_every_set(tmp_path):
    soft2 = scaled_tables(tmp_path / "soft", 0.8)
    one = model_guid(DEFAULT_TABLES, 2)
    a = model_guid(DEFAULT_TABLES, 2, sets=table_sets.carried_sets([DEFAULT_TABLES, soft_tables()]))
    b = model_guid(DEFAULT_TABLES, 2, sets=table_sets.carried_sets([DEFAULT_TABLES, soft2]))
    assert len({one, a, b}) == 3
    assert model_guid(DEFAULT_TABLES, 2, sets=()) == one       # a one-set FMU keeps its GUID


def test_carried_sets_names_and_refusals(tmp_path):
    sets = table_sets.carried_sets([DEFAULT_TABLES, soft_tables(), scaled_tables(tmp_path / "9x", 1.1)])
    assert [s.name for s in sets] == ["default", "soft", "set_9x"]
    assert [s.resource for s in sets] == ["tables", "tables_2", "tables_3"]
    with pytest.raises(ParameterError, match="given twice"):
        table_sets.carried_sets([DEFAULT_TABLES, DEFAULT_TABLES])


def test_cli_builds_a_two_set_fmu_and_refuses_thermal(tmp_path, capsys):
    out = tmp_path / "F.fmu"
    assert main(["build-fmu", "--tables", str(DEFAULT_TABLES), "--tables", str(soft_tables()), "-o", str(out)]) == 0
    assert "2 table sets, parameter spring: 1 = default, 2 = soft" in capsys.readouterr().out
    assert read_model_description(str(out)).guid == read_model_description(str(two_set_fmu(2))).guid
    assert main(["build-fmu", "--tables", str(DEFAULT_TABLES), "--tables", str(soft_tables()), "--thermal",
                 "-o", str(tmp_path / "T.fmu")]) == 2
    assert "carries one table set" in capsys.readouterr().err


def _own_kiss(dst, x_kiss_ref_m):
    """The default tables as a tolerance set measured from its own kiss point at ``x_kiss_ref_m`` (m)."""
    import json
    import shutil
    shutil.copytree(DEFAULT_TABLES, dst)
    meta = json.loads((dst / "metadata.json").read_text())
    meta["tolerance_study"] = {"percentile": 95.0, "sample": 3, "x_kiss_ref_m": x_kiss_ref_m}
    (dst / "metadata.json").write_text(json.dumps(meta))
    return dst


@pytest.mark.parametrize("version", [2, 3])
def test_a_set_s_own_kiss_point_moves_with_the_choice(tmp_path, version):
    """Set 2 measured from its own kiss point (4.22 mm against set 1's default 4 mm): chosen, the FMU's kiss
    point is x_kiss_ref + 0.22 mm, as the one-set FMU of that set gives with its own start value; x_kiss_ref
    keeps the value set, and a host's own x_kiss_ref shifts both alike."""
    from cushion_clutch.fmu.build import build_fmu
    p95 = _own_kiss(tmp_path / "p95", 4.22e-3)
    two = build_fmu([DEFAULT_TABLES, p95], tmp_path / "two.fmu", fmi_version=version)
    one = build_fmu(p95, tmp_path / "one.fmu", fmi_version=version)
    (item,) = [i for t in read_model_description(str(two)).typeDefinitions for i in t.items if i.name == "p95"]
    assert "x_kiss_ref +0.2200 mm" in item.description

    def run(fmu, **start):
        res = simulate_fmu(str(fmu), stop_time=0.01, output_interval=0.01, output=["x_kiss", "u_f", "x_kiss_ref"],
                           start_values={"x_to": 5e-3, "theta_cm": 293.15, "release_compliance_m_per_N": 0.0,
                                         **start})
        return res["x_kiss"][-1], res["u_f"][-1], res["x_kiss_ref"][-1]

    chosen, alone = run(two, spring=2), run(one)
    assert chosen[:2] == alone[:2] and chosen[0] == pytest.approx(4.22e-3, abs=1e-9)
    assert chosen[2] == 4e-3 and alone[2] == 4.22e-3                 # x_kiss_ref reads as set
    moved = run(two, spring=2, x_kiss_ref=4.5e-3)
    assert moved[0] == pytest.approx(4.72e-3, abs=1e-9)
    assert run(two)[0] == pytest.approx(4e-3, abs=1e-9)


def test_the_pythonfmu_backend_carries_the_sets_too(capfd):
    """pythonfmu: the same enumeration, set 2 = the native FMU of set 2 alone and the native two-set FMU's set 2
    (a second implementation: the Python model), and a change after initialisation refused with the message."""
    two, alone = two_set_fmu(2, "python"), soft_fmu(2)
    md = read_model_description(str(two))
    (enum,) = md.typeDefinitions
    assert [(i.name, int(i.value)) for i in enum.items] == [("default", 1), ("soft", 2)]
    assert validate_fmu(str(two)) == []
    for x_to, theta in POINTS[::3]:
        chosen = _torque(two, x_to, theta, {"spring": 2})
        assert abs(chosen - _torque(alone, x_to, theta)) <= 1e-9
        assert abs(chosen - _torque(two_set_fmu(2), x_to, theta, {"spring": 2})) <= 1e-9
    s, vr = _slave(two)
    s.instantiate(loggingOn=True)
    _set_two_then_refuse_a_change(s, vr, capfd)
    s.terminate()
    s.freeInstance()
