"""Build the CushionClutch FMU from a table set: the front door for both backends.

:func:`build_fmu` checks the tables and hands over to the native C backend
(:mod:`.native`, the default) or to the pythonfmu backend (:mod:`.pythonfmu_backend`).
"""
from __future__ import annotations

import argparse
import logging
from pathlib import Path

from ..errors import FmuError, ParameterError, TableError
from ..model.table_format import REQUIRED_FILES, read_tables

log = logging.getLogger(__name__)


def build_fmu(tables, output: Path, backend: str = "native", fmi_version: int = 2,
              thermal: bool = False) -> Path:
    """Build ``output`` (.fmu) carrying the table set in ``tables`` (a folder), or every set of a list of
    folders: the enumeration parameter ``spring`` then picks one (:mod:`.table_sets`; native FMI 2.0 and 3.0
    and the pythonfmu backend, not the thermal variant).

    ``backend`` is ``"native"`` (C; loads in any FMI host; binaries for Windows,
    Linux and macOS; Co-Simulation and Model Exchange) or ``"python"``
    (pythonfmu; FMI 2.0 Co-Simulation; needs Python and numpy where it runs).
    ``fmi_version`` is 2 (FMI 2.0) or 3 (FMI 3.0, native only). ``thermal`` (native only)
    builds ``CushionClutchThermal``: the clutch with the plant's thermal network inside
    (:mod:`.thermal_chain`; inputs x_to, omega_slip, omega_engine; theta_cm an output).

    Raises
    ------
    TableError
        If the table set is missing or malformed (checked before building).
    """
    folders = [Path(t) for t in tables] if isinstance(tables, (list, tuple)) else [Path(tables)]
    tables, more, output = folders[0], tuple(folders[1:]), Path(output)
    check_output(output)
    for folder in folders:
        read_tables(folder)                             # fail early, with the file's name
        for name in REQUIRED_FILES:
            if not (folder / name).exists():
                raise TableError(f"{folder / name} is missing")
    if more:
        from .table_sets import carried_sets
        carried_sets(folders)                           # names, count, duplicates: before building
    if more and thermal:
        raise ParameterError(["thermal = true carries one table set (give --tables once)"])
    if fmi_version not in (2, 3):
        raise ParameterError([f"fmi_version = {fmi_version!r}: allowed 2 or 3"])
    if thermal and backend != "native":
        raise ParameterError([f"thermal = true needs backend 'native' (got {backend!r})"])
    output.parent.mkdir(parents=True, exist_ok=True)
    if backend == "native":
        from .native import build_native_fmu
        from .thermal_chain import chain_of
        return build_native_fmu(tables, output, fmi_version=fmi_version, chain=chain_of() if thermal else None,
                                more_tables=more)
    if backend != "python":
        raise ValueError(f"backend = {backend!r}: allowed 'python' or 'native'")
    if fmi_version != 2:
        raise ParameterError(["fmi_version = 3 needs backend 'native' (the pythonfmu backend writes FMI 2.0)"])
    from .pythonfmu_backend import build_python_fmu
    build_python_fmu(tables, output, more_tables=more)
    log.info("built %s from tables %s", output, tables)
    return output


def check_output(output: Path) -> None:
    """Refuse an FMU path that is a folder or does not end in ``.fmu`` (before anything is built).

    Raises
    ------
    FmuError
        Naming the path and what to give instead.
    """
    output = Path(output)
    if output.is_dir():
        raise FmuError(f"{output} is a folder; give the FMU's file name, e.g. {output / 'CushionClutch.fmu'}")
    if output.suffix.lower() != ".fmu":
        raise FmuError(f"{output}: an FMU's file name must end in .fmu (FMI hosts look for it); "
                       f"give {output.name}.fmu")


def add_backend(parser) -> None:
    """The ``--backend`` option shared by every command that builds an FMU."""
    parser.add_argument("--backend", choices=("native", "python"), default="native",
                        help="native: C, loads in any FMI host (default); "
                             "python: pythonfmu, needs Python + numpy where it runs")


def add_build_arguments(parser) -> None:
    """Options of ``cushion-clutch build-fmu`` and ``build_fmu.py`` (the same)."""
    from ..data import DEFAULT_TABLES
    parser.add_argument("--tables", type=Path, action="append", default=None,
                        help="table folder (force_deflection.csv, kiss_point.csv, metadata.json); give it more "
                             "than once to carry several sets, chosen by the FMU's enumeration parameter spring "
                             f"(default {DEFAULT_TABLES.name})")
    parser.add_argument("-o", "--out", dest="output", type=Path, default=Path("CushionClutch.fmu"),
                        help="FMU file to write, ending in .fmu (default CushionClutch.fmu)")
    parser.add_argument("--output", dest="output", type=Path, help=argparse.SUPPRESS)   # the old name
    add_backend(parser)
    parser.add_argument("--fmi-version", type=int, choices=(2, 3), default=2,
                        help="FMI 2.0 (default) or 3.0 (native backend only); both carry Co-Simulation "
                             "and Model Exchange")
    parser.add_argument("--thermal", action="store_true",
                        help="CushionClutchThermal: the clutch with the plant's thermal network inside (native "
                             "only): inputs x_to, omega_slip, omega_engine; theta_cm and the nodes' "
                             "temperatures are outputs")


def build_from_args(args) -> str:
    """Build the FMU that parsed ``build-fmu`` options describe; return a one-line report."""
    from ..model.clutch_model import ClutchParameters
    from ..model.table_format import table_set_x_kiss_ref
    version = getattr(args, "fmi_version", 2)
    thermal = getattr(args, "thermal", False)
    folders = table_folders(args)
    out = build_fmu(folders if len(folders) > 1 else folders[0], args.output, backend=args.backend,
                    fmi_version=version, thermal=thermal)
    own = table_set_x_kiss_ref(folders[0])
    kiss = (f"x_kiss_ref = {own * 1e3:.4f} mm (the table set's own kiss point, metadata.json tolerance_study)"
            if own is not None else f"x_kiss_ref = {ClutchParameters().x_kiss_ref * 1e3:.4f} mm (default)")
    what = f"{args.backend}, FMI {version}.0" + (", thermal network inside" if thermal else "")
    if len(folders) > 1:
        from .table_sets import carried_sets
        names = ", ".join(f"{s.index} = {s.name}" for s in carried_sets(folders))
        return (f"built {out} ({what}) with {len(folders)} table sets, parameter spring: {names}; "
                f"start spring = 1; {kiss} (set 1's)")
    return f"built {out} ({what}) from {folders[0]}; {kiss}"


def table_folders(args) -> list[Path]:
    """The ``--tables`` folders of parsed ``build-fmu`` options (the default set if none was given)."""
    from ..data import DEFAULT_TABLES
    tables = getattr(args, "tables", None)
    if tables is None:
        return [Path(DEFAULT_TABLES)]
    return [Path(t) for t in tables] if isinstance(tables, (list, tuple)) else [Path(tables)]
