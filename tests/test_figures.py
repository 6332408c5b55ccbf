"""Every PNG of the documentation has a named generator, and the committed figure is that generator's current
output: each test reruns one generator into a scratch folder and compares the result with the committed PNG
(matplotlib's RMS image difference; a rerun on this machine gives 0, a moved curve or a changed legend far
more). ``CUSHION_UPDATE_FIGURES=1`` copies the fresh figure over the committed one (then look at it)."""
from __future__ import annotations

import importlib
import os
import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: RMS tolerance in grey levels (0-255); the stale cover figure (305 against 328 N.m at 1 mm wear) was at 21
TOL = 2.0

#: docs PNG (relative to docs/) -> (generator module, its arguments with {out} for the PNG, pytest marks)
FIGURES = {
    "protection.png": ("cushion_clutch.benchmarks.protection_figure", ["--png", "{out}"], [pytest.mark.fmu]),
    "cover_characteristics.png": ("cushion_clutch.benchmarks.cover", ["--png", "{out}"], []),
    "cover_wear.png": ("cushion_clutch.benchmarks.cover_wear", ["--png", "{out}", "--md", "{md}"], []),
    "thermal_validation.png": ("cushion_clutch.benchmarks.thermal_validation", ["--out", "{out}", "--write", "{md}"],
                               [pytest.mark.fmu]),
}
#: generators that also rewrite marked blocks of a page ({md}, a copy of it): docs PNG -> the page (under docs/)
PAGES = {"cover_wear.png": "explanation/cover.md", "thermal_validation.png": "explanation/thermal.md"}
#: figures too costly to redraw in CI (a calibration: 24 and more CalculiX cases at the 2 mm mesh, about 10 min on
#: 2 cores): docs PNG -> (its generator command, the sources it depends on). tests/figure_inputs.json records the
#: PNG's hash and the sources' hash at the time it was drawn; a change of either fails until the figure is
#: redrawn (then rerun this test with CUSHION_UPDATE_FIGURES=1 to record the new hashes)
CALIBRATION_SOURCES = ("cushion_clutch/benchmarks/calibrate.py", "cushion_clutch/fe/*.py",
                       "cushion_clutch/fe/springs/default.toml", "cushion_clutch/fe/studies/calibrate.py",
                       "cushion_clutch/fe/studies/measured.py", "cushion_clutch/fe/studies/calibration_report.py")
#: the heat path (a transient thermal FE of the disc sector and the kiss shift under its field, about 10 min)
HEAT_PATH_SOURCES = ("cushion_clutch/fe/heat_*.py", "cushion_clutch/fe/kiss_field.py", "cushion_clutch/fe/deck.py",
                     "cushion_clutch/fe/joint.py", "cushion_clutch/fe/springs/default.toml")
#: the fleet study (1000 samples of three TCUs on Dask, about 15 min; docs/results/fleet.md names its commit)
FLEET_SOURCES = ("cushion_clutch/benchmarks/fleet.py", "cushion_clutch/launch/fleet/run.py",
                 "cushion_clutch/launch/fleet/population.py", "cushion_clutch/launch/populations/*.toml")
RECORDED = {
    "images/heat_path.png": ("cushion-clutch heat-path --kiss-shift --out heat_path_out "
                             "(then copied as docs/developer/guide.md says)", HEAT_PATH_SOURCES),
    "images/fleet_default.png": ("python -m cushion_clutch.benchmarks.fleet --part possible,bar,identity,duty,"
                                 "scaling,big --work W --page docs/results/fleet.md", FLEET_SOURCES),
    "fe_vs_measured.png": ("python -m cushion_clutch.benchmarks.calibrate --png docs/fe_vs_measured.png",
                           CALIBRATION_SOURCES),
    "fe_vs_measured_hot.png": ("python -m cushion_clutch.benchmarks.calibrate --hot "
                               "--png docs/fe_vs_measured_hot.png",
                               CALIBRATION_SOURCES),
}
INPUTS_FILE = Path(__file__).with_name("figure_inputs.json")
#: figures that another test regenerates: docs PNG -> that test
ELSEWHERE = {"images/quickstart_torque.png": "tests/test_readme.py::test_readme_python_block_runs (the README's "
                                             "quick-start block writes it)"}


