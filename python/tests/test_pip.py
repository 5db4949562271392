"""pip install --no-build-isolation . into a venv made with --system-site-packages (Debian's
numpy), offline. It builds the module again in build-pip/ (minutes; seconds where ccache has the
objects of the tree's build): ctest python_install sets FLEXKIN_TEST_PIP=1; by hand, set it too."""
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR


@pytest.mark.skipif(os.environ.get("FLEXKIN_TEST_PIP") != "1",
                    reason="builds the module again (minutes); ctest python_install sets FLEXKIN_TEST_PIP=1")
def test_pip_install_into_a_venv(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)],
                   check=True)
    python = str(venv / "bin" / "python")
    # The build goes to the tree's build-pip/ (setup.py's default), beside build/: at the same depth
    # ccache finds the objects of the tree's build there (CMakeLists.txt, CCACHE_BASEDIR).
    env = dict(os.environ, PIP_NO_INDEX="1")
    env.pop("FLEXKIN_PIP_BUILD_DIR", None)
    env.pop("PYTHONPATH", None)
    build = subprocess.run([python, "-m", "pip", "install", "--no-build-isolation", "--no-deps",
                            "-v", str(SOURCE_DIR)], env=env, capture_output=True, text=True)
    # On failure the build's last lines come first in the report (a CI log keeps its head and tail).
    tail = "\n".join((build.stdout + build.stderr).splitlines()[-60:])
    assert build.returncode == 0, f"pip install exited with {build.returncode}; its last lines:\n{tail}"
    out = subprocess.run([python, "-c", "import flexkin; print(flexkin.__file__); "
                          "print(flexkin.run(flexkin.parabola(links=3), [[0.1, 0]]).frames.shape)"],
                         check=True, env=env, cwd=tmp_path, capture_output=True, text=True).stdout
    assert str(venv) in out.splitlines()[0] and "(2, 4, 2)" in out
