"""C sources of ``fmu_src`` (its role folders) compiled for the machine Python runs on and cached by their hash.

The launch loop's compiled parts (:mod:`cushion_clutch.launch.plant.plant_block`) load such a library with cffi. It
is built once per source version with the FMU's compiler (:func:`.crossbuild.compile_command` with no
platform: zig, else the system C compiler) and kept under ``$XDG_CACHE_HOME/cushion_clutch`` (default
``~/.cache``; the temporary folder if that is not writable).
"""
from __future__ import annotations

import hashlib
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from ..data import fmu_source, fmu_sources
from .crossbuild import compile_command
from .variable_table import COVER_HEADER, cover_header

#: the role folders of ``fmu_src`` a host library compiles against (each on the include path)
LIBRARY_ROLES = ("core", "hosts")
#: the headers a host library's build generates (name -> text): the cover's parameter enum
GENERATED = {COVER_HEADER: cover_header}
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
        Sources compiled and headers they include, file names in ``fmu_src``'s role folders
        (:func:`cushion_clutch.data.fmu_source`); the folders of :data:`LIBRARY_ROLES` and the headers the
        build generates (:data:`GENERATED`) are on the include path, and every header there is hashed too.
    extra_flags : tuple of str
        Compiler flags after the FMU's (default: :data:`EXACT_FLAGS`).

    Raises
    ------
    RuntimeError
        If no compiler is found or the build fails (with the compiler's message), or no cache folder is
        writable.
    """
    src = fmu_sources()
    rel = tuple(fmu_source(f).relative_to(src).as_posix() for f in files)
    folders = [src / role for role in LIBRARY_ROLES]
    every_header = sorted(h for folder in folders for h in folder.glob("*.h"))   # a changed header rebuilds too
    generated = {name: make() for name, make in GENERATED.items()}
    blob = b"".join(p.read_bytes() for p in (*(fmu_source(f) for f in (*files, *headers)), *every_header))
    blob += "".join(generated.values()).encode()
    includes = tuple(f"-I{folder}" for folder in folders)
    cmd = " ".join(compile_command(None, 2, Path("."), rel, Path("lib"),
                                   extra_flags=(*(f"-I{role}" for role in LIBRARY_ROLES), "-Igenerated",
                                                *extra_flags)))
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
        with tempfile.TemporaryDirectory(prefix="cushion_generated_") as gen:
            for gen_name, text in generated.items():
                (Path(gen) / gen_name).write_text(text)
            proc = subprocess.run(compile_command(None, 2, src, rel, tmp, extra_flags=(*includes, f"-I{gen}",
                                                                                       *extra_flags)),
                                  capture_output=True, text=True)
        if proc.returncode != 0 or not tmp.exists():
            tmp.unlink(missing_ok=True)
            raise RuntimeError(f"building the native {name} library failed:\n{proc.stderr}")
        os.replace(tmp, out)                        # atomic: a parallel build leaves one whole library
        return out
    raise RuntimeError(f"no writable cache folder for the native {name} library")


def declarations(header: str, seen: set | None = None) -> str:
    """The plain C declarations of ``header`` (a file name in ``fmu_src``'s role folders) for ``cffi.FFI.cdef``:
    its quoted includes of other such headers inlined (each once), every other preprocessor line (the include
    guards, system includes) dropped."""
    seen = set() if seen is None else seen
    seen.add(header)
    out = []
    for line in fmu_source(header).read_text().splitlines():
        included = re.match(r'\s*#\s*include\s+"([^"]+)"', line)
        if included:
            if included.group(1) not in seen:
                out.append(declarations(included.group(1), seen))
        elif not line.lstrip().startswith("#"):
            out.append(line)
    return "\n".join(out)


class HostLibrary:
    """One ``fmu_src`` library for this machine, compiled on first use and loaded once with cffi.

    Parameters
    ----------
    name : str
        The library's file name stem (see :func:`host_library`).
    files, headers : tuple of str
        Sources compiled and headers they include, file names in ``fmu_src``'s role folders; ``headers[0]``
        declares the API (``cffi.FFI.cdef`` of :func:`declarations`).
    extra_flags : tuple of str
        Compiler flags after the FMU's (default: :data:`EXACT_FLAGS`).
    """

    def __init__(self, name: str, files: tuple[str, ...], headers: tuple[str, ...],
                 extra_flags: tuple[str, ...] = EXACT_FLAGS):
        self.name, self.files, self.headers, self.extra_flags = name, files, headers, extra_flags
        self._loaded = None

    def path(self) -> Path:
        """The compiled library (:func:`host_library`; raises ``RuntimeError`` as it does)."""
        return host_library(self.name, self.files, self.headers, self.extra_flags)

    def load(self):
        """``(ffi, lib)``: the API of ``headers[0]`` and the opened library (opened once per process)."""
        if self._loaded is None:
            import cffi
            ffi = cffi.FFI()
            ffi.cdef(declarations(self.headers[0]))
            self._loaded = (ffi, ffi.dlopen(str(self.path())))
        return self._loaded
