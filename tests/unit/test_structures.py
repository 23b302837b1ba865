"""Structures from cards: closed forms, variants, scaling, constraints, card errors."""

from __future__ import annotations

import re

import numpy as np
import pytest
from scipy import signal

from bayesfo.data import FrequencyResponse
from bayesfo.errors import InputError, StructureError
from bayesfo.priors import Uniform
from bayesfo.structures import (
    Scaling,
    default_library,
    load_library,
    resolve_structures,
)
from bayesfo.structures.response import dissipation_grid

W = np.logspace(-2, 2, 21)
JW = 1j * W
LIB = default_library()


def test_library_has_every_family_and_generated_variant():
    for base in ("voigt", "zener", "maxwell"):
        for suffix in ("", "-int", "-inv", "-inv-int"):
            assert base + suffix in LIB
    members = {(n, m) for n in range(1, 4) for m in range(n + 1)}
    inverted = {(n, m) for m in range(1, 4) for n in range(m + 1)}
    for n, m in members:
        assert f"max-n{n}m{m}" in LIB and f"max-n{n}m{m}-int" in LIB
    for n, m in inverted:
        assert f"max-n{n}m{m}-inv" in LIB and f"max-n{n}m{m}-inv-int" in LIB
    thesis = [n for n, st in LIB.items() if st.family in ("voigt", "zener", "maxwell", "max")]
    assert len(thesis) == 12 + 2 * (len(members) + len(inverted))
    # The named rheology models of docs/models.md come on top of the thesis' families.
    for name in ("springpot", "fractional_kelvin_voigt", "fractional_maxwell_gel",
                 "fractional_maxwell_liquid", "fractional_zener_sl", "fractional_zener_ll",
                 "fractional_jeffreys", "fractional_burgers"):
        assert name in LIB
    assert "max-n0m2" not in LIB and "max-n3m0-inv" not in LIB


def test_closed_forms_of_the_thesis_models():
    a1, b0, b1, q, alpha, beta = 0.7, 2.0, 0.9, 0.45, 0.3, 0.8
    np.testing.assert_allclose(LIB["voigt"].transfer([a1, b0, q], W), b0 / (a1 * JW**q + 1), rtol=1e-13)
    np.testing.assert_allclose(
        LIB["zener"].transfer([a1, b0, b1, q], W), (b1 * JW**q + b0) / (a1 * JW**q + 1), rtol=1e-13
    )
    np.testing.assert_allclose(
        LIB["maxwell"].transfer([a1, b1, alpha, beta], W),
        (b1 * JW**alpha + 1) / (a1 * JW**beta), rtol=1e-13,
    )
    # The dashpot-like inverted member 1/(b0 + b1 λ + b2 λ²) of thesis §4.3.4.
    np.testing.assert_allclose(
        LIB["max-n0m2-inv"].transfer([1.0, 2.0, 3.0, q], W),
        1 / (1.0 + 2.0 * JW**q + 3.0 * JW ** (2 * q)), rtol=1e-13,
    )


def test_variants_are_derived_from_their_parent():
    theta = np.array([[0.7, 2.0, 0.9, 0.45], [1.5, 0.3, 0.2, 0.8]])
    zener = LIB["zener"]
    np.testing.assert_allclose(LIB["zener-inv"].transfer(theta, W), 1 / zener.transfer(theta, W), rtol=1e-13)
    np.testing.assert_allclose(
        LIB["zener-int"].transfer(theta[:, :3], W),
        zener.transfer(np.column_stack([theta[:, :3], np.ones(2)]), W), rtol=1e-13,
    )
    np.testing.assert_allclose(
        LIB["zener-inv-int"].transfer(theta[:, :3], W),
        1 / LIB["zener-int"].transfer(theta[:, :3], W), rtol=1e-13,
    )
    np.testing.assert_allclose(
        LIB["maxwell-int"].transfer([2.0, 0.5], W), (0.5 * JW + 1) / (2.0 * JW), rtol=1e-13
    )
    # voigt and max-n1m0 are the same function of the same parameters.
    assert LIB["max-n1m0"].param_names == LIB["voigt"].param_names
    np.testing.assert_allclose(LIB["max-n1m0"].transfer([0.7, 2, 0.45], W),
                               LIB["voigt"].transfer([0.7, 2, 0.45], W))


