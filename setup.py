"""`pip install .` from the repository: the Python module (python/) built by the project's
own CMake, driven by setuptools (Debian's python3-setuptools; no scikit-build needed).
Needs what scripts/setup.sh installs (compiler, CMake, vcglib in third_party/meshlab,
pybind11-dev, python3-dev). On Debian, without network access for build isolation:
    python3 -m venv --system-site-packages venv
    venv/bin/pip install --no-build-isolation .
POMAR_CMAKE_ARGS adds CMake options (e.g. "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")."""
import os
import re
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def version():
    with open(os.path.join(ROOT, "codec/include/pomar/version.h")) as f:
        text = f.read()
    parts = [re.search(rf"#define POMAR_VERSION_{p} (\d+)", text).group(1)
             for p in ("MAJOR", "MINOR", "PATCH")]
    return ".".join(parts)


class CMakeBuild(build_ext):
    """Builds the target _pomar with CMake and copies it where setuptools wants it."""

    def build_extension(self, ext):
        build = os.path.join(os.path.abspath(self.build_temp), "cmake")
        subprocess.check_call(
            ["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
             "-DPOMAR_BUILD_TESTS=OFF", "-DPOMAR_BUILD_BENCH=OFF",
             "-DPOMAR_BUILD_MESHLAB_PLUGINS=OFF", "-DPOMAR_BUILD_PYTHON=ON",
             f"-DPython3_EXECUTABLE={sys.executable}"]
            + shlex.split(os.environ.get("POMAR_CMAKE_ARGS", "")))
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.check_call(["cmake", "--build", build, "--target", "_pomar", "-j", jobs])
        built = os.path.join(build, "python", "pomar", os.path.basename(self.get_ext_filename(ext.name)))
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built, target)


setup(
    version=version(),
    packages=["pomar"],
    package_dir={"pomar": "python/pomar"},
    ext_modules=[Extension("pomar._pomar", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build-pip"}},  # not build/, where a CMake build may be
)
