"""Benchmark: time per step of the CushionClutch FMU through fmpy, and of the model alone.

    python -m cushion_clutch.benchmarks.fmu [--steps 200000] [--fmu FILE]
"""
from __future__ import annotations

import argparse
import shutil
import tempfile
import time
from pathlib import Path


def main(argv=None) -> None:
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from cushion_clutch.fmu_build import build_fmu
    from cushion_clutch.model import DEFAULT_TABLES, ClutchParameters, load_table, outputs, thermal_step

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--fmu", type=Path, help="FMU to time (default: build from the default tables)")
    args = ap.parse_args(argv)
    n, h = args.steps, 1e-3
    with tempfile.TemporaryDirectory() as tmp:
        fmu = args.fmu or build_fmu(DEFAULT_TABLES, Path(tmp) / "CushionClutch.fmu")
        md = read_model_description(str(fmu))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        unzip = extract(str(fmu))
        s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier="CushionClutch",
                      instanceName="bench")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        vin, vout = [vr["x_to"], vr["theta_cm"]], [vr[k] for k in ("torque", "force", "theta_cs", "u_f", "x_kiss")]
        xs = [0.003 + 0.004 * (k % 1000) / 1000.0 for k in range(1000)]
        t0 = time.perf_counter()
        for k in range(n):
            s.setReal(vin, [xs[k % 1000], 450.0])
            s.doStep(k * h, h)
            s.getReal(vout)
        full = (time.perf_counter() - t0) / n
        t0 = time.perf_counter()
        for k in range(n):
            s.doStep((n + k) * h, h)
        step_only = (time.perf_counter() - t0) / n
        s.terminate()
        s.freeInstance()
        shutil.rmtree(unzip, ignore_errors=True)
    table, p = load_table(), ClutchParameters()
    theta = 293.15
    t0 = time.perf_counter()
    for k in range(n):
        theta = thermal_step(theta, 450.0, h, p)
        outputs(xs[k % 1000], theta, table, p)
    model = (time.perf_counter() - t0) / n
    print(f"steps: {n}, communication step {h:g} s")
    print(f"fmpy FMU2Slave set(2 inputs) + doStep + get(5 outputs): {full * 1e6:7.2f} us/step")
    print(f"fmpy FMU2Slave doStep alone:                           {step_only * 1e6:7.2f} us/step")
    print(f"model alone (thermal_step + outputs, Python):          {model * 1e6:7.2f} us/step")


if __name__ == "__main__":
    main()
