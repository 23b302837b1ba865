"""Likelihood of a structure on complex frequency-response data, and its prior support.

Each measured point G_k is modelled as the structure's response plus circular complex Gaussian
noise: real and imaginary parts independent with variance σ_k²/2 each, so σ_k² = E|ΔG_k|² (the σ of
the CSV contract). The pointwise log-likelihood of a complex point is

    ln p(G_k | θ) = −ln(π σ_k²) − |G_k − Ĝ_k(θ)|² / σ_k²,

which is the sum of the two real Gaussian terms of the stacked real and imaginary parts. Noise
models:

``known``
    σ_k from the data (a ``sigma`` column or replicates).
``constant``
    One unknown σ for all points, sampled with a log-uniform (scale-invariant) prior.
``proportional``
    σ_k = σ_rel·|G_k| (data magnitude), σ_rel sampled with a log-uniform prior: relative errors,
    suited to data spanning decades.
``relative_parts``
    Not circular: the real and imaginary parts are independent Gaussians with standard
    deviations σ_rel·|Re G_k| and σ_rel·|Im G_k| (data values), σ_rel sampled with the prior of
    ``proportional``. σ_rel is then the relative error of each part, and E|ΔG_k|² =
    σ_rel²·|G_k|² at every point, the convention of ``proportional`` (with which it coincides
    where |Re G_k| = |Im G_k|). The usual error model of a rheometer or DMA, which reports G'
    and G'' each with a relative error. The pointwise log-likelihood is

        ln p(G_k | θ) = −ln(2π σ_rel² |Re G_k|·|Im G_k|)
                        − [(ΔRe_k / Re G_k)² + (ΔIm_k / Im G_k)²] / (2 σ_rel²),

    so for a fixed σ_rel the maximum-likelihood structure parameters minimise
    Σ_k (ΔRe_k / Re G_k)² + (ΔIm_k / Im G_k)², the cost that pyRheo and RheoJAX minimise on
    storage and loss moduli. It weights each part by itself where one is much smaller than the
    other (G' ≪ G'' or G' ≫ G''), where ``proportional`` weights both by |G|. Data with a part
    exactly 0 cannot use it. :func:`bayesfo.compare` weighs it by evidence with ``constant`` and
    ``proportional`` under ``noise="auto"``; the rule of :func:`choose_noise` (a bare
    :class:`Likelihood`) never picks it.

Everything is evaluated on the scaled data (ω/ω_ref, G/g_ref) and vectorised over parameter sets;
the log-likelihood is reported in physical units (the scaling adds −2·ln g_ref per point).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError
from ..priors import LogUniform, Prior
from ..structures import Scaling, Structure
from ..structures.response import dissipation_grid

NOISE_MODELS = ("known", "constant", "proportional", "relative_parts")

#: Priors of the noise scale on the scaled data (|G|/g_ref is of order one).
NOISE_PRIORS = {
    "constant": ("sigma", LogUniform(1e-6, 10.0)),
    "proportional": ("sigma_rel", LogUniform(1e-5, 1.0)),
    "relative_parts": ("sigma_rel", LogUniform(1e-5, 1.0)),
}


def noise_variance(noise: str, g, sigma) -> np.ndarray:
    """The variance of a measurement's ln|G| and arg G [rad] (last axis, 2) under the noise
    model ``noise`` where the model's response is ``g`` (any shape, physical units), in the
    small-noise approximation: what a new point measured there would scatter by.

    ``sigma`` is the noise scale, broadcast against ``g``: the sampled ``sigma`` (in the units
    of G) or ``sigma_rel`` of :data:`NOISE_PRIORS`' models, and for ``known`` noise the data's
    relative σ (σ/|G|).

    Examples
    --------
    Noise proportional to |G| scatters ln|G| and arg G alike, by σ_rel²/2:

    >>> noise_variance("proportional", np.array([2.0 + 1.0j]), 0.1)
    array([[0.005, 0.005]])
    """
    g2 = np.abs(g) ** 2
    if noise == "known":
        v = np.full(g.shape, sigma**2 / 2.0)
        return np.stack([v, v], axis=-1)
    if noise == "constant":
        v = sigma**2 / (2.0 * g2)
        return np.stack([v, v], axis=-1)
    if noise == "relative_parts":
        re2, im2 = g.real**2, g.imag**2
        return np.stack([sigma**2 * (re2**2 + im2**2) / g2**2,
                         sigma**2 * 2.0 * re2 * im2 / g2**2], axis=-1)
    if noise == "proportional":
        v = np.broadcast_to(sigma**2 / 2.0, g.shape)
        return np.stack([v, v], axis=-1)
    raise InputError(f"noise must be one of {', '.join(NOISE_MODELS)}, got {noise!r}",
                     option="noise")


def zero_part(data: FrequencyResponse) -> str | None:
    """Why ``relative_parts`` noise cannot be used on ``data`` (a real or imaginary part exactly
    0 at some frequency, where the relative error of that part has no scale), or None."""
    zero = (data.response.real == 0) | (data.response.imag == 0)
    if not zero.any():
        return None
    k = int(np.flatnonzero(zero)[0])
    part = "real" if data.response.real[k] == 0 else "imaginary"
    return (f"{data.where()}: the {part} part of the response is exactly 0 at omega = "
            f"{data.omega[k]:.4g} rad/s, where noise model 'relative_parts' (relative errors of "
            "the real and imaginary parts) has no scale; use noise 'constant' (or "
            "'proportional'), give sigma, or remove the point")


def choose_noise(data: FrequencyResponse, noise: str = "auto") -> tuple[str, str]:
    """Resolve ``"auto"`` by a rule, and say why.

    This is the default of a bare :class:`Likelihood`. :func:`bayesfo.compare` does not use the
    rule: without σ it weighs ``constant``, ``proportional`` and ``relative_parts`` noise for
    each structure by evidence and keeps the one with the largest (see ``docs/adequacy.md``).

    Returns
    -------
    noise : str
        ``known`` when the data carry σ; else ``proportional`` when |G| spans more than a decade
        (a constant σ would let the largest values dominate); else ``constant``.
    reason : str
        Why, in a few words (e.g. "|G| spans 1.2 decades").
    """
    if noise not in NOISE_MODELS + ("auto",):
        raise InputError(f"noise model must be auto, {', '.join(NOISE_MODELS)}; got {noise!r}")
    if noise == "known" and data.sigma is None:
        raise InputError(f"noise model 'known' needs sigma in {data.where()}")
    if noise == "relative_parts" and (why := zero_part(data)) is not None:
        raise InputError(why)
    if noise != "auto":
        return noise, "chosen by the user"
    if data.sigma is not None:
        return "known", "the data give sigma per point"
    mag = data.magnitude
    if mag.max() > 10 * mag.min():
        return "proportional", f"|G| spans {np.log10(mag.max() / mag.min()):.1f} decades"
    return "constant", "|G| spans less than a decade"


@dataclass(frozen=True, eq=False)
class Likelihood:
    """Log-likelihood and prior support of ``structure`` on ``data``.

    Parameter vectors are the structure's parameters on the scaled problem followed by the noise
    parameter (``sigma`` or ``sigma_rel``) unless the noise is known: see :attr:`param_names`.

    Parameters
    ----------
    structure : Structure
    data : FrequencyResponse
    noise : {"auto", "known", "constant", "proportional", "relative_parts"}
        ``auto`` follows the rule of :func:`choose_noise` (never ``relative_parts``;
        :func:`bayesfo.compare` chooses by evidence instead).
    priors : dict, optional
        Overrides of structure or noise priors, ``{name: Prior}``.
    scaling : Scaling, optional
        The units of the scaled problem on which the priors are declared (default
        ``Scaling.from_data(data)``: ω_ref the geometric mean of ω, g_ref the median |G|). Fixing
        it makes priors mean the same on several data sets.
    require_points : bool
        Refuse data with fewer frequencies than parameters (off for held-out validation points,
        which are only evaluated).
    """

    structure: Structure
    data: FrequencyResponse
    noise: str = "auto"
    priors: dict = field(default_factory=dict)
    scaling: Scaling | None = None
    require_points: bool = True

    def __post_init__(self):
        if self.require_points:
            self.structure.check_data(self.data)
        noise, reason = choose_noise(self.data, self.noise)
        object.__setattr__(self, "noise", noise)
        object.__setattr__(self, "noise_reason", reason)
        struct_priors = {k: v for k, v in self.priors.items() if k in self.structure.param_names}
        structure = self.structure.with_priors(struct_priors) if struct_priors else self.structure
        object.__setattr__(self, "structure", structure)
        noise_param = NOISE_PRIORS.get(noise)
        unknown = set(self.priors) - set(structure.param_names) - ({noise_param[0]} if noise_param else set())
        if unknown:
            raise InputError(
                f"prior override for unknown parameter '{sorted(unknown)[0]}'; parameters are "
                f"{', '.join(structure.param_names + ((noise_param[0],) if noise_param else ()))}"
            )
        if noise_param is not None and noise_param[0] in self.priors:
            noise_param = (noise_param[0], self.priors[noise_param[0]])
        object.__setattr__(self, "noise_param", noise_param)
        scaling = Scaling.from_data(self.data) if self.scaling is None else self.scaling
        if scaling.reciprocal != (self.data.kind == "modulus"):
            raise InputError("argument 'scaling' must have reciprocal=True exactly for modulus data")
        object.__setattr__(self, "scaling", scaling)
        w = self.data.omega / scaling.omega_ref
        g = self.data.response / scaling.g_ref
        object.__setattr__(self, "omega_scaled", w)
        object.__setattr__(self, "g_scaled", g)
        object.__setattr__(self, "grid", dissipation_grid(w.min(), w.max()))
        if noise == "known":
            s2 = (self.data.sigma / scaling.g_ref) ** 2
            object.__setattr__(self, "_var", s2)
            object.__setattr__(self, "_log_norm", -np.log(np.pi * s2))
        elif noise == "relative_parts":
            # ln p = −ln(2π σ_rel² |Re g|·|Im g|) − [ρ_re² + ρ_im²] / (2 σ_rel²), ρ the relative
            # residual of each part: the σ-free terms and the weights are fixed by the data.
            object.__setattr__(self, "_log_parts", -np.log(2.0 * np.pi * np.abs(g.real * g.imag)))
            object.__setattr__(self, "_w_re", 1.0 / g.real ** 2)
            object.__setattr__(self, "_w_im", 1.0 / g.imag ** 2)
        else:
            object.__setattr__(self, "_abs_g2", np.abs(g) ** 2)
        object.__setattr__(self, "_unit_shift", -2.0 * math.log(scaling.g_ref))

    # ------------------------------------------------------------------ names and priors
    @property
    def param_names(self) -> tuple[str, ...]:
        names = self.structure.param_names
        return names + ((self.noise_param[0],) if self.noise_param else ())

    @property
    def ndim(self) -> int:
        return len(self.param_names)

    @property
    def prior_list(self) -> list[Prior]:
        """The prior of every parameter, in the order of :attr:`param_names`."""
        out = [p.prior for p in self.structure.parameters]
        if self.noise_param:
            out.append(self.noise_param[1])
        return out

    def describe_priors(self) -> dict[str, dict]:
        return {n: p.to_dict() for n, p in zip(self.param_names, self.prior_list)}

    # ------------------------------------------------------------------ evaluation
    def model(self, theta) -> np.ndarray:
        """Scaled model response for parameter sets ``theta`` (n_sets, ndim)."""
        theta = np.atleast_2d(theta)
        return self.structure.response(theta[:, : self.structure.n_params], self.omega_scaled,
                                       self.data.kind)

    def pointwise(self, theta) -> np.ndarray:
        """Log-likelihood of each frequency, shape (n_sets, n_freq), ignoring the support.

        Non-finite model values give −inf.
        """
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        model = self.model(theta)
        if self.noise == "relative_parts":
            s2 = theta[:, -1:] ** 2
            rho2 = self._relative_parts2(model)
            with np.errstate(divide="ignore", invalid="ignore"):
                out = self._log_parts - np.log(s2) - rho2 / (2.0 * s2)
            out = out + self._unit_shift
            return np.where(np.isfinite(out), out, -np.inf)
        # In place where the arrays are this call's own: the same arithmetic with fewer
        # temporaries of shape (n_sets, n_freq).
        own = model.flags.writeable and model.shape == (theta.shape[0], self.g_scaled.size)
        r2 = np.abs(np.subtract(self.g_scaled, model, out=model) if own else self.g_scaled - model)
        np.square(r2, out=r2)
        if self.noise == "known":
            r2 /= self._var
            out = np.subtract(self._log_norm, r2, out=r2)
        else:
            s = theta[:, -1:]
            var = s * s if self.noise == "constant" else (s * s) * self._abs_g2
            with np.errstate(divide="ignore", invalid="ignore"):
                out = -np.log(np.pi * var)
                out = out - np.divide(r2, var, out=r2)
        out += self._unit_shift
        np.copyto(out, -np.inf, where=~np.isfinite(out))
        return out

    def noise_variance(self, g, sigma) -> np.ndarray:
        """:func:`noise_variance` under this likelihood's noise model."""
        return noise_variance(self.noise, g, sigma)

    def _relative_parts2(self, model) -> np.ndarray:
        """(ΔRe/Re g)² + (ΔIm/Im g)² per point, the summand of pyRheo's cost."""
        d = self.g_scaled - model
        return d.real ** 2 * self._w_re + d.imag ** 2 * self._w_im

    def in_support(self, theta) -> np.ndarray:
        """True where θ lies in the support of the prior: every prior range, the structure's
        inequalities, stability and dissipation."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        ok = np.all(np.isfinite(theta), axis=1)
        if self.noise_param:
            ok &= self.noise_param[1].contains(theta[:, -1])
        rows = np.flatnonzero(ok)
        if rows.size:
            ok[rows] = self.structure.admissible(
                theta[rows, : self.structure.n_params], self.data.kind, self.grid
            )
        return ok

    def log_prior(self, theta) -> np.ndarray:
        """Log prior density of θ (−inf outside the support)."""
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        out = np.zeros(theta.shape[0])
        for i, prior in enumerate(self.prior_list):
            out += prior.log_prob(theta[:, i])
        support = self.in_support(theta)
        return np.where(support & np.isfinite(out), out, -np.inf)

    def __call__(self, theta) -> np.ndarray:
        """Total log-likelihood, shape (n_sets,) (ignores the support)."""
        return self.pointwise(theta).sum(axis=1)

    def to_physical(self, theta) -> np.ndarray:
        """Scaled parameter sets → physical units (σ in the units of G; σ_rel unchanged)."""
        return self._convert(theta, to_physical=True)

    def to_scaled(self, theta) -> np.ndarray:
        """Physical parameter sets → the scaled problem."""
        return self._convert(theta, to_physical=False)

    def _convert(self, theta, to_physical: bool) -> np.ndarray:
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        out = theta.copy()
        k = self.structure.n_params
        convert = self.structure.to_physical if to_physical else self.structure.to_scaled
        out[:, :k] = convert(theta[:, :k], self.scaling)
        if self.noise == "constant":
            g = self.scaling.g_ref
            out[:, k] = theta[:, k] * (g if to_physical else 1.0 / g)
        return out

    def log_noise_marginal(self, theta_structure) -> np.ndarray | None:
        """The log-likelihood with the noise scale integrated out, ln ∫ L(θ, σ) p(σ) dσ.

        For structure parameters θ (scaled, rows), under the log-uniform prior p(σ) on [a, b],
        in closed form. With S = Σ_k |r_k|²/w_k (w_k = 1, or |g_k|² under ``proportional``)
        over n points,

            ∫_a^b σ^(-2n) e^(-S/σ²) dσ/(σ ln(b/a)) = Γ(n) [P(n, S/a²) − P(n, S/b²)] / (2 S^n ln(b/a)),

        P the regularised lower incomplete gamma function. Under ``relative_parts`` the 2n real
        parts give the same integral with S = ½ Σ_k (ΔRe_k/Re g_k)² + (ΔIm_k/Im g_k)² and the
        normalisation ∏ 1/(2π |Re g_k|·|Im g_k|). None where it does not apply (known noise, or
        a noise prior that is not log-uniform)."""
        from scipy.special import gammainc, gammaln

        prior = self.noise_param[1] if self.noise_param else None
        if self.noise == "known" or not isinstance(prior, LogUniform):
            return None
        theta_structure = np.atleast_2d(theta_structure)
        model = self.structure.response(theta_structure, self.omega_scaled, self.data.kind)
        n = model.shape[1]
        if self.noise == "relative_parts":
            s = 0.5 * self._relative_parts2(model).sum(axis=1)
            log_norm = n * self._unit_shift + float(self._log_parts.sum())
        else:
            r2 = np.abs(self.g_scaled - model) ** 2
            if self.noise == "constant":
                s, log_w = r2.sum(axis=1), 0.0
            else:
                s, log_w = (r2 / self._abs_g2).sum(axis=1), float(np.log(self._abs_g2).sum())
            log_norm = n * (self._unit_shift - math.log(math.pi)) - log_w
        a, b = prior.low, prior.high
        with np.errstate(divide="ignore", invalid="ignore"):
            mass = gammainc(n, s / a**2) - gammainc(n, s / b**2)
            out = (log_norm - math.log(2.0 * math.log(b / a)) + gammaln(n) - n * np.log(s)
                   + np.log(mass))
        return np.where(np.isfinite(out), out, -np.inf)

    def noise_estimate(self, theta_structure) -> np.ndarray:
        """The noise parameter that maximises the likelihood for given structure parameters
        (scaled): sqrt(mean |r|²) (``constant``), sqrt(mean |r|²/|G|²) (``proportional``) or the
        root mean square of the relative residuals of the 2n parts (``relative_parts``)."""
        theta_structure = np.atleast_2d(theta_structure)
        model = self.structure.response(theta_structure, self.omega_scaled, self.data.kind)
        if self.noise == "relative_parts":
            return np.sqrt(0.5 * self._relative_parts2(model).mean(axis=1))
        r2 = np.abs(self.g_scaled - model) ** 2
        if self.noise == "constant":
            return np.sqrt(r2.mean(axis=1))
        return np.sqrt((r2 / self._abs_g2).mean(axis=1))
