"""The documentation site as a reader sees it: the main pages (and the other generated pages with wide tables)
rendered in headless Chromium (Debian's `chromium`, .ci/install) at 1280 px. A table or code block wider than
the content column, an image that does not load or an internal link that leads nowhere fails; every page of
the site is free of the checkout's absolute path and of ``+dirty``. Screenshots (full page, collapsed sections
opened) are kept in ``docs/_build/screenshots/`` for review (CI artefacts, never committed).

How: the site is built into a temporary folder; each main page gets a copy beside it with a small script that
opens every ``<details>``, measures the tables, code blocks and images after the page has loaded and writes
the findings into an attribute of ``<html>``; ``chromium --headless --dump-dom`` returns that DOM (no
Python browser driver needed), a second run takes the screenshot at the page's measured height.
"""
from __future__ import annotations

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

from conftest import missing_tool

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
SCREENSHOTS = DOCS / "_build" / "screenshots"
WIDTH_PX = 1280
#: the pages a reader opens first (the issue's list), relative to the site's root
MAIN_PAGES = ("index.html", "getting_started.html", "reference/fmu_variables.html", "results/launch.html",
              "tutorials/fmu_in_python.html")
#: the other generated pages with wide tables
MORE_PAGES = ("results/benchmarks.html", "results/fe_cost.html", "results/production_bar.html",
              "explanation/clutch_model.html")
#: Chromium's flags that work on a CI runner as root, without network or GPU
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--virtual-time-budget=8000")

