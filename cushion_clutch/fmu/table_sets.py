"""Several spring table sets in one FMU, chosen by the enumeration parameter ``spring`` (issue 42).

An FMU built from more than one table folder (``build-fmu --tables A --tables B ...``) carries set 1 in
``resources/tables`` (where a one-set FMU has its only set, so a one-set FMU is unchanged), set k >= 2 in
``resources/tables_<k>``, and ``resources/table_sets.json`` (the sets' names, descriptions, source folders and
own kiss points). The model core loads every set at instantiation (``cc_table_sets_load`` in
``fmu_src/core/clutch_tables.c``) and the parameter ``spring`` (``clutch_model.TABLE_SET_VARIABLE``; an
enumeration with one item per set, FMI 2.0 ``SimpleType/Enumeration``, FMI 3.0 ``EnumerationType``; value
reference after FMI 3's ``time``) picks one until initialisation ends; a change after that is refused with a
message. The GUID (instantiationToken) hashes every set carried (:func:`hash_sets`).

A tolerance set measures u from its own spring's kiss point (``metadata.json``
``tolerance_study.x_kiss_ref_m``, placed against the nominal spring's). In a multi-set FMU the parameter
``x_kiss_ref`` is set 1's kiss point (its start value: set 1's own, or the model's default), and each other set
carries its own kiss point's offset from set 1's (``resources/tables_<k>/x_kiss_ref_offset_m.txt``, read by
``cc_table_sets_load``), which the model adds when that set is chosen: choosing P95 moves the kiss point as a
P95 spring does, whatever installation ``x_kiss_ref`` describes.
"""
from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

from ..errors import ParameterError
from ..model import clutch_model
from ..model.table_format import FMU_FILES, read_metadata, table_set_x_kiss_ref

#: the manifest of a multi-set FMU's resources
MANIFEST = "table_sets.json"
#: the enumeration type's name in the modelDescription
TYPE_NAME = "CushionClutch.Spring"
#: the most sets one FMU carries (CC_MAX_SETS in clutch_tables.h)
MAX_SETS = 64
#: a set's kiss-point offset from set 1's, m (CC_KISS_OFFSET_FILE in clutch_tables.h)
KISS_OFFSET_FILE = "x_kiss_ref_offset_m.txt"


@dataclass(frozen=True)
class CarriedSet:
    """One table set of a multi-set FMU: enumeration item ``name`` (value ``index``, 1-based), its
    ``description``, the ``folder`` it came from and its own kiss point ``x_kiss_ref_m`` (m; None: the
    model's default)."""

    index: int
    name: str
    description: str
    folder: Path
    x_kiss_ref_m: float | None
    kiss_offset_m: float = 0.0


    @property
    def resource(self) -> str:
        """Its folder inside the FMU's ``resources/``."""
        return resource_folder(self.index)


def resource_folder(index: int) -> str:
    """``resources/`` sub-folder of set ``index`` (1-based): ``tables``, ``tables_2``, ``tables_3``, ..."""
    return "tables" if index == 1 else f"tables_{index}"


def vr_spring() -> int:
    """Value reference of ``spring``: the one after FMI 3's ``time`` (CC_VR_SPRING in clutch_core.h)."""
    from .descriptions import vr_time
    return vr_time() + 1


def _item_name(folder: Path) -> str:
    name = re.sub(r"\W", "_", Path(folder).resolve().name) or "set"
    return name if name[0].isalpha() else "set_" + name


def _description(folder: Path, kiss_offset_m: float) -> str:
    meta = read_metadata(folder)
    spring = meta.get("spring", {}) if isinstance(meta.get("spring"), dict) else {}
    text = str(spring.get("description") or spring.get("name") or f"tables from {Path(folder).name}")
    scale = meta.get("force_scale")
    if scale is not None:
        text += f"; forces x {scale}"
    if kiss_offset_m:
        text += f"; its own kiss point: x_kiss_ref {kiss_offset_m * 1e3:+.4f} mm (applied when chosen)"
    return text


def carried_sets(folders) -> tuple[CarriedSet, ...]:
    """The sets of the folders, in order: item names from the folder names (made identifiers, made unique).

    Raises
    ------
    ParameterError
        More than :data:`MAX_SETS` folders, or one folder given twice.
    """
    folders = [Path(f) for f in folders]
    problems = []
    if not 1 <= len(folders) <= MAX_SETS:
        problems.append(f"--tables given {len(folders)} times: allowed 1..{MAX_SETS}")
    seen = [f.resolve() for f in folders]
    problems += [f"--tables {f}: given twice" for i, f in enumerate(folders) if seen[i] in seen[:i]]
    if problems:
        raise ParameterError(problems)
    sets, names = [], []
    default = clutch_model.ClutchParameters().x_kiss_ref
    kisses = [table_set_x_kiss_ref(f) for f in folders]
    first = default if kisses[0] is None else kisses[0]
    for index, (folder, kiss) in enumerate(zip(folders, kisses), start=1):
        name, k = _item_name(folder), 2
        while name in names:
            name, k = f"{_item_name(folder)}_{k}", k + 1
        names.append(name)
        offset = 0.0 if index == 1 else (default if kiss is None else kiss) - first
        sets.append(CarriedSet(index, name, _description(folder, offset), folder, kiss, offset))
    return tuple(sets)


def hash_sets(digest, sets) -> None:
    """Add every set after the first (its number, name, description and files) to the GUID's ``digest``
    (the first is hashed as a one-set FMU's tables are: a one-set FMU keeps its GUID)."""
    for s in sets[1:]:
        digest.update(f"table set {s.index} {s.name} {s.description}".encode())
        for name in FMU_FILES:
            if (s.folder / name).exists():
                digest.update(name.encode() + (s.folder / name).read_bytes())


