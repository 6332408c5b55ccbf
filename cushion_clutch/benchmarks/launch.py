"""Benchmark: real-time factor of the default launch scenario (simulated s per wall s).

    python -m cushion_clutch.benchmarks.launch [--scenario FILE]
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path


def main(argv=None) -> None:
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.fmu.model import DEFAULT_TABLES, load_table
    from cushion_clutch.launch.scenario import DEFAULT_SCENARIO, load_scenario

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default=DEFAULT_SCENARIO)
    args = ap.parse_args(argv)
    sc = load_scenario(args.scenario)
    sim = sc.run.launches * sc.run.period_s
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_fmu(DEFAULT_TABLES, Path(tmp) / "CushionClutch.fmu")
        for aware in (False, True):
            res = simulate_launches(fmu, sc, load_table(), aware)
            steps = sim / sc.run.step_s
            print(f"{res.tcu:>5} TCU: {sim:g} s simulated in {res.wall_time_s:.2f} s wall -> real-time factor "
                  f"{sim / res.wall_time_s:.0f}x ({res.wall_time_s / steps * 1e6:.1f} us per {sc.run.step_s * 1e3:g} ms step)")


if __name__ == "__main__":
    main()
