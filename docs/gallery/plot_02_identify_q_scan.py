"""
Deterministic identification: the q-grid scan
=============================================

Before any posterior, bayesfo fits each structure deterministically: the linear methods 1–5 of
the thesis with a scan over a grid of the commensurate order q, and a global optimisation
seeded by them (:mod:`bayesfo.identify`). Here on the bundled polypropylene compliance data
(simulated from the thesis' fitted fractional Voigt model, q = 0.698).
"""

import matplotlib.pyplot as plt
import numpy as np

import bayesfo as bf
from bayesfo.identify import identify, q_grid_scan

# The gallery runs in docs/gallery/; from the repository root: examples/data/pp_compliance.csv
data = bf.read("../../examples/data/pp_compliance.csv")
print(data.name, "|", data.n_frequencies, "frequencies |", data.kind,
      "in", data.units)

# %%
# RMSE against q for the linear methods
# -------------------------------------
# The fractional Voigt compliance b0 / (1 + a1 s^q) has n = 1, m = 0 in the thesis' notation.
# Method 1 is the output error, method 3 Levy with Sanathanan–Koerner iterations.
fig, ax = plt.subplots(figsize=(6, 3.5), layout="constrained")
for method in (1, 2, 3):
    scan = q_grid_scan(data, 1, 0, method)
    label = f"method {method} (best q = {scan.best.q:.2f})"
    ax.semilogy(scan.q_grid, scan.rmse, label=label)
ax.axvline(0.698, color="0.5", ls=":", label="q of the generating model")
ax.set_xlabel("q")
ax.set_ylabel("RMSE (eq. 3.23)")
ax.legend()

# %%
# The global optimisation
# -----------------------
# ``identify`` is what ``bayesfo identify`` runs: here the multi-start least squares on scaled
# data, which keeps only stable and dissipative optima.
voigt = bf.get_structure("voigt")
fit = identify(data, voigt, method="opt")
for name, value in fit["parameters"].items():
    print(f"{name} = {value:.4g}")
print(f"RMSE = {fit['rmse']:.3g}")

# %%
# The fitted response against the data
# ------------------------------------
# A :class:`~bayesfo.structures.Structure` evaluates vectorised: ``response(theta, omega,
# kind)`` with ``theta`` of shape (n_sets, n_params) returns (n_sets, n_freq) complex values.
omega = np.logspace(np.log10(data.omega.min()), np.log10(data.omega.max()), 200)
theta = [[fit["parameters"][name] for name in voigt.param_names]]
model = voigt.response(theta, omega, data.kind)[0]

fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6, 5),
                               layout="constrained")
ax1.loglog(data.omega, np.abs(data.response), "o", label="data")
ax1.loglog(omega, np.abs(model), label="voigt, optimised")
ax1.set_ylabel(f"|J| [{data.units}]")
ax1.legend()
ax2.semilogx(data.omega, np.degrees(np.angle(data.response)), "o")
ax2.semilogx(omega, np.degrees(np.angle(model)))
ax2.set_ylabel("phase [deg]")
ax2.set_xlabel("ω [rad/s]")
