"""Issue 8, item 1: the wheel works anywhere, from an empty folder, with no repository in sight.

Builds the wheel, installs it (no editable install, no source tree on the path) into a fresh
virtual environment that borrows only the third-party dependencies, and runs the user-facing
commands from an empty folder.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import venv
from pathlib import Path

import pytest

from cushion_clutch.data import DEFAULT_SPRING

REPO = Path(__file__).resolve().parents[1]          # the checkout under test (tests only)

pytestmark = [pytest.mark.fmu, pytest.mark.ccx]


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """(python, cushion-clutch script, environment) of a venv holding only the built wheel."""
    root = tmp_path_factory.mktemp("wheel")
    dist = root / "dist"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q",
                    "-w", str(dist), str(REPO)], check=True, capture_output=True)
    wheel = next(dist.glob("cushion_clutch-*.whl"))
    env_dir = root / "venv"
    venv.EnvBuilder(system_site_packages=True, with_pip=False).create(env_dir)
    py = env_dir / "bin" / "python"
    subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "--no-deps", "-q",
                    str(wheel)], check=True, capture_output=True)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    return py, env_dir / "bin" / "cushion-clutch", env


def _run(cmd, cwd, env, timeout=600):
    res = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True,
                         timeout=timeout)
    assert res.returncode == 0, f"{cmd}: exit {res.returncode}\n{res.stdout[-2000:]}\n{res.stderr[-3000:]}"
    return res.stdout


def test_the_package_comes_from_the_wheel(installed, tmp_path):
    py, _, env = installed
    out = _run([py, "-c", "import cushion_clutch, cushion_clutch.data as d; print(cushion_clutch.__file__);"
                "print(d.DEFAULT_TABLES); print(d.fmu_sources())"], tmp_path, env)
    for line in out.splitlines():
        assert "site-packages" in line and str(REPO) not in line, out


def test_commands_work_from_an_empty_folder(installed, tmp_path):
    py, cli, env = installed
    work = tmp_path / "empty"
    work.mkdir()
    _run([cli, "build-fmu", "-o", "X.fmu"], work, env)
    assert (work / "X.fmu").stat().st_size > 0
    _run([cli, "export", "--out", "exports"], work, env)
    assert (work / "exports" / "cushion_spring_tables.mat").exists()
    out = _run([py, "-c", "from cushion_clutch.model import load_table; print(load_table().theta_degC)"],
               work, env)
    assert "20.0" in out
    _run([cli, "launch", "--out", "out"], work, env, timeout=900)
    assert (work / "out" / "launch_metrics.csv").stat().st_size > 0
    # a user's own spring, coarse and at one temperature, into ./lookup_tables/<name>/
    text = DEFAULT_SPRING.read_text()
    text = re.sub(r'(?m)^name\s*=.*$', 'name = "my"', text)
    text = re.sub(r'(?m)^element_size_m\s*=.*$', 'element_size_m = 2e-3', text)
    text = re.sub(r'(?ms)(^\[sweep\].*?^temperatures_degC\s*=\s*)\[[^\]]*\]', r'\1[20.0]', text)
    (work / "my.toml").write_text(text)
    _run([cli, "sweep", "--spring", "my.toml", "--cache", "cache"], work, env)
    assert (work / "lookup_tables" / "my" / "force_deflection.csv").exists()