def test_integer_members_equal_scipy_rational_functions():
    rng = np.random.default_rng(3)
    for name in ("max-n2m2-int", "max-n3m1-int", "max-n1m2-inv-int"):
        s = LIB[name]
        theta = rng.uniform(0.1, 2.0, s.n_params)
        den, num, q = s.polynomials(theta)
        assert np.all(q == 1.0)
        _, h = signal.freqs(num[0, ::-1], den[0, ::-1], worN=W)
        np.testing.assert_allclose(s.transfer(theta, W), h, rtol=1e-11)


def test_response_for_modulus_data_is_the_reciprocal_material():
    theta = [0.7, 2.0, 0.45]
    np.testing.assert_allclose(LIB["voigt"].response(theta, W, "modulus"),
                               (0.7 * JW**0.45 + 1) / 2.0, rtol=1e-13)
    np.testing.assert_array_equal(LIB["voigt"].response(theta, W, "generic"), LIB["voigt"].transfer(theta, W))


def _typical_theta(s, rng, n):
    theta = np.empty((n, s.n_params))
    for i, p in enumerate(s.parameters):
        theta[:, i] = rng.uniform(0.2, 0.9, n) if p.role == "exponent" else rng.uniform(0.1, 3.0, n)
    return theta


@pytest.mark.parametrize("kind", ["compliance", "modulus"])
@pytest.mark.parametrize("name", sorted(LIB))
def test_scaling_round_trip_and_invariance(name, kind):
    # G(ω; θ) = g_tf · G̃(ω/ω_ref; θ̃) with θ̃ = to_scaled(θ): the scaled problem is the same model.
    s = LIB[name]
    rng = np.random.default_rng(abs(hash(name)) % 2**32)
    theta = _typical_theta(s, rng, 5)
    scaling = Scaling(omega_ref=37.0, g_ref=2.5e-4, reciprocal=(kind == "modulus"))
    scaled = s.to_scaled(theta, scaling)
    np.testing.assert_allclose(s.to_physical(scaled, scaling), theta, rtol=1e-12)
    w = np.logspace(0, 3, 9)
    np.testing.assert_allclose(
        s.response(theta, w, kind) / scaling.g_ref,
        s.response(scaled, w / scaling.omega_ref, kind), rtol=1e-10,
    )


def test_scaling_from_data_uses_kind():
    fr = FrequencyResponse([1.0, 100.0], [1e6, 4e6], kind="modulus")
    sc = Scaling.from_data(fr)
    assert sc.omega_ref == pytest.approx(10.0) and sc.g_ref == pytest.approx(2.5e6)
    assert sc.reciprocal and sc.tf_gain == pytest.approx(1 / 2.5e6)


def test_passivity_on_grid_equals_zener_ordering():
    rng = np.random.default_rng(5)
    zener = LIB["zener"]
    theta = np.column_stack([rng.uniform(0.1, 3, 500), rng.uniform(0.1, 3, 500),
                             rng.uniform(0.1, 3, 500), rng.uniform(0.05, 1, 500)])
    analytic = theta[:, 2] <= theta[:, 0] * theta[:, 1]
    grid = dissipation_grid(1e-2, 1e2)
    np.testing.assert_array_equal(zener.passive(theta, "compliance", grid), analytic)
    np.testing.assert_array_equal(zener.passive(theta, "modulus", grid), analytic)
    np.testing.assert_array_equal(zener.admissible(theta, "generic"), analytic)
    assert 50 < analytic.sum() < 450


