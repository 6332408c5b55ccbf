"""Build the CushionClutch FMU (FMI 2.0 co-simulation) from a table set.

pythonfmu writes the binaries and a bare modelDescription.xml; this module
stages the slave, the shared model module and the tables, then completes the
description: SI units on every variable (temperatures in K with degC as
display unit) and the ``InitialUnknowns`` that FMI 2.0 requires for outputs.
"""
from __future__ import annotations

import hashlib
import logging
import shutil
import subprocess
import tempfile
import uuid
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from .errors import TableError
from .fmu_src.clutch_model import VARIABLES, ClutchParameters
from .tables import read_tables

log = logging.getLogger(__name__)

REPO = Path(__file__).resolve().parents[1]
FMU_SRC = REPO / "fmu_src"
SLAVE = "CushionClutch"
TABLE_FILES = ("force_deflection.csv", "kiss_point.csv", "metadata.json")

#: unit of each variable (from the shared model module); temperatures get degC as display unit
UNITS = {name: unit for name, _, unit, _ in VARIABLES}
#: SI base-unit exponents of each unit
BASE_UNITS = {
    "m": {"m": "1"}, "K": {"K": "1"}, "N": {"kg": "1", "m": "1", "s": "-2"},
    "N.m": {"kg": "1", "m": "2", "s": "-2"}, "W/K": {"kg": "1", "m": "2", "s": "-3", "K": "-1"},
    "J/K": {"kg": "1", "m": "2", "s": "-2", "K": "-1"}, "1": {},
}

FMU_OPTIONS = dict(needsExecutionTool=False, canHandleVariableCommunicationStepSize=True,
                   canInterpolateInputs=False, canBeInstantiatedOnlyOncePerProcess=False,
                   canGetAndSetFMUstate=True, canSerializeFMUstate=True)


def complete_model_description(xml_text: str) -> str:
    """Add unit definitions, variable units and InitialUnknowns to pythonfmu's XML."""
    root = ET.fromstring(xml_text)
    units = ET.Element("UnitDefinitions")
    for name, base in BASE_UNITS.items():
        unit = ET.SubElement(units, "Unit", name=name)
        ET.SubElement(unit, "BaseUnit", base)
        if name == "K":
            ET.SubElement(unit, "DisplayUnit", name="degC", offset="-273.15")
    cosim = root.find("CoSimulation")
    root.insert(list(root).index(cosim) + 1, units)
    outputs = []
    for index, var in enumerate(root.find("ModelVariables"), start=1):
        real = var.find("Real")
        name = var.get("name")
        if real is None or name not in UNITS:
            raise ValueError(f"variable {name!r} has no unit in fmu_build.UNITS")
        real.set("unit", UNITS[name])
        if UNITS[name] == "K":
            real.set("displayUnit", "degC")
        if var.get("causality") == "output":
            outputs.append(index)
    structure = root.find("ModelStructure")
    for old in structure.findall("InitialUnknowns"):
        structure.remove(old)
    if outputs:
        init = ET.SubElement(structure, "InitialUnknowns")
        for index in outputs:
            ET.SubElement(init, "Unknown", index=str(index))
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def build_fmu(tables: Path, output: Path, backend: str = "python") -> Path:
    """Build ``output`` (.fmu) carrying the table set in ``tables``.

    ``backend`` is ``"python"`` (pythonfmu; needs Python and numpy where it
    runs) or ``"native"`` (C, compiled here with gcc; loads in any FMI host).

    Raises
    ------
    TableError
        If the table set is missing or malformed (checked before building).
    """
    from pythonfmu.builder import FmuBuilder

    tables, output = Path(tables), Path(output)
    read_tables(tables)                                 # fail early, with the file's name
    for name in TABLE_FILES[:2]:
        if not (tables / name).exists():
            raise TableError(f"{tables / name} is missing")
    output.parent.mkdir(parents=True, exist_ok=True)
    if backend == "native":
        return build_native_fmu(tables, output)
    if backend != "python":
        raise ValueError(f"backend = {backend!r}: allowed 'python' or 'native'")
    with tempfile.TemporaryDirectory(prefix="cushion_fmu_") as tmp:
        stage = Path(tmp)
        shutil.copy(FMU_SRC / f"{SLAVE}.py", stage / f"{SLAVE}.py")
        shutil.copy(FMU_SRC / "clutch_model.py", stage / "clutch_model.py")
        (stage / "tables").mkdir()
        for name in TABLE_FILES:
            if (tables / name).exists():
                shutil.copy(tables / name, stage / "tables" / name)
        built = FmuBuilder.build_FMU(stage / f"{SLAVE}.py", dest=stage / "out",
                                     project_files=[stage / "clutch_model.py", stage / "tables"],
                                     **FMU_OPTIONS)
        _rewrite_description(Path(built), output)
    log.info("built %s from tables %s", output, tables)
    return output


