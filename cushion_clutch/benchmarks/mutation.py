"""Benchmark: mutation score of the test suite (how many deliberate bugs the tests catch).

Two parts, both on a temporary copy of the checkout (the checkout itself is never changed):

``hand``
    Our own list of mutants (:data:`MUTANTS`): sign flips, off-by-one and status changes in the
    C core (``fmu_src/core/*.c``), and the Python mutants that survived every test on c5f3d16 (issue 21).
    Each is applied alone and the tests named for it run; the mutant is *killed* when they fail.
``mutmut``
    `mutmut <https://pypi.org/project/mutmut/>`_ (``pip install -e .[mutation]``) over the Python
    model, table and launch code with the fast (non-ccx) tests; configuration in
    ``[tool.mutmut]`` of ``pyproject.toml``; the score is read from ``mutmut results``.

Not part of the CI time budget: ``hand`` rebuilds the native FMUs per C mutant (minutes), ``mutmut``
runs for tens of minutes. Run it niced::

    nice -n 10 python -m cushion_clutch.benchmarks.mutation [--part hand|mutmut|all] [--only NAME] [--list]

Needs the repository checkout (pyproject.toml and tests/), not an installed wheel.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

#: tests that exercise the native C core (FMI 2 and FMI 3 front ends, tables, closed forms)
NATIVE_TESTS = ("tests/test_native_fmi.py",)


@dataclass(frozen=True)
class Mutant:
    """One deliberate bug: ``old`` (found exactly once in ``path``) replaced by ``new``."""

    name: str
    path: str
    old: str
    new: str
    tests: tuple[str, ...]
    why: str


MUTANTS = (
    # ---- C core: sign flips
    Mutant("c-der-sign", "fmu_src/core/clutch_core.c",
           "r[CC_VR_DER_THETA_CS] = (r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A] - g * r[VR_THETA_CS]) / r[VR_C];",
           "r[CC_VR_DER_THETA_CS] = -(r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A] - g * r[VR_THETA_CS]) / r[VR_C];",
           NATIVE_TESTS, "exposed der(theta_cs) output with the wrong sign (survived on c5f3d16)"),
    Mutant("c-kiss-sign", "fmu_src/core/clutch_cover.c",
           "stack = (w == 0.0 ? tb->delta[i] : (1.0 - w) * tb->delta[i] + w * tb->delta[i + 1]) +",
           "stack = -(w == 0.0 ? tb->delta[i] : (1.0 - w) * tb->delta[i] + w * tb->delta[i + 1]) +",
           NATIVE_TESTS, "kiss point moves the wrong way when hot"),
    Mutant("c-step-decay-sign", "fmu_src/core/clutch_core.c",
           "exp(-h * g / r[VR_C])", "exp(h * g / r[VR_C])", NATIVE_TESTS, "CS thermal step grows instead of decays"),
    Mutant("c-me-der-sign", "fmu_src/core/clutch_core.c",
           "*der = (r[VR_U] * r[VR_THETA_CM] + r[VR_H] * r[VR_THETA_A] - (r[VR_U] + r[VR_H]) * theta) / r[VR_C];",
           "*der = (r[VR_U] * r[VR_THETA_CM] - r[VR_H] * r[VR_THETA_A] - (r[VR_U] + r[VR_H]) * theta) / r[VR_C];",
           NATIVE_TESTS, "ME derivative with the ambient term's sign flipped"),
    Mutant("c-uf-clip", "fmu_src/core/clutch_core.c",
           "r[VR_U_F] = st.u > 0.0 ? st.u : 0.0;", "r[VR_U_F] = st.u;", NATIVE_TESTS, "u_f not clipped at the kiss point"),
    # ---- C tables: off-by-one
    Mutant("c-bracket-off-by-one", "fmu_src/core/clutch_tables.c",
           "if (v >= g[n - 1]) { *i = n - 2; *w = 1.0; return; }",
           "if (v >= g[n - 1]) { *i = n - 2; *w = 0.0; return; }",
           NATIVE_TESTS, "above the hottest table, the second hottest curve is used"),
    Mutant("c-delta-weight", "fmu_src/core/clutch_tables.c",
           "(1.0 - w) * tb->delta[i] + w * tb->delta[i + 1]", "(1.0 - w) * tb->delta[i] + w * tb->delta[i]",
           NATIVE_TESTS, "kiss shift not interpolated towards the next temperature"),
    Mutant("c-hermite-end", "fmu_src/core/clutch_tables.c",
           "if (u >= c->x[c->n - 1]) return c->y[c->n - 1];", "if (u >= c->x[c->n - 1]) return c->y[c->n - 2];",
           NATIVE_TESTS, "force beyond full compression is the second to last row"),
    # ---- C front ends: status changes
    Mutant("c-discard-terminates", "fmu_src/core/clutch_core.c",
           'log_inputs(m, CC_DISCARD, t, "step refused");\n        return CC_DISCARD;',
           'log_inputs(m, CC_DISCARD, t, "step refused");\n        m->terminated = 1;\n        return CC_DISCARD;',
           NATIVE_TESTS, "a recoverable Discard sets fmi2Terminated / terminateSimulation (issue 39)"),
    Mutant("c-discard-ok", "fmu_src/core/clutch_core.c",
           'log_inputs(m, CC_DISCARD, t, "step refused");\n        return CC_DISCARD;',
           'log_inputs(m, CC_DISCARD, t, "step refused");\n        return CC_OK;',
           NATIVE_TESTS, "a step with bad inputs returns OK"),
    Mutant("c-stale-read-ok", "fmu_src/core/clutch_core.c",
           "if (m->dirty && refresh(m, fn) != CC_OK) {", "if (m->dirty && refresh(m, fn) != CC_OK && m->me) {",
           NATIVE_TESTS, "Co-Simulation reads stale outputs with OK after a refused input (issue 39)"),
    Mutant("c-param-after-init", "fmu_src/core/clutch_core.c",
           "if (is_parameter(vr[k]) && after_init) {", "if (is_parameter(vr[k]) && !after_init && 0) {",
           NATIVE_TESTS, "parameters can be changed while stepping"),
    # ---- Python: the mutants that survived on c5f3d16 (issue 21) and two the ccx tests alone caught
    Mutant("py-energy-endpoint", "cushion_clutch/launch/plant/driveline.py",
           "wm_e, wm_d, wm_v = 0.5 * (w_e + w_e_new), 0.5 * (w_d + w_d_new), 0.5 * (w_v + w_v_new)",
           "wm_e, wm_d, wm_v = w_e_new, w_d_new, w_v_new",
           ("tests/test_launch.py",), "energy bookkeeping with end-of-step speeds"),
    Mutant("py-kiss-row-order", "cushion_clutch/model/table_format.py",
           "    order = np.argsort(kp[:, 0])\n", "    order = np.arange(len(kp))\n",
           ("tests/test_spring_table.py",), "the table reader ignores the row order of kiss_point.csv"),
    Mutant("py-api-parameters", "cushion_clutch/model/clutch_model.py",
           "            and (theta_cm is None or THETA_MIN_K <= theta_cm <= THETA_MAX_K) and _clutch_ok(p)):\n"
           "        raise _argument_error({\"x_to\"",
           "            and (theta_cm is None or THETA_MIN_K <= theta_cm <= THETA_MAX_K)):\n"
           "        raise _argument_error({\"x_to\"",
           ("tests/test_model.py",), "the Python API no longer rejects bad clutch parameters"),
    Mutant("py-writer-swap", "cushion_clutch/fe/tables.py",
           'w.writerow([f"{c.theta_degC:g}", f"{u:.9e}", f"{f:.6f}"])',
           'w.writerow([f"{c.theta_degC:g}", f"{f:.9e}", f"{u:.6f}"])',
           ("tests/test_tables.py",), "table writer swaps u and force (only a ccx test caught it)"),
    Mutant("py-kiss-shift-sign", "cushion_clutch/fe/tables.py",
           "ref[0].kiss_travel_m - c.kiss_travel_m", "c.kiss_travel_m - ref[0].kiss_travel_m",
           ("tests/test_tables.py",), "kiss shift sign flipped (only a ccx test caught it)"),
    # ---- packaging: a wheel without a subpackage (the wheel test installs it into an isolated venv)
    Mutant("wheel-without-launch", "pyproject.toml", '"cushion_clutch.launch", ', "",
           ("tests/test_wheel.py::test_every_module_of_the_source_tree_imports_from_the_wheel",),
           "wheel built without cushion_clutch.launch (passed the wheel test on c5f3d16)"),
)


def repo_root() -> Path:
    """The checkout this module lives in (pyproject.toml and tests/ beside the package)."""
    root = Path(__file__).resolve().parents[2]
    if not ((root / "pyproject.toml").exists() and (root / "tests").is_dir()):
        raise FileNotFoundError(f"{root}: not a checkout of cushion-clutch (mutation testing needs the tests)")
    return root


def scratch_copy(root: Path, dest: Path, link: bool = True) -> Path:
    """Copy the checkout's tracked and untracked-not-ignored files into ``dest``.

    Packages that pyproject maps to another folder (``cushion_clutch.fmu_src`` = ``fmu_src/``) are
    linked there (``link``: a mutant of ``fmu_src/x`` is what the package imports) or copied (for
    mutmut, which copies the package again and does not follow links).
    """
    res = subprocess.run(["git", "-C", str(root), "ls-files", "-co", "--exclude-standard", "-z"],
                         capture_output=True, text=True)
    if res.returncode == 0:
        for name in filter(None, res.stdout.split("\0")):
            src = root / name
            if src.is_file():
                (dest / name).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(src, dest / name)
    else:       # not a git checkout (a copy made by this function): everything but build products
        shutil.copytree(root, dest, symlinks=True, dirs_exist_ok=True, ignore=shutil.ignore_patterns(
            "build", "dist", "*.egg-info", "__pycache__", ".pytest_cache", ".hypothesis", "mutants"))
    # so that the copy imports from itself, never from an editable install
    conf = tomllib.loads((root / "pyproject.toml").read_text())
    for pkg, folder in conf.get("tool", {}).get("setuptools", {}).get("package-dir", {}).items():
        target = dest.joinpath(*pkg.split("."))
        if pkg and not target.exists() and (dest / folder).is_dir():
            if link:
                target.symlink_to(dest / folder, target_is_directory=True)
            else:
                shutil.copytree(dest / folder, target)
    return dest


def run_tests(copy: Path, tests: tuple[str, ...], timeout_s: float) -> tuple[str, float]:
    """('passed' | 'failed' | 'error' | 'timeout', seconds) of pytest on ``tests`` in the copy."""
    env = dict(os.environ, PYTHONPATH=str(copy), PYTHONDONTWRITEBYTECODE="1")
    t0 = time.perf_counter()
    try:
        res = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *tests],
                             cwd=copy, env=env, capture_output=True, text=True, timeout=timeout_s)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0
    verdict = {0: "passed", 1: "failed"}.get(res.returncode, "error")
    return verdict, time.perf_counter() - t0


def apply(copy: Path, m: Mutant) -> str:
    """Apply a mutant to the copy; returns the original text to restore."""
    path = copy / m.path
    text = path.read_text()
    if text.count(m.old) != 1:
        raise ValueError(f"mutant {m.name}: the text to mutate occurs {text.count(m.old)} times in {m.path} "
                         "(the source changed: update MUTANTS)")
    path.write_text(text.replace(m.old, m.new))
    return text


def hand_mutants(mutants, timeout_s: float, progress=print) -> list[tuple[Mutant, str, float]]:
    """Run each mutant's tests on a copy with the mutant applied; baseline first (it must pass)."""
    root = repo_root()
    out = []
    with tempfile.TemporaryDirectory(prefix="cushion_mutation_") as tmp:
        copy = scratch_copy(root, Path(tmp))
        for tests in sorted({m.tests for m in mutants}):
            verdict, secs = run_tests(copy, tests, timeout_s)
            progress(f"baseline {' '.join(tests)}: {verdict} ({secs:.0f} s)")
            if verdict != "passed":
                raise RuntimeError(f"the unmutated tests {tests} do not pass ({verdict}): no score")
        for m in mutants:
            original = apply(copy, m)
            try:
                verdict, secs = run_tests(copy, m.tests, timeout_s)
            finally:
                (copy / m.path).write_text(original)
            status = {"passed": "SURVIVED", "failed": "killed", "timeout": "killed (timeout)"}.get(
                verdict, "ERROR (no verdict)")
            progress(f"{m.name:24s} {status:18s} {secs:6.0f} s  {m.why}")
            out.append((m, verdict, secs))
    return out


