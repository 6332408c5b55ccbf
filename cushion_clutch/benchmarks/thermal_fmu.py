"""The thermal clutch FMU (``build-fmu --thermal``) against its bar and against the launch plant.

1. The bar's duty: twelve 3 s slips at x_to = 7 mm and 100 rad/s (engine at 100 rad/s, disc held),
   60 s apart, Co-Simulation steps of 10 ms: slip energy, theta_cm rise per kJ, and whether theta_cm
   falls in every step while the clutch is open.
2. A launch of the default scenario run by :func:`~cushion_clutch.launch.simulate.simulate_launches`
   with the plant's network on (the plain clutch FMU in the loop, every 1 ms step recorded), its
   bearing position, slip and engine speeds replayed open-loop through the thermal FMU: the largest
   difference of theta_cm and theta_cs from the plant's. The two differ by construction (the plant's slip
   energy comes from the driveline's midpoint speeds and steps the network every TCU period with the
   mean power and the TCU's engaged flag as the clamp state; the FMU heats with torque * |omega_slip| held
   over each step and clamps on clamp force > 0); the lock-step test in ``tests/test_thermal_fmu.py``
   checks the same network and model to 1e-9.

    python -m cushion_clutch.benchmarks.thermal_fmu
"""
from __future__ import annotations

import dataclasses
import shutil
import tempfile
from pathlib import Path

import numpy as np


class CsInstance:
    """A Co-Simulation instance of an FMI 2.0 FMU, stepped with held inputs (fmpy); the tests use it too."""

    def __init__(self, fmu: Path, start: dict[str, float] | None = None, name: str = "bench"):
        from fmpy import extract, read_model_description
        from fmpy.fmi1 import FMICallException
        from fmpy.fmi2 import FMU2Slave
        md = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.unzip = extract(str(fmu))
        self.s = FMU2Slave(guid=md.guid, unzipDirectory=self.unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                           instanceName=name)
        self.s.instantiate()
        try:
            self.s.setupExperiment(startTime=0.0)
            if start:
                self.s.setReal([self.vr[k] for k in start], list(start.values()))
            self.s.enterInitializationMode()
            self.s.exitInitializationMode()
        except FMICallException:             # a refused start: nothing left behind
            self.s.freeInstance()
            shutil.rmtree(self.unzip, ignore_errors=True)
            raise
        self.t = 0.0

    def step(self, h: float, names: list[str], **inputs: float) -> list[float]:
        self.s.setReal([self.vr[k] for k in inputs], list(inputs.values()))
        self.s.doStep(self.t, h)
        self.t += h
        return self.s.getReal([self.vr[k] for k in names])

    def close(self) -> None:
        self.s.terminate()
        self.s.freeInstance()
        shutil.rmtree(self.unzip, ignore_errors=True)


def bar_duty(fmu: Path, h: float = 0.01) -> dict[str, float]:
    """The bar's twelve slips: slip energy (J), theta_cm rise (K) and per kJ, and the open steps where
    theta_cm did not fall (count)."""
    s = CsInstance(fmu)
    try:
        theta0 = s.step(0.0, ["theta_cm"], x_to=0.0, omega_slip=0.0, omega_engine=100.0)[0]
        energy, last, not_falling, peak = 0.0, theta0, 0, theta0
        for k in range(int(round(12 * 60.0 / h))):
            phase = (k * h) % 60.0
            slipping = phase < 3.0 - 1e-9
            th, power = s.step(h, ["theta_cm", "slip_power"], x_to=0.007 if slipping else 0.0,
                               omega_slip=100.0 if slipping else 0.0, omega_engine=100.0)
            energy += power * h
            if not slipping and phase > 3.0 + h and th >= last:
                not_falling += 1
            last, peak = th, max(peak, th)
    finally:
        s.close()
    return {"energy_J": energy, "rise_K": last - theta0, "K_per_kJ": (last - theta0) / (energy / 1e3),
            "peak_rise_K": peak - theta0, "open_steps_not_falling": not_falling}


