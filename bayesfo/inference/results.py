"""A posterior as the rest of bayesfo uses it (:class:`PosteriorResult`: draws, summaries,
diagnostics, an ArviZ DataTree), built from whichever route produced the draws (emcee, the
tempered ladder's particles, importance sampling), and written as NetCDF."""

from __future__ import annotations

import errno
import hashlib
import math
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._io import publish
from ._arviz import ess_min, from_dict, group_names, hdi, rhat_max, write_tree
from .likelihood import Likelihood
from .smc import unique_rows
from .transform import Transform, _log_prob_fn

HDI_PROB = 0.94


RHAT_MAX = 1.01

#: A posterior whose 94 % HDI ends within this share of the prior range of a finite prior
#: bound (in the sampling coordinate: log for log-uniform priors) runs into that bound
#: (``ParameterSummary.at_prior_bound``): 1 % of the default coefficient priors' 18.4 units of
#: ln is a factor of 1.2.
AT_BOUND = 0.01


ESS_MIN = 400


@dataclass(frozen=True)
class ParameterSummary:
    """Posterior summary of one parameter, in physical units.

    ``poorly_determined``: the 94 % HDI covers more than half of the prior range (in the sampling
    coordinate, i.e. in log for log-uniform priors). ``multimodal``: the marginal density has more
    than one clearly separated peak. ``at_prior_bound``: ``"low"`` or ``"high"`` where the HDI
    reaches within :data:`AT_BOUND` of the prior range of that finite bound (in the sampling
    coordinate): the prior, not the data, ends the posterior there; ``""`` otherwise.
    """

    mean: float
    sd: float
    hdi_low: float
    hdi_high: float
    map: float
    median: float
    poorly_determined: bool
    multimodal: bool
    at_prior_bound: str = ""

    def to_dict(self) -> dict:
        return {k: (bool(v) if isinstance(v, (bool, np.bool_)) else v if isinstance(v, str)
                    else float(v)) for k, v in self.__dict__.items()}


@dataclass(frozen=True, eq=False)
class PosteriorResult:
    """Posterior draws of one structure on one data set, with diagnostics.

    Attributes
    ----------
    structure : str
    param_names : tuple of str
        Structure parameters, then ``sigma``/``sigma_rel`` when the noise is sampled.
    noise, noise_reason : str
        The noise model and why it was chosen.
    samples : ndarray, shape (n_draws, ndim)
        Thinned post-burn-in draws in physical units (walkers × kept steps).
    samples_scaled : ndarray
        The same draws on the scaled problem.
    log_likelihood : ndarray, shape (n_draws,)
        Total log-likelihood of each draw (physical units).
    summary : dict
        ``{name: ParameterSummary}``.
    map_theta : ndarray
        The draw with the highest posterior density (physical units).
    max_log_likelihood : float
        Highest log-likelihood among the draws.
    tau : ndarray
        Integrated autocorrelation time of each parameter [steps].
    n_steps, burn, thin, n_walkers : int
    acceptance : float
        Mean acceptance fraction.
    rhat_max, ess_bulk_min, ess_tail_min : float
    converged : bool
    messages : tuple of str
        Warnings raised during the run.
    sampler : str
        ``"emcee"``; ``"ladder"`` for the final particles of independent tempered-ladder runs
        (:func:`posterior_from_particles`; each run is one chain of the diagnostics);
        ``"importance"`` for draws resampled from certified importance weights
        (:func:`bayesfo.inference.importance.importance_posterior`; R-hat does not apply, the
        ESS is that of the weights).
    idata : xarray.DataTree
        Posterior, log_likelihood (per frequency), posterior_predictive, observed_data and
        sample_stats, coordinates named by frequency.
    """

    structure: str
    param_names: tuple[str, ...]
    noise: str
    noise_reason: str
    samples: np.ndarray
    samples_scaled: np.ndarray
    log_likelihood: np.ndarray
    summary: dict
    map_theta: np.ndarray
    max_log_likelihood: float
    tau: np.ndarray
    n_steps: int
    burn: int
    thin: int
    n_walkers: int
    acceptance: float
    rhat_max: float
    ess_bulk_min: float
    ess_tail_min: float
    converged: bool
    messages: tuple[str, ...] = ()
    idata: object = field(default=None, repr=False)
    sampler: str = "emcee"

    @property
    def ess_min(self) -> float:
        return min(self.ess_bulk_min, self.ess_tail_min)

    def to_dict(self) -> dict:
        return {
            "structure": self.structure,
            "noise": self.noise,
            "noise_reason": self.noise_reason,
            "parameters": {k: v.to_dict() for k, v in self.summary.items()},
            "max_log_likelihood": self.max_log_likelihood,
            "tau": dict(zip(self.param_names, map(float, self.tau))),
            "n_steps": self.n_steps, "burn": self.burn, "thin": self.thin,
            "n_walkers": self.n_walkers, "n_draws": int(self.samples.shape[0]),
            "acceptance": self.acceptance,
            "rhat_max": self.rhat_max, "ess_bulk_min": self.ess_bulk_min,
            "ess_tail_min": self.ess_tail_min, "ess_min": self.ess_min,
            "converged": self.converged, "messages": list(self.messages),
            "sampler": self.sampler, "draws_sha256": draws_digest(self.samples),
        }


