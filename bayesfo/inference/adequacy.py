"""Posterior predictive adequacy checks: does a structure describe the data at all?

The log-evidence and the information criteria rank structures against each other; they never say
whether any of them describes the data. A structure that misses the shape of G(jω) can still win
"very strongly" against worse ones, and with a sampled noise scale (``constant``,
``proportional``) the misfit is simply absorbed into a large σ. :func:`check_adequacy` asks the
absolute question with posterior predictive checks (Gelman, Meng & Stern 1996): for posterior
draws θ_s, replicated data y_rep are simulated from the likelihood's own noise model at θ_s, and a
discrepancy T(y, θ_s) of the data is compared with T(y_rep, θ_s),

    p = Pr(T(y_rep, θ) ≥ T(y, θ) | y).

Residuals
---------
Every statistic is a function of the normalised residuals of the points ordered by frequency,

    z_k = √2 (G_k − Ĝ_k(θ)) / σ_k · conj(Ĝ_k) / |Ĝ_k|,

whose real part is the residual along the model's magnitude (≈ √2 Δln|G| / σ_rel) and whose
imaginary part the residual along its phase (≈ √2 Δφ / σ_rel). Under the likelihood's circular
complex noise both parts are independent standard normal whatever θ, because σ_k is the one the
likelihood uses (``known``: from the data; ``constant``: σ; ``proportional``: σ_rel·|G_k| with
the data's |G_k|) and a rotation keeps circular noise circular.

``relative_parts`` noise is not circular (σ_rel·|Re G_k| and σ_rel·|Im G_k| on the two parts),
so a rotation would mix parts of different variance: its residuals are the relative residuals of
the parts themselves, a_k = ΔRe_k / (σ_rel Re G_k) and b_k = ΔIm_k / (σ_rel Im G_k), again
independent standard normal under the model (positive where the data's part is larger in
magnitude than the fit's), and the statistics below apply to them unchanged, with "magnitude
part" and "phase part" read as "real part" and "imaginary part".

Statistics
----------
``chi2``
    Σ_k |G_k − Ĝ_k|² / σ_k², mean n under the model: residuals larger than the noise allows.
    Powerful when σ is known; with a sampled σ it is near its mean by construction (the misfit
    goes into σ, which :attr:`Adequacy.noise_scale_implausible` catches instead).
``autocorrelation``
    Lag-1 autocorrelation of the residuals along frequency, magnitude and phase parts pooled,
    Σ_k Re(z_k conj z_{k+1}) / Σ_k |z_k|². Scale-free, so a large fitted σ does not hide it: a
    structure that misses the shape leaves residuals that vary smoothly with ω.
``scan``
    The largest |Σ_{k∈W} Re z_k| / √|W| or |Σ_{k∈W} Im z_k| / √|W| over windows W of at least
    three consecutive frequencies: a band where the magnitude (or the phase) of the data stays on
    one side of the fit. The windows where it exceeds its critical value are the band reported in
    :attr:`Adequacy.systematic_at_omega`.

Reference distribution
----------------------
Replicated data y_rep = Ĝ(θ_s) + ε_s·σ at a draw θ_s have normalised residuals at θ_s that are
the unit normal draws ε_s themselves (rotated by a phase factor, which keeps them unit normal):
T(y_rep, θ_s) has one distribution for every draw (the statistics are pivotal). The module
therefore simulates the reference from the unit normal draws directly, ``n_reference`` replicated
data sets pooled over all draws, and p is the posterior mean over the draws of
(1 + #{T_rep ≥ T(y, θ_s)}) / (1 + n_reference): the same expectation as the per-draw fraction,
with a resolution of 1/n_reference instead of 1/n_draws (5·10⁻⁵ by default, well below the
per-statistic level of 0.0033), and one sort per statistic instead of a simulation per draw.
(The replicated data themselves are formed, five per draw, only for the predictive band of
:attr:`Adequacy.outside_band_omega`.)

Level
-----
``LEVEL = 0.01`` per structure and data set, for the family of the three statistics (Bonferroni:
each p is compared with 0.01/3). It sets the false-alarm rate on data that the structure
generated: at most 1 % of such data sets are called inadequate (fewer in practice: posterior
predictive p-values are conservative, since the draws have been fitted to the data they are
compared with; Bayarri & Berger 2000). 1 % rather than 5 %: the check runs on every structure of
every comparison, six structures on a batch of ten isotherms is sixty checks, and 5 % would
flag three adequate fits by chance in every such batch; misfits that matter in practice (a phase
missed by several degrees at 1 % noise) give p below 10⁻⁴, so the stricter level costs little
power.

Size of the misfit
------------------
Real data are often so precise that every structure fails the checks although some miss the
data by a degree or a per cent (the residuals are smooth, not noise-like). The check does not
hide that, but it says how large the misfit is: the largest phase and log10-magnitude errors of
the posterior mode, and :attr:`Adequacy.misfit_small` when they are within ``SMALL_MISFIT``
(2°, 0.015 in log10 |G| = 3.5 %) and the noise scale is plausible.

Noise scale
-----------
When the noise scale is sampled, a structure that misses the shape fits a large σ and the
misfit looks like noise. A posterior median σ_rel above ``max_noise_scale`` (0.1: rheometers
and dynamic analysers give a few per cent), or a constant σ above ``max_noise_scale`` times the
median |G|, counts against adequacy.

A constant σ that is plausible on the median |G| can still swamp the points of smallest |G|
(a modulus that spans two decades, fitted with σ = 5 % of its median, has noise of 70 % at its
lowest point): there a misfit of tens of per cent looks like noise to every statistic. Such
points are listed (``noise_dominated_omega``: the noise's standard deviation above
``max_noise_scale`` of |G|), and a pass where the posterior mode misses them by more than
``SMALL_MISFIT`` is marked ``misfit_masked``: the structure describes the rest of the data, and
the noise model says those points carry no information; whether they do is for the user (or the
evidence of the other noise model) to say.

References
----------
Gelman, A., Meng, X.-L., Stern, H. (1996). Posterior predictive assessment of model fitness via
realized discrepancies. Statistica Sinica 6, 733–807.
Bayarri, M. J., Berger, J. O. (2000). P values for composite null models. JASA 95, 1127–1142.
Kulldorff, M. (1997). A spatial scan statistic. Commun. Statist. Theory Meth. 26, 1481–1496.

The argument checks and the sentences of the verdict are in
:mod:`bayesfo.inference._adequacy_parts`.
"""

