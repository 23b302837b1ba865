"""Polymer compliance (PP): which structure do data like the thesis' position-controlled
measurement support, how well is q determined, and do max-order models overfit?

The data are simulated from the thesis' own fitted model of the orange polypropylene sample in
the position-controlled (PC) set-up, with the set-up's frequency grid and a noise level read
from the thesis' fitting errors; two frequencies are held out for validation, as in the thesis
(§4.3.2–4.3.3). The data set is ``examples/data/pp_compliance.csv``; this script regenerates it
and checks that the file is what the generator produces.

Truth and set-up (the thesis' values; see ``generate``):

* Model: fractional Voigt compliance J(s) = b0 / (1 + a1 s^q) with a = [1, 0.0133],
  b0 = 0.0011, q = 0.6980: Table 4.2, PC column, row "Opt" (the global optimisation). Units:
  J = ε/σ with σ in N/mm² = MPa, so J in 1/MPa (1/b0 ≈ 0.9 GPa, inside the 0.5–1.2 GPa the
  thesis measured, §4.3.1); s = jω with ω in rad/s. Among the PC fits this is the one the
  thesis singles out (lowest Voigt RMSE in Table 4.1, q confirmed by method 3); the PC Zener
  fit (Table A.8, Opt: a1 = 0.0002, b1 = −0.0000) has collapsed to a spring, and the PC
  max-order fits (Table A.9) disagree wildly with each other, which the thesis calls overfitting.
* Frequencies: the PC set-up covered 0.01–30 Hz with "less frequencies", one measurement each
  (§4.2), and held out 0.5 Hz and 10 Hz for validation (§4.3.3). The grid is the 1-2-5 series
  0.01, 0.02, 0.05, …, 10, 20, 30 Hz (12 points, 10 fitted), which contains both.
* Noise: circular complex Gaussian, E|ξ|² = σ², σ = 1.5e-5 1/MPa (about 1.4 % of |J|), the same
  at every frequency (sensor-limited). Read from Table 4.1: the smallest PC fitting error is
  0.40e-5 (method 3, G_max3, a member with 7 parameters); with eq. (3.23) over 10 points this is
  a per-point error of 1.27e-5, and a least-squares fit of k = 7 real parameters to 20 real
  numbers leaves E|e|² = σ²(1 − 7/20), so σ ≈ 1.6e-5. No σ column is written (one measurement
  per frequency): bayesfo estimates a constant σ.

Usage: python examples/pp_compliance.py [--quick] [--out DIR] [--seed N] [--regenerate]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from _common import (
    check_or_write_csv as _check_or_write_csv,
)
from _common import (
    comment_lines,
    make_parser,
    print_holdout,
    print_orders,
    print_table,
    run_compare,
    save,
)

from bayesfo import FrequencyResponse, read_csv
from bayesfo.structures import get_structure, resolve_structures

HERE = Path(__file__).resolve().parent
NAME = "pp_compliance"
CSV = HERE / "data" / "pp_compliance.csv"
FREQ_HZ = np.array([0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 30.0])
HOLDOUT_HZ = (0.5, 10.0)
#: Table 4.2, PC, Opt: a = [1, a1], b0, q (the voigt card's order: a1, b0, q).
TRUTH = {"structure": "voigt", "a1": 0.0133, "b0": 0.0011, "q": 0.6980}
SIGMA = 1.5e-5
GENERATOR_SEED = 0

STRUCTURES_FULL = ("voigt,zener,maxwell,max-n1m1,max-n2m1,max-n2m2,max-n3m3,"
                   "voigt-int,zener-int,maxwell-int,max-n2m2-int")
STRUCTURES_QUICK = "voigt,zener,max-n2m2,voigt-int"


def truth_response(omega) -> np.ndarray:
    """J(jω) of the thesis' PC Voigt fit [1/MPa]."""
    theta = [TRUTH["a1"], TRUTH["b0"], TRUTH["q"]]
    return get_structure(TRUTH["structure"]).response(theta, omega, "compliance")


