"""Running CalculiX: write a deck to a folder, run ``ccx``, judge the outcome.

ccx's exit code alone proves nothing (a missing input file returns 0), so a
run counts as finished only with exit code 0, ``Job finished`` in its
output, no ``*ERROR`` and no input-reading warning.
"""
from __future__ import annotations

import functools
import logging
import os
import re
import shutil
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from .. import interrupt
from ..errors import CalculixError, CalculixNotFoundError, ConvergenceError

log = logging.getLogger(__name__)

_INC_RE = re.compile(r"^\s*increment\s+(\d+)\s+attempt\s+(\d+)", re.M)
_STEP_RE = re.compile(r"^\s*STEP\s+(\d+)", re.M)
_ITER_RE = re.compile(r"iteration\s+(\d+)")


@dataclass(frozen=True)
class RunStats:
    """What a finished ccx run cost.

    Attributes
    ----------
    wall_time_s : float
        Wall-clock time, s.
    increments : int
        Converged increments over all steps.
    iterations : int
        Newton iterations over all steps and attempts.
    cutbacks : int
        Increments reattempted with a smaller size.
    """

    wall_time_s: float
    increments: int
    iterations: int
    cutbacks: int


def ccx_executable() -> str:
    """Path of the ccx binary (``$CCX`` or ``ccx`` on PATH)."""
    exe = os.environ.get("CCX", "ccx")
    path = shutil.which(exe)
    if path is None:
        raise CalculixNotFoundError(exe)
    return path


def ccx_version() -> str:
    """The CalculiX version string, e.g. ``2.20``."""
    return _version_of(ccx_executable())


@functools.lru_cache(maxsize=None)
def _version_of(executable: str) -> str:
    out = subprocess.run([executable, "-v"], capture_output=True, text=True, timeout=30)
    return parse_version(out.stdout + out.stderr)


def parse_version(text: str) -> str:
    """The version in the output of ``ccx -v`` (``unknown`` if none is printed)."""
    m = re.search(r"Version\s+([\w.]+)", text)
    return m.group(1) if m else "unknown"


def _tail(text: str, n: int = 25) -> str:
    return "\n".join(text.rstrip().splitlines()[-n:])


def _last_step_increment(log_text: str, sta_text: str) -> tuple[int | None, int | None]:
    """Step and increment that were being attempted when the run stopped."""
    rows = [ln.split() for ln in sta_text.splitlines() if re.match(r"^\s*\d+\s+\d+", ln)]
    step = inc = None
    if rows:
        step, inc = int(rows[-1][0]), int(rows[-1][1])
    steps = _STEP_RE.findall(log_text)
    incs = _INC_RE.findall(log_text)
    if steps:
        step = int(steps[-1])
    if incs:
        inc = int(incs[-1][0])
    return step, inc


def parse_stats(log_text: str, sta_text: str, wall_time_s: float) -> RunStats:
    """Count increments, iterations and cut-backs from ccx's output and ``.sta``."""
    rows = [ln.split() for ln in sta_text.splitlines() if re.match(r"^\s*\d+\s+\d+\s+\d+", ln)]
    increments = len(rows)
    iterations = sum(int(r[3]) for r in rows if len(r) > 3 and r[3].isdigit())
    cutbacks = len(re.findall(r"increment size is decreased|increment is reattempted", log_text))
    if not iterations:
        iterations = len(_ITER_RE.findall(log_text))
    return RunStats(wall_time_s, increments, iterations, cutbacks)


def run_ccx(deck_text: str, workdir: Path, job: str = "case", *, threads: int = 1,
            timeout_s: float | None = None, theta_degC: float | None = None,
            on_line: Callable[[str], None] | None = None) -> RunStats:
    """Run one deck in ``workdir`` and check that it finished.

    Parameters
    ----------
    deck_text : str
        The ``.inp`` content.
    workdir : Path
        Folder for the job's files (created).
    job : str
        Job name (``job.inp``, ``job.dat``, ...).
    threads : int
        Threads for ccx (``OMP_NUM_THREADS``).
    timeout_s : float, optional
        Kill the run after this long.
    theta_degC : float, optional
        Case temperature, for error messages.
    on_line : callable, optional
        Called with each line of ccx's standard output (progress).

    Raises
    ------
    CalculixNotFoundError
        ccx is not installed.
    ConvergenceError
        The increment size fell below its minimum or the increment cap was hit.
    CalculixError
        Any other failure (input error, crash, missing output).
    """
    exe = ccx_executable()
    workdir.mkdir(parents=True, exist_ok=True)
    for suffix in (".dat", ".sta", ".cvg", ".frd", ".log"):
        (workdir / f"{job}{suffix}").unlink(missing_ok=True)
    (workdir / f"{job}.inp").write_text(deck_text)
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), CCX_NPROC_EQUATION_SOLVER=str(threads))
    start = time.perf_counter()
    lines: list[str] = []
    with interrupt.popen([exe, "-i", job], cwd=workdir, env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, errors="replace") as proc:
        assert proc.stdout is not None
        try:
            for line in proc.stdout:
                lines.append(line)
                if on_line is not None:
                    on_line(line)
                if timeout_s is not None and time.perf_counter() - start > timeout_s:
                    proc.kill()
                    lines.append(f"*ERROR: killed after {timeout_s:g} s (timeout)\n")
                    break
        finally:
            returncode = proc.wait()
    interrupt.check()                               # killed by Ctrl-C / SIGTERM: not a solver failure
    wall = time.perf_counter() - start
    log_text = "".join(lines)
    (workdir / f"{job}.log").write_text(log_text)
    sta_path = workdir / f"{job}.sta"
    sta_text = sta_path.read_text(errors="replace") if sta_path.exists() else ""
    tail = _tail(log_text)
    where = f" at theta = {theta_degC:g} degC" if theta_degC is not None else ""

    not_converged = ("increment size smaller than minimum" in log_text
                     or "too many cutbacks" in log_text
                     or "max. # of increments reached" in log_text
                     or "too many increments" in log_text.lower()
                     or "maximum number of increments" in log_text.lower())
    if not_converged:
        step, inc = _last_step_increment(log_text, sta_text)
        raise ConvergenceError(
            f"CalculiX did not converge{where}: step {step}, increment {inc}", returncode, tail,
            theta_degC=theta_degC, step=step, increment=inc)
    squashed = re.sub(r"\s+", "", log_text)         # ccx breaks long words across columns
    if "*ERROR" in log_text or "*WARNING in calinput" in log_text or "cannotbeinterpreted" in squashed:
        raise CalculixError(f"CalculiX reported an error{where}", returncode, tail)
    if returncode != 0:
        raise CalculixError(f"CalculiX failed{where}", returncode, tail)
    if "Job finished" not in log_text or not (workdir / f"{job}.dat").exists():
        raise CalculixError(f"CalculiX did not finish{where} (no 'Job finished' or no .dat)",
                            returncode, tail)
    stats = parse_stats(log_text, sta_text, wall)
    log.debug("ccx %s%s finished: %s", job, where, stats)
    return stats
