"""PEP 517 build backend of the Python module `wires`: the project's own CMake build, packed into a wheel.

`pip install ./python` (python/pyproject.toml names this file through `backend-path`) calls build_wheel(), which
configures the repository's CMake project for the interpreter running pip (-DPython3_EXECUTABLE=sys.executable),
builds the target wires_python only (the module and the six static libraries it links), installs its component
(`cmake --install --component python`) into a staging folder and writes a wheel holding the extension module and
its metadata. The version is CMakeLists.txt's project(wires VERSION ...), the number the CMake package and
wires.__version__ carry.

Settings, from pip's --config-settings KEY=VALUE or the environment:
  build-dir  / WIRES_CMAKE_BUILD_DIR   reuse this CMake build tree (configured with this project and an interpreter
                                       of the same ABI: only the module is relinked and installed; tools/test.sh
                                       passes build/). Default: a fresh temporary build, removed afterwards.
  cmake-args / WIRES_CMAKE_ARGS        extra arguments for a fresh configure (split on spaces).
  CMAKE_BUILD_PARALLEL_LEVEL           jobs of the build (default: every core).
No sdist and no editable install: the module is built from a whole checkout (pip install ./python).
"""
import base64
import hashlib
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path

PYTHON_DIR = Path(__file__).resolve().parents[1]  # python/
SOURCE_DIR = PYTHON_DIR.parent  # the repository root (CMakeLists.txt)
NAME = "wires"


def _version():
    text = (SOURCE_DIR / "CMakeLists.txt").read_text()
    match = re.search(r"project\(\s*wires\s+VERSION\s+([0-9]+(?:\.[0-9]+){0,3})", text)
    if match is None:
        raise RuntimeError(f"{SOURCE_DIR / 'CMakeLists.txt'}: no project(wires VERSION x.y.z)")
    return match.group(1)


def _project():
    """pyproject.toml's [project] table (tomllib from Python 3.11, tomli before it, else the few keys we use)."""
    text = (PYTHON_DIR / "pyproject.toml").read_text()
    try:
        import tomllib as toml
    except ImportError:
        try:
            import tomli as toml
        except ImportError:
            toml = None
    if toml is not None:
        return toml.loads(text).get("project", {})
    section = text[text.index("[project]"):]
    project = {k: v for k, v in re.findall(r'^([a-z-]+) = "([^"]*)"', section, re.M)}
    deps = re.search(r"^dependencies = \[([^\]]*)\]", section, re.M)
    project["dependencies"] = re.findall(r'"([^"]+)"', deps.group(1)) if deps else []
    return project


def _setting(config_settings, key, env):
    settings = config_settings or {}
    value = settings.get(key, settings.get("--" + key))
    if value is None:
        value = os.environ.get(env)
    return value or None


def _tag():
    if sys.implementation.name != "cpython":
        raise RuntimeError("the wires module is built for CPython only")
    python = f"cp{sys.version_info.major}{sys.version_info.minor}"
    platform = sysconfig.get_platform().replace("-", "_").replace(".", "_")
    return f"{python}-{python}-{platform}"


def _metadata():
    project = _project()
    lines = ["Metadata-Version: 2.1", f"Name: {NAME}", f"Version: {_version()}"]
    if project.get("description"):
        lines.append(f"Summary: {project['description']}")
    if project.get("requires-python"):
        lines.append(f"Requires-Python: {project['requires-python']}")
    lines += [f"Requires-Dist: {d}" for d in project.get("dependencies", [])]
    return "\n".join(lines) + "\n"


def _wheel_file():
    return f"Wheel-Version: 1.0\nGenerator: wires_build (python/build_backend)\nRoot-Is-Purelib: false\nTag: {_tag()}\n"


def _dist_info():
    return f"{NAME}-{_version()}.dist-info"


def _run(args, **kwargs):
    print("wires_build:", " ".join(shlex.quote(str(a)) for a in args), file=sys.stderr, flush=True)
    subprocess.run([str(a) for a in args], check=True, **kwargs)


def _cmake():
    cmake = shutil.which("cmake")
    if cmake is None:
        raise RuntimeError("cmake not found (Debian: apt-get install cmake; with build isolation pip installs it)")
    return cmake


def _cached(build_dir, name):
    cache = (build_dir / "CMakeCache.txt").read_text()
    match = re.search(rf"^{re.escape(name)}:[A-Z]+=(.*)$", cache, re.M)
    return match.group(1) if match else None