#: run in the page once it has loaded: open collapsed sections, then measure against the content column
PROBE = """<script>
window.addEventListener("load", () => {
  document.querySelectorAll("details").forEach(d => { d.open = true; });
  const column = document.querySelector("article") || document.body;
  const right = column.getBoundingClientRect().right;
  const wide = [];
  const name = el => (el.tagName + " " + (el.innerText || "").trim().slice(0, 60)).replace(/\\s+/g, " ");
  column.querySelectorAll("table").forEach(t => {
    const r = t.getBoundingClientRect();
    if (r.right > right + 1 || (t.parentElement && t.parentElement.scrollWidth > t.parentElement.clientWidth + 1))
      wide.push([name(t), Math.round(r.width), Math.round(column.clientWidth), t.parentElement.scrollWidth,
                 t.parentElement.clientWidth]);
  });
  column.querySelectorAll("pre").forEach(p => {
    if (p.scrollWidth > p.clientWidth + 1 || p.getBoundingClientRect().right > right + 1)
      wide.push([name(p), p.scrollWidth, p.clientWidth]);
  });
  const broken = [...document.images].filter(i => !i.complete || i.naturalWidth === 0).map(i => i.src);
  const page = document.documentElement.scrollWidth > window.innerWidth + 1 ?
    [document.documentElement.scrollWidth, window.innerWidth] : null;
  document.documentElement.setAttribute("data-cc-check", JSON.stringify({
    wide: wide, broken_images: broken, page_scrolls_sideways: page, images: document.images.length,
    tables: column.querySelectorAll("table").length, height: document.documentElement.scrollHeight}));
});
</script>
"""


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    pytest.importorskip("sphinx")
    from sphinx.cmd.build import build_main
    out = tmp_path_factory.mktemp("site") / "html"
    assert build_main(["-W", "--keep-going", "-q", "-b", "html", str(DOCS), str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def chromium() -> str:
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        missing_tool("chromium is not installed: apt-get install chromium (.ci/install)")
    return exe


def _run_chromium(exe: str, profile: Path, *args: str, timeout: float = 60) -> str:
    profile.mkdir(parents=True, exist_ok=True)
    done = subprocess.run([exe, *FLAGS, f"--user-data-dir={profile}", *args], capture_output=True, text=True,
                          timeout=timeout)
    return done.stdout


def _probe_copy(page: Path) -> Path:
    """A copy of ``page`` beside it (so relative links and images resolve alike) with :data:`PROBE`."""
    html = page.read_text(encoding="utf-8")
    copy = page.with_name("_cc_probe_" + page.name)
    copy.write_text(html.replace("</body>", PROBE + "</body>", 1), encoding="utf-8")
    return copy


def render(exe: str, site: Path, rel: str, tmp: Path) -> dict:
    """The probe's findings for page ``rel`` of ``site`` at :data:`WIDTH_PX`, and its full-page screenshot in
    :data:`SCREENSHOTS`."""
    copy = _probe_copy(site / rel)
    try:
        dom = _run_chromium(exe, tmp / "profile", f"--window-size={WIDTH_PX},900", "--dump-dom", copy.as_uri())
        m = re.search(r'data-cc-check="([^"]*)"', dom)
        assert m, f"{rel}: the probe did not run (Chromium printed {len(dom)} characters)"
        found = json.loads(m.group(1).replace("&quot;", '"').replace("&amp;", "&").replace("&lt;", "<")
                           .replace("&gt;", ">"))
        SCREENSHOTS.mkdir(parents=True, exist_ok=True)
        shot = SCREENSHOTS / (rel.replace("/", "_").removesuffix(".html") + ".png")
        height = max(600, min(int(found["height"]) + 20, 16000))
        _run_chromium(exe, tmp / "profile", f"--window-size={WIDTH_PX},{height}", f"--screenshot={shot}",
                      copy.as_uri())
        found["screenshot"] = shot
        return found
    finally:
        copy.unlink()


@pytest.mark.parametrize("rel", MAIN_PAGES + MORE_PAGES)
def test_main_page_fits_1280px_and_its_images_load(rel, site, chromium, tmp_path):
    found = render(chromium, site, rel, tmp_path)
    assert found["wide"] == [], f"{rel}: wider than the content column at {WIDTH_PX} px: {found['wide']}"
    assert found["broken_images"] == [], f"{rel}: images that do not load: {found['broken_images']}"
    assert found["page_scrolls_sideways"] is None, f"{rel}: the page scrolls sideways: {found}"
    assert found["screenshot"].stat().st_size > 10_000


class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.hrefs: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("id"):
            self.ids.add(a["id"])
        if tag == "a" and a.get("href"):
            self.hrefs.append(a["href"])
        if tag in ("img", "script") and a.get("src"):
            self.hrefs.append(a["src"])
        if tag == "link" and a.get("href"):
            self.hrefs.append(a["href"])


def _parse(path: Path) -> _Links:
    p = _Links()
    p.feed(path.read_text(encoding="utf-8"))
    return p


@pytest.mark.parametrize("rel", MAIN_PAGES)
def test_main_page_internal_links_resolve(rel, site):
    """Every relative link, image, script and stylesheet of the page leads to a file of the site, and every
    #anchor to an id of its target."""
    page = site / rel
    bad = []
    for href in _parse(page).hrefs:
        parts = urlsplit(href)
        if parts.scheme or parts.netloc:
            continue
        target = (page.parent / unquote(parts.path)).resolve() if parts.path else page
        if target.is_dir():
            target = target / "index.html"
        if not target.exists():
            bad.append(href)
        elif parts.fragment and target.suffix == ".html" and unquote(parts.fragment) not in _parse(target).ids:
            bad.append(href)
    assert bad == [], f"{rel}: broken internal links {bad}"


def test_no_page_names_the_checkout_or_a_dirty_tree(site):
    """No page of the built site holds the absolute path of the checkout it was built from, nor ``+dirty``."""
    leaks = []
    for path in site.rglob("*"):
        if path.suffix in (".html", ".txt", ".js", ".md") and path.is_file():
            text = path.read_text(encoding="utf-8", errors="replace")
            if str(ROOT) in text or "+dirty" in text:
                leaks.append(str(path.relative_to(site)))
    assert leaks == [], f"pages naming {ROOT} or +dirty: {leaks}"
