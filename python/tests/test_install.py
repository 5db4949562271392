"""The installed form: cmake --install of the python component, imported from the prefix."""
import os
import pathlib
import subprocess
import sys

import pytest


def test_installed_module_imports_and_runs(tmp_path):
    build = os.environ.get("FLEXKIN_BUILD_DIR")
    install_dir = os.environ.get("FLEXKIN_PYTHON_INSTALL_DIR")
    if not build or not install_dir:
        pytest.skip("run by ctest (FLEXKIN_BUILD_DIR, FLEXKIN_PYTHON_INSTALL_DIR)")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix), "--component", "python"],
                   check=True, stdout=subprocess.DEVNULL)
    site = prefix / install_dir
    assert (site / "flexkin" / "__init__.py").exists()
    env = dict(os.environ, PYTHONPATH=str(site))
    code = ("import flexkin, numpy as np; p = flexkin.parabola(links=4); "
            "r = flexkin.run(p, [[0.1, 0.1]]); print(flexkin.__file__, r.frames.shape)")
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, check=True,
                         capture_output=True, text=True).stdout
    assert pathlib.Path(out.split()[0]).is_relative_to(site) and "(2, 5, 2)" in out


def test_the_default_install_dir_is_where_debians_python_looks():
    """make install (prefix /usr/local) puts the package in a folder on the interpreter's own
    sys.path, with no PYTHONPATH: Debian's python3 reads /usr/local/lib/python3.X/dist-packages."""
    install_dir = os.environ.get("FLEXKIN_PYTHON_INSTALL_DIR")
    if not install_dir:
        pytest.skip("run by ctest (FLEXKIN_PYTHON_INSTALL_DIR)")
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    path = subprocess.run([sys.executable, "-c", "import sys; print('\\n'.join(sys.path))"],
                          env=env, check=True, capture_output=True, text=True).stdout.split()
    assert str(pathlib.Path("/usr/local") / install_dir) in path, path
