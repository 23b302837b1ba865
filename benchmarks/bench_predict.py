"""Cost of a prediction with its band: G(t) at 200 times from 2 000 posterior draws (fixed
Talbot, 20 nodes, vectorised), against mpmath's ``invertlaplace`` (Talbot in arbitrary
precision, one time and one draw per call) timed on a few points and scaled; the frequency
quantities; the accuracy of the vectorised inversion against Mittag-Leffler closed forms.

Usage: python benchmarks/bench_predict.py
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

from bayesfo.predictions import evaluate
from bayesfo.predictions.functions import _band
from bayesfo.structures import get_structure

T = np.logspace(-3, 3, 200)
W = np.logspace(-2, 3, 200)


def best_of(fn, repeat=5):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def draws(theta, n=2000, seed=0):
    rng = np.random.default_rng(seed)
    return np.asarray(theta) * (1 + 0.01 * rng.normal(size=(n, len(theta))))


def main():
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, python "
          f"{platform.python_version()}, numpy {np.__version__}")
    cases = {"zener": [2.0, 3.0, 0.5, 0.6], "maxwell": [2.0, 0.5, 0.8, 0.3],
             "fractional_zener_sl": [1.0, 2.0, 5.0, 0.5], "zener-int": [2.0, 3.0, 0.5]}
    print(f"{'structure':<22} {'G(t) 2000x200 [s]':>18} {'+ band [s]':>11} {'J(t) [s]':>9} "
          f"{'G′,G″ [s]':>10}")
    for name, theta in cases.items():
        s, th = get_structure(name), draws(theta)
        g = best_of(lambda: evaluate(s, th, "relaxation_modulus", T))
        values = evaluate(s, th, "relaxation_modulus", T)
        b = best_of(lambda: _band(values))
        j = best_of(lambda: evaluate(s, th, "creep_compliance", T))
        f = best_of(lambda: (evaluate(s, th, "storage", W), evaluate(s, th, "loss", W)))
        print(f"{name:<22} {g:18.3f} {b:11.3f} {j:9.3f} {f:10.3f}")
    try:
        import mpmath
    except ImportError:
        print("mpmath not installed: no comparison with invertlaplace")
        return
    s = get_structure("zener")
    theta = cases["zener"]

    def transform(p):
        c = complex(s.laplace(theta, np.array([complex(p)]))[0])
        return mpmath.mpc(1.0 / (c * complex(p)))

    pts = T[::40]
    t0 = time.perf_counter()
    ref = [float(mpmath.invertlaplace(transform, float(t), method="talbot")) for t in pts]
    per_point = (time.perf_counter() - t0) / len(pts)
    ours = evaluate(s, theta, "relaxation_modulus", pts)[0]
    print(f"mpmath invertlaplace (talbot): {per_point * 1e3:.1f} ms per time and draw, so "
          f"{per_point * 2000 * 200:.0f} s for 2000 draws x 200 times; largest relative "
          f"difference to the vectorised inversion {np.max(np.abs(ours / ref - 1)):.1e}")


if __name__ == "__main__":
    main()
