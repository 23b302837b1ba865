"""Parts of the adequacy check (:mod:`bayesfo.inference.adequacy`): its argument checks, and its
sentences (the reasons against adequacy, the caution of a pass that rests on noise-dominated
points)."""

from __future__ import annotations

import math
import numbers

import numpy as np

from ..errors import InputError
from .likelihood import Likelihood
from .results import PosteriorResult


def _p_text(p: float) -> str:
    return "p < 0.001" if p < 0.001 else f"p = {p:.3f}"


def _band_text(bands) -> str:
    return ", ".join(f"ω = {lo:.3g}–{hi:.3g} rad/s" for lo, hi, _ in bands)


def reasons(failed, p, stats, n, bands, implausible, noise_scale, noise,
             max_scale) -> tuple[str, ...]:
    out = []
    where = _band_text(bands)
    if "autocorrelation" in failed:
        out.append(f"residuals are correlated along frequency (lag-1 autocorrelation "
                   f"{stats['autocorrelation']:.2f}, {_p_text(p['autocorrelation'])}): the structure "
                   f"misses the shape" + (f" at {where}" if where else ""))
    if "scan" in failed:
        lo, hi, text = bands[0]
        out.append(f"{text} over ω = {lo:.3g}–{hi:.3g} rad/s more consistently than noise "
                   f"allows (scan statistic {stats['scan']:.1f}, {_p_text(p['scan'])})")
        out.extend(f"also {t} over ω = {lo:.3g}–{hi:.3g} rad/s" for lo, hi, t in bands[1:])
    if "chi2" in failed:
        out.append(f"residuals are larger than the noise model allows (Σ|r|²/σ² = "
                   f"{stats['chi2']:.0f} for {n} points, expected about {n}; {_p_text(p['chi2'])})")
    if implausible:
        what = "σ_rel" if noise in ("proportional", "relative_parts") else "σ / median |G|"
        out.append(f"the fitted noise scale is implausibly large ({what} = {noise_scale:.3g}, above "
                   f"{max_scale:g}): the structure's misfit is being absorbed as noise"
                   + (f", most clearly at {where}" if where and not failed else ""))
    return tuple(out)


def masked_text(omega, n: int, max_scale: float, phase_deg: float, log10_mag: float) -> str:
    """The caution of a pass that rests on noise-dominated points (:attr:`Adequacy.misfit_masked`):
    where they are, and by how much the posterior mode misses them."""
    where = (f"ω = {omega.min():.3g}–{omega.max():.3g} rad/s" if omega.size > 1
             else f"ω = {omega[0]:.3g} rad/s")
    return (f"at {where} ({omega.size} of {n} points) the fitted noise exceeds "
            f"{100 * max_scale:g} % of |G|, so the checks do not test the structure there, and "
            f"its posterior mode misses those points by up to {phase_deg:.1f}° in phase and "
            f"{100 * (10 ** log10_mag - 1):.0f} % in magnitude")


def check_args(lik, post, seed, level, n_draws, n_reference, max_noise_scale) -> None:
    if not isinstance(lik, Likelihood):
        raise InputError(f"argument 'lik' must be a Likelihood, got {type(lik).__name__}")
    if not isinstance(post, PosteriorResult):
        raise InputError(f"argument 'post' must be a PosteriorResult, got {type(post).__name__}")
    if tuple(post.param_names) != tuple(lik.param_names):
        raise InputError(
            f"argument 'post' does not belong to 'lik': its parameters are "
            f"{', '.join(post.param_names)}, the likelihood's {', '.join(lik.param_names)} "
            f"(structure {lik.structure.name}, noise {lik.noise})")
    samples = np.asarray(post.samples_scaled)
    if samples.ndim != 2 or samples.shape[1] != lik.ndim or samples.shape[0] == 0:
        raise InputError(f"argument 'post': samples_scaled must have shape (n_draws, {lik.ndim}), "
                         f"got {samples.shape}")
    for name, value, low in (("seed", seed, 0), ("n_draws", n_draws, 20),
                             ("n_reference", n_reference, 1000)):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral):
            raise InputError(f"argument '{name}' must be an integer, got {value!r}")
        if value < low:
            raise InputError(f"argument '{name}' must be at least {low}, got {value}")
    for name, value, ok, what in (
            ("level", level, lambda v: 0 < v <= 0.5, "in (0, 0.5]"),
            ("max_noise_scale", max_noise_scale, lambda v: v > 0, "positive")):
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise InputError(f"argument '{name}' must be a finite number, got {value!r}")
        if not ok(value):
            raise InputError(f"argument '{name}' must be {what}, got {value!r}")
