"""Named FMU parameter sets shipped as data (``*.toml`` here: the wear states), and the cushion spring's thermal
parameter sets (:mod:`cushion_clutch.model.thermal_set`: the paper's U, H, C and every set in
``cushion_clutch/thermal_sets``, e.g. the FE-identified ``fe_default``) as ``thermal_<name>``.

Each file holds ``name``, ``kind`` (``wear`` or ``thermal``), ``description`` and a ``[parameters]`` table of
FMU parameter names with values in the FMU's units (SI; temperatures in K). ``cushion-clutch export-ssp``
writes one SSV parameter set per file (:mod:`cushion_clutch.fmu.ssp`); adding a set is adding a file.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

from ..errors import ParameterError
from ..model import clutch_model

KINDS = ("wear", "thermal")
KEYS = ("name", "kind", "description", "parameters")


@dataclass(frozen=True)
class NamedSet:
    """A named parameter set: ``values`` maps FMU parameter names to values in their units."""

    name: str
    kind: str
    description: str
    values: tuple[tuple[str, float], ...]

    def parameters(self, base: "clutch_model.ClutchParameters | None" = None) -> "clutch_model.ClutchParameters":
        """``base`` (default: the defaults) with this set's values."""
        flat = (base or clutch_model.ClutchParameters()).flat()
        flat.update(dict(self.values))
        return clutch_model.ClutchParameters.from_flat(flat)


def folder() -> Path:
    """The folder of the shipped sets."""
    return Path(str(files(__name__)))


def load_set(path: Path) -> NamedSet:
    """Read and check one set file.

    Raises
    ------
    ParameterError
        Every problem: unknown keys, a missing key, an unknown kind, an unknown parameter name, a value that is
        not a finite number or lies outside the parameter's range (the range named).
    """
    path = Path(path)
    data = tomllib.loads(path.read_text())
    problems = [f"{path}: unknown key {k!r} (allowed {', '.join(KEYS)})" for k in data if k not in KEYS]
    problems += [f"{path}: key {k!r} is missing" for k in KEYS if k not in data]
    if data.get("kind") not in KINDS:
        problems.append(f"{path}: kind = {data.get('kind')!r}: allowed {', '.join(KINDS)}")
    params = data.get("parameters", {})
    ranges = clutch_model.ClutchParameters.RANGES
    for name, value in params.items():
        if name not in ranges:
            problems.append(f"{path}: parameter {name!r} is not an FMU parameter")
        elif isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            problems.append(f"{path}: {name} = {value!r} is not a finite number")
    if not problems:
        problems += [f"{path}: {p}" for p in NamedSet("", "", "", tuple(params.items())).parameters().problems()]
    if problems:
        raise ParameterError(problems)
    return NamedSet(str(data["name"]), data["kind"], str(data["description"]),
                    tuple((k, float(v)) for k, v in params.items()))


def thermal_sets() -> list[NamedSet]:
    """The shipped cushion-spring thermal sets as parameter sets ``thermal_<name>`` (FMU parameters U, H, C):
    declared once, in :mod:`cushion_clutch.model.thermal_set`, which the launch plant reads too."""
    from ..model.thermal_set import load_thermal_set, shipped_names
    out = []
    for name in shipped_names():
        ts = load_thermal_set(name)
        out.append(NamedSet(f"thermal_{name}", "thermal", f"cushion-spring U, H, C: {ts.description}",
                            tuple(ts.parameters().items())))
    return out


def shipped_sets() -> tuple[NamedSet, ...]:
    """Every shipped set, wear states first (new first), then the thermal sets, each by name.

    Raises
    ------
    ParameterError
        A bad file, or two files with one name.
    """
    sets = [load_set(p) for p in sorted(folder().glob("*.toml"))] + thermal_sets()
    names = [s.name for s in sets]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ParameterError([f"parameter sets named twice: {', '.join(dup)}"])
    return tuple(sorted(sets, key=lambda s: (KINDS.index(s.kind), s.name != "new", s.name)))
