"""docs/guide.md runs as printed: its Python and shell blocks, in the page's order, in one
scratch directory (a block may read the files an earlier one wrote), the shell blocks with
`seqsmooth` the command under test; and every picture it shows is made by a command it
prints and equal to it byte for byte: after a change to `seqsmooth plot`, re-make them with
`SEQSMOOTH_GUIDE_PICTURES=write` (the test then writes the pictures it made into docs/images)."""

from __future__ import annotations

import os
import re
import shutil
import subprocess

from conftest import ROOT, cli_path

PAGE = ROOT / "docs" / "guide.md"
BLOCK = re.compile(r"```(py|python|sh)\n(.*?)```", flags=re.S)
PICTURE = re.compile(r"!\[[^\]]*\]\(images/(guide-[\w-]+\.(?:svg|png))\)")
MAX_PICTURE_BYTES = 300_000


def blocks(text: str):
    """(language, first line number, code) of each runnable block, in the page's order."""
    for m in BLOCK.finditer(text):
        yield m.group(1), text.count("\n", 0, m.start()) + 2, m.group(2)


def run_page(page, tmp_path, monkeypatch):
    """Runs `page`'s blocks in order in a scratch directory (the Python blocks in one
    namespace: a block may use an earlier one's names) and returns the pictures they made."""
    text = page.read_text()
    found = list(blocks(text))
    assert any(lang == "sh" for lang, _, _ in found), f"{page.name} has no shell example"
    assert any(lang != "sh" for lang, _, _ in found), f"{page.name} has no Python example"
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    (bin_dir / "seqsmooth").symlink_to(cli_path())
    work = tmp_path / "work"
    (work / "docs" / "images").mkdir(parents=True)
    env = dict(os.environ, PATH=f"{bin_dir}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.chdir(work)
    scope = {"__name__": page.stem}
    where = f"docs/{page.name}"
    for lang, line, code in found:
        if lang == "sh":
            run = subprocess.run(
                ["bash", "-e", "-o", "pipefail", "-c", code],
                cwd=work,
                env=env,
                capture_output=True,
                text=True,
            )
            assert run.returncode == 0, f"{where} line {line}: {run.stderr}"
        else:
            exec(compile(code, f"{where}:{line}", "exec"), scope)
    made = sorted((work / "docs" / "images").iterdir())
    assert made, f"no shell block of {where} makes a picture"
    for picture in made:
        size = picture.stat().st_size
        assert 0 < size < MAX_PICTURE_BYTES, f"{picture.name}: {size} bytes"
        stored = ROOT / "docs" / "images" / picture.name
        if os.environ.get("SEQSMOOTH_GUIDE_PICTURES") == "write":
            shutil.copyfile(picture, stored)
        assert stored.exists() and stored.read_bytes() == picture.read_bytes(), (
            f"docs/images/{picture.name} is not what its command in {where} makes: "
            "re-make it with SEQSMOOTH_GUIDE_PICTURES=write"
        )
    return made


def test_blocks_run(tmp_path, monkeypatch):
    run_page(PAGE, tmp_path, monkeypatch)


def check_pictures_shown(page, picture):
    """Every picture `page` shows (the names `picture` matches, two at least) is made by one
    of its shell blocks and stored, under the size bound."""
    text = page.read_text()
    shown = picture.findall(text)
    assert len(shown) >= 2, f"{page.name} shows fewer than two pictures"
    commands = "\n".join(code for lang, _, code in blocks(text) if lang == "sh")
    for name in shown:
        assert f"docs/images/{name}" in commands, f"no command in {page.name} makes {name}"
        stored = ROOT / "docs" / "images" / name
        assert stored.exists(), f"docs/images/{name} is missing"
        assert stored.stat().st_size < MAX_PICTURE_BYTES, f"{name} is too large"


def test_pictures_have_their_commands():
    check_pictures_shown(PAGE, PICTURE)
