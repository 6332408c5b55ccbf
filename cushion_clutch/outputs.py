"""Atomic outputs: single files written under a temporary name and renamed, and output sets.

An interrupted run never leaves a file that looks complete, and a killed
rerun never leaves new files mixed with old ones:

- :func:`atomic_path` yields a temporary sibling path; on success it is
  renamed over the target (``os.replace``, atomic on one file system), on
  failure it is removed.
- :class:`OutputSet` stages a command's whole set of outputs in a hidden
  folder next to its destination. On success the files of the previous set
  (listed in its manifest) are removed, the manifest first, then the new files
  are moved in, and the new manifest ``<set>.manifest.json`` (file names,
  sizes, SHA-256) is written last. A set without its manifest is incomplete.
  Creating the stage also checks that the destination can be written, before
  any long computation starts.
"""
from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import shutil
import time
from pathlib import Path
from typing import Iterator

log = logging.getLogger(__name__)

MANIFEST_SUFFIX = ".manifest.json"


def _tmp_name(path: Path) -> Path:
    return path.with_name(f".{path.stem}.tmp-{os.getpid()}{path.suffix}")


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it to ``path`` if the block succeeds.

    The temporary name keeps the suffix (writers such as matplotlib pick the
    format from it). On an exception the temporary file is removed and the
    old ``path``, if any, is left as it was.
    """
    path = Path(path)
    tmp = _tmp_name(path)
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            if tmp.is_dir():
                shutil.rmtree(tmp, ignore_errors=True)
            else:
                tmp.unlink()


def check_writable(folder: str | Path) -> Path:
    """Create ``folder`` if needed and prove a file can be written in it.

    Raises
    ------
    OSError
        With the folder's name, if it cannot be created or written (a regular
        file in the way, no permission, read-only file system).
    """
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / f".write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise OSError(f"output folder {folder} cannot be written: {exc.strerror or exc}") from exc
    return folder


def _digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def read_manifest(folder: str | Path, name: str) -> dict | None:
    """The manifest of set ``name`` in ``folder``, or None if there is no complete set."""
    path = Path(folder) / f"{name}{MANIFEST_SUFFIX}"
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


class OutputSet:
    """Context manager: stage a set of outputs, swap it into ``folder`` as one set on success.

    Parameters
    ----------
    folder : path
        Destination folder (created if needed; other files in it are left alone).
    name : str
        Name of the set (``launch``, ``simulate``, ``export``, ``tables``); the
        manifest is ``folder/<name>.manifest.json``.
    info : dict, optional
        JSON-serialisable entries for the manifest beside ``set``, ``written_utc`` and ``files`` (what
        made the set: scenario, version, command); :attr:`info` may be updated inside the block.

    Examples
    --------
    >>> with OutputSet(out, "launch") as stage:          # doctest: +SKIP
    ...     write_everything(stage)
    >>> # now out/ holds the new files and out/launch.manifest.json
    """

    def __init__(self, folder: str | Path, name: str, info: dict | None = None):
        self.folder = Path(folder)
        self.name = name
        #: what made the set (scenario, version, command, ...), written into the manifest; may be updated
        #: until the set is committed
        self.info = dict(info or {})
        self.stage = self.folder / f".{name}.staging-{os.getpid()}"
        self.files: list[Path] = []

    def __enter__(self) -> Path:
        check_writable(self.folder)
        for old in self.folder.glob(f".{self.name}.staging-*"):    # left by a killed run
            pid = old.name.rsplit("-", 1)[-1]
            if old == self.stage or not (pid.isdigit() and Path(f"/proc/{pid}").exists()):
                shutil.rmtree(old, ignore_errors=True)
        self.stage.mkdir()
        return self.stage

    def __exit__(self, exc_type, exc, tb) -> bool:
        try:
            if exc_type is None:
                self._commit()
        finally:
            shutil.rmtree(self.stage, ignore_errors=True)
        return False

    def _commit(self) -> None:
        new = sorted(p for p in self.stage.rglob("*") if p.is_file())
        entries = {str(p.relative_to(self.stage)): {"bytes": p.stat().st_size, "sha256": _digest(p)}
                   for p in new}
        manifest = self.folder / f"{self.name}{MANIFEST_SUFFIX}"
        old = read_manifest(self.folder, self.name) or {}
        manifest.unlink(missing_ok=True)                  # from here on the set reads as incomplete
        for rel in set(old.get("files", {})) | set(entries):   # old set gone before any new file lands
            target = self.folder / rel
            if target.is_file() or target.is_symlink():
                target.unlink()
        for rel in entries:
            target = self.folder / rel
            target.parent.mkdir(parents=True, exist_ok=True)
            os.replace(self.stage / rel, target)
        self.files = [self.folder / rel for rel in entries]
        with atomic_path(manifest) as tmp:
            tmp.write_text(json.dumps({"set": self.name, "written_utc": time.strftime(
                "%Y-%m-%dT%H:%M:%SZ", time.gmtime()), **self.info, "files": entries}, indent=1) + "\n",
                encoding="utf-8")
        log.info("wrote output set %s (%d files) to %s", self.name, len(entries), self.folder)
