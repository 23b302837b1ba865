"""Monte Carlo studies of the thesis (§3.4, appendix A.1), side by side with the printed values.

Set-up (§3.4, as reproduced from Tables 3.2–3.3): 25 log-spaced ω in [0.6, 300] rad/s, U = 1,
G_spec = 1/(1 + s^0.5) (eq. (3.24)), noise Ξ = FFT of a real N(0, σ²) vector of length 25 (so
E|Ξ_k|² = 25σ²), σ = 0.001, RMSE = (1/N)·sqrt(Σ|e_k|²) (eq. (3.23)) against G_spec and against the
noisy data G_noise.

Studies: ``table-3.2`` (methods 1–5, q = 0.5, n = 1, m = 0; with Table 3.3), ``table-a.1``
(n = 1, m = 1; with A.2), ``table-a.3`` (q = 0.25, n = m = 2; with A.4), ``table-3.4`` (local
optimisation from the thesis' four initial vectors, n = 1, m = 0), ``table-a.5`` (the same for
n = m = 2; Tables A.5/A.6) and ``table-a.7`` (global optimisation for the three orders); ``figure-3.2`` (RMSE against G_noise over
the noise level σ and the commensurate order q, method 5, n = 1, m = 0).
"""

from __future__ import annotations

import numpy as np
from scipy import optimize

from .data import FrequencyResponse
from .errors import InputError
from .identify.linear import identify_linear
from .identify.optimize import fit_structure
from .structures import get_structure
from .structures.response import commensurate_response

OMEGA = np.logspace(np.log10(0.6), np.log10(300.0), 25)
SIGMA = 1e-3


def g_spec(omega=OMEGA) -> np.ndarray:
    """G_spec(jω) = 1/(1 + (jω)^0.5), thesis eq. (3.24)."""
    return 1.0 / (1.0 + (1j * np.asarray(omega, float)) ** 0.5)


def thesis_noise(rng: np.random.Generator, runs: int, sigma: float = SIGMA, n: int = 25) -> np.ndarray:
    """Ξ = FFT of real N(0, σ²) vectors of length n, one row per run (thesis eq. (3.22))."""
    return np.fft.fft(rng.normal(0.0, sigma, size=(runs, n)), axis=-1)


def g_spec_data(seed: int = 0, kind: str = "compliance") -> FrequencyResponse:
    """One noisy realisation of the thesis set-up as a data set: G_spec + Ξ (σ = 0.001 per time
    sample), with the known complex standard deviation sqrt(25)·σ = 0.005 at every point."""
    noise = thesis_noise(np.random.default_rng(seed), 1)[0]
    return FrequencyResponse(OMEGA, g_spec() + noise, np.full(OMEGA.size, 5.0 * SIGMA),
                             kind=kind, name=f"G_spec + thesis noise (seed {seed})")


def rmse(reference, fitted) -> np.ndarray:
    """(1/N)·sqrt(Σ_k |G_ref − Ĝ|²) over the last axis (thesis eq. (3.23))."""
    reference = np.asarray(reference)
    return np.sqrt(np.sum(np.abs(reference - fitted) ** 2, axis=-1)) / reference.shape[-1]


def _stats(a, b, q, fitted, noisy) -> dict:
    spec = rmse(g_spec(), fitted)
    noise = rmse(noisy, fitted)
    return {
        "mean_a": a.mean(axis=0).tolist(), "var_a": a.var(axis=0).tolist(),
        "mean_b": b.mean(axis=0).tolist(), "var_b": b.var(axis=0).tolist(),
        "mean_q": float(np.mean(q)), "var_q": float(np.var(q)),
        "rmse_spec": float(spec.mean()), "var_rmse_spec": float(spec.var()),
        "rmse_noise": float(noise.mean()), "var_rmse_noise": float(noise.var()),
    }


def _row(a, b, q=None, rs=None, vrs=None, rn=None, vrn=None, va=None, vb=None, vq=None):
    out = {"mean_a": a, "mean_b": b}
    for key, v in (("var_a", va), ("var_b", vb), ("mean_q", q), ("var_q", vq), ("rmse_spec", rs),
                   ("var_rmse_spec", vrs), ("rmse_noise", rn), ("var_rmse_noise", vrn)):
        if v is not None:
            out[key] = v
    return out


def _scale(values, factor):
    return [v * factor for v in values]