def run_mutmut(timeout_s: float, max_children: int = 1, progress=print) -> dict[str, int]:
    """mutmut over [tool.mutmut]'s paths in a copy of the checkout; counts by mutmut's status."""
    root = repo_root()
    counts: dict[str, int] = {}
    with tempfile.TemporaryDirectory(prefix="cushion_mutmut_") as tmp:
        copy = scratch_copy(root, Path(tmp), link=False)
        env = dict(os.environ, PYTHONPATH=str(copy))
        exe = [sys.executable, "-m", "mutmut"]
        progress("mutmut run (this takes a while) ...")
        try:
            subprocess.run([*exe, "run", "--max-children", str(max_children)], cwd=copy, env=env,
                           timeout=timeout_s, capture_output=True, text=True)
        except subprocess.TimeoutExpired:
            progress(f"mutmut stopped after {timeout_s:g} s: the counts below are partial "
                     "('not checked' = not run)")
        res = subprocess.run([*exe, "results", "--all", "true"], cwd=copy, env=env, capture_output=True, text=True)
        for line in res.stdout.splitlines():
            name, _, status = line.strip().rpartition(": ")
            if name:
                counts[status] = counts.get(status, 0) + 1
                if status != "killed":
                    progress(f"  {status:12s} {name}")
        report = Path(os.environ.get("MUTMUT_REPORT", root / "mutmut_results.txt"))
        report.write_text(res.stdout)
        progress(f"mutmut results written to {report}")
    return counts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--part", choices=("hand", "mutmut", "all"), default="hand")
    ap.add_argument("--only", action="append", help="run only this hand mutant (repeatable)")
    ap.add_argument("--list", action="store_true", help="list the hand mutants and exit")
    ap.add_argument("--timeout", type=float, default=1800.0, help="per test run (hand) or whole mutmut run, s")
    a = ap.parse_args(argv)
    if a.list:
        for m in MUTANTS:
            print(f"{m.name:24s} {m.path:36s} {m.why}")
        return 0
    try:
        if a.part in ("hand", "all"):
            chosen = [m for m in MUTANTS if not a.only or m.name in a.only]
            if a.only and len(chosen) != len(set(a.only)):
                print(f"unknown mutant in {a.only}; --list shows them", file=sys.stderr)
                return 2
            res = hand_mutants(chosen, a.timeout)
            killed = sum(v in ("failed", "timeout") for _, v, _ in res)
            print(f"hand mutants: {killed}/{len(res)} killed ({100.0 * killed / max(len(res), 1):.0f} %)")
            for m, v, _ in res:
                if v not in ("failed", "timeout"):
                    print(f"  {'survived' if v == 'passed' else 'no verdict (pytest error)'}: {m.name}: {m.why}")
        if a.part in ("mutmut", "all"):
            counts = run_mutmut(a.timeout)
            print(f"mutmut: {counts}")
            killed = counts.get("killed", 0) + counts.get("timeout", 0)
            tested = sum(counts.values()) - counts.get("not checked", 0) - counts.get("skipped", 0)
            if tested:      # 'no tests' (no fast test reaches the line) and 'survived' count against the score
                print(f"mutmut score: {killed}/{tested} killed ({100.0 * killed / tested:.1f} %)")
    except (FileNotFoundError, RuntimeError, ValueError, subprocess.CalledProcessError,
            subprocess.TimeoutExpired) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
