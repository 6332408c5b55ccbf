"""C sources of ``fmu_src`` compiled for the machine Python runs on and cached by their hash.

The launch loop's compiled parts (:mod:`cushion_clutch.launch.plant.plant_block`) load such a library with cffi. It
is built once per source version with the FMU's compiler (:func:`.crossbuild.compile_command` with no
platform: zig, else the system C compiler) and kept under ``$XDG_CACHE_HOME/cushion_clutch`` (default
``~/.cache``; the temporary folder if that is not writable).
"""
from __future__ import annotations

import hashlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

from ..data import fmu_sources
from .crossbuild import compile_command

#: exact IEEE arithmetic as Python's: no contraction into FMAs, no builtin rewriting of ``pow``
EXACT_FLAGS = ("-ffp-contract=off", "-fno-builtin")


def _cache_dir() -> Path:
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "cushion_clutch"


def host_library(name: str, files: tuple[str, ...], headers: tuple[str, ...],
                 extra_flags: tuple[str, ...] = EXACT_FLAGS) -> Path:
    """The library ``name`` compiled from ``files`` of ``fmu_src`` (hashed with ``headers`` and the command).

    Parameters
    ----------
    name : str
        The library's file name stem (``launch_plant``); the cached file is ``{name}_{hash}.so``.
    files, headers : tuple of str
        Sources compiled and headers they include, names in ``fmu_src``.
    extra_flags : tuple of str
        Compiler flags after the FMU's (default: :data:`EXACT_FLAGS`).

    Raises
    ------
    RuntimeError
        If no compiler is found or the build fails (with the compiler's message), or no cache folder is
        writable.
    """
    src = fmu_sources()
    blob = b"".join((src / f).read_bytes() for f in (*files, *headers))
    cmd = " ".join(compile_command(None, 2, Path("."), files, Path("lib"), extra_flags=extra_flags))
    digest = hashlib.sha256(blob + cmd.encode()).hexdigest()[:16]
    suffix = ".dll" if sys.platform == "win32" else (".dylib" if sys.platform == "darwin" else ".so")
    for folder in (_cache_dir(), Path(tempfile.gettempdir()) / "cushion_clutch"):
        out = folder / f"{name}_{digest}{suffix}"
        if out.exists():
            return out
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError:
            continue
        tmp = out.with_name(f"{out.stem}.{os.getpid()}{suffix}")
        proc = subprocess.run(compile_command(None, 2, src, files, tmp, extra_flags=extra_flags),
                              capture_output=True, text=True)
        if proc.returncode != 0 or not tmp.exists():
            tmp.unlink(missing_ok=True)
            raise RuntimeError(f"building the native {name} library failed:\n{proc.stderr}")
        os.replace(tmp, out)                        # atomic: a parallel build leaves one whole library
        return out
    raise RuntimeError(f"no writable cache folder for the native {name} library")


class HostLibrary:
    """One ``fmu_src`` library for this machine, compiled on first use and loaded once with cffi.

    Parameters
    ----------
    name : str
        The library's file name stem (see :func:`host_library`).
    files, headers : tuple of str
        Sources compiled and headers they include, names in ``fmu_src``; ``headers[0]`` declares the API
        (``cffi.FFI.cdef``).
    """

    def __init__(self, name: str, files: tuple[str, ...], headers: tuple[str, ...]):
        self.name, self.files, self.headers = name, files, headers
        self._loaded = None

    def path(self) -> Path:
        """The compiled library (:func:`host_library`; raises ``RuntimeError`` as it does)."""
        return host_library(self.name, self.files, self.headers)

    def load(self):
        """``(ffi, lib)``: the API of ``headers[0]`` and the opened library (opened once per process)."""
        if self._loaded is None:
            import cffi
            ffi = cffi.FFI()
            ffi.cdef((fmu_sources() / self.headers[0]).read_text())
            self._loaded = (ffi, ffi.dlopen(str(self.path())))
        return self._loaded
