"""Measured load-deflection curves for calibration: read and checked, kept as measured.

A curve (CSV ``u_m,force_N``) is the compression of one paddle pair (or the
whole spring) from the kiss point at the reference temperature and its force,
at one spring temperature. Noise, points where the force falls, repeated or
backward compressions and a small zero offset are kept: the fit
(:mod:`cushion_clutch.fe.studies.calibrate`) sees the curve as measured.

A curve measured from its own kiss point hardly depends on the wave height
(the force of the bent sheet is set by the thickness; the wave height mostly sets
where the curve ends). A bench that also measures the pair's free height from a
datum gives the fit that information: the file may carry it as settings in
comment lines before or among the rows, ``# free_height_m = 2.78e-3`` and its
1-sigma ``# free_height_sd_m = 10e-6`` (both m, both or none): the pair's height at
the kiss force at the curve's temperature, plate to plate less the carrier disc's
thickness (the FE's carrier is a plane).
"""
from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ...errors import ParameterError, TableError

#: a raw curve may start this far before the kiss point (zero offset of the bench's travel), m
U_OFFSET_LIMIT_M = 0.2e-3
#: a hot curve (measured from the reference temperature's kiss point) may begin where the hot spring first
#: touches, earlier by its kiss shift: read down to this, then checked against the FE's kiss shift at its temperature
#: by :func:`cushion_clutch.fe.studies.calibrate.offset_problems`, m
HOT_U_READ_LIMIT_M = 2e-3
#: ... and its force may dip this far below zero (load-cell zero offset), fraction of its largest force
F_OFFSET_LIMIT = 0.05
#: settings a measured-curve file may carry in ``# key = value`` comment lines: allowed range, m
SETTINGS_M = {"free_height_m": (1e-5, 0.05), "free_height_sd_m": (1e-7, 1e-3)}
#: a setting: a comment line ``# key_unit = value``, a unit-named key (with an underscore) and one value;
#: other comments (``# F = k u``) stay comments
_SETTING = re.compile(r"^#\s*([A-Za-z][A-Za-z0-9]*(?:_[A-Za-z0-9]+)+)\s*=\s*(\S+)\s*$")


def free_height_problems(free_height_m, free_height_sd_m, where: str = "") -> list[str]:
    """Every problem of an optional free height and its 1-sigma (both m, both or none), naming the key and range."""
    out = []
    for key, v in (("free_height_m", free_height_m), ("free_height_sd_m", free_height_sd_m)):
        lo, hi = SETTINGS_M[key]
        if v is not None and not (isinstance(v, (int, float)) and math.isfinite(v) and lo <= v <= hi):
            out.append(f"{where}{key} = {v!r}: allowed {lo:g} .. {hi:g} m")
    if (free_height_m is None) != (free_height_sd_m is None):
        given, missing = (("free_height_m", "free_height_sd_m") if free_height_sd_m is None
                          else ("free_height_sd_m", "free_height_m"))
        out.append(f"{where}{given} given without {missing}: a free height needs its 1-sigma (m), and "
                   "a 1-sigma its free height")
    return out


@dataclass(frozen=True)
class Measured:
    """A measured load-deflection curve, SI, as measured (noise and non-monotone points kept).

    Attributes
    ----------
    u_m : ndarray
        Compression from the reference temperature's kiss point, m, in the order measured;
        may repeat or go back and start slightly below zero (a zero offset).
    force_N : ndarray
        Force, N, as measured (not smoothed, not made monotone).
    basis : str
        ``"pair"`` (one paddle pair) or ``"spring"`` (the whole spring).
    theta_degC : float
        Temperature of the spring during the measurement, degC.
    source : str
        The file it was read from ("" if built in code).
    free_height_m : float or None
        The pair's free height at the kiss force and ``theta_degC`` from a datum, m (plate to plate less
        the carrier disc's thickness), if the bench measured it; with ``free_height_sd_m``, its 1-sigma, m.

    Raises
    ------
    ParameterError
        A free height or 1-sigma out of range, or one without the other.
    """

    u_m: np.ndarray
    force_N: np.ndarray
    basis: str = "pair"
    theta_degC: float = 20.0
    source: str = ""
    free_height_m: float | None = None
    free_height_sd_m: float | None = None

    def __post_init__(self):
        problems = free_height_problems(self.free_height_m, self.free_height_sd_m,
                                        f"{self.source}: " if self.source else "")
        if problems:
            raise ParameterError(problems)