def test_admissible_rejects_each_constraint():
    maxwell = LIB["maxwell"]
    np.testing.assert_array_equal(
        maxwell.admissible(np.array([[1, 1, 0.3, 0.6], [1, 1, 0.6, 0.3]]), "compliance"), [True, False]
    )
    voigt = LIB["voigt"]
    assert voigt.admissible([1.0, 1.0, 0.5], "compliance")
    assert not voigt.admissible([1e5, 1.0, 0.5], "compliance")  # outside the prior
    assert not voigt.admissible([1.0, 1.0, 1.2], "compliance")
    # An unstable max-order member: 1 - 0.5 λ has a root on the positive real axis.
    assert not LIB["max-n1m0"].admissible([-0.5, 1.0, 0.5], "generic")
    assert LIB["max-n1m0"].admissible([0.5, 1.0, 0.5], "generic")
    # For material data the zeros must be stable too: b0 + b1 λ with b1 < 0 has a zero at
    # λ = -b0/b1 > 0, so the modulus 1/J would have an unstable pole. Generic data allow it.
    theta = [0.5, 1.0, -0.2, 0.5]
    assert LIB["max-n1m1"].stable(theta, "generic") and not LIB["max-n1m1"].stable(theta, "modulus")
    assert not LIB["max-n1m1"].admissible(theta, "compliance")
    assert LIB["max-n1m1"].admissible(theta, "generic")
    # Inverted structures keep stability (integrators allowed) and passivity.
    inv = LIB["voigt-inv"]
    assert inv.admissible([1.0, 1.0, 0.5], "compliance") == bool(
        np.all((1 + (1j * dissipation_grid(1, 1)) ** 0.5).imag <= 0)
    )


def test_prior_override_and_data_check():
    z = LIB["zener"].with_priors({"q": Uniform(0.2, 0.6)})
    assert z.priors["q"] == Uniform(0.2, 0.6) and LIB["zener"].priors["q"] == Uniform(0.0, 1.0)
    with pytest.raises(StructureError, match="has no parameter 'c'"):
        LIB["zener"].with_priors({"c": Uniform(0, 1)})
    fr = FrequencyResponse([1.0, 2.0, 3.0], [1, 1, 1])
    LIB["voigt"].check_data(fr)
    with pytest.raises(InputError, match="fewer than the 4 parameters of structure 'zener'"):
        LIB["zener"].check_data(fr)


def test_wrong_theta_shape_is_named():
    with pytest.raises(StructureError, match="takes 3 parameters \\(a1, b0, q\\)"):
        LIB["voigt"].transfer([1.0, 2.0], W)


def test_resolve_shortcuts_and_unknown_names():
    names = [s.name for s in resolve_structures("voigt, max2")]
    assert names == ["voigt", "max-n1m0", "max-n1m1", "max-n2m0", "max-n2m1", "max-n2m2"]
    assert len(resolve_structures("all")) == len(LIB)
    assert [s.name for s in resolve_structures("max1-inv")] == ["max-n0m1-inv", "max-n1m1-inv"]
    with pytest.raises(StructureError, match="unknown structure 'zenr'"):
        resolve_structures("voigt,zenr")


# ---------------------------------------------------------------- user cards
CARD = """
name = "mypot"
numerator = [["b0", 0]]
denominator = [["a1", "q"]]
constraints = ["passive"]
[parameters]
a1 = { prior = "log-uniform", low = 1e-3, high = 1e3 }
b0 = { prior = "log-uniform", low = 1e-3, high = 1e3 }
q = { prior = "uniform", low = 0, high = 1 }
"""


def test_user_card_adds_a_structure_with_variants(tmp_path, monkeypatch):
    (tmp_path / "mypot.toml").write_text(CARD)
    lib = load_library(extra=[tmp_path])
    for name in ("mypot", "mypot-int", "mypot-inv", "mypot-inv-int"):
        assert name in lib
    np.testing.assert_allclose(lib["mypot"].transfer([2.0, 3.0, 0.5], W), 3.0 / (2.0 * JW**0.5))
    monkeypatch.setenv("BAYESFO_MODEL_PATH", str(tmp_path))
    assert "mypot" in load_library()


