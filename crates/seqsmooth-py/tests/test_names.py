"""docs/names.md, the table of names, against the front ends: every command-line flag it lists
exists on the subcommand named, every Python keyword on the class or function named, every
attribute on its class, and every Rust name it quotes in the library's sources."""

from __future__ import annotations

import inspect
import re
import subprocess

import pytest

import seqsmooth as ss
from conftest import ROOT, cli_path

NAMES = (ROOT / "docs" / "names.md").read_text()
ROWS = [line for line in NAMES.splitlines() if line.startswith("| ") and "---" not in line]
TABLE = [[c.strip() for c in row.strip("|").split("|")] for row in ROWS if row[2:6] != "name"]
RUST_SOURCES = "\n".join(
    p.read_text() for p in (ROOT / "crates" / "seqsmooth" / "src").rglob("*.rs")
)


def cells(column: int) -> list[tuple[str, str]]:
    """The backticked entries of one column, with the row's name."""
    return [(row[0], c) for row in TABLE for c in re.findall(r"`([^`]+)`", row[column])]


def test_the_table_has_the_names():
    names = [row[0] for row in TABLE]
    for name in ["degree", "theta", "tau", "theta_per_update", "sigma", "std_devs"]:
        assert name in names
    assert all(len(row) == 6 for row in TABLE), "every row: name, meaning, units, Rust, CLI, Python"


@pytest.mark.parametrize("name,entry", [e for e in cells(4) if " --" in e[1]])
def test_every_flag_exists(name, entry):
    sub, flag = entry.split(" ")
    out = subprocess.run(
        [str(cli_path()), sub, "--help"], capture_output=True, text=True, check=True
    )
    assert re.search(rf"\s{re.escape(flag)}[\s,]", out.stdout), f"{name}: {entry}"


@pytest.mark.parametrize("name,entry", [e for e in cells(5) if re.fullmatch(r"\w+\(\w+=\)", e[1])])
def test_every_keyword_exists(name, entry):
    owner, keyword = re.fullmatch(r"(\w+)\((\w+)=\)", entry).groups()
    params = inspect.signature(getattr(ss, owner)).parameters
    assert keyword in params, f"{name}: {owner} has no keyword {keyword}"


@pytest.mark.parametrize("name,entry", [e for e in cells(5) if re.fullmatch(r"\w+\.\w+", e[1])])
def test_every_attribute_exists(name, entry):
    owner, attribute = entry.split(".")
    assert hasattr(getattr(ss, owner), attribute), f"{name}: {entry}"


@pytest.mark.parametrize("name,entry", cells(3))
def test_every_rust_name_exists(name, entry):
    # The last path segment of each Rust spelling (a type, variant, method or field).
    for word in re.findall(r"(?:::|^)(\w+)", entry):
        assert re.search(rf"\b{word}\b", RUST_SOURCES), f"{name}: {entry} ({word})"


def test_the_old_discount_names_are_gone():
    """``beta`` and the Kalman filters' per-update ``theta`` are refused (test_kalman.py); the
    command's ``track --beta`` is hidden and refused naming the new spelling."""
    out = subprocess.run(
        [str(cli_path()), "track", "--help"], capture_output=True, text=True, check=True
    )
    assert "--beta" not in out.stdout
    assert "--theta-per-update" in out.stdout


def test_the_linear_kalman_filters_keywords_are_in_the_table():
    """Every keyword of ``LinearKalmanFilter`` has its row (F, H, Q, R, B, x0, P0)."""
    listed = {kw for _, e in cells(5) for kw in re.findall(r"LinearKalmanFilter\((\w+)=\)", e)}
    assert set(inspect.signature(ss.LinearKalmanFilter).parameters) <= listed
