"""``cushion-clutch export-ssp``: the clutch FMU with its parameter sets as an SSP 1.0 archive (issue 42).

Layout of the ``.ssp`` (a zip; docs/reference/ssp.md)::

    SystemStructure.ssd                  the system: one component "clutch", its connectors wired to the system's
    resources/CushionClutch.fmu          the clutch FMU (native; one or several table sets)
    resources/parameters/<set>.ssv       one SSV parameter set per wear state and thermal set
                                         (cushion_clutch/parameter_sets/*.toml) and per table set the FMU carries
                                         (spring_<item>.ssv); new.ssv is bound to the component in the SSD

Every SSV binds every FMU parameter by name, as ssv:Real with its unit (ssv:Units defines each unit by its SI
base units), starting from the FMU's own start values (its modelDescription) and changing what the set
changes; a multi-set FMU's SSVs also bind the enumeration ``spring`` (ssv:Enumeration with the item names in
ssv:Enumerations). The SSD and every SSV are validated against the SSP 1.0 schemas shipped with FMPy before
the archive is written (:func:`validate`; lxml), and the archive is written whole or not at all.
"""
from __future__ import annotations

import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

from ..errors import FmuError
from ..model import clutch_model
from ..model.ssv import NS as SSV_NS
from ..model.ssv import SSV_FOLDER
from .constants import BASE_UNITS, SLAVE
from .table_sets import fmu_sets

SSD_NS = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC, SSV = SSV_NS["ssc"], SSV_NS["ssv"]
SSD_FILE = "SystemStructure.ssd"
FMU_FILE = f"resources/{SLAVE}.fmu"
COMPONENT = "clutch"
#: the parameter set bound to the component in the SSD (the FMU's start values)
DEFAULT_SET = "new"
for _prefix, _uri in (("ssd", SSD_NS), ("ssc", SSC), ("ssv", SSV)):
    ET.register_namespace(_prefix, _uri)


@dataclass(frozen=True)
class ParameterSetFile:
    """One SSV of the archive: its set ``name``, ``description``, the values (FMU name -> float, in the FMU's
    units) and the table-set item it chooses (None: the FMU's start)."""

    name: str
    description: str
    values: tuple[tuple[str, float], ...]
    spring: str | None = None

    @property
    def path(self) -> str:
        return f"{SSV_FOLDER}/{self.name}.ssv"


def _q(ns: str, tag: str) -> str:
    return f"{{{ns}}}{tag}"


def fmu_interface(fmu: Path) -> tuple[dict[str, tuple[str, str, float | None]], str]:
    """The FMU's variables, name -> (causality, unit, start), and its FMI version ("2.0" or "3.0")."""
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    version = root.get("fmiVersion")
    out = {}
    for v in root.find("ModelVariables"):
        typed = v.find("Real") if v.tag == "ScalarVariable" else v
        if typed is None or typed.tag not in ("Real", "Float64"):
            continue
        start = typed.get("start")
        out[v.get("name")] = (v.get("causality"), typed.get("unit", "1"), None if start is None else float(start))
    return out, version


def parameter_files(fmu: Path) -> list[ParameterSetFile]:
    """The archive's parameter sets for ``fmu``: each shipped wear and thermal set, then each table set it carries.

    Raises
    ------
    FmuError
        The FMU lacks a parameter a set names.
    """
    from ..parameter_sets import shipped_sets
    variables, _ = fmu_interface(fmu)
    starts = {n: s for n, (c, _, s) in variables.items() if c == "parameter"}
    sets = fmu_sets(fmu)
    multi = len(sets) > 1
    out = []
    for named in shipped_sets():
        missing = [k for k, _ in named.values if k not in starts]
        if missing:
            raise FmuError(f"{fmu}: no parameter {', '.join(missing)} (parameter set {named.name})")
        values = dict(starts, **dict(named.values))
        out.append(ParameterSetFile(named.name, named.description, tuple(values.items()),
                                    sets[0]["name"] if multi else None))
    if multi:
        for s in sets:                                  # the set's own kiss-point offset is in the FMU
            values = dict(starts)
            out.append(ParameterSetFile(f"spring_{s['name']}", f"table set {s['value']} ({s['name']}): "
                                        f"{s['description']}", tuple(values.items()), s["name"]))
    return out


