"""Ctrl-C and SIGTERM for long runs: cancel queued work, end running solver processes.

One mechanism for every command that runs external solvers in worker
threads (the sweep now; calibration and tolerance studies later):

- :func:`handle_signals` (a context manager, main thread) installs SIGINT
  and SIGTERM handlers. On a signal it marks the run as cancelled, kills the
  process group of every tracked child process, and raises
  :class:`~cushion_clutch.errors.RunInterrupted` in the main thread.
- :func:`popen` starts a child in its own process group (so a terminal's
  Ctrl-C reaches only us, and we end the child *and its children*) and
  tracks it while it runs; it refuses to start anything once cancelled.
- Worker code calls :func:`check` between pieces of work; queued work is
  dropped by the executor's ``shutdown(cancel_futures=True)``.

Examples
--------
>>> with handle_signals():                     # doctest: +SKIP
...     run_many_cases()                       # RunInterrupted on Ctrl-C / SIGTERM
"""
from __future__ import annotations

import contextlib
import logging
import os
import signal
import subprocess
import threading
from typing import Iterator

from .errors import RunInterrupted

log = logging.getLogger(__name__)

_cancelled = threading.Event()
_lock = threading.Lock()
_children: set[subprocess.Popen] = set()
_signum: list[int] = []
_handlers = [0]                                   # depth of active handle_signals() blocks


def cancelled() -> bool:
    """True once a SIGINT/SIGTERM arrived (or :func:`cancel` was called) in this run."""
    return _cancelled.is_set()


def check() -> None:
    """Raise :class:`RunInterrupted` if the run was cancelled (call between pieces of work)."""
    if _cancelled.is_set():
        raise RunInterrupted(_signum[0] if _signum else signal.SIGINT)


def _kill_group(proc: subprocess.Popen) -> None:
    if proc.poll() is not None:
        return
    try:
        os.killpg(proc.pid, signal.SIGKILL)       # the child leads its own group: take its children too
    except (ProcessLookupError, PermissionError):
        with contextlib.suppress(OSError):
            proc.kill()


def cancel(signum: int = signal.SIGINT) -> None:
    """Cancel the run: no new child starts, every running tracked child group is killed."""
    if not _signum:
        _signum.append(int(signum))
    _cancelled.set()
    with _lock:
        children = list(_children)
    for proc in children:
        _kill_group(proc)


@contextlib.contextmanager
def cancelling(kill: bool = True) -> Iterator[None]:
    """Cancel the run (if ``kill``) for the block, e.g. while an executor drops its queue.

    Outside :func:`handle_signals` (a library caller that got a plain
    KeyboardInterrupt) the cancelled flag is cleared afterwards, so the next
    run in the process starts fresh.
    """
    if kill:
        cancel()
    try:
        yield
    finally:
        if _handlers[0] == 0:
            _cancelled.clear()
            _signum.clear()


@contextlib.contextmanager
def popen(args, **kwargs) -> Iterator[subprocess.Popen]:
    """``subprocess.Popen`` in its own process group, killed (with its group) on cancel.

    Raises
    ------
    RunInterrupted
        If the run is already cancelled (nothing is started).
    """
    check()
    kwargs.setdefault("start_new_session", True)
    with subprocess.Popen(args, **kwargs) as proc:
        with _lock:
            _children.add(proc)
        try:
            if _cancelled.is_set():               # a signal between check() and registration
                _kill_group(proc)
            yield proc
        except BaseException:
            _kill_group(proc)
            raise
        finally:
            with _lock:
                _children.discard(proc)


@contextlib.contextmanager
def handle_signals() -> Iterator[None]:
    """Turn SIGINT/SIGTERM into :class:`RunInterrupted` after cancelling the run (main thread only).

    Outside the main thread (where Python cannot install handlers) this does
    nothing. Previous handlers are restored on exit, and the cancelled flag is
    cleared so a later run in the same process starts fresh.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):               # noqa: ARG001 - signal handler signature
        first = not _cancelled.is_set()
        cancel(signum)
        if first:
            log.info("signal %d: cancelling queued cases and ending running solver processes", signum)
            raise RunInterrupted(signum)

    old = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    _handlers[0] += 1
    try:
        yield
    finally:
        _handlers[0] -= 1
        for s, h in old.items():
            signal.signal(s, h)
        _cancelled.clear()
        _signum.clear()
