"""Package data, found through :mod:`importlib.resources` (never the repository root).

The wheel carries the shipped table sets (``cushion_clutch.lookup_tables``,
the repository's ``lookup_tables/``), the spring and scenario files, and the
FMU sources (``cushion_clutch.fmu_src``, the repository's ``fmu_src/``, a data
folder that nothing imports: the C model, the pythonfmu slave and the test hosts).
"""
from __future__ import annotations

from importlib.resources import files
from pathlib import Path


def _folder(package: str) -> Path:
    """File-system folder of a package shipped unzipped (wheels install so)."""
    return Path(str(files(package)))


def tables_root() -> Path:
    """Folder holding the shipped table sets (one sub-folder per spring)."""
    return _folder("cushion_clutch.lookup_tables")


def shipped_tables(name: str = "default") -> Path:
    """Folder of a shipped table set (``force_deflection.csv``, ``kiss_point.csv``, ...)."""
    return tables_root() / name


def fmu_sources() -> Path:
    """Folder of the FMU sources: the C model (``clutch_core.c``, ...), ``CushionClutch.py``, ``cushion_slave.py``."""
    return _folder("cushion_clutch.fmu_src")


#: the default spring parameter file
DEFAULT_SPRING = _folder("cushion_clutch.fe.springs") / "default.toml"
#: the default launch scenario
DEFAULT_SCENARIO = _folder("cushion_clutch.launch.scenarios") / "default.toml"
#: the default spring's table set
DEFAULT_TABLES = shipped_tables("default")
