"""Benchmark: real-time factor of a launch scenario for every TCU variant (simulated s per wall s).

    python -m cushion_clutch.benchmarks.launch [--scenario NAME|FILE] [--backend native|python] [--repeat N]

Also times one FMU step (set inputs, doStep, get outputs) through the
master's cffi client and through fmpy's ``FMU2Slave`` in the same run.
Machines are noisy: compare figures from one run, or medians (``--repeat``).
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path


def _fmu_call_us(fmu: Path, n: int = 50000) -> tuple[float, float]:
    """Microseconds per step: the cffi client and fmpy FMU2Slave (name-based set/get)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from cushion_clutch.launch.fmu_client import INPUTS, OUTPUTS, ClutchFmu

    c = ClutchFmu(fmu, {})
    t0 = time.perf_counter()
    for k in range(n):
        c.step(k * 1e-3, 1e-3, 0.005, 400.0, 10.0)
    ours = (time.perf_counter() - t0) / n * 1e6
    c.close()
    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzip = extract(str(fmu))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier)
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    vin, vout = [vr[x] for x in INPUTS], [vr[x] for x in OUTPUTS]
    t0 = time.perf_counter()
    for k in range(n):
        s.setReal(vin, [0.005, 400.0, 10.0])
        s.doStep(k * 1e-3, 1e-3)
        s.getReal(vout)
    theirs = (time.perf_counter() - t0) / n * 1e6
    s.terminate()
    s.freeInstance()
    return ours, theirs


def main(argv=None) -> None:
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import load_table
    from cushion_clutch.launch.plant import build_plant_fmu
    from cushion_clutch.launch.scenario import DEFAULT_SCENARIO, load_scenario, scenario_path
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.launch.tcu import VARIANTS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenario", default=str(DEFAULT_SCENARIO))
    ap.add_argument("--backend", default="native", choices=("native", "python"))
    ap.add_argument("--repeat", type=int, default=1, help="runs per variant; the median is printed")
    args = ap.parse_args(argv)
    sc = load_scenario(scenario_path(args.scenario))
    sim = sc.run.duration()
    steps = sim / sc.run.step_s
    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_plant_fmu(DEFAULT_TABLES, sc, Path(tmp) / "CushionClutch.fmu", backend=args.backend)
        ours, theirs = _fmu_call_us(fmu)
        print(f"FMU step (set 3 inputs, doStep, get 3 outputs), {args.backend} FMU: {ours:.2f} us through the "
              f"cffi client, {theirs:.2f} us through fmpy FMU2Slave ({theirs / ours:.1f}x)")
        for name in VARIANTS:
            runs = [simulate_launches(fmu, sc, load_table(), name) for _ in range(args.repeat)]
            wall = statistics.median(r.wall_time_s for r in runs)
            cpu = statistics.median(r.cpu_time_s for r in runs)
            print(f"{name:>24} TCU: {sim:g} s simulated in {wall:.2f} s wall -> real-time factor "
                  f"{sim / wall:.0f}x ({wall / steps * 1e6:.2f} us per {sc.run.step_s * 1e3:g} ms step); "
                  f"CPU time {cpu:.2f} s -> {sim / cpu:.0f}x")


if __name__ == "__main__":
    main()
