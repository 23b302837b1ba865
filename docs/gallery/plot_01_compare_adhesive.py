"""
Which structure fits a pressure-sensitive adhesive?
===================================================

Compare the fractional Voigt and Zener models and the two-springpot fractional Kelvin–Voigt
model on the storage and loss modulus of the 3M 468MP adhesive at 20 °C (17 frequencies,
bundled with bayesfo; hermes-rheo, MIT License), with the flat API:
:func:`bayesfo.read <bayesfo.data.read>` and :func:`bayesfo.compare <bayesfo.comparison.compare>`.
"""

# %%
# Read the data
# -------------
# ``bf.read`` reads the bayesfo CSV and the exports of rheometers; the file says it holds a
# modulus in Pa. (The gallery runs in ``docs/gallery/``; from the repository root the path is
# ``examples/data/adhesive_468mp/Tp020C.csv``.)

# sphinx_gallery_start_ignore
import warnings

# sphinx_gallery_end_ignore
import bayesfo as bf
from bayesfo.plotting import plot_bode, plot_q_posteriors

# sphinx_gallery_start_ignore
# Warnings as one line, the way the command line prints them.
warnings.formatwarning = lambda message, category, *args, **kwargs: (
    f"{category.__name__}: {message}\n")
# sphinx_gallery_end_ignore
data = bf.read("../../examples/data/adhesive_468mp/Tp020C.csv")
print(data.name, "|", data.n_frequencies, "frequencies |", data.kind,
      "in", data.units)

# %%
# Compare three structures
# ------------------------
# Each structure gets a global least-squares fit, a certified posterior, the log-evidence
# ln Z, PSIS-LOO and the information criteria, and posterior predictive checks of whether it
# describes the data at all (``fits``). ``workers=1`` runs in this process. The warnings are
# the comparison's flags on these precise real data.
structures = "voigt,zener,fractional_kelvin_voigt"
result = bf.compare(data, structures, workers=1, progress=False)
print("ranking by ln Z:", result.ranking)

table = result.to_dataframe()
columns = {"structure": "structure", "log_evidence": "ln Z",
           "posterior_probability": "P", "loo": "elpd_loo", "q_mean": "q",
           "fits": "fits"}
shown = table[list(columns)].rename(columns=columns)
print(shown.to_string(index=False, float_format=lambda x: f"{x:.3f}"))

# %%
# The two-springpot model wins by tens of nats. ``fits`` says that no structure reproduces
# these data within their noise: Voigt and Zener miss them systematically (``no``), the
# winner by less than 2° in phase and 3.5 % in magnitude (``small``).

# %%
# The winner's physical parameters
# --------------------------------
# Each :class:`~bayesfo.comparison.StructureResult` holds the posterior summary of every
# parameter in physical units; the table gives the posterior medians with their units.
best = result[result.ranking[0]]
row = table.loc[table["structure"] == best.name].iloc[0]
print(best.name)
print("\n".join(row["physical_parameters"].split("; ")))

# %%
# Bode plot
# ---------
# Data and the posterior predictive median with 50 % and 90 % bands of each structure.
drawn = plot_bode(result)

# %%
# The posterior of the fractional order
# -------------------------------------
# One ridge per structure, best on top; the dashed line is the prior. The bar is the 94 %
# HDI.
drawn = plot_q_posteriors(result)
