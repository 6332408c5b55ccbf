"""Native FMU binaries for other platforms: the win64 DLL run by our Windows host under Wine, and
every binary checked for its architecture and its exported FMI functions (lief)."""
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import lief
import pytest
from fmpy import read_model_description

from cushion_clutch.data import fmu_source
from cushion_clutch.fmu.descriptions import sources
from cushion_clutch.fmu.native import fmi_header_dir
from conftest import WINE
from native_builds import assert_final_matches_model, native_fmus

pytestmark = pytest.mark.fmu


def fmi_functions(version: int) -> set[str]:
    """Every function the FMI standard header of ``version`` declares."""
    text = (fmi_header_dir() / f"fmi{version}Functions.h").read_text()
    return set(re.findall(rf"FMI{version}_Export\s+\w+TYPE\s+(\w+);", text))


EXPECTED = {  # platform folder -> (format, architecture)
    "linux64": (lief.Binary.FORMATS.ELF, lief.ELF.ARCH.X86_64),
    "x86_64-linux": (lief.Binary.FORMATS.ELF, lief.ELF.ARCH.X86_64),
    "aarch64-linux": (lief.Binary.FORMATS.ELF, lief.ELF.ARCH.AARCH64),
    "win64": (lief.Binary.FORMATS.PE, lief.PE.Header.MACHINE_TYPES.AMD64),
    "x86_64-windows": (lief.Binary.FORMATS.PE, lief.PE.Header.MACHINE_TYPES.AMD64),
    "darwin64": (lief.Binary.FORMATS.MACHO, lief.MachO.Header.CPU_TYPE.X86_64),
    "x86_64-darwin": (lief.Binary.FORMATS.MACHO, lief.MachO.Header.CPU_TYPE.X86_64),
    "aarch64-darwin": (lief.Binary.FORMATS.MACHO, lief.MachO.Header.CPU_TYPE.ARM64),
}


def _arch_and_exports(binary):
    if binary.format == lief.Binary.FORMATS.ELF:
        names = {s.name for s in binary.exported_functions}
        return binary.header.machine_type, names
    if binary.format == lief.Binary.FORMATS.PE:
        return binary.header.machine, {e.name for e in binary.get_export().entries}
    linker = {"__mh_dylib_header", "___dso_handle"}      # synthesized by every Mach-O linker
    return binary.header.cpu_type, {s.name[1:] for s in binary.exported_symbols if s.name not in linker}


def test_every_binary_has_its_architecture_and_exports_exactly_the_fmi_api(tmp_path):
    seen = set()
    for version, fmu in native_fmus().items():
        with zipfile.ZipFile(fmu) as z:
            libs = [n for n in z.namelist() if n.startswith("binaries/")]
            z.extractall(tmp_path / f"fmi{version}", libs)
        for name in libs:
            platform = name.split("/")[1]
            binary = lief.parse(str(tmp_path / f"fmi{version}" / name))
            fmt, arch = EXPECTED[platform]
            assert binary.format == fmt, name
            got_arch, exports = _arch_and_exports(binary)
            assert got_arch == arch, name
            assert exports == fmi_functions(version), (name, exports ^ fmi_functions(version))
            seen.add(platform)
    assert seen == set(EXPECTED)
    assert len(fmi_functions(2)) == 44 and len(fmi_functions(3)) > 70


#: the C hosts: FMI 2.0's is the benchmarks' (fmu_src/bench), FMI 3.0's the tests' own (tests/c_hosts)
HOST_SOURCES = {2: fmu_source("fmi2_host.c"), 3: Path(__file__).parent / "c_hosts" / "fmi3_host.c"}
#: the folder of host_platform.h, which both hosts include
HOST_INCLUDE = f"-I{fmu_source('host_platform.h').parent}"


