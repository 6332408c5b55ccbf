"""Write a production TCU's stored adapted state: run a scenario with a reset TCU and keep its state at key-off.

    python -m cushion_clutch.benchmarks.learned_state wear cushion_clutch/launch/scenarios/wear_learned.json

The file is what a scenario with ``tcu_store.start = "learned"`` starts from (the shipped ``wear_learned``
scenario reads ``wear_learned.json``, written by the command above). It lives here, beside the scripts that
write shipped results, and not in :mod:`cushion_clutch.launch.tcu.store`, which the TCU itself imports.
"""
from __future__ import annotations

import argparse
import dataclasses
import tempfile
from pathlib import Path


def learn_state(scenario: str | Path, out: Path, tables: Path | None = None) -> Path:
    """Run ``scenario`` with a reset production TCU and store its adapted state at key-off in ``out`` (JSON)."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.launch.plant.build import build_plant_fmu
    from cushion_clutch.launch.scenario import load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.launch.scenario.tcu_params import TcuStore
    from cushion_clutch.model import load_table

    sc = load_scenario(scenario_path(str(scenario)))
    sc = dataclasses.replace(sc, tcu_store=TcuStore(start="reset", save=str(Path(out).resolve())))
    tables = Path(tables or DEFAULT_TABLES)
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_plant_fmu(tables, sc, Path(tmp) / "CushionClutch.fmu")
        simulate_launches(fmu, sc, load_table(sc.tables_path("tcu") or tables), "production")
    return Path(out)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario", help="shipped scenario name or TOML file, run with a reset production TCU")
    ap.add_argument("out", type=Path, help="JSON file to write")
    args = ap.parse_args(argv)
    print(learn_state(args.scenario, args.out))


if __name__ == "__main__":
    main()
