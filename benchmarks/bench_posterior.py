"""Wall time of a converged posterior (R-hat < 1.01, bulk and tail ESS >= 400, >= 50 tau).

Fractional Zener compliance with 1 % relative noise (known sigma) on 25 and 40 log-spaced points,
including the global optimisation that seeds the walkers; arviz is imported beforehand.
"""

from __future__ import annotations

import platform
import time

import numpy as np

from bayesfo.data import FrequencyResponse
from bayesfo.inference import run_posterior
from bayesfo.inference._arviz import preload
from bayesfo.structures import get_structure


def main():
    preload()
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy {np.__version__}")
    s = get_structure("zener")
    truth = np.array([0.5, 1.0, 0.05, 0.6])
    for n in (25, 40):
        w = np.logspace(np.log10(0.6), np.log10(300), n)
        g = s.response(truth, w, "compliance")
        times = []
        for seed in range(5):
            rng = np.random.default_rng(seed)
            sd = 0.01 * np.abs(g)
            noisy = g + sd / np.sqrt(2) * (rng.normal(size=n) + 1j * rng.normal(size=n))
            data = FrequencyResponse(w, noisy, sd, kind="compliance")
            t = time.perf_counter()
            r, _ = run_posterior(s, data, seed=seed, progress=False)
            times.append(time.perf_counter() - t)
            status = "converged" if r.converged else "NOT converged"
            print(f"  {n} points, seed {seed}: {times[-1]:.2f} s, {r.n_steps} steps, tau_max "
                  f"{np.max(r.tau):.0f}, R-hat {r.rhat_max:.4f}, ESS {r.ess_min:.0f}, {status}")
        print(f"zener posterior, {n} points: median {np.median(times):.2f} s, max {np.max(times):.2f} s")


if __name__ == "__main__":
    main()
