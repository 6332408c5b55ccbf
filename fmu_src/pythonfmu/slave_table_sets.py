# Table sets of the pythonfmu slave (issue 42): the sets after the first (resources/tables_2, tables_3, ...) with
# their kiss-point offsets, as the native core's cc_table_sets_load reads them (fmu_src/core/clutch_tables.c).
# Copied into the FMU next to cushion_slave.py (cushion_clutch.fmu.constants.SLAVE_MODULES). Comments, not
# docstrings: pythonfmu's wrapper re-imports sibling modules per instance (see CushionClutch.py).
from __future__ import annotations

import math
from pathlib import Path

from clutch_model import SpringTable

#: the sets' folders after the first, the offset file, the most sets (as clutch_tables.h)
KISS_OFFSET_FILE = "x_kiss_ref_offset_m.txt"
MAX_SETS = 64


def more_sets(resources):
    # [(table or None, kiss offset m, error or None)] of resources/tables_2, tables_3, ... until one is missing
    out = []
    if not resources:
        return out
    for k in range(2, MAX_SETS + 1):
        folder = Path(resources) / f"tables_{k}"
        if not (folder / "force_deflection.csv").is_file():
            break
        offset, error = 0.0, None
        path = folder / KISS_OFFSET_FILE
        if path.is_file():
            try:
                offset = float(path.read_text().strip())
            except ValueError:
                offset = math.nan
            if not (math.isfinite(offset) and abs(offset) < 0.1):
                offset, error = 0.0, f"{path}: must hold one number, the set's kiss-point offset in m, |offset| < 0.1 m"
        try:
            table = SpringTable.from_dir(folder) if error is None else None
        except Exception as exc:  # noqa: BLE001 - reported at initialisation, never raised
            table, error = None, f"cannot load the F(u, theta) tables of {folder.name}: {exc}"
        out.append((table, offset, error))
    return out
