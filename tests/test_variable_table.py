"""The FMI variable table is written once (clutch_model.VARIABLES): a parameter appended at the end shows up,
with its start value and range, in the generated C table and in both FMUs (native C and pythonfmu)."""
import dataclasses
import json
import re
import shutil
import subprocess
import sys

import pytest
from fmpy import read_model_description

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu import constants
from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.fmu.native import build_native_fmu
from cushion_clutch.fmu.variable_table import enum_name, variable_header
from cushion_clutch.model import clutch_model

EXTRA = ("k_extra", "parameter", "1", "a parameter appended at the end for this test")
EXTRA_START, EXTRA_RANGE = 0.5, (0.0, 1.0, False, False)


def test_header_lists_every_variable_in_value_reference_order():
    text = variable_header()
    body = text[text.index("enum {"):text.index("};")]
    names = [line.strip().rstrip(",") for line in body.splitlines()[1:] if line.strip()]
    assert names == [*(enum_name(n) for n, _, _, _ in clutch_model.VARIABLES), "CC_VR_DER_THETA_CS", "CC_NVARS"]
    starts = clutch_model.start_values()
    for name, causality, unit, _ in clutch_model.VARIABLES:
        row = next(line for line in text.splitlines() if line.startswith(f'    {{"{name}", '))
        assert f"CC_{causality.upper()}, {starts[name]!r}, " in row
        if causality in ("parameter", "input"):
            lo, hi, lo_open, hi_open = {**clutch_model.ClutchParameters.RANGES, **clutch_model.INPUT_RANGES}[name]
            assert row.endswith(f'{{{lo!r}, {hi!r}, {int(lo_open)}, {int(hi_open)}}}, "{unit}"}},')


def test_a_parameter_without_a_range_is_refused(monkeypatch):
    monkeypatch.setattr(clutch_model, "VARIABLES", clutch_model.VARIABLES + (EXTRA,))
    monkeypatch.setattr(clutch_model, "ClutchParameters", _params_with_extra(ranged=False))
    with pytest.raises(ValueError, match="k_extra: no range"):
        variable_header()


def _params_with_extra(ranged=True):
    cls = dataclasses.make_dataclass("ClutchParameters", [(EXTRA[0], float, EXTRA_START)],
                                     bases=(clutch_model.ClutchParameters,))
    cls.RANGES = dict(clutch_model.ClutchParameters.RANGES, **({EXTRA[0]: EXTRA_RANGE} if ranged else {}))
    return cls


@pytest.fixture(scope="module")
def extended_fmus(tmp_path_factory):
    """Both FMUs built from a model whose VARIABLES end with EXTRA (this process and the pythonfmu copy)."""
    tmp = tmp_path_factory.mktemp("extended")
    model_src = tmp / "model"
    model_src.mkdir()
    for module, folder in constants.SLAVE_MODULES.items():
        if folder == constants.MODEL_SRC:
            shutil.copy(folder / module, model_src / module)
    text = (model_src / "clutch_model.py").read_text()
    # the last row of the table (the line before the closing parenthesis of VARIABLES)
    head, rest = text.split("\nVARIABLES = (\n", 1)
    rows, tail = rest.split("\n)\n", 1)
    text = head + "\nVARIABLES = (\n" + rows + f"\n    {EXTRA!r},\n)\n" + tail
    field = [line for line in text.splitlines() if line.startswith("    lever_ratio: float = ")][0]
    text = text.replace(field, field + f"\n    {EXTRA[0]}: float = {EXTRA_START!r}")
    text = text.replace('        "lever_ratio": (0.0, 100.0, True, False),\n',
                        f'        "lever_ratio": (0.0, 100.0, True, False),\n        "{EXTRA[0]}": {EXTRA_RANGE!r},\n')
    assert text.count(EXTRA[0]) == 3
    (model_src / "clutch_model.py").write_text(text)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(clutch_model, "VARIABLES", clutch_model.VARIABLES + (EXTRA,))
        mp.setattr(clutch_model, "ClutchParameters", _params_with_extra())
        mp.setitem(constants.SLAVE_MODULES, "clutch_model.py", model_src)
        fmus = {"native": build_native_fmu(DEFAULT_TABLES, tmp / "native.fmu", 2, platforms=("linux64",)),
                "python": build_fmu(DEFAULT_TABLES, tmp / "python.fmu", backend="python")}
    return {k: (p, read_model_description(str(p))) for k, p in fmus.items()}