def _rewrite_description(src: Path, dst: Path) -> None:
    tmp = dst.with_suffix(".fmu.tmp")
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                data = complete_model_description(data.decode("utf-8")).encode("utf-8")
            zout.writestr(item, data)
    tmp.replace(dst)


FMI2_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")


def fmi2_header_dir() -> Path:
    """The FMI 2.0 standard headers shipped with FMPy."""
    import fmpy
    return Path(fmpy.__file__).parent / "c-code"


def native_model_description(guid: str) -> str:
    """modelDescription.xml of the native FMU: the variables of ``clutch_model.VARIABLES``."""
    defaults = ClutchParameters()
    root = ET.Element("fmiModelDescription", fmiVersion="2.0", modelName=SLAVE, guid=guid,
                      description="Dry-clutch torque T = n*mu*R_eq*F(u_f(x_to, theta_cs), theta_cs) "
                                  "with the cushion-spring thermal ODE; F from CalculiX tables (native C)",
                      generationTool="cushion_clutch fmu_build (native)", variableNamingConvention="flat",
                      numberOfEventIndicators="0")
    cs = ET.SubElement(root, "CoSimulation", modelIdentifier=SLAVE, needsExecutionTool="false",
                       canHandleVariableCommunicationStepSize="true", canInterpolateInputs="false",
                       canBeInstantiatedOnlyOncePerProcess="false", canNotUseMemoryManagementFunctions="true",
                       canGetAndSetFMUstate="true", canSerializeFMUstate="true")
    files = ET.SubElement(cs, "SourceFiles")
    ET.SubElement(files, "File", name=f"{SLAVE}.c")
    cats = ET.SubElement(root, "LogCategories")
    for name in ("logStatusWarning", "logStatusError"):
        ET.SubElement(cats, "Category", name=name)
    variables = ET.SubElement(root, "ModelVariables")
    for vr, (name, causality, unit, desc) in enumerate(VARIABLES):
        attrs = dict(name=name, valueReference=str(vr), description=f"{desc} [{unit}]", causality=causality)
        if causality == "parameter":
            attrs.update(variability="fixed", initial="exact")
        else:
            attrs["variability"] = "continuous"
        var = ET.SubElement(variables, "ScalarVariable", attrs)
        real = ET.SubElement(var, "Real")
        if causality == "input":
            real.set("start", repr({"x_to": 0.0, "theta_cm": defaults.theta_a}[name]))
        elif causality == "parameter":
            real.set("start", repr(float(getattr(defaults, name))))
    structure = ET.SubElement(root, "ModelStructure")
    outputs = ET.SubElement(structure, "Outputs")
    for vr, (_, causality, _, _) in enumerate(VARIABLES):
        if causality == "output":
            ET.SubElement(outputs, "Unknown", index=str(vr + 1))
    return complete_model_description(ET.tostring(root, encoding="unicode"))


def compile_native(dest: Path, extra_flags: tuple[str, ...] = ()) -> Path:
    """Compile ``fmu_src/CushionClutch.c`` into the shared library ``dest`` with gcc."""
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        raise RuntimeError("no C compiler: install gcc (apt-get install -y gcc)")
    cmd = [cc, "-std=c99", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-Wall", "-Wextra",
           *extra_flags, f"-I{fmi2_header_dir()}", str(FMU_SRC / f"{SLAVE}.c"), "-o", str(dest), "-lm"]
    out = subprocess.run(cmd, capture_output=True, text=True)
    if out.returncode != 0:
        raise RuntimeError(f"compiling the native FMU failed:\n{' '.join(cmd)}\n{out.stderr}")
    return dest


def build_native_fmu(tables: Path, output: Path) -> Path:
    """Build the native C FMU: binaries/linux64, sources/, resources/tables, modelDescription.xml."""
    digest = hashlib.sha256()
    for name in TABLE_FILES[:2]:
        digest.update((tables / name).read_bytes())
    digest.update((FMU_SRC / f"{SLAVE}.c").read_bytes())
    guid = "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, "cushion_clutch:" + digest.hexdigest())) + "}"
    with tempfile.TemporaryDirectory(prefix="cushion_native_") as tmp:
        lib = compile_native(Path(tmp) / f"{SLAVE}.so")
        tmp_out = output.with_suffix(".fmu.tmp")
        with zipfile.ZipFile(tmp_out, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", native_model_description(guid))
            z.write(lib, f"binaries/linux64/{SLAVE}.so")
            z.write(FMU_SRC / f"{SLAVE}.c", f"sources/{SLAVE}.c")
            for header in FMI2_HEADERS:
                z.write(fmi2_header_dir() / header, f"sources/{header}")
            for name in TABLE_FILES:
                if (tables / name).exists():
                    z.write(tables / name, f"resources/tables/{name}")
        tmp_out.replace(output)
    log.info("built native %s from tables %s", output, tables)
    return output
