"""gains and vrf: exact against closed forms of Morrison's tables, the same numbers and
fractions as `seqsmooth gains` / `seqsmooth vrf`, and their errors."""

from __future__ import annotations

import csv
import subprocess
from fractions import Fraction

import numpy as np
import pytest

import seqsmooth as ss
from conftest import cli_path


def cli(*args: str) -> list[list[str]]:
    out = subprocess.run(
        [str(cli_path()), *args], check=True, capture_output=True, text=True
    ).stdout
    return list(csv.reader(out.splitlines()))[1:]


def test_exact_closed_forms():
    # Morrison T9-01 style: the expanding-memory gains of degree 2 at n = 10.
    assert ss.gains("expanding", 2, n=10, exact=True) == [
        Fraction(83, 143),
        Fraction(63, 286),
        Fraction(5, 286),
    ]
    for theta in (Fraction(1, 2), Fraction(9, 10), Fraction(99, 100)):
        # Table 13.1, degree 1: g = 1 − θ², h = (1 − θ)².
        g, h = 1 - theta**2, (1 - theta) ** 2
        assert ss.gains("fading", 1, theta=theta, exact=True) == [g, h]
        # The predictor form's gain Φ(1) H: (g + h, h).
        assert ss.gains("fading", 1, theta=theta, form="predictor", exact=True) == [g + h, h]
        # (13.7.1), degree 0: the VRF (1 − θ)/(1 + θ).
        assert ss.vrf("fading", 0, theta=theta, exact=True) == [[(1 - theta) / (1 + theta)]]
    for n in (0, 5, 1000):
        assert ss.vrf("expanding", 0, n=n, exact=True) == [[Fraction(1, n + 1)]]
    for window in (1, 7, 50):
        assert ss.vrf("fixed", 0, window=window, exact=True) == [[Fraction(1, window)]]


def test_theta_is_read_as_its_decimal():
    assert ss.gains("fading", 2, theta=0.9, exact=True) == ss.gains(
        "fading", 2, theta="9/10", exact=True
    )
    assert ss.gains("fading", 2, theta=0.9, exact=True)[0] == Fraction(271, 1000)


@pytest.mark.parametrize(
    "call,flags",
    [
        (
            dict(kind="expanding", degree=3, n=17),
            ["--kind", "expanding", "--degree", "3", "--n", "17"],
        ),
        (
            dict(kind="fading", degree=4, theta=0.95),
            ["--kind", "fading", "--degree", "4", "--theta", "0.95"],
        ),
        (
            dict(kind="fading", degree=2, theta="7/8"),
            ["--kind", "fading", "--degree", "2", "--theta", "7/8"],
        ),
    ],
)
def test_gains_equal_the_command(call, flags):
    kwargs = {k: v for k, v in call.items() if k not in ("kind", "degree")}
    floats = ss.gains(call["kind"], call["degree"], **kwargs)
    rows = cli("gains", *flags)
    assert np.array_equal(floats, [float(r[1]) for r in rows])
    exact = ss.gains(call["kind"], call["degree"], exact=True, **kwargs)
    assert [str(f) for f in exact] == [r[1] for r in cli("gains", *flags, "--exact")]


@pytest.mark.parametrize(
    "call,flags",
    [
        (
            dict(kind="expanding", degree=2, n=9),
            ["--kind", "expanding", "--degree", "2", "--n", "9"],
        ),
        (
            dict(kind="fading", degree=3, theta=0.9),
            ["--kind", "fading", "--degree", "3", "--theta", "0.9"],
        ),
        (
            dict(kind="fixed", degree=2, window=11, lead=-5),
            ["--kind", "fixed", "--degree", "2", "--window", "11", "--lead", "-5"],
        ),
        (
            dict(kind="fixed", degree=1, window=6, lead="1/2"),
            ["--kind", "fixed", "--degree", "1", "--window", "6", "--lead", "1/2"],
        ),
    ],
)
def test_vrf_equals_the_command(call, flags):
    kwargs = {k: v for k, v in call.items() if k not in ("kind", "degree")}
    m = call["degree"]
    floats = ss.vrf(call["kind"], m, **kwargs)
    rows = cli("vrf", *flags)
    assert floats.shape == (m + 1, m + 1)
    assert np.array_equal(floats.ravel(), [float(r[2]) for r in rows])
    exact = ss.vrf(call["kind"], m, exact=True, **kwargs)
    assert [str(f) for row in exact for f in row] == [r[2] for r in cli("vrf", *flags, "--exact")]


@pytest.mark.parametrize(
    "call",
    [
        lambda: ss.gains("fading", 2),  # no theta
        lambda: ss.gains("fading", 2, theta=1.0),
        lambda: ss.gains("fading", 2, theta="x"),
        lambda: ss.gains("fading", 2, theta=0.5, n=3),
        lambda: ss.gains("expanding", 2),  # no n
        lambda: ss.gains("expanding", 25, n=3),
        lambda: ss.gains("fixed", 2, n=3),
        lambda: ss.gains("expanding", 2, n=3, form="later"),
        lambda: ss.vrf("expanding", 3, n=2),  # n < degree
        lambda: ss.vrf("fixed", 3, window=3),
        lambda: ss.vrf("fixed", 3),
        lambda: ss.vrf("fixed", 1, window=5, form="predictor"),
        lambda: ss.vrf("fading", 1, theta=0.5, lead=1),
    ],
)
def test_bad_arguments(call):
    with pytest.raises(ss.ParameterError):
        call()