# Printed values (Tables 3.2/3.3, A.1/A.2, A.3/A.4, 3.4, A.5/A.6, A.7), in plain units.
THESIS = {
    "table-3.2": {
        "1": _row([1, 0.9990], [0.9996], va=_scale([0, 3.7071], 1e-4), vb=[1.2010e-4],
                  rs=3.7326e-4, vrs=3.9322e-8, rn=10.2942e-4, vrn=2.5483e-8),
        "2": _row([1, 0.9982], [0.9990], va=_scale([0, 1.3618], 1e-4), vb=[0.4828e-4],
                  rs=2.3283e-4, vrs=1.4941e-8, rn=9.7477e-4, vrn=1.9882e-8),
        "3": _row([1, 0.9979], [0.9988], va=_scale([0, 1.3907], 1e-4), vb=[0.4570e-4],
                  rs=2.1990e-4, vrs=1.3706e-8, rn=9.6404e-4, vrn=1.9425e-8),
        "4": _row([1, 1.0000], [1.0000], va=_scale([0, 1.2513], 1e-4), vb=[0.0893e-4],
                  rs=5.0580e-4, vrs=14.2000e-8, rn=11.2319e-4, vrn=5.6183e-8),
        "5": _row([1, 0.9974], [0.9987], va=_scale([0, 0.4281], 1e-4), vb=[0.3563e-4],
                  rs=3.8884e-4, vrs=7.0998e-8, rn=10.4396e-4, vrn=3.0687e-8),
    },
    "table-a.1": {
        "1": _row([1, 0.9948], [0.9984, -0.0013], va=_scale([0, 10.1675], 1e-4),
                  vb=_scale([1.8887, 0.2752], 1e-4), rs=6.1425e-4, vrs=9.2972e-8, rn=11.3107e-4, vrn=5.4620e-8),
        "2": _row([1, 0.9963], [0.9984, -0.0004], va=_scale([0, 2.1930], 1e-4),
                  vb=_scale([0.6472, 0.0254], 1e-4), rs=2.8526e-4, vrs=1.5611e-8, rn=9.7315e-4, vrn=2.0643e-8),
        "3": _row([1, 0.9989], [0.9995, -0.0001], va=_scale([0, 1.2065], 1e-4),
                  vb=_scale([0.4026, 0.0146], 1e-4), rs=2.2822e-4, vrs=1.2675e-8, rn=9.5670e-4, vrn=1.9496e-8),
        "4": _row([1, 0.9997], [0.9999, -0.0001], va=_scale([0, 7.9542], 1e-4),
                  vb=_scale([0.2020, 0.6184], 1e-4), rs=9.1282e-4, vrs=24.5144e-8, rn=13.4264e-4, vrn=13.6890e-8),
        "5": _row([1, 0.9965], [0.9984, -0.0002], va=_scale([0, 0.9622], 1e-4),
                  vb=_scale([0.2523, 0.0332], 1e-4), rs=4.3684e-4, vrs=6.5408e-8, rn=10.4361e-4, vrn=3.2819e-8),
    },
    "table-a.3": {
        "1": _row([1, 0.1069, 0.6263], [1.1292, -0.3346, 0.0723], va=[0, 0.0387, 0.0631],
                  vb=[0.0182, 0.0403, 0.0014], rs=3.1417e-3, vrs=9.1396e-6, rn=3.3116e-3, vrn=8.8555e-6),
        "2": _row([1, 0.0442, 0.9059], [1.0334, -0.0705, 0.0122], va=[0, 0.0129, 0.0073],
                  vb=[0.0049, 0.0043, 0.0001], rs=0.4314e-3, vrs=0.0204e-6, rn=0.9853e-3, vrn=0.0251e-6),
        "3": _row([1, 0.0606, 0.9420], [1.0388, -0.0433, 0.0065], va=[0, 0.0283, 0.0173],
                  vb=[0.0112, 0.0103, 0.0002], rs=0.3623e-3, vrs=0.0210e-6, rn=0.9569e-3, vrn=0.0219e-6),
        "4": _row([1, 0.1330, 0.6851], [1.1249, -0.2690, 0.0564], va=[0, 0.0967, 0.2374],
                  vb=[0.0521, 0.1605, 0.0062], rs=4.4785e-3, vrs=35.3426e-6, rn=4.6783e-3, vrn=34.4486e-6),
        "5": _row([1, 0.1457, 0.8448], [1.0886, -0.1057, 0.0153], va=[0, 0.0239, 0.0137],
                  vb=[0.0074, 0.0069, 0.0002], rs=0.6078e-3, vrs=0.0550e-6, rn=1.0848e-3, vrn=0.0386e-6),
    },
    "table-3.4": {
        # The thesis found the same optimum from all four initial vectors for n = 1, m = 0.
        label: _row([1, 0.9997], [0.9998], q=0.5001, va=[0, 1.7678e-4], vb=[0.7195e-4],
                    vq=7.1897e-6, rs=2.3346e-4, vrs=1.3059e-8, rn=9.5296e-4, vrn=1.8946e-8)
        for label in ("x0=[0.5,0.5,0.1]", "x0=[-0.5,0.5,0.1]", "x0=[0.5,0.5,1]", "x0=[-0.5,0.5,1]")
    },
    "table-a.5": {
        "x0=[0.5,0.5,0.5,0.5,0.5,0.1]": _row([1, 9.7620, 8.8087], [1.0991, 8.7117, -0.0215], q=0.4831,
                                             va=[0, 280.6334, 277.0976], vb=[0.4013, 278.5133, 0.0168],
                                             vq=5.1489e-3, rs=5.3899e-4, vrs=1.3983e-6, rn=11.2805e-4, vrn=1.1731e-6),
        "x0=[-0.5,0.5,0.5,0.5,0.5,0.1]": _row([1, 8.3781, 7.4182], [0.9905, 7.4089, -0.0022], q=0.4995,
                                              va=[0, 18.7990, 17.0455], vb=[0.0577, 17.3309, 0.0026],
                                              vq=1.5945e-4, rs=3.0339e-4, vrs=1.5727e-8, rn=9.3163e-4, vrn=1.8977e-8),
        "x0=[0.5,0.5,0.5,0.5,0.5,1]": _row([1, 5.1492, 12.6855], [-1.6210, 0.5380, 5.7133], q=1.0978e-7,
                                           va=[0, 0.0501e-4, 5.6528e-4], vb=[0.1907e-4, 1.6068e-4, 1.5147e-4],
                                           vq=9.5824e-15, rs=452.5970e-4, vrs=4.7178e-13, rn=452.6772e-4, vrn=7.7618e-9),
        "x0=[-0.5,0.5,0.5,0.5,0.5,1]": _row([1, 31.3166, 30.4820], [0.9609, 30.4430, -0.0081], q=0.4996,
                                            va=[0, 3.6875, 0.6190], vb=[0.2756, 0.0118, 0.0153],
                                            vq=1.4635e-4, rs=3.0477e-4, vrs=1.5762e-8, rn=9.3115e-4, vrn=1.8988e-8),
    },
    "table-a.7": {
        "opt-n1m0": _row([1, 1.0009], [1.0006], q=0.4998, va=[0, 1.3654e-4], vb=[6.0778e-5], vq=4.5006e-5,
                         rs=2.4991e-4, vrs=1.8020e-8, rn=9.2988e-4, vrn=1.9265e-8),
        "opt-n1m1": _row([1, 1.0010], [1.0006, -0.0000], q=0.4998, va=[0, 2.4027e-4],
                         vb=[9.4542e-5, 0.8066e-5], vq=3.6767e-5, rs=2.8640e-4, vrs=1.9921e-8,
                         rn=9.1765e-4, vrn=2.0411e-8),
        "opt-n2m2": _row([1, 45.3903, 44.2364], [1.0231, 44.2933, 0.0008], q=0.5012,
                         va=[0, 544.6653, 531.9798], vb=[0.5869, 533.0843, 0.0377], vq=1.6159e-4,
                         rs=3.1031e-4, vrs=1.7875e-8, rn=9.1088e-4, vrn=2.0519e-8),
    },
}

