"""
The fractional order across temperature
=======================================

Three isotherms of the 3M 468MP adhesive (0, 20 and 40 °C), each compared on the fractional
Voigt model: how the posterior of its order q moves with temperature. ``bayesfo batch`` does
this for a whole directory of isotherms (:mod:`bayesfo.batch`), with a figure of q against
temperature; here the same from the flat API in a loop.
"""

# sphinx_gallery_start_ignore
import warnings

# sphinx_gallery_end_ignore
import matplotlib.pyplot as plt
import pandas as pd

import bayesfo as bf

# sphinx_gallery_start_ignore
# Warnings as one line, the way the command line prints them.
warnings.formatwarning = lambda message, category, *args, **kwargs: (
    f"{category.__name__}: {message}\n")
# sphinx_gallery_end_ignore
# The gallery runs in docs/gallery/; from the repository root: examples/data/adhesive_468mp/
rows = []
for celsius, stem in ((0, "Tp000C"), (20, "Tp020C"), (40, "Tp040C")):
    data = bf.read(f"../../examples/data/adhesive_468mp/{stem}.csv")
    result = bf.compare(data, "voigt", workers=1, progress=False)
    row = result.to_dataframe().iloc[0]
    rows.append({"T [C]": celsius, "q_mean": row["q_mean"], "q_sd": row["q_sd"],
                 "ln Z": row["log_evidence"], "fits": row["fits"]})
table = pd.DataFrame(rows)
print(table.to_string(index=False, float_format=lambda x: f"{x:.4f}"))

# %%
# q against temperature
# ---------------------
# Error bars are ± 2 posterior standard deviations. The Voigt model misses these precise data
# systematically at every temperature (``fits`` is ``no``), so q is an effective order over
# the measured band rather than a material constant; the first example compares structures.
fig, ax = plt.subplots(figsize=(5, 3.5), layout="constrained")
ax.errorbar(table["T [C]"], table["q_mean"], yerr=2 * table["q_sd"],
            fmt="o-", capsize=3)
ax.set_xlabel("temperature [°C]")
ax.set_ylabel("posterior mean of q (voigt)")
