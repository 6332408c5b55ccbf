#!/usr/bin/env python3
"""Build CushionClutch.fmu (FMI 2.0 co-simulation) from a lookup-table folder.

    python build_fmu.py [--tables lookup_tables/default] [-o CushionClutch.fmu] [--backend python|native]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv: list[str] | None = None) -> int:
    sys.path.insert(0, str(HERE))
    from cushion_clutch.errors import TableError
    from cushion_clutch.fmu_build import build_fmu

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tables", type=Path, default=HERE / "lookup_tables" / "default",
                    help="table folder (force_deflection.csv, kiss_point.csv, metadata.json)")
    ap.add_argument("-o", "--output", type=Path, default=Path("CushionClutch.fmu"), help="FMU file")
    ap.add_argument("--backend", choices=("python", "native"), default="python",
                    help="python: pythonfmu (needs Python + numpy where it runs); "
                         "native: C compiled with gcc, loads in any FMI host")
    args = ap.parse_args(argv)
    try:
        out = build_fmu(args.tables, args.output, backend=args.backend)
    except (TableError, RuntimeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(f"built {out} ({args.backend}) from {args.tables}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
