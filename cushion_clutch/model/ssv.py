"""SSV parameter sets (SSP 1.0 ``SystemStructureParameterValues``) into :class:`ClutchParameters` (issue 42).

An SSV binds values to FMU variables by name, each Real with its unit. :func:`ssv_parameters` reads one (a
file, or the bytes of one inside an ``.ssp``: :func:`cushion_clutch.fmu.ssp.ssp_parameter_set`) into
``ClutchParameters``, refusing every unknown name, a value that is not a finite Real, a unit other than the
FMU variable's and a value outside the parameter's range, each problem with the name (and the range). The
table-set selector ``spring`` (an enumeration, :data:`clutch_model.TABLE_SET_VARIABLE`) is not a field of
``ClutchParameters``: :func:`ssv_spring` gives its item. Standard library only (ElementTree).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

from ..errors import ParameterError
from . import clutch_model

SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
NS = {"ssv": SSV, "ssc": SSC}
TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration", "Binary")


@dataclass(frozen=True)
class SsvValue:
    """One ``ssv:Parameter``: its ``name``, value ``kind`` (Real, Integer, Enumeration, ...), the value's text
    and the unit (Real only; None if not given)."""

    name: str
    kind: str
    text: str
    unit: str | None


def read_ssv(source: "Path | str | bytes", where: str | None = None) -> tuple[str, tuple[SsvValue, ...]]:
    """The set's name and its parameters, in file order. ``source``: a path or the file's bytes (``where`` names
    it in messages).

    Raises
    ------
    ParameterError
        Not an SSV parameter set, or a parameter without a value.
    """
    where = where or str(source) if not isinstance(source, bytes) else where or "SSV"
    try:
        root = ET.fromstring(source) if isinstance(source, bytes) else ET.parse(source).getroot()
    except ET.ParseError as exc:
        raise ParameterError([f"{where}: not XML ({exc})"]) from None
    if root.tag != f"{{{SSV}}}ParameterSet":
        raise ParameterError([f"{where}: not an SSV parameter set (root {root.tag}, expected "
                              f"{{{SSV}}}ParameterSet)"])
    values, problems = [], []
    for p in root.findall("ssv:Parameters/ssv:Parameter", NS):
        name = p.get("name", "")
        found = [(t, e) for t in TYPES if (e := p.find(f"ssv:{t}", NS)) is not None]
        if len(found) != 1 or found[0][1].get("value") is None:
            problems.append(f"{where}: parameter {name!r} has no single typed value")
            continue
        kind, e = found[0]
        values.append(SsvValue(name, kind, e.get("value"), e.get("unit")))
    if problems:
        raise ParameterError(problems)
    return root.get("name", ""), tuple(values)


def ssv_parameters(source: "Path | str | bytes", base: "clutch_model.ClutchParameters | None" = None,
                   where: str | None = None) -> "clutch_model.ClutchParameters":
    """``base`` (default: the model's defaults) with the SSV's values.

    Raises
    ------
    ParameterError
        Every problem, each naming the parameter: an unknown name (the FMU's parameters are listed in
        ``clutch_model.VARIABLES``), a kind other than Real, a unit other than the variable's, a value that is not
        finite, a value outside its range (the range named), or an inconsistent cover.
    """
    where = where or (str(source) if not isinstance(source, bytes) else "SSV")
    _, values = read_ssv(source, where)
    units = {n: u for n, c, u, _ in clutch_model.VARIABLES if c == "parameter"}
    selector = clutch_model.TABLE_SET_VARIABLE[0]
    problems, flat = [], (base or clutch_model.ClutchParameters()).flat()
    for v in values:
        if v.name == selector:
            if v.kind not in ("Enumeration", "Integer"):
                problems.append(f"{where}: {v.name} is an enumeration (the table set); got ssv:{v.kind}")
            continue
        if v.name not in units:
            problems.append(f"{where}: unknown parameter {v.name!r} (not a parameter of the clutch FMU)")
            continue
        if v.kind != "Real":
            problems.append(f"{where}: {v.name} must be ssv:Real (got ssv:{v.kind})")
            continue
        if v.unit is not None and v.unit != units[v.name]:
            problems.append(f"{where}: {v.name} in unit {v.unit!r}: the FMU's unit is {units[v.name]!r}")
            continue
        try:
            value = float(v.text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            problems.append(f"{where}: {v.name} = {v.text!r} is not a finite number")
            continue
        flat[v.name] = value
    if not problems:
        problems = [f"{where}: {p}" for p in clutch_model.ClutchParameters.from_flat(flat).problems()]
    if problems:
        raise ParameterError(problems)
    return clutch_model.ClutchParameters.from_flat(flat)


def ssv_spring(source: "Path | str | bytes") -> str | None:
    """The table-set item the SSV chooses (``spring``: an enumeration item's name, or an integer's text), or
    None."""
    _, values = read_ssv(source)
    chosen = [v.text for v in values if v.name == clutch_model.TABLE_SET_VARIABLE[0]]
    return chosen[0] if chosen else None


#: where an SSP made by ``cushion-clutch export-ssp`` keeps its parameter sets
SSV_FOLDER = "resources/parameters"


def ssp_parameter_sets(ssp: "Path | str") -> list[str]:
    """Names of the SSV parameter sets in an ``.ssp`` (the files in :data:`SSV_FOLDER`, without ``.ssv``)."""
    import zipfile
    with zipfile.ZipFile(ssp) as z:
        return sorted(Path(n).stem for n in z.namelist() if n.startswith(SSV_FOLDER + "/") and n.endswith(".ssv"))


def ssp_parameter_set(ssp: "Path | str", name: str) -> bytes:
    """The bytes of parameter set ``name`` in an ``.ssp``.

    Raises
    ------
    ParameterError
        No such set (the sets there listed), or not an SSP archive.
    """
    import zipfile
    try:
        with zipfile.ZipFile(ssp) as z:
            member = f"{SSV_FOLDER}/{name}.ssv"
            if member in z.namelist():
                return z.read(member)
    except (zipfile.BadZipFile, OSError) as exc:
        raise ParameterError([f"{ssp}: not an SSP archive ({exc})"]) from None
    raise ParameterError([f"{ssp}: no parameter set {name!r} (it holds: "
                          f"{', '.join(ssp_parameter_sets(ssp)) or 'none'})"])


def load_parameters(source: "Path | str", parameter_set: str | None = None) -> "clutch_model.ClutchParameters":
    """``ClutchParameters`` from an ``.ssv`` file, or from parameter set ``parameter_set`` of an ``.ssp``.

    Raises
    ------
    ParameterError
        As :func:`ssv_parameters`; an ``.ssp`` without ``parameter_set`` or without that set.
    """
    source = Path(source)
    if source.suffix.lower() == ".ssp":
        if parameter_set is None:
            raise ParameterError([f"{source}: give the parameter set to load (it holds: "
                                  f"{', '.join(ssp_parameter_sets(source))})"])
        return ssv_parameters(ssp_parameter_set(source, parameter_set), where=f"{source}:{parameter_set}")
    return ssv_parameters(source)
