"""pip install --no-build-isolation . into a venv made with --system-site-packages (Debian's
numpy), offline. It builds the module again (minutes, less where ccache has the objects of the
tree's build): ctest python_install sets FLEXKIN_TEST_PIP=1; by hand, set it too."""
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
    env = dict(os.environ, FLEXKIN_PIP_BUILD_DIR=str(tmp_path / "build"), PIP_NO_INDEX="1")
    env.pop("PYTHONPATH", None)
    subprocess.run([python, "-m", "pip", "install", "--no-build-isolation", "--no-deps", "-q",
                    str(SOURCE_DIR)], check=True, env=env)
    out = subprocess.run([python, "-c", "import flexkin; print(flexkin.__file__); "
                          "print(flexkin.run(flexkin.parabola(links=3), [[0.1, 0]]).frames.shape)"],
                         check=True, env=env, cwd=tmp_path, capture_output=True, text=True).stdout
    assert str(venv) in out.splitlines()[0] and "(2, 4, 2)" in out
