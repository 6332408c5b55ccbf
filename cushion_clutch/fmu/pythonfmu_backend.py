"""The pythonfmu backend: the FMI 2.0 Co-Simulation FMU that runs the Python model.

pythonfmu writes the binaries and a bare modelDescription.xml; this module
stages the slave, the shared model modules and the tables, then completes the
description: SI units on every variable (temperatures in K with degC, lengths in m with mm as
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
from ..model.table_format import FMU_FILES
from .constants import BASE_UNITS, PYTHONFMU_SRC, SLAVE, SLAVE_MODULES
from .descriptions import add_display_unit, bounds_attributes, display_unit
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
        add_display_unit(unit, name)             # degC for K, mm for m, as the native FMU's
    cosim = root.find("CoSimulation")
    root.insert(list(root).index(cosim) + 1, units)
    outputs = []
    for index, var in enumerate(root.find("ModelVariables"), start=1):
        real = var.find("Real")
        name = var.get("name")
        if name == clutch_model.TABLE_SET_VARIABLE[0] and var.find("Integer") is not None:
            continue                                            # the table sets' enumeration (table_sets.py)
        if real is None or name not in var_units:
            raise ValueError(f"variable {name!r} has no unit in clutch_model.VARIABLES")
        real.set("unit", var_units[name])
        if display_unit(var_units[name]):
            real.set("displayUnit", display_unit(var_units[name]))
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


def build_python_fmu(tables: Path, output: Path, more_tables: tuple = ()) -> Path:
    """Build the pythonfmu FMU ``output`` carrying the (checked) table set ``tables`` (and ``more_tables``: the
    FMU then carries every set and its enumeration ``spring`` picks one, :mod:`.table_sets`)."""
    from pythonfmu.builder import FmuBuilder

    from .table_sets import carried_sets, enumeration_from_integer, stage_sets, wear_limiting_table
    sets = carried_sets([tables, *more_tables]) if more_tables else ()
    with tempfile.TemporaryDirectory(prefix="cushion_fmu_") as tmp:
        stage = Path(tmp)
        shutil.copy(PYTHONFMU_SRC / f"{SLAVE}.py", stage / f"{SLAVE}.py")
        for module, folder in SLAVE_MODULES.items():
            shutil.copy(folder / module, stage / module)
        (stage / "tables").mkdir()
        for name in FMU_FILES:
            if (tables / name).exists():
                shutil.copy(tables / name, stage / "tables" / name)
        extra = stage_sets(stage, sets)                 # tables_2, ... and table_sets.json (none for one set)
        with _fresh_imports(stage):
            built = FmuBuilder.build_FMU(stage / f"{SLAVE}.py", dest=stage / "out",
                                         project_files=[*(stage / m for m in SLAVE_MODULES), stage / "tables",
                                                        *extra], **FMU_OPTIONS)
        table = wear_limiting_table([tables, *more_tables])
        guard_fmu(Path(built), output,
                  lambda xml: enumeration_from_integer(complete_model_description(xml, table), sets))
    return output