#: run in a fresh interpreter: a pythonfmu FMU imports its model modules into the host process, where
#: another FMU's (the default model's) may already sit
RUN = """
import json, sys
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
path, value = sys.argv[1], float(sys.argv[2])
md = read_model_description(path)
vr = {v.name: v.valueReference for v in md.modelVariables}
s = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
              instanceName="extended")
s.instantiate(loggingOn=True)
s.setupExperiment(startTime=0.0)
s.setReal([vr["k_extra"]], [value])
s.enterInitializationMode()
try:
    s.exitInitializationMode()   # native: fmi2Error on a bad parameter; pythonfmu: refused, the step discarded
    s.setReal([vr["x_to"]], [0.0055])
    s.doStep(0.0, 0.1)
    out = {"k_extra": s.getReal([vr["k_extra"]])[0], "torque": s.getReal([vr["torque"]])[0]}
except FMICallException as exc:
    out = {"refused": str(exc)}
print(json.dumps(out))
"""


def _run(fmu, value):
    res = subprocess.run([sys.executable, "-c", RUN, str(fmu[0]), repr(value)], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    return json.loads(res.stdout.strip().splitlines()[-1]), res.stdout + res.stderr


@pytest.mark.fmu
@pytest.mark.parametrize("backend", ["native", "python"])
def test_appended_parameter_is_exposed(extended_fmus, backend):
    md = extended_fmus[backend][1]
    var = {v.name: v for v in md.modelVariables}[EXTRA[0]]
    assert (var.valueReference, var.causality, var.variability, var.unit) == (
        len(clutch_model.VARIABLES), "parameter", "fixed", "1")
    assert float(var.start) == EXTRA_START
    names = [v.name for v in md.modelVariables]
    assert names[:len(clutch_model.VARIABLES) + 1] == [*(n for n, _, _, _ in clutch_model.VARIABLES), EXTRA[0]]
    out, log = _run(extended_fmus[backend], 0.75)
    assert out.get("k_extra") == 0.75, log
    assert out["torque"] > 0.0


@pytest.mark.fmu
@pytest.mark.parametrize("backend", ["native", "python"])
def test_appended_parameter_range_is_checked(extended_fmus, backend):
    out, log = _run(extended_fmus[backend], 1.5)
    assert "refused" in out, log
    assert re.search("discard|error", out["refused"], re.I), out
    assert "k_extra" in log and "1.5" in log


@pytest.mark.fmu
def test_native_description_puts_the_derivative_after_the_appended_parameter(extended_fmus):
    md = extended_fmus["native"][1]
    der = {v.name: v for v in md.modelVariables}["der(theta_cs)"]
    assert der.valueReference == len(clutch_model.VARIABLES) + 1
    assert [d.variable.name for d in md.derivatives] == ["der(theta_cs)"]


# ---------------------------------------------------------------- one range table (issue 44 item 2, issue 39)
def _docs_rows():
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).parents[1] / "docs" / "_ext"))
    try:
        import fmu_variables
    finally:
        sys.path.pop(0)
    return {row[0]: row for row in fmu_variables._rows()}