from __future__ import annotations

import functools
import json
import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from . import _adequacy_parts as _parts
from .likelihood import Likelihood
from .results import PosteriorResult

#: Family-wise level of the checks (see the module docstring).
LEVEL = 0.01
#: Posterior draws at which the data's discrepancies are evaluated.
N_DRAWS = 400
#: Replicated data sets in the pooled reference distribution.
N_REFERENCE = 20_000
#: Largest plausible relative noise scale (σ_rel, or constant σ over the median |G|).
MAX_NOISE_SCALE = 0.1
#: Shortest window of the scan statistic: a systematic misfit spans several frequencies.
MIN_WINDOW = 3
#: Largest number of separate bands reported.
MAX_BANDS = 3
#: Central probability of the posterior predictive band (``outside_band_omega``).
BAND_PROB = 0.94
#: Replicated data sets per draw for that band.
REPLICATES_PER_DRAW = 5
#: A misfit of the posterior mode within these (phase [degrees], log10 |G|) is "small": it does
#: not show on a Bode plot, and it is within the between-loading reproducibility of dynamic
#: mechanical measurements (a few per cent in modulus, a degree or two in phase).
SMALL_MISFIT = (2.0, 0.015)

STATISTICS = ("chi2", "autocorrelation", "scan")


@dataclass(frozen=True)
class Adequacy:
    """Result of :func:`check_adequacy` for one structure on one data set.

    Attributes
    ----------
    adequate : bool
        No p-value below ``level / len(p_values)`` (Bonferroni) and a plausible noise scale.
    p_values : dict
        Posterior predictive p-value of each statistic (``chi2``, ``autocorrelation``,
        ``scan``); small means the data are more extreme than the structure's replicates.
    statistics : dict
        Posterior median of each statistic on the data (``chi2`` has mean n under the model,
        ``autocorrelation`` about 0, ``scan`` about 2–3).
    level : float
        Family-wise level.
    max_phase_error_deg, max_phase_error_omega : float
        Largest |arg(G_k / Ĝ_k)| of the posterior mode's response [degrees], and its ω [rad/s].
    max_log10_magnitude_error, max_log10_magnitude_error_omega : float
        Largest |log10 |G_k / Ĝ_k|| of the posterior mode's response, and its ω [rad/s].
    systematic_at_omega : tuple of float
        Frequencies [rad/s] of the bands where the misfit is systematic (empty when adequate):
        windows where the posterior median scan statistic exceeds its critical value, the
        strongest first and without overlaps; when the check fails for another reason and no
        window does, the window with the largest scan statistic.
    systematic_bands : tuple of (float, float, str)
        The same bands as (ω_low, ω_high, description).
    outside_band_omega : tuple of float
        Frequencies where the data lie outside the central ``BAND_PROB`` posterior predictive
        band of log10 |G| or of the phase (expect about 6 % of the points by chance).
    noise : str
        The noise model of the likelihood.
    noise_scale : float or None
        Posterior median of σ_rel (``proportional``, ``relative_parts``) or of σ / median |G|
        (``constant``); None when σ is known.
    noise_scale_implausible : bool
        ``noise_scale`` above ``max_noise_scale``.
    misfit_small : bool
        The posterior mode misses the data by at most ``SMALL_MISFIT`` (2° in phase, 0.015 in
        log10 |G|) and the noise scale is plausible: when not ``adequate``, a systematic misfit
        that is small in practice.
    noise_dominated_omega : tuple of float
        Frequencies where the sampled noise (posterior median of its standard deviation) exceeds
        ``max_noise_scale`` times the data's |G|: the checks hardly test the structure there.
        Empty when σ is known. Under ``constant`` noise these are the points of smallest |G|.
    misfit_masked : bool
        ``adequate``, but the posterior mode misses the noise-dominated points by more than
        ``SMALL_MISFIT``: the pass rests on a noise scale that swamps part of the data.
    masked_phase_error_deg, masked_log10_magnitude_error : float
        The posterior mode's largest misfit at the noise-dominated points (0 when there are
        none).
    caution : str
        When ``misfit_masked``, where the noise-dominated points are and by how much the mode
        misses them, in words; else empty.
    reasons : tuple of str
        Plain-language reasons against adequacy (empty when adequate).
    summary : str
        A one-sentence verdict.
    n_draws, n_reference, seed : int
        Posterior draws used, replicated data sets in the reference, the seed.
    """

    adequate: bool
    p_values: dict
    statistics: dict
    level: float
    max_phase_error_deg: float
    max_phase_error_omega: float
    max_log10_magnitude_error: float
    max_log10_magnitude_error_omega: float
    systematic_at_omega: tuple[float, ...]
    systematic_bands: tuple[tuple[float, float, str], ...]
    outside_band_omega: tuple[float, ...]
    noise: str
    noise_scale: float | None
    noise_scale_implausible: bool
    misfit_small: bool
    reasons: tuple[str, ...]
    summary: str
    n_draws: int
    n_reference: int
    seed: int
    noise_dominated_omega: tuple[float, ...] = ()
    misfit_masked: bool = False
    masked_phase_error_deg: float = 0.0
    masked_log10_magnitude_error: float = 0.0
    caution: str = ""

    def to_dict(self) -> dict:
        """The JSON block of ``summary.json``: finite numbers, None for anything else."""
        return {
            "adequate": bool(self.adequate),
            "level": _finite(self.level),
            "p_values": {k: _finite(v) for k, v in self.p_values.items()},
            "statistics": {k: _finite(v) for k, v in self.statistics.items()},
            "max_phase_error_deg": _finite(self.max_phase_error_deg),
            "max_phase_error_omega": _finite(self.max_phase_error_omega),
            "max_log10_magnitude_error": _finite(self.max_log10_magnitude_error),
            "max_log10_magnitude_error_omega": _finite(self.max_log10_magnitude_error_omega),
            "systematic_at_omega": [_finite(w) for w in self.systematic_at_omega],
            "systematic_bands": [{"omega_low": _finite(lo), "omega_high": _finite(hi),
                                  "description": text}
                                 for lo, hi, text in self.systematic_bands],
            "outside_band_omega": [_finite(w) for w in self.outside_band_omega],
            "noise": self.noise,
            "noise_scale": _finite(self.noise_scale),
            "noise_scale_implausible": bool(self.noise_scale_implausible),
            "misfit_small": bool(self.misfit_small),
            "reasons": list(self.reasons),
            "summary": self.summary,
            "n_draws": int(self.n_draws),
            "n_reference": int(self.n_reference),
            "seed": int(self.seed),
            "noise_dominated_omega": [_finite(w) for w in self.noise_dominated_omega],
            "misfit_masked": bool(self.misfit_masked),
            "masked_phase_error_deg": _finite(self.masked_phase_error_deg),
            "masked_log10_magnitude_error": _finite(self.masked_log10_magnitude_error),
            "caution": self.caution,
        }