STUDIES = {
    "table-3.2": {"type": "methods", "q": 0.5, "n": 1, "m": 0, "runs": 10_000},
    "table-a.1": {"type": "methods", "q": 0.5, "n": 1, "m": 1, "runs": 10_000},
    "table-a.3": {"type": "methods", "q": 0.25, "n": 2, "m": 2, "runs": 10_000},
    "table-3.4": {"type": "local", "n": 1, "m": 0, "runs": 1000},
    "table-a.5": {"type": "local", "n": 2, "m": 2, "runs": 1000},
    "table-a.7": {"type": "global", "orders": [(1, 0), (1, 1), (2, 2)], "runs": 100},
}


def _initial_vectors(n: int, m: int) -> dict[str, np.ndarray]:
    """The four initial vectors of §3.4.2, [±0.5, 0.5, …, 0.5, q0] with q0 = 0.1 and q0 = 1,
    in the thesis' order."""
    out = {}
    for q0 in (0.1, 1.0):
        for sign in (1.0, -1.0):
            x = np.full(n + m + 2, 0.5)
            x[0], x[-1] = sign * 0.5, q0
            out["x0=[" + ",".join(f"{v:g}" for v in x) + "]"] = x
    return out


def _local_fit(x0, noisy, n, m):
    """Bounded local least squares from x0 (thesis Problem 5 without the global search)."""
    lb = np.r_[np.full(n + m + 1, -100.0), 0.0]
    ub = np.r_[np.full(n + m + 1, 100.0), 1.0]
    x0 = np.clip(x0, lb + 1e-9, ub - 1e-9)

    def resid(x):
        a = np.r_[1.0, x[:n]]
        g = commensurate_response(OMEGA, a, x[n:n + m + 1], x[-1])
        r = g - noisy
        out = np.concatenate([r.real, r.imag])
        return np.where(np.isfinite(out), out, 1e6)

    return optimize.least_squares(resid, x0, bounds=(lb, ub), method="trf", xtol=1e-12,
                                  ftol=1e-12, gtol=1e-12, max_nfev=2000).x