@pytest.mark.parametrize(
    "change, message",
    [
        (('prior = "uniform", low = 0, high = 1', 'prior = "beta", low = 0, high = 1'), "unknown prior 'beta'"),
        (('q = { prior = "uniform", low = 0, high = 1 }', ""), "parameter 'q' has no prior"),
        (('[["b0", 0]]', '[["b0", 0], [2, "q"]]'), "constant coefficient is only allowed on s\\^0"),
        (('constraints = ["passive"]', 'constraints = ["stable", "causal"]'), "unknown constraint 'causal'"),
        (('constraints = ["passive"]', 'constraints = ["b0 <= c"]'), "unknown parameter 'c'"),
        (('name = "mypot"', 'name = "mypot"\ncolour = "red"'), "unknown key 'colour'"),
        (('low = 1e-3, high = 1e3 }\nb0', 'low = 1e3, high = 1e-3 }\nb0'), "finite low < high"),
        (('name = "mypot"', 'name = "voigt"'), "already declared"),
        (('[parameters]', '[parameters'), "not valid TOML"),
    ],
)
def test_bad_cards_are_named(tmp_path, change, message):
    path = tmp_path / "bad.toml"
    path.write_text(CARD.replace(*change))
    with pytest.raises(StructureError, match=message):
        load_library(extra=[path])


def test_stable_applies_to_a_denominator_of_several_orders(tmp_path):
    # a1 s^q + 1 + c s^p with positive coefficients and orders in [0, 1]: a positive springpot
    # sum of spread below 2, free of zeros in Re s >= 0 (structures/passivity.py), so 'stable'
    # admits it for positive parameters; it is not commensurate.
    card = CARD.replace('[["a1", "q"]]', '[["a1", "q"], [1, 0], ["c", "p"]]').replace(
        'constraints = ["passive"]', 'constraints = ["stable"]'
    ) + 'c = { prior = "uniform", low = 0, high = 1 }\np = { prior = "uniform", low = 0, high = 1 }\n'
    (tmp_path / "x.toml").write_text(card)
    s = load_library(extra=[tmp_path])["mypot"]
    theta = np.array([[2.0, 3.0, 0.5, 0.4, 0.8]])  # a1, b0, c, p, q in the structure's order
    order = [s.param_names.index(n) for n in ("a1", "b0", "c", "p", "q")]
    ordered = np.empty_like(theta)
    ordered[:, order] = theta
    assert s.admissible(ordered, "compliance", np.logspace(-3, 3, 50)).all()


def test_missing_card_path():
    with pytest.raises(StructureError, match="does not exist"):
        load_library(extra=["/nonexistent/cards"])


@pytest.mark.parametrize("name", ["voigt", "zener-inv", "voigt-inv-int", "max-n1m1", "max-n1m1-inv",
                                  "max-n0m1-inv", "zener-int"])
@pytest.mark.parametrize("kind", ["compliance", "modulus"])
def test_exact_dissipation_of_first_degree_structures_equals_grid(name, kind):
    from bayesfo.structures.response import is_dissipative

    s = LIB[name]
    assert s._first_degree
    rng = np.random.default_rng(len(name))
    theta = rng.uniform(-1.0, 3.0, (400, s.n_params))
    if "q" in s.param_names:
        theta[:, s.param_names.index("q")] = rng.uniform(0.05, 1.0, 400)
    grid = dissipation_grid(1e-2, 1e2)
    on_grid = is_dissipative(s.response(theta, grid, kind), kind)
    np.testing.assert_array_equal(s.passive(theta, kind, grid), on_grid)
    assert 20 < on_grid.sum() < 380


def test_the_modulus_formula_in_text_is_the_networks_modulus():
    """Structure.modulus_formula, read back as arithmetic, equals the network's G(jω) evaluated
    element by element, for every structure with a picture (orders fixed by the variant)."""
    from bayesfo.structures import default_library

    rng = np.random.default_rng(3)
    omega = np.logspace(-2, 2, 7)
    checked = 0
    for s in default_library().values():
        if s.modulus_formula is None:
            continue
        network = s.pictures[0].network
        values = {n: rng.uniform(0.2, 0.9) for n in network.names}
        values.update(s.fixed)
        expected = network.modulus({n: np.array([v]) for n, v in values.items()}, omega)[0]
        text = s.modulus_formula.replace("^", "**")
        text = re.sub(r"(\w) s\b", r"\1*s", text)
        got = eval(text, {"__builtins__": {}}, {**values, "s": 1j * omega})  # noqa: S307
        np.testing.assert_allclose(got, expected, rtol=1e-12, err_msg=s.name)
        checked += 1
    assert checked >= 10  # the thesis cards, the named models and their -int variants