def draws_digest(samples) -> str:
    """SHA-256 of a set of draws (rows), in hex, whatever their order: what ties a posterior's
    NetCDF to the ``summary.json`` written with it (:func:`bayesfo.load` refuses a NetCDF
    whose draws are not those the summary describes: one copied in from another run)."""
    a = np.asarray(samples, dtype="<f8")
    a = a.reshape(a.shape[0], -1) if a.ndim else a.reshape(1, 1)
    a = a + 0.0  # -0.0 and 0.0 alike
    rows = a[np.lexsort(a.T[::-1])] if a.size else a
    h = hashlib.sha256(f"{a.shape[0]}x{a.shape[1]}:".encode())
    h.update(np.ascontiguousarray(rows).tobytes())
    return h.hexdigest()


@dataclass(frozen=True)
class Agreement:
    """Whether independent tempered-ladder runs agree (:func:`ladder_agreement`): the runs'
    particles as chains (sampling coordinates, each run in random order) and the diagnostics
    of the certificate, without the posterior's summaries and DataTree."""

    chain_u: np.ndarray
    rhat_max: float
    ess_bulk_min: float
    ess_tail_min: float
    messages: tuple[str, ...]

    @property
    def converged(self) -> bool:
        return not self.messages


def ladder_agreement(lik: Likelihood, runs, *, seed: int = 0) -> Agreement:
    """The certificate of :func:`posterior_from_particles` alone (the same numbers from the same
    ``seed``): where the runs only decide what runs next, the posterior need not be built."""
    rng = np.random.default_rng(seed)
    tr = Transform(lik)
    chain_u = np.stack([np.asarray(getattr(r, "particles", r), dtype=float) for r in runs])
    n_runs, n_kept, _ = chain_u.shape
    if n_runs < 2:
        raise ValueError("at least two runs are needed to certify the posterior")
    chain_u = np.stack([c[rng.permutation(n_kept)] for c in chain_u])
    chains = tr.to_theta(chain_u)
    r_hat = rhat_max(chains)
    distinct = float(len(unique_rows(chain_u.reshape(-1, chain_u.shape[2]))))
    ess_bulk = min(distinct, ess_min(chains, "bulk"))
    ess_tail = min(distinct, ess_min(chains, "tail"))
    messages = []
    if not r_hat < RHAT_MAX:
        messages.append(f"{lik.structure.name}: the tempered-ladder runs disagree (R-hat "
                        f"{r_hat:.3f} is not below {RHAT_MAX})")
    if not min(ess_bulk, ess_tail) >= ESS_MIN:
        messages.append(f"{lik.structure.name}: the tempered-ladder particles give an effective "
                        f"sample size of {min(ess_bulk, ess_tail):.0f}, below {ESS_MIN}")
    return Agreement(chain_u, r_hat, ess_bulk, ess_tail, tuple(messages))