def _finite(x):
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


# ---------------------------------------------------------------------- statistics
# Residuals are carried as a pair of real arrays (magnitude part, phase part), shape
# (n_sets, n_freq) each, with unit variance under the model.
def _chi2(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # The parts carry a factor √2: (a² + b²)/2 = |G − Ĝ|²/σ².
    return 0.5 * np.sum(a * a + b * b, axis=-1)


def _autocorrelation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    # Not centred: an offset of all residuals is a misfit too, and under the model the mean is 0.
    num = np.sum(a[:, :-1] * a[:, 1:] + b[:, :-1] * b[:, 1:], axis=-1)
    den = np.sum(a * a + b * b, axis=-1)
    return num / np.where(den > 0, den, 1.0)


def _widths(n: int) -> np.ndarray:
    """Window widths of the scan: every width up to 6, then growing by a quarter (a band of
    width w is caught by a window within 25 % of it at little loss, and the cost grows as
    n·log n instead of n²)."""
    out, w = [], min(MIN_WINDOW, n)
    while w <= n:
        out.append(w)
        w = w + 1 if w < 6 else int(math.ceil(1.25 * w))
    if out[-1] != n:
        out.append(n)
    return np.array(out)


def _scan(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """max over windows and both parts of |window sum| / √width; a loop over widths keeps the
    memory at one (N, n) array for the large reference."""
    out = np.zeros(a.shape[0])
    for part in (a, b):
        c = np.zeros((part.shape[0], part.shape[1] + 1))
        np.cumsum(part, axis=1, out=c[:, 1:])
        for w in _widths(part.shape[1]):
            s = np.abs(c[:, w:] - c[:, :-w]).max(axis=1) * (1.0 / math.sqrt(w))
            np.maximum(out, s, out=out)
    return out


def _windows(n: int) -> tuple[np.ndarray, np.ndarray]:
    start, width = zip(*[(i, w) for w in _widths(n) for i in range(n - w + 1)])
    return np.array(start), np.array(width)


def _scan_windows(a, b, start, width) -> np.ndarray:
    """Signed window sums / √width, shape (2, n_sets, n_windows): [magnitude part, phase part]."""
    out = []
    for part in (a, b):
        c = np.concatenate([np.zeros((part.shape[0], 1)), np.cumsum(part, axis=1)], axis=1)
        out.append((c[:, start + width] - c[:, start]) / np.sqrt(width))
    return np.stack(out)


_STAT_FUNCS = {"chi2": _chi2, "autocorrelation": _autocorrelation, "scan": _scan}


def _normalised(y, model, sd) -> tuple[np.ndarray, np.ndarray]:
    """(magnitude part, phase part) of √2 (y − Ĝ)/σ rotated onto the direction of Ĝ."""
    mag = np.abs(model)
    rot = np.where(mag > 0, np.conj(model) / np.where(mag > 0, mag, 1.0), 1.0)
    z = math.sqrt(2.0) * (y - model) / sd * rot
    return z.real, z.imag


def _normalised_parts(y, model, sd) -> tuple[np.ndarray, np.ndarray]:
    """(real part, imaginary part) of the residuals under ``relative_parts`` noise: each part's
    residual over its own standard deviation ``sd`` (complex: Re, Im), signed by the data's part
    so that positive means larger in magnitude than the fit."""
    d = y - model
    return (d.real / sd.real * np.sign(y.real), d.imag / sd.imag * np.sign(y.imag))


def _noise_sd(lik: Likelihood, theta: np.ndarray) -> np.ndarray:
    """σ_k of every draw on the scaled problem, shape (n_sets, n_freq), as the likelihood forms
    it. Under ``relative_parts`` a complex array: the standard deviation of the real part in its
    real part, that of the imaginary part in its imaginary part."""
    n = lik.g_scaled.size
    if lik.noise == "known":
        return np.broadcast_to(lik.data.sigma / lik.scaling.g_ref, (theta.shape[0], n))
    s = theta[:, -1:]
    if lik.noise == "constant":
        return np.broadcast_to(s, (theta.shape[0], n))
    if lik.noise == "relative_parts":
        g = lik.g_scaled[None, :]
        return s * np.abs(g.real) + 1j * (s * np.abs(g.imag))
    return s * np.abs(lik.g_scaled)[None, :]


#: The reference distributions kept (:func:`_drawn`), by the generator's state.
REFERENCES_KEPT = 4


def _reference(rng: np.random.Generator, n_reference: int, n: int) -> dict:
    """The sorted reference distribution of each statistic: its value on ``n_reference`` data
    sets of ``n`` unit normal residual pairs drawn from ``rng``, which is left as the draws
    leave it.

    The residuals depend on nothing but the generator's state, which the structures of one
    comparison share (the same seed, and as many posterior draws): the last
    :data:`REFERENCES_KEPT` are kept by that state, with the state the draws leave, and given
    again without drawing (the same numbers)."""
    values, after = _drawn(json.dumps(rng.bit_generator.state), n_reference, n)
    rng.bit_generator.state = after
    return dict(values)


@functools.lru_cache(maxsize=REFERENCES_KEPT)
def _drawn(state: str, n_reference: int, n: int) -> tuple[dict, dict]:
    rng = np.random.default_rng()
    rng.bit_generator.state = json.loads(state)
    a_rep, b_rep = rng.normal(size=(2, n_reference, n))
    values = {name: np.sort(_STAT_FUNCS[name](a_rep, b_rep)) for name in STATISTICS}
    for v in values.values():
        v.flags.writeable = False
    return values, rng.bit_generator.state


# ---------------------------------------------------------------------- the check
def check_adequacy(lik: Likelihood, post: PosteriorResult, *, seed: int = 0, level: float = LEVEL,
                   n_draws: int = N_DRAWS, n_reference: int = N_REFERENCE,
                   max_noise_scale: float = MAX_NOISE_SCALE) -> Adequacy:
    """Posterior predictive checks of whether ``post``'s structure describes ``lik``'s data.

    Parameters
    ----------
    lik : Likelihood
        The likelihood the posterior was sampled with (same structure, data, noise model and
        scaling).
    post : PosteriorResult
        Its posterior; ``post.samples_scaled`` are the draws on ``lik``'s scaled problem.
    seed : int
        Seeds the choice of draws and the replicated data; the same seed gives the same numbers.
    level : float
        Family-wise level, in (0, 0.5]: each of the three p-values is compared with
        ``level / 3``.
    n_draws : int
        Posterior draws used (at least 20; all of them if fewer are available).
    n_reference : int
        Replicated data sets in the pooled reference distribution (at least 1 000).
    max_noise_scale : float
        Largest plausible σ_rel (or constant σ over the median |G|) when σ is sampled.

    Returns
    -------
    Adequacy

    Raises
    ------
    InputError
        If an argument has the wrong type or range, the posterior does not belong to the
        likelihood (parameter names, dimensions), the data have fewer than four frequencies, or
        no draw gives a finite response.

    References
    ----------
    Gelman, Meng & Stern (1996), realized discrepancies; Kulldorff (1997), scan statistics.

    Examples
    --------
    >>> from bayesfo.inference.adequacy import check_adequacy        # doctest: +SKIP
    >>> result = check_adequacy(lik, post, seed=1)                    # doctest: +SKIP
    >>> result.adequate, result.p_values["autocorrelation"]           # doctest: +SKIP
    (True, 0.41)
    """
    _parts.check_args(lik, post, seed, level, n_draws, n_reference, max_noise_scale)
    rng = np.random.default_rng(seed)
    n = lik.g_scaled.size
    if n < 4:
        raise InputError(f"the adequacy check needs at least 4 frequencies, {lik.data.where()} has {n}")
    order = np.argsort(lik.data.omega)
    omega = lik.data.omega[order]
    g = lik.g_scaled[order]

    draws = np.asarray(post.samples_scaled, dtype=float)
    draws = draws[np.all(np.isfinite(draws), axis=1)]
    if draws.shape[0] > n_draws:
        draws = draws[np.sort(rng.choice(draws.shape[0], n_draws, replace=False))]
    model = lik.model(draws)[:, order]
    sd = _noise_sd(lik, draws)[:, order]
    parts = lik.noise == "relative_parts"
    sd_ok = ((sd.real > 0) & (sd.imag > 0)) if parts else (sd > 0)
    ok = np.all(np.isfinite(model), axis=1) & np.all(np.isfinite(sd) & sd_ok, axis=1)
    if not ok.any():
        raise InputError(f"argument 'post': no posterior draw of '{post.structure}' gives a finite "
                         "response and noise scale")
    draws, model, sd = draws[ok], model[ok], sd[ok]
    n_used = draws.shape[0]

    # Replicated data y_rep = Ĝ(θ_s) + noise at θ_s. Their normalised residuals at θ_s are the
    # unit normal draws themselves, rotated by a phase factor that leaves them unit normal: the
    # reference of every statistic is simulated from those draws directly (n_reference data
    # sets), and y_rep itself is formed only for the predictive band (REPLICATES_PER_DRAW each).
    reference = _reference(rng, n_reference, n)
    a_obs, b_obs = (_normalised_parts if parts else _normalised)(g[None, :], model, sd)

    p_values, statistics = {}, {}
    for name in STATISTICS:
        t_rep = reference[name]
        t_obs = _STAT_FUNCS[name](a_obs, b_obs)
        exceed = t_rep.size - np.searchsorted(t_rep, t_obs, side="left")
        p_values[name] = float(np.mean((1.0 + exceed) / (1.0 + t_rep.size)))
        statistics[name] = float(np.median(t_obs))
    per_stat = level / len(STATISTICS)
    failed = [name for name in STATISTICS if p_values[name] < per_stat]

    # Noise scale on the scaled problem: σ_rel is scale-free; the constant σ is in units of
    # g_ref, the median |G|.
    noise_scale = None if lik.noise == "known" else float(np.median(draws[:, -1]))
    implausible = noise_scale is not None and noise_scale > max_noise_scale

    # Misfit of the posterior mode's response: the shape a reader sees on the Bode plot.
    k = lik.structure.n_params
    mode = lik.to_scaled(np.asarray(post.map_theta, dtype=float)[None, :])
    m_map = lik.structure.response(mode[:, :k], lik.omega_scaled, lik.data.kind)[0][order]
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = g / m_map
    phase_err = np.degrees(np.angle(ratio))
    mag_err = np.log10(np.abs(ratio))
    i_ph = int(np.nanargmax(np.abs(phase_err))) if np.any(np.isfinite(phase_err)) else 0
    i_mag = int(np.nanargmax(np.abs(mag_err))) if np.any(np.isfinite(mag_err)) else 0

    which = np.repeat(np.arange(n_used), REPLICATES_PER_DRAW)
    eps = rng.normal(size=(2, which.size, n)) / math.sqrt(2.0)
    if parts:  # each part with its own standard deviation (eps carries 1/√2)
        y_rep = model[which] + math.sqrt(2.0) * (sd[which].real * eps[0]
                                                 + 1j * sd[which].imag * eps[1])
    else:
        y_rep = model[which] + sd[which] * (eps[0] + 1j * eps[1])
    outside = _outside_band(g, y_rep, m_map)
    adequate = not failed and not implausible
    bands = ()
    if not adequate:
        crit = float(np.quantile(reference["scan"], 1.0 - per_stat))
        bands = _bands(a_obs, b_obs, omega, crit, parts)
    systematic = tuple(float(w) for lo, hi, _ in bands for w in omega[(omega >= lo) & (omega <= hi)])
    systematic = tuple(sorted(set(systematic)))
    reasons = _parts.reasons(failed, p_values, statistics, n, bands, implausible, noise_scale,
                       lik.noise, max_noise_scale)
    if reasons:
        reasons += (f"largest misfit of the posterior mode: {abs(phase_err[i_ph]):.1f}° in phase "
                    f"at ω = {omega[i_ph]:.3g} rad/s, {abs(mag_err[i_mag]):.2f} in log10 |G| "
                    f"({100 * (10 ** abs(mag_err[i_mag]) - 1):.0f} %) at ω = {omega[i_mag]:.3g} rad/s",)
    small = bool(abs(phase_err[i_ph]) <= SMALL_MISFIT[0]
                 and abs(mag_err[i_mag]) <= SMALL_MISFIT[1] and not implausible)
    # Points where the sampled noise exceeds max_noise_scale of |G| (under a constant σ, those of
    # smallest |G|): a misfit there looks like noise to every statistic.
    dominated = np.zeros(n, dtype=bool)
    if lik.noise != "known":
        dominated = np.median(np.abs(sd), axis=0) > max_noise_scale * np.abs(g)
    masked_ph = float(np.nanmax(np.abs(phase_err[dominated]), initial=0.0))
    masked_mag = float(np.nanmax(np.abs(mag_err[dominated]), initial=0.0))
    masked = bool(adequate and (masked_ph > SMALL_MISFIT[0] or masked_mag > SMALL_MISFIT[1]))
    caution = (_parts.masked_text(omega[dominated], n, max_noise_scale, masked_ph, masked_mag)
               if masked else "")
    if adequate:
        summary = (f"{post.structure} describes the data: no discrepancy below the level "
                   f"{level:g} (smallest p = {min(p_values.values()):.3g}); largest misfit "
                   f"{abs(phase_err[i_ph]):.1f}° in phase, {abs(mag_err[i_mag]):.3f} in log10 |G|"
                   + ("; but " + caution if masked else ""))
    elif small:
        summary = (f"{post.structure} misses the data systematically but by little (at most "
                   f"{abs(phase_err[i_ph]):.1f}° in phase and "
                   f"{100 * (10 ** abs(mag_err[i_mag]) - 1):.1f} % in magnitude): {reasons[0]}")
    else:
        summary = f"{post.structure} does not describe the data: {reasons[0]}"
    return Adequacy(
        adequate=bool(adequate), p_values=p_values, statistics=statistics, level=float(level),
        max_phase_error_deg=float(abs(phase_err[i_ph])), max_phase_error_omega=float(omega[i_ph]),
        max_log10_magnitude_error=float(abs(mag_err[i_mag])),
        max_log10_magnitude_error_omega=float(omega[i_mag]),
        systematic_at_omega=systematic, systematic_bands=bands,
        outside_band_omega=tuple(float(w) for w in omega[outside]),
        noise=lik.noise, noise_scale=noise_scale, noise_scale_implausible=bool(implausible),
        misfit_small=small, reasons=reasons, summary=summary, n_draws=int(n_used), n_reference=int(n_reference),
        seed=int(seed), noise_dominated_omega=tuple(float(w) for w in omega[dominated]),
        misfit_masked=masked, masked_phase_error_deg=masked_ph,
        masked_log10_magnitude_error=masked_mag, caution=caution,
    )


def _outside_band(g, y_rep, m_ref) -> np.ndarray:
    """Points whose log10 |G| or phase lies outside the central BAND_PROB predictive band.

    Both are taken relative to the mode's response, so the phase does not wrap at ±180°."""
    tail = 50.0 * (1.0 - BAND_PROB)
    with np.errstate(divide="ignore", invalid="ignore"):
        rep = y_rep / m_ref
        obs = g / m_ref
    out = np.zeros(g.size, dtype=bool)
    for f in (lambda x: np.log10(np.abs(x)), np.angle):
        lo, hi = np.percentile(f(rep), [tail, 100.0 - tail], axis=0)
        x = f(obs)
        out |= (x < lo) | (x > hi)
    return out


def _bands(a_obs, b_obs, omega, crit: float, parts: bool = False) -> tuple:
    """Separate windows of systematic misfit, strongest first: the windows whose posterior
    median scan statistic exceeds ``crit``, greedily without overlaps, at most MAX_BANDS. The
    strongest window is kept even below ``crit`` (called only when the check has failed, it is
    then where the misfit is most systematic)."""
    n = omega.size
    start, width = _windows(n)
    med = np.median(_scan_windows(a_obs, b_obs, start, width), axis=1)  # (2, n_windows), signed
    strength = np.abs(med)
    flat = np.argsort(-strength, axis=None)
    chosen, taken = [], np.zeros(n, dtype=bool)
    for idx in flat:
        part, j = np.unravel_index(idx, strength.shape)
        if strength[part, j] <= crit and chosen:
            break
        lo, hi = start[j], start[j] + width[j]
        if taken[lo:hi].any():
            continue
        taken[lo:hi] = True
        chosen.append((int(part), int(lo), int(hi) - 1, float(med[part, j])))
        if len(chosen) == MAX_BANDS or strength[part, j] <= crit:
            break
    bands = []
    for part, lo, hi, value in chosen:
        if parts:  # relative_parts noise: the residuals are those of the real and imaginary parts
            text = (f"the data's {('real', 'imaginary')[part]} part is "
                    + ("larger" if value > 0 else "smaller") + " in magnitude than the fit's")
        elif part == 0:
            text = "the data's magnitude lies " + ("above" if value > 0 else "below") + " the fit"
        else:
            text = "the data's phase lies " + ("above" if value > 0 else "below") + " the fit's"
        bands.append((float(omega[lo]), float(omega[hi]), text))
    return tuple(bands)
