"""The README's, docs/python.md's and docs/paml.md's Python examples run as printed."""

from __future__ import annotations

import re

import pytest

from conftest import ROOT


@pytest.mark.parametrize("page", ["README.md", "docs/python.md", "docs/paml.md"])
def test_python_blocks_run(page):
    text = (ROOT / page).read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, flags=re.S)
    assert blocks, f"{page} has no Python example"
    for block in blocks:
        exec(compile(block, page, "exec"), {"__name__": "readme"})
