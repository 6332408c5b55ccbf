"""Shared fixtures: coarse-mesh parameters and a session cache for ccx cases."""
from __future__ import annotations

import shutil

import pytest

from cushion_clutch.fe.params import load_params

COARSE_M = 2e-3


def pytest_collection_modifyitems(config, items):
    if shutil.which("ccx") is None:
        skip = pytest.mark.skip(reason="CalculiX (ccx) is not installed: apt-get install calculix-ccx")
        for item in items:
            if "ccx" in item.keywords:
                item.add_marker(skip)


@pytest.fixture(scope="session")
def coarse():
    """The default spring on the coarse test mesh."""
    return load_params().replace(mesh={"element_size_m": COARSE_M})


@pytest.fixture(scope="session")
def case_cache(tmp_path_factory):
    return tmp_path_factory.mktemp("ccx_cache")
