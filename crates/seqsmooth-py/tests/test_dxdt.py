"""The user's continuous dynamics as a Python callable, ``dxdt(x, t)``, integrated by the
library with its variational equations for Φ (DOP853, 1e-10 relative, 1e-12 absolute):
ExtendedKalmanFilter(dxdt=) on a linear dxdt = A x against ContinuousKalmanFilter (e^{A dt}
and Van Loan's Q, exact) within the integrator's tolerance; a pendulum's state and Φ against
scipy's solve_ivp at tight tolerance; UnscentedKalmanFilter(dxdt=) against the same model as
f(x, t0, t1) = e^{A dt} x; and a bad dxdt refused naming it, the time and the sample."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

import seqsmooth as ss

# A damped oscillator with a slowly decaying forcing state: not nilpotent, so e^{A dt} is no
# finite series.
A = np.array([[0.0, 1.0, 0.0], [-2.0, -0.3, 1.0], [0.0, 0.0, -0.5]])
QC = np.diag([0.0, 0.05, 0.2])
H = np.array([[1.0, 0.0, 0.0]])
X0 = np.array([1.0, 0.0, 0.5])
P0 = np.eye(3)


def rel(a, b):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return np.max(np.abs(a - b)) / max(np.max(np.abs(b)), 1e-300)


def data(rng, count=40):
    t = np.cumsum(rng.uniform(0.1, 1.5, size=count))
    z = np.cos(1.4 * t) * np.exp(-0.1 * t) + rng.normal(0, 0.1, size=count)
    return t, z


@pytest.mark.parametrize("jacobian", [False, True])
def test_linear_dxdt_equals_the_exact_continuous_model(jacobian):
    """dxdt = A x with Q(t0, t1) = Van Loan's Q: the extended filter's states and covariances
    equal ContinuousKalmanFilter's (e^{A dt} exact) within 1e-8 relative (the integrator's
    1e-10 per step over 40 irregular steps; the differenced ∂F/∂X adds O(ε^(2/3)))."""
    model = ss.ContinuousModel(A, QC)
    rng = np.random.default_rng(5)
    t, z = data(rng)
    exact = ss.ContinuousKalmanFilter(model, H, 0.01, X0, P0).update_many(t, z)
    kw = {"dxdt_jacobian": lambda x, t: A} if jacobian else {}
    ekf = ss.ExtendedKalmanFilter(
        X0,
        P0,
        h=lambda x, t: H @ x,
        Q=lambda t0, t1: model.discretise(abs(t1 - t0))[1],
        dxdt=lambda x, t: A @ x,
        **kw,
    )
    got = ekf.update_many(t, z, 0.01)
    assert rel(got[0], exact[0]) < 1e-8, rel(got[0], exact[0])
    assert rel(got[1], exact[1]) < 1e-8, rel(got[1], exact[1])
    # The RTS smoother on the integrated model against the exact one.
    s_ekf = ss.ExtendedKalmanFilter(
        X0,
        P0,
        h=lambda x, t: H @ x,
        Q=lambda t0, t1: model.discretise(abs(t1 - t0))[1],
        dxdt=lambda x, t: A @ x,
    ).smooth(t, z, 0.01)
    s_exact = ss.ContinuousKalmanFilter(model, H, 0.01, X0, P0).smooth(t, z)
    assert rel(s_ekf[0], s_exact[0]) < 1e-8 and rel(s_ekf[1], s_exact[1]) < 1e-8


def pendulum(x, t):
    """θ'' = −(g/L) sin θ − c θ' + a cos(ω t): time-varying and nonlinear."""
    return np.array([x[1], -9.81 * np.sin(x[0]) - 0.2 * x[1] + 0.5 * np.cos(1.3 * t)])


def pendulum_jacobian(x, t):
    return np.array([[0.0, 1.0], [-9.81 * np.cos(x[0]), -0.2]])


def variational(t, y):
    x, phi = y[:2], y[2:].reshape(2, 2)
    return np.concatenate([pendulum(x, t), (pendulum_jacobian(x, t) @ phi).ravel()])