def _windows_host(tmp_path, version):
    host = tmp_path / f"fmi{version}_host.exe"
    subprocess.run([sys.executable, "-m", "ziglang", "cc", "-target", "x86_64-windows-gnu", "-std=c99", "-O2",
                    f"-I{fmi_header_dir()}", HOST_INCLUDE, str(HOST_SOURCES[version]), "-o", str(host)],
                   check=True, capture_output=True)
    return host


def _final_outputs(stdout):
    return [float(v) for v in stdout.splitlines()[0].split()[1:]]


def test_win64_binary_runs_under_wine_with_windows_resource_uris(tmp_path, wine_env):
    host = _windows_host(tmp_path, 2)
    fmu = native_fmus()[2]
    guid = read_model_description(str(fmu)).guid
    plain = tmp_path / "plain"
    spaced = tmp_path / "r\u00e9s dir"                      # space and non-ASCII: percent-encoded in the URI
    for folder in (plain, spaced):
        zipfile.ZipFile(fmu).extractall(folder)
    dll = plain / "binaries" / "win64" / "CushionClutch.dll"
    for folder in (plain, spaced):
        uri = "file:///Z:" + (folder / "resources").as_uri()[len("file://"):]   # file:///Z:/tmp/...
        res = subprocess.run([str(WINE), str(host), "Z:" + str(dll).replace("/", "\\"), uri, guid, "3000", "0.01"],
                             env=wine_env, capture_output=True, text=True, timeout=120)
        assert res.returncode == 0, (uri, res.stdout, res.stderr[-2000:])
        assert_final_matches_model(_final_outputs(res.stdout), 3000, 0.01, uri)
    assert "%C3%A9s%20dir" in (spaced / "resources").as_uri()


def test_fmi3_windows_binary_runs_under_wine(tmp_path, wine_env):
    host = _windows_host(tmp_path, 3)
    fmu = native_fmus()[3]
    unzip = tmp_path / "fmu3"
    zipfile.ZipFile(fmu).extractall(unzip)
    token = read_model_description(str(fmu)).guid
    win = lambda p: "Z:" + str(p).replace("/", "\\")  # noqa: E731
    res = subprocess.run([str(WINE), str(host), win(unzip / "binaries/x86_64-windows/CushionClutch.dll"),
                          win(unzip / "resources") + "\\", token, "3000", "0.01"],
                         env=wine_env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, (res.stdout, res.stderr[-2000:])
    assert_final_matches_model(_final_outputs(res.stdout), 3000, 0.01)


def test_fmi3_c_host_under_address_sanitizer_matches_the_model(tmp_path):
    """Our FMI 3.0 C host on Linux, host and FMU library both built with ASan + UBSan."""
    fmu = native_fmus()[3]
    unzip = tmp_path / "fmu3"
    zipfile.ZipFile(fmu).extractall(unzip)
    flags = ["-fsanitize=address,undefined", "-fno-omit-frame-pointer", "-g", "-O1"]
    cc, srcs = shutil.which("gcc"), unzip / "sources"
    lib = tmp_path / "CushionClutch.so"
    subprocess.run([cc, "-std=c99", "-fPIC", "-shared", *flags, f"-I{srcs}",
                    *(str(srcs / f) for f in sources(3)), "-o", str(lib), "-lm"], check=True)
    host = tmp_path / "fmi3_host"
    subprocess.run([cc, "-std=c99", "-D_POSIX_C_SOURCE=199309L", *flags, f"-I{fmi_header_dir()}",
                    HOST_INCLUDE, str(HOST_SOURCES[3]), "-o", str(host), "-ldl"], check=True)
    res = subprocess.run([str(host), str(lib), str(unzip / "resources") + "/", read_model_description(str(fmu)).guid,
                          "3000", "0.01"], capture_output=True, text=True,
                         env={"ASAN_OPTIONS": "detect_leaks=1", "UBSAN_OPTIONS": "halt_on_error=1",
                              "PATH": "/usr/bin:/bin"})
    assert res.returncode == 0, res.stderr[-3000:]
    assert "runtime error" not in res.stderr
    assert_final_matches_model(_final_outputs(res.stdout), 3000, 0.01)