def test_every_docs_png_has_a_generator():
    pngs = {p.relative_to(DOCS).as_posix() for p in DOCS.rglob("*.png") if "_build" not in p.parts}
    assert pngs == set(FIGURES) | set(RECORDED) | set(ELSEWHERE), \
        "a PNG under docs/ without a generator, or a generator without its PNG"


def _sha(paths) -> str:
    import hashlib
    h = hashlib.sha256()
    for path in paths:
        h.update(path.relative_to(ROOT).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return h.hexdigest()


def _sources(patterns) -> list[Path]:
    return sorted({p for pattern in patterns for p in ROOT.glob(pattern) if p.is_file()})


@pytest.mark.parametrize("name", sorted(RECORDED))
def test_costly_figure_was_drawn_from_today_s_sources(name):
    """The PNG and the sources it was drawn from are those recorded when it was last redrawn by its command."""
    import json
    command, patterns = RECORDED[name]
    now = {"command": command, "png_sha256": _sha([DOCS / name]), "sources_sha256": _sha(_sources(patterns))}
    recorded = json.loads(INPUTS_FILE.read_text(encoding="utf-8")) if INPUTS_FILE.exists() else {}
    if os.environ.get("CUSHION_UPDATE_FIGURES") == "1":
        recorded[name] = now
        INPUTS_FILE.write_text(json.dumps(recorded, indent=2, sort_keys=True) + "\n", encoding="utf-8")
    assert recorded.get(name) == now, (f"docs/{name} or the sources it was drawn from changed since it was drawn: "
                                       f"redraw it with `{command}`, look at it, then rerun this test with "
                                       "CUSHION_UPDATE_FIGURES=1")


def _compare(committed: Path, fresh: Path) -> None:
    from matplotlib.testing.compare import compare_images

    assert fresh.exists() and fresh.stat().st_size > 10_000, fresh
    if os.environ.get("CUSHION_UPDATE_FIGURES") == "1":
        shutil.copy(fresh, committed)
    diff = compare_images(str(committed), str(fresh), tol=TOL)
    assert diff is None, f"docs/{committed.relative_to(DOCS)} is stale: rerun its generator (or this test with " \
                         f"CUSHION_UPDATE_FIGURES=1) and look at it\n{diff}"


@pytest.mark.parametrize("name", [pytest.param(n, marks=m) for n, (_, _, m) in FIGURES.items()])
def test_committed_figure_is_its_generator_s_output(name, tmp_path, monkeypatch):
    import matplotlib
    matplotlib.use("Agg")
    module, args, _ = FIGURES[name]
    md = tmp_path / "page.md"
    if "{md}" in args:                                  # the generator also rewrites its blocks of a page
        shutil.copy(DOCS / PAGES[name], md)
    out = tmp_path / name
    monkeypatch.chdir(tmp_path)
    importlib.import_module(module).main([a.format(out=out, md=md) for a in args])
    if "{md}" in args:                                  # the page's blocks first: they do not depend on fonts
        undated = lambda text: re.sub(r" on \d{4}-\d{2}-\d{2} ", " on DATE ", text)   # noqa: E731
        assert undated(md.read_text(encoding="utf-8")) == \
            undated((DOCS / PAGES[name]).read_text(encoding="utf-8")), \
            f"docs/{PAGES[name]}'s generated blocks are stale: python -m {module} " + \
            " ".join(a.format(out=f"docs/{name}", md=f"docs/{PAGES[name]}") for a in args)
    _compare(DOCS / name, out)
