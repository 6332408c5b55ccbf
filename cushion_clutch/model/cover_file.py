"""The ``[cover]`` section of a TOML file: a checked :class:`CoverParameters`.

Example::

    [cover]
    diaphragm_thickness_m = 0.0026
    installed_deflection_m = 0.0028

Keys are the fields of :class:`~cushion_clutch.model.cover.CoverParameters` (SI, units in the
names); missing keys keep the default cover. Unknown keys are rejected; every problem (range,
type, geometry, snap-through) is collected and raised at once as
:class:`~cushion_clutch.errors.ParameterError`.
"""
from __future__ import annotations

from dataclasses import fields
from pathlib import Path

from .cover import CoverParameters
from ..number_check import is_number

__all__ = ["load_cover", "cover_from_dict"]


def cover_from_dict(section: dict, lever_ratio: float = 3.0, source: str | None = None) -> CoverParameters:
    """A checked cover from the ``[cover]`` table's key/value pairs.

    Raises
    ------
    ParameterError
        Naming every unknown key, every value of the wrong type or out of range, and every
        inconsistent geometry.
    """
    from ..errors import ParameterError     # the package's error classes: not needed inside the FMU

    allowed = {f.name for f in fields(CoverParameters)}
    problems = [f"cover.{k}: unknown key (allowed: {', '.join(sorted(allowed))})" for k in sorted(set(section) - allowed)]
    values = {}
    for k, v in section.items():
        if k not in allowed:
            continue
        if not is_number(v):
            problems.append(f"cover.{k} = {v!r}: must be a number")
        else:
            values[k] = float(v)
    if not problems:
        problems += [f"cover.{q}" for q in CoverParameters(**values).problems(lever_ratio)]
    if problems:
        raise ParameterError(problems, source)
    return CoverParameters(**values)


def load_cover(path: str | Path, lever_ratio: float = 3.0) -> CoverParameters:
    """The checked ``[cover]`` section of the TOML file ``path`` (other sections are not read here)."""
    from ..config import load_toml
    from ..errors import ParameterError

    data = load_toml(path, required=("cover",))
    section = data["cover"]
    if not isinstance(section, dict):
        raise ParameterError(["[cover]: must be a table"], str(path))
    return cover_from_dict(section, lever_ratio, str(path))
