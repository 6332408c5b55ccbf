"""Checked parameter files: frozen dataclasses loaded from TOML, problems collected.

Shared by the spring parameters (:mod:`cushion_clutch.fe.params`) and the
launch scenarios (:mod:`cushion_clutch.launch.scenario`). Every dataclass
checks itself in ``__post_init__``; all problems of all sections are
collected and raised at once as :class:`~cushion_clutch.errors.ParameterError`,
each naming its key and the allowed range. Unknown keys are rejected.
"""
from __future__ import annotations

import dataclasses
import math
import re
import tomllib
from dataclasses import fields
from pathlib import Path
from typing import Any, Iterable

from .errors import ParameterError
from .number_check import is_finite_number, is_number


def range_problem(key: str, value: Any, lo: float | None, hi: float | None,
                  lo_open: bool = False, hi_open: bool = False) -> str | None:
    """Return a message if ``value`` is not a finite number in the range, else None."""
    lo_s = "-inf" if lo is None else f"{lo:g}"
    hi_s = "inf" if hi is None else f"{hi:g}"
    allowed = f"{'(' if lo_open or lo is None else '['}{lo_s}, {hi_s}{')' if hi_open or hi is None else ']'}"
    if not is_finite_number(value):
        return f"{key} = {value!r}: must be a finite number in {allowed}"
    bad_lo = lo is not None and (value <= lo if lo_open else value < lo)
    bad_hi = hi is not None and (value >= hi if hi_open else value > hi)
    if bad_lo or bad_hi:
        return f"{key} = {value!r}: out of range, allowed {allowed}"
    return None


class Checked:
    """Mixin: run ``_problems`` after init and raise if there are any."""

    _section = ""

    def __post_init__(self) -> None:
        problems = list(self._problems())
        if problems:
            raise ParameterError(problems)

    def _key(self, name: str) -> str:
        return f"{self._section}.{name}" if self._section else name

    def _ranges(self, spec: dict[str, tuple]) -> Iterable[str]:
        for name, bounds in spec.items():
            msg = range_problem(self._key(name), getattr(self, name), *bounds)
            if msg:
                yield msg

    def _integers(self, *names: str) -> Iterable[str]:
        """A message for every named field that is a number but not an integer (a value that is no
        number at all, a boolean included, is named once, by its range check)."""
        for name in names:
            value = getattr(self, name)
            if is_number(value) and not isinstance(value, int):
                yield f"{self._key(name)} = {value!r}: must be an integer"

    def _passed(self, spec: dict[str, tuple], *names: str) -> bool:
        """True if every named field passed its own range check in ``spec`` (as :meth:`_ranges` runs it).

        Cross-field checks run only then, so one bad value gives one message naming one key.
        """
        return all(range_problem(self._key(n), getattr(self, n), *spec[n]) is None for n in names)

    def _problems(self) -> Iterable[str]:  # pragma: no cover - overridden
        return ()


def _type_problems(cls: type, section: str, values: dict[str, Any]) -> Iterable[str]:
    """Values whose type does not match the field's default: lists, strings and booleans.

    Numbers are left to the range checks (which name the allowed range).
    """
    for f in fields(cls):
        if f.name not in values or f.default is dataclasses.MISSING:
            continue
        v, default = values[f.name], f.default
        key = f"{section}.{f.name}"
        if isinstance(default, tuple):
            if not isinstance(v, tuple):
                yield f"{key} = {v!r}: must be a list"
            elif default and all(is_number(d) for d in default) and not all(is_number(x) for x in v):
                yield f"{key} = {list(v)!r}: must be a list of numbers"
        elif isinstance(default, bool):
            if not isinstance(v, bool):
                yield f"{key} = {v!r}: must be true or false"
        elif isinstance(default, str) and not isinstance(v, str):
            yield f"{key} = {v!r}: must be a string"


