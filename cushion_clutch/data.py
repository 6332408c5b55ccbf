"""Package data, found through :mod:`importlib.resources` (never the repository root).

The wheel carries the shipped table sets (``cushion_clutch.lookup_tables``,
the repository's ``lookup_tables/``), the spring and scenario files, and the
FMU sources (``cushion_clutch.fmu_src``, the repository's ``fmu_src/``, a data
folder that nothing imports), one folder per role: ``core/`` (the C model, the twin of
:mod:`cushion_clutch.model`), ``fmi/`` (the FMI 2.0 and 3.0 front ends), ``hosts/`` (the launch plant's and the
production TCU's host libraries), ``pythonfmu/`` (the pythonfmu slave and its guard library) and ``bench/`` (the
C hosts the shipped benchmarks compile).
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
    """Folder of the FMU sources, one sub-folder per role (:data:`FMU_ROLES`)."""
    return _folder("cushion_clutch.fmu_src")


#: the role folders of the FMU sources (``fmu_src/<role>/``); a file name is unique across them
FMU_ROLES = ("core", "fmi", "hosts", "pythonfmu", "bench")


def fmu_source(name: str) -> Path:
    """The FMU source file ``name`` (``clutch_core.c``, ``launch_plant.h``, ...) in its role folder.

    Raises
    ------
    FileNotFoundError
        If no role folder holds ``name``.
    """
    root = fmu_sources()
    for role in FMU_ROLES:
        if (root / role / name).is_file():
            return root / role / name
    raise FileNotFoundError(f"{name}: not an FMU source (looked in {', '.join(FMU_ROLES)} of {root})")


#: the default spring parameter file
DEFAULT_SPRING = _folder("cushion_clutch.fe.springs") / "default.toml"
#: the default launch scenario
DEFAULT_SCENARIO = _folder("cushion_clutch.launch.scenarios") / "default.toml"
#: the default spring's table set
DEFAULT_TABLES = shipped_tables("default")
