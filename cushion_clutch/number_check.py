"""What counts as a number in a parameter file, a keyword argument or an FMU state: the one predicate;
and the hint for the likely unit mistake behind a value out of its range.

Python's ``bool`` is a subclass of ``int`` (``isinstance(False, (int, float))`` is true), so a check
written as ``isinstance(x, (int, float))`` takes TOML's ``true``/``false`` or a JSON ``false`` for
1 and 0. Every loader and every argument check of the package asks :func:`is_number` instead.
The pythonfmu FMU carries this module beside the model.
"""
from __future__ import annotations

import math

__all__ = ["is_number", "is_finite_number", "any_bool", "unit_hint"]

#: 0 degC in K: the one kelvin offset of the model (spring_table and the rest take it from here)
KELVIN = 273.15


def is_number(value: object) -> bool:
    """True for an ``int`` or a ``float`` (numpy's float64 included), never for a ``bool``; NaN and inf count."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def is_finite_number(value: object) -> bool:
    """:func:`is_number` and finite (no NaN, no inf)."""
    return is_number(value) and math.isfinite(value)


def any_bool(*values: object) -> bool:
    """True if one of ``values`` is a ``bool`` (for fast paths that compare ranges without a type check,
    where ``True`` would pass as 1 and ``False`` as 0)."""
    return any(isinstance(v, bool) for v in values)


def unit_hint(value: object, unit: str, lo: float, hi: float) -> str:
    """The likely unit mistake behind ``value`` (in ``unit``) outside ``[lo, hi]``, as ``"did you mean ...?"``;
    "" when none fits. Messages append it after ": ".

    - ``m``: millimetres typed as metres, when ``value / 1000`` lies in the range
      (``x_to = 12``: ``"did you mean 0.012 m?"``);
    - ``K``: degrees Celsius typed as kelvins, when ``value`` is below the range and ``value + 273.15`` in it
      (``theta_cs_start = 20``: ``"did you mean 293.15 K (20 degC)?"``).

    Numbers are written with ``%g``, as the native FMU's C helper ``unit_hint`` (``clutch_core.c``) writes
    them: both FMUs give the same text. A range check cannot catch a degC value that is a valid kelvin value
    (200-527 degC read as 200-527 K).
    """
    if not is_finite_number(value) or lo <= value <= hi:
        return ""
    if unit == "m" and lo <= value * 1e-3 <= hi:
        return "did you mean %g m?" % (value * 1e-3)
    if unit == "K" and value < lo and lo <= value + KELVIN <= hi:
        return "did you mean %g K (%g degC)?" % (value + KELVIN, value)
    return ""
