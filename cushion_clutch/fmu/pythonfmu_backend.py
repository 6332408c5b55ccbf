"""The pythonfmu backend: the FMI 2.0 Co-Simulation FMU that runs the Python model.

pythonfmu writes the binaries and a bare modelDescription.xml; this module
stages the slave, the shared model modules and the tables, then completes the
description: SI units on every variable (temperatures in K with degC as
display unit) and the ``InitialUnknowns`` that FMI 2.0 requires for outputs.
The guard library (:mod:`.guard`) goes in front of pythonfmu's wrapper.
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path
from xml.etree import ElementTree as ET

from ..model import clutch_model
from ..model.api import load_table
from ..model.table_format import FMU_FILES
from .constants import BASE_UNITS, FMU_SRC, SLAVE, SLAVE_MODULES
from .descriptions import bounds_attributes
from .guard import guard_fmu

FMU_OPTIONS = dict(needsExecutionTool=False, canHandleVariableCommunicationStepSize=True,
                   canInterpolateInputs=False, canBeInstantiatedOnlyOncePerProcess=False,
                   canGetAndSetFMUstate=True, canSerializeFMUstate=True)


def complete_model_description(xml_text: str, table=None) -> str:
    """Add unit definitions, variable units, min/max/nominal (``table``: the FMU's SpringTable, for facing_wear's
    declared max) and InitialUnknowns to pythonfmu's XML."""
    root = ET.fromstring(xml_text)
    bounds = clutch_model.variable_bounds(table)
    var_units = {name: unit for name, _, unit, _ in clutch_model.VARIABLES}   # temperatures: degC displayed
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
        if real is None or name not in var_units:
            raise ValueError(f"variable {name!r} has no unit in clutch_model.VARIABLES")
        real.set("unit", var_units[name])
        if var_units[name] == "K":
            real.set("displayUnit", "degC")
        for key, value in bounds_attributes(name, bounds).items():     # min, max, nominal (issue 28)
            real.set(key, value)
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


@contextmanager
def _fresh_imports(stage: Path):
    """pythonfmu imports the staged slave in this process: let it import the staged modules (not ones
    cached by an earlier build), and leave ``sys.modules`` and ``sys.path`` as they were afterwards."""
    names = [Path(m).stem for m in (f"{SLAVE}.py", *SLAVE_MODULES)]
    saved = {n: sys.modules.pop(n) for n in names if n in sys.modules}
    path = list(sys.path)
    try:
        yield
    finally:
        for n in names:
            sys.modules.pop(n, None)
        sys.modules.update(saved)
        sys.path[:] = path


def build_python_fmu(tables: Path, output: Path) -> Path:
    """Build the pythonfmu FMU ``output`` carrying the (checked) table set ``tables``."""
    from pythonfmu.builder import FmuBuilder
    with tempfile.TemporaryDirectory(prefix="cushion_fmu_") as tmp:
        stage = Path(tmp)
        shutil.copy(FMU_SRC / f"{SLAVE}.py", stage / f"{SLAVE}.py")
        for module, folder in SLAVE_MODULES.items():
            shutil.copy(folder / module, stage / module)
        (stage / "tables").mkdir()
        for name in FMU_FILES:
            if (tables / name).exists():
                shutil.copy(tables / name, stage / "tables" / name)
        with _fresh_imports(stage):
            built = FmuBuilder.build_FMU(stage / f"{SLAVE}.py", dest=stage / "out",
                                         project_files=[*(stage / m for m in SLAVE_MODULES), stage / "tables"],
                                         **FMU_OPTIONS)
        table = load_table(tables)
        guard_fmu(Path(built), output, lambda xml: complete_model_description(xml, table))
    return output
