"""The streamlined evaluations of the tempered ladder's hot path give the values of the former
code, written out here as references: the power sums and pseudo-polynomials of the responses,
the Gaussian log-likelihood per point, the closed-form cubic roots and the dissipation
polynomial, bit for bit (NaN payloads aside); and the constraint checks make the same decisions
on batches of every size."""

from __future__ import annotations

import numpy as np
import pytest

from bayesfo.inference.likelihood import Likelihood
from bayesfo.structures import get_structure, passivity, response
from bayesfo.structures.response import HALF_PI, ROOT_RTOL
from bayesfo.studies import g_spec_data


def _identical(a, b):
    """Equal values, NaN at the same places and the same signs of zeros."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape
    np.testing.assert_array_equal(a, b)
    for x, y in ((a.real, b.real), (a.imag, b.imag)) if np.iscomplexobj(a) else ((a, b),):
        keep = ~np.isnan(x)
        np.testing.assert_array_equal(np.signbit(x[keep]), np.signbit(y[keep]))


# ---------------------------------------------------------------------- former code
def _power_sum_ref(omega, coef, exponent):
    coef, exponent = np.broadcast_arrays(np.asarray(coef, float), np.asarray(exponent, float))
    modulus = np.exp(exponent[..., None] * np.log(omega))
    phase = coef * np.exp(1j * HALF_PI * exponent)
    return np.einsum("...t,...tf->...f", phase, modulus)


def _polyval_ref(coef, lam):
    out = coef[..., -1:] + np.zeros(np.broadcast_shapes(coef.shape[:-1] + (1,), lam.shape), complex)
    for k in range(coef.shape[-1] - 2, -1, -1):
        out = out * lam + coef[..., k: k + 1]
    return out


def _cubic_roots_ref(c):
    a, b, d = c[:, 0], c[:, 1], c[:, 2]
    with np.errstate(all="ignore"):
        third = a / 3.0
        p = b - a * third
        r = (2.0 * third * third - b) * third + d
        disc = 0.25 * r * r + (p / 3.0) ** 3
        u = np.cbrt(-0.5 * r - np.copysign(np.sqrt(np.abs(disc)), r))
        t_one = np.where(u != 0, u - p / (3.0 * np.where(u != 0, u, 1.0)), 0.0)
        m = np.sqrt(np.maximum(-p / 3.0, 0.0))
        cos3 = np.clip(-0.5 * r / np.where(m > 0, m ** 3, 1.0), -1.0, 1.0)
        x1 = np.where(disc > 0, t_one, 2.0 * m * np.cos(np.arccos(cos3) / 3.0)) - third
        for _ in range(2):
            f = ((x1 + a) * x1 + b) * x1 + d
            df = (3.0 * x1 + 2.0 * a) * x1 + b
            x1 = np.where(df != 0, x1 - f / np.where(df != 0, df, 1.0), x1)
        s = a + x1
        t_fwd = b + x1 * s
        t_bwd = -d / x1
        use_bwd = np.isfinite(t_bwd) & (np.abs(b - t_bwd + x1 * s) * np.sqrt(np.abs(t_bwd))
                                        < np.abs(((x1 + a) * x1 + b) * x1 + d))
        t = np.where(use_bwd, t_bwd, t_fwd)
        dq = s * s - 4.0 * t
        sq = np.sqrt(np.abs(dq))
        big = -0.5 * (s + np.copysign(sq, s))
        small = np.where(big != 0, t / np.where(big != 0, big, 1.0), 0.0)
        x = np.stack([x1 + 0j, np.where(dq >= 0, big, -0.5 * s + 0.5j * sq),
                      np.where(dq >= 0, small, -0.5 * s - 0.5j * sq)], axis=1)
        a, b, d = a[:, None], b[:, None], d[:, None]
        df = (3.0 * x + 2.0 * a) * x + b
        x = x - np.where(df != 0, (((x + a) * x + b) * x + d) / np.where(df != 0, df, 1.0), 0.0)
        f = ((x + a) * x + b) * x + d
        df = np.abs((3.0 * x + 2.0 * a) * x + b)
        ax = np.abs(x)
        coefwise = ((ax + np.abs(a)) * ax + np.abs(b)) * ax + np.abs(d)
        norm_c = np.sqrt(a * a + b * b + d * d + 2.0)
        cond = (np.sqrt((ax * ax + 1.0) * ax * ax + 1.0)
                * np.sqrt(1.0 + np.abs(x + a) ** 2 + np.abs((x + a) * x + b) ** 2))
        err = (np.abs(f) + ROOT_RTOL * coefwise + 2.2e-16 * norm_c * cond) / df
        d01, d02, d12 = (np.abs(x[:, 0] - x[:, 1]), np.abs(x[:, 0] - x[:, 2]),
                         np.abs(x[:, 1] - x[:, 2]))
        sep = np.stack([np.minimum(d01, d02), np.minimum(d01, d12), np.minimum(d02, d12)], axis=1)
        err = np.where(np.isfinite(err) & np.isfinite(ax) & (err < 0.01 * sep), err, np.inf)
    return x, err


def _dissipation_polynomial_ref(den, num, q):
    n_sets = max(den.shape[0], num.shape[0], q.shape[0])
    coef = np.zeros((n_sets, den.shape[1] + num.shape[1] - 1))
    scale = np.zeros_like(coef)
    with np.errstate(all="ignore"):
        for k in range(num.shape[1]):
            for j in range(den.shape[1]):
                prod = num[:, k] * den[:, j]
                scale[:, k + j] += np.abs(prod)
                if k != j:
                    coef[:, k + j] += prod * np.sin((k - j) * q * HALF_PI)
    return coef, scale


def _pointwise_ref(lik, theta):
    model = lik.model(theta)
    r2 = np.abs(lik.g_scaled - model) ** 2
    if lik.noise == "known":
        out = lik._log_norm - r2 / lik._var
    else:
        s = theta[:, -1:]
        var = s * s if lik.noise == "constant" else (s * s) * lik._abs_g2
        with np.errstate(divide="ignore", invalid="ignore"):
            out = -np.log(np.pi * var) - r2 / var
    out = out + lik._unit_shift
    return np.where(np.isfinite(out), out, -np.inf)


# ---------------------------------------------------------------------- responses
@pytest.mark.parametrize("terms", [0, 1, 2, 3, 5])
def test_power_sum_is_the_einsum_of_the_former_code(terms):
    rng = np.random.default_rng(terms)
    omega = np.logspace(-3, 3, 25)
    coef = rng.uniform(-10, 10, (3000, terms)) * 10.0 ** rng.uniform(-8, 8, (3000, terms))
    expo = rng.uniform(-1, 3, (3000, terms))
    coef[:50] = 0.0
    coef[50:100] = -0.0
    _identical(response.power_sum(omega, coef, expo), _power_sum_ref(omega, coef, expo))
    # Broadcast coefficients, one set, and an extra batch dimension.
    _identical(response.power_sum(omega, coef[:1], expo), _power_sum_ref(omega, coef[:1], expo))
    _identical(response.power_sum(omega, coef[0], expo[0]), _power_sum_ref(omega, coef[0], expo[0]))
    c3, e3 = coef.reshape(30, 100, terms), expo.reshape(30, 100, terms)
    _identical(response.power_sum(omega, c3, e3), _power_sum_ref(omega, c3, e3))
    if terms:
        # A constant term (exponent 0 in every set: a spring, the 1 of a side), first, last or
        # with the sign of zero flipped, is added without its exponentials: the same values.
        for t, zero in ((0, 0.0), (terms - 1, -0.0), (terms // 2, 0.0)):
            e0 = expo.copy()
            e0[:, t] = zero
            _identical(response.power_sum(omega, coef, e0), _power_sum_ref(omega, coef, e0))
        with np.errstate(invalid="ignore", over="ignore"):
            inf = coef.copy()
            inf[100:110, 0] = np.inf
            inf[110:120, 0] = -np.inf
            inf[120:130, 0] = np.nan
            e0 = expo.copy()
            e0[:, 0] = 0.0
            got, ref = response.power_sum(omega, inf, e0), _power_sum_ref(omega, inf, e0)
            # Not finite where a coefficient is not (the former code's NaN real part is ±inf
            # here, as in the real-arithmetic sum before constants were singled out).
            np.testing.assert_array_equal(np.isfinite(got), np.isfinite(ref))
            assert not np.isfinite(got[100:130]).any()
            _identical(got[130:], ref[130:])


@pytest.mark.parametrize("degree", [0, 1, 2, 3, 4])
def test_polyval_and_commensurate_response_as_the_former_code(degree):
    rng = np.random.default_rng(degree)
    omega = np.logspace(-3, 3, 25)
    q = rng.uniform(0.0, 2.0, 2000)
    a = rng.uniform(-10, 10, (2000, degree + 1)) * 10.0 ** rng.uniform(-6, 6, (2000, degree + 1))
    b = rng.uniform(-10, 10, (2000, degree + 1))
    lam = response.lambda_powers(omega, q)
    _identical(response.polyval_ascending(a, lam), _polyval_ref(a, lam))
    _identical(response.polyval_ascending(a[:1], lam), _polyval_ref(a[:1], lam))
    with np.errstate(all="ignore"):
        ref = _polyval_ref(b, lam) / _polyval_ref(a, lam)
        _identical(response.commensurate_response(omega, a, b, q), ref)
        # One numerator for every denominator (broadcast shapes).
        ref = _polyval_ref(b[0], lam) / _polyval_ref(a, lam)
        _identical(response.commensurate_response(omega, a, b[0], q), ref)


@pytest.mark.parametrize("name", ["maxwell", "max-n3m3", "max-n2m2", "voigt"])
@pytest.mark.parametrize("noise", ["known", "constant", "proportional"])
@pytest.mark.parametrize("kind", ["compliance", "modulus"])
def test_pointwise_log_likelihood_as_the_former_code(name, noise, kind):
    lik = Likelihood(get_structure(name), g_spec_data(0, kind=kind), noise=noise)
    rng = np.random.default_rng(7)
    theta = np.column_stack([p.sample(rng, 3000) for p in lik.prior_list])
    theta[:20, 0] = 0.0  # zero coefficients: non-finite responses of some structures
    with np.errstate(all="ignore"):
        ref = _pointwise_ref(lik, theta)
        _identical(lik.pointwise(theta), ref)
        _identical(lik(theta), ref.sum(axis=1))
        _identical(lik(theta[:1]), ref[:1].sum(axis=1))


# ---------------------------------------------------------------------- constraint checks
def test_cubic_roots_as_the_former_code():
    rng = np.random.default_rng(5)
    for decades in (0, 3, 12, 200):
        c = (rng.uniform(-100, 100, (20_000, 3))
             * 10.0 ** rng.uniform(-decades, decades, (20_000, 3)))
        c[:200, 0] = 0.0
        c[200:400, 2] = 0.0
        c[400:450] = 0.0
        c[450:500, 1] = np.inf
        c[500:550, 0] = np.nan
        c[550:600] = -0.0
        x, err = response.cubic_roots(c)
        x_ref, err_ref = _cubic_roots_ref(c)
        _identical(x, x_ref)
        _identical(err, err_ref)


@pytest.mark.parametrize("n_den", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("n_num", [1, 2, 4])
def test_dissipation_polynomial_as_the_former_code(n_den, n_num):
    rng = np.random.default_rng(10 * n_den + n_num)
    den = rng.uniform(-10, 10, (1000, n_den)) * 10.0 ** rng.uniform(-5, 5, (1000, n_den))
    num = rng.uniform(-10, 10, (1000, n_num))
    num[:20] = -0.0
    den[20:25] = np.inf
    q = rng.uniform(0, 2, 1000)
    q[30:35] = np.nan
    for d, n, qq in ((den, num, q), (den, num[:1], q), (den, num, q[:1])):
        coef, scale = passivity.dissipation_polynomial(d, n, qq)
        coef_ref, scale_ref = _dissipation_polynomial_ref(d, n, qq)
        _identical(coef, coef_ref)
        _identical(scale, scale_ref)


@pytest.mark.parametrize("name", ["max-n2m1", "max-n2m2", "max-n3m1", "max-n3m3", "maxwell"])
def test_constraints_hold_on_small_batches_as_on_one_large(name):
    # Batches below and above the closed-form threshold, and single rows, decide each row as
    # one batch of all rows does (the tempered ladder checks batches of 10–500 rows).
    s = get_structure(name)
    rng = np.random.default_rng(len(name) + 1)
    theta = np.column_stack([p.prior.sample(rng, 3000) for p in s.parameters])
    theta[:500] *= rng.choice([-1.0, 1.0], (500, s.n_params))
    for kind in ("compliance", "modulus"):
        whole = s.constraints_hold(theta, kind)
        starts = np.cumsum([0] + [1, 7, 63, 64, 127, 128, 129, 150, 300] * 3)
        parts = [s.constraints_hold(theta[i:j], kind) for i, j in zip(starts[:-1], starts[1:])]
        np.testing.assert_array_equal(np.concatenate(parts), whole[:starts[-1]])
        assert whole.any() and not whole.all()


@pytest.mark.parametrize("name", ["voigt", "zener", "zener-int", "max-n1m1", "max-n2m1",
                                  "max-n3m3", "fractional_kelvin_voigt", "maxwell"])
def test_constraints_hold_as_the_separate_checks(name):
    # The former code: the inequalities, then stable() and passive() on the rows still in,
    # each computing its own polynomials; the checks that share them decide every row alike.
    s = get_structure(name)
    rng = np.random.default_rng(len(name))
    theta = np.column_stack([p.prior.sample(rng, 2000) for p in s.parameters])
    theta[:300] *= rng.choice([-1.0, 1.0], (300, s.n_params))
    theta[300:310, 0] = np.inf
    grid = np.logspace(-3, 3, 40)
    for kind in ("compliance", "modulus"):
        with np.errstate(all="ignore"):  # the infinite coefficients, in both
            ok, held = _separate_checks(s, theta, kind, grid), s.constraints_hold(theta, kind, grid)
        np.testing.assert_array_equal(held, ok)
        assert held.any() and not held.all()


def _separate_checks(s, theta, kind, grid):
    ok = np.ones(len(theta), dtype=bool)
    vals, _ = s.values(theta)
    for c in s._constraint_plan[0]:
        ok &= c.holds(vals)
    rows = np.flatnonzero(ok)
    ok[rows] = s.stable(theta[rows], kind)
    rows = np.flatnonzero(ok)
    ok[rows] = s.passive(theta[rows], kind, grid)
    return ok


def test_polynomials_of_parameter_columns_as_the_former_code():
    # The coefficients copied without the floating-point guard where each is one parameter's
    # column of its own degree, computed under it otherwise: the same arrays, with no warning
    # for coefficients that overflow (the suite turns warnings into errors).
    def former(side, vals, n):
        plan = side_plan[id(side)]
        out = np.zeros((n, plan[0] + 1))
        with np.errstate(all="ignore"):
            for degree, name, t in plan[1]:
                out[:, degree] += vals[name] if name is not None else t.coefficient(vals, n)
        return out

    for name in ("zener", "max-n2m1", "max-n3m3", "voigt-int", "fractional_zener_sl"):
        s = get_structure(name)
        if s.commensurate_order is None:
            continue
        side_plan = {id(side): plan for side, plan in s._polynomial_plans}
        rng = np.random.default_rng(3)
        theta = np.column_stack([p.prior.sample(rng, 50) for p in s.parameters])
        theta[:5] = 1e308
        theta[5:10, 0] = np.nan
        vals, _ = s.values(theta)
        for side in (s.numerator, s.denominator):
            _identical(s._polynomial(side, vals, len(theta)), former(side, vals, len(theta)))


@pytest.mark.parametrize("rows", [0, 1, 9, 255, 256, 257, 2000])
def test_prior_box_of_small_and_large_batches_as_column_by_column(rows):
    from bayesfo.inference.transform import Transform

    lik = Likelihood(get_structure("zener"), g_spec_data(0), noise="constant")
    tr = Transform(lik)
    rng = np.random.default_rng(rows)
    span = tr.hi_u - tr.lo_u
    u = tr.lo_u - 0.05 * span + rng.random((rows, span.size)) * 1.1 * span
    if rows > 3:
        u[0] = tr.lo_u
        u[1] = tr.hi_u
        u[2, 1] = np.nan
    ok = np.ones(rows, dtype=bool)
    for j in range(u.shape[1]):
        ok &= (u[:, j] >= tr.lo_u[j]) & (u[:, j] <= tr.hi_u[j])
    np.testing.assert_array_equal(tr.in_box(u), ok)
    if rows > 3:
        assert ok[:2].all() and not ok[2]


def test_power_sums_of_a_scalar_or_two_dimensional_omega_keep_their_shapes():
    # As the former einsum: a scalar ω gives one value per set, an (sets, n) ω a table.
    s = get_structure("maxwell")
    theta = np.array([1.0, 0.5, 0.3, 0.7])
    one = s.transfer(theta, 2.0)
    assert one.shape == (1,)
    np.testing.assert_allclose(one, s.transfer(theta, np.array([2.0])), rtol=1e-15)
    w = np.array([[0.5, 1.0, 2.0]])
    table = response.power_sum(w, np.ones((3, 2)), np.array([[0.0, 0.5]] * 3))
    assert table.shape == (3, 3)
    np.testing.assert_allclose(table[1], 1 + np.sqrt(1j * w[0]), rtol=1e-14)


def test_polynomial_plans_survive_pickling():
    # A structure sent to a worker process carries its cached plans; they must still match
    # its own numerator and denominator there.
    import pickle

    s = get_structure("max-n2m1")
    theta = np.array([[0.7, 0.2, 1.3, 0.4, 0.55]])
    before = s.polynomials(theta)
    again = pickle.loads(pickle.dumps(s))
    assert again._polynomial_plans[0][0] is again.numerator
    assert again._polynomial_plans[1][0] is again.denominator
    for x, y in zip(before, again.polynomials(theta), strict=True):
        np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("n,d", [(0, 3), (1, 3), (2, 4), (1000, 4), (1000, 6), (5000, 10)])
def test_unique_rows_are_numpys(n, d):
    # The ladder's distinct particles (its collapse check, the rows its mixtures are fitted
    # to, the reweighted guide draws): numpy's unique rows, in the same order, from a
    # lexicographic sort of the columns. Rows are repeated (resampling), share a column with
    # another row (a coordinate a move left alone), and hold zeros.
    from bayesfo.inference.smc import unique_rows

    rng = np.random.default_rng(n + d)
    base = rng.normal(size=(max(n // 3, 1), d))
    k = len(base) // 2
    base[k:2 * k, 0] = base[:k, 0]
    base[::5, -1] = 0.0
    x = base[rng.integers(0, len(base), size=n)] if n else np.empty((0, d))
    _identical(unique_rows(x), np.unique(x, axis=0))
    if n > 1:
        assert len(unique_rows(x)) < n  # repeated rows were there to be removed
