"""Shared fixtures: coarse-mesh parameters, a session cache for ccx cases, a Wine prefix."""
from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from cushion_clutch.fe.params import load_params

COARSE_M = 2e-3
WINE = Path("/usr/lib/wine/wine64")     # Debian wine64 (.ci/install)


def in_ci() -> bool:
    """True on a CI runner (``CI=true``, as GitHub Actions and most CI services set it)."""
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")


def missing_tool(reason: str):
    """A required tool is missing: a failure in CI (a broken install step must not turn failures
    into skips), a skip on a developer's machine without it."""
    if in_ci():
        pytest.fail(f"{reason} (CI=true: a missing tool is a failure, not a skip)", pytrace=False)
    pytest.skip(reason)


def pytest_runtest_setup(item):
    if "ccx" in item.keywords and shutil.which("ccx") is None:
        missing_tool("CalculiX (ccx) is not installed: apt-get install calculix-ccx")


@pytest.fixture(scope="session")
def coarse():
    """The default spring on the coarse test mesh."""
    return load_params().replace(mesh={"element_size_m": COARSE_M})


@pytest.fixture(scope="session")
def case_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("ccx_cache")


@pytest.fixture(scope="session")
def wine_env(tmp_path_factory):
    """Environment of one initialised Wine prefix for the Windows binaries' tests."""
    if not WINE.exists():
        missing_tool("wine64 is not installed (.ci/install installs it)")
    prefix = tmp_path_factory.mktemp("wineprefix")
    env = dict(os.environ, WINEPREFIX=str(prefix), WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    subprocess.run([str(WINE), "wineboot", "--init"], env=env, capture_output=True, timeout=300)
    return env


@pytest.fixture(autouse=True)
def _fmpy_logger_proxy():
    """Point fmpy's native printf proxy back at a logger that lives as long as the session.

    fmpy's ``logging`` library keeps ONE global pointer to the Python logger of the last
    ``addLoggerProxy`` call; ``simulate_fmu`` (and any custom callbacks) leave it pointing at a logger
    that is freed when they return. An instance made later with fmpy's default callbacks then calls a
    freed function as soon as the FMU logs: the native FMU logs its Warnings whatever ``loggingOn``
    (issue 28), so a test of it after such a test crashed the interpreter. Our code is not involved.
    """
    from cushion_clutch.fmpy_logger import restore_fmpy_logger

    restore_fmpy_logger()             # the package's one helper (the launch client and `simulate` call it too)
    yield
