"""Shared fixtures: the `seqsmooth` command (the Rust results the binding must equal to the
last bit) and seeded series."""

from __future__ import annotations

import csv
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]


def cli_path() -> Path:
    """The `seqsmooth` binary: $SEQSMOOTH_CLI, else the workspace's release build (the test
    command builds it before pytest runs)."""
    path = Path(os.environ.get("SEQSMOOTH_CLI", ROOT / "target" / "release" / "seqsmooth"))
    if not path.exists():
        pytest.fail(f"{path} is missing: run `cargo build --release -p seqsmooth-cli` first")
    return path


def run_filter(tmp_path: Path, t: np.ndarray, y: np.ndarray, *args: str) -> dict:
    """`seqsmooth filter` on the series (times and values written with repr, which round-trips
    exactly); its columns as float arrays (an empty cell is NaN), keyed by header name."""
    source = tmp_path / "in.csv"
    with open(source, "w") as f:
        f.write("t,y\n")
        for a, b in zip(t.tolist(), y.tolist()):
            f.write(f"{a!r},{b!r}\n")
    out = subprocess.run(
        [str(cli_path()), "filter", str(source), "--no-progress", *args],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    rows = list(csv.reader(out.splitlines()))
    header, body = rows[0], rows[1:]
    return {
        name: np.array([float(r[i]) if r[i] else np.nan for r in body])
        for i, name in enumerate(header)
    }


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261204)


def irregular_series(rng: np.random.Generator, n: int, start: float = 0.0):
    """`n` samples at steps U(0.5, 1.5) of a cubic trend plus N(0, 0.3²) noise."""
    t = start + np.cumsum(rng.uniform(0.5, 1.5, n))
    x = t - t[0]
    y = 2.0 + 0.3 * x - 0.01 * x**2 + 1e-4 * x**3 + 0.3 * rng.standard_normal(n)
    return t, y


BAD_SPECIALS = [np.nan, np.inf, -np.inf, -1.0, 0.0, 1e308, 1e-308]


def bad_value(rng: np.random.Generator, specials=BAD_SPECIALS):
    """A seeded random bad argument for the 10⁴-bad-calls tests: an array of 0-3 dimensions of
    0-3 entries, one entry often a special (NaN, inf, a sign, the double range's ends), a
    special alone, or a symmetric, often indefinite 2 x 2 matrix."""
    kind = rng.integers(6)
    shape = tuple(int(s) for s in rng.integers(0, 4, size=rng.integers(0, 4)))
    a = rng.normal(size=shape)
    if a.size and kind < 3:
        a.flat[rng.integers(a.size)] = specials[rng.integers(len(specials))]
    if kind == 3:
        return float(rng.choice(specials))
    if kind == 4:
        m = rng.normal(size=(2, 2))
        return m + m.T  # symmetric, often indefinite
    return a


# The scale-out recipes' clusters, one of each for the whole run (a Spark session or a Dask
# cluster takes seconds to start): the tests of test_scaleout*.py share them.
@pytest.fixture(scope="session")
def client():
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as c,
    ):
        yield c


@pytest.fixture(scope="session")
def spark():
    import os
    import sys

    pyspark = pytest.importorskip("pyspark")
    os.environ["PYSPARK_PYTHON"] = sys.executable
    # The workers import the recipe functions from the test modules, as they would from the
    # user's own module (shipped with --py-files or on PYTHONPATH).
    here = os.path.dirname(os.path.abspath(__file__))
    os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [here, os.environ.get("PYTHONPATH")]))
    os.environ["PYSPARK_DRIVER_PYTHON"] = sys.executable
    session = (
        pyspark.sql.SparkSession.builder.master("local[2]")
        .appName("seqsmooth-test")
        .config("spark.driver.memory", "4g")
        .config("spark.sql.execution.arrow.pyspark.enabled", "true")
        .config("spark.sql.shuffle.partitions", "8")
        .config("spark.ui.enabled", "false")
        .getOrCreate()
    )
    yield session
    session.stop()
