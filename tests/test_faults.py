"""The fault catalogue (issue 12): every misuse case against both FMU backends, one subprocess per row.

``CATALOGUE`` is the one table of cases. Each row runs ``tests/fault_cases.py``
in its own process through fmpy (with a printf-formatting logger, as a C
host has), so a host crash is a failing row. Expectations follow FMI 2.0 and
the issue, per backend:

- native rows are written to the spec (state machine, GUID, checked states,
  tables in any order, overflow, GetBooleanStatus after Discard);
- pythonfmu rows: the native FMU's statuses (the guard library in front of the
  wrapper, ``fmu_src/pythonfmu/pythonfmu_guard.c``, returns the fmi2Error and fmi2Warning
  the slave sends, which the wrapper alone cannot return; issue 31); the guard
  also refuses NULL or wrong resource locations and a wrong GUID before the
  wrapper sees them, so no row crashes the host.

The native backend runs the whole catalogue again with the FMU library built
with AddressSanitizer + UBSan (``test_native_catalogue_under_asan``).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import pytest

pytestmark = pytest.mark.fmu

RUNNER = Path(__file__).with_name("fault_cases.py")


@dataclass
class E:
    """Expected observations of one row: probe status set, log regex, other observation values."""

    probe: set = field(default_factory=lambda: {0})
    log: str | None = None
    obs: dict = field(default_factory=dict)


def refused(log, **obs):
    """pythonfmu: refused call -> fmi2Error + logged error, nothing changed (as the native FMU)."""
    obs.pop("next_step", None)
    return E({3}, log, obs)


ERR, DISCARD_OR_ERR, OK_OR_WARN = {3}, {2, 3}, {0, 1}

#: case, what it does, native expectation, pythonfmu expectation
CATALOGUE = [
    ("step_before_init", "fmi2DoStep right after fmi2Instantiate",
     E(ERR, r"(?i)dostep"), E(ERR, "phase instantiated")),
    ("step_after_terminate", "fmi2DoStep after fmi2Terminate",
     E(ERR, r"(?i)dostep"), E(ERR, "phase terminated")),
    ("exit_init_after_steps", "fmi2ExitInitializationMode after 200 steps (must not reset theta_cs)",
     E(ERR, None, {"unchanged": True}), refused("ExitInitializationMode refused", unchanged=True)),
    ("enter_init_midrun", "fmi2EnterInitializationMode mid-run, then set mu",
     E(ERR, None, {"mu_unchanged": True}), refused("EnterInitializationMode refused", mu_unchanged=True)),
    ("terminate_before_init", "fmi2Terminate before initialisation",
     E(ERR, r"(?i)terminate"), refused("fmi2Terminate refused")),
    ("set_output", "fmi2SetReal on the output torque",
     E(ERR, r"torque|value reference 2", {"unchanged": True}),
     refused("torque is an output", unchanged=True, next_step=2)),
    ("set_theta_cs", "fmi2SetReal on the output theta_cs (the thermal state)",
     E(ERR, None, {"unchanged": True}), refused("theta_cs is an output", unchanged=True)),
    ("set_fixed_param_after_init", "fmi2SetReal on the fixed parameter mu after initialisation",
     E(ERR, r"mu", {"mu_unchanged": True}), refused("mu is a fixed parameter", mu_unchanged=True)),
    ("set_param_in_init", "control: mu = 0.56 set in initialisation doubles the torque",
     E({0}, None, {"ratio_ok": True}), E({0}, None, {"ratio_ok": True})),
    ("set_partially_bad", "fmi2SetReal([x_to, torque]): refused as a whole, x_to unchanged",
     E(ERR, None, {"unchanged": True}), refused("torque is an output", unchanged=True)),
    ("set_unknown_vr", "fmi2SetReal on value reference 999",
     E(ERR, r"999"), refused("999 does not exist", next_step=2)),
    ("get_unknown_vr", "fmi2GetReal on value reference 999",
     E(ERR, r"999", {"value_not_plausible": True}), refused("999 does not exist", value_not_plausible=True)),
    ("set_integer", "fmi2SetInteger (the FMU has Real variables only)",
     E(ERR, None), refused("Real variables only")),
    ("negative_step", "fmi2DoStep with step size -0.1 s",
     E(DISCARD_OR_ERR, r"step size"), E({2}, "step size -0.1")),
    ("nan_step", "fmi2DoStep with step size NaN",
     E(DISCARD_OR_ERR, r"step size"), E({2}, "step size nan")),
    ("nan_input", "x_to = NaN, then fmi2DoStep",
     E(DISCARD_OR_ERR, r"x_to"), E({2}, "x_to = nan")),
    ("inf_input", "theta_cm = inf, then fmi2DoStep",
     E(DISCARD_OR_ERR, r"theta_cm"), E({2}, "theta_cm = inf")),
    ("time_backwards", "currentCommunicationPoint 0.05 s after a step ending at 0.1 s: warned, accepted",
     E(OK_OR_WARN, r"(?i)communication"), E(OK_OR_WARN, "does not follow")),
    ("n_surfaces_fraction", "n_surfaces = 2.5",
     E(ERR, r"n_surfaces"), refused("n_surfaces = 2.5 must be a positive integer", next_step=2)),
    ("c_zero", "C = 0 J/K",
     E(ERR, r"\bC\b"), refused(r"C = 0.0 is out of range", next_step=2)),
    ("state_roundtrip", "serialize after 2000 steps, 500 steps, restore, 500 steps: bit-identical",
     E({0}, None, {"identical": True}), E({0}, None, {"identical": True})),
    ("state_truncated", "deserialize half a serialized state",
     E(ERR, None, {"unchanged": True}), refused("fmi2SetFMUstate refused", unchanged=True, next_step=2)),
    ("state_corrupted", "deserialize a state with one byte flipped",
     E(ERR, None, {"unchanged": True}), refused("checksum mismatch", unchanged=True)),
    ("state_nan_parameter", "a state with a valid header and C = NaN",
     E(ERR, None, {"no_nan_output": True}), refused("C = nan", no_nan_output=True, next_step=2)),
    ("state_bad_phase", "a valid state with a garbage phase field (pythonfmu only: JSON layout)",
     None, refused("phase 'bogus'", unchanged=True)),
    ("table_one_row", "force_deflection.csv with one row per temperature",
     E(ERR, r"force_deflection\.csv"), refused(r"force_deflection\.csv.*needs >= 2", next_step=2)),
    ("table_missing", "force_deflection.csv missing",
     E(ERR, r"force_deflection\.csv"), refused(r"force_deflection\.csv", next_step=2)),
    ("table_descending", "temperature groups in descending order: accepted, same torque",
     E({0}, None, {"same_torque": True}), E({0}, None, {"same_torque": True})),
    ("table_format_chars", "a table cell '%s%n%s%n' (the message reaches a printf logger)",
     E(ERR, r"force_deflection\.csv"), refused(r"'%s%n%s%n'", next_step=2)),
    ("table_huge_force", "a force of 1e308 N (torque would overflow)",
     E(ERR, r"force"), refused(r"torque would overflow", next_step=2)),
    ("path_format_chars", "FMU unpacked under 'dir %s%n %d'",
     E({0}, None, {"torque_ok": True}), E({0}, None, {"torque_ok": True})),   # the guard re-encodes the URI
    ("resources_null", "fmi2Instantiate with resourceLocation = NULL",
     E(ERR, r"(?i)resource"),
     E(ERR, r"(?i)fmuResourceLocation is NULL")),                        # refused by the guard
    ("resources_missing", "the FMU's resources folder is empty",
     E(ERR, r"(?i)resource|force_deflection"),
     E(ERR, r"(?i)no slave module")),                                     # refused by the guard
    ("wrong_guid", "fmi2Instantiate with another GUID",
     E(ERR, r"(?i)guid"), E(ERR, r"(?i)guid")),                            # the guard checks it
    ("logging_off", "loggingOn = false: a refused step is still reported",
     E(DISCARD_OR_ERR, r"(?i)dostep|initiali"), E(ERR, "phase instantiated")),
    ("discard_status", "fmi2GetBooleanStatus(fmi2Terminated) and LastSuccessfulTime after a Discard",
     E({2}, None, {"bool_status": 0, "real_status": 0, "last_time": 0.01, "terminated": False}),
     E({2}, None, {"bool_status": 0, "real_status": 0, "last_time": 0.01, "terminated": False})),
    ("simulate_refused", "fmpy.simulate_fmu with C = 0: never a silent early end",
     E(ERR), E(ERR, r"C = 0.0 is out of range")),
    ("reset_after_fault", "fmi2Reset after a refused call, then a normal run",
     E({0}, None, {"torque_ok": True}), E({0}, None, {"torque_ok": True})),
    ("fifty_instances", "50 instances alive at once, identical results",
     E({0}, None, {"identical": True}), E({0}, None, {"identical": True})),
    # pythonfmu: the wrapper itself leaks ~4.5 kB per instance (findClass's MRO lists and repr
    # strings, the class they keep); our former slave leaked ~22 kB more (a class per instance)
    ("cycles_1000", "1000 instantiate/step/free cycles: RSS growth < 2 MB native, < 8 MB pythonfmu",
     E({0}, None, {"rss_growth_MB": lambda v: v < 2.0}), E({0}, None, {"rss_growth_MB": lambda v: v < 8.0})),
    ("threads_8", "one instance per thread in 8 threads, 2000 steps each, equal to serial",
     E({0}, None, {"identical": True}), E({0}, None, {"identical": True})),
]
BACKENDS = ("native", "python")


def run_case(case: str, fmu: Path, work: Path, env: dict | None = None, timeout: float = 120):
    """Run one row in a fresh process; return (returncode, observations or None, stderr)."""
    work = work / case
    shutil.rmtree(work, ignore_errors=True)
    try:
        proc = subprocess.run([sys.executable, str(RUNNER), case, str(fmu), str(work)], capture_output=True,
                              text=True, timeout=timeout, env=env, errors="replace")
    except subprocess.TimeoutExpired:
        return -999, None, f"timed out after {timeout:g} s"
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")), None)
    return proc.returncode, (json.loads(line[7:]) if line else None), proc.stderr


def check_row(expect: E, rc: int, obs: dict | None, stderr: str) -> list[str]:
    """Every way the observed row differs from the expectation (empty: the row passes)."""
    if rc != 0 or obs is None:
        return [f"host died or failed: returncode {rc}; stderr tail: {stderr[-600:]}"]
    problems = []
    if obs.get("probe") not in expect.probe:
        problems.append(f"status {obs.get('probe')}, expected one of {sorted(expect.probe)}")
    text = "\n".join(m for _, _, m in obs["logs"]) + "\n" + stderr
    if expect.log and not re.search(expect.log, text):
        problems.append(f"no log message matching {expect.log!r}; logged: {[m for _, _, m in obs['logs']]}")
    for key, want in expect.obs.items():
        got = obs.get(key)
        ok = want(got) if callable(want) else got == want
        if not ok:
            problems.append(f"{key} = {got!r}, expected {want if not callable(want) else 'bound'}")
    return problems


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu
    out = tmp_path_factory.mktemp("fault_fmus")
    return {b: build_fmu(DEFAULT_TABLES, out / f"{b}.fmu", backend=b) for b in BACKENDS}


ROWS = [(case, b, exp) for case, _, nat, py in CATALOGUE for b, exp in (("native", nat), ("python", py))
        if exp is not None]


@pytest.fixture(scope="module")
def outcomes(fmus, tmp_path_factory):
    """Every row, each in its own process, two at a time (the machine has 2 cores); computed once."""
    from concurrent.futures import ThreadPoolExecutor
    work = tmp_path_factory.mktemp("fault_rows")
    with ThreadPoolExecutor(max_workers=2) as pool:
        futs = {(case, b): pool.submit(run_case, case, fmus[b], work / b) for case, b, _ in ROWS}
    return {key: f.result() for key, f in futs.items()}


@pytest.mark.parametrize("case,backend,expect", ROWS, ids=[f"{c}-{b}" for c, b, _ in ROWS])
def test_fault_row(case, backend, expect, outcomes):
    rc, obs, stderr = outcomes[(case, backend)]
    problems = check_row(expect, rc, obs, stderr)
    assert not problems, f"{case} [{backend}]: " + "; ".join(problems)


def test_catalogue_is_one_table_of_known_cases():
    """Every row names a case of the runner and every case is in the table (nothing silently skipped)."""
    sys.path.insert(0, str(RUNNER.parent))
    try:
        import fault_cases
    finally:
        sys.path.pop(0)
    assert [c for c, *_ in CATALOGUE] == list(dict.fromkeys(c for c, *_ in CATALOGUE))
    assert {c for c, *_ in CATALOGUE} == set(fault_cases.CASES)


def _asan_runtime() -> str | None:
    gcc = shutil.which("gcc")
    if gcc is None:
        return None
    lib = subprocess.run([gcc, "-print-file-name=libasan.so"], capture_output=True, text=True).stdout.strip()
    return lib if lib and Path(lib).is_file() else None


def test_native_catalogue_under_asan(fmus, tmp_path):
    """The whole catalogue on the native FMU built with -fsanitize=address,undefined: no sanitizer report."""
    lib = _asan_runtime()
    if lib is None:
        pytest.skip("gcc with libasan is not available")
    from cushion_clutch.fmu.descriptions import sources
    fmu = tmp_path / "asan.fmu"
    src = tmp_path / "src"
    with zipfile.ZipFile(fmus["native"]) as z:      # the FMU's own sources/, rebuilt instrumented
        for name in z.namelist():
            if name.startswith("sources/"):
                z.extract(name, src)
    so = tmp_path / "CushionClutch.so"
    subprocess.run([shutil.which("gcc"), "-std=c99", "-shared", "-fPIC", "-fsanitize=address,undefined",
                    "-fno-omit-frame-pointer", "-fno-sanitize-recover=all", "-g", "-O1", f"-I{src / 'sources'}",
                    *(str(src / "sources" / f) for f in sources(2)), "-o", str(so), "-lm"], check=True)
    with zipfile.ZipFile(fmus["native"]) as zin, zipfile.ZipFile(fmu, "w") as zout:
        for item in zin.infolist():
            data = so.read_bytes() if item.filename == "binaries/linux64/CushionClutch.so" else zin.read(item.filename)
            zout.writestr(item, data)
    env = dict(os.environ, LD_PRELOAD=lib, ASAN_OPTIONS="detect_leaks=0:abort_on_error=0:exitcode=99",
               UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:exitcode=98")
    # one process for the whole catalogue: the sanitizers, not process isolation, are the check here
    proc = subprocess.run([sys.executable, str(RUNNER), "all", str(fmu), str(tmp_path / "asan")],
                          capture_output=True, text=True, timeout=600, env=env, errors="replace")
    done = [json.loads(ln[7:])["case"] for ln in proc.stdout.splitlines() if ln.startswith("RESULT ")]
    assert "Sanitizer" not in proc.stderr and "runtime error" not in proc.stderr, proc.stderr[-3000:]
    assert proc.returncode == 0, f"rc {proc.returncode}: {proc.stderr[-3000:]}"
    assert done == [c for c, *_ in CATALOGUE], f"cases run: {done}"


# ---------------------------------------------------------------------------------------------
# The native FMU through our C host (tests/c_hosts/fault_host.c): the same rows and expectations,
# with a printf-style logger as C masters have; and the same host under valgrind memcheck.
C_HOST_CASES = ("step_before_init", "step_after_terminate", "exit_init_after_steps", "set_output",
                "set_fixed_param_after_init", "set_partially_bad", "set_unknown_vr", "negative_step",
                "nan_input", "time_backwards", "discard_status", "state_roundtrip", "state_truncated",
                "state_corrupted", "table_format_chars", "resources_null", "resources_missing", "wrong_guid",
                "fifty_instances", "cycles_1000", "threads_8")
EXPECT = {case: nat for case, _, nat, _ in CATALOGUE}


@pytest.fixture(scope="module")
def c_host(fmus, tmp_path_factory):
    """The compiled fault host and the native FMU unpacked (plus a copy with a '%s%n' table cell)."""
    from cushion_clutch.fmu.native import fmi2_header_dir
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc is not available")
    work = tmp_path_factory.mktemp("c_host")
    exe = work / "fault_host"
    subprocess.run([gcc, "-std=c99", "-D_POSIX_C_SOURCE=200809L", "-O1", "-g", "-Wall", "-Wextra",
                    f"-I{fmi2_header_dir()}", str(Path(__file__).parent / "c_hosts" / "fault_host.c"), "-o", str(exe),
                    "-ldl", "-lpthread", "-lm"], check=True)
    unzip = work / "fmu"
    with zipfile.ZipFile(fmus["native"]) as z:
        z.extractall(unzip)
        guid = re.search(r'guid="([^"]+)"', z.read("modelDescription.xml").decode()).group(1)
    bad = work / "fmu_format_chars"
    shutil.copytree(unzip, bad)
    table = bad / "resources" / "tables" / "force_deflection.csv"
    rows = table.read_text().splitlines()
    rows[4] = rows[4].rsplit(",", 1)[0] + ",%s%n%s%n"
    table.write_text("\n".join(rows) + "\n")
    return exe, unzip, bad, guid


def c_host_command(c_host, case: str) -> list[str]:
    exe, unzip, bad, guid = c_host
    folder = bad if case == "table_format_chars" else unzip
    uri = {"resources_null": "NULL", "resources_missing": (unzip / "no_such_folder").as_uri()}.get(
        case, (folder / "resources").as_uri())
    return [str(exe), str(folder / "binaries" / "linux64" / "CushionClutch.so"), uri,
            "{00000000-0000-0000-0000-000000000000}" if case == "wrong_guid" else guid, case]


def check_c_host_row(case: str, proc) -> list[str]:
    if proc.returncode != 0 or "survived" not in proc.stdout:
        return [f"host died: returncode {proc.returncode}; {proc.stderr[-600:]}"]
    out = proc.stdout.splitlines()
    problems = []
    status = int(next(ln.split()[1] for ln in out if ln.startswith("status ")))
    if status not in EXPECT[case].probe:
        problems.append(f"status {status}, expected one of {sorted(EXPECT[case].probe)}")
    logs = "\n".join(ln[6:] for ln in out if ln.startswith("log "))
    if EXPECT[case].log and not re.search(EXPECT[case].log, logs):
        problems.append(f"no log message matching {EXPECT[case].log!r}; logged: {logs!r}")
    problems += [f"check {ln.split()[1]} failed" for ln in out if ln.startswith("check ") and ln.endswith(" 0")]
    return problems


@pytest.mark.parametrize("case", C_HOST_CASES)
def test_fault_row_c_host(case, c_host):
    proc = subprocess.run(c_host_command(c_host, case), capture_output=True, text=True, timeout=120,
                          errors="replace")
    problems = check_c_host_row(case, proc)
    assert not problems, f"{case} [native, C host]: " + "; ".join(problems)


def test_c_host_catalogue_under_valgrind(c_host):
    """Every C-host row under valgrind memcheck: no invalid access, no uninitialised use, no crash."""
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        pytest.skip("valgrind is not installed")
    bad = []
    for case in C_HOST_CASES:
        cmd = [valgrind, "--error-exitcode=97", "--errors-for-leak-kinds=none", "-q", *c_host_command(c_host, case)]
        if case == "cycles_1000":
            cmd[-1] = "fifty_instances"          # the 1000-cycle row is covered by ASan; memcheck is ~50x slower
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600, errors="replace")
        if proc.returncode != 0 or "survived" not in proc.stdout:
            bad.append(f"{case}: rc {proc.returncode}: {proc.stderr[-1500:]}")
    assert not bad, "\n".join(bad)