def generate(seed: int = GENERATOR_SEED) -> FrequencyResponse:
    """The simulated PC measurement: truth plus circular complex noise of sd ``SIGMA``."""
    rng = np.random.default_rng(seed)
    omega = 2 * np.pi * FREQ_HZ
    noise = SIGMA / np.sqrt(2) * (rng.normal(size=omega.size) + 1j * rng.normal(size=omega.size))
    return FrequencyResponse(omega, truth_response(omega) + noise, kind="compliance",
                             units="1/MPa", name="PP (orange), PC set-up, simulated")


def csv_text(seed: int = GENERATOR_SEED) -> str:
    """The CSV file of the generated data, with its provenance in comment lines."""
    data = generate(seed)
    header = [
        f"# name: {data.name}",
        "# kind: compliance",
        "# units: 1/MPa",
        "# Simulated from the master thesis' fitted model of the orange PP sample, position-",
        "#   controlled set-up: fractional Voigt J(s) = b0/(1 + a1 s^q), a = [1, 0.0133],",
        ("#   b0 = 0.0011, q = 0.6980 (Table 4.2, PC, Opt; s = j*omega, omega in rad/s; "
         "J in 1/MPa)."),
        "# Frequencies: 1-2-5 series over the PC range 0.01-30 Hz (thesis §4.2); 0.5 Hz and 10 Hz",
        "#   are the thesis' validation points (§4.3.3): hold them out with",
        "#   --holdout 3.141593,62.83185 (rad/s).",
        f"# Noise: circular complex Gaussian, E|xi|^2 = sigma^2, sigma = {SIGMA:g} 1/MPa at every",
        "#   frequency (from the PC fitting errors of Table 4.1); one measurement per frequency.",
        f"# Generator: examples/pp_compliance.py (generate(seed={seed}), numpy default_rng);",
        "#   python examples/pp_compliance.py --regenerate rewrites this file.",
        "freq,real,imag",
    ]
    rows = [f"{f!r},{g.real!r},{g.imag!r}"
            for f, g in zip(FREQ_HZ.tolist(), data.response.tolist())]
    return "\n".join(header + rows) + "\n"


def check_or_write_csv(regenerate: bool) -> Path:
    """Write the CSV (``regenerate``), or check that the bundled file is the generator's."""
    return _check_or_write_csv(CSV, csv_text(), regenerate, GENERATOR_SEED)


def overfit_summary(comp) -> None:
    """Which structure each yardstick prefers: in-sample fit, evidence, held-out density."""
    rows = [r for r in comp.table() if not r.get("error")]
    by_fit = min(rows, key=lambda r: r["rmse"])
    by_z = max(rows, key=lambda r: r["log_evidence"] if r["log_evidence"] is not None
               else -np.inf)
    by_test = max(rows, key=lambda r: r["holdout_lpd"])
    print(f"\nSmallest in-sample RMSE: {by_fit['structure']} ({by_fit['n_params']} parameters); "
          f"highest ln Z: {by_z['structure']} ({by_z['n_params']}); highest held-out log "
          f"predictive density: {by_test['structure']} ({by_test['n_params']}).")


def main(argv=None) -> int:
    parser = make_parser(NAME, __doc__)
    parser.add_argument("--regenerate", action="store_true",
                        help=f"rewrite {CSV.name} from the generator")
    args = parser.parse_args(argv)

    for line in comment_lines(check_or_write_csv(args.regenerate))[3:]:
        print("  " + line)
    data = read_csv(CSV)  # the bundled file, exactly as `bayesfo compare` reads it
    holdout = [2 * np.pi * f for f in HOLDOUT_HZ]
    names = STRUCTURES_QUICK if args.quick else STRUCTURES_FULL
    comp = run_compare(data, resolve_structures(names), seed=args.seed, quick=args.quick,
                       workers=args.workers, holdout=holdout)

    print_table(comp, f"Ranking by ln Z (truth: {TRUTH['structure']}, q = {TRUTH['q']})")
    print_orders(comp)
    print_holdout(comp)
    overfit_summary(comp)
    save(comp, args.out, figures=not args.no_figures, quick=args.quick)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