def _check_reused(build_dir):
    """A reused tree must be this project's, built for an interpreter with this one's extension ABI."""
    if not (build_dir / "CMakeCache.txt").exists():
        raise RuntimeError(f"build-dir {build_dir}: not a configured CMake build tree (no CMakeCache.txt)")
    home = _cached(build_dir, "CMAKE_HOME_DIRECTORY")
    if home is None or Path(home).resolve() != SOURCE_DIR.resolve():
        raise RuntimeError(f"build-dir {build_dir} was configured for {home}, not {SOURCE_DIR}")
    python = _cached(build_dir, "Python3_EXECUTABLE")
    ours = sysconfig.get_config_var("EXT_SUFFIX")
    theirs = None
    if python:
        theirs = subprocess.run([python, "-c", "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))"],
                                capture_output=True, text=True).stdout.strip()
    if theirs != ours:
        raise RuntimeError(f"build-dir {build_dir} builds the module for {python} ({theirs}), not for "
                           f"{sys.executable} ({ours}): leave build-dir unset for a fresh build")


def _build_module(build_dir, fresh, stage, config_settings):
    cmake = _cmake()
    if fresh:
        args = [cmake, "-S", SOURCE_DIR, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                f"-DPython3_EXECUTABLE={sys.executable}", "-DWIRE_BUILD_PYTHON=ON", "-DWIRE_BUILD_TESTS=OFF",
                "-DWIRE_BUILD_BENCHMARKS=OFF"]
        if shutil.which("ninja"):
            args += ["-G", "Ninja"]
        try:  # pybind11 from a package index (build isolation) brings its CMake package along
            import pybind11
            args.append(f"-Dpybind11_DIR={pybind11.get_cmake_dir()}")
        except ImportError:
            pass  # Debian's pybind11-dev: found by CMake in /usr/lib/cmake/pybind11
        extra = _setting(config_settings, "cmake-args", "WIRES_CMAKE_ARGS")
        args += shlex.split(extra) if extra else []
        _run(args)
    else:
        _check_reused(build_dir)
    build = [cmake, "--build", build_dir, "--target", "wires_python"]
    if not os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL"):
        build += ["--parallel", str(os.cpu_count() or 1)]
    _run(build)
    _run([cmake, "--install", build_dir, "--component", "python", "--prefix", stage])
    modules = sorted(Path(stage).rglob(f"{NAME}*{sysconfig.get_config_var('EXT_SUFFIX')}"))
    if len(modules) != 1:
        raise RuntimeError(f"cmake --install --component python installed {[str(m) for m in modules]}, "
                           f"expected one {NAME}{sysconfig.get_config_var('EXT_SUFFIX')}")
    return modules[0]


def _record_line(path, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return f"{path},sha256={digest},{len(data)}"


# ---- PEP 517 hooks ----

def get_requires_for_build_wheel(config_settings=None):
    return []  # [build-system] requires says it all


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    dist_info = Path(metadata_directory) / _dist_info()
    dist_info.mkdir(parents=True, exist_ok=True)
    (dist_info / "METADATA").write_text(_metadata())
    (dist_info / "WHEEL").write_text(_wheel_file())
    return dist_info.name


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    reuse = _setting(config_settings, "build-dir", "WIRES_CMAKE_BUILD_DIR")
    with tempfile.TemporaryDirectory(prefix="wires-wheel-") as work:
        work = Path(work)
        build_dir = Path(reuse).resolve() if reuse else work / "build"
        module = _build_module(build_dir, reuse is None, work / "stage", config_settings)
        files = [(module.name, module.read_bytes()),
                 (f"{_dist_info()}/METADATA", _metadata().encode()),
                 (f"{_dist_info()}/WHEEL", _wheel_file().encode())]
        record = [_record_line(path, data) for path, data in files] + [f"{_dist_info()}/RECORD,,"]
        files.append((f"{_dist_info()}/RECORD", ("\n".join(record) + "\n").encode()))
        wheel_name = f"{NAME}-{_version()}-{_tag()}.whl"
        with zipfile.ZipFile(Path(wheel_directory) / wheel_name, "w", zipfile.ZIP_DEFLATED) as wheel:
            for path, data in files:
                info = zipfile.ZipInfo(path, date_time=(1980, 1, 1, 0, 0, 0))
                info.external_attr = (0o755 if path == module.name else 0o644) << 16
                info.compress_type = zipfile.ZIP_DEFLATED
                wheel.writestr(info, data)
    return wheel_name


def build_sdist(sdist_directory, config_settings=None):
    raise RuntimeError("wires has no sdist: the module is built from a whole checkout of the repository "
                       "(pip install ./python, or pip wheel ./python for a wheel)")