def recorded_launch():
    """(scenario, LaunchResult): one shortened default launch with the plant's network on, through the plain clutch
    FMU with the naive TCU, every 1 ms step recorded (the thermal FMU's replay input)."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.crossbuild import HOST
    from cushion_clutch.fmu.native import build_native_fmu
    from cushion_clutch.launch.scenario import load_scenario
    from cushion_clutch.launch.simulate import simulate_launches
    from cushion_clutch.model import load_table

    sc = load_scenario()
    tcu = dataclasses.replace(sc.tcu, drive_time_s=4.0)
    sc = dataclasses.replace(sc, tcu=tcu, run=dataclasses.replace(sc.run, launches=1, quiet_steps=False,
                                                                  period_s=tcu.prefill_s + tcu.drive_time_s + 5.5),
                             plant_thermal=dataclasses.replace(sc.plant_thermal, enabled=True))
    with tempfile.TemporaryDirectory() as tmp:
        plain = build_native_fmu(DEFAULT_TABLES, Path(tmp) / "plain.fmu", platforms=(HOST[2],))
        return sc, simulate_launches(plain, sc, load_table(), "naive", record_every=1)


def plant_replay() -> dict[str, float]:
    """One default launch (network on) through simulate_launches, replayed through the thermal FMU."""
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.crossbuild import HOST
    from cushion_clutch.fmu.native import build_native_fmu
    from cushion_clutch.fmu.thermal_chain import chain_of
    from cushion_clutch.model import KELVIN

    sc, res = recorded_launch()
    s = res.series
    with tempfile.TemporaryDirectory() as tmp:
        thermal = build_native_fmu(DEFAULT_TABLES, Path(tmp) / "thermal.fmu", platforms=(HOST[2],),
                                   chain=chain_of(sc.plant_thermal))
        theta_a, theta0 = sc.facing.ambient_degC + KELVIN, sc.facing.initial_degC + KELVIN
        f = CsInstance(thermal, {"theta_a": theta_a, "theta_cs_start": theta0, "theta_network_start": theta0})
        try:
            out = np.array([f.step(sc.run.step_s, ["theta_cm", "theta_cs", "slip_power"], x_to=float(x),
                                   omega_slip=float(we - wd), omega_engine=float(we))
                            for x, we, wd in zip(s["x_to_m"], s["w_engine_rad_s"], s["w_disc_rad_s"])])
        finally:
            f.close()
    return {"steps": len(s), "plant_rise_K": float(s["theta_cm_K"].max() - theta0),
            "fmu_rise_K": float(out[:, 0].max() - theta0),
            "max_theta_cm_difference_K": float(np.abs(out[:, 0] - s["theta_cm_K"]).max()),
            "max_theta_cs_difference_K": float(np.abs(out[:, 1] - s["theta_cs_K"]).max()),
            "plant_slip_J": float(res.energy.slip), "fmu_slip_J": float(out[:, 2].sum() * sc.run.step_s)}


def main(argv=None) -> None:
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.model.thermal_network import NODES

    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_fmu(DEFAULT_TABLES, Path(tmp) / "thermal.fmu", thermal=True)
        b = bar_duty(fmu)
    print(f"network: {len(NODES)} nodes ({', '.join(NODES)})")
    print(f"bar duty: {b['energy_J'] / 1e3:.1f} kJ of slip, theta_cm +{b['rise_K']:.2f} K at the end "
          f"(peak +{b['peak_rise_K']:.2f} K): {b['K_per_kJ']:.3f} K/kJ (bar 0.05-0.5); open steps where theta_cm "
          f"did not fall: {b['open_steps_not_falling']}")
    r = plant_replay()
    print(f"plant replay ({r['steps']} steps of 1 ms): theta_cm rise plant {r['plant_rise_K']:.3f} K, FMU "
          f"{r['fmu_rise_K']:.3f} K; largest difference theta_cm {r['max_theta_cm_difference_K']:.4f} K, theta_cs "
          f"{r['max_theta_cs_difference_K']:.4f} K; slip energy plant {r['plant_slip_J']:.0f} J, "
          f"FMU {r['fmu_slip_J']:.0f} J")


if __name__ == "__main__":
    main()
