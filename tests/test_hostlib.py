"""The FMU sources by role (data.fmu_source) and the host libraries' declarations (fmu.hostlib.declarations)."""
from __future__ import annotations

import re

import pytest

from cushion_clutch.data import FMU_ROLES, fmu_source, fmu_sources
from cushion_clutch.fmu.hostlib import GENERATED, LIBRARY_ROLES, declarations


def test_every_source_is_found_in_its_role_folder_and_names_are_unique():
    """Every file of fmu_src's role folders is found by its name alone (the FMU's sources/ are flat), so no two
    roles may hold one name; nothing but __init__.py sits outside a role folder."""
    root = fmu_sources()
    files = [p for role in FMU_ROLES for p in (root / role).iterdir() if p.is_file()]
    names = [p.name for p in files]
    assert len(names) == len(set(names)), sorted(n for n in names if names.count(n) > 1)
    assert all(fmu_source(p.name) == p for p in files)
    assert {p.name for p in root.iterdir() if p.is_file()} == {"__init__.py"}
    assert set(LIBRARY_ROLES) < set(FMU_ROLES)


def test_an_unknown_source_names_the_folders_looked_in():
    with pytest.raises(FileNotFoundError, match=r"nope\.c: not an FMU source \(looked in core, fmi, hosts"):
        fmu_source("nope.c")


def test_declarations_inline_the_quoted_includes_once_and_drop_the_preprocessor():
    """The launch plant's cffi declarations: its own and the thermal step's (TnNode, tn_chain_step), no
    preprocessor line left, each declaration once."""
    text = declarations("launch_plant.h")
    assert not [line for line in text.splitlines() if line.lstrip().startswith("#")]
    assert len(re.findall(r"}\s*TnNode;", text)) == 1
    assert "void tn_chain_step(" in text and "} lp_consts;" in text
    assert declarations("tcu_model.h") == fmu_source("tcu_model.h").read_text().rstrip("\n")   # no includes there


def test_generated_headers_are_not_in_the_tree():
    """A header the build generates (the cover's enum) must not also sit in a role folder (it would shadow it)."""
    for name in GENERATED:
        with pytest.raises(FileNotFoundError):
            fmu_source(name)
