"""Results pages: a benchmark writes its own Markdown page for the documentation (``docs/results/``), headed by
what produced it (command relative to the repository, commit, machine, load, date), so that no number on a page
is copied by hand.

A page is written from a clean tree only (no uncommitted changes to tracked files): its commit must be the
code that measured it. ``--draft`` (every page-writing benchmark takes it) writes one anyway, headed by a loud
DRAFT warning that ``tests/test_docs.py`` refuses in a committed page. No page names an absolute path of the
machine that wrote it: paths inside the checkout are written relative to it, others by their file name.

    with results_page(Path("docs/results/fe_cost.md"), "FE cost", argv) as page:
        page.markdown("| model | ... |")          # Markdown written as is
        print("a line")                           # everything printed lands in a text block too
"""
from __future__ import annotations

import contextlib
import datetime
import io
import os
import platform
import re
import subprocess
import sys
from pathlib import Path


#: the checkout (the repository root): paths under it are written relative to it
ROOT = Path(__file__).resolve().parents[2]
#: the heading of a page written from a dirty tree with ``--draft``
DRAFT_MARK = "DRAFT: written from a tree with uncommitted changes"


class DirtyTreeError(RuntimeError):
    """A results page was to be written from a tree with uncommitted changes (without ``--draft``)."""


def _git(*args: str) -> str:
    return subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True,
                          timeout=10).stdout.strip()


def tree_state(ignore: tuple[Path, ...] = ()) -> tuple[str, bool]:
    """The checkout's commit (short hash, or ``unknown`` outside git) and whether tracked files have
    uncommitted changes (``ignore``: files the page's own benchmark writes, e.g. its figure)."""
    try:
        head = _git("rev-parse", "--short", "HEAD")
        excluded = [f":(exclude){Path(p).resolve().relative_to(ROOT).as_posix()}" for p in ignore]
        dirty = bool(_git("status", "--porcelain", "--untracked-files=no", "--", ".", *excluded))
    except (OSError, subprocess.SubprocessError):
        return "unknown", False
    return head or "unknown", dirty


def add_draft_option(ap) -> None:
    """The ``--draft`` option of a page-writing benchmark (an :class:`argparse.ArgumentParser`)."""
    ap.add_argument("--draft", action="store_true",
                    help="with --out: write the page from a tree with uncommitted changes, marked as a draft")


def check_tree(draft: bool, ignore: tuple[Path, ...] = ()) -> tuple[str, bool]:
    """The commit and dirtiness (but for ``ignore``, :func:`tree_state`); raises :class:`DirtyTreeError` for a
    dirty tree unless ``draft``."""
    head, dirty = tree_state(ignore)
    if dirty and not draft:
        raise DirtyTreeError(f"the checkout has uncommitted changes (commit {head}): a results page must name the "
                             "commit that measured it; commit first, or pass --draft to write a page marked as a "
                             "draft (never to be committed)")
    return head, dirty


def relative_arg(arg: str) -> str:
    """A command-line argument as a page shows it: an absolute path inside the checkout relative to it, one
    outside by its file name (``--out=/abs/x.md`` likewise); everything else as is."""
    key, eq, value = arg.partition("=") if arg.startswith("--") and "=" in arg else ("", "", arg)
    if value.startswith(("/", "~")) or re.match(r"^[A-Za-z]:[\\/]", value):
        path = Path(value).expanduser()
        try:
            value = path.resolve().relative_to(ROOT).as_posix()
        except ValueError:
            value = path.name
    return key + eq + value


def scrub(text: str) -> str:
    """``text`` without the checkout's absolute path (written as ``.``) nor the home folder (``~``)."""
    text = text.replace(str(ROOT) + "/", "").replace(str(ROOT), ".")
    home = str(Path.home())
    return text.replace(home, "~") if len(home) > 1 else text


def _machine() -> str:
    """CPU model, cores and the 1-minute load average (figures from a loaded machine are noisy)."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return f"{cpu}, {os.cpu_count()} cores, load average {load:.1f} at the start; Python {platform.python_version()}"


def provenance(command: str, draft: bool = False, ignore: tuple[Path, ...] = ()) -> str:
    """The header block of a results page: how to regenerate it (``command``, run from the repository root)
    and where and when it was measured; a loud draft warning first when ``draft`` and the tree is dirty
    (``ignore``: the files the benchmark itself wrote for the page, which are not a change of the code)."""
    head, dirty = check_tree(draft, ignore)
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    warn = (f"```{{danger}} {DRAFT_MARK}\nThe figures below were measured by code that differs from commit "
            f"`{head}`. Do not commit this page: regenerate it from a clean tree.\n```\n\n" if dirty else "")
    return (warn + f"```{{admonition}} Generated, not edited\n"
            f"Written by `{command}` (run from the repository's root).\n\n"
            f"- commit: `{head}`{' with uncommitted changes' if dirty else ''}\n- machine: {_machine()}\n"
            f"- date: {now}\n\n"
            "Rerun the command to regenerate this page; never edit its numbers by hand.\n```\n")


class _Page:
    def __init__(self) -> None:
        self.parts: list[str] = []
        self.written: list[Path] = []
        """files the benchmark writes for the page (its figures): not a change of the measured code"""

    def markdown(self, text: str) -> None:
        """Append Markdown (a table, a heading, a paragraph) to the page."""
        self.parts.append(text.rstrip("\n") + "\n")


@contextlib.contextmanager
def results_page(out: Path | None, title: str, module: str, argv: list[str] | None, intro: str = ""):
    """Collect a benchmark's page and write it to ``out`` at the end (``out`` None: print only).

    Printed lines still reach the terminal and are also kept, in a ``text`` block after the Markdown parts.
    The page is written only when the block finishes without an exception. With ``out``, a dirty tree raises
    :class:`DirtyTreeError` before the benchmark runs (and again at the end, if the tree changed meanwhile)
    unless the arguments hold ``--draft``; the page shows the command with paths relative to the checkout and
    never the checkout's absolute path.
    """
    page = _Page()
    if out is None:
        yield page
        for part in page.parts:
            print(part)
        return
    args = list(sys.argv[1:] if argv is None else argv)
    draft = "--draft" in args
    check_tree(draft)
    command = " ".join(["python3 -m", module, *(relative_arg(a) for a in args)])
    buffer = io.StringIO()

    class _Tee(io.TextIOBase):
        def write(self, s):
            sys.__stdout__.write(s)
            return buffer.write(s)

        def flush(self):
            sys.__stdout__.flush()

    with contextlib.redirect_stdout(_Tee()):
        yield page
    text = f"# {title}\n\n{provenance(command, draft, tuple(page.written))}\n" + (intro.rstrip() + "\n\n" if intro else "")
    text += "\n".join(page.parts)
    printed = buffer.getvalue().strip()
    if printed:
        text += f"\n## Printed by the benchmark\n\n```text\n{printed}\n```\n"
    text = scrub(text)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(out.suffix + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(out)