def run_study(study: str, runs: int | None = None, seed: int = 0, *, n_starts: int = 16) -> dict:
    """Run a thesis study and return the ``simulate --json`` contract.

    Parameters
    ----------
    study : str
        One of :data:`STUDIES`.
    runs : int, optional
        Number of noisy realisations (default: the thesis' number).
    seed : int
        Seed of the noise; the same seed gives the same numbers.
    n_starts : int
        Random starts of the global optimisation (``table-a.7``), besides the linear seeds.
    """
    if study not in STUDIES:
        raise InputError(f"unknown study '{study}'; known studies: {', '.join(STUDIES)}")
    spec = STUDIES[study]
    runs = spec["runs"] if runs is None else int(runs)
    if runs < 2:
        raise InputError(f"--runs must be at least 2, got {runs}")
    rng = np.random.default_rng(seed)
    noisy = g_spec() + thesis_noise(rng, runs)
    results = {}
    if spec["type"] == "methods":
        q, n, m = spec["q"], spec["n"], spec["m"]
        for method in (1, 2, 3, 4, 5):
            a, b = identify_linear(OMEGA, noisy, q, n, m, method)
            fitted = commensurate_response(OMEGA, a, b, np.full(runs, q))
            results[str(method)] = _stats(a, b, np.full(runs, q), fitted, noisy)
    elif spec["type"] == "local":
        n, m = spec["n"], spec["m"]
        for label, x0 in _initial_vectors(n, m).items():
            xs = np.array([_local_fit(x0, noisy[r], n, m) for r in range(runs)])
            a = np.column_stack([np.ones(runs), xs[:, :n]])
            b = xs[:, n:n + m + 1]
            fitted = commensurate_response(OMEGA, a, b, xs[:, -1])
            results[label] = _stats(a, b, xs[:, -1], fitted, noisy)
    else:
        for n, m in spec["orders"]:
            s = get_structure(f"max-n{n}m{m}")
            thetas = []
            for r in range(runs):
                data = FrequencyResponse(OMEGA, noisy[r], kind="generic")
                fit = fit_structure(s, data, rng=rng, n_starts=n_starts, weighting="none",
                                    seed_methods=True)
                thetas.append(fit.theta)
            thetas = np.array(thetas)
            den, num, q = s.polynomials(thetas)
            fitted = commensurate_response(OMEGA, den, num, q)
            results[f"opt-n{n}m{m}"] = _stats(den, num, q, fitted, noisy)
    return {"study": study, "runs": runs, "seed": seed, "methods": results,
            "thesis": THESIS.get(study, {})}


def rmse_surface(sigmas=None, q_grid=None, *, method: int = 5, n: int = 1, m: int = 0,
                 runs: int = 1, seed: int = 0) -> dict:
    """RMSE against G_noise over noise levels σ and orders q (thesis Figure 3.2).

    For each σ, ``runs`` noisy data sets are drawn (the thesis used one) and fitted by the
    linear ``method`` at every q of the grid at once; the RMSE (eq. (3.23)) is averaged over runs.

    Returns
    -------
    dict
        ``sigma`` (n_sigma,), ``q`` (n_q,), ``rmse`` (n_sigma, n_q) as lists, and the settings.
    """
    sigmas = np.round(np.arange(1, 11) * 1e-4, 6) if sigmas is None else np.asarray(sigmas, float)
    q_grid = np.round(np.arange(1, 101) * 0.01, 2) if q_grid is None else np.asarray(q_grid, float)
    rng = np.random.default_rng(seed)
    out = np.empty((sigmas.size, q_grid.size))
    for i, sigma in enumerate(sigmas):
        noisy = g_spec() + thesis_noise(rng, runs, sigma)
        a, b = identify_linear(OMEGA, noisy[:, None, :], q_grid[None, :], n, m, method)
        fitted = commensurate_response(OMEGA, a, b, np.broadcast_to(q_grid, a.shape[:-1]))
        out[i] = rmse(noisy[:, None, :], fitted).mean(axis=0)
    return {"study": "figure-3.2", "method": method, "n": n, "m": m, "runs": runs, "seed": seed,
            "sigma": sigmas.tolist(), "q": q_grid.tolist(), "rmse": out.tolist()}
