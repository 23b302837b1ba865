"""The shortcuts of the constraint checks make the decisions of the eigenvalue route.

Matignon's test of cubics takes closed-form roots (:func:`bayesfo.structures.response.cubic_roots`) and
leaves to the companion-matrix eigenvalues only the rows whose decision the roots' error bound
cannot settle; the exact dissipation check settles most rows by a certificate
(``_isolated_negatives_dominated``) or closed-form critical points of cubic p′. Each test below
turns the shortcuts off (every row through the eigenvalues, as before they existed) and asks
for the same decision on every row, on prior draws and on sets built at the decision
boundaries: roots at |arg λ| = qπ/2 (1 ± δ), near-zero leading and constant coefficients,
multiple roots, dissipation polynomials that touch zero within and beyond the rounding
tolerance. Measured before they were added: 0 disagreements in 1.1e7 stability and 1.4e7
dissipation decisions of this kind and 1.4e7 ``constraints_hold`` decisions (every library
structure, and the rows of tempered ladders on G_spec)."""

from __future__ import annotations

import numpy as np
import pytest

from bayesfo.structures import get_structure, passivity, response


def _eigen_only(monkeypatch):
    """Every row through the companion-matrix eigenvalues."""

    def unsure_cubic(a, q):
        n = a.shape[0]
        return np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)

    def unsure_critical(p, s, deriv, rtol):
        n = p.shape[0]
        return np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)

    monkeypatch.setattr(response, "_cubic_matignon", unsure_cubic)
    monkeypatch.setattr(passivity, "_cubic_critical_check", unsure_critical)
    monkeypatch.setattr(passivity, "_isolated_negatives_dominated",
                        lambda p: np.zeros(p.shape[0], dtype=bool))


def _from_roots(r):
    """Ascending real coefficients of Π(λ − r_i) for rows of three roots (closed under
    conjugation)."""
    s1 = r.sum(axis=1)
    s2 = r[:, 0] * r[:, 1] + r[:, 0] * r[:, 2] + r[:, 1] * r[:, 2]
    return np.stack([-r.prod(axis=1), s2, -s1, np.ones(len(r))], axis=1).real


