"""The rheology model library: named springpot models against closed forms from the literature,
limits of the orders against classical models, physical parameters and units, exact passivity
and stability conditions against dense-grid checks, and integer baselines."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bayesfo.errors import StructureError
from bayesfo.structures import (
    Scaling,
    coefficient_units,
    coefficients_from_physical,
    default_library,
    get_structure,
    load_library,
    parameter_forms,
    physical_dimensions,
    physical_parameters,
    physical_units,
    picture_for,
    resolve_structures,
    stress_unit,
)
from bayesfo.structures.passivity import rhp_zero_count, side_stable
from bayesfo.structures.physical import pictures
from bayesfo.structures.response import dissipation_grid, is_dissipative, matignon_stable
from bayesfo.structures.variants import identifiable_rank

LIB = default_library()
W = np.logspace(-3, 3, 31)
JW = 1j * W
PI2 = np.pi / 2
NAMED = ["springpot", "fractional_kelvin_voigt", "fractional_maxwell_gel",
         "fractional_maxwell_liquid", "fractional_zener_sl", "fractional_zener_ll",
         "fractional_jeffreys", "fractional_burgers"]
MATERIALS = sorted(n for n, s in LIB.items() if s.pictures)


def theta_of(s, **values):
    """θ of structure ``s`` from its physical parameters (through the card's inverse)."""
    coef = coefficients_from_physical(s, values)
    return np.array([coef[n] for n in s.param_names], dtype=float)


def modulus(name, w=W, **values):
    s = get_structure(name)
    picture = picture_for(name)
    coef = coefficients_from_physical(s, values, picture=picture)
    return s.response(np.array([coef[n] for n in s.param_names]), w, "modulus")


# ------------------------------------------------------------------ closed forms (pyRheo, RHEOS)
def test_springpot_and_kelvin_voigt_forms():
    c, a, cb, b, ge = 3.0, 0.35, 0.7, 0.8, 2.5
    ref = c * W**a * (np.cos(a * PI2) + 1j * np.sin(a * PI2))
    np.testing.assert_allclose(modulus("springpot", c_alpha=c, alpha=a), ref, rtol=1e-12)
    np.testing.assert_allclose(get_structure("springpot").response([c, a], W, "compliance"),
                               W**-a * (np.cos(a * PI2) - 1j * np.sin(a * PI2)) / c, rtol=1e-12)
    # pyRheo FractionalKelvinVoigt: G' = V w^a cos + G w^b cos, G'' = V w^a sin + G w^b sin.
    ref = (c * W**b * np.cos(b * PI2) + cb * W**a * np.cos(a * PI2)
           + 1j * (c * W**b * np.sin(b * PI2) + cb * W**a * np.sin(a * PI2)))
    np.testing.assert_allclose(modulus("fkv", c_alpha=c, alpha=b, c_beta=cb, beta=a), ref,
                               rtol=1e-12)
    # pyRheo FractionalKelvinVoigtS through the thesis' voigt.
    ref = ge + c * W**a * np.cos(a * PI2) + 1j * c * W**a * np.sin(a * PI2)
    np.testing.assert_allclose(modulus("fractional_kelvin_voigt_s", G_e=ge, c_q=c, q=a), ref,
                               rtol=1e-12)


def test_fractional_maxwell_forms():
    v, g, a, b = 233.6, 1251.2, 0.8476, 0.2852  # pyRheo FractionalMaxwell(G, V, alpha, beta)
    tau = (v / g) ** (1 / (a - b))
    gc, x = v * tau**-a, W * tau
    den = 1 + x ** (2 * (a - b)) + 2 * x ** (a - b) * np.cos((a - b) * PI2)
    ref = gc * (x**a * np.cos(a * PI2) + x ** (2 * a - b) * np.cos(b * PI2)
                + 1j * (x**a * np.sin(a * PI2) + x ** (2 * a - b) * np.sin(b * PI2))) / den
    got = modulus("fractional_maxwell", c_beta=v, beta=a, c_delta=g, alpha=a - b)
    np.testing.assert_allclose(got, ref, rtol=1e-11)
    s = get_structure("maxwell")
    j = s.response(theta_of(s, c_beta=v, beta=a, c_delta=g, alpha=a - b), W, "compliance")
    np.testing.assert_allclose(j, W**-a * np.exp(-1j * a * PI2) / v + W**-b * np.exp(-1j * b * PI2) / g,
                               rtol=1e-12)
    # pyRheo FractionalMaxwellGel(G_s, V, alpha): spring and springpot in series.
    gs, v, a = 900.0, 40.0, 0.6
    tau = (v / gs) ** (1 / a)
    x = W * tau
    den = 1 + x ** (2 * a) + 2 * x**a * np.cos(a * PI2)
    ref = v * tau**-a * (x ** (2 * a) + x**a * np.cos(a * PI2) + 1j * x**a * np.sin(a * PI2)) / den
    np.testing.assert_allclose(modulus("fmg", G_m=gs, c_alpha=v, alpha=a), ref, rtol=1e-11)
    j = get_structure("fmg").response([gs, v, a], W, "compliance")
    np.testing.assert_allclose(j, 1 / gs + W**-a * (np.cos(a * PI2) - 1j * np.sin(a * PI2)) / v,
                               rtol=1e-12)
    # pyRheo FractionalMaxwellLiquid(G, eta_s, beta): springpot and dashpot in series.
    g, eta, b = 50.0, 300.0, 0.4
    tau = (eta / g) ** (1 / (1 - b))
    x = W * tau
    den = 1 + x ** (2 * (1 - b)) + 2 * x ** (1 - b) * np.cos((1 - b) * PI2)
    ref = eta / tau * (x ** (2 - b) * np.cos(b * PI2) + 1j * (x + x ** (2 - b) * np.sin(b * PI2))) / den
    np.testing.assert_allclose(modulus("fml", c_alpha=g, eta=eta, alpha=b), ref, rtol=1e-11)
    j = get_structure("fml").response([g, eta, b], W, "compliance")
    np.testing.assert_allclose(j, W**-b * np.exp(-1j * b * PI2) / g - 1j / (eta * W), rtol=1e-12)


def test_fractional_zener_forms():
    # pyRheo FractionalZenerSolidS(G_p, G_s, V, alpha) through the thesis' zener.
    gp, gs, v, a = 30.0, 120.0, 15.0, 0.45
    vw = v * W**a
    den = vw**2 + gs**2 + 2 * vw * gs * np.cos(a * PI2)
    ref = gp + (gs**2 * vw * np.cos(a * PI2) + vw**2 * gs + 1j * gs**2 * vw * np.sin(a * PI2)) / den
    np.testing.assert_allclose(modulus("fzss", G_e=gp, G_m=gs, c_q=v, q=a), ref, rtol=1e-11)
    # The Poynting-Thomson picture of the same card: J = 1/G_g + 1/(G_k + V (jw)^q).
    gg, gk = 200.0, 60.0
    kv = gk + v * W**a * np.cos(a * PI2) + 1j * v * W**a * np.sin(a * PI2)
    j_ref = 1 / gg + (kv.real - 1j * kv.imag) / np.abs(kv) ** 2
    s = get_structure("zener")
    coef = coefficients_from_physical(s, {"G_g": gg, "G_k": gk, "c_q": v, "q": a},
                                      picture="fpt")
    j = s.response([coef[n] for n in s.param_names], W, "compliance")
    np.testing.assert_allclose(j, j_ref, rtol=1e-11)
    # pyRheo FractionalZenerLiquidS(G_p, G, eta_s, beta).
    g, eta, b = 25.0, 80.0, 0.3
    gwb, ew = g * W**b, eta * W
    den = ew**2 + gwb**2 + 2 * ew * gwb * np.cos((1 - b) * PI2)
    ref = gp + (ew**2 * gwb * np.cos(b * PI2) + 1j * (gwb**2 * ew + ew**2 * gwb * np.sin(b * PI2))) / den
    np.testing.assert_allclose(modulus("fzsl", G_e=gp, c_alpha=g, eta=eta, alpha=b), ref, rtol=1e-11)
    # pyRheo FractionalZener(G, V, K, alpha, beta, kappa) = springpot || two springpots.
    g, v, k, a, b, kap = 94929.06, 786171.48, 607.96, 0.8916, 0.1957, 0.8225
    gwb, vwa, kwk = g * W**b, v * W**a, k * W**kap
    den = vwa**2 + gwb**2 + 2 * vwa * gwb * np.cos((a - b) * PI2)
    ref = (kwk * np.cos(kap * PI2) + (gwb**2 * vwa * np.cos(a * PI2) + vwa**2 * gwb * np.cos(b * PI2)) / den
           + 1j * (kwk * np.sin(kap * PI2)
                   + (gwb**2 * vwa * np.sin(a * PI2) + vwa**2 * gwb * np.sin(b * PI2)) / den))
    got = modulus("fractional_zener", c_alpha=v, alpha=a, c_beta=g, beta=b, c_kappa=k, kappa=kap)
    np.testing.assert_allclose(got, ref, rtol=1e-11)


def test_jeffreys_and_burgers_forms():
    # pyRheo FractionalZenerLiquidD(eta_p, G, eta_s, beta) = the fractional Jeffreys card.
    ep, g, es, b = 5.0, 40.0, 70.0, 0.35
    den = (es * W) ** 2 + (g * W**b) ** 2 + 2 * es * g * W ** (b + 1) * np.sin(b * PI2)
    storage = es**2 * g * W ** (b + 2) * np.cos(b * PI2) / den
    loss = ep * W + (g**2 * es * W ** (2 * b + 1) + es**2 * g * W ** (b + 2) * np.sin(b * PI2)) / den
    got = modulus("fractional_jeffreys", eta_p=ep, c_alpha=g, eta_s=es, alpha=b)
    np.testing.assert_allclose(got, storage + 1j * loss, rtol=1e-11)
    # Burgers: J = 1/G_m + 1/(i w eta) + 1/(G_k + c (i w)^a), real and imaginary parts.
    gm, eta, gk, c, a = 500.0, 900.0, 150.0, 60.0, 0.55
    re, im = gk + c * W**a * np.cos(a * PI2), c * W**a * np.sin(a * PI2)
    j_ref = 1 / gm + re / (re**2 + im**2) - 1j * (1 / (eta * W) + im / (re**2 + im**2))
    j = get_structure("fbm").response([gm, eta, gk, c, a], W, "compliance")
    np.testing.assert_allclose(j, j_ref, rtol=1e-11)


# ------------------------------------------------------------------ limits of the orders
def maxwell_ref(g, eta):
    tau = eta / g
    return g * JW * tau / (1 + JW * tau)


def zener_ref(ge, gm, eta):
    return ge + maxwell_ref(gm, eta)


def test_orders_to_zero_or_one_give_the_classical_models():
    s = get_structure
    np.testing.assert_allclose(s("springpot").response([3.0, 1.0], W, "modulus"), 3.0 * JW, rtol=1e-12)
    np.testing.assert_allclose(s("springpot").response([3.0, 0.0], W, "modulus"), 3.0, rtol=1e-12)
    np.testing.assert_allclose(s("springpot-int").response([3.0], W, "modulus"), 3.0 * JW, rtol=1e-12)
    # Kelvin-Voigt: spring G in parallel with dashpot eta.
    np.testing.assert_allclose(s("fkv").response([7.0, 2.0, 1.0, 0.0], W, "modulus"), 2 + 7 * JW,
                               rtol=1e-12)
    np.testing.assert_allclose(s("voigt-int").response([3.5, 0.5], W, "modulus"), 2 + 7 * JW, rtol=1e-12)
    # Maxwell: spring 40 in series with dashpot 100, from four cards.
    ref = maxwell_ref(40.0, 100.0)
    np.testing.assert_allclose(s("maxwell-int").response([100.0, 2.5], W, "modulus"), ref, rtol=1e-12)
    np.testing.assert_allclose(s("fmg").response([40.0, 100.0, 1.0], W, "modulus"), ref, rtol=1e-12)
    np.testing.assert_allclose(s("fml").response([40.0, 100.0, 0.0], W, "modulus"), ref, rtol=1e-12)
    assert s("fmg-int") is s("maxwell-int") is s("fractional_maxwell_gel-int")
    # Zener (standard linear solid): spring 10 parallel to spring 40 in series with dashpot 100.
    ref = zener_ref(10.0, 40.0, 100.0)
    z = s("zener-int")
    coef = coefficients_from_physical(z, {"G_e": 10.0, "G_m": 40.0, "c_q": 100.0})
    np.testing.assert_allclose(z.response([coef[n] for n in z.param_names], W, "modulus"), ref, rtol=1e-12)
    np.testing.assert_allclose(s("fzsl").response([10.0, 40.0, 100.0, 0.0], W, "modulus"), ref, rtol=1e-12)
    np.testing.assert_allclose(s("fzll").response([100.0, 40.0, 10.0, 1.0, 0.0, 0.0], W, "modulus"),
                               ref, rtol=1e-12)
    # Poynting-Thomson (spring in series with Kelvin-Voigt) at q = 1.
    pt = coefficients_from_physical(z, {"G_g": 50.0, "G_k": 20.0, "c_q": 30.0}, picture="fpt")
    np.testing.assert_allclose(z.response([pt[n] for n in z.param_names], W, "compliance"),
                               1 / 50 + 1 / (20 + 30 * JW), rtol=1e-12)
    # Jeffreys: dashpot 5 parallel to spring 40 in series with dashpot 70.
    np.testing.assert_allclose(s("fjm").response([5.0, 40.0, 70.0, 0.0], W, "modulus"),
                               5 * JW + maxwell_ref(40.0, 70.0), rtol=1e-12)


def test_burgers_at_order_one_is_the_classical_burgers_model():
    # RHEOS BurgersLiquid (eta1, k1 Maxwell; eta2, k2 Kelvin-Voigt), its storage and loss moduli.
    eta1, k1, eta2, k2 = 900.0, 500.0, 60.0, 150.0
    p1, p2 = eta1 / k1 + eta1 / k2 + eta2 / k2, eta1 * eta2 / (k1 * k2)
    q1, q2 = eta1, eta1 * eta2 / k2
    den = p1**2 * W**2 + (1 - p2 * W**2) ** 2
    ref = (p1 * q1 * W**2 - q2 * W**2 * (1 - p2 * W**2)
           + 1j * (p1 * q2 * W**3 + q1 * W * (1 - p2 * W**2))) / den
    fb = get_structure("fractional_burgers")
    np.testing.assert_allclose(fb.response([k1, eta1, k2, eta2, 1.0], W, "modulus"), ref, rtol=1e-10)
    np.testing.assert_allclose(get_structure("fractional_burgers-int").response(
        [k1, eta1, k2, eta2], W, "modulus"), ref, rtol=1e-10)


# ------------------------------------------------------------------ library, aliases, baselines
def test_named_models_aliases_and_integer_baselines():
    for name in NAMED:
        s = LIB[name]
        assert s.pictures and s.pictures[0].network is not None and s.reference
        assert f"{name}-inv" not in LIB  # the reciprocal of a material is not a material
    assert [n for n in NAMED if f"{n}-int" in LIB] == ["springpot", "fractional_burgers"]
    for alias, (target, picture) in {"fkv": ("fractional_kelvin_voigt", None),
                                     "fractional_kelvin_voigt_s": ("voigt", None),
                                     "fmm": ("maxwell", None), "fzss": ("zener", "fractional_zener_ss"),
                                     "fpt": ("zener", "fractional_poynting_thomson"),
                                     "fractional_zener": ("fractional_zener_ll", None),
                                     "fpt-int": ("zener-int", "fractional_poynting_thomson"),
                                     "fjm": ("fractional_jeffreys", None)}.items():
        assert get_structure(alias) is LIB[target] and picture_for(alias) == picture
    assert [s.name for s in resolve_structures("fkv,fractional_kelvin_voigt,voigt,fkvs")] == [
        "fractional_kelvin_voigt", "voigt"]
    with pytest.raises(StructureError, match="unknown structure 'fkv-inv'"):
        get_structure("fkv-inv")
    # The thesis' cards keep all their variants.
    for base in ("voigt", "zener", "maxwell"):
        assert {f"{base}{x}" for x in ("", "-int", "-inv", "-inv-int")} <= set(LIB)


def test_degenerate_integer_baselines_are_not_generated(tmp_path):
    # The custom card: 1/(a1 s^alpha + a2 s^beta) has the integer baseline 1/((a1+a2) s).
    (tmp_path / "fkv2.toml").write_text("""
name = "fkv2"
numerator = [[1, 0]]
denominator = [["a1", "alpha"], ["a2", "beta"]]
constraints = ["stable", "passive", "beta <= alpha"]
[parameters]
a1 = { prior = "log-uniform", low = 1e-4, high = 1e4 }
a2 = { prior = "log-uniform", low = 1e-4, high = 1e4 }
alpha = { prior = "uniform", low = 0, high = 1 }
beta = { prior = "uniform", low = 0, high = 1 }
""")
    lib = load_library(extra=[tmp_path])
    assert "fkv2" in lib and "fkv2-inv" in lib and "fkv2-int" not in lib and "fkv2-inv-int" not in lib
    assert identifiable_rank(lib["fkv2"]) == 4
    # ... and 'stable' now applies to its two-exponent denominator.
    assert lib["fkv2"].admissible([2.0, 0.5, 0.7, 0.2], "modulus")
    assert lib["fkv2"].describe()["constraints"] == ["stable", "passive", "beta <= alpha"]


# ------------------------------------------------------------------ physical parameters
def _draws(s, rng, n=200):
    """Parameter sets from the priors that satisfy the card's inequalities, in physical units."""
    theta = np.column_stack([p.prior.sample(rng, n) for p in s.parameters])
    vals, _ = s.values(theta)
    keep = np.ones(n, dtype=bool)
    for c in s.constraints:
        if not isinstance(c, str):
            keep &= c.holds(vals)
    return s.to_physical(theta[keep], Scaling(omega_ref=23.0, g_ref=4e3, reciprocal=True))


@pytest.mark.parametrize("name", MATERIALS)
def test_round_trip_physical_coefficients(name):
    s = LIB[name]
    theta = _draws(s, np.random.default_rng(len(name)))
    for pic in pictures(s):
        phys = physical_parameters(s, theta, "modulus", "Pa", picture=pic.name, derived=False)
        back = coefficients_from_physical(s, {k: v for k, (v, _) in phys.items()}, picture=pic.name)
        np.testing.assert_allclose(np.column_stack([back[n] for n in s.param_names]), theta,
                                   rtol=1e-12, atol=0)


@pytest.mark.parametrize("kind", ["modulus", "compliance"])
@pytest.mark.parametrize("name", MATERIALS)
def test_declared_units_follow_the_scaling(name, kind):
    # Changing the stress unit by c and the time unit by k multiplies a quantity of dimensions
    # (p, t) by c^p k^t: the scaled problem is such a change (k = ω_ref, c = 1/g_ref for moduli).
    s = LIB[name]
    theta = _draws(s, np.random.default_rng(7))
    g_ref = 4e3 if kind == "modulus" else 2.5e-4
    sc = Scaling(omega_ref=23.0, g_ref=g_ref, reciprocal=kind == "modulus")
    stress = 1 / g_ref if kind == "modulus" else g_ref
    scaled = s.to_scaled(theta, sc)
    for pic in pictures(s):
        a = physical_parameters(s, theta, kind, picture=pic.name)
        b = physical_parameters(s, scaled, kind, picture=pic.name)
        for n, (p, t) in physical_dimensions(s, theta, picture=pic.name).items():
            np.testing.assert_allclose(b[n][0], a[n][0] * stress**p * 23.0**t, rtol=1e-10,
                                       err_msg=f"{name}, {pic.name}: {n}")


def test_unit_strings_come_from_the_data():
    assert stress_unit("modulus", "Pa") == "Pa" and stress_unit("compliance", "1/MPa") == "MPa"
    assert stress_unit("compliance", "1/(kPa)") == "kPa" and stress_unit("generic", "um/N") == "1/(um/N)"
    assert stress_unit("modulus", "") == "a.u." and stress_unit("compliance", "") == "1/a.u."
    assert coefficient_units(LIB["zener"], "modulus", "Pa") == {"a1": "s^q", "b0": "1/Pa",
                                                                "b1": "s^q/Pa", "q": ""}
    assert coefficient_units(LIB["zener-int"], "compliance", "1/MPa") == {
        "a1": "s", "b0": "1/MPa", "b1": "s/MPa"}
    assert physical_units(LIB["maxwell"], "modulus", "Pa") == {
        "c_beta": "Pa s^beta", "c_delta": "Pa s^(beta-alpha)", "alpha": "", "beta": "",
        "delta": "", "tau": "s", "E": "Pa"}
    assert physical_units(LIB["fractional_burgers"], "compliance", "1/kPa") == {
        "G_m": "kPa", "eta": "kPa s", "G_k": "kPa", "c_alpha": "kPa s^alpha", "alpha": "",
        "tau_m": "s", "tau_k": "s"}
    assert physical_units(LIB["zener"], "modulus", "Pa", picture="fpt")["G_g"] == "Pa"
    # The integer baseline fixes both orders: its second springpot's order β − α is the
    # constant 0, not a quantity the data tell; its other parameters stay.
    assert physical_units(LIB["maxwell-int"], "modulus", "Pa") == {
        "c_beta": "Pa s", "c_delta": "Pa", "tau": "s", "E": "Pa"}


def test_each_physical_parameter_says_what_it_is():
    from bayesfo.structures.physical import meanings

    maxwell = meanings(LIB["maxwell"])
    assert list(maxwell) == list(physical_units(LIB["maxwell"]))
    # The card's descriptions, and for the orders the elements they are or enter: the
    # thesis' alpha is no element's order, only part of the second springpot's.
    assert maxwell["delta"] == "order of the second springpot"
    assert maxwell["E"] == ("modulus E of the thesis' eq. (2.16), c_beta/tau^beta (a shear "
                            "modulus for shear data)")
    assert maxwell["beta"] == ("order of the springpot c_beta; in the order beta - alpha of the "
                               "springpot c_delta")
    assert maxwell["alpha"] == "in the order beta - alpha of the springpot c_delta"
    # Without a description in the card: from the element the coefficient belongs to.
    burgers = meanings(LIB["fractional_burgers"])
    assert burgers["eta"] == "viscosity of the dashpot"
    assert burgers["c_alpha"] == "quasi-property of the springpot of order alpha"
    assert burgers["alpha"] == "order of the springpot c_alpha"
    assert all(all(meanings(LIB[n]).values()) for n in ("zener", "voigt", "fractional_zener_ll"))


def test_physical_parameters_of_draws_and_the_natural_form():
    z = LIB["zener"]
    draws = {"a1": np.array([2.0, 3.0]), "b0": np.array([1e-3, 2e-3]),
             "b1": np.array([1e-3, 1e-3]), "q": np.array([0.5, 0.25])}
    phys = physical_parameters(z, draws, "modulus", "Pa")
    assert list(phys) == ["G_e", "G_m", "c_q", "q", "tau"]
    np.testing.assert_allclose(phys["G_e"][0], [1000.0, 500.0])
    np.testing.assert_allclose(phys["G_m"][0], (draws["a1"] * draws["b0"] - draws["b1"])
                               / (draws["b0"] * draws["b1"]))
    np.testing.assert_allclose(phys["tau"][0], (draws["b1"] / draws["b0"]) ** (1 / draws["q"]))
    natural, other = parameter_forms(z, draws, "modulus", "Pa")
    assert "G_e" in natural and "b0" in other and other["b0"][1] == "1/Pa"
    natural, other = parameter_forms(z, draws, "compliance", "1/Pa")
    assert "b0" in natural and natural["b0"][1] == "1/Pa" and other["c_q"][1] == "Pa s^q"
    fkv = LIB["fractional_kelvin_voigt"]
    phys = physical_parameters(fkv, np.array([5.06, 65.26, 0.795, 0.128]), "modulus", "Pa")
    assert phys["c_alpha"] == (pytest.approx(5.06), "Pa s^alpha")
    assert phys["tau"][0] == pytest.approx((5.06 / 65.26) ** (1 / (0.795 - 0.128)))
    with pytest.raises(StructureError, match="needs 'b1' among the coefficients"):
        physical_parameters(z, {"a1": 1, "b0": 1, "q": 0.5})
    with pytest.raises(StructureError, match="has no picture 'kelvin'"):
        physical_parameters(z, draws, picture="kelvin")
    # Inverted variants are not the material of the card: their coefficients are reported.
    assert list(physical_parameters(LIB["zener-inv"], [1, 1, 0.5, 0.5])) == ["a1", "b0", "b1", "q"]


# ------------------------------------------------------------------ passivity and stability
def _admissible_draws(s, rng, n=300):
    theta = np.column_stack([p.prior.sample(rng, n) for p in s.parameters])
    for i, p in enumerate(s.parameters):
        if p.role == "exponent":
            theta[:, i] = rng.uniform(0.02, 0.95, n)
    vals, _ = s.values(theta)
    keep = np.ones(n, dtype=bool)
    for c in s.constraints:
        if not isinstance(c, str):
            keep &= c.holds(vals)
    return theta[keep]


@pytest.mark.parametrize("name", NAMED + ["voigt", "zener", "maxwell", "fractional_burgers-int",
                                          "springpot-int"])
def test_passive_and_stable_by_the_conditions_and_on_a_dense_grid(name):
    s = LIB[name]
    theta = _admissible_draws(s, np.random.default_rng(11))
    if name == "zener":  # positive G_m: the picture's condition
        theta = theta[theta[:, 2] <= theta[:, 0] * theta[:, 1]]
    assert len(theta) > 50
    assert np.all(s.admissible(theta, "modulus")) and np.all(s.admissible(theta, "compliance"))
    w = np.logspace(-8, 8, 481)
    g = s.response(theta, w, "modulus")
    tol = 1e-9 * np.abs(g)
    assert np.all(g.real >= -tol) and np.all(g.imag >= -tol)  # G', G'' >= 0 over 16 decades
    j = s.response(theta, w, "compliance")
    tol = 1e-9 * np.abs(j)
    assert np.all(j.real >= -tol) and np.all(j.imag <= tol)
    # No zero of numerator or denominator in the closed right half plane (s = 0 aside):
    # |Σ c s^e| stays a fixed fraction of Σ |c s^e| on a polar grid.
    r = np.logspace(-6, 6, 49)[:, None]
    phi = np.linspace(-PI2, PI2, 33)[None, :]
    s_grid = (r * np.exp(1j * phi)).ravel()
    vals, _ = s.values(theta)
    for terms in (s.numerator, s.denominator):
        total, size = 0, 0
        for t in terms:
            c = t.coefficient(vals, len(theta))[:, None]
            e = np.asarray(t.exponent.value(vals), dtype=float) * np.ones(len(theta))
            term = c * np.exp(e[:, None] * np.log(s_grid)[None, :])
            total, size = total + term, size + np.abs(term)
        assert np.min(np.abs(total) / size) > 1e-3


def test_violations_are_caught_by_the_conditions_and_the_grid():
    grid = dissipation_grid(1e-2, 1e2)
    fkv = LIB["fractional_kelvin_voigt"]
    bad = np.array([[1.0, -0.5, 0.8, 0.2], [1.0, 0.5, 0.8, 0.2]])  # a negative springpot
    np.testing.assert_array_equal(fkv.passive(bad, "modulus", grid), [False, True])
    np.testing.assert_array_equal(
        is_dissipative(fkv.response(bad, grid, "modulus"), "modulus"), [False, True])
    z = LIB["zener"]  # b1 > a1 b0: a negative arm modulus G_m, loss < 0
    assert not z.admissible([1.0, 1.0, 2.0, 0.5], "modulus")
    assert not is_dissipative(z.response([1.0, 1.0, 2.0, 0.5], grid, "modulus"), "modulus")


def test_power_sum_stability_against_matignon():
    # Mixed-sign commensurate sums Σ a_k s^(k q), written as plain power sums: the argument
    # principle (used for non-commensurate sides) agrees with Matignon's theorem.
    rng = np.random.default_rng(5)
    n = 400
    a = rng.uniform(-1, 2, (n, 4))
    a[:, 0] = rng.uniform(0.2, 2, n)
    q = rng.uniform(0.1, 1.4, n)
    expo = np.arange(4)[None, :] * q[:, None]
    ref = matignon_stable(a, q)
    # Skip sets within rounding of the boundary |arg λ| = q π/2.
    margin = np.array([np.min(np.abs(np.abs(np.angle(np.roots(row[::-1]))) - qq * PI2))
                       for row, qq in zip(a, q)])
    keep = margin > 0.02
    got = rhp_zero_count(a[keep], expo[keep]) == 0
    np.testing.assert_array_equal(got, ref[keep])
    assert 50 < ref[keep].sum() < keep.sum() - 50
    # Positive sums with exponents spanning less than 2 never vanish in Re s >= 0.
    c = rng.uniform(0, 1, (200, 3))
    e = rng.uniform(0, 1.9, (200, 3))
    assert np.all(side_stable(c, e))
    count = rhp_zero_count(c, e)  # NaN: exponents so close that the check cannot decide
    assert np.all((count == 0) | np.isnan(count)) and np.mean(count == 0) > 0.95


# ------------------------------------------------------------------ card grammar and checks
CARD = """
name = "fsl"
numerator = [["eta", 1], ["c_alpha", "alpha"]]
denominator = [["G_e*eta", 1], ["G_e*c_alpha", "alpha"], ["c_alpha*eta", "alpha+1"]]
constraints = ["stable", "passive"]
inverted = false
[parameters]
G_e = { prior = "log-uniform", low = 1e-4, high = 1e4 }
c_alpha = { prior = "log-uniform", low = 1e-4, high = 1e4 }
eta = { prior = "log-uniform", low = 1e-4, high = 1e4 }
alpha = { prior = "uniform", low = 0, high = 1 }
[physical]
network = "parallel(spring(G_e), series(springpot(c_alpha, alpha), dashpot(eta)))"
"""


def test_products_and_sums_in_a_user_card(tmp_path):
    (tmp_path / "fsl.toml").write_text(CARD)
    s = load_library(extra=[tmp_path])["fsl"]
    assert s.formula == ("(eta s + c_alpha s^alpha) / (G_e*eta s + G_e*c_alpha s^alpha "
                         "+ c_alpha*eta s^(alpha+1))")
    np.testing.assert_allclose(s.transfer([1.0, 2.0, 3.0, 0.4], W),
                               LIB["fractional_zener_sl"].transfer([1.0, 2.0, 3.0, 0.4], W))


@pytest.mark.parametrize("old, new, message", [
    ('"parallel(spring(G_e)', '"series(spring(G_e)', "is not the reciprocal of the card's compliance"),
    ('["c_alpha*eta", "alpha+1"]', '["c_alpha*eta", "alpha+2"]', "is not the reciprocal"),
    ('[["eta", 1], ["c_alpha", "alpha"]]', '[["eta", 1], ["eta", "alpha"]]',
     "cannot be given consistent units"),
    ('["eta", 1]', '["eta*nan", 1]', "bad coefficient 'eta\\*nan'"),
    ('inverted = false', 'inverted = false\ninteger = "nothing-int"', "'integer' names 'nothing-int'"),
    ('network = ', 'derived = [{ name = "tau", value = "eta/x" }]\nnetwork = ', "unknown parameter 'x'"),
    ('network = "parallel', 'network = "lever', "unknown network element 'lever'"),
    ('network = "parallel(spring(G_e), ', 'network = "parallel(spring(G_e)), ', "cannot read the network"),
])
def test_bad_physical_cards_are_named(tmp_path, old, new, message):
    assert old in CARD
    (tmp_path / "bad.toml").write_text(CARD.replace(old, new))
    with pytest.raises(StructureError, match=message):
        load_library(extra=[tmp_path])


def test_docs_table_names_every_model():
    text = (Path(__file__).parents[2] / "docs" / "models.md").read_text()
    for name, s in LIB.items():
        if s.pictures and not s.integer:
            assert f"`{name}`" in text, name
    for alias in LIB.aliases:
        assert f"`{alias}`" in text, alias


def test_an_alias_naming_a_picture_reports_that_picture():
    from bayesfo.errors import StructureError
    from bayesfo.structures import picture_of, resolve_structures

    (fpt,) = resolve_structures("fpt")
    (zener,) = resolve_structures("zener")
    assert fpt.name == zener.name == "zener"
    assert picture_of(fpt).name == "fractional_poynting_thomson"
    assert picture_of(zener).name == "fractional_zener_ss"
    # The same model: responses and priors are those of the card.
    theta = np.array([0.3, 2.0, 0.5, 0.6])
    w = np.logspace(-2, 2, 9)
    assert np.array_equal(fpt.response(theta, w, "modulus"), zener.response(theta, w, "modulus"))
    assert [p.prior for p in fpt.parameters] == [p.prior for p in zener.parameters]
    assert resolve_structures("zener,fzss") == [zener]  # the default picture twice is one
    with pytest.raises(StructureError, match="same structure 'zener' with different pictures"):
        resolve_structures("zener,fpt")
    with pytest.raises(StructureError, match="has no picture"):
        zener.with_picture("burgers")


def test_every_fractional_structure_reports_an_order():
    # The ranking's q column, the q-posterior figure and the verdict take the structure's
    # order from order_parameter: each structure with a free exponent names one of its
    # exponents (the springpot models' alpha too, which had no order reported before).
    from bayesfo.comparison.table import order_parameter

    lib = default_library()
    with_exponent = 0
    for s in lib.values():
        exponents = [p.name for p in s.parameters if p.role == "exponent"]
        name = order_parameter(s.param_names)
        if exponents:
            with_exponent += 1
            assert name in exponents, (s.name, exponents, name)
        else:
            assert name is None, (s.name, name)
    assert with_exponent >= 12
    assert order_parameter(get_structure("fractional_maxwell_gel").param_names) == "alpha"
    assert order_parameter(get_structure("maxwell").param_names) == "beta"
    assert order_parameter(get_structure("max-n2m1").param_names) == "q"


def test_structure_names_ignore_case_and_unknown_ones_get_the_closest():
    from bayesfo.structures import resolve_structures

    names = [s.name for s in resolve_structures("Voigt, ZENER,Fractional Kelvin Voigt,MAX1")]
    assert names == ["voigt", "zener", "fractional_kelvin_voigt", "max-n1m0", "max-n1m1"]
    assert [s.name for s in resolve_structures("ALL")] == [s.name for s in resolve_structures("all")]
    with pytest.raises(StructureError, match=r"unknown structure 'vogit' \(did you mean 'voigt'\?\)"):
        get_structure("vogit")
    with pytest.raises(StructureError, match=r"'zenr' \(did you mean 'zener'"):
        resolve_structures("voigt,zenr")
    with pytest.raises(StructureError) as info:
        get_structure("xyz")
    assert "did you mean" not in str(info.value)
