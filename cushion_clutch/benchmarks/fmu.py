"""Benchmark: time per step of the CushionClutch FMUs (pythonfmu and native C), and the native build time.

Through fmpy (FMU2Slave: set 2 inputs, doStep, get 5 outputs), in our small C
host (fmu_src/hosts/fmi2_host.c, dlopen; with valgrind also the native step's instructions, callgrind, which
do not depend on the machine's load), and the Python model alone; the time
to build the native FMU with the binaries of every platform (FMI 2.0: 3, FMI 3.0: 5),
with zig's cache warm, and with ``--cold`` also from an empty zig cache.

    python -m cushion_clutch.benchmarks.fmu [--steps 200000] [--cold] [--thermal-only] [--ab REF]

The thermal FMU (``build-fmu --thermal``) against the plain one, both native in the C host
``fmu_src/hosts/fmi2_duty_host.c`` on the same bearing sweep with 100 rad/s of slip (the plain FMU
also gets a theta_cm sweep, the thermal one an engine speed): median of 5 alternating runs and the ratio
(target: at most 3x). ``--thermal-only`` runs only this comparison.

``--ab REF`` compares the native step of this checkout's C sources with those of git ref ``REF`` (e.g. ``main``):
both built for linux64 with the FMU build's compiler and flags, from the same generated headers and tables, run
alternately in the C host (median of 9 on the same machine state), their callgrind instructions per step (if
valgrind is installed) and whether every output of every step is the same bit for bit (the host's ``checksum``).
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sysconfig
import tempfile
import time
import zipfile
from pathlib import Path


def time_fmpy(fmu: Path, n: int, h: float = 1e-3) -> tuple[float, float]:
    """(us per set+doStep+get, us per doStep alone) through fmpy's FMU2Slave."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    unzip = extract(str(fmu))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="bench")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    vin = [vr["x_to"], vr["theta_cm"]]
    vout = [vr[k] for k in ("torque", "force", "theta_cs", "u_f", "x_kiss")]
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
    return full * 1e6, step_only * 1e6


def compile_host(dest: Path) -> Path:
    from cushion_clutch.data import fmu_sources
    from cushion_clutch.fmu.native import fmi2_header_dir
    subprocess.run([shutil.which("gcc") or "cc", "-std=c99", "-D_POSIX_C_SOURCE=199309L", "-O2",
                    f"-I{fmi2_header_dir()}", str(fmu_sources() / "hosts" / "fmi2_host.c"), "-o", str(dest), "-ldl"], check=True)
    return dest


def time_c_host(host: Path, fmu: Path, n: int, python: bool, workdir: Path) -> tuple[float, int, str]:
    """(us per set+doStep+get in the C host, exit code, stderr tail)."""
    from fmpy import read_model_description

    unzip = workdir / fmu.stem
    zipfile.ZipFile(fmu).extractall(unzip)
    env = dict(os.environ)
    if python:   # a pythonfmu binary loads only with libpython preloaded
        env["LD_PRELOAD"] = os.path.join(sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("LDLIBRARY"))
        import numpy
        env["PYTHONPATH"] = str(Path(numpy.__file__).parents[1])
    res = subprocess.run([str(host), str(unzip / "binaries/linux64/CushionClutch.so"),
                          (unzip / "resources").as_uri(), read_model_description(str(fmu)).guid, str(n), "0.001"],
                         capture_output=True, text=True, env=env)
    us = float("nan")
    for line in res.stdout.splitlines():
        if line.startswith("us_per_step"):
            us = float(line.split()[1])
    return us, res.returncode, res.stderr.strip()[-200:]


