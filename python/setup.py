"""Builds the extension vitri._vitri with CMake (the repository around this folder) for setuptools.

The version is the library's (project(vitri VERSION ...) in the top CMakeLists.txt). Environment:
VITRI_BUILD_JOBS (default 2) parallel jobs, VITRI_CMAKE_ARGS extra arguments for the configuration,
VITRI_BUILD_DIR an existing build tree configured with -DVITRI_BUILD_PYTHON=ON to build the module in
(no configuration step: a developer's build reused).
"""
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def library_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(vitri VERSION ([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        given = os.environ.get("VITRI_BUILD_DIR")
        build = Path(given).resolve() if given else Path(self.build_temp).resolve() / "cmake"
        configure = ["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                     "-DVITRI_BUILD_PYTHON=ON", "-DVITRI_BUILD_TESTS=OFF", "-DVITRI_BUILD_BENCH=OFF",
                     "-DVITRI_BUILD_APPS=OFF", "-DVITRI_INSTALL=OFF", f"-DPython_EXECUTABLE={sys.executable}"]
        configure += shlex.split(os.environ.get("VITRI_CMAKE_ARGS", ""))
        if not given:
            subprocess.check_call(configure)
        jobs = os.environ.get("VITRI_BUILD_JOBS", "2")
        subprocess.check_call(["cmake", "--build", str(build), "--target", "_vitri", "-j", jobs])
        built = next((build / "python" / "vitri").glob("_vitri*.so"))
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(
    version=library_version(),
    ext_modules=[Extension("vitri._vitri", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
