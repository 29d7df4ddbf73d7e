"""Build of the Python package idcol for pip and `python3 -m build`.

The extension idcol._idcol is built by the project's CMake (the target
idcol_python alone, tests, harness and baselines off) for the interpreter
running this script, then copied where setuptools packs it; the pure-Python
part (core/python/idcol: __init__.py, the type stubs, py.typed) is packed as
is. The version is the one of CMakeLists.txt's project(idcol VERSION ...).

Why not scikit-build-core: Debian (the project's platform) does not package
it, and an offline `pip install --no-build-isolation` must work from Debian's
packages alone (cmake, g++, python3-dev, pybind11-dev, libeigen3-dev,
python3-setuptools, python3-wheel, python3-numpy).

Environment: IDCOL_CMAKE (default cmake), IDCOL_BUILD_JOBS (default 2),
IDCOL_CMAKE_ARGS (extra -D flags, space-separated).
"""
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt")) as f:
        m = re.search(r"project\(\s*idcol\s+VERSION\s+([0-9][0-9.]*)", f.read())
    if not m:
        raise RuntimeError("CMakeLists.txt: no project(idcol VERSION ...) found")
    return m.group(1)


class CMakeBuild(build_ext):
    """Builds each extension by configuring the project and building its
    Python target; the module lands in <build>/python/idcol/."""

    def build_extension(self, ext):
        cmake = os.environ.get("IDCOL_CMAKE", "cmake")
        build_dir = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        configure = [
            cmake, "-S", ROOT, "-B", build_dir,
            "-DCMAKE_BUILD_TYPE=Release",
            "-DIDCOL_BUILD_PYTHON=ON",
            "-DIDCOL_BUILD_TESTS=OFF",
            "-DIDCOL_BUILD_BENCHMARKS=OFF",
            "-DIDCOL_BUILD_HARNESS=OFF",
            "-DIDCOL_BUILD_BASELINES=OFF",
            "-DPython_EXECUTABLE=" + sys.executable,
        ] + shlex.split(os.environ.get("IDCOL_CMAKE_ARGS", ""))
        try:
            subprocess.check_call(configure)
        except FileNotFoundError:
            raise RuntimeError("idcol: '%s' not found; the build needs CMake (Debian: cmake)" % cmake)
        subprocess.check_call([cmake, "--build", build_dir, "--target", "idcol_python",
                               "-j", os.environ.get("IDCOL_BUILD_JOBS", "2")])
        built = glob.glob(os.path.join(build_dir, "python", "idcol", "_idcol*" + os.path.splitext(
            self.get_ext_filename("x"))[1]))
        if len(built) != 1:
            raise RuntimeError("idcol: CMake did not build the extension (looked for %s/python/idcol/_idcol*; "
                               "is pybind11-dev installed? see CMake's warning above)" % build_dir)
        dest = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        shutil.copyfile(built[0], dest)


setup(
    version=project_version(),
    packages=["idcol"],
    package_dir={"idcol": "core/python/idcol"},
    package_data={"idcol": ["py.typed", "*.pyi"]},
    ext_modules=[Extension("idcol._idcol", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # Keep setuptools' scratch apart from the developer's CMake build/.
    options={"build": {"build_base": "build-pip"}},
    zip_safe=False,
)
