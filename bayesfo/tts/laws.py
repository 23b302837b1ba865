"""The shift laws of time–temperature superposition, fitted to posterior draws of the shifts.

WLF, log10 a_T = −C1 (T − T_ref)/(C2 + T − T_ref), and Arrhenius,
log10 a_T = E_a/(R ln 10) · (1/T − 1/T_ref) (T in kelvin), each fitted to every one of a
seeded subset of the posterior draws of log10 a_T (weighted by the shifts' posterior sds), so
that their parameters carry the shifts' uncertainty. Their relative support is judged by BIC on
the posterior mean and covariance of the shifts (an approximation of their evidence: the
shifts' posterior taken as a Gaussian measurement); χ²/dof says how far each misses the shifts
in their posterior sds, and ``dof`` (free shifts less the law's constants) whether the shifts
can test the law at all: with none to spare (WLF on three isotherms) it passes through them.
"""

from __future__ import annotations

import math

import numpy as np

#: Gas constant [J/(mol K)].
GAS_CONSTANT = 8.314462618
#: Kelvin of 0 °C.
KELVIN = 273.15
#: Posterior draws to which the shift laws are fitted (a seeded subset).
LAW_DRAWS = 400


def wlf(temperature, t_ref, c1, c2):
    """log10 a_T by the WLF equation (temperatures in °C or K alike: differences only)."""
    dt = np.asarray(temperature, float) - t_ref
    return -c1 * dt / (c2 + dt)


def arrhenius(temperature, t_ref, ea):
    """log10 a_T by the Arrhenius law, temperatures in °C, E_a in J/mol."""
    inv = 1.0 / (np.asarray(temperature, float) + KELVIN) - 1.0 / (t_ref + KELVIN)
    return ea / (GAS_CONSTANT * math.log(10.0)) * inv


def _fit_laws(shift_draws, temperatures, reference: int, seed: int) -> dict:
    """WLF and Arrhenius fitted to each of :data:`LAW_DRAWS` posterior draws of the shifts
    (least squares, each shift weighted by its posterior sd), and the laws' BIC-based
    probabilities from the shifts' posterior mean and covariance."""
    from scipy.optimize import least_squares

    from ..inference import hdi

    temps = np.asarray(temperatures, float)
    t_ref = temps[reference]
    others = np.array([i for i in range(temps.size) if i != reference])
    x = shift_draws[:, others]
    sd = np.maximum(x.std(axis=0, ddof=1), 1e-6)
    rng = np.random.default_rng(seed)
    rows = rng.choice(x.shape[0], size=min(LAW_DRAWS, x.shape[0]), replace=False)
    t = temps[others]
    out = {}
    # Arrhenius: linear in E_a; weighted least squares, closed form for every draw at once.
    basis = arrhenius(t, t_ref, 1.0)
    ea = (x[rows] / sd**2) @ basis / np.sum(basis**2 / sd**2)
    # WLF: C1, C2 per draw by nonlinear least squares from a common start.
    c2_min = -(t.min() - t_ref) + 1.0  # C2 + T − T_ref > 0 over the isotherms
    mean = x.mean(axis=0)

    def fit_wlf(y, start):
        sol = least_squares(lambda p: (wlf(t, t_ref, p[0], p[1]) - y) / sd, start,
                            bounds=([-1e3, max(c2_min, 1e-3)], [1e3, 1e5]))
        return sol.x

    start = fit_wlf(mean, [10.0, max(50.0, c2_min + 10.0)])
    wlf_draws = np.array([fit_wlf(x[r], start) for r in rows])

    def summary(v, unit):
        lo, hi = hdi(v, 0.94)
        return {"mean": float(v.mean()), "sd": float(v.std(ddof=1)), "hdi_low": lo,
                "hdi_high": hi, "unit": unit}

    cov = np.cov(x, rowvar=False) if x.shape[1] > 1 else np.array([[sd[0] ** 2]])
    cov = np.atleast_2d(cov) + 1e-12 * np.eye(x.shape[1])
    prec = np.linalg.inv(cov)
    n = x.shape[1]

    def bic(pred, k):
        r = mean - pred
        return float(r @ prec @ r) + k * math.log(n)

    predicted = {"wlf": wlf(t, t_ref, *start), "arrhenius": arrhenius(t, t_ref, float(np.median(ea)))}
    bics = {"wlf": bic(predicted["wlf"], 2), "arrhenius": bic(predicted["arrhenius"], 1)}
    low = min(bics.values())
    weights = {k: math.exp(-0.5 * (v - low)) for k, v in bics.items()}
    total = sum(weights.values())
    out["wlf"] = {"parameters": {"C1": summary(wlf_draws[:, 0], ""),
                                 "C2": summary(wlf_draws[:, 1], "°C")}}
    out["arrhenius"] = {"parameters": {"Ea": summary(ea, "J/mol")}}
    for name, k in (("wlf", 2), ("arrhenius", 1)):
        # How far the law misses the shifts, in their posterior sds: near 1 where it holds.
        z = (mean - predicted[name]) / sd
        worst = int(np.argmax(np.abs(z)))
        out[name].update(
            bic=bics[name], probability=weights[name] / total,
            chi2_per_dof=float(np.sum(z**2) / max(n - k, 1)), dof=n - k,
            worst_temperature=float(t[worst]), worst_deviation=float(mean[worst] - predicted[name][worst]))
    return out
