"""Benchmark: time per step of the CushionClutch FMUs (pythonfmu and native C), and the native build time.

Through fmpy (FMU2Slave: set 2 inputs, doStep, get 5 outputs), in our small C
host (fmu_src/bench/fmi2_host.c, dlopen; with valgrind also the native step's instructions, callgrind, which
do not depend on the machine's load), and the Python model alone; the time
to build the native FMU with the binaries of every platform (FMI 2.0: 3, FMI 3.0: 5),
with zig's cache warm, and with ``--cold`` also from an empty zig cache.

    python -m cushion_clutch.benchmarks.fmu [--steps 200000] [--cold] [--thermal-only] [--ab REF]

The thermal FMU (``build-fmu --thermal``) against the plain one, both native in the C host
``fmu_src/bench/fmi2_duty_host.c`` on the same bearing sweep with 100 rad/s of slip (the plain FMU
also gets a theta_cm sweep, the thermal one an engine speed): median of 5 alternating runs and the ratio
(target: at most 3x). ``--thermal-only`` runs only this comparison.

The native FMU runs in the C host in two input patterns (:data:`PATTERNS`): the host's own *jump* pattern (x_to
3-8 mm and theta_cm 300-600 K pseudo-random, set every step: every step a cold solve of the cover) and a *launch*
pattern, what a time-stepping host feeds: the inputs the launch simulation gives the clutch FMU over the first
``--launches`` launches of the shipped ``default`` scenario (recorded at run time, :func:`record_launch`; 1 ms
steps throughout, also while the car stands braked), replayed with the launch client's set-only-what-changed
calls (:func:`write_pattern`, the host's ``--replay``).

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

import numpy as np


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
    from cushion_clutch.data import fmu_source
    from cushion_clutch.fmu.native import fmi2_header_dir
    subprocess.run([shutil.which("gcc") or "cc", "-std=c99", "-D_POSIX_C_SOURCE=199309L", "-O2",
                    f"-I{fmi2_header_dir()}", str(fmu_source("fmi2_host.c")), "-o", str(dest), "-ldl"], check=True)
    return dest


#: the C host's input patterns for the native FMU: name -> what it stands for
PATTERNS = {"jump": "every step a cold solve", "launch": "what a time-stepping host feeds"}

#: value references the C host's replay pattern uses (fmu_src/bench/fmi2_host.c): set, then read
REPLAY_VRS = {"x_to": 0, "theta_cm": 1, "omega_slip": 17, "torque": 2, "theta_cs": 4, "x_kiss": 6}


def record_launch(fmu: Path, launches: int = 2, tcu: str = "naive") -> dict[str, np.ndarray]:
    """The inputs the launch simulation gives the clutch FMU, step by step, and the outputs it gets back.

    The shipped ``default`` scenario (with the FMU's default cushion-spring heat path) cut to its first
    ``launches`` launches (moderate and hard pedal alternating,
    each a 60 s slot: prefill, 8 s of pedal, then braked standstill with the clutch open), with 1 ms steps
    throughout (``quiet_steps`` off: a fixed-step host's pattern; the launch loop's quiet periods would step
    10 ms) and the Python plant loop (the compiled one calls the FMU from C), through ``fmu`` (a native FMU with
    a binary for this machine). Every call of the clutch FMU's step is recorded by a subclass of
    :class:`~cushion_clutch.launch.plant.fmu_client.ClutchFmu` put in for the run.

    Returns
    -------
    dict
        ``inputs`` (steps, 3): x_to [m], theta_cm [K], omega_slip [rad/s]; ``outputs`` (steps, 3): torque [N.m],
        theta_cs [K], x_kiss [m]; ``h`` the step [s].
    """
    import dataclasses
    from unittest import mock

    from cushion_clutch.launch import simulate
    from cushion_clutch.launch.plant.fmu_client import ClutchFmu
    from cushion_clutch.launch.scenario import load_scenario
    from cushion_clutch.model import load_table

    ins: list[tuple[float, float, float]] = []
    outs: list[tuple[float, float, float]] = []
    steps: set[float] = set()

    class Recording(ClutchFmu):
        def _make_step(self):
            inner = super()._make_step()

            def step(t, h, x_to, theta_cm, omega_slip):
                o = inner(t, h, x_to, theta_cm, omega_slip)
                ins.append((x_to, theta_cm, omega_slip))
                outs.append(o)
                steps.add(h)
                return o
            return step

    sc = load_scenario()
    # the clutch FMU's own start values for the cushion spring's heat path (the paper's U, H, C: a C host that
    # replays the pattern sets no parameter), not the scenario's FE set
    sc = dataclasses.replace(sc, run=dataclasses.replace(sc.run, launches=launches, quiet_steps=False),
                             clutch=dataclasses.replace(sc.clutch, spring_thermal="paper"))
    with mock.patch.object(simulate, "ClutchFmu", Recording):
        simulate.simulate_launches(fmu, sc, load_table(), tcu, record_every=1000, plant="python")
    if len(steps) != 1:
        raise RuntimeError(f"the launch stepped the clutch FMU with steps {sorted(steps)} s, not one fixed step")
    return {"inputs": np.array(ins, dtype=float), "outputs": np.array(outs, dtype=float), "h": steps.pop()}


def write_pattern(path: Path, inputs: np.ndarray) -> Path:
    """``inputs`` (steps, 3: x_to m, theta_cm K, omega_slip rad/s) as the C host's ``--replay`` file (doubles)."""
    np.ascontiguousarray(inputs, dtype=float).tofile(path)
    return path


def describe_pattern(rec: dict[str, np.ndarray], launches: int) -> str:
    """What the launch pattern contains (steps, set calls, slip, quiet phases), one paragraph."""
    x, th, w = rec["inputs"].T
    torque = rec["outputs"][:, 0]
    n = len(x)
    changed = np.r_[True, (np.diff(rec["inputs"], axis=0) != 0).any(axis=1)]
    slipping = (torque != 0.0) & (np.abs(w) > 1e-3)
    held_run = np.diff(np.flatnonzero(np.r_[changed, True]))          # steps per set call
    small = np.abs(np.diff(x)) <= 1e-4
    peak = np.abs(w[slipping]).max() if slipping.any() else 0.0
    return (f"launch pattern: {n} steps of {rec['h'] * 1e3:g} ms, {launches} launch(es) of the default scenario "
            f"(naive TCU); inputs set (one fmi2SetReal of 3) in {changed.sum()} steps ({changed.mean():.0%}), "
            f"held up to {held_run.max()} steps; clutch transmitting torque in {(torque != 0).sum()} steps "
            f"({(torque != 0).mean():.0%}), slipping with torque in {slipping.sum()} (peak {peak:.0f} rad/s, "
            f"{np.sum(np.abs(torque * w)[slipping]) * rec['h'] / 1e3:.0f} kJ); open with the bearing below 0.1 mm "
            f"(braked standstill and idle: the quiet phases) in {(x < 1e-4).sum()} steps; bearing moved <= 0.1 mm "
            f"in {small.mean():.1%} of the steps (max {np.abs(np.diff(x)).max() * 1e3:.2f} mm); "
            f"theta_cm {th.min():.1f}-{th.max():.1f} K, theta_cs {rec['outputs'][:, 1].min():.1f}-"
            f"{rec['outputs'][:, 1].max():.1f} K")


def active_part(rec: dict[str, np.ndarray], launches: int) -> np.ndarray:
    """The launch pattern's inputs without its quiet phases: of each launch's slot, the steps from its start to
    0.5 s after the bearing was last at 0.1 mm or more (prefill, pedal, opening), the slots' parts joined."""
    x = rec["inputs"][:, 0]
    slot = len(x) // launches
    pad = int(round(0.5 / rec["h"]))
    parts = []
    for i in range(launches):
        out = np.flatnonzero(x[i * slot:(i + 1) * slot] >= 1e-4)
        end = min(slot, (out[-1] + 1 + pad) if len(out) else 0)
        parts.append(rec["inputs"][i * slot:i * slot + end])
    return np.concatenate(parts)


def time_c_host(host: Path, fmu: Path, n: int, python: bool, workdir: Path,
                replay: Path | None = None) -> tuple[float, int, str]:
    """(us per set+doStep+get in the C host, exit code, stderr tail); ``replay``: the launch pattern's file."""
    from fmpy import read_model_description

    unzip = workdir / fmu.stem
    zipfile.ZipFile(fmu).extractall(unzip)
    env = dict(os.environ)
    if python:   # a pythonfmu binary loads only with libpython preloaded
        env["LD_PRELOAD"] = os.path.join(sysconfig.get_config_var("LIBDIR"), sysconfig.get_config_var("LDLIBRARY"))
        import numpy
        env["PYTHONPATH"] = str(Path(numpy.__file__).parents[1])
    res = subprocess.run([str(host), str(unzip / "binaries/linux64/CushionClutch.so"),
                          (unzip / "resources").as_uri(), read_model_description(str(fmu)).guid, str(n), "0.001",
                          *_replay_args(replay)], capture_output=True, text=True, env=env)
    us = float("nan")
    for line in res.stdout.splitlines():
        if line.startswith("us_per_step"):
            us = float(line.split()[1])
    return us, res.returncode, res.stderr.strip()[-200:]


def _replay_args(replay: Path | None) -> list[str]:
    return [] if replay is None else ["--replay", str(replay)]


def check_replay_vrs(fmu: Path) -> None:
    """The C host's replay value references are those of ``fmu``'s variables (ValueError naming the first not)."""
    from fmpy import read_model_description

    vr = {v.name: v.valueReference for v in read_model_description(str(fmu)).modelVariables}
    for name, ref in REPLAY_VRS.items():
        if vr.get(name) != ref:
            raise ValueError(f"{fmu}: {name} has value reference {vr.get(name)}, the C host's replay uses {ref}")


def native_instructions(host: Path, fmu: Path, workdir: Path, replay: Path | None = None) -> float | None:
    """Instructions per set+doStep+get of the native FMU in the C host (callgrind, independent of the machine's
    load), or None without valgrind. Jump pattern: 120 000 steps minus 20 000, so start-up cancels; ``replay``
    (the launch pattern's file, N steps): 20 000 + N steps minus 20 000, every step of the file once. ``fmu`` must
    have been extracted into ``workdir`` by :func:`time_c_host`."""
    from fmpy import read_model_description

    if not shutil.which("valgrind"):
        return None
    unzip = workdir / fmu.stem
    cmd = [str(host), str(unzip / "binaries/linux64/CushionClutch.so"), (unzip / "resources").as_uri(),
           read_model_description(str(fmu)).guid]
    return _ir_per_step(cmd, replay)


def _ir_per_step(cmd: list[str], replay: Path | None) -> float:
    """callgrind instructions per step of host command ``cmd`` (library, URI, GUID) in a pattern (see above)."""
    extra = _replay_args(replay)
    span = 100_000 if replay is None else replay.stat().st_size // 24
    return (_callgrind_ir(cmd + [str(20_000 + span), "0.001", *extra])
            - _callgrind_ir(cmd + ["20000", "0.001", *extra])) / span


def time_thermal(tmp: Path, n: int, repeats: int = 5) -> tuple[float, float]:
    """(plain, thermal) native FMI 2.0 FMU: median us per set+doStep+get in the C duty host; prints the ratio."""
    import statistics

    from fmpy import read_model_description

    from cushion_clutch.data import DEFAULT_TABLES, fmu_source
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.fmu.native import fmi2_header_dir

    host = tmp / "duty_host"
    subprocess.run([shutil.which("gcc") or "cc", "-std=c99", "-D_POSIX_C_SOURCE=199309L", "-O2",
                    f"-I{fmi2_header_dir()}", str(fmu_source("fmi2_duty_host.c")), "-o", str(host),
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


def time_ab(tmp: Path, ref: str, n: int, repeats: int = 9, launches: int = 2) -> dict[str, dict[str, float]]:
    """The native FMI 2.0 step of git ref ``ref``'s C sources against this checkout's, in both patterns
    (:data:`PATTERNS`): median us per step in the C host (alternating runs: ref and worktree, jump and launch),
    callgrind Ir per step, and the bit-for-bit checksum per pattern. Returns {pattern: figures}."""
    import statistics

    from fmpy import read_model_description

    from cushion_clutch.data import DEFAULT_TABLES, fmu_source, fmu_sources
    from cushion_clutch.fmu.constants import CORE_HEADERS
    from cushion_clutch.fmu.crossbuild import HOST, compile_command
    from cushion_clutch.fmu.native import build_native_fmu, sources

    fmu = build_native_fmu(DEFAULT_TABLES, tmp / "ab.fmu", 2, platforms=(HOST[2],))
    check_replay_vrs(fmu)
    unzip = tmp / "ab"
    zipfile.ZipFile(fmu).extractall(unzip)
    guid = read_model_description(str(fmu)).guid
    rec = record_launch(fmu, launches)          # the launch pattern, recorded through this checkout's FMU
    print(describe_pattern(rec, launches))
    replay = {"jump": None, "launch": write_pattern(tmp / "launch.f64", rec["inputs"])}
    files = sources(2)
    libs = {}
    for label in (ref, "worktree"):
        src = tmp / f"src_{len(libs)}"
        shutil.copytree(unzip / "sources", src)
        if label == ref:                 # the ref's model sources over the generated headers of this checkout
            for name in (*files, *CORE_HEADERS):
                role = fmu_source(name).parent.name         # a ref before the role folders has it in fmu_src/
                for path in (f"fmu_src/{role}/{name}", f"fmu_src/{name}"):
                    got = subprocess.run(["git", "-C", str(fmu_sources()), "show", f"{ref}:{path}"],
                                         capture_output=True, text=True)
                    if got.returncode == 0:
                        break
                if got.returncode and name in CORE_HEADERS:   # a header the ref did not have yet: unused there
                    continue
                got.check_returncode()
                (src / name).write_text(got.stdout)
        libs[label] = tmp / f"lib_{len(libs)}.so"
        subprocess.run(compile_command(HOST[2], 2, src, files, libs[label]), check=True)
    host = compile_host(tmp / "ab_host")
    cmd = {k: [str(host), str(lib), (unzip / "resources").as_uri(), guid] for k, lib in libs.items()}
    runs = {(pat, k): c + [str(n), "0.001", *_replay_args(replay[pat])] for pat in PATTERNS for k, c in cmd.items()}
    sums = {key: _host_run(c + ["checksum"])["checksum"] for key, c in runs.items()}
    times: dict[tuple[str, str], list[float]] = {key: [] for key in runs}
    for _ in range(repeats):
        for key, c in runs.items():
            times[key].append(float(_host_run(c)["us_per_step"]))
    result = {}
    for pat, what in PATTERNS.items():
        med = {k: statistics.median(times[pat, k]) for k in cmd}
        print(f"{pat} pattern ({what}): C host, {n} steps of 1 ms, median of {repeats} alternating runs: "
              f"{ref} {med[ref]:.3f} us/step, worktree {med['worktree']:.3f} us/step, "
              f"ratio {med[ref] / med['worktree']:.2f}")
        if shutil.which("valgrind"):
            ir = {k: _ir_per_step(c, replay[pat]) for k, c in cmd.items()}
            print(f"{pat} pattern: callgrind {ref} {ir[ref]:.0f} Ir/step, worktree {ir['worktree']:.0f} Ir/step, "
                  f"ratio {ir[ref] / ir['worktree']:.2f}")
            med.update({f"ir_{k}": v for k, v in ir.items()})
        same = sums[pat, ref] == sums[pat, "worktree"]
        print(f"{pat} pattern: every output of every step {'identical' if same else 'DIFFERENT'} bit for bit "
              f"(checksums {sums[pat, ref]}, {sums[pat, 'worktree']})")
        result[pat] = med
    return result


def native_patterns(page, host: Path, fmu: Path, n: int, tmp: Path, launches: int, jump_us: float) -> None:
    """The native FMU in the C host in both patterns (:data:`PATTERNS`): us and callgrind Ir per step, printed and
    as a table on the results page. ``jump_us``: the jump pattern's time, measured just before."""
    check_replay_vrs(fmu)
    rec = record_launch(fmu, launches)
    print(describe_pattern(rec, launches))
    replay = {"jump": None, "launch": write_pattern(tmp / "launch.f64", rec["inputs"])}
    us = {"jump": jump_us}
    got = time_c_host(host, fmu, n, False, tmp, replay["launch"])
    if got[1] != 0:
        raise RuntimeError(f"the C host's launch replay failed (exit code {got[1]}): {got[2]}")
    us["launch"] = got[0]
    print(f"C host, native FMU, launch pattern: set-if-changed+doStep+get {us['launch']:8.3f} us/step")
    ir = {pat: native_instructions(host, fmu, tmp, replay[pat]) for pat in PATTERNS}
    active = write_pattern(tmp / "active.f64", active_part(rec, launches))
    act_us = time_c_host(host, fmu, n, False, tmp, active)[0]
    act_ir = native_instructions(host, fmu, tmp, active)
    print(f"C host, native FMU, launch pattern without its quiet phases (each launch's first "
          f"{active.stat().st_size // 24 // launches} steps on average: prefill, pedal, opening): {act_us:8.3f} us/step"
          + ("" if act_ir is None else f", {act_ir:.0f} instructions per step (callgrind)"))
    rows = []
    for pat, what in PATTERNS.items():
        irs = "n/a (no valgrind)" if ir[pat] is None else f"{ir[pat]:.0f}"
        if ir[pat] is not None:
            print(f"C host, native FMU, {pat} pattern ({what}): {ir[pat]:8.0f} instructions per step "
                  "(callgrind; load-independent)")
        rows.append(f"| {pat} | {what} | {us[pat]:.3f} | {irs} |")
    page.markdown("## The native FMU in the C host: two input patterns\n\n"
                  + describe_pattern(rec, launches) + ".\n\n"
                  "| pattern | what it stands for | us per step | callgrind Ir per step |\n|---|---|---|---|\n"
                  + "\n".join(rows) + f"\n| launch, no quiet phases | the launch pattern's prefill, pedal and opening "
                  f"only | {act_us:.3f} | {'n/a' if act_ir is None else f'{act_ir:.0f}'} |")


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
              "the pythonfmu FMU, through fmpy and in our C host (`fmu_src/bench/fmi2_host.c`), the Python model "
              "alone, and the time to build the native FMU for every platform. The native FMU runs in the C host "
              "in two input patterns: the host's jump pattern (every step a cold solve) and a launch pattern "
              "(the inputs a launch of the default scenario gives the FMU, set only when they change: what a "
              "time-stepping host feeds). Per-step times on a shared, loaded machine are noisy: compare figures "
              "from one run.")


def main(argv=None) -> None:
    from cushion_clutch.fmu.build import build_fmu
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.model import ClutchParameters, load_table, outputs, thermal_step

    from .page import add_draft_option, results_page

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--thermal-only", action="store_true",
                    help="only the thermal FMU's step against the plain FMU's in the C host")
    ap.add_argument("--ab", metavar="REF", help="only the native step of git ref REF's C sources against this "
                    "checkout's (time, callgrind, bit-for-bit checksum; both input patterns)")
    ap.add_argument("--steps", type=int, default=200_000)
    ap.add_argument("--launches", type=int, default=2,
                    help="launches of the default scenario recorded for the launch pattern (60 000 steps each)")
    ap.add_argument("--cold", action="store_true", help="also time builds from an empty zig cache (minutes)")
    ap.add_argument("--markdown", action="store_true", help="with --out: the results page")
    ap.add_argument("--out", type=Path, help="write the results page (e.g. docs/results/benchmarks.md)")
    add_draft_option(ap)
    args = ap.parse_args(argv)
    if args.launches < 1:
        ap.error(f"--launches {args.launches}: must be at least 1")
    with results_page(args.out, "Benchmarks: the FMU", "cushion_clutch.benchmarks.fmu", argv, PAGE_INTRO) as page:
        _run(args, page, build_fmu, DEFAULT_TABLES, ClutchParameters, load_table, outputs, thermal_step)


def _run(args, page, build_fmu, DEFAULT_TABLES, ClutchParameters, load_table, outputs, thermal_step) -> None:
    n = args.steps
    if args.ab:
        with tempfile.TemporaryDirectory() as tmp:
            time_ab(Path(tmp), args.ab, n * 5, launches=args.launches)
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
            print(f"C host, {b:>6} FMU: set+doStep+get {ch[b][0]:8.3f} us/step{note} (jump pattern)")
        native_patterns(page, host, fmus["native"], n * 10, tmp, args.launches, ch["native"][0])
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
