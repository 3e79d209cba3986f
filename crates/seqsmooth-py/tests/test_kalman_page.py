"""docs/kalman.md runs as printed, as docs/guide.md does (test_guide.py): its Python and shell
blocks in the page's order in one scratch directory, `seqsmooth` the command under test; every
picture it shows is made by a command it prints and equal to it byte for byte (re-made with
`SEQSMOOTH_GUIDE_PICTURES=write`)."""

from __future__ import annotations

import re

from test_guide import check_pictures_shown, run_page

from conftest import ROOT

PAGE = ROOT / "docs" / "kalman.md"
PICTURE = re.compile(r"!\[[^\]]*\]\(images/(kalman-[\w-]+\.(?:svg|png))\)")


def test_blocks_run(tmp_path, monkeypatch):
    made = run_page(PAGE, tmp_path, monkeypatch)
    assert len(made) >= 2, "the page's shell blocks make fewer than two pictures"


def test_pictures_have_their_commands():
    check_pictures_shown(PAGE, PICTURE)


def test_the_table_names_what_exists():
    """Every seqsmooth class the table's last column names is in the package."""
    import seqsmooth as ss

    table = [line for line in PAGE.read_text().splitlines() if line.startswith("| `")]
    assert len(table) >= 10
    for line in table:
        last = line.rstrip("|").split("|")[-1]
        for name in re.findall(r"`([A-Z]\w+)\(", last):
            assert hasattr(ss, name), f"docs/kalman.md names {name}, which seqsmooth lacks"
