"""Captions that state what each figure shows for the structure and data it was drawn from.

A fixed caption can claim what a figure does not show ("well-mixed walkers overlap and show no
trend" under walkers that did not converge). These captions are built from the same results as
the figures: the sampler that produced the draws, whether they converged and by how much they
missed the targets, the form of the Nyquist diagram. No matplotlib: the report imports them.

Examples
--------
>>> figure_caption("trace_voigt", comparison)            # doctest: +SKIP
'Walker traces of voigt after burn-in: the walkers overlap and show no trend (R-hat 1.002, ...'
"""

from __future__ import annotations

import math
import re

from ..data.symbols import in_symbol
from ._compute import (
    NYQUIST_LOG_DECADES,
    ORDER_STRUCTURES,
    RANKING_SHOWN,
    magnitude_decades,
    natural_coordinates,
)

#: Convergence targets of the sampler (as :mod:`bayesfo.inference.results`).
RHAT_TARGET = 1.01
ESS_TARGET = 400
PARETO_K_WARN = 0.7


def file_stem(name: str) -> str:
    """The part of a figure's file name that names a structure (unsafe characters as ``_``)."""
    return re.sub(r"[^A-Za-z0-9._-]", "_", name)


def _diagnostics(post) -> str:
    return f"R-hat {post.rhat_max:.3f}, ESS {post.ess_min:.0f}"


def _misses(post) -> str:
    """Which convergence target the draws miss, and what that looks like in a trace."""
    parts = []
    if not (math.isfinite(post.rhat_max) and post.rhat_max < RHAT_TARGET):
        parts.append(f"R-hat {post.rhat_max:.3f} is not below {RHAT_TARGET}: the walkers "
                     "disagree (separate bands or a drift)")
    if not (math.isfinite(post.ess_min) and post.ess_min >= ESS_TARGET):
        parts.append(f"ESS {post.ess_min:.0f} is below {ESS_TARGET}: the walkers move slowly, "
                     "so few draws are independent")
    return "; ".join(parts) or _diagnostics(post)


def trace_caption(result) -> str:
    """Caption of :func:`~bayesfo.plotting.plot_trace` for ``result``: what the panels are
    (walker traces, or histograms where there is no chain) and what they show here."""
    post = result.posterior
    name = result.name
    sampler = getattr(post, "sampler", "emcee")
    if sampler == "importance":
        return (f"Posterior draws of {name} resampled from importance weights (ESS "
                f"{post.ess_min:.0f}; no chain to trace): the marginal of each parameter"
                + ("." if post.converged else "; the weights do not certify this posterior."))
    if sampler == "ladder":
        return (f"Particles of {name} from {post.n_walkers} independent tempered-ladder runs, one "
                "histogram per run: "
                + ("they agree, which certifies the posterior" if post.converged else
                   "they disagree, so the posterior is not certified")
                + f" ({_diagnostics(post)}).")
    if post.converged:
        return (f"Walker traces of {name} after burn-in: the walkers overlap and show no trend "
                f"({_diagnostics(post)}).")
    return (f"Walker traces of {name} after burn-in: NOT converged ({_misses(post)}); its "
            "posterior, ln Z and ranking are flagged as unreliable.")


def corner_caption(result) -> str:
    """Caption of :func:`~bayesfo.plotting.plot_corner` for ``result``."""
    post = result.posterior
    coords = natural_coordinates(result)
    form = ("the physical parameters and the noise; log10 of those that are positive"
            if coords.physical else "log10 of parameters with a log-uniform prior")
    text = (f"Posterior of {result.name}: marginal and pairwise distributions of "
            f"{len(coords.names)} parameters ({form}; contours hold 50 % and 90 %), with the "
            "posterior mode"
            + (" and the least-squares optimum" if result.fit is not None
               and getattr(result.fit, "admissible", False) else "") + ".")
    if not post.converged:
        text += f" The draws did not converge ({_diagnostics(post)}): the shapes are unreliable."
    return text


