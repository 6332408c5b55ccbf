"""Ctrl-C and SIGTERM stop a real sweep cleanly (issue 12, item 1).

A terminal's Ctrl-C sends SIGINT to the whole foreground process group; the
test does the same to a ``cushion-clutch sweep`` on the 2 mm mesh once one
case is finished and the next one is running in ccx.
"""
from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cushion_clutch.data import DEFAULT_SPRING
from cushion_clutch import interrupt
from cushion_clutch.errors import RunInterrupted


def _ccx_processes_in(folder: Path) -> list[int]:
    """PIDs of live processes whose working directory is inside ``folder``."""
    found = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            cwd = Path(os.readlink(d / "cwd"))
            state = (d / "stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state != "Z" and cwd.is_relative_to(folder):
            found.append(int(d.name))
    return found


def _wait_for(predicate, timeout_s: float, what: str):
    end = time.monotonic() + timeout_s
    while time.monotonic() < end:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture(scope="module")
def sweep_dirs(tmp_path_factory):
    """One cache for both signals: the SIGTERM run resumes from the case the SIGINT run finished."""
    return tmp_path_factory.mktemp("interrupt")


@pytest.mark.ccx
@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_stops_a_real_sweep(sweep_dirs, sig, code):
    tmp_path = sweep_dirs
    spring = tmp_path / "spring.toml"
    text = Path(DEFAULT_SPRING).read_text()
    text = re.sub(r'(?m)^name = .*$', 'name = "interrupt_test"', text)
    text = re.sub(r"(?ms)(^\[sweep\].*?^temperatures_degC = )\[[^\]]*\]", r"\1[20.0, 195.0, 300.0]", text)
    spring.write_text(text)
    cache, out = tmp_path / "cache", tmp_path / "tables"
    proc = subprocess.Popen([sys.executable, "-m", "cushion_clutch.cli", "sweep", "--spring", str(spring),
                             "--mesh-size", "0.002", "--jobs", "1", "--cache", str(cache), "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        # one case finished and cached, the next one running in ccx, the third queued
        _wait_for(lambda: list(cache.rglob("result.json")), 300, "the first finished case")
        _wait_for(lambda: _ccx_processes_in(cache), 60, "the second case's ccx process")
        cached = set(cache.rglob("result.json"))
        start = time.monotonic()
        os.killpg(proc.pid, sig)                   # as a terminal does: the whole process group
        stdout, stderr = proc.communicate(timeout=30)
        took = time.monotonic() - start
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert took < 5.0, f"the sweep took {took:.1f} s to stop"
    assert proc.returncode == code, stderr
    assert "Traceback" not in stderr
    lines = [ln for ln in stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "resume" in lines[0] and signal.Signals(sig).name in lines[0], stderr
    assert not _ccx_processes_in(cache), "ccx processes survived the interrupt"
    after = set(cache.rglob("result.json"))
    assert cached <= after and len(after) < 3, "finished cases stay cached; the queued case never ran"
    assert not (out / "force_deflection.csv").exists() and not (out / "tables.manifest.json").exists()


def test_cancel_refuses_new_children_and_kills_running_ones(tmp_path):
    """The mechanism itself: a tracked child is killed with its group; nothing starts after cancel."""
    with interrupt.handle_signals():
        with interrupt.popen(["sh", "-c", "sleep 30 & sleep 30"]) as proc:
            interrupt.cancel(signal.SIGTERM)
            assert proc.wait(timeout=5) == -signal.SIGKILL
        with pytest.raises(RunInterrupted) as exc:
            with interrupt.popen(["true"]):
                pass
        assert exc.value.exit_code == 143
    assert not interrupt.cancelled(), "leaving handle_signals() resets the run"
