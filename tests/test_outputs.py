"""Atomic files and output sets (issue 12, item 7)."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from cushion_clutch.outputs import OutputSet, atomic_path, check_writable, read_manifest


def test_set_replaces_the_old_set_and_leaves_other_files(tmp_path):
    (tmp_path / "user_notes.txt").write_text("mine")
    with OutputSet(tmp_path, "launch") as stage:
        (stage / "launch_naive.csv").write_text("old naive")
        (stage / "launch_aware.csv").write_text("old aware")
    with OutputSet(tmp_path, "launch") as stage:
        (stage / "launch_naive.csv").write_text("new naive")
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["launch.manifest.json", "launch_naive.csv", "user_notes.txt"]
    m = read_manifest(tmp_path, "launch")
    assert list(m["files"]) == ["launch_naive.csv"] and m["files"]["launch_naive.csv"]["bytes"] == 9


def test_failed_run_leaves_the_old_set_untouched(tmp_path):
    with OutputSet(tmp_path, "export") as stage:
        (stage / "a.txt").write_text("old")
    with pytest.raises(RuntimeError):
        with OutputSet(tmp_path, "export") as stage:
            (stage / "a.txt").write_text("new, half")
            raise RuntimeError("simulation failed")
    assert (tmp_path / "a.txt").read_text() == "old" and read_manifest(tmp_path, "export")
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], "no staging left behind"


def test_atomic_path_keeps_the_old_file_on_failure(tmp_path):
    target = tmp_path / "plot.png"
    target.write_text("old")
    with pytest.raises(ValueError):
        with atomic_path(target) as tmp:
            assert tmp.suffix == ".png" and tmp.parent == tmp_path
            tmp.write_text("partial")
            raise ValueError
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["plot.png"]


def test_check_writable_names_the_folder(tmp_path):
    (tmp_path / "file").write_text("x")
    with pytest.raises(OSError, match="file/sub cannot be written"):
        check_writable(tmp_path / "file" / "sub")


WRITER = """
import sys, time
from cushion_clutch.outputs import OutputSet
with OutputSet(sys.argv[1], "launch") as stage:
    with open(stage / "launch_naive.csv", "w") as fh:
        fh.write("time_s,x\\n")
        for k in range(10**9):
            fh.write(f"{k},1\\n")
            if k == 1000:
                fh.flush(); print("writing", flush=True)
"""


def test_killed_rerun_never_mixes_sets(tmp_path):
    """SIGKILL while a rerun writes: the old set is complete (manifest matches), no new file beside it."""
    with OutputSet(tmp_path, "launch") as stage:
        (stage / "launch_naive.csv").write_text("time_s,x\n0,1\n")
        (stage / "launch_aware.csv").write_text("time_s,x\n0,2\n")
    before = read_manifest(tmp_path, "launch")
    p = subprocess.Popen([sys.executable, "-c", WRITER, str(tmp_path)], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "writing"
    time.sleep(0.2)
    os.kill(p.pid, signal.SIGKILL)
    p.wait()
    assert read_manifest(tmp_path, "launch") == before
    visible = sorted(q.name for q in tmp_path.iterdir() if not q.name.startswith("."))
    assert visible == ["launch.manifest.json", "launch_aware.csv", "launch_naive.csv"]
    assert (tmp_path / "launch_naive.csv").read_text() == "time_s,x\n0,1\n"
    assert json.loads((tmp_path / "launch.manifest.json").read_text())["set"] == "launch"
    with OutputSet(tmp_path, "launch") as stage:          # the next run clears the killed run's staging
        (stage / "launch_naive.csv").write_text("new\n")
    assert sorted(q.name for q in tmp_path.iterdir()) == ["launch.manifest.json", "launch_naive.csv"]
