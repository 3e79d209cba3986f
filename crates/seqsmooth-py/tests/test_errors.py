"""Bad input from Python raises the right SeqsmoothError with the sample's index, never a
PanicException, and a filter keeps the samples before the bad one."""

from __future__ import annotations

import numpy as np
import pytest

import seqsmooth as ss
from seqsmooth import errors


def test_the_hierarchy_is_value_error():
    for name in errors.__all__:
        assert issubclass(getattr(errors, name), ValueError)
    assert issubclass(ss.InvalidTypeError, TypeError)
    assert issubclass(ss.InvalidTypeError, ss.InvalidInputError)


def test_every_error_kind_has_its_class():
    """The class of an error is chosen by the library's kind (``seqsmooth::error::ErrorKind``),
    one class per kind, each a SeqsmoothError; and a call of each kind raises its class."""
    from seqsmooth._seqsmooth import error_kinds

    kinds = error_kinds()
    assert [k for k, _ in kinds] == [
        "InvalidInput",
        "Parameter",
        "TooFewSamples",
        "NotDetermined",
        "Numerical",
        "DamagedState",
    ]
    for kind, cls in kinds:
        assert cls == kind + "Error" and issubclass(getattr(errors, cls), errors.SeqsmoothError)
    assert len({cls for _, cls in kinds}) == len(kinds)
    with pytest.raises(ss.ParameterError):
        ss.FadingMemory(degree=1, theta=2.0)
    with pytest.raises(ss.InvalidInputError):
        ss.FadingMemory(degree=1, theta=0.9).update_many(np.arange(3.0), [1.0, np.nan, 1.0])
    with pytest.raises(ss.TooFewSamplesError):
        ss.smooth(np.ones(5), 7, 2)
    _, (cls, state) = ss.FadingMemory(degree=1, theta=0.9).__reduce__()
    with pytest.raises(ss.DamagedStateError):
        cls._from_state(state[:-3])


def test_every_parameter_takes_its_kind_and_the_callers_words():
    """Each library parameter's refusal raises its kind's class (``error_kinds`` walks the
    kinds, ``parameter_kinds`` every parameter), with no class chosen by a name string."""
    from seqsmooth._seqsmooth import error_kinds, parameter_kinds

    classes = dict(error_kinds())
    params = parameter_kinds()
    assert len(params) > 50 and len({name for name, _, _ in params}) == len(params)
    for name, kind, cls in params:
        assert kind in ("Parameter", "InvalidInput"), name
        assert cls == classes[kind], name
    kinds = {name: kind for name, kind, _ in params}
    assert kinds["theta"] == "Parameter" and kinds["azimuth"] == "InvalidInput"


def test_smooth_names_scipys_arguments():
    """``smooth`` takes scipy's names, and its errors say them: a series shorter than the
    window names ``window_length``, a degree out of range ``polyorder``."""
    with pytest.raises(ss.TooFewSamplesError) as e:
        ss.smooth(np.ones(30), 31, 2)
    assert str(e.value) == "too few samples for window_length 31: 30 given, at least 31 needed"
    with pytest.raises(ss.TooFewSamplesError) as e:
        ss.smooth(np.ones(30), 31, 2, return_sigma=True, sigma=1.0)
    assert "window_length 31" in str(e.value)
    with pytest.raises(ss.ParameterError) as e:
        ss.smooth(np.ones(30), 5, 30)
    assert str(e.value).startswith("polyorder 30 is out of range")
    with pytest.raises(ss.ParameterError) as e:
        ss.smooth(np.ones(30), 2, 2)
    assert str(e.value).startswith("window_length 2 is invalid")
    # The classes' own keywords keep the library's words.
    with pytest.raises(ss.ParameterError) as e:
        ss.FixedMemory(degree=3, window=3)
    assert str(e.value).startswith("window 3 is invalid")


