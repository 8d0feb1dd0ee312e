# SPDX-License-Identifier: MIT
"""Build and install the verdant Python package with pip, offline:

    python3 -m venv --system-site-packages venv && venv/bin/pip install ./python
    /usr/bin/python3 -m pip install --break-system-packages ./python    # Debian's own Python

setuptools drives the project's CMake build (the library and the extension verdant._verdant,
for the Python running pip) and copies the module into the wheel beside the pure-Python files.
The source tree is the folder above this one (or VERDANT_SOURCE_DIR). Needs Debian's cmake, gcc,
python3-dev, python3-numpy, python3-setuptools and the library's packages (scripts/deps.sh).
"""
import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

# pip builds a wheel through setup.py bdist_wheel: setuptools >= 70.1 has it, older ones need the
# wheel package. Without either, setuptools says only "invalid command 'bdist_wheel'".
try:
    from setuptools.command.bdist_wheel import bdist_wheel as _bdist_wheel  # noqa: F401
except ImportError:
    try:
        from wheel.bdist_wheel import bdist_wheel as _bdist_wheel  # noqa: F401
    except ImportError:
        _bdist_wheel = None
NO_WHEEL_HINT = (
    f"verdant: {sys.executable} cannot build a wheel: its setuptools has no bdist_wheel command "
    "and the 'wheel' package is not installed. Install it into that Python "
    f"({sys.executable} -m pip install wheel, or Debian's python3-wheel), or use Debian's Python: "
    "python3 -m venv --system-site-packages venv && venv/bin/pip install ./python")
if _bdist_wheel is None and "bdist_wheel" in sys.argv[1:]:
    sys.exit(NO_WHEEL_HINT)

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.environ.get("VERDANT_SOURCE_DIR") or os.path.dirname(HERE)


def version():
    with open(os.path.join(ROOT, "include", "verdant", "core.h")) as f:
        return re.search(r'#define VD_VERSION_STRING "([^"]+)"', f.read()).group(1)


class CMakeBuild(build_ext):
    """Builds the extension with the project's CMake (target verdant_python)."""

    def build_extension(self, ext):
        build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
        jobs = str(os.cpu_count() or 2)
        subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                               f"-DPython3_EXECUTABLE={sys.executable}"])
        subprocess.check_call(["cmake", "--build", build, "--target", "verdant_python", "-j", jobs])
        built = glob.glob(os.path.join(build, "python", "verdant", "_verdant*.so"))
        if len(built) != 1:
            raise RuntimeError(f"expected one built module in {build}/python/verdant, got {built}")
        dest = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        shutil.copyfile(built[0], dest)


setup(
    name="verdant",
    version=version(),
    description="Virtual plants: L-systems to labelled plants, physics, point clouds and images",
    license="MIT",
    packages=["verdant"],
    package_data={"verdant": ["*.pyi", "py.typed"]},
    package_dir={"verdant": os.path.join(HERE, "verdant")} if HERE != os.getcwd() else {},
    ext_modules=[Extension("verdant._verdant", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    python_requires=">=3.9",
    install_requires=["numpy"],
    zip_safe=False,
)