def native_instructions(host: Path, fmu: Path, workdir: Path) -> float | None:
    """Instructions per set+doStep+get of the native FMU in the C host (callgrind: 120 000 steps minus 20 000, so
    start-up cancels; independent of the machine's load), or None without valgrind. ``fmu`` must have been
    extracted into ``workdir`` by :func:`time_c_host`."""
    from fmpy import read_model_description

    if not shutil.which("valgrind"):
        return None
    unzip = workdir / fmu.stem
    cmd = [str(host), str(unzip / "binaries/linux64/CushionClutch.so"), (unzip / "resources").as_uri(),
           read_model_description(str(fmu)).guid]
    return (_callgrind_ir(cmd + ["120000", "0.001"]) - _callgrind_ir(cmd + ["20000", "0.001"])) / 100_000


def time_thermal(tmp: Path, n: int, repeats: int = 5) -> tuple[float, float]:
    """(plain, thermal) native FMI 2.0 FMU: median us per set+doStep+get in the C duty host; prints the ratio."""
    import statistics

    from fmpy import read_model_description

    from cushion_clutch.data import DEFAULT_TABLES, fmu_sources
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.fmu.native import fmi2_header_dir

    host = tmp / "duty_host"
    subprocess.run([shutil.which("gcc") or "cc", "-std=c99", "-D_POSIX_C_SOURCE=199309L", "-O2",
                    f"-I{fmi2_header_dir()}", str(fmu_sources() / "hosts" / "fmi2_duty_host.c"), "-o", str(host),
                    "-ldl"], check=True)
    runs = {}
    for label, thermal in (("plain", False), ("thermal", True)):
        fmu = build_fmu(DEFAULT_TABLES, tmp / f"duty_{label}.fmu", thermal=thermal)
        md = read_model_description(str(fmu))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        unzip = tmp / f"duty_{label}"
        zipfile.ZipFile(fmu).extractall(unzip)
        ins = ("x_to", "omega_slip", "omega_engine") if thermal else ("x_to", "theta_cm", "omega_slip")
        lib = unzip / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
        runs[label] = [str(host), str(lib), (unzip / "resources").as_uri(), md.guid, str(n), "0.001",
                       *(str(vr[k]) for k in ins), "1" if thermal else "0"]
    times: dict[str, list[float]] = {"plain": [], "thermal": []}
    for _ in range(repeats):
        for label, cmd in runs.items():
            res = subprocess.run(cmd, capture_output=True, text=True, check=True)
            times[label].append(next(float(x.split()[1]) for x in res.stdout.splitlines()
                                     if x.startswith("us_per_step")))
    plain, thermal = statistics.median(times["plain"]), statistics.median(times["thermal"])
    print(f"C duty host, {n} steps of 1 ms, median of {repeats}: plain FMU {plain:.3f} us/step, "
          f"thermal FMU {thermal:.3f} us/step, ratio {thermal / plain:.2f} (target <= 3)")
    return plain, thermal


def _host_run(cmd: list[str]) -> dict[str, str]:
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    return {ln.split()[0]: ln.split(None, 1)[1] for ln in out.splitlines() if ln.strip()}


def _callgrind_ir(cmd: list[str]) -> int:
    res = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", *cmd],
                         capture_output=True, text=True, check=True)
    return int(next(ln for ln in res.stderr.splitlines() if "Collected" in ln).split()[-1])


