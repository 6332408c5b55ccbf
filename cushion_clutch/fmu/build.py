"""Build the CushionClutch FMU from a table set: the front door for both backends.

:func:`build_fmu` checks the tables and hands over to the native C backend
(:mod:`cushion_clutch.fmu.native`, the default) or to pythonfmu. For the
latter, pythonfmu writes the binaries and a bare modelDescription.xml; this module
stages the slave, the shared model module and the tables, then completes the
description: SI units on every variable (temperatures in K with degC as
display unit) and the ``InitialUnknowns`` that FMI 2.0 requires for outputs.
"""
from __future__ import annotations

import logging
import shutil
import tempfile
from pathlib import Path
from xml.etree import ElementTree as ET

from ..data import fmu_sources
from ..errors import ParameterError, TableError
from ..fe.tables import read_tables
from ..model import VARIABLES, clutch_model
from ..model.table_format import FMU_FILES, REQUIRED_FILES

log = logging.getLogger(__name__)

FMU_SRC = fmu_sources()
SLAVE = "CushionClutch"
#: folder of the numpy-only model modules (:mod:`cushion_clutch.model`)
MODEL_SRC = Path(clutch_model.__file__).parent
#: the modules the pythonfmu slave imports (siblings inside the FMU): the slave class (from ``FMU_SRC``)
#: and the numpy-only model (from ``MODEL_SRC``)
SLAVE_MODULES = {"cushion_slave.py": FMU_SRC, "clutch_model.py": MODEL_SRC, "spring_table.py": MODEL_SRC,
                 "friction.py": MODEL_SRC, "table_format.py": MODEL_SRC}

#: unit of each variable (from the shared model module); temperatures get degC as display unit
UNITS = {name: unit for name, _, unit, _ in VARIABLES}
#: SI base-unit exponents of each unit
BASE_UNITS = {
    "m": {"m": "1"}, "K": {"K": "1"}, "N": {"kg": "1", "m": "1", "s": "-2"},
    "N.m": {"kg": "1", "m": "2", "s": "-2"}, "W/K": {"kg": "1", "m": "2", "s": "-3", "K": "-1"},
    "J/K": {"kg": "1", "m": "2", "s": "-2", "K": "-1"}, "1": {}, "rad/s": {"s": "-1", "rad": "1"},
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


def build_fmu(tables: Path, output: Path, backend: str = "native", fmi_version: int = 2) -> Path:
    """Build ``output`` (.fmu) carrying the table set in ``tables``.

    ``backend`` is ``"native"`` (C; loads in any FMI host; binaries for Windows,
    Linux and macOS; Co-Simulation and Model Exchange) or ``"python"``
    (pythonfmu; FMI 2.0 Co-Simulation; needs Python and numpy where it runs).
    ``fmi_version`` is 2 (FMI 2.0) or 3 (FMI 3.0, native only).

    Raises
    ------
    TableError
        If the table set is missing or malformed (checked before building).
    """
    tables, output = Path(tables), Path(output)
    read_tables(tables)                                 # fail early, with the file's name
    for name in REQUIRED_FILES:
        if not (tables / name).exists():
            raise TableError(f"{tables / name} is missing")
    if fmi_version not in (2, 3):
        raise ParameterError([f"fmi_version = {fmi_version!r}: allowed 2 or 3"])
    output.parent.mkdir(parents=True, exist_ok=True)
    if backend == "native":
        from .native import build_native_fmu
        return build_native_fmu(tables, output, fmi_version=fmi_version)
    if backend != "python":
        raise ValueError(f"backend = {backend!r}: allowed 'python' or 'native'")
    if fmi_version != 2:
        raise ParameterError(["fmi_version = 3 needs backend 'native' (the pythonfmu backend writes FMI 2.0)"])
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
        built = FmuBuilder.build_FMU(stage / f"{SLAVE}.py", dest=stage / "out",
                                     project_files=[*(stage / m for m in SLAVE_MODULES), stage / "tables"],
                                     **FMU_OPTIONS)
        _rewrite_description(Path(built), output)
    log.info("built %s from tables %s", output, tables)
    return output


def _rewrite_description(src: Path, dst: Path) -> None:
    from .guard import guard_fmu
    guard_fmu(src, dst, complete_model_description)


def add_backend(parser) -> None:
    """The ``--backend`` option shared by every command that builds an FMU."""
    parser.add_argument("--backend", choices=("native", "python"), default="native",
                        help="native: C, loads in any FMI host (default); "
                             "python: pythonfmu, needs Python + numpy where it runs")


def add_build_arguments(parser) -> None:
    """Options of ``cushion-clutch build-fmu`` and ``build_fmu.py`` (the same)."""
    from ..data import DEFAULT_TABLES
    parser.add_argument("--tables", type=Path, default=DEFAULT_TABLES,
                        help="table folder (force_deflection.csv, kiss_point.csv, metadata.json)")
    parser.add_argument("-o", "--output", type=Path, default=Path("CushionClutch.fmu"), help="FMU file")
    add_backend(parser)
    parser.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                        help="FMI 2.0 (default) or 3.0 (native backend only); both carry Co-Simulation "
                             "and Model Exchange")


def build_from_args(args) -> str:
    """Build the FMU that parsed ``build-fmu`` options describe; return a one-line report."""
    from ..model.table_format import table_set_x_kiss_ref
    version = getattr(args, "fmi_version", 2)
    out = build_fmu(args.tables, args.output, backend=args.backend, fmi_version=version)
    own = table_set_x_kiss_ref(args.tables)
    kiss = (f"x_kiss_ref = {own * 1e3:.4f} mm (the table set's own kiss point, metadata.json tolerance_study)"
            if own is not None else f"x_kiss_ref = {clutch_model.ClutchParameters().x_kiss_ref * 1e3:.4f} mm (default)")
    return f"built {out} ({args.backend}, FMI {version}.0) from {args.tables}; {kiss}"