def nyquist_form(comparison) -> str:
    """``"log"`` or ``"linear"``: the form :func:`~bayesfo.plotting.plot_nyquist` chooses."""
    holdout = comparison.holdout
    decades = magnitude_decades(comparison.data.response,
                                None if holdout is None else holdout.response)
    return "log" if decades > NYQUIST_LOG_DECADES else "linear"


def figure_caption(name: str, comparison) -> str | None:
    """The caption of the figure ``name`` of :func:`~bayesfo.plotting.write_figures` drawn from
    ``comparison`` (``corner_<structure>`` and ``trace_<structure>`` by the structure's file
    stem), or None for a name it does not know. The response's symbols follow the data's
    (E′, E″, E(t), D(t) for tensile data, :attr:`~bayesfo.data.FrequencyResponse.symbol`)."""
    text = _combined_caption(name, comparison)
    if text is not None:
        return in_symbol(text, getattr(comparison.data, "symbol", "G"))
    return _structure_caption(name, comparison)


def _combined_caption(name: str, comparison) -> str | None:
    """The caption of a figure of the whole comparison, written for shear data."""
    if name == "ranking":
        return ("Log-evidence (top) and information criteria (bottom) relative to the best "
                "structure, in nats, higher is better; posterior probabilities right of the "
                "evidence, the largest Pareto k̂ of PSIS-LOO right of the criteria (above "
                f"{PARETO_K_WARN}: PSIS-LOO unreliable, open marker); red labels: posterior not "
                "converged. WAIC is not shown: it estimates the same as PSIS-LOO without a "
                f"diagnostic of its own. At most the best {RANKING_SHOWN} structures are "
                "drawn; the rest are named under the figure and ranked in the table.")
    if name == "bode":
        return ("Magnitude and phase of the data (± 1 sd where σ is known) with each "
                "structure's posterior median response (one line style per structure) and its "
                "50 % and 90 % credible bands; the legend names structures whose curves "
                "coincide and marks those the posterior predictive checks reject (misfits).")
    if name == "moduli":
        storage, loss = ("J′", "J″") if comparison.data.kind == "compliance" else ("G′", "G″")
        return (f"Storage part {storage}, loss part {loss} and loss tangent tan δ = "
                f"{loss}/{storage} of the data (± 1 sd) with each structure's posterior median "
                "and its 50 % and 90 % credible bands, on logarithmic axes (values that are not "
                "positive are left out, and the legend says how many).")
    if name == "time_functions":
        return ("Relaxation modulus G(t) and creep compliance J(t) of each structure's posterior "
                "(median, 50 % and 90 % credible bands), from the inverse Laplace transform of "
                "the model; the data inform about t between 1/ω_max and 1/ω_min, and the hatched "
                "stretches beyond are extrapolation. 'bayesfo predict' gives the numbers.")
    if name == "nyquist":
        if nyquist_form(comparison) == "log":
            return ("The same in the complex plane, log-magnitude form (|G| spans more than "
                    f"{NYQUIST_LOG_DECADES:g} decades): angle arg G, radius log10 |G|; "
                    "posterior median curve and single posterior draws (thin lines).")
        return ("The same in the complex plane (linear axes): posterior median curve and "
                "single posterior draws (thin lines).")
    if name == "residuals":
        return ("Residuals of the data from the posterior median prediction, real and "
                "imaginary parts, normalised by the noise (or relative to |G|); one marker per "
                "structure, offset slightly along ω.")
    if name == "q_posteriors":
        return ("Posterior density of the fractional order per structure (best on top), with "
                "the prior (dashed), the 94 % HDI (bar) and the mean (tick); orders determined "
                "too sharply to see at this scale are zoomed in an inset; the orders of at "
                f"most the best {ORDER_STRUCTURES} structures with a free order are drawn.")
    return None


def _structure_caption(name: str, comparison) -> str | None:
    """The caption of a structure's corner or trace figure."""
    kind, _, stem = name.partition("_")
    by_stem = {file_stem(r.name): r for r in comparison.results
               if r.error is None and r.posterior is not None}
    result = by_stem.get(stem)
    if result is None or result.posterior is None:
        return None
    if kind == "trace":
        return trace_caption(result)
    if kind == "corner":
        return corner_caption(result)
    return None