def test_ranges_are_the_librarys_in_pythons_words():
    """Every range a call is refused by is the library's check, in Python's keywords (scipy's
    ``delta`` for ``smooth``): no range is written in the binding."""
    radar = {"sigma_range": 10.0, "sigma_angle": 1e-3}
    cases = [
        (
            lambda: ss.smooth(np.arange(10.0), 5, 2, delta=0.0),
            "delta 0 is invalid: must be a positive finite number",
        ),
        (
            lambda: ss.SlidingFit(window=-3, **radar),
            "window -3 is invalid: must hold at least 1 sample",
        ),
        (
            lambda: ss.SlidingFit(window=0, **radar),
            "window 0 is invalid: must hold at least 1 sample",
        ),
        (
            lambda: ss.SlidingFit("polynomial", degree=2, sigma=0.3, window=2),
            "window 2 is invalid: too small for degree 2: a degree-2 fit needs a window of at "
            "least 3 rows",
        ),
        (
            lambda: ss.SlidingFit(max_iterations=1001, **radar),
            "max_iterations 1001 is invalid: must be from 1 to 1000",
        ),
        (
            lambda: ss.RadarTracker("kalman", max_iterations=0),
            "max_iterations 0 is invalid: must be from 1 to 1000",
        ),
        (
            lambda: ss.RadarTracker("kalman", azimuth="north"),
            "azimuth \"north\" is invalid: must be one of 'from-x', 'bearing'",
        ),
        (
            lambda: ss.SlidingFit(azimuth="north", **radar),
            "azimuth \"north\" is invalid: must be one of 'from-x', 'bearing'",
        ),
        (
            lambda: ss.RadarTracker("kalman", q=-1.0),
            "q -1 is invalid: must be a finite number at least 0",
        ),
        (
            lambda: ss.polynomial_samples(np.arange(40.0), np.arange(40.0), 1.0, 31),
            "degree 31 is out of range: the largest supported degree is 30",
        ),
        (
            lambda: ss.vrf("expanding", 3, n=2),
            "n 2 is invalid: too small for degree 3: the expanding-memory variance-reduction "
            "matrix needs n >= 3 (at least 4 samples)",
        ),
        (
            lambda: ss.SlidingFit(epoch=np.inf, **radar),
            "epoch inf is invalid: must be 'end', 'centre' or a finite time",
        ),
        (
            lambda: ss.luenberger_gains(61),
            "n 61 is invalid: must be from 1 to 60 coefficients",
        ),
        (
            lambda: ss.vrf("fixed", 3, window=3),
            "window 3 is invalid: a degree-3 fit needs a window of at least 4 samples",
        ),
    ]
    for call, message in cases:
        with pytest.raises(ss.ParameterError) as e:
            call()
        assert str(e.value) == message
    assert len(ss.polynomial_samples(np.arange(40.0), np.arange(40.0), 1.0, 30)[0]) == 31


@pytest.mark.parametrize("where", [0, 3, 9])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_value_is_named_with_its_index(where, bad):
    t = np.arange(10.0)
    y = np.ones(10)
    y[where] = bad
    f = ss.FadingMemory(degree=1, theta=0.9)
    with pytest.raises(ss.InvalidInputError) as e:
        f.update_many(t, y)
    assert e.value.index == where
    assert f"sample {where}" in str(e.value) and "not finite" in str(e.value)
    assert f.samples == where  # the samples before it are taken


def test_unsorted_times_name_the_sample():
    t = np.array([0.0, 1.0, 2.0, 2.0, 3.0])
    f = ss.ExpandingMemory(degree=1)
    with pytest.raises(ss.InvalidInputError) as e:
        f.update_many(t, np.zeros(5))
    assert e.value.index == 3 and "strictly increasing" in str(e.value)
    with pytest.raises(ss.InvalidInputError):
        f.update(1.5, 0.0)


def test_the_index_counts_from_the_callers_array_across_blocks():
    n = (1 << 16) + 10  # past the first block of the GIL-free loop
    t = np.arange(float(n))
    y = np.zeros(n)
    y[n - 3] = np.nan
    with pytest.raises(ss.InvalidInputError) as e:
        ss.ExpandingMemory(degree=0).update_many(t, y)
    assert e.value.index == n - 3


@pytest.mark.parametrize(
    "t,y,kind",
    [
        ([1.0, 2.0], [1.0], ss.InvalidInputError),  # mismatched lengths
        ([], [], ss.InvalidInputError),  # empty
        ([[1.0, 2.0]], [[1.0, 2.0]], ss.InvalidInputError),  # two-dimensional
        (["a", "b"], [1.0, 2.0], ss.InvalidTypeError),  # strings
        ([1.0, 2.0], np.array([1 + 2j, 2 + 0j]), ss.InvalidTypeError),  # complex
        ([1.0, 2.0], [object(), object()], ss.InvalidTypeError),
        (  # dates are times (test_inputs.py), never values
            [1.0, 2.0],
            np.array(["2026-01-01", "2026-01-02"], dtype="datetime64[ns]"),
            ss.InvalidTypeError,
        ),
    ],
)
def test_bad_arrays(t, y, kind):
    with pytest.raises(kind):
        ss.ExpandingMemory(degree=0).update_many(t, y)