def _units(parent: ET.Element, ns: str, units) -> None:
    element = ET.SubElement(parent, _q(ns, "Units"))
    for name in sorted(units):
        unit = ET.SubElement(element, _q(SSC, "Unit"), name=name)
        ET.SubElement(unit, _q(SSC, "BaseUnit"), BASE_UNITS_SSP.get(name, BASE_UNITS.get(name, {})))


#: units beyond the model's parameters' (constants.BASE_UNITS): the connectors' and the state's
BASE_UNITS_SSP = {"K/s": {"K": "1", "s": "-1"}, "s": {"s": "1"}}


def _text(root: ET.Element) -> bytes:
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8", xml_declaration=False)


def ssv_text(ps: ParameterSetFile, units: dict[str, str], items: list[dict]) -> bytes:
    """The SSV of a parameter set: every value as ssv:Real with its unit (``units``: FMU name -> unit), the table
    set as ssv:Enumeration (``items``: the FMU's sets)."""
    root = ET.Element(_q(SSV, "ParameterSet"), {"version": "1.0", "name": ps.name, "description": ps.description,
                                                "generationTool": "cushion_clutch export-ssp"})
    params = ET.SubElement(root, _q(SSV, "Parameters"))
    for name, value in ps.values:
        p = ET.SubElement(params, _q(SSV, "Parameter"), name=name)
        ET.SubElement(p, _q(SSV, "Real"), value=repr(float(value)), unit=units[name])
    if ps.spring is not None:
        selector = clutch_model.TABLE_SET_VARIABLE[0]
        p = ET.SubElement(params, _q(SSV, "Parameter"), name=selector)
        ET.SubElement(p, _q(SSV, "Enumeration"), value=ps.spring, name=ENUMERATION)
        enums = ET.SubElement(root, _q(SSV, "Enumerations"))
        enum = ET.SubElement(enums, _q(SSC, "Enumeration"), name=ENUMERATION,
                             description="the table sets the FMU carries (its enumeration CushionClutch.Spring)")
        for s in items:
            ET.SubElement(enum, _q(SSC, "Item"), name=s["name"], value=str(s["value"]))
    _units(root, SSV, {units[n] for n, _ in ps.values})
    return _text(root)


#: the SSV's name of the table-set enumeration (the FMU's type name)
ENUMERATION = "CushionClutch.Spring"


def ssd_text(variables: dict, default: ParameterSetFile, description: str) -> bytes:
    """The SSD: system ``CushionClutchSystem`` with the component ``clutch`` (the FMU), every input and output a
    connector of both, wired through; the default parameter set bound to the component."""
    root = ET.Element(_q(SSD_NS, "SystemStructureDescription"), {
        "version": "1.0", "name": SLAVE, "description": description,
        "generationTool": "cushion_clutch export-ssp"})
    system = ET.SubElement(root, _q(SSD_NS, "System"), name=f"{SLAVE}System",
                           description="the clutch FMU with its inputs and outputs as the system's")
    ports = [(n, c, u) for n, (c, u, _) in variables.items() if c in ("input", "output")]

    def connectors(parent):
        element = ET.SubElement(parent, _q(SSD_NS, "Connectors"))
        for name, causality, unit in ports:
            ET.SubElement(ET.SubElement(element, _q(SSD_NS, "Connector"), name=name, kind=causality),
                          _q(SSC, "Real"), unit=unit)

    connectors(system)
    elements = ET.SubElement(system, _q(SSD_NS, "Elements"))
    comp = ET.SubElement(elements, _q(SSD_NS, "Component"), name=COMPONENT, type="application/x-fmu-sharedlibrary",
                         source=FMU_FILE)
    connectors(comp)
    bindings = ET.SubElement(comp, _q(SSD_NS, "ParameterBindings"))
    ET.SubElement(bindings, _q(SSD_NS, "ParameterBinding"), type="application/x-ssp-parameter-set",
                  source=default.path)
    wires = ET.SubElement(system, _q(SSD_NS, "Connections"))
    for name, causality, _ in ports:
        a, b = ((None, COMPONENT) if causality == "input" else (COMPONENT, None))
        attrs = {"startConnector": name, "endConnector": name}
        if a:
            attrs["startElement"] = a
        if b:
            attrs["endElement"] = b
        ET.SubElement(wires, _q(SSD_NS, "Connection"), attrs)
    _units(root, SSD_NS, {u for _, _, u in ports})
    return _text(root)


