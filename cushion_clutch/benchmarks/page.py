"""Results pages: a benchmark writes its own Markdown page for the documentation (``docs/results/``), headed by
what produced it (command, commit, machine, load, date), so that no number on a page is copied by hand.

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
import subprocess
import sys
from pathlib import Path


def _commit() -> str:
    """The checkout's commit (short hash, ``+dirty`` with uncommitted changes), or ``unknown``."""
    root = Path(__file__).resolve().parents[2]
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return (head + ("+dirty" if dirty else "")) if head else "unknown"


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


def provenance(command: str) -> str:
    """The header block of a results page: how to regenerate it and where and when it was measured."""
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    return (f"```{{admonition}} Generated, not edited\n"
            f"Written by `{command}`.\n\n"
            f"- commit: `{_commit()}`\n- machine: {_machine()}\n- date: {now}\n\n"
            "Rerun the command to regenerate this page; never edit its numbers by hand.\n```\n")


class _Page:
    def __init__(self) -> None:
        self.parts: list[str] = []

    def markdown(self, text: str) -> None:
        """Append Markdown (a table, a heading, a paragraph) to the page."""
        self.parts.append(text.rstrip("\n") + "\n")


@contextlib.contextmanager
def results_page(out: Path | None, title: str, module: str, argv: list[str] | None, intro: str = ""):
    """Collect a benchmark's page and write it to ``out`` at the end (``out`` None: print only).

    Printed lines still reach the terminal and are also kept, in a ``text`` block after the Markdown parts.
    The page is written only when the block finishes without an exception.
    """
    page = _Page()
    if out is None:
        yield page
        for part in page.parts:
            print(part)
        return
    args = list(sys.argv[1:] if argv is None else argv)
    command = " ".join(["python3 -m", module, *args])
    buffer = io.StringIO()

    class _Tee(io.TextIOBase):
        def write(self, s):
            sys.__stdout__.write(s)
            return buffer.write(s)

        def flush(self):
            sys.__stdout__.flush()

    with contextlib.redirect_stdout(_Tee()):
        yield page
    text = f"# {title}\n\n{provenance(command)}\n" + (intro.rstrip() + "\n\n" if intro else "")
    text += "\n".join(page.parts)
    printed = buffer.getvalue().strip()
    if printed:
        text += f"\n## Printed by the benchmark\n\n```text\n{printed}\n```\n"
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(out.suffix + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(out)
