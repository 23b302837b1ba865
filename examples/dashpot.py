"""Hydraulic dashpot: integrator-like data, compared without and with inverted structures.

The thesis (§4.3.4) found the open-loop position response of its dashpot to be integrator-like
(−20 dB per decade, phase near −90°, with an extra phase drop at the highest frequencies) and
could not fit it with structures whose denominator starts with a fixed 1; it therefore fitted the
reciprocal U/Y instead, and could not compare the inverted fits with the others because their
RMSEs live on different scales (Table 4.4). bayesfo evaluates an inverted structure as A/B against
the measured G itself, so both kinds stand on the same likelihood and evidence. This example
simulates data from the thesis' dashpot fit and ranks both kinds together.

Truth (see ``generate``): the thesis' best inverted fit, Table A.12, G_Zener, rows "Opt" and
"Int" (identical, q = 1), G(s) = (1 + b1 s)/(a0 + a1 s) with b = [1, −0.1908],
a = [−2.0973e3, 2.2762e5]. Read literally it has an unstable pole at +a0/a1 = 0.0092 rad/s
(below the measured band, 0.03–10 rad/s: the thesis had removed the stability constraint) and a
right-half-plane zero at 5.24 rad/s. We keep what the thesis reads off the data, an integrator
with gain 1/a1 and a phase lag of time constant T = |b1| = 0.1908 s, in the stable,
minimum-phase form of a valve-driven cylinder:

    G(s) = 1 / (a1 s (1 + T s)) = 1 / (b1' s + b2' s²),  b1' = 2.2762e5, b2' = a1·T = 4.3430e4,

i.e. ``max-n0m2-inv`` with b0 = 0 and q = 1 (its integer baseline ``max-n0m2-inv-int``). The
phase runs from −90.3° at 0.03 rad/s to −152° at 10 rad/s, as the thesis' model does; the units
are those of the thesis' fit (cylinder position per valve input; the thesis does not state them).

Measurement: 16 log-spaced frequencies over the open-loop band 0.03–10 rad/s (§4.2), ten
replicate series per frequency (as measured, §4.2) with circular complex noise of 10 % of |G|
each; the CSV holds the ten series (column ``series``) and bayesfo averages them, with σ the
standard error of the mean (about 3 %). The noise seed is fixed; for this truth, whose integrator
sits on the stability boundary (b0 = 0), about a third of the noise realisations put the
least-squares optimum of the inverted members just outside the stable region (b0 < 0, as in the
thesis' own fit with a0 < 0); bayesfo moves such an optimum onto the boundary before it starts
the sampler, so the posterior still starts at the mode of the data (checked on noise seeds 0–5).

Usage: python examples/dashpot.py [--quick] [--out DIR] [--seed N] [--regenerate]
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
    print_orders,
    print_table,
    run_compare,
    save,
)

from bayesfo import FrequencyResponse, read_csv
from bayesfo.structures import get_structure, resolve_structures

HERE = Path(__file__).resolve().parent
NAME = "dashpot"
CSV = HERE / "data" / "dashpot.csv"
OMEGA = np.logspace(np.log10(0.03), 1.0, 16)
N_SERIES = 10
REL_NOISE = 0.10
#: Table A.12, G_Zener, Opt/Int: denominator a = [a0, a1], numerator b = [1, b1], q = 1.
THESIS_A1, THESIS_B1 = 2.2762e5, -0.1908
#: max-n0m2-inv parameters (b0, b1, b2, q): 1/(b0 + b1 s^q + b2 s^2q).
TRUTH = {"structure": "max-n0m2-inv", "b0": 0.0, "b1": THESIS_A1,
         "b2": THESIS_A1 * abs(THESIS_B1), "q": 1.0}
GENERATOR_SEED = 7

INVERTED_FULL = "zener-inv,max-n0m1-inv,max-n0m2-inv,max-n1m2-inv,zener-inv-int,max-n0m2-inv-int"
PLAIN_FULL = "voigt,zener,maxwell,max-n1m0,max-n2m0,max-n2m1,voigt-int,zener-int,max-n2m0-int"
INVERTED_QUICK = "zener-inv,max-n0m2-inv-int"
PLAIN_QUICK = "voigt,zener,max-n2m0"


def truth_response(omega) -> np.ndarray:
    theta = [TRUTH["b0"], TRUTH["b1"], TRUTH["b2"], TRUTH["q"]]
    return get_structure(TRUTH["structure"]).response(theta, omega, "generic")


def generate_series(seed: int = GENERATOR_SEED) -> np.ndarray:
    """Ten replicate measurements, shape (N_SERIES, len(OMEGA))."""
    rng = np.random.default_rng(seed)
    g = truth_response(OMEGA)
    shape = (N_SERIES, OMEGA.size)
    return g * (1 + REL_NOISE / np.sqrt(2) * (rng.normal(size=shape) + 1j * rng.normal(size=shape)))


def generate(seed: int = GENERATOR_SEED) -> FrequencyResponse:
    """The averaged measurement (σ from the spread of the series), as read from the CSV."""
    return FrequencyResponse.from_replicates(OMEGA, generate_series(seed), kind="generic",
                                             name="dashpot open loop, simulated")


def csv_text(seed: int = GENERATOR_SEED) -> str:
    header = [
        "# name: dashpot open loop, simulated",
        "# kind: generic",
        "# Simulated position response of the thesis' hydraulic dashpot (open loop, valve input),",
        "#   from its best inverted fit (Table A.12, G_Zener, Opt/Int, q = 1): integrator gain",
        "#   1/a1 with a1 = 2.2762e5 and phase-lag time constant |b1| = 0.1908 s, in the stable",
        "#   minimum-phase form G(s) = 1/(a1 s (1 + 0.1908 s)) (structure max-n0m2-inv, b0 = 0,",
        "#   q = 1); units of the thesis' fit.",
        (f"# Frequencies: {OMEGA.size} log-spaced in the open-loop band 0.03-10 rad/s "
         "(thesis §4.2)."),
        (f"# {N_SERIES} replicate series (column 'series'), each with circular complex noise "
         f"of {REL_NOISE:.0%} of |G|;"),
        "#   bayesfo averages them and takes sigma as the standard error of the mean.",
        f"# Generator: examples/dashpot.py (generate_series(seed={seed}), numpy default_rng);",
        "#   python examples/dashpot.py --regenerate rewrites this file.",
        "omega,real,imag,series",
    ]
    rows = []
    for k, series in enumerate(generate_series(seed), start=1):
        rows += [f"{w!r},{g.real!r},{g.imag!r},{k}"
                 for w, g in zip(OMEGA.tolist(), series.tolist())]
    return "\n".join(header + rows) + "\n"


def check_or_write_csv(regenerate: bool) -> Path:
    """Write the CSV (``regenerate``), or check that the bundled file is the generator's."""
    return _check_or_write_csv(CSV, csv_text(), regenerate, GENERATOR_SEED)