def _numbers(text: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?", text)]


@pytest.mark.fmu
def test_the_docs_allowed_column_states_every_declared_min_and_max():
    """The FMU-variables page's "allowed" cell of every variable that the built default FMU declares with a min and
    a max holds both numbers (the page and the modelDescription read the same range table), and no legacy limit
    constant is left."""
    from native_builds import native_fmus
    rows = _docs_rows()
    md = read_model_description(str(native_fmus()[2]))
    declared = [v for v in md.modelVariables if v.min is not None and v.max is not None]
    assert len(declared) >= 30
    for v in declared:
        cell = rows[v.name][4]
        assert float(v.min) in _numbers(cell) and float(v.max) in _numbers(cell), (v.name, cell, v.min, v.max)
    assert not hasattr(clutch_model, "X_TO_LIMIT") and not hasattr(clutch_model, "THETA_CM_LIMIT")
    assert rows["x_to"][4] == "[-0.002, 0.025]" and rows["theta_cm"][4] == "[200, 800]"


@pytest.mark.fmu
def test_facing_wear_declares_what_initialisation_accepts():
    """facing_wear's declared max is the default cover's wear limit (at most 2.4 mm): the native FMU initialises
    with it and refuses 2 um more with the wear-limit message."""
    import math

    from fmpy import extract
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import FMU2Slave

    from native_builds import native_fmus
    fmu = native_fmus()[2]
    md = read_model_description(str(fmu))
    wear = next(v for v in md.modelVariables if v.name == "facing_wear")
    top = float(wear.max)
    assert 0.002 < top <= 0.0024 and "wear limit" in wear.description
    unzip = extract(str(fmu))
    try:
        for value, ok in ((top, True), (top + 2e-6, False)):
            s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                          instanceName="wear")
            s.instantiate()
            s.setupExperiment(startTime=0.0)
            s.setReal([wear.valueReference], [value])
            s.enterInitializationMode()
            if ok:
                s.exitInitializationMode()
            else:
                with pytest.raises(FMICallException):
                    s.exitInitializationMode()
            s.freeInstance()
    finally:
        shutil.rmtree(unzip, ignore_errors=True)
    assert math.isclose(top, clutch_model.facing_wear_max(clutch_model.SpringTable.from_dir(DEFAULT_TABLES)))


#: the value references of the model's variables as released (clutch_model.VARIABLES' order): a new variable is
#: appended, so none of these may move (hosts and SSP files store them)
PINNED_VRS = {
    "x_to": 0, "theta_cm": 1, "torque": 2, "force": 3, "theta_cs": 4, "u_f": 5, "x_kiss": 6, "n_surfaces": 7,
    "mu": 8, "R_eq": 9, "U": 10, "H": 11, "C": 12, "theta_a": 13, "theta_cs_start": 14, "x_kiss_ref": 15,
    "lever_ratio": 16, "omega_slip": 17, "clamp_force": 18, "bearing_force": 19, "facing_wear": 20,
    "diaphragm_outer_radius_m": 21, "diaphragm_inner_radius_m": 22, "diaphragm_thickness_m": 23,
    "diaphragm_cone_height_m": 24, "diaphragm_youngs_modulus_Pa": 25, "diaphragm_modulus_drop_per_K": 26,
    "diaphragm_poisson_ratio": 27, "pressure_plate_radius_m": 28, "fulcrum_radius_m": 29,
    "installed_deflection_m": 30, "release_compliance_m_per_N": 31, "facing_thickness_m": 32,
    "facing_expansion_per_K": 33, "pressure_plate_thickness_m": 34, "pressure_plate_expansion_per_K": 35,
    "flywheel_length_m": 36, "flywheel_expansion_per_K": 37, "reference_temperature_K": 38,
    "facing_damage_temperature_K": 39, "validity": 40,
}
#: the cover's parameter enum as released (cushion_cover.h, CoverParameters' field order)
PINNED_CV = ["diaphragm_outer_radius_m", "diaphragm_inner_radius_m", "diaphragm_thickness_m",
             "diaphragm_cone_height_m", "diaphragm_youngs_modulus_Pa", "diaphragm_modulus_drop_per_K",
             "diaphragm_poisson_ratio", "pressure_plate_radius_m", "fulcrum_radius_m", "installed_deflection_m",
             "release_compliance_m_per_N", "facing_thickness_m", "facing_expansion_per_K",
             "pressure_plate_thickness_m", "pressure_plate_expansion_per_K", "flywheel_length_m",
             "flywheel_expansion_per_K", "reference_temperature_K"]
COVER_EXTRA = ("k_cover_extra", "parameter", "1", "a cover parameter appended at the end for this test")


def _enum(text: str, first: str) -> list[str]:
    """The constants of the C enum of ``text`` that begins with ``first``."""
    body = text[text.index(first):]
    return [c.strip() for c in body[:body.index("}")].split(",") if c.strip()]


def _value_references(text: str) -> dict[str, int]:
    return {name: k for k, name in enumerate(_enum(text, enum_name("x_to")))}