def schema_dir() -> Path:
    """FMPy's copy of the SSP 1.0 schemas."""
    import fmpy.ssp
    return Path(fmpy.ssp.__file__).parent / "schema"


def validate(text: bytes, schema: str) -> list[str]:
    """Problems of an SSD or SSV (``text``) against the SSP 1.0 ``schema`` file (e.g.
    ``SystemStructureParameterValues.xsd``); [] if it validates."""
    from lxml import etree
    xsd = etree.XMLSchema(etree.parse(str(schema_dir() / schema)))
    doc = etree.fromstring(text)
    return [] if xsd.validate(doc) else [f"line {e.line}: {e.message}" for e in xsd.error_log]


@dataclass(frozen=True)
class SspReport:
    """What :func:`export_ssp` wrote: the archive, its files and the parameter sets (name, description)."""

    path: Path
    files: tuple[str, ...]
    sets: tuple[tuple[str, str], ...]
    table_sets: tuple[tuple[int, str, str], ...]


def export_ssp(output: Path, fmu: Path, bind: str = DEFAULT_SET) -> SspReport:
    """Write the SSP ``output`` (.ssp) around the clutch FMU ``fmu``; the SSD binds parameter set ``bind`` to the
    component (default :data:`DEFAULT_SET`).

    Raises
    ------
    FmuError
        ``output`` is not an ``.ssp`` name, ``bind`` is not one of its parameter sets (they are listed), or a
        generated file does not validate against the SSP 1.0 schemas (a bug: nothing is written).
    """
    output = Path(output)
    if output.suffix.lower() != ".ssp" or output.is_dir():
        raise FmuError(f"{output}: an SSP archive's file name must end in .ssp (and not be a folder)")
    variables, _ = fmu_interface(fmu)
    units = {n: u for n, (_, u, _) in variables.items()}
    items = fmu_sets(fmu)
    files = parameter_files(fmu)
    bound = [f for f in files if f.name == bind]
    if not bound:
        raise FmuError(f"--bind {bind}: no such parameter set (allowed: {', '.join(f.name for f in files)})")
    default = bound[0]
    texts = {SSD_FILE: ssd_text(variables, default, "The cushion-clutch FMU and its parameter sets (wear states, "
                                                    "thermal sets, table sets)")}
    for f in files:
        texts[f.path] = ssv_text(f, units, items)
    problems = [f"{name}: {p}" for name, text in texts.items() for p in
                validate(text, "SystemStructureDescription.xsd" if name == SSD_FILE
                         else "SystemStructureParameterValues.xsd")]
    if problems:
        raise FmuError("the SSP's files do not validate against the SSP 1.0 schemas: " + "; ".join(problems))
    output.parent.mkdir(parents=True, exist_ok=True)
    tmp = output.with_suffix(".ssp.tmp")
    try:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr(SSD_FILE, texts.pop(SSD_FILE))
            z.write(fmu, FMU_FILE)
            for name, text in texts.items():
                z.writestr(name, text)
        tmp.replace(output)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    with zipfile.ZipFile(output) as z:
        names = tuple(z.namelist())
    return SspReport(output, names, tuple((f.name, f.description) for f in files),
                     tuple((s["value"], s["name"], s["description"]) for s in items))