def read_measured(path: str | Path, basis: str = "pair", theta_degC: float = 20.0,
                  u_offset_limit_m: float = U_OFFSET_LIMIT_M) -> Measured:
    """Read and check a measured curve CSV with the header ``u_m,force_N``, keeping it as measured.

    Noise, points where the force falls, repeated or backward u and a small
    zero offset (u down to ``-u_offset_limit_m``, default ``U_OFFSET_LIMIT_M``; force down to
    ``-F_OFFSET_LIMIT`` of the largest force) are accepted and fitted as they are.
    Comment lines ``# free_height_m = ...`` and ``# free_height_sd_m = ...`` (m) give the
    pair's free height from a datum and its 1-sigma (:data:`SETTINGS_M`); other comments are ignored.

    Raises
    ------
    TableError
        Missing file, wrong header, non-numeric, non-finite or too few rows,
        u beyond the zero-offset limit, force below it, no force above zero;
        an unknown, repeated, non-numeric or out-of-range setting, or a free height without its 1-sigma
        (every setting problem at once).
    """
    path = Path(path)
    if basis not in ("pair", "spring"):
        raise TableError(f"measured basis = {basis!r}: allowed 'pair' or 'spring'")
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            lines = fh.read().splitlines()
    except OSError as exc:
        raise TableError(f"{path}: cannot read the measured curve ({exc.strerror})") from exc
    settings = _settings(path, lines)
    rows = [r for r in csv.reader(ln for ln in lines if not ln.lstrip().startswith("#")) if r]
    if not rows or [c.strip() for c in rows[0]] != ["u_m", "force_N"]:
        raise TableError(f"{path}: the first line must be the header 'u_m,force_N', got "
                         f"{','.join(rows[0]) if rows else 'an empty file'!r}")
    data = []
    for i, row in enumerate(rows[1:], start=2):
        try:
            vals = [float(v) for v in row]
        except ValueError:
            raise TableError(f"{path}, line {i}: not two numbers: {','.join(row)!r}") from None
        if len(vals) != 2 or not all(math.isfinite(v) for v in vals):
            raise TableError(f"{path}, line {i}: need two finite numbers u_m,force_N, got {row}")
        data.append(vals)
    if len(data) < 4:
        raise TableError(f"{path}: need at least 4 data rows, got {len(data)}")
    a = np.array(data)
    f_max = float(np.max(a[:, 1]))
    if f_max <= 0:
        raise TableError(f"{path}: force_N never rises above 0 N")
    if np.min(a[:, 0]) < -u_offset_limit_m:
        i = int(np.argmin(a[:, 0])) + 2
        raise TableError(f"{path}, line {i}: u_m = {a[i - 2, 0]:g} m; u_m is the compression from the kiss "
                         f"point, allowed >= {-u_offset_limit_m:g} m (a small zero offset)")
    if np.min(a[:, 1]) < -F_OFFSET_LIMIT * f_max:
        i = int(np.argmin(a[:, 1])) + 2
        raise TableError(f"{path}, line {i}: force_N = {a[i - 2, 1]:g} N, below the allowed zero offset "
                         f"{-F_OFFSET_LIMIT * f_max:.3g} N ({F_OFFSET_LIMIT:.0%} of the largest force)")
    return Measured(a[:, 0], a[:, 1], basis, float(theta_degC), str(path),
                    settings.get("free_height_m"), settings.get("free_height_sd_m"))


def _settings(path: Path, lines: Sequence[str]) -> dict[str, float]:
    """The ``# key = value`` settings of a measured-curve file, checked (:data:`SETTINGS_M`), every problem at once."""
    out: dict[str, float] = {}
    problems, bad = [], set()
    for i, line in enumerate(lines, start=1):
        m = _SETTING.match(line.strip())
        if not m:
            continue
        key, text = m.groups()
        if key not in SETTINGS_M:
            problems.append(f"line {i}: unknown setting {key!r} (allowed: {', '.join(SETTINGS_M)}, in m)")
            continue
        if key in out or key in bad:
            problems.append(f"line {i}: {key} given twice")
            continue
        try:
            value = float(text)
        except ValueError:
            value = text
        lo, hi = SETTINGS_M[key]
        if isinstance(value, float) and math.isfinite(value) and lo <= value <= hi:
            out[key] = value
        else:
            bad.add(key)
            problems.append(f"line {i}: {key} = {text!r}: allowed {lo:g} .. {hi:g} m")
    if not bad:
        problems += free_height_problems(out.get("free_height_m"), out.get("free_height_sd_m"))
    if problems:
        raise TableError(f"{path}: " + "; ".join(problems))
    return out


def parse_measured(items: Sequence[str], basis: str = "pair",
                   reference_degC: float = 20.0) -> list[Measured]:
    """``--measured`` values: ``FILE`` (at the reference temperature) or ``THETA=FILE`` (degC).

    Raises
    ------
    ParameterError
        Bad temperature, a temperature given twice, no curve at the reference temperature.
    """
    out, problems, seen = [], [], set()
    for item in items:
        theta, sep, file = item.partition("=")
        if not sep:
            theta, file = f"{reference_degC:g}", item
        try:
            t = float(theta)
        except ValueError:
            problems.append(f"--measured {item!r}: expected FILE or THETA_DEGC=FILE")
            continue
        if not -60.0 <= t <= 400.0:
            problems.append(f"--measured {item!r}: temperature {t:g} degC outside -60..400 degC")
        elif t in seen:
            problems.append(f"--measured {item!r}: {t:g} degC given twice")
        else:
            seen.add(t)
            out.append((t, file))
    if out and reference_degC not in seen:
        problems.append(f"--measured: no curve at the reference temperature {reference_degC:g} degC "
                        "(hot curves are measured from its kiss point)")
    if problems:
        raise ParameterError(problems)
    # hot curves may start earlier by the kiss shift: calibrate checks them against the FE's (issue 28)
    return [read_measured(f, basis, t, U_OFFSET_LIMIT_M if t == reference_degC else HOT_U_READ_LIMIT_M)
            for t, f in out]
