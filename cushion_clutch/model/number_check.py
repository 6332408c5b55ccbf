"""What counts as a number in a parameter file, a keyword argument or an FMU state: the one predicate.

Python's ``bool`` is a subclass of ``int`` (``isinstance(False, (int, float))`` is true), so a check
written as ``isinstance(x, (int, float))`` takes TOML's ``true``/``false`` or a JSON ``false`` for
1 and 0. Every loader and every argument check of the package asks :func:`is_number` instead.
The pythonfmu FMU carries this module beside the model (it imports nothing).
"""
from __future__ import annotations

import math

__all__ = ["is_number", "is_finite_number", "any_bool"]


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
