"""Known-truth checks of the model ranking: simulate data from a known structure and see whether
the comparison picks it (issue of the evidence: hit rates over many seeds).

Each scenario draws noisy data (known per-point σ, relative noise) from a true structure and
compares a set of candidates by ln Z; a hit is when the truth (or, for integer-order data, the
integer baseline or its parent with q's 94 % HDI reaching 0.97) ranks first.
"""

from __future__ import annotations

import warnings

import numpy as np

from bayesfo.comparison import compare
from bayesfo.data import FrequencyResponse
from bayesfo.structures import get_structure, resolve_structures

OMEGA = np.logspace(np.log10(0.6), np.log10(300.0), 25)

#: name: (true structure, true parameters, kind, relative noise, candidates)
SCENARIOS = {
    "voigt": ("voigt", [1.0, 1e-3, 0.5], "compliance", 0.02, "voigt,zener,max-n2m1"),
    "zener": ("zener", [20.0, 1e-3, 2e-4, 0.6], "compliance", 0.02, "voigt,zener,maxwell"),
    "integer": ("zener-int", [0.05, 1e-3, 1e-5], "compliance", 0.02, "zener,zener-int,voigt"),
    # A dashpot-like response (thesis §4.3.4, Table A.12): 1/(b0 + b1 λ + b2 λ²) with b0 → 0,
    # an integrator with a lag; its phase passes −90°, which no non-inverted candidate reaches.
    "inverted": ("max-n0m2-inv", [1e-3, 1.0, 0.2, 0.9], "generic", 0.02,
                 "voigt,zener,maxwell,zener-inv,max-n0m2-inv"),
}


def simulate(scenario: str, seed: int) -> FrequencyResponse:
    """Noisy data of a scenario (complex noise of sd = noise·|G| per point, σ known)."""
    name, theta, kind, noise, _ = SCENARIOS[scenario]
    rng = np.random.default_rng(seed)
    g = get_structure(name).response(theta, OMEGA, kind)
    sd = noise * np.abs(g)
    noisy = g + sd / np.sqrt(2) * (rng.normal(size=g.size) + 1j * rng.normal(size=g.size))
    return FrequencyResponse(OMEGA, noisy, sd, kind=kind, name=f"{scenario} seed {seed}")


def hit(scenario: str, result) -> bool:
    """Whether the comparison ``result`` picked the truth of ``scenario``."""
    best = result.ranking[0]
    if scenario == "integer":
        if best == "zener-int":
            return True
        q = result[best].posterior.summary.get("q")
        return best == "zener" and q is not None and q.hdi_high >= 0.97
    if scenario == "inverted":
        return best.endswith("-inv")
    return best == SCENARIOS[scenario][0]


def hit_rate(scenario: str, seeds, *, workers: int = 1) -> tuple[float, list[str]]:
    """Share of seeds for which the comparison picks the truth, and the winner of each seed
    (``workers``: processes per comparison, see :func:`~bayesfo.comparison.compare`)."""
    winners = []
    hits = 0
    candidates = resolve_structures(SCENARIOS[scenario][4])
    for seed in seeds:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = compare(simulate(scenario, seed), candidates, seed=seed, progress=False,
                             predictive=False, workers=workers)
        winners.append(result.ranking[0])
        hits += hit(scenario, result)
    return hits / len(winners), winners