def time_ab(tmp: Path, ref: str, n: int, repeats: int = 9) -> dict[str, float]:
    """The native FMI 2.0 step of git ref ``ref``'s C sources against this checkout's: median us per
    set+doStep+get in the C host (alternating runs), callgrind Ir per step, and the bit-for-bit checksum."""
    import statistics

    from fmpy import read_model_description

    from cushion_clutch.data import DEFAULT_TABLES, fmu_sources
    from cushion_clutch.fmu.constants import CORE_HEADERS
    from cushion_clutch.fmu.crossbuild import HOST, compile_command
    from cushion_clutch.fmu.native import build_native_fmu, sources

    fmu = build_native_fmu(DEFAULT_TABLES, tmp / "ab.fmu", 2, platforms=(HOST[2],))
    unzip = tmp / "ab"
    zipfile.ZipFile(fmu).extractall(unzip)
    guid = read_model_description(str(fmu)).guid
    files = sources(2)
    libs = {}
    for label in (ref, "worktree"):
        src = tmp / f"src_{len(libs)}"
        shutil.copytree(unzip / "sources", src)
        if label == ref:                 # the ref's model sources over the generated headers of this checkout
            for name in (*files, *CORE_HEADERS):
                got = subprocess.run(["git", "-C", str(fmu_sources()), "show", f"{ref}:fmu_src/{name}"],
                                     capture_output=True, text=True)
                if got.returncode and name in CORE_HEADERS:   # a header the ref did not have yet: unused there
                    continue
                got.check_returncode()
                (src / name).write_text(got.stdout)
        libs[label] = tmp / f"lib_{len(libs)}.so"
        subprocess.run(compile_command(HOST[2], 2, src, files, libs[label]), check=True)
    host = compile_host(tmp / "ab_host")
    cmd = {k: [str(host), str(lib), (unzip / "resources").as_uri(), guid] for k, lib in libs.items()}
    sums = {k: _host_run(c + [str(n), "0.001", "checksum"])["checksum"] for k, c in cmd.items()}
    times: dict[str, list[float]] = {k: [] for k in cmd}
    for _ in range(repeats):
        for k, c in cmd.items():
            times[k].append(float(_host_run(c + [str(n), "0.001"])["us_per_step"]))
    med = {k: statistics.median(v) for k, v in times.items()}
    print(f"C host, {n} steps of 1 ms, median of {repeats} alternating runs: {ref} {med[ref]:.3f} us/step, "
          f"worktree {med['worktree']:.3f} us/step, ratio {med[ref] / med['worktree']:.2f}")
    if shutil.which("valgrind"):
        ir = {k: (_callgrind_ir(c + ["120000", "0.001"]) - _callgrind_ir(c + ["20000", "0.001"])) / 100000
              for k, c in cmd.items()}
        print(f"callgrind: {ref} {ir[ref]:.0f} Ir/step, worktree {ir['worktree']:.0f} Ir/step, "
              f"ratio {ir[ref] / ir['worktree']:.2f}")
        med.update({f"ir_{k}": v for k, v in ir.items()})
    same = sums[ref] == sums["worktree"]
    print(f"every output of every step {'identical' if same else 'DIFFERENT'} bit for bit "
          f"(checksums {sums[ref]}, {sums['worktree']})")
    return med


def time_builds(tmp: Path, cold: bool) -> None:
    """Print the time to build the native FMU for all platforms, per FMI version (warm, optionally cold)."""
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.data import DEFAULT_TABLES

    caches = [("warm zig cache", None)]
    if cold:
        caches.insert(0, ("cold zig cache", tmp / "zig-cache"))
    for label, cache in caches:
        env_before = os.environ.get("ZIG_GLOBAL_CACHE_DIR")
        if cache is not None:
            os.environ["ZIG_GLOBAL_CACHE_DIR"] = str(cache)
        try:
            for version in (2, 3):
                build_fmu(DEFAULT_TABLES, tmp / f"warmup{version}.fmu", fmi_version=version) if label.startswith(
                    "warm") else None
                t0 = time.perf_counter()
                out = build_fmu(DEFAULT_TABLES, tmp / f"build{version}.fmu", fmi_version=version)
                dt = time.perf_counter() - t0
                platforms = sum(1 for name in zipfile.ZipFile(out).namelist() if name.startswith("binaries/"))
                print(f"native FMI {version}.0 FMU, all {platforms} platforms, {label}: {dt:6.1f} s")
        finally:
            if cache is not None:
                if env_before is None:
                    os.environ.pop("ZIG_GLOBAL_CACHE_DIR")
                else:
                    os.environ["ZIG_GLOBAL_CACHE_DIR"] = env_before