@pytest.mark.parametrize(
    "make",
    [
        lambda: ss.FadingMemory(degree=1, theta=1.0),
        lambda: ss.FadingMemory(degree=1, theta=0.0),
        lambda: ss.FadingMemory(degree=1, theta=float("nan")),
        lambda: ss.FadingMemory(degree=1, theta=0.9, tau=0.0),
        lambda: ss.FadingMemory(degree=1, theta=0.9, engine="fast"),
        lambda: ss.ExpandingMemory(degree=25),
        lambda: ss.ExpandingMemory(degree=11, engine="gain"),
        lambda: ss.ExpandingMemory(degree=1, sigma=-1.0),
        lambda: ss.ExpandingMemory(degree=1, sigma=0.0),
        lambda: ss.FixedMemory(degree=3, window=3),
        lambda: ss.FixedMemory(degree=1, window=5, engine="slow"),
    ],
)
def test_bad_settings_raise_parameter_errors(make):
    with pytest.raises(ss.ParameterError):
        make()


def test_negative_degree_is_refused_by_python():
    with pytest.raises(OverflowError):
        ss.ExpandingMemory(degree=-1)


def test_sigma_needs_the_noise():
    with pytest.raises(ss.ParameterError) as e:
        ss.ExpandingMemory(degree=0).update_many([0.0, 1.0], [1.0, 2.0], return_sigma=True)
    assert "sigma" in str(e.value)


