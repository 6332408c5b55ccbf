"""The plant clutch FMU of a scenario: the table set plus the scenario's friction table.

The FMU carries ``friction.csv`` in its resources when the table folder has
one; a scenario's ``clutch.friction_csv`` is staged next to a copy of the
spring tables so that the plant FMU gets it and the slip speed input selects
mu(theta_cm, omega_slip). Without one, mu = 0.28 constant (the paper's model).
"""
from __future__ import annotations

import shutil
from pathlib import Path

from ...model.table_format import FORCE_DEFLECTION, FRICTION, KISS_POINT, METADATA
from ..scenario.load import Scenario

SPRING_FILES = (FORCE_DEFLECTION, KISS_POINT, METADATA)


def plant_tables(tables: Path, sc: Scenario, work: Path) -> Path:
    """Folder of the plant's tables: ``tables`` (or the scenario's ``clutch.plant_tables``), or a copy in
    ``work`` with the scenario's friction table."""
    tables = sc.tables_path("plant") or tables
    friction = sc.friction_path()
    if friction is None:
        return Path(tables)
    stage = Path(work) / "plant_tables"
    stage.mkdir(parents=True, exist_ok=True)
    for name in SPRING_FILES:
        if (Path(tables) / name).exists():
            shutil.copy(Path(tables) / name, stage / name)
    shutil.copy(friction, stage / FRICTION)
    return stage


def build_plant_fmu(tables: Path, sc: Scenario, out: Path, backend: str = "native") -> Path:
    """Build the plant FMU ``out`` for the scenario (see :func:`plant_tables`)."""
    from ...fmu.build import build_fmu

    return build_fmu(plant_tables(tables, sc, Path(out).parent), Path(out), backend=backend)
