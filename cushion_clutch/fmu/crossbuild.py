"""Compile the native FMU's binaries for every platform on this machine with zig (``ziglang`` on PyPI).

Each FMI version has its platform folders (FMI 2.0: ``linux64``, ``win64``,
``darwin64``; FMI 3.0: ``x86_64-linux``, ``aarch64-linux``, ``x86_64-windows``,
``x86_64-darwin``, ``aarch64-darwin``). ``zig cc`` cross-compiles them all (its
cache makes later builds fast); without ziglang, gcc builds the host platform only.
Only the FMI API is exported: ``-fvisibility=hidden`` plus the FMI headers'
export macros (``__declspec(dllexport)`` on Windows).
(``python -m cushion_clutch.fmu.native`` warms zig's cache: the CI install step.)
"""
from __future__ import annotations

import importlib.util
import logging
import shutil
import subprocess
import sys
from pathlib import Path

log = logging.getLogger(__name__)

#: platform folder -> (zig target, library suffix), per FMI version
TARGETS = {
    2: {"linux64": ("x86_64-linux-gnu.2.17", ".so"), "win64": ("x86_64-windows-gnu", ".dll"),
        "darwin64": ("x86_64-macos.11.0", ".dylib")},
    3: {"x86_64-linux": ("x86_64-linux-gnu.2.17", ".so"), "aarch64-linux": ("aarch64-linux-gnu.2.17", ".so"),
        "x86_64-windows": ("x86_64-windows-gnu", ".dll"), "x86_64-darwin": ("x86_64-macos.11.0", ".dylib"),
        "aarch64-darwin": ("aarch64-macos.11.0", ".dylib")},
}
#: the platform folder of this (Linux x86_64) machine, per FMI version
HOST = {2: "linux64", 3: "x86_64-linux"}
CFLAGS = ("-std=c99", "-O2", "-shared", "-fvisibility=hidden", "-Wall")


def zig_available() -> bool:
    """Whether ``python -m ziglang`` can be used."""
    return importlib.util.find_spec("ziglang") is not None


def compile_command(platform: str | None, fmi_version: int, src: Path, files: tuple[str, ...], out: Path,
                    linux_libs: tuple[str, ...] = (), extra_flags: tuple[str, ...] = ()) -> list[str]:
    """The zig (or, for the host without ziglang, gcc) command building one platform's library.

    ``platform`` None: a library for the machine this Python runs on (not an FMU platform folder): zig's
    Linux x86_64 FMU target on such a machine (its libc is in zig's cache), zig's native target elsewhere.
    ``extra_flags`` follow the common flags (e.g. ``-ffp-contract=off``).
    """
    if platform is None:
        linux_x86 = sys.platform.startswith("linux") and _machine() == "x86_64"
        target = TARGETS[2][HOST[2]][0] if linux_x86 else None
        host = True
    else:
        target, _ = TARGETS[fmi_version][platform]
        host = platform == HOST[fmi_version]
    native = target is None
    srcs = [str(src / f) for f in files]
    libs = ["-lm", *linux_libs] if native or "linux" in target else []
    pic = ["-fPIC"] if native or "windows" not in target else []
    if zig_available():
        return [sys.executable, "-m", "ziglang", "cc", *([] if native else ["-target", target]), *CFLAGS, *pic,
                *extra_flags, f"-I{src}", *srcs, "-o", str(out), *libs]
    if not host:
        raise RuntimeError(f"cross-compiling for {platform} needs ziglang (pip install ziglang)")
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        raise RuntimeError("no C compiler: pip install ziglang, or install gcc")
    return [cc, *CFLAGS, *pic, *extra_flags, f"-I{src}", *srcs, "-o", str(out), *libs]


def _machine() -> str:
    import platform
    return platform.machine()


def build_binaries(src: Path, files: tuple[str, ...], fmi_version: int, out_dir: Path,
                   platforms: tuple[str, ...] | None = None, linux_libs: tuple[str, ...] = (),
                   name: str = "CushionClutch") -> dict[str, Path]:
    """Compile ``files`` (in ``src``, with the headers) for ``platforms`` (default: all, or the host
    without ziglang) in parallel, linking ``linux_libs`` too on Linux; return platform -> library path.
    ``name``: the library's name, the FMU's model identifier."""
    if platforms is None:
        platforms = tuple(TARGETS[fmi_version]) if zig_available() else (HOST[fmi_version],)
        if not zig_available():
            log.warning("ziglang is not installed: building %s only (pip install ziglang for all platforms)",
                        HOST[fmi_version])
    jobs = {}
    for platform in platforms:
        _, suffix = TARGETS[fmi_version][platform]
        out = out_dir / platform / f"{name}{suffix}"
        out.parent.mkdir(parents=True, exist_ok=True)
        cmd = compile_command(platform, fmi_version, src, files, out, linux_libs)
        jobs[platform] = (cmd, out, subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                                     text=True))
    failed = []
    for platform, (cmd, out, proc) in jobs.items():
        _, err = proc.communicate()
        if proc.returncode != 0 or not out.exists():
            failed.append(f"{platform}: {' '.join(cmd)}\n{err}")
    if failed:
        raise RuntimeError("compiling the native FMU failed:\n" + "\n".join(failed))
    return {p: out for p, (_, out, _) in jobs.items()}

