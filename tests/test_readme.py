"""The README's Python examples run as written (from a folder holding the FMU the README builds first), its
figure is that example's output, and the default-table figures in the documentation are the committed CSVs'."""
import os
import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
BLOCKS = re.findall(r"^```python\n(.*?)^```", README.read_text(encoding="utf-8"), flags=re.S | re.M)
FE_PAGE = ROOT / "docs" / "explanation" / "fe_model.md"
#: the quick start's figure, committed; CUSHION_UPDATE_FIGURES=1 replaces it with the example's new output
FIGURE = ROOT / "docs" / "images" / "quickstart_torque.png"
#: RMS tolerance (0-255 grey levels) between the committed figure and a fresh one: a rerun here gives 0; a moved
#: curve or a changed legend gives far more (the cover figure's 305 -> 328 N.m change: 21)
FIGURE_TOL = 2.0


def test_readme_has_python_examples():
    assert BLOCKS


def test_readme_fits_a_screenful_or_so():
    assert len(README.read_text(encoding="utf-8").splitlines()) <= 250


def test_readme_keeps_the_two_commands_and_ci_runs_the_same_tests():
    text = README.read_text(encoding="utf-8")
    assert "bash .ci/install && cushion-clutch launch --out out" in text
    assert "bash .ci/install && python3 -m pytest -q" in text
    assert "bash .ci/install && python3 -m pytest -q" in (ROOT / ".ci" / "run").read_text()
    assert "sphinx-build -W --keep-going -b html docs docs/_build/html" in text


def test_ci_tests_a_fresh_environment_and_the_constraints_pin_every_dependency():
    """.ci/run makes a virtual environment without system site packages and activates it before the README's
    command (issue 43); constraints.txt pins every dependency of pyproject.toml (runtime, test, docs) at a
    version its lower bound allows."""
    import tomllib

    from packaging.requirements import Requirement
    from packaging.utils import canonicalize_name

    run = (ROOT / ".ci" / "run").read_text()
    assert run.index("python3 -m venv") < run.index("/bin/activate") < run.index("bash .ci/install && python3 -m pytest")
    assert "--system-site-packages" not in run
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        if line and not line.startswith("#"):
            name, _, version = line.partition("==")
            pins[canonicalize_name(name)] = version
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = project["optional-dependencies"]
    for spec in project["dependencies"] + extras["test"] + extras["docs"]:
        req = Requirement(spec)
        name = canonicalize_name(req.name)
        assert name in pins, f"constraints.txt does not pin {req.name}"
        assert req.specifier.contains(pins[name], prereleases=True), (spec, pins[name])


@pytest.mark.fmu
@pytest.mark.parametrize("code", BLOCKS, ids=[f"block{i}" for i in range(len(BLOCKS))])
def test_readme_python_block_runs(code, tmp_path, monkeypatch):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu

    if "CushionClutch.fmu" in code:                          # what `cushion-clutch build-fmu` wrote before
        build_fmu(DEFAULT_TABLES, tmp_path / "CushionClutch.fmu")
    monkeypatch.chdir(tmp_path)
    plt.close("all")                    # a reader's fresh session: no figure left open by an earlier test
    exec(compile(code, str(README), "exec"), {"__name__": "readme_example"})
    plt.close("all")
    png = tmp_path / FIGURE.name
    if png.exists():
        assert png.stat().st_size > 10_000 and FIGURE.exists()
        if os.environ.get("CUSHION_UPDATE_FIGURES") == "1":
            shutil.copy(png, FIGURE)
        # the committed figure is this block's output (its generator), not a picture drawn once
        from matplotlib.testing.compare import compare_images
        diff = compare_images(str(FIGURE), str(png), tol=FIGURE_TOL)
        assert diff is None, f"{FIGURE} is stale: rerun with CUSHION_UPDATE_FIGURES=1\n{diff}"


def _page_table(path: Path, header_start: str) -> list[list[str]]:
    """Rows (cells as text) of the Markdown table in ``path`` whose header starts with ``header_start``."""
    lines = path.read_text(encoding="utf-8").splitlines()
    i = next(k for k, line in enumerate(lines) if line.startswith(header_start))
    rows = []
    for line in lines[i + 2:]:
        if not line.startswith("|"):
            break
        rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows


def test_committed_table_figures_are_the_readme_s():
    """The committed default tables' figures (docs/explanation/fe_model.md, once the README's): delta_kiss,
    crest growth, full force, k20/k50/k90 and k90/k20 per temperature, recomputed from the CSVs of
    lookup_tables/default (each at the page's rounding)."""
    import numpy as np

    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fe.tables import progressivity
    from cushion_clutch.model.table_format import read_tables

    t = read_tables(DEFAULT_TABLES)
    crest = dict(np.loadtxt(DEFAULT_TABLES / "crest_growth.csv", delimiter=",", skiprows=1))
    rows = _page_table(FE_PAGE, "| θ [°C] | δ_kiss [mm]")
    assert [float(r[0]) for r in rows] == list(t.theta_degC)
    for r, theta, u, f, d in zip(rows, t.theta_degC, t.u_m, t.force_N, t.delta_kiss_m):
        assert float(r[1]) == pytest.approx(d * 1e3, abs=0.5e-4), r
        assert float(r[2]) == pytest.approx(crest[theta] * 1e3, abs=0.5e-4), r
        assert float(r[3]) == pytest.approx(f[-1], abs=0.5), r
        k = progressivity(u, f)
        k20, k50, k90 = (float(x) for x in r[4].split("/"))
        assert (k20, k50, k90) == pytest.approx(
            (k["k20_N_per_m"] / 1e6, k["k50_N_per_m"] / 1e6, k["k90_N_per_m"] / 1e6), abs=0.005), r
        assert float(r[5]) == pytest.approx(k["k90_over_k20"], abs=0.005), r
        # the metadata's own figures are those of the CSV
        assert t.metadata["progressivity"][f"{theta:g}"]["k90_over_k20"] == pytest.approx(k["k90_over_k20"],
                                                                                        rel=1e-9)
