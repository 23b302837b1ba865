"""Evidence: bayesfo compare (posteriors, bridge-sampling evidence, criteria) against plain dynesty
nested sampling in the same run, on a 40-point fractional-Zener modulus data set with known σ.

Prints the wall time of `compare --structures zener,voigt` (everything) and of dynesty (nlive 500,
evidence only) for each structure, with the ln Z values and errors of both routes.
"""

from __future__ import annotations

import platform
import tempfile
import time
import warnings

import numpy as np

from bayesfo.comparison import compare
from bayesfo.data import FrequencyResponse
from bayesfo.inference import Likelihood
from bayesfo.inference._arviz import preload
from bayesfo.inference.evidence import nested_evidence
from bayesfo.output import write_outputs
from bayesfo.parallel import process_pool
from bayesfo.structures import get_structure, resolve_structures


def main():
    import matplotlib

    matplotlib.use("Agg")
    warnings.simplefilter("ignore")
    preload()
    print(f"machine: {platform.machine()}, python {platform.python_version()}, numpy {np.__version__}")
    w = np.logspace(-2, 3, 40)
    zener = get_structure("zener")
    truth = [5.0, 1e-6, 1e-7, 0.6]  # compliance [1/Pa]: plateaus 1e-6 and 2e-8
    g = zener.response(truth, w, "modulus")
    rng = np.random.default_rng(0)
    sd = 0.02 * np.abs(g)
    data = FrequencyResponse(w, g + sd / np.sqrt(2) * (rng.normal(size=40) + 1j * rng.normal(size=40)),
                             sd, kind="modulus", units="Pa")
    # What `bayesfo compare --structures zener,voigt` does: both structures side by side on the
    # two cores, then the NetCDF files, the figures (PNG and PDF, drawn by the same two processes),
    # report.html and summary.json.
    t = time.perf_counter()
    with process_pool(2) as pool, tempfile.TemporaryDirectory() as out:
        result = compare(data, resolve_structures("zener,voigt"), seed=0, progress=False,
                         pool=pool)
        t_posteriors = time.perf_counter() - t
        write_outputs(result, out, pool=pool)
    t_compare = time.perf_counter() - t
    print(f"compare zener,voigt: {t_posteriors:.1f} s for optimisation, posteriors, evidence and "
          f"criteria (2 processes), {t_compare - t_posteriors:.1f} s for figures and report")
    total_dynesty = 0.0
    for name in ("zener", "voigt"):
        ev = result[name].criteria.evidence
        t = time.perf_counter()
        nested = nested_evidence(Likelihood(get_structure(name), data), seed=0, nlive=500)
        dt = time.perf_counter() - t
        total_dynesty += dt
        print(f"{name}: bridge ln Z = {ev.log_z:.2f} ± {ev.log_z_err:.2f}; dynesty ln Z = "
              f"{nested.log_z:.2f} ± {nested.log_z_err:.2f} in {dt:.1f} s ({nested.n_likelihood} calls)")
    print(f"bayesfo compare zener,voigt (posteriors, evidence, criteria, figures, report): "
          f"{t_compare:.1f} s; "
          f"dynesty evidence alone: {total_dynesty:.1f} s; ratio {t_compare / total_dynesty:.2f}")


if __name__ == "__main__":
    main()
