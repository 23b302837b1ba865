"""Throughput of the vectorised log-posterior (likelihood + prior support) of the Zener model.

Zener compliance, 25 frequencies, known σ: parameter sets per second for large batches (the
throughput) and for batches of 16 (what emcee passes with 32 walkers and vectorize=True);
then the cost per parameter set of the tempered ladder's likelihood calls (prior box and
log-likelihood, ``_Target.unchecked``) on the thesis' G_spec set-up at its batch sizes.
"""

from __future__ import annotations

import platform
import time
import warnings

import numpy as np

from bayesfo.data import FrequencyResponse
from bayesfo.inference.likelihood import Likelihood
from bayesfo.inference.smc import _Target
from bayesfo.structures import get_structure
from bayesfo.studies import g_spec_data


def best_of(fn, repeat=5):
    out = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return min(out)


def main():
    warnings.simplefilter("ignore")
    w = np.logspace(np.log10(0.6), np.log10(300), 25)
    z = get_structure("zener")
    truth = np.array([0.5, 1.0, 0.05, 0.6])
    data = FrequencyResponse(w, z.response(truth, w, "compliance"), np.full(25, 0.01), kind="compliance")
    lik = Likelihood(z, data)
    rng = np.random.default_rng(0)
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy {np.__version__}")
    for batch, calls in [(20_000, 1), (16, 2000)]:
        theta = lik.to_scaled(truth * rng.uniform(0.9, 1.1, (batch, 4)))
        for label, fn in [("log-likelihood", lik), ("prior + support", lik.log_prior),
                          ("log-posterior", lambda t: lik(t) + lik.log_prior(t))]:
            dt = best_of(lambda: [fn(theta) for _ in range(calls)])
            print(f"batch {batch:>6}: {label:<16} {batch * calls / dt:>12,.0f} sets/s")
    ladder_batches()


def ladder_batches(names=("maxwell", "max-n2m2", "max-n3m3"), sizes=(250, 1000, 2000, 4000)):
    """µs per parameter set of ``_Target.unchecked`` on prior draws (in the sampling
    coordinates) of each structure on G_spec, at the batch sizes of a tempered ladder."""
    rng = np.random.default_rng(1)
    for name in names:
        target = _Target(Likelihood(get_structure(name), g_spec_data(0)))
        prior = target.lik.prior_list
        u = target.tr.to_u(np.column_stack([p.sample(rng, max(sizes)) for p in prior]))
        line = []
        for n in sizes:
            calls = max(2, 8000 // n)
            dt = best_of(lambda: [target.unchecked(u[:n]) for _ in range(calls)], repeat=7)
            line.append(f"{n}: {dt / (calls * n) * 1e6:.2f}")
        print(f"ladder likelihood {name:9s} us per set at " + ", ".join(line))


if __name__ == "__main__":
    main()
