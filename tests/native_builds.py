"""The native FMUs (FMI 2.0 and 3.0, all platforms) built once per test session, shared by test modules."""
from __future__ import annotations

import atexit
import functools
import shutil
import tempfile
from pathlib import Path

from cushion_clutch.fmu.build import build_fmu
from cushion_clutch.fmu.model import DEFAULT_TABLES


@functools.cache
def native_fmus() -> dict[int, Path]:
    """{2: FMI 2.0 FMU, 3: FMI 3.0 FMU} of the default tables, every platform's binary inside."""
    tmp = Path(tempfile.mkdtemp(prefix="cushion_native_tests_"))
    atexit.register(shutil.rmtree, tmp, ignore_errors=True)
    return {v: build_fmu(DEFAULT_TABLES, tmp / f"fmi{v}.fmu", fmi_version=v) for v in (2, 3)}
