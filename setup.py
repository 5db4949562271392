"""The build of `pip install --no-build-isolation .` (pyproject.toml): the extension
flexkin._flexkin is built by the project's CMake (target flexkin_python) for the interpreter
that runs pip, in build-pip/ (FLEXKIN_PIP_BUILD_DIR overrides), and copied into the wheel."""
import glob
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


def default_jobs():
    """The compile jobs this process may run at once: the CPUs it may use (its affinity, not the
    host's count, which a container can exceed many times over), fewer where a cgroup's CPU quota
    is lower, and at most one per 1.5 GiB of available memory (a binding object takes about 1 GiB
    to compile). At least 1."""
    jobs = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    try:
        with open("/sys/fs/cgroup/cpu.max") as f:
            quota, period = f.read().split()[:2]
        if quota != "max":
            jobs = min(jobs, -(-int(quota) // int(period)))
    except (OSError, ValueError):
        pass
    try:
        with open("/proc/meminfo") as f:
            available = next(int(line.split()[1]) for line in f if line.startswith("MemAvailable:"))
        jobs = min(jobs, available // (3 * 512 * 1024))
    except (OSError, StopIteration, ValueError):
        pass
    return max(1, jobs)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("FLEXKIN_PIP_BUILD_DIR", os.path.join(ROOT, "build-pip"))
        subprocess.run(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
                        f"-DPython3_EXECUTABLE={sys.executable}", "-DFLEXKIN_PYTHON=ON",
                        "-DFLEXKIN_BUILD_TESTS=OFF", "-DFLEXKIN_BUILD_BENCHMARKS=OFF",
                        "-DFLEXKIN_BUILD_EXAMPLES=OFF"], check=True)
        jobs = os.environ.get("FLEXKIN_PIP_JOBS", str(default_jobs()))
        subprocess.run(["cmake", "--build", build, "--target", "flexkin_python", "-j", jobs],
                       check=True)
        built = glob.glob(os.path.join(build, "python", "flexkin", "_flexkin*.so"))
        if len(built) != 1:
            raise RuntimeError(f"flexkin: expected one built extension, found {built}")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(built[0], target)


# setuptools' own files go to build-pip/ too (not build/, the CMake build, nor the sources).
os.makedirs(os.path.join(ROOT, "build-pip", "setuptools"), exist_ok=True)
setup(ext_modules=[Extension("flexkin._flexkin", sources=[])],
      cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": os.path.join("build-pip", "setuptools")},
               "egg_info": {"egg_base": os.path.join("build-pip", "setuptools")}})
