"""The documentation (docs/ and README.md): code blocks run or are marked as not run, internal links resolve,
the site builds with warnings as errors and names every subcommand, and the launch results page's check
figures are what a fresh run gives (a stale page fails)."""
from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
PAGES = sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.parts)
README = ROOT / "README.md"

#: fenced code blocks: ```python is executed, every other language is shown, never run; these spellings of
#: Python are refused, since a reader would take them for examples that the tests run
AMBIGUOUS = {"py", "python3", "ipython", "pycon", "Python"}
FENCE = re.compile(r"^```(\S*)[^\n]*\n(.*?)^```\s*$", flags=re.S | re.M)


def python_blocks(path: Path) -> list[str]:
    """The executed blocks of a page: fenced exactly as ```python."""
    return [body for lang, body in FENCE.findall(path.read_text(encoding="utf-8")) if lang == "python"]


def test_there_are_pages_and_executed_blocks():
    assert len(PAGES) >= 15
    assert sum(len(python_blocks(p)) for p in PAGES) >= 3


@pytest.mark.parametrize("page", PAGES + [README], ids=lambda p: str(p.relative_to(ROOT)))
def test_every_code_block_is_run_or_marked_not_run(page):
    """```python runs (below); console, text, toml, ... are shown; a {code-block} python says "not run" and
    why; another spelling of Python is a convention break (it would silently never run)."""
    for lang, body in FENCE.findall(page.read_text(encoding="utf-8")):
        assert lang not in AMBIGUOUS, (page, lang, body[:80])
    for m in re.finditer(r"```\{code-block\} (\w+)\n((?::\w+:.*\n)*)", page.read_text(encoding="utf-8")):
        if m.group(1) == "python":
            assert re.search(r":caption: not run \(.+\)", m.group(2)), (page, m.group(0))


@pytest.fixture(scope="session")
def fmu_file(tmp_path_factory) -> Path:
    from cushion_clutch.data import DEFAULT_TABLES
    from cushion_clutch.fmu.build import build_fmu
    return build_fmu(DEFAULT_TABLES, tmp_path_factory.mktemp("fmu") / "CushionClutch.fmu")


def _block_params():
    out = []
    for page in PAGES:
        blocks = python_blocks(page)
        if blocks:
            needs_fmu = any(".fmu" in b for b in blocks)
            out.append(pytest.param(page, blocks, marks=[pytest.mark.fmu] if needs_fmu else [],
                                    id=str(page.relative_to(DOCS))))
    return out


@pytest.mark.parametrize("page,blocks", _block_params())
def test_python_blocks_run(page, blocks, tmp_path, monkeypatch, request):
    """A page's ```python blocks, in order, in one namespace, from a scratch folder (with the FMU if used)."""
    import matplotlib
    matplotlib.use("Agg")
    if any(".fmu" in b for b in blocks):
        shutil.copy(request.getfixturevalue("fmu_file"), tmp_path / "CushionClutch.fmu")
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "docs_example"}
    for code in blocks:
        exec(compile(code, str(page), "exec"), namespace)
    import matplotlib.pyplot as plt
    plt.close("all")


LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)\)|!\[[^\]]*\]\(([^)\s]+)\)")


def _anchors(path: Path) -> set[str]:
    """MyST's heading anchors (myst_heading_anchors = 3) of a page."""
    out = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        m = re.match(r"^(#{1,3}) (.+)$", line)
        if m:
            text = re.sub(r"[`*]", "", m.group(2)).strip().lower()
            out.add(re.sub(r"\s+", "-", re.sub(r"[^\w\s-]", "", text)))
    return out


@pytest.mark.parametrize("page", PAGES + [README], ids=lambda p: str(p.relative_to(ROOT)))
def test_internal_links_resolve(page):
    """Every relative link (pages, figures, anchors) points at something that exists."""
    text = FENCE.sub("", page.read_text(encoding="utf-8"))
    for m in LINK.finditer(text):
        target = m.group(1) or m.group(2)
        if re.match(r"^[a-z]+:", target):
            continue                                            # http(s), mailto
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        assert dest.exists(), f"{page.name}: {target} does not exist"
        if anchor and dest.suffix == ".md":
            assert anchor in _anchors(dest), f"{page.name}: #{anchor} is no heading of {dest.name}"


@pytest.mark.filterwarnings("ignore")            # Sphinx's own deprecation notices, not ours
def test_site_builds_with_warnings_as_errors_and_names_every_subcommand(tmp_path):
    """The Sphinx build (-W --keep-going) succeeds and its CLI reference names every subcommand."""
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_parser")
    pytest.importorskip("sphinxarg")
    from sphinx.cmd.build import build_main

    from cushion_clutch.cli import build_parser

    out = tmp_path / "html"
    assert build_main(["-W", "--keep-going", "-q", "-b", "html", str(DOCS), str(out)]) == 0
    html = (out / "reference" / "cli.html").read_text(encoding="utf-8")
    sub = next(a for a in build_parser()._actions if a.__class__.__name__ == "_SubParsersAction")
    for name in sub.choices:
        assert f"cushion-clutch {name}" in html or f">{name}<" in html, name
    variables = (out / "reference" / "fmu_variables.html").read_text(encoding="utf-8")
    from cushion_clutch.model.clutch_model import VARIABLES
    for name, *_ in VARIABLES:
        assert f">{name}<" in variables, name


RESULTS = DOCS / "results"


@pytest.mark.parametrize("page", sorted(RESULTS.glob("*.md")), ids=lambda p: p.name)
def test_results_pages_say_what_made_them(page):
    text = page.read_text(encoding="utf-8")
    assert "Generated, not edited" in text and "Written by `python3 -m cushion_clutch.benchmarks." in text
    assert re.search(r"- commit: `[0-9a-f]{7,}", text) and "- machine: " in text and re.search(r"- date: \d{4}-", text)
    # a clean tree and no machine path: page.py refuses a dirty tree unless --draft, which marks the page
    from cushion_clutch.benchmarks.page import DRAFT_MARK
    assert DRAFT_MARK not in text and "+dirty" not in text and "uncommitted changes" not in text, page.name
    command = re.search(r"Written by `([^`]*)`", text).group(1)
    assert not re.search(r"(^|[\s=])(/|~|[A-Za-z]:\\)", command), f"{page.name}: absolute path in {command!r}"


@pytest.mark.fmu
def test_launch_page_check_figures_are_today_s():
    """The launch page's check figures (the first launches of `default`, per launch and TCU) equal a fresh
    run's: a page left stale after a physics change fails here."""
    from cushion_clutch.benchmarks.launch import CHECK_HEADING, check_run

    text = (RESULTS / "launch.md").read_text(encoding="utf-8")
    section = text.split(CHECK_HEADING, 1)[1]
    page_rows = [line for line in section.splitlines() if line.startswith("| ")]
    fresh_rows = [line for line in check_run().splitlines() if line.startswith("| ")]
    assert page_rows == fresh_rows, "docs/results/launch.md is stale: regenerate it (see docs/developer/guide.md)"
