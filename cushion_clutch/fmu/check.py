"""Check that a file given as ``--fmu`` is a CushionClutch co-simulation FMU, before loading it.

A host that loads a wrong file learns little from a failing ``dlopen`` or a
missing variable deep in a simulation; this check names the file and what is
wrong with it.
"""
from __future__ import annotations

import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from ..errors import FmuError
from ..model import VARIABLES


def check_fmu(path: str | Path) -> Path:
    """Return ``path`` if it is an FMI 2.0 co-simulation FMU with the CushionClutch variables.

    Raises
    ------
    FmuError
        Naming the file: missing, not a zip archive, no or malformed
        ``modelDescription.xml``, not FMI 2.0 co-simulation, or a variable of
        :data:`~cushion_clutch.model.clutch_model.VARIABLES` missing or with
        another causality.
    """
    path = Path(path)
    if not path.is_file():
        raise FmuError(f"{path}: FMU file does not exist" if not path.exists() else f"{path}: not a file")
    try:
        with zipfile.ZipFile(path) as z:
            if "modelDescription.xml" not in z.namelist():
                raise FmuError(f"{path}: not an FMU (the archive has no modelDescription.xml)")
            root = ET.fromstring(z.read("modelDescription.xml"))
    except zipfile.BadZipFile as exc:
        raise FmuError(f"{path}: not an FMU (not a zip archive)") from exc
    except ET.ParseError as exc:
        raise FmuError(f"{path}: modelDescription.xml is not well-formed XML: {exc}") from exc
    except OSError as exc:
        raise FmuError(f"{path}: cannot be read: {exc}") from exc
    if root.tag != "fmiModelDescription" or root.get("fmiVersion") != "2.0":
        raise FmuError(f"{path}: not an FMI 2.0 model description (fmiVersion = {root.get('fmiVersion')!r})")
    if root.find("CoSimulation") is None:
        raise FmuError(f"{path}: the FMU has no CoSimulation interface")
    found = {v.get("name"): v.get("causality", "local") for v in root.iter("ScalarVariable")}
    problems = []
    for name, causality, unit, _ in VARIABLES:
        if name not in found:
            problems.append(f"{name} ({causality}, {unit}) missing")
        elif found[name] != causality:
            problems.append(f"{name} has causality {found[name]!r}, expected {causality!r}")
    if problems:
        raise FmuError(f"{path}: not a CushionClutch FMU: " + "; ".join(problems))
    return path