def test_ten_thousand_random_bad_calls_never_panic():
    """A seeded loop of 10⁴ calls with random bad (and some good) arguments: each returns or
    raises a SeqsmoothError (or Python's own OverflowError/TypeError for a negative or
    non-integer count); none raises pyo3's PanicException or crashes the interpreter."""
    rng = np.random.default_rng(13)
    specials = [np.nan, np.inf, -np.inf, 0.0, -0.0, 1e308, -1e308, 5e-324, 1.0, 2.0]

    def values(n):
        v = rng.standard_normal(n) * 10.0 ** rng.integers(-300, 300)
        k = rng.integers(0, max(n, 1))
        if n and rng.random() < 0.5:
            v[k] = specials[rng.integers(len(specials))]
        return v

    def times(n):
        t = np.cumsum(rng.uniform(0.0, 2.0, n)) * 10.0 ** rng.integers(-200, 200)
        if n and rng.random() < 0.3:
            t[rng.integers(n)] = specials[rng.integers(len(specials))]
        if n > 1 and rng.random() < 0.3:
            rng.shuffle(t)
        return t + (1.7e9 if rng.random() < 0.3 else 0.0)

    outcomes = {"ok": 0, "error": 0}
    for _ in range(10_000):
        n = int(rng.integers(0, 40))
        degree = int(rng.integers(-1, 27))
        theta = float(rng.choice([rng.random(), -0.5, 1.0, 1.5, np.nan]))
        tau = float(rng.choice([1.0, rng.random() * 1e3, 0.0, -1.0, np.inf]))
        engine = str(rng.choice(["exact", "gain", "adaptive", "x"]))
        window = int(rng.integers(-1, 50))
        try:
            kind = rng.integers(11)
            if kind == 0:
                f = ss.ExpandingMemory(degree=degree, engine=engine)
            elif kind == 1:
                f = ss.FadingMemory(degree=degree, theta=theta, tau=tau, engine=engine)
            elif kind == 2:
                f = ss.FixedMemory(degree=degree, window=window)
            elif kind == 3:
                out = ss.smooth(
                    values(n),
                    window,
                    degree,
                    deriv=int(rng.integers(0, 4)),
                    t=times(n) if rng.random() < 0.5 else None,
                )
                assert np.isfinite(out).all()
                outcomes["ok"] += 1
                continue
            elif kind == 6:
                k = int(rng.integers(-1, 5))
                bank = ss.FadingBank(degree=degree, theta=theta, channels=k, tau=tau)
                bank.update(values(n * max(k, 1)).reshape(n, max(k, 1)) if n else [])
                assert not np.isinf(bank.estimate()).any()
                outcomes["ok"] += 1
                continue
            elif kind == 5:
                table = ss.gains if rng.random() < 0.5 else ss.vrf
                args = {
                    "n": int(rng.integers(0, 30)) if rng.random() < 0.6 else None,
                    "theta": rng.choice([theta, "9/10", "x", 0]) if rng.random() < 0.6 else None,
                    "exact": bool(rng.random() < 0.3),
                }
                if table is ss.vrf and rng.random() < 0.4:
                    args.update(window=window, lead=float(rng.normal() * 3))
                out = table(str(rng.choice(["expanding", "fading", "fixed"])), degree % 12, **args)
                if not args["exact"]:
                    assert np.isfinite(out).all()
                outcomes["ok"] += 1
                continue
            elif kind == 4:
                m = max(degree, 0) % 4
                f = ss.KalmanFilter(
                    degree=m,
                    x0=values(m + 1),
                    P0=float(rng.choice([1.0, 1e300, 0.0, -1.0, np.nan])),
                    q=float(rng.choice([0.0, 1.0, -1.0, 1e300])),
                    theta_per_update=float(rng.choice([0.5, 1.0, 2.0]))
                    if rng.random() < 0.3
                    else None,
                )
                x, p, nis = f.update_many(times(n), values(n), float(rng.choice([1.0, 0.0, -1.0])))
                assert np.isfinite(x).all() and np.isfinite(p).all()
                outcomes["ok"] += 1
                continue
            elif kind == 8:
                tracker = ss.RadarTracker(
                    str(rng.choice(["kalman", "fading", "smooth", "window"])),
                    sigma_range=float(rng.choice([10.0, 0.0, -1.0, np.nan])),
                    sigma_angle=float(rng.choice([1e-3, 0.0, 1e300])),
                    theta_per_update=float(rng.choice([0.9, 1.5])) if rng.random() < 0.5 else None,
                    window=window if rng.random() < 0.3 else None,
                )
                r = np.abs(values(n)) if rng.random() < 0.7 else values(n)
                with np.errstate(invalid="ignore"):
                    az, el = values(n) % 7.0, values(n) % 1.6
                x, p, nis, _ = tracker.update_many(times(n), r, az, el)
                held, xs, ps, ns, _ = tracker.finish()
                assert not np.isinf(x).any() and not np.isinf(p).any()
                assert np.isfinite(xs).all() and np.isfinite(ps).all()
                outcomes["ok"] += 1
                continue
            elif kind == 9:
                # Each setting good most of the time, so that most calls reach the rows.
                def pick(good, bad):
                    return good if rng.random() < 0.85 else bad[rng.integers(len(bad))]

                radar = rng.random() < 0.5
                kw = {
                    "window": pick(max(window, 4), [window, 0, -1]),
                    "epoch": pick(
                        ["end", "centre", 1.7e9, float(rng.normal() * 1e3)][rng.integers(4)],
                        ["x", np.nan, np.inf],
                    ),
                    "degree": pick(degree % 2 + 1 if radar else degree % 4, [degree, None, -1]),
                    "max_iterations": pick(20, [3, 0, 1001]),
                }
                if radar:
                    kw["sigma_range"] = pick(10.0, [0.0, -1.0, np.nan, 1e200])
                    kw["sigma_angle"] = pick(1e-3, [0.0, 1e300, 1e-170])
                else:
                    kw["sigma"] = pick(0.3, [0.0, 1e-200, np.inf])
                fit = ss.SlidingFit("radar" if radar else "polynomial", **kw)
                if radar:
                    r = np.abs(values(n)) if rng.random() < 0.7 else values(n)
                    with np.errstate(invalid="ignore"):
                        az, el = values(n) % 7.0, values(n) % 1.6
                    x, p, info = fit.update_many(times(n), r, az, el)
                else:
                    x, p, info = fit.update_many(times(n), values(n))
                assert np.isfinite(x).all(axis=1).sum() == np.isfinite(info["chi2"]).sum()
                assert not np.isinf(x).any() and not np.isinf(p).any()
                outcomes["ok"] += 1
                continue
            elif kind == 10:
                m = max(degree, 0) % 5
                prior = rng.random() < 0.3
                f = ss.BayesFilter(
                    m,
                    t0=float(rng.choice([0.0, 1.7e9, np.nan])),
                    x0=values(m + 1) if prior else None,
                    P0=float(rng.choice([1.0, 1e300, 0.0, -1.0])) if prior else None,
                    **(
                        {"theta": float(rng.choice([0.9, 0.0, 1.5, np.nan])), "tau": 1.0}
                        if rng.random() < 0.3
                        else {}
                    ),
                )
                x, p = f.update_many(times(n), values(n), float(rng.choice([1.0, 0.0, -1.0])))
                assert not np.isinf(x).any() and not np.isinf(p).any()
                assert np.array_equal(np.isnan(x).all(axis=1), np.isnan(x).any(axis=1))
                outcomes["ok"] += 1
                continue
            else:
                f = ss.FadingMemory(degree=max(degree, 0) % 4, theta=0.9)
            out = f.update_many(times(n), values(n), return_sigma=bool(rng.random() < 0.2))
            est = out[0] if isinstance(out, tuple) else out
            assert not np.isinf(est).any()
            if kind != 2:  # expanding and fading: every row from sample m+1 on is finite
                assert np.isfinite(est[f.degree :]).all()
            if f.is_determined:
                assert np.isfinite(f.estimate().derivatives).all()
            outcomes["ok"] += 1
        except (ss.SeqsmoothError, OverflowError) as e:
            assert str(e)
            outcomes["error"] += 1
    assert outcomes["ok"] > 100 and outcomes["error"] > 1000, outcomes