def manifest(sets) -> str:
    """Text of ``resources/table_sets.json``."""
    return json.dumps({"parameter": clutch_model.TABLE_SET_VARIABLE[0],
                       "sets": [{"value": s.index, "name": s.name, "description": s.description,
                                 "resource": s.resource, "source": s.folder.resolve().name,
                                 "x_kiss_ref_m": s.x_kiss_ref_m, "kiss_offset_m": s.kiss_offset_m}
                                for s in sets]}, indent=2) + "\n"


def write_resources(z, sets) -> None:
    """Write sets 2.. and the manifest into the open FMU zip ``z`` (set 1 is written as a one-set FMU's)."""
    for s in sets[1:]:
        for name in FMU_FILES:
            if (s.folder / name).exists():
                z.write(s.folder / name, f"resources/{s.resource}/{name}")
        if s.kiss_offset_m:
            z.writestr(f"resources/{s.resource}/{KISS_OFFSET_FILE}", f"{s.kiss_offset_m!r}\n")
    z.writestr(f"resources/{MANIFEST}", manifest(sets))


def _items(parent: ET.Element, sets) -> None:
    for s in sets:
        ET.SubElement(parent, "Item", name=s.name, value=str(s.index), description=s.description)


def _variable_description() -> str:
    name, _, unit, desc = clutch_model.TABLE_SET_VARIABLE
    return f"{desc} [{unit}]"


def with_table_sets(xml_text: str, sets, fmi_version: int) -> str:
    """The modelDescription ``xml_text`` with the enumeration type and the parameter ``spring`` (start: set 1)
    added; unchanged for one set."""
    if len(sets) < 2:
        return xml_text
    root = ET.fromstring(xml_text)
    types = ET.Element("TypeDefinitions")
    if fmi_version == 2:
        _items(ET.SubElement(ET.SubElement(types, "SimpleType", name=TYPE_NAME), "Enumeration"), sets)
    else:
        _items(ET.SubElement(types, "EnumerationType", name=TYPE_NAME), sets)
    after = root.find("UnitDefinitions")
    root.insert(list(root).index(after) + 1, types)
    name, causality, _, _ = clutch_model.TABLE_SET_VARIABLE
    common = dict(name=name, valueReference=str(vr_spring()), description=_variable_description(),
                  causality=causality, variability="fixed")
    variables = root.find("ModelVariables")
    if fmi_version == 2:
        var = ET.SubElement(variables, "ScalarVariable", common, initial="exact")
        ET.SubElement(var, "Enumeration", declaredType=TYPE_NAME, start="1")
    else:
        ET.SubElement(variables, "Enumeration", common, declaredType=TYPE_NAME, start="1")
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def fmu_sets(fmu: Path) -> list[dict]:
    """The sets a built FMU carries (its manifest), or one entry for a one-set FMU."""
    import zipfile
    with zipfile.ZipFile(fmu) as z:
        if f"resources/{MANIFEST}" in z.namelist():
            return json.loads(z.read(f"resources/{MANIFEST}"))["sets"]
    return [{"value": 1, "name": "tables", "description": "the FMU's one table set", "resource": "tables",
             "source": None, "x_kiss_ref_m": None, "kiss_offset_m": 0.0}]


def stage_sets(stage: Path, sets) -> list[Path]:
    """Sets 2.. (with their kiss-offset files) and the manifest as files in ``stage`` for the pythonfmu build
    (its resources); return them ([] for one set)."""
    out = []
    for s in sets[1:]:
        folder = stage / s.resource
        folder.mkdir()
        for name in FMU_FILES:
            if (s.folder / name).exists():
                (folder / name).write_bytes((s.folder / name).read_bytes())
        if s.kiss_offset_m:
            (folder / KISS_OFFSET_FILE).write_text(f"{s.kiss_offset_m!r}\n")
        out.append(folder)
    if sets:
        (stage / MANIFEST).write_text(manifest(sets))
        out.append(stage / MANIFEST)
    return out


def enumeration_from_integer(xml_text: str, sets) -> str:
    """A pythonfmu modelDescription with the slave's Integer ``spring`` declared as the sets' enumeration (the
    type added as :func:`with_table_sets` adds it); unchanged for one set."""
    if len(sets) < 2:
        return xml_text
    root = ET.fromstring(xml_text)
    name = clutch_model.TABLE_SET_VARIABLE[0]
    (var,) = [v for v in root.find("ModelVariables") if v.get("name") == name]
    var.remove(var.find("Integer"))
    var.set("initial", "exact")
    var.set("description", _variable_description())
    ET.SubElement(var, "Enumeration", declaredType=TYPE_NAME, start="1")
    types = ET.Element("TypeDefinitions")
    _items(ET.SubElement(ET.SubElement(types, "SimpleType", name=TYPE_NAME), "Enumeration"), sets)
    root.insert(list(root).index(root.find("UnitDefinitions")) + 1, types)
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"


def wear_limiting_table(folders) -> clutch_model.SpringTable:
    """The table of the carried set whose default-cover wear limit is the smallest
    (:func:`~cushion_clutch.model.clutch_model.facing_wear_max`): ``facing_wear``'s declared maximum must hold
    whichever set a host chooses, so an FMU carrying several sets declares the tightest one."""
    from ..model.api import load_table
    from ..model.clutch_model import facing_wear_max

    tables = [load_table(folder) for folder in folders]
    return tables[0] if len(tables) == 1 else min(tables, key=facing_wear_max)