def posterior_from_particles(lik: Likelihood, runs, *, seed: int = 0,
                             predictive: bool = True,
                             agreement: Agreement | None = None) -> PosteriorResult:
    """The posterior as the final particles of independent tempered-ladder runs.

    Each run (a :class:`~bayesfo.inference.smc.LadderRun`, or its particles in the sampling
    coordinates) carries prior draws to the posterior through resampling and Metropolis moves,
    so its particles are posterior draws that no walker had to reach by a long chain; where
    the emcee walkers did not converge (ridges, several modes) they are the posterior that is
    reported. The certificate is the agreement of the runs: each run is one chain of the
    rank-normalised split R-hat, and the bulk and tail ESS are computed over the runs (the
    particles of a run are put in random order first: their order after resampling follows
    their ancestors, not a chain). That ESS is an upper bound (particles of a run that share
    ancestors count as independent), capped by the number of distinct particles: the
    certificate rests on R-hat, the agreement of runs that share nothing but the guide.

    Parameters
    ----------
    lik : Likelihood
    runs : sequence of LadderRun or of ndarray, shape (n_particles, ndim)
        At least two runs, the same number of particles each.
    seed : int
        Seed of the shuffle and of the posterior predictive draws.
    predictive : bool
        Store the posterior predictive and the model response in the DataTree.
    agreement : Agreement, optional
        :func:`ladder_agreement` of the same runs and seed, where it was already computed.

    Returns
    -------
    PosteriorResult
        With ``sampler="ladder"``; ``n_walkers`` is the number of runs, ``n_steps`` 0 and
        ``tau`` NaN (no chain); ``converged`` when R-hat < 1.01 and the ESS ≥ 400.
    """
    if agreement is None:
        agreement = ladder_agreement(lik, runs, seed=seed)
    a = agreement
    acceptance = [float(np.mean(r.acceptance[-1:])) for r in runs if hasattr(r, "acceptance")]
    post = result_from_draws(lik, a.chain_u, sampler="ladder", rhat=a.rhat_max,
                             ess_bulk=a.ess_bulk_min, ess_tail=a.ess_tail_min,
                             messages=a.messages, converged=a.converged, seed=seed,
                             predictive=predictive,
                             acceptance=float(np.mean(acceptance)) if acceptance else np.nan)
    post.idata.posterior.attrs.update(sampler="tempered ladder", runs=len(a.chain_u))
    return post


def result_from_draws(lik: Likelihood, chain_u, *, sampler: str, rhat: float, ess_bulk: float,
                      ess_tail: float, messages: tuple, converged: bool, seed: int = 0,
                      predictive: bool = True, acceptance: float = np.nan) -> PosteriorResult:
    """A :class:`PosteriorResult` from posterior draws that another route than emcee produced
    (``chain_u``: chains × draws × parameters in the sampling coordinates), with that route's
    diagnostics. ``n_walkers`` is the number of chains, ``n_steps`` 0 and ``tau`` NaN."""
    rng = np.random.default_rng(seed)
    tr = Transform(lik)
    chain_u = np.asarray(chain_u, dtype=float)
    n_chains, n_kept, ndim = chain_u.shape
    flat_u = chain_u.reshape(-1, ndim)  # chain-major
    flat_scaled = tr.to_theta(flat_u)
    pointwise = lik.pointwise(flat_scaled)
    loglik = pointwise.sum(axis=1)
    flat_phys = lik.to_physical(flat_scaled)
    lp_flat = _log_prob_fn(lik, tr)(flat_u)
    post = {name: flat_phys[:, i].reshape(n_chains, n_kept)
            for i, name in enumerate(lik.param_names)}
    best = int(np.argmax(lp_flat))
    map_theta = flat_phys[best]
    summary = _summaries(lik, tr, flat_phys, flat_u, map_theta)
    idata = _inference_data(lik, post, pointwise, flat_scaled, lp_flat, n_chains, n_kept,
                            rng if predictive else None)
    idata.posterior.attrs.update(sampler=sampler)
    return PosteriorResult(
        structure=lik.structure.name, param_names=lik.param_names, noise=lik.noise,
        noise_reason=lik.noise_reason, samples=flat_phys, samples_scaled=flat_scaled,
        log_likelihood=loglik, summary=summary, map_theta=map_theta,
        max_log_likelihood=float(loglik.max()), tau=np.full(ndim, np.nan), n_steps=0, burn=0,
        thin=1, n_walkers=n_chains, acceptance=acceptance, rhat_max=rhat, ess_bulk_min=ess_bulk,
        ess_tail_min=ess_tail, converged=converged, messages=tuple(messages), idata=idata,
        sampler=sampler,
    )