@pytest.mark.parametrize("t0,t1", [(0.0, 0.7), (0.3, 2.9), (2.0, 1.1)])
def test_pendulum_state_and_transition_against_solve_ivp(t0, t1):
    """A predict of the pendulum from t0 to t1 (either way): the state and Φ (from the
    covariance Φ P0 Φᵀ with P0 = I and from a unit-vector probe) against scipy's solve_ivp
    (DOP853, rtol 1e-13, atol 1e-15) of the state and its variational equations: within 1e-8
    relative (the library's tolerance 1e-10 per component, the Jacobian differenced)."""
    x0 = np.array([1.2, -0.4])
    ref = solve_ivp(
        variational,
        (t0, t1),
        np.concatenate([x0, np.eye(2).ravel()]),
        method="DOP853",
        rtol=1e-13,
        atol=1e-15,
    )
    x_ref, phi_ref = ref.y[:2, -1], ref.y[2:, -1].reshape(2, 2)
    ekf = ss.ExtendedKalmanFilter(x0, np.eye(2), h=lambda x, t: x[:1], dxdt=pendulum, t0=t0)
    ekf.predict(t1)
    assert rel(ekf.state, x_ref) < 1e-8, rel(ekf.state, x_ref)
    assert rel(ekf.covariance, phi_ref @ phi_ref.T) < 1e-8
    # With the analytic Jacobian the same, and the UKF carries the mean through the same ODE.
    ekf = ss.ExtendedKalmanFilter(
        x0,
        np.eye(2),
        h=lambda x, t: x[:1],
        dxdt=pendulum,
        dxdt_jacobian=pendulum_jacobian,
        t0=t0,
    )
    ekf.predict(t1)
    assert rel(ekf.state, x_ref) < 1e-8 and rel(ekf.covariance, phi_ref @ phi_ref.T) < 1e-8


def test_ukf_dxdt_equals_the_matrix_exponential():
    """UnscentedKalmanFilter(dxdt=A x) equals UnscentedKalmanFilter(f=e^{A dt} x) (every
    sigma point integrated) within 1e-8 relative."""
    rng = np.random.default_rng(6)
    t, z = data(rng, 25)
    Q = np.diag([1e-3, 1e-2, 1e-2])
    by_ode = ss.UnscentedKalmanFilter(
        x0=X0, P0=P0, dxdt=lambda x, t: A @ x, h=lambda x, t: H @ x, Q=Q
    ).update_many(t, z, 0.01)
    by_expm = ss.UnscentedKalmanFilter(
        x0=X0, P0=P0, f=lambda x, t0, t1: expm(A * (t1 - t0)) @ x, h=lambda x, t: H @ x, Q=Q
    ).update_many(t, z, 0.01)
    assert rel(by_ode[0], by_expm[0]) < 1e-8 and rel(by_ode[1], by_expm[1]) < 1e-8


def test_f_or_dxdt_exactly_one():
    h = lambda x, t: x[:1]  # noqa: E731
    f = lambda x, t0, t1: x  # noqa: E731
    d = lambda x, t: 0 * x  # noqa: E731
    for kw in ({}, {"f": f, "dxdt": d}, {"dxdt": d, "F_jacobian": lambda x, a, b: np.eye(2)}):
        with pytest.raises(ss.ParameterError, match="f .* or dxdt"):
            ss.ExtendedKalmanFilter([0.0, 1.0], 1.0, h=h, **kw)
    with pytest.raises(ss.ParameterError, match="h is required"):
        ss.ExtendedKalmanFilter([0.0, 1.0], 1.0, dxdt=d)
    with pytest.raises(ss.InvalidTypeError, match="dxdt must be callable"):
        ss.ExtendedKalmanFilter([0.0, 1.0], 1.0, h=h, dxdt=3.0)


BAD = {
    "raises": (lambda good: (_ for _ in ()).throw(RuntimeError("boom")), "raised RuntimeError"),
    "shape": (lambda good: np.append(good, 1.0), "returned shape"),
    "nan": (lambda good: good * np.nan, "returned NaN"),
    "inf": (lambda good: good + np.inf, "returned inf"),
    "text": (lambda good: "x", "not an array of numbers"),
}