def export_from_args(args) -> SspReport:
    """``cushion-clutch export-ssp``: the FMU from ``--fmu``, or built from the ``--tables`` folders."""
    from .build import build_fmu, table_folders
    if args.fmu:
        from .check import check_fmu
        return export_ssp(args.output, check_fmu(args.fmu), args.bind)
    folders = table_folders(args)
    with tempfile.TemporaryDirectory(prefix="cushion_ssp_") as tmp:
        fmu = build_fmu(folders if len(folders) > 1 else folders[0], Path(tmp) / f"{SLAVE}.fmu",
                        fmi_version=args.fmi_version)
        return export_ssp(args.output, fmu, args.bind)


def fmu_of(ssp: Path, dest: Path) -> Path:
    """Extract the clutch FMU of an SSP written by :func:`export_ssp` into the folder ``dest``; return its path.

    Raises
    ------
    FmuError
        Not an SSP archive, or no clutch FMU in it.
    """
    try:
        with zipfile.ZipFile(ssp) as z:
            if FMU_FILE not in z.namelist():
                raise FmuError(f"{ssp}: no {FMU_FILE} (an SSP written by cushion-clutch export-ssp holds one)")
            dest.mkdir(parents=True, exist_ok=True)
            out = dest / Path(FMU_FILE).name
            out.write_bytes(z.read(FMU_FILE))
            return out
    except (zipfile.BadZipFile, OSError) as exc:
        raise FmuError(f"{ssp}: not an SSP archive ({exc})") from None


def start_values_of(ssp: Path, parameter_set: str, fmu: Path) -> dict[str, float | int]:
    """The start values that parameter set ``parameter_set`` of ``ssp`` gives the FMU ``fmu``: every value it
    binds, the table set as the item's number (checked: :func:`cushion_clutch.model.ssv.ssv_parameters`).

    Raises
    ------
    ParameterError
        Unknown names, values out of range, an item the FMU does not carry.
    """
    from ..errors import ParameterError
    from ..model.ssv import read_ssv, ssp_parameter_set, ssv_parameters
    text = ssp_parameter_set(ssp, parameter_set)
    where = f"{ssp}:{parameter_set}"
    p = ssv_parameters(text, where=where)              # checks names, kinds, units and ranges
    values = {k: float(v) for k, v in p.flat().items()}
    _, entries = read_ssv(text, where)
    bound = {e.name for e in entries}
    out: dict[str, float | int] = {k: v for k, v in values.items() if k in bound}
    selector = clutch_model.TABLE_SET_VARIABLE[0]
    chosen = [e.text for e in entries if e.name == selector]
    if chosen:
        items = {s["name"]: s["value"] for s in fmu_sets(fmu)}
        if chosen[0] not in items or len(items) < 2:
            raise ParameterError([f"{where}: {selector} = {chosen[0]!r}: the FMU carries "
                                  f"{', '.join(items) if len(items) > 1 else 'one table set (no selector)'}"])
        out[selector] = int(items[chosen[0]])
    return out


def plant_from_ssp(ssp: Path, parameter_set: str | None, dest: Path) -> tuple[Path, dict[str, float | int]]:
    """The clutch FMU of ``ssp`` (extracted into ``dest`` and checked) and the start values of its parameter set
    ``parameter_set`` (default :data:`DEFAULT_SET`), for ``simulate`` and ``launch``.

    Raises
    ------
    FmuError, ParameterError
        Not an SSP with a clutch FMU; no such set (the sets listed); a bad value (named, with its range).
    """
    from .check import check_fmu
    fmu = check_fmu(fmu_of(Path(ssp), Path(dest)))
    return fmu, start_values_of(Path(ssp), parameter_set or DEFAULT_SET, fmu)


def chosen_tables(fmu: Path, start: dict, dest: Path) -> Path:
    """The table set the start values ``start`` choose in ``fmu`` (``spring``; set 1 without it), extracted into
    the folder ``dest``."""
    index = int(start.get(clutch_model.TABLE_SET_VARIABLE[0], 1))
    (entry,) = [s for s in fmu_sets(fmu) if int(s["value"]) == index]
    prefix = f"resources/{entry['resource']}/"
    dest.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(fmu) as z:
        for name in z.namelist():
            if name.startswith(prefix) and not name.endswith("/"):
                (dest / name[len(prefix):]).write_bytes(z.read(name))
    return dest
