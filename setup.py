"""The compiled part of `pip install .`: runs the project's CMake for the _extwrench target
(pyproject.toml says why; docs/python.md). Everything else is in pyproject.toml."""

import os
import pathlib
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(extwrench VERSION ([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = pathlib.Path(self.build_temp).resolve() / "cmake"
        subprocess.check_call([
            "cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
            "-DEXTWRENCH_BUILD_PYTHON=ON", "-DEXTWRENCH_BUILD_TESTS=OFF",
            "-DEXTWRENCH_BUILD_CLI=OFF", "-DEXTWRENCH_BUILD_EXAMPLES=OFF",
            "-DPython3_EXECUTABLE=" + sys.executable])
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        subprocess.check_call(["cmake", "--build", str(build), "--target", "_extwrench",
                               "-j", jobs])
        built = next((build / "python" / "extwrench").glob("_extwrench*.so"))
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(version=project_version(),
      ext_modules=[Extension("extwrench._extwrench", sources=[])],
      cmdclass={"build_ext": CMakeBuild})