def build_checked(top_cls: type, data: dict[str, Any], source: str | None = None) -> Any:
    """Build a checked dataclass of sections (``top_cls``) from nested dicts.

    Sections are the fields whose default is a dataclass; other fields are
    plain top-level keys. Unknown keys are rejected and all problems of all
    sections are collected before one :class:`ParameterError` is raised.
    """
    sections = {f.name: type(f.default_factory()) for f in fields(top_cls)
                if f.default_factory is not dataclasses.MISSING}
    plain = {f.name for f in fields(top_cls)} - set(sections)
    problems: list[str] = []
    top: dict[str, Any] = {}
    for key, value in data.items():
        if key in sections:
            cls = sections[key]
            if not isinstance(value, dict):
                problems.append(f"[{key}]: must be a table")
                continue
            allowed = {f.name for f in fields(cls)}
            for k in sorted(set(value) - allowed):
                problems.append(f"{key}.{k}: unknown key (allowed: {', '.join(sorted(allowed))})")
            kwargs = {k: (tuple(v) if isinstance(v, list) else v)
                      for k, v in value.items() if k in allowed}
            shape = list(_type_problems(cls, key, kwargs))
            if shape:
                problems.extend(shape)
                continue
            try:
                top[key] = cls(**kwargs)
            except ParameterError as exc:
                problems.extend(exc.problems)
            except (TypeError, ValueError, ArithmeticError) as exc:   # a check the types above missed
                problems.append(f"[{key}]: invalid values ({exc})")
        elif key in plain:
            default = next(f.default for f in fields(top_cls) if f.name == key)
            if isinstance(default, str) and not isinstance(value, str):
                problems.append(f"{key} = {value!r}: must be a string")
                continue
            top[key] = value
        else:
            problems.append(f"{key}: unknown key (allowed: {', '.join(sorted(plain | set(sections)))})")
    try:
        if not problems:
            return top_cls(**top)
        top_cls(**{k: v for k, v in top.items() if k in plain})   # complete the report
    except ParameterError as exc:
        problems.extend(exc.problems)
    raise ParameterError(problems, source)


def load_toml(path: str | Path, required: tuple[str, ...] = ()) -> dict[str, Any]:
    """Read a TOML file that must not be empty and must hold the ``required`` top-level keys.

    Raises
    ------
    ParameterError
        Naming the file: missing or unreadable, not UTF-8 text, a TOML syntax
        error, an empty document, or a required key absent.
    """
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError as exc:
        raise ParameterError(["file does not exist"], str(path)) from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise ParameterError([f"cannot read the file: {exc}"], str(path)) from exc
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError([f"TOML syntax error: {exc}"], str(path)) from exc
    if not data:
        raise ParameterError(["the file is empty: it must set at least "
                              + (", ".join(required) if required else "one key")], str(path))
    missing = [f"{key}: required key missing" for key in required if key not in data]
    if missing:
        raise ParameterError(missing, str(path))
    return data


_BARE_KEY = re.compile(r"[A-Za-z0-9_-]+")


def _toml_string(text: str) -> str:
    out = text.replace("\\", "\\\\").replace('"', '\\"')
    return '"' + "".join(f"\\u{ord(c):04x}" if ord(c) < 0x20 or ord(c) == 0x7F else c for c in out) + '"'


def toml_value(v: Any) -> str:
    """``v`` (bool, int, float incl. nan/inf, str, list/tuple, dict as inline table) as TOML text."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{toml_key(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def toml_key(key: str) -> str:
    """A TOML key: bare when it can be, quoted and escaped otherwise."""
    return key if _BARE_KEY.fullmatch(key) else _toml_string(key)


def toml_document(doc: dict[str, Any], header: str = "") -> str:
    """``doc`` as TOML text that :func:`load_toml` reads back equal: ``header`` as comment lines,
    then top-level values, then one ``[section]`` per dict (dicts inside sections as inline tables).

    ``None`` values are left out: TOML has no null, and a key left out reads back as its field's default,
    which is ``None`` for every optional field (e.g. ``carrier.far_end_stiffness_N_per_m``)."""
    lines = [f"# {h}" for h in header.splitlines()]
    lines += [f"{toml_key(k)} = {toml_value(v)}" for k, v in doc.items() if not isinstance(v, dict) and v is not None]
    for sec, vals in doc.items():
        if isinstance(vals, dict):
            lines += ["", f"[{toml_key(sec)}]"] + [f"{toml_key(k)} = {toml_value(v)}" for k, v in vals.items()
                                                   if v is not None]
    return "\n".join(lines) + "\n"
