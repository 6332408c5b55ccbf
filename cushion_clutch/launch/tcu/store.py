"""The production TCU's adapted state, kept between drive cycles (a JSON file: its non-volatile memory).

Production AMT and DCT controllers keep the adapted touch point and friction in
non-volatile memory across key-off; after a reset or a clutch change they have
none and learn the touch point at standstill (:mod:`.touchpoint`). The stored
state here: the touch-point offset and its standard deviation (in the
position sensor's frame, m), the friction scale, the two thermal scales of the
TCU's network, whether the touch point came from the standstill routine, and
the key-ons since it was last learned there.
"""
from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

from ...errors import ParameterError
from ...number_check import is_finite_number, is_number

#: format version of the file
VERSION = 1


@dataclass(frozen=True)
class AdaptedState:
    """What the production TCU stores at key-off (SI)."""

    dx_kiss_m: float = 0.0
    """touch-point offset at the bearing, position sensor's frame, m"""
    dx_kiss_sd_m: float = math.nan
    """its standard deviation, m (NaN: none stored, the TCU's prior applies)"""
    mu_scale: float = 1.0
    loss_scale: float = 1.0
    heat_scale: float = 1.0
    touch_point_learned: bool = False
    """a touch point is stored (learned at standstill or in launches)"""
    starts_since_standstill: int = 0
    """key-ons since the touch point was last learned at standstill"""

    def problems(self) -> list[str]:
        """Every out-of-range value, named."""
        out = []
        for key, lo, hi in (("dx_kiss_m", -0.005, 0.005), ("mu_scale", 0.3, 3.0), ("loss_scale", 0.0, 100.0),
                            ("heat_scale", 0.0, 100.0)):
            v = getattr(self, key)
            if not is_finite_number(v) or not lo <= v <= hi:
                out.append(f"{key} = {v!r}: allowed [{lo}, {hi}]")
        if not (is_number(self.dx_kiss_sd_m) and (math.isnan(self.dx_kiss_sd_m)
                                                                   or 0.0 < self.dx_kiss_sd_m < 0.01)):
            out.append(f"dx_kiss_sd_m = {self.dx_kiss_sd_m!r}: allowed (0, 0.01) or NaN")
        if not isinstance(self.touch_point_learned, bool):
            out.append(f"touch_point_learned = {self.touch_point_learned!r}: must be true or false")
        if not (is_number(self.starts_since_standstill) and isinstance(self.starts_since_standstill, int)) \
                or self.starts_since_standstill < 0:
            out.append(f"starts_since_standstill = {self.starts_since_standstill!r}: must be an integer >= 0")
        return out


def save_state(state: AdaptedState, path: str | Path) -> Path:
    """Write ``state`` as JSON (NaN as null); the file's path."""
    d = {k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in asdict(state).items()}
    path = Path(path)
    path.write_text(json.dumps({"version": VERSION, **d}, indent=2) + "\n")
    return path


def load_state(path: str | Path) -> AdaptedState:
    """Read a state written by :func:`save_state`.

    Raises
    ------
    ParameterError
        The file is missing, not JSON, of another version, has unknown keys or values out of range.
    """
    path = Path(path)
    if not path.is_file():
        raise ParameterError([f"tcu_store.file: {path} not found"])
    try:
        data = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ParameterError([f"tcu_store.file: {path} is not JSON ({exc})"]) from exc
    if not isinstance(data, dict) or data.get("version") != VERSION:
        raise ParameterError([f"tcu_store.file: {path}: version must be {VERSION}"])
    data.pop("version")
    known = set(AdaptedState.__dataclass_fields__)
    problems = [f"{k}: unknown key" for k in data if k not in known]
    if data.get("dx_kiss_sd_m", 0.0) is None:
        data["dx_kiss_sd_m"] = math.nan
    if not problems:
        state = AdaptedState(**data)
        problems = state.problems()
    if problems:
        raise ParameterError(problems, str(path))
    return state