def _cover_vrs(text: str) -> list[str]:
    line = next(line for line in text.splitlines() if line.startswith("static const int CC_COVER_VR[]"))
    return [c.strip() for c in line[line.index("{") + 1:line.index("}")].split(",")]


def test_released_value_references_and_cover_numbers_do_not_move():
    """Every variable keeps its released value reference (the FMU's and the thermal FMU's, whose own follow),
    the cover's enum keeps its numbers, and CC_COVER_VR maps each cover parameter to its variable."""
    from cushion_clutch.fmu.thermal_chain import chain_of, thermal_header
    from cushion_clutch.fmu.variable_table import cover_enum_name, cover_header
    for text in (variable_header(), thermal_header(chain_of())):
        vrs = _value_references(text)
        assert {n: vrs[enum_name(n)] for n in PINNED_VRS} == PINNED_VRS
        assert _cover_vrs(text) == [enum_name(n) for n in PINNED_CV]
    assert _enum(cover_header(), "CV_") == [*(cover_enum_name(n) for n in PINNED_CV), "CV_NPAR"]


@pytest.fixture
def cover_extended(monkeypatch):
    """The model with one cover parameter appended: to CoverParameters (with a range) and to VARIABLES."""
    ext = dataclasses.make_dataclass("CoverParameters", [(COVER_EXTRA[0], float, 1.0)],
                                     bases=(clutch_model.CoverParameters,), frozen=True)
    starts = clutch_model.start_values()                 # the released model's, before the patch
    monkeypatch.setattr(clutch_model, "CoverParameters", ext)
    monkeypatch.setattr(clutch_model, "VARIABLES", clutch_model.VARIABLES + (COVER_EXTRA,))
    monkeypatch.setattr(clutch_model.ClutchParameters, "RANGES",
                        dict(clutch_model.ClutchParameters.RANGES, **{COVER_EXTRA[0]: (0.0, 2.0, False, False)}))
    monkeypatch.setattr(clutch_model, "start_values", lambda p=None: {**starts, COVER_EXTRA[0]: 1.0})


def test_an_appended_cover_parameter_moves_no_number_and_the_core_compiles(cover_extended, tmp_path):
    """A cover parameter appended to the dataclass and to VARIABLES: every released value reference and cover
    number stays, the new one is the last of each, CC_COVER_VR names its variable, and the C core (which reads the
    cover through CC_COVER_VR) compiles against the generated headers."""
    from cushion_clutch.data import fmu_source
    from cushion_clutch.fmu.variable_table import COVER_HEADER, HEADER, cover_enum_name, cover_header
    text, cover = variable_header(), cover_header()
    vrs = _value_references(text)
    assert {n: vrs[enum_name(n)] for n in PINNED_VRS} == PINNED_VRS
    assert vrs[enum_name(COVER_EXTRA[0])] == len(PINNED_VRS)
    assert _cover_vrs(text) == [*(enum_name(n) for n in PINNED_CV), enum_name(COVER_EXTRA[0])]
    assert _enum(cover, "CV_") == [*(cover_enum_name(n) for n in (*PINNED_CV, COVER_EXTRA[0])), "CV_NPAR"]
    for name in (*constants.CORE_HEADERS, *constants.CORE_SOURCES):
        shutil.copy(fmu_source(name), tmp_path / name)
    (tmp_path / HEADER).write_text(text)
    (tmp_path / COVER_HEADER).write_text(cover)
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc is not available")
    res = subprocess.run([gcc, "-std=c99", "-Wall", "-Werror", "-c", f"-I{tmp_path}",
                          *(str(tmp_path / f) for f in constants.CORE_SOURCES)], cwd=tmp_path, capture_output=True,
                         text=True)
    assert res.returncode == 0, res.stderr


def test_a_cover_parameter_missing_from_variables_is_refused(monkeypatch):
    ext = dataclasses.make_dataclass("CoverParameters", [(COVER_EXTRA[0], float, 1.0)],
                                     bases=(clutch_model.CoverParameters,), frozen=True)
    monkeypatch.setattr(clutch_model, "CoverParameters", ext)
    with pytest.raises(ValueError, match="cover parameter k_cover_extra: not a parameter of VARIABLES"):
        variable_header()
