"""Shared constants of the FMU builds: model identifier, units, source folders and file lists.

Every other module of :mod:`cushion_clutch.fmu` takes these from here; this module
imports nothing of the FMU builds (the bottom of the package).
"""
from __future__ import annotations

from pathlib import Path

from ..data import fmu_sources
from ..model import clutch_model

#: the FMUs' model identifier and modelName
SLAVE = "CushionClutch"
#: folder of the FMU sources, one sub-folder per role (:data:`cushion_clutch.data.FMU_ROLES`; a file's path:
#: :func:`cushion_clutch.data.fmu_source`)
FMU_SRC = fmu_sources()
#: the pythonfmu backend's sources (the slave, its table-set reader, the guard library)
PYTHONFMU_SRC = FMU_SRC / "pythonfmu"
#: folder of the numpy-only model modules (:mod:`cushion_clutch.model`)
MODEL_SRC = Path(clutch_model.__file__).parent
#: the package's ground floor (:mod:`cushion_clutch.number_check`, which the model and the loaders share, and
#: :mod:`cushion_clutch.errors`, whose TableError the table reader raises)
PACKAGE_SRC = MODEL_SRC.parent
#: the modules the pythonfmu slave imports (siblings inside the FMU): the slave class (from ``PYTHONFMU_SRC``)
#: and the numpy-only model (from ``MODEL_SRC``, its number check and errors from ``PACKAGE_SRC``)
SLAVE_MODULES = {"cushion_slave.py": PYTHONFMU_SRC, "slave_table_sets.py": PYTHONFMU_SRC, "clutch_model.py": MODEL_SRC,
                 "spring_table.py": MODEL_SRC,
                 "friction.py": MODEL_SRC, "table_format.py": MODEL_SRC, "cover.py": MODEL_SRC,
                 "number_check.py": PACKAGE_SRC, "errors.py": PACKAGE_SRC}

#: the native model core (shared) and the front end of each FMI version, as shipped in sources/ (flat there: the
#: role folders of ``FMU_SRC`` are a layout of the package only; :func:`cushion_clutch.data.fmu_source` finds each)
CORE_HEADERS = ("clutch_core.h", "clutch_tables.h", "clutch_cover.h", "resource_uri.h")
CORE_SOURCES = ("clutch_core.c", "clutch_tables.c", "clutch_cover.c", "resource_uri.c")
FRONT_ENDS = {2: "fmi2_frontend.c", 3: "fmi3_frontend.c"}
#: the pythonfmu FMU's guard library
GUARD_SOURCES = ("pythonfmu_guard.c", "resource_uri.c")
GUARD_HEADERS = ("resource_uri.h",)
#: the FMI standard headers each FMI version compiles against (from FMPy, :func:`fmi_header_dir`)
FMI_HEADERS = {2: ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               3: ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}

#: SI base-unit exponents of each unit of the model's variables
BASE_UNITS = {
    "m": {"m": "1"}, "K": {"K": "1"}, "N": {"kg": "1", "m": "1", "s": "-2"},
    "N.m": {"kg": "1", "m": "2", "s": "-2"}, "W/K": {"kg": "1", "m": "2", "s": "-3", "K": "-1"},
    "J/K": {"kg": "1", "m": "2", "s": "-2", "K": "-1"}, "1": {}, "rad/s": {"s": "-1", "rad": "1"},
    "Pa": {"kg": "1", "m": "-1", "s": "-2"}, "1/K": {"K": "-1"}, "m/N": {"kg": "-1", "s": "2"},
}


def sources(fmi_version: int) -> tuple[str, ...]:
    """C files compiled into the native FMI ``fmi_version`` binary."""
    return (*CORE_SOURCES, FRONT_ENDS[fmi_version])


def fmi_header_dir() -> Path:
    """The FMI 2.0 and 3.0 standard headers shipped with FMPy."""
    import fmpy
    return Path(fmpy.__file__).parent / "c-code"


fmi2_header_dir = fmi_header_dir