def _count_modes(u: np.ndarray, lo: float, hi: float) -> int:
    """Peaks of a kernel density of ``u`` with a prominence of at least 5 % of the highest and
    half their own height.

    The bandwidth is Silverman's robust rule, 0.9·min(sd, IQR/1.34)·n^(-1/5): the standard
    deviation of draws from two separated modes is that of their distance, and a bandwidth set
    by it smooths a minor mode away. The density is the binned Gaussian kernel estimate on a
    512-point grid (draws shared linearly between the two nearest grid points, then convolved
    with the kernel). It matches the exact kernel sum of ``scipy.stats.gaussian_kde`` on that
    grid closely (tested at 1 % of the peak height) at a small fraction of its cost
    (BENCHMARKS.md, "Measurements behind design choices"), and unlike a kernel sum taken only
    at the grid points it does not turn scattered tail draws into peaks where the kernel is
    narrower than a grid step.
    """
    from scipy import signal

    if np.ptp(u) <= 0 or u.size < 20:
        return 1
    dens = _binned_density(u, lo, hi)
    padded = np.r_[0.0, dens, 0.0]
    peaks, props = signal.find_peaks(padded, prominence=0.05 * dens.max())
    # A mode stands out: the valley to its higher neighbour is below half its own height (a
    # flat or noisy density has bumps of small relative prominence).
    real = props["prominences"] >= 0.5 * padded[peaks]
    return max(1, int(np.sum(real)))


def _binned_density(u: np.ndarray, lo: float, hi: float, n_grid: int = 512) -> np.ndarray:
    """Gaussian kernel density of ``u`` (Silverman's robust bandwidth) on ``n_grid`` points
    over [max(lo, min u), min(hi, max u)], by linear binning and a discrete convolution."""
    sd = float(np.std(u))
    spread = min(sd, float(np.subtract(*np.percentile(u, [75, 25]))) / 1.34) or sd
    bw = 0.9 * spread * u.size ** -0.2
    a, b = max(lo, float(u.min())), min(hi, float(u.max()))
    if not b > a:
        return np.ones(n_grid)
    step = (b - a) / (n_grid - 1)
    pos = np.clip((u - a) / step, 0.0, n_grid - 1.0)
    left = np.minimum(np.floor(pos).astype(int), n_grid - 2)
    frac = pos - left
    counts = np.bincount(left, weights=1.0 - frac, minlength=n_grid)
    counts += np.bincount(left + 1, weights=frac, minlength=n_grid)
    half = min(n_grid - 1, int(np.ceil(5.0 * bw / step)))
    kernel = np.exp(-0.5 * (np.arange(-half, half + 1) * step / bw) ** 2)
    return np.convolve(counts, kernel)[half:half + n_grid]


def _summaries(lik, tr, flat_phys, flat_u, map_theta) -> dict:
    out = {}
    for i, (name, prior) in enumerate(zip(lik.param_names, lik.prior_list)):
        x = flat_phys[:, i]
        lo, hi = hdi(x, HDI_PROB)
        plo, phi = prior.bounds
        if tr.log[i]:
            plo, phi = math.log(plo), math.log(phi)
        u = flat_u[:, i]
        ulo, uhi = hdi(u, HDI_PROB)
        wide = bool(np.isfinite(phi - plo) and (uhi - ulo) > 0.5 * (phi - plo))
        near = AT_BOUND * (phi - plo) if np.isfinite(phi - plo) else 0.0
        bound = ("low" if near and ulo - plo <= near else
                 "high" if near and phi - uhi <= near else "")
        out[name] = ParameterSummary(
            mean=float(x.mean()), sd=float(x.std(ddof=1)), hdi_low=float(lo), hdi_high=float(hi),
            map=float(map_theta[i]), median=float(np.median(x)), poorly_determined=wide,
            multimodal=_count_modes(u, plo, phi) > 1, at_prior_bound=bound,
        )
    return out