@pytest.mark.parametrize("which", ["dxdt", "dxdt_jacobian"])
@pytest.mark.parametrize("how", list(BAD))
@pytest.mark.parametrize("kind", ["ekf", "ukf"])
def test_bad_dxdt_is_named_and_leaves_the_filter(which, how, kind):
    """A dxdt (or its Jacobian) that raises or returns a wrong shape, NaN or infinity past a
    time (between two measurements): a ParameterError naming it and the time, the filter as
    it was; in update_many the sample's index (the samples before it taken); a raised
    exception as the cause."""
    if kind == "ukf" and which == "dxdt_jacobian":
        pytest.skip("the unscented filter takes no Jacobian")
    spoil, words = BAD[how]
    after = {"t": np.inf}

    def maybe(fn):
        def call(x, t):
            good = np.asarray(fn(x, t), float)
            return spoil(good) if t > after["t"] else good

        return call

    good = {"dxdt": lambda x, t: A @ x, "dxdt_jacobian": lambda x, t: A}
    kw = {k: (maybe(v) if k == which else v) for k, v in good.items()}
    rng = np.random.default_rng(7)
    t, z = data(rng, 6)

    def make():
        if kind == "ekf":
            return ss.ExtendedKalmanFilter(X0, P0, h=lambda x, t: H @ x, **kw)
        return ss.UnscentedKalmanFilter(x0=X0, P0=P0, h=lambda x, t: H @ x, dxdt=kw["dxdt"])

    flt = make()
    flt.update(t[0], z[0], 0.01)
    before = (flt.state.copy(), flt.covariance.copy(), flt.time)
    after["t"] = (t[0] + t[1]) / 2
    with pytest.raises(ss.ParameterError) as e:
        flt.update(t[1], z[1], 0.01)
    message = str(e.value)
    assert message.startswith(f"{which} at t = "), message
    assert words in message, message
    if how == "raises":
        assert isinstance(e.value.__cause__, RuntimeError)
    assert np.array_equal(flt.state, before[0]) and np.array_equal(flt.covariance, before[1])
    assert flt.time == before[2]
    after["t"] = (t[2] + t[3]) / 2
    flt = make()
    with pytest.raises(ss.ParameterError) as e:
        flt.update_many(t, z, 0.01)
    assert e.value.index == 3 and str(e.value).startswith(f"sample 3 of the batch: {which} ")
    assert flt.time == t[2]


def test_ten_thousand_seeded_bad_calls_never_panic():
    """10⁴ seeded calls of the new entry points with misbehaving callables (dxdt, its
    Jacobian, h: each bad way) and junk arguments (fit_model's arrays, epochs, iterations):
    every refusal a SeqsmoothError, a refused update leaving the filter as it was, every
    accepted one finite."""
    rng = np.random.default_rng(20261207)
    ways = list(BAD) + ["ok"] * 3
    plan = {"which": None, "how": "ok"}
    specials = [np.nan, np.inf, -np.inf, 0.0, -1.0, 1e308]

    def chaos(name, fn):
        def call(x, t):
            good = np.asarray(fn(x, t), float)
            if plan["which"] == name and plan["how"] != "ok" and rng.random() < 0.3:
                return BAD[plan["how"]][0](good)
            return good

        return call

    A2 = np.array([[0.0, 1.0], [-1.0, -0.1]])
    kw = {
        "dxdt": chaos("dxdt", lambda x, t: A2 @ x),
        "dxdt_jacobian": chaos("dxdt_jacobian", lambda x, t: A2),
        "h": chaos("h", lambda x, t: x[:1]),
    }
    ekf = ss.ExtendedKalmanFilter([1.0, 0.0], 1.0, Q=1e-3, **kw)
    refused = accepted = 0
    for k in range(10_000):
        plan["which"] = ["dxdt", "dxdt_jacobian", "h"][rng.integers(3)]
        plan["how"] = ways[rng.integers(len(ways))]
        if k % 2:
            n = int(rng.integers(0, 6))
            t = np.sort(rng.uniform(0, 3, size=n))
            z = rng.normal(size=n)
            if n and rng.random() < 0.3:
                z[rng.integers(n)] = specials[rng.integers(len(specials))]
            epoch = ["end", "centre", "middle", float(rng.normal()), np.nan][rng.integers(5)]
            try:
                fit = ss.fit_model(
                    rng.normal(size=int(rng.integers(1, 4))),
                    t,
                    z,
                    [1.0, -1.0, np.inf, 0.5][rng.integers(4)],
                    epoch=epoch,
                    max_iterations=int(rng.integers(0, 4)),
                    **kw,
                )
                assert np.all(np.isfinite(fit["state"]))
            except ss.SeqsmoothError:
                refused += 1
            continue
        before = (ekf.state.copy(), ekf.covariance.copy(), ekf.time)
        try:
            ekf.update(ekf.time + rng.uniform(0.05, 0.5), rng.normal(), 0.01)
        except ss.SeqsmoothError:
            refused += 1
            assert np.array_equal(ekf.state, before[0]) and ekf.time == before[2]
            assert np.array_equal(ekf.covariance, before[1])
            continue
        accepted += 1
        assert np.all(np.isfinite(ekf.state)) and np.all(np.isfinite(ekf.covariance))
    assert refused > 2_000 and accepted > 500, (refused, accepted)
