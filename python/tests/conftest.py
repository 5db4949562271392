"""Shared fixtures of the flexkin Python tests (ctest `python` sets the environment)."""
import os
import pathlib
import shutil

import pytest

SOURCE_DIR = pathlib.Path(
    os.environ.get("FLEXKIN_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
EXAMPLES = SOURCE_DIR / "examples"


@pytest.fixture(scope="session")
def cli():
    """The flexkin command line built with the module (FLEXKIN_CLI), else one on the PATH."""
    path = os.environ.get("FLEXKIN_CLI") or shutil.which("flexkin")
    if not path or not os.path.exists(path):
        pytest.skip("the flexkin command line is not built (FLEXKIN_CLI)")
    return path
