"""The native C FMU: compile ``fmu_src/CushionClutch.c`` and pack it with its tables."""
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

from ..fmu_src.clutch_model import OMEGA_SLIP_START, VARIABLES, ClutchParameters
from .build import FMU_SRC, SLAVE, TABLE_FILES, complete_model_description

log = logging.getLogger(__name__)


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
            real.set("start", repr({"x_to": 0.0, "theta_cm": defaults.theta_a,
                                   "omega_slip": OMEGA_SLIP_START}[name]))
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
