"""Issue 8, item 1: the wheel works anywhere, from an empty folder, with no repository in sight.

Builds the wheel and installs it into an isolated virtual environment (no system site packages, so
neither the editable install nor the source tree can fill in a module the wheel lacks) whose
dependencies come from pip (PyPI; cached between sessions; the project is re-installed from the
wheel every time), imports every module of the source tree from it, and runs the user-facing
commands from an empty folder.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
import tomllib
import venv
from pathlib import Path

import pytest

from cushion_clutch.benchmarks.mutation import scratch_copy
from cushion_clutch.data import DEFAULT_SPRING

REPO = Path(__file__).resolve().parents[1]          # the checkout under test (tests only)

pytestmark = [pytest.mark.fmu, pytest.mark.ccx]


def _dependency_venv() -> Path:
    """An isolated venv (no system site packages) holding the wheel's dependencies from pip.

    Kept between sessions in ``~/.cache/cushion-clutch/`` under a hash of the Python version and the
    dependency list, so that only the first run downloads and installs them; the project itself is
    re-installed from the fresh wheel every time (the old one uninstalled first).
    """
    deps = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["dependencies"]
    key = hashlib.sha256(repr((sys.version, sorted(deps))).encode()).hexdigest()[:16]
    env_dir = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "cushion-clutch" / f"wheel-venv-{key}"
    py = env_dir / "bin" / "python"
    if not (env_dir / "complete").exists():
        shutil.rmtree(env_dir, ignore_errors=True)
        venv.EnvBuilder(system_site_packages=False, with_pip=False).create(env_dir)
        subprocess.run([sys.executable, "-m", "pip", "--python", str(py), "install", "-q", *deps],
                       check=True, capture_output=True)
        (env_dir / "complete").write_text("dependencies installed\n")
    return env_dir


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    """The wheel, built from a clean copy of the sources (a stale build/ folder in the checkout would put
    modules into the wheel that the sources no longer package: setuptools reuses build/lib)."""
    root = tmp_path_factory.mktemp("wheel")
    dist = root / "dist"
    src = scratch_copy(REPO, root / "src")
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q",
                    "-w", str(dist), str(src)], check=True, capture_output=True)
    return next(dist.glob("cushion_clutch-*.whl"))


def test_wheel_carries_every_fmu_source_and_no_test_host(wheel):
    """Every file of fmu_src's role folders is in the wheel (the FMU builds and host libraries read them there);
    the C hosts only the tests compile (tests/c_hosts) are not."""
    import zipfile
    names = set(zipfile.ZipFile(wheel).namelist())
    shipped = {f"cushion_clutch/fmu_src/{p.relative_to(REPO / 'fmu_src').as_posix()}"
               for p in (REPO / "fmu_src").rglob("*") if p.is_file() and "__pycache__" not in p.parts}
    assert shipped - names == set()
    assert {n for n in names if n.startswith("cushion_clutch/fmu_src/")} == shipped
    test_hosts = {p.name for p in (REPO / "tests" / "c_hosts").glob("*.c")}
    assert test_hosts and not {n for n in names if n.rsplit("/", 1)[-1] in test_hosts}


@pytest.fixture(scope="module")
def installed(wheel):
    """(python, cushion-clutch script, environment) of an isolated venv: dependencies from pip, the project
    only from the built wheel."""
    env_dir = _dependency_venv()
    py = env_dir / "bin" / "python"
    pip = [sys.executable, "-m", "pip", "--python", str(py)]
    subprocess.run([*pip, "uninstall", "-y", "-q", "cushion-clutch"], capture_output=True)
    subprocess.run([*pip, "install", "--no-deps", "-q", str(wheel)], check=True, capture_output=True)
    res = subprocess.run([*pip, "check"], capture_output=True, text=True)        # the wheel's requirements met
    assert res.returncode == 0, res.stdout + res.stderr
    assert "include-system-site-packages = false" in (env_dir / "pyvenv.cfg").read_text()
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


def source_modules(repo: Path = REPO) -> list[str]:
    """Every module and package of the source tree, by walking the folders (not pyproject's package list)."""
    conf = tomllib.loads((repo / "pyproject.toml").read_text())
    roots = {"cushion_clutch": repo / "cushion_clutch",
             **{pkg: repo / folder for pkg, folder in conf["tool"]["setuptools"]["package-dir"].items() if pkg}}
    names = set()
    for pkg, folder in roots.items():
        for path in folder.rglob("*.py"):
            rel = path.relative_to(folder).with_suffix("").parts
            if "__pycache__" in rel:
                continue
            names.add(".".join((pkg, *rel[:-1])) if rel[-1] == "__init__" else ".".join((pkg, *rel)))
    return sorted(names)


IMPORT_ALL = """
import importlib, sys, sysconfig
site = sysconfig.get_paths()["purelib"]
bad = []
for name in sys.argv[1:]:
    try:
        mod = importlib.import_module(name)
    except ModuleNotFoundError as exc:
        # the pythonfmu slave scripts import their siblings and the model top-level, as pythonfmu
        # loads them from the FMU's resources (the build copies cushion_clutch.model and the ground
        # floor's number_check there: fmu.constants.SLAVE_MODULES): import them so, from the wheel's folders
        pkg, _, base = name.rpartition(".")
        folders = [importlib.import_module(pkg).__path__[0],
                   importlib.import_module("cushion_clutch.model").__path__[0],
                   importlib.import_module("cushion_clutch").__path__[0]]
        sys.path[:0] = folders
        try:
            mod = importlib.import_module(base)
        except Exception as exc2:
            bad.append(f"{name}: {type(exc).__name__}: {exc}; top-level: {type(exc2).__name__}: {exc2}")
            continue
        finally:
            del sys.path[:len(folders)]
    except Exception as exc:
        bad.append(f"{name}: {type(exc).__name__}: {exc}")
        continue
    if not getattr(mod, "__file__", "").startswith(site):
        bad.append(f"{name}: imported from {mod.__file__}, not from the wheel in {site}")
print("\\n".join(bad) or "all imported")
"""


def test_every_module_of_the_source_tree_imports_from_the_wheel(installed, tmp_path):
    py, _, env = installed
    names = source_modules()
    assert {"cushion_clutch.launch", "cushion_clutch.fe", "cushion_clutch.model.clutch_model", "cushion_clutch.fmu_src"} <= set(names)
    out = _run([py, "-c", IMPORT_ALL, *names], tmp_path, env)
    assert out.strip() == "all imported", out


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
    # the shortest shipped scenario, found by name in the wheel (12 creep launches 20 s apart: a third
    # of the default scenario's simulated time)
    _run([cli, "launch", "--scenario", "creep", "--out", "out"], work, env, timeout=900)
    assert (work / "out" / "launch_metrics.csv").stat().st_size > 0
    # a user's own spring, coarse (4 mm: the command is under test here, not the mesh) and at one
    # temperature, into ./lookup_tables/<name>/
    text = DEFAULT_SPRING.read_text()
    text = re.sub(r'(?m)^name\s*=.*$', 'name = "my"', text)
    text = re.sub(r'(?m)^element_size_m\s*=.*$', 'element_size_m = 4e-3', text)
    text = re.sub(r'(?ms)(^\[sweep\].*?^temperatures_degC\s*=\s*)\[[^\]]*\]', r'\1[20.0]', text)
    (work / "my.toml").write_text(text)
    _run([cli, "sweep", "--spring", "my.toml", "--cache", "cache"], work, env)
    assert (work / "lookup_tables" / "my" / "force_deflection.csv").exists()