def _cubic_cases(rng, n):
    q = rng.uniform(0.0, 1.0, n)
    cases = [(rng.uniform(-100, 100, (n, 4)), q),
             (rng.uniform(-1, 1, (n, 4)) * 10.0 ** rng.uniform(-8, 8, (n, 4)), q)]
    a = rng.uniform(-100, 100, (n, 4))
    a[:, 3] *= 10.0 ** rng.uniform(-20, -6, n)
    cases.append((a, q))
    a = rng.uniform(-100, 100, (n, 4))
    a[:, 0] *= 10.0 ** rng.uniform(-20, -6, n)
    a[: n // 4, 0] = 0.0  # integrators
    cases.append((a, q))
    for delta in (0.0, 1e-15, 1e-12, 1e-9, 1e-6):
        ang = q * np.pi / 2 * (1 + rng.choice([-1, 1], n) * delta)
        pair = 10.0 ** rng.uniform(-2, 2, n) * np.exp(1j * ang)
        c = _from_roots(np.stack([pair, pair.conj(), rng.uniform(-10, 10, n) + 0j], axis=1))
        cases.append((c * rng.uniform(-10, 10, (n, 1)), q))
    r = rng.uniform(0, 3, n)
    cases.append((_from_roots(np.stack([r, r * (1 + 1e-9 * rng.normal(size=n)),
                                        -r[::-1]], axis=1) + 0j), q))
    cases.append((_from_roots(np.stack([-r, -r, -r], axis=1) + 0j), q))
    cases.append((rng.uniform(-100, 100, (n, 4)), 10.0 ** rng.uniform(-18, -6, n)))
    cases.append((rng.uniform(-100, 100, (n, 4)), rng.uniform(1.0, 2.5, n)))
    return cases


def test_cubic_root_bound_covers_the_eigenvalues():
    # Coefficients over 6 and over 24 decades: the bound holds for both; it is finite (the
    # closed form decides) for almost every row of the first, and for 71 % of the second (the
    # others go to the eigenvalues).
    rng = np.random.default_rng(3)
    for decades, finite_share in ((3, 0.999), (12, 0.6)):
        c = (rng.uniform(-100, 100, (20_000, 3))
             * 10.0 ** rng.uniform(-decades, decades, (20_000, 3)))
        x, err = response.cubic_roots(c)
        comp = np.zeros((len(c), 3, 3))
        comp[:, 0, :] = -c
        comp[:, 1, 0] = comp[:, 2, 1] = 1.0
        eig = np.linalg.eigvals(comp)
        dist = np.abs(x[:, :, None] - eig[:, None, :]).min(axis=2)
        bounded = np.all(np.isfinite(err), axis=1)
        assert bounded.mean() > finite_share
        assert np.all(dist[bounded] <= 2 * err[bounded])


def test_matignon_cubic_shortcut_makes_the_eigenvalue_decisions(monkeypatch):
    rng = np.random.default_rng(11)
    cases = _cubic_cases(rng, 5000)
    fast = [(response.matignon_stable(a, q, allow_integrator=True), response.matignon_stable(a, q))
            for a, q in cases]
    _eigen_only(monkeypatch)
    for (a, q), (f_int, f) in zip(cases, fast):
        np.testing.assert_array_equal(f_int, response.matignon_stable(a, q, allow_integrator=True))
        np.testing.assert_array_equal(f, response.matignon_stable(a, q))


@pytest.mark.parametrize("degree", [2, 3, 4])
def test_same_sign_certificate_makes_the_eigenvalue_decisions(monkeypatch, degree):
    # Coefficients of one sign over 12 decades, some zero, with q spread over (0, 1.2) and
    # packed at the certificate's edge 2/n; and 1 + λ^n, whose roots lie on the edge
    # |arg λ| = π/n itself. Every row the certificate settles must be stable by the roots.
    rng = np.random.default_rng(20 + degree)
    n = 20_000
    a = rng.uniform(0.0, 1.0, (n, degree + 1)) * 10.0 ** rng.uniform(-6, 6, (n, degree + 1))
    a[rng.random((n, degree + 1)) < 0.1] = 0.0
    a[:, 0] = np.where(a[:, 0] == 0, 1.0, a[:, 0])
    a[: n // 2] *= rng.choice([-1.0, 1.0], (n // 2, 1))
    edge = 2.0 / degree
    q = np.concatenate([rng.uniform(0.0, 1.2, n // 2),
                        np.minimum(edge * (1 + rng.choice([-1, 1], n // 2)
                                           * 10.0 ** rng.uniform(-12, -3, n // 2)), 1.99)])
    tip = np.zeros((4, degree + 1))
    tip[:, 0] = tip[:, -1] = 1.0
    a = np.concatenate([a, tip])
    q = np.concatenate([q, edge * (1 - np.array([1e-3, 1e-9, 1e-12, 0.0]))])
    c = a[:, 1:] / a[:, :1]
    settled = response._same_sign_sector(c, q)
    assert settled.mean() > 0.3 and not settled.all()
    fast = response.matignon_stable(a, q)
    assert np.all(fast[settled])
    _eigen_only(monkeypatch)
    monkeypatch.setattr(response, "_same_sign_sector",
                        lambda c, q: np.zeros(c.shape[0], dtype=bool))
    roots = response.matignon_stable(a, q)
    # Where the companion matrix's eigenvalues decide otherwise, they are the ones that err: a
    # root far smaller than the matrix's norm has an error of eps times that norm, which can
    # flip its sign (a root of -2e-9 beside roots of 6e3 has been seen to come out positive on
    # one CPU and not on another). Those rows are decided again from roots computed to 50
    # digits; the certificate must agree with them.
    for row in np.flatnonzero(fast != roots):
        assert settled[row], row
        assert fast[row] == _stable_by_precise_roots(a[row], q[row]), (row, a[row], q[row])
    assert np.mean(fast != roots) < 1e-3


def _stable_by_precise_roots(a, q) -> bool:
    """Matignon's test on the roots of a0 + a1 λ + ... (ascending) computed to 50 digits."""
    mpmath = pytest.importorskip("mpmath")
    import inspect

    coeffs = [float(x) for x in np.trim_zeros(np.asarray(a, dtype=float), "b")]
    # mpmath 1.4 takes ascending coefficients (asc=True); 1.3 only descending ones.
    order = ({"asc": True} if "asc" in inspect.signature(mpmath.polyroots).parameters
             else {})
    with mpmath.workdps(50):
        roots = mpmath.polyroots(coeffs if order else coeffs[::-1], maxsteps=500,
                                 extraprec=500, **order)
        return all(abs(mpmath.arg(r)) > q * mpmath.pi / 2 for r in roots)


def _touching(rng, n, k, eps):
    """x ((x − r)² + eps r²) e(x), e with positive coefficients: ≥ 0 iff eps ≥ 0 (up to the
    rounding tolerance 1e-12 of the check)."""
    r = 10.0 ** rng.uniform(-2, 2, n)
    base = np.stack([r * r * (1 + eps), -2 * r, np.ones(n)], axis=1)
    extra = rng.uniform(0.1, 10, (n, k - 3))
    coef = np.zeros((n, k + 1))
    for i in range(3):
        for j in range(k - 3):
            coef[:, 1 + i + j] += base[:, i] * extra[:, j]
    return coef


@pytest.mark.parametrize("k", [4, 5, 6])
def test_dissipation_shortcuts_make_the_eigenvalue_decisions(monkeypatch, k):
    rng = np.random.default_rng(k)
    polys = [rng.uniform(-1, 1, (5000, k + 1)) * 10.0 ** rng.uniform(-6, 6, (5000, k + 1))]
    polys += [_touching(rng, 2000, k, eps) for eps in (0.0, 1e-13, 1e-9, -1e-13, -1e-11, -1e-9)]
    fast = [passivity.nonnegative_on_positive_axis(p) for p in polys]
    _eigen_only(monkeypatch)
    for p, f in zip(polys, fast):
        np.testing.assert_array_equal(f, passivity.nonnegative_on_positive_axis(p))


@pytest.mark.parametrize("name", ["max-n2m1", "max-n2m2", "max-n3m1", "max-n3m3", "maxwell"])
def test_constraints_hold_unchanged_by_the_shortcuts(monkeypatch, name):
    s = get_structure(name)
    rng = np.random.default_rng(len(name))
    theta = np.column_stack([p.prior.sample(rng, 6000) for p in s.parameters])
    theta[:2000] *= rng.choice([-1.0, 1.0], (2000, s.n_params))
    col = rng.integers(0, s.n_params, 2000)
    theta[2000 + np.arange(2000), col] *= 10.0 ** rng.uniform(-16, -6, 2000)
    kinds = ("compliance", "modulus", "generic")
    fast = [s.constraints_hold(theta, kind) for kind in kinds]
    _eigen_only(monkeypatch)
    for kind, f in zip(kinds, fast):
        np.testing.assert_array_equal(f, s.constraints_hold(theta, kind))


@pytest.mark.parametrize("size", [1, 31, 127, 128, 129, 400])
def test_matignon_batch_size_does_not_change_decisions(monkeypatch, size):
    # Batches below CLOSED_FORM_MIN_ROWS take the eigenvalues, larger ones the closed form:
    # the same decisions either way.
    rng = np.random.default_rng(size)
    a, q = _cubic_cases(rng, 400)[5]
    a = np.concatenate([a, rng.uniform(-100, 100, (400, 4))])
    q = np.concatenate([q, rng.uniform(0.0, 1.0, 400)])
    chunks = [response.matignon_stable(a[i:i + size], q[i:i + size], allow_integrator=True)
              for i in range(0, len(a), size)]
    _eigen_only(monkeypatch)
    np.testing.assert_array_equal(np.concatenate(chunks),
                                  response.matignon_stable(a, q, allow_integrator=True))
