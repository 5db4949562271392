"""Every ```python example of docs/python.md runs (from the source directory)."""
import re

import pytest

from conftest import SOURCE_DIR

DOC = (SOURCE_DIR / "docs" / "python.md").read_text()
EXAMPLES = re.findall(r"```python\n(.*?)```", DOC, flags=re.S)


def test_the_page_has_examples():
    assert len(EXAMPLES) >= 4


@pytest.mark.parametrize("index", range(len(EXAMPLES)))
def test_example_runs(index, monkeypatch, capsys):
    monkeypatch.chdir(SOURCE_DIR)
    exec(compile(EXAMPLES[index], f"docs/python.md example {index + 1}", "exec"), {})
