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


@pytest.fixture
def fake_tqdm(monkeypatch):
    """A stand-in tqdm module; returns the list of what the bars were told: ("total", n),
    ("update", n), ("close",)."""
    import sys
    import types
    updates = []

    class FakeBar:
        def __init__(self, total, unit):
            updates.append(("total", total))

        def update(self, n):
            updates.append(("update", n))

        def close(self):
            updates.append(("close",))

    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeBar))
    return updates


def updated(updates):
    """The sum of a fake tqdm bar's updates."""
    return sum(n for kind, *n in updates if kind == "update" for n in n)