#: the results page's intro
PAGE_INTRO = ("Cost of one FMU step (set inputs, doStep, get outputs; 1 ms communication step) for the native and "
              "the pythonfmu FMU, through fmpy and in our C host (`fmu_src/hosts/fmi2_host.c`), the Python model "
              "alone, and the time to build the native FMU for every platform. Per-step times on a shared, loaded "
              "machine are noisy: compare figures from one run.")


def main(argv=None) -> None:
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import ClutchParameters, load_table, outputs, thermal_step

    from .page import results_page

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thermal-only", action="store_true",
                    help="only the thermal FMU's step against the plain FMU's in the C host")
    ap.add_argument("--ab", metavar="REF", help="only the native step of git ref REF's C sources against this "
                    "checkout's (time, callgrind, bit-for-bit checksum)")
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--cold", action="store_true", help="also time builds from an empty zig cache (minutes)")
    ap.add_argument("--markdown", action="store_true", help="with --out: the results page")
    ap.add_argument("--out", type=Path, help="write the results page (e.g. docs/results/benchmarks.md)")
    args = ap.parse_args(argv)
    with results_page(args.out, "Benchmarks: the FMU", "cushion_clutch.benchmarks.fmu", argv, PAGE_INTRO):
        _run(args, build_fmu, DEFAULT_TABLES, ClutchParameters, load_table, outputs, thermal_step)


def _run(args, build_fmu, DEFAULT_TABLES, ClutchParameters, load_table, outputs, thermal_step) -> None:
    n = args.steps
    if args.ab:
        with tempfile.TemporaryDirectory() as tmp:
            time_ab(Path(tmp), args.ab, n * 5)
        return
    if args.thermal_only:
        with tempfile.TemporaryDirectory() as tmp:
            time_thermal(Path(tmp), n)
        return
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        time_builds(tmp, args.cold)
        fmus = {b: build_fmu(DEFAULT_TABLES, tmp / f"{b}.fmu", backend=b) for b in ("python", "native")}
        host = compile_host(tmp / "host")
        print(f"steps: {n}, communication step 1 ms")
        fm = {}
        for b, path in fmus.items():
            fm[b] = time_fmpy(path, n)
            print(f"fmpy, {b:>6} FMU: set+doStep+get {fm[b][0]:8.3f} us/step, doStep alone {fm[b][1]:8.3f} us/step")
        ch = {}
        for b, path in fmus.items():
            ch[b] = time_c_host(host, path, n * (10 if b == "native" else 1), b == "python", tmp)
            note = "" if ch[b][1] == 0 else f"  (host exit code {ch[b][1]}: {ch[b][2]!r})"
            print(f"C host, {b:>6} FMU: set+doStep+get {ch[b][0]:8.3f} us/step{note}")
        ir = native_instructions(host, fmus["native"], tmp)
        if ir is not None:
            print(f"C host, native FMU: {ir:8.0f} instructions per set+doStep+get (callgrind; load-independent)")
        print(f"native speed-up: {ch['python'][0] / ch['native'][0]:.0f}x in the C host, "
              f"{fm['python'][0] / fm['native'][0]:.1f}x through fmpy")
        # the duty slips at 100 rad/s without a pause: by about 840 s the thermal FMU's facings leave the 800 K
        # it accepts (it refuses the step, as it should), so the thermal duty stops at 600 s
        time_thermal(tmp, min(n * 10, 600_000))
    table, p = load_table(), ClutchParameters()
    theta = 293.15
    t0 = time.perf_counter()
    for k in range(n):
        theta = thermal_step(theta, 450.0, 1e-3, p)
        outputs(0.003 + 0.004 * (k % 1000) / 1000.0, theta, table, p)
    print(f"Python model alone (thermal_step + outputs): {(time.perf_counter() - t0) / n * 1e6:8.3f} us/step")


if __name__ == "__main__":
    main()