def _inference_data(lik, post, pointwise, flat_scaled, lp_flat, n_walkers, n_kept, rng):
    omega = lik.data.omega
    shape = (n_walkers, n_kept, omega.size)
    g = lik.data.response
    groups = dict(
        posterior=post,
        log_likelihood={"G": pointwise.reshape(shape)},
        observed_data={"G_real": g.real, "G_imag": g.imag},
        sample_stats={"lp": lp_flat.reshape(n_walkers, n_kept)},
    )
    if rng is not None:
        model = lik.model(flat_scaled) * lik.scaling.g_ref
        z = rng.normal(size=model.shape) + 1j * rng.normal(size=model.shape)
        if lik.noise == "relative_parts":
            # Not circular: each part has its own standard deviation σ_rel·|part of G|.
            rel = flat_scaled[:, -1:]
            noise = rel * (np.abs(g.real) * z.real + 1j * np.abs(g.imag) * z.imag)
        else:
            if lik.noise == "known":
                sd = np.broadcast_to(lik.data.sigma, model.shape)
            elif lik.noise == "constant":
                sd = flat_scaled[:, -1:] * lik.scaling.g_ref * np.ones(model.shape)
            else:
                sd = flat_scaled[:, -1:] * np.abs(g)
            noise = sd / math.sqrt(2.0) * z
        rep = model + noise
        groups["posterior_predictive"] = {"G_real": rep.real.reshape(shape), "G_imag": rep.imag.reshape(shape)}
        groups["posterior"] = dict(post, model_real=model.real.reshape(shape), model_imag=model.imag.reshape(shape))
    dims = {k: ["omega"] for k in ("G", "G_real", "G_imag", "model_real", "model_imag")}
    idata = from_dict(groups, coords={"omega": omega}, dims=dims)
    idata.posterior.attrs.update(
        structure=lik.structure.name, noise=lik.noise, kind=lik.data.kind,
        units=lik.data.units or "", omega_units="rad/s", data=lik.data.label,
    )
    return idata


#: Version of the attributes that a NetCDF of bayesfo carries (``posterior.attrs["bayesfo_format"]``),
#: the same for a comparison's structures and a master curve's joint posterior.
NETCDF_FORMAT = 1


def _netcdf_bytes_needed(idata) -> int:
    """An upper bound of the size of ``idata`` as NetCDF: its arrays uncompressed, plus the
    HDF5 headers of every variable and group."""
    total = 0
    for group in group_names(idata):
        ds = idata[group].dataset
        total += ds.nbytes + 16_384 * (len(ds.variables) + 1)
    return total + 65_536


def save_netcdf(idata, path) -> Path:
    """Write a DataTree (ArviZ groups) to NetCDF through a temporary file and an atomic rename.

    Raises
    ------
    OSError
        ``ENOSPC`` before anything is written when the file system has less free space than the
        file may need: HDF5 fails on a full disk with errors it cannot recover from (the
        process crashes at exit), so the space is checked first.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    needed = _netcdf_bytes_needed(idata)
    free = shutil.disk_usage(path.parent).free
    if free < needed:
        raise OSError(errno.ENOSPC, f"{needed} bytes may be needed for {path.name}, "
                                    f"{free} are free", str(path.parent))
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".nc", dir=path.parent)
    os.close(fd)
    try:
        write_tree(idata, tmp)
        publish(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def exponent_intervals(lik: Likelihood, theta: np.ndarray, w: np.ndarray,
                       interval: float = 0.94) -> dict:
    """Central ``interval`` of each exponent (q, α, β, ...) of draws ``theta`` (rows) with
    normalised weights ``w``: ``{name: (low, high)}``."""
    tail = (1.0 - interval) / 2.0
    intervals = {}
    for i, p in enumerate(lik.structure.parameters):
        if p.role != "exponent":
            continue
        order = np.argsort(theta[:, i])
        cdf = np.cumsum(w[order])
        lo = theta[order[min(np.searchsorted(cdf, tail), cdf.size - 1)], i]
        hi = theta[order[min(np.searchsorted(cdf, 1.0 - tail), cdf.size - 1)], i]
        intervals[p.name] = (float(lo), float(hi))
    return intervals
