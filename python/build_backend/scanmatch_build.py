"""An in-tree PEP 517 build backend for `pip install .`, offline and without setuptools.

pyproject.toml names it (build-backend = "scanmatch_build", backend-path = ["python/build_backend"],
requires = []), so pip's isolated build environment needs nothing from an index. build_wheel
configures and builds the extension module with CMake (Release, -DSCANMATCH_BUILD_PYTHON=ON,
tests and benchmarks off) in a reused build folder, then writes the wheel: a zip of the package
(python/scanmatch/*.py and the module) with .dist-info/METADATA, WHEEL and RECORD.

Settings (environment variables, or pip's --config-settings KEY=VALUE with the same names):
  SCANMATCH_PYTHON_BUILD_DIR  the CMake build folder (default: build-python in the source tree)
  SCANMATCH_JOBS              parallel compile jobs (default: all cores)
  SCANMATCH_CMAKE_ARGS        extra CMake configure arguments, space-separated
"""

from __future__ import annotations

import base64
import hashlib
import io
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
NAME = "scanmatch"
SUMMARY = "LiDAR registration, odometry, simulation and evaluation (C++ core, numpy API)"

__all__ = [
    "build_sdist",
    "build_wheel",
    "get_requires_for_build_sdist",
    "get_requires_for_build_wheel",
    "prepare_metadata_for_build_wheel",
]


def _version() -> str:
    """The project version, from CMakeLists.txt's project() (the one place it is kept)."""
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"project\(\s*scanmatch\s+VERSION\s+([0-9.]+)", text)
    if not match:
        raise RuntimeError("scanmatch_build: no project(scanmatch VERSION x.y.z) in CMakeLists.txt")
    return match.group(1)


def _setting(config_settings, key: str, default: str = "") -> str:
    if config_settings and key in config_settings:
        value = config_settings[key]
        return value[-1] if isinstance(value, list) else str(value)
    return os.environ.get(key, default)


def _tag() -> str:
    """cpXY-cpXY-platform: the module is built for this interpreter and platform only."""
    impl = sys.implementation.name
    prefix = {"cpython": "cp", "pypy": "pp"}.get(impl, impl)
    version = f"{sys.version_info.major}{sys.version_info.minor}"
    platform = re.sub(r"[^A-Za-z0-9]", "_", sysconfig.get_platform())
    return f"{prefix}{version}-{prefix}{version}-{platform}"


def _metadata() -> str:
    readme = (ROOT / "README.md").read_text() if (ROOT / "README.md").exists() else ""
    return (
        "Metadata-Version: 2.1\n"
        f"Name: {NAME}\n"
        f"Version: {_version()}\n"
        f"Summary: {SUMMARY}\n"
        "Requires-Python: >=3.9\n"
        "Requires-Dist: numpy\n"
        "Description-Content-Type: text/markdown\n"
        "\n" + readme
    )


def _wheel_file() -> str:
    return (
        "Wheel-Version: 1.0\n"
        "Generator: scanmatch_build (in-tree)\n"
        "Root-Is-Purelib: false\n"
        f"Tag: {_tag()}\n"
    )


def _dist_info() -> str:
    return f"{NAME}-{_version()}.dist-info"


def _run(command, **kwargs) -> None:
    print("scanmatch_build: " + " ".join(shlex.quote(str(c)) for c in command), file=sys.stderr)
    subprocess.run(command, check=True, **kwargs)


def _build_module(config_settings) -> Path:
    """Configures (once) and builds the extension module; returns its path."""
    if shutil.which("cmake") is None:
        raise RuntimeError("scanmatch_build: cmake not found (run scripts/bootstrap)")
    build_dir = Path(_setting(config_settings, "SCANMATCH_PYTHON_BUILD_DIR",
                              str(ROOT / "build-python"))).resolve()
    jobs = _setting(config_settings, "SCANMATCH_JOBS", str(os.cpu_count() or 1))
    configure = [
        "cmake", "-S", str(ROOT), "-B", str(build_dir),
        "-DCMAKE_BUILD_TYPE=Release",
        "-DSCANMATCH_BUILD_PYTHON=ON",
        "-DSCANMATCH_BUILD_TESTS=OFF",
        "-DSCANMATCH_BUILD_BENCH=OFF",
        f"-DPython3_EXECUTABLE={sys.executable}",
    ]
    cache = build_dir / "CMakeCache.txt"
    if not cache.exists():
        if shutil.which("ninja"):
            configure += ["-G", "Ninja"]
        if shutil.which("ccache"):
            configure += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"]
    configure += shlex.split(_setting(config_settings, "SCANMATCH_CMAKE_ARGS"))
    _run(configure)
    _run(["cmake", "--build", str(build_dir), "--target", "_scanmatch", "-j", jobs])
    suffix = sysconfig.get_config_var("EXT_SUFFIX") or ".so"
    module = build_dir / "python" / "package" / NAME / f"_scanmatch{suffix}"
    if not module.exists():
        found = sorted((build_dir / "python" / "package" / NAME).glob("_scanmatch*"))
        if len(found) != 1:
            raise RuntimeError(f"scanmatch_build: the built module is not in {module.parent}")
        module = found[0]
    return module


def _record_line(name: str, data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{name},sha256={digest},{len(data)}"


# PEP 517 hooks.

def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    folder = Path(metadata_directory) / _dist_info()
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "METADATA").write_text(_metadata())
    (folder / "WHEEL").write_text(_wheel_file())
    return folder.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    module = _build_module(config_settings)
    files = {}  # archive name -> bytes
    for source in sorted((ROOT / "python" / NAME).glob("*.py")):
        files[f"{NAME}/{source.name}"] = source.read_bytes()
    files[f"{NAME}/{module.name}"] = module.read_bytes()
    dist_info = _dist_info()
    files[f"{dist_info}/METADATA"] = _metadata().encode()
    files[f"{dist_info}/WHEEL"] = _wheel_file().encode()
    files[f"{dist_info}/top_level.txt"] = f"{NAME}\n".encode()
    record = [_record_line(name, data) for name, data in files.items()]
    record.append(f"{dist_info}/RECORD,,")
    files[f"{dist_info}/RECORD"] = ("\n".join(record) + "\n").encode()

    wheel_name = f"{NAME}-{_version()}-{_tag()}.whl"
    path = Path(wheel_directory) / wheel_name
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as wheel:
        for name, data in files.items():
            info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if name.endswith(module.suffix) else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            wheel.writestr(info, data)
    return wheel_name


# The source distribution holds what a wheel build needs: the library, the CLI sources (the
# top-level CMakeLists.txt defines the CLI target), the Python package and this backend.
_SDIST_PATHS = ["CMakeLists.txt", "pyproject.toml", "README.md", "scanmatch", "apps", "python"]


def build_sdist(sdist_directory, config_settings=None):
    base = f"{NAME}-{_version()}"
    path = Path(sdist_directory) / f"{base}.tar.gz"

    def skip(info: tarfile.TarInfo):
        parts = Path(info.name).parts
        if "__pycache__" in parts or info.name.endswith(".pyc"):
            return None
        info.uid = info.gid = 0
        info.uname = info.gname = ""
        return info

    with tarfile.open(path, "w:gz") as archive:
        for entry in _SDIST_PATHS:
            source = ROOT / entry
            if not source.exists():
                raise RuntimeError(f"scanmatch_build: {source} is missing, cannot build an sdist")
            archive.add(source, arcname=f"{base}/{entry}", filter=skip)
        pkg_info = _metadata().encode()
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        info.size = len(pkg_info)
        archive.addfile(info, io.BytesIO(pkg_info))
    return path.name