def main(argv=None) -> int:
    parser = make_parser(NAME, __doc__)
    parser.add_argument("--regenerate", action="store_true",
                        help=f"rewrite {CSV.name} from the generator")
    args = parser.parse_args(argv)

    for line in comment_lines(check_or_write_csv(args.regenerate))[2:]:
        print("  " + line)
    data = read_csv(CSV)
    plain = (PLAIN_QUICK if args.quick else PLAIN_FULL).split(",")
    inverted = (INVERTED_QUICK if args.quick else INVERTED_FULL).split(",")
    comp = run_compare(data, resolve_structures(",".join(plain + inverted)), seed=args.seed,
                       quick=args.quick, workers=args.workers)

    print_table(comp, "Without inverted structures (as the thesis' first attempt):", names=plain)
    print_table(comp, f"With inverted structures (truth: {TRUTH['structure']} with q = 1, "
                      "i.e. max-n0m2-inv-int):")
    print_orders(comp)
    best_plain = next(n for n in comp.ranking if n in plain)
    best = comp.ranking[0]
    dz = (comp[best].criteria.evidence.log_z - comp[best_plain].criteria.evidence.log_z)
    print(f"\nBest structure: {best}; best without inversion: {best_plain}, "
          f"{dz:.1f} nats of ln Z below it.")
    save(comp, args.out, figures=not args.no_figures, quick=args.quick)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
