"""Table sets and multi-set FMUs shared by tests/test_table_sets.py and tests/test_ssp.py (built once a session)."""
from __future__ import annotations

import atexit
import shutil
import tempfile
from functools import lru_cache
from pathlib import Path

from cushion_clutch.data import DEFAULT_TABLES
from cushion_clutch.fmu.build import build_fmu


def scaled_tables(dst: Path, factor: float, src: Path = DEFAULT_TABLES) -> Path:
    """A copy of the table set ``src`` in ``dst`` with every force_N multiplied by ``factor`` (the issue's DIR2)."""
    from cushion_clutch.fmu.ssp_doc import scaled_copy
    return scaled_copy(dst, factor, src)


@lru_cache(maxsize=None)
def _tmp() -> Path:
    tmp = Path(tempfile.mkdtemp(prefix="cushion_table_sets_"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    return tmp


@lru_cache(maxsize=None)
def soft_tables() -> Path:
    """DEFAULT_TABLES with every force scaled by 0.9, in a folder named soft (the docs' example set:
    cushion_clutch.fmu.ssp_doc.soft_copy, checked here to be the bar's scaled copy)."""
    from cushion_clutch.fmu.ssp_doc import SCALE, soft_copy
    assert SCALE == 0.9
    return soft_copy(_tmp() / "soft")


@lru_cache(maxsize=None)
def two_set_fmu(fmi_version: int = 2, backend: str = "native") -> Path:
    """The FMU carrying the default set (spring = 1) and :func:`soft_tables` (spring = 2)."""
    return build_fmu([DEFAULT_TABLES, soft_tables()], _tmp() / f"two_{backend}_{fmi_version}.fmu",
                     backend=backend, fmi_version=fmi_version)


@lru_cache(maxsize=None)
def soft_fmu(fmi_version: int = 2, backend: str = "native") -> Path:
    """The FMU built from :func:`soft_tables` alone."""
    return build_fmu(soft_tables(), _tmp() / f"soft_{backend}_{fmi_version}.fmu", backend=backend,
                     fmi_version=fmi_version)
