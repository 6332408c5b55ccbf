"""Distributed runs on a real Dask cluster: scheduler and workers as separate processes on 127.0.0.1.

One worker lacks the package (``sys.modules['cushion_clutch'] = None`` before it
starts, see /work/shared/notes/dask.md): the check must name it within 30 s.
A good worker must give the local result, with a client that has no ccx, and
a worker killed mid-case must be reported, not waited for.
"""
from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import time

import numpy as np
import pytest

from cushion_clutch.errors import ClusterError

pytestmark = pytest.mark.ccx
pytest.importorskip("distributed")

BAD_WORKER = ("import sys; sys.modules['cushion_clutch'] = None; "
              "from distributed.cli.dask_worker import main; sys.argv[0] = 'dask_worker'; main()")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Cluster:
    """A scheduler and workers started as processes; each is ended by its own pid."""

    def __init__(self, tmp_path):
        self.port = _free_port()
        self.address = f"tcp://127.0.0.1:{self.port}"
        self.tmp = tmp_path
        self.procs: list[subprocess.Popen] = []
        self.scheduler = self._start([sys.executable, "-m", "distributed.cli.dask_scheduler", "--host",
                                      "127.0.0.1", "--port", str(self.port), "--no-dashboard"], "scheduler")
        deadline = time.monotonic() + 60.0           # a loaded machine starts Python slowly
        while True:
            try:
                socket.create_connection(("127.0.0.1", self.port), timeout=1.0).close()
                break
            except OSError:
                if time.monotonic() > deadline or self.scheduler.poll() is not None:
                    self.close()
                    raise RuntimeError(f"the scheduler did not start: {(tmp_path / 'scheduler.log').read_text()}")
                time.sleep(0.2)

    def _start(self, argv, name):
        log = open(self.tmp / f"{name}.log", "w")
        proc = subprocess.Popen(argv, stdout=log, stderr=subprocess.STDOUT, cwd=self.tmp,
                                env=dict(os.environ, PYTHONWARNINGS="ignore"))
        self.procs.append(proc)
        return proc

    def worker(self, name: str, package: bool = True) -> subprocess.Popen:
        args = [self.address, "--nthreads", "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1",
                "--name", name]
        argv = [sys.executable, "-m", "distributed.cli.dask_worker", *args] if package else \
            [sys.executable, "-c", BAD_WORKER, *args]
        return self._start(argv, name)

    def close(self):
        for proc in reversed(self.procs):
            if proc.poll() is None:
                proc.terminate()
                try:
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    proc.kill()


@pytest.fixture
def cluster(tmp_path):
    c = Cluster(tmp_path)
    yield c
    c.close()


def test_a_worker_without_the_package_is_named_within_30_s(cluster, tmp_path, capsys):
    from cushion_clutch.cli import main
    cluster.worker("nopkg", package=False)
    start = time.monotonic()
    code = main(["sweep", "--scheduler", cluster.address, "--mesh-size", "2e-3", "--out", str(tmp_path / "t"),
                 "--cache", str(tmp_path / "cache")])
    took = time.monotonic() - start
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err and took < 30.0, (took, err)
    assert f"the Dask cluster at {cluster.address} cannot run the FE cases" in err
    assert "cannot import cushion_clutch (ModuleNotFoundError" in err and "worker tcp://127.0.0.1:" in err
    assert not list((tmp_path / "t").glob("*.csv")) if (tmp_path / "t").exists() else True
    print(err, f"took {took:.1f} s")


def test_no_worker_at_all_fails_within_the_check_time(cluster, tmp_path):
    from cushion_clutch.fe.cluster import open_cluster
    start = time.monotonic()
    with pytest.raises(ClusterError, match="no Dask worker joined the scheduler"):
        with open_cluster(cluster.address, timeout_s=3.0):
            pass
    assert time.monotonic() - start < 15.0


def test_remote_case_equals_local_with_no_ccx_on_the_client_and_a_lost_worker_is_reported(
        cluster, coarse, case_cache, tmp_path, monkeypatch):
    from cushion_clutch.fe.cluster import open_cluster, run_cases
    from cushion_clutch.fe.cases import case_key, solve_shipped
    from cushion_clutch.fe.sweep import run_sweep
    p = coarse.replace(solver={"compression_increments": 30}, sweep={"temperatures_degC": (20.0,)})
    local = run_sweep(p, cache_dir=case_cache, jobs=1)[20.0]
    worker = cluster.worker("good")
    monkeypatch.setenv("PATH", os.pathsep.join(d for d in os.environ["PATH"].split(os.pathsep)
                                               if not os.path.exists(os.path.join(d, "ccx"))))
    monkeypatch.delenv("CCX", raising=False)
    assert shutil.which("ccx") is None                     # the client has no CalculiX
    remote = run_sweep(p, cache_dir=tmp_path / "cache", scheduler=cluster.address)[20.0]
    assert not remote.from_cache and remote.ccx_version == local.ccx_version
    np.testing.assert_array_equal(remote.result.force_N, local.result.force_N)
    key = f"theta_20_{case_key(p, 20.0, 1, local.ccx_version)}"   # the workers' ccx version in the key
    assert (tmp_path / "cache" / p.name / key / "result.json").exists()

    # the only worker dies while it solves: reported within the grace time, not waited for
    done = []
    with open_cluster(cluster.address) as (client, info):
        def kill_soon():
            time.sleep(3.0)
            worker.kill()
        import threading
        threading.Thread(target=kill_soon, daemon=True).start()
        start = time.monotonic()
        with pytest.raises(ClusterError, match=r"all Dask workers of .* were lost \(tcp://127\.0\.0\.1:\d+\)"):
            run_cases(client, info, solve_shipped, [("c", p.replace(solver={"compression_increments": 60}), 80.0, 1)],
                      lambda *a: done.append(a), lost_grace_s=2.0)
        assert time.monotonic() - start < 20.0 and done == []


def test_idle_cores_become_threads(monkeypatch):
    from cushion_clutch.fe.cluster import ClusterInfo, WorkerInfo
    from cushion_clutch.fe.cases import idle_threads
    monkeypatch.setattr(os, "cpu_count", lambda: 16)
    monkeypatch.setattr(os, "getloadavg", lambda: (0.2, 0.2, 0.2))
    assert [idle_threads(16, n) for n in (1, 5, 16, 40)] == [16, 3, 1, 1]
    assert idle_threads(2, 1) == 2
    monkeypatch.setattr(os, "getloadavg", lambda: (12.0, 12.0, 12.0))     # others keep 12 cores busy
    assert idle_threads(16, 1) == 4 and idle_threads(16, 5) == 3
    workers = tuple(WorkerInfo(f"tcp://h:{i}", "h", 1, 8, "x", "2.20", ()) for i in range(16))
    info = ClusterInfo("tcp://h:8786", workers, "2.20")
    assert info.slots == 16 and [info.threads_per_case(n) for n in (1, 5, 16)] == [8, 3, 1]
