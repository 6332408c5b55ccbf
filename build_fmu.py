#!/usr/bin/env python3
"""Build CushionClutch.fmu from a lookup-table folder: ``cushion-clutch build-fmu`` as a script.

    python build_fmu.py [--tables DIR] [-o CushionClutch.fmu] [--backend native|python]
"""
from __future__ import annotations

import sys

from cushion_clutch.cli import main

if __name__ == "__main__":
    sys.exit(main(["build-fmu", *sys.argv[1:]]))
