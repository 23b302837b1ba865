"""A master structure fitted to isotherms whose shifts come from the model-free master
(:mod:`bayesfo.tts.shifts`), so that its misfit cannot move them.

The structure's posterior is certified on the isotherms at the shifts' posterior mean (as
``compare`` certifies one on a data set, :func:`bayesfo.inference.certified_posterior`), and
its draws are paired with independent draws of the shifts: the posterior of the shifts given
the data under the model-free master, and of the structure given the shifts (a "cut" of the
joint model: the structure informs nothing of the shifts). Its ln Z is that of the isotherms
so shifted, which ranks the structures on one data set. The pairs are stored as the joint
model's draws (:class:`~bayesfo.tts.model.ShiftedStructure`: structure, shifts, noise), so that
predictions, Prony series and ``load`` treat them as any master curve's.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError
from .isotherms import _Isotherms, _reduced
from .laws import _fit_laws
from .model import ShiftedStructure
from .result import ISOTHERM_MISFIT, MasterCurve
from .shifts import Shifts
from .spectrum import NAME as SPECTRUM
from .spectrum import Spectrum


def best_on_shifts(iso: _Isotherms, structure, noise: str, seed: int,
                   shifts: Shifts) -> tuple[np.ndarray, float]:
    """The optima of ``structure`` on the isotherms shifted by ``shifts`` (scaled, rows) and the
    highest log-likelihood among the admissible ones (the noise at its maximum-likelihood
    value): an upper bound of the structure's ln Z.

    Raises
    ------
    InputError
        No admissible fit of the structure to the shifted isotherms.
    """
    from ..inference import Likelihood

    master, reduced, scaling, modes, _ = _setup(iso, structure, seed, shifts)
    lik = Likelihood(master, reduced, noise=noise, scaling=scaling)
    theta = modes if not lik.noise_param else np.column_stack(
        [modes, lik.noise_estimate(modes)])
    ok = lik.in_support(theta)
    if not ok.any():
        raise InputError(f"no admissible fit of {master.name} to the shifted isotherms")
    return modes, float(np.max(lik(theta[ok])))


def _setup(iso: _Isotherms, structure, seed: int, shifts: Shifts, modes=None):
    """(master, the isotherms at the shifts' posterior mean, scaling, optima (scaled), the
    reduced window scaled)."""
    from ..identify.optimize import fit_structure
    from ..structures import Scaling, get_structure

    sp = shifts.posterior
    spectral = structure == SPECTRUM or isinstance(structure, Spectrum)
    joint = iso.joint
    scaling = Scaling.from_data(joint)
    vertical_mean = None if sp.vertical_draws is None else sp.vertical_draws.mean(axis=0)
    reduced = _reduced(iso, sp.shift_draws.mean(axis=0), vertical_mean)
    w = reduced.omega / scaling.omega_ref
    if spectral:
        master = Spectrum.over(w.min(), w.max())
        if modes is None:
            modes = master.seed(FrequencyResponse(w, reduced.response / scaling.g_ref,
                                                  kind=joint.kind))[None, :]
    else:
        master = get_structure(structure) if isinstance(structure, str) else structure
        if modes is None:
            fit = fit_structure(master, reduced, rng=seed, seed_methods=True, scaling=scaling)
            modes = master.to_scaled(master.to_physical(
                np.atleast_2d(fit.optima if fit.optima.size else fit.theta_scaled),
                fit.scaling), scaling)
    return master, reduced, scaling, modes, w


def fit_on_shifts(iso: _Isotherms, structure, noise: str, seed: int, shifts: Shifts,
                  reach: float, modes=None) -> MasterCurve:
    """The master curve of ``structure`` on the isotherms shifted by ``shifts`` (see the
    module), from its optima ``modes`` where :func:`best_on_shifts` found them.

    Raises
    ------
    InputError
        No admissible fit of the structure to the shifted isotherms.
    """
    from ..inference import Likelihood, certified_posterior
    from ..inference import preload_arviz as preload
    from ..inference.results import result_from_draws
    from ..inference.transform import Transform as _Transform
    from ..parallel import settle_worker
    from ..structures.response import dissipation_grid

    settle_worker(preload)
    sp = shifts.posterior
    spectral = structure == SPECTRUM or isinstance(structure, Spectrum)
    joint = iso.joint
    master, reduced, scaling, modes, w = _setup(iso, structure, seed, shifts, modes)
    lik = Likelihood(master, reduced, noise=noise, scaling=scaling)
    if not np.any(lik.in_support(np.c_[modes, np.full(len(modes), 0.05)]
                                 if lik.noise_param else modes)):
        raise InputError(f"no admissible fit of {master.name} to the shifted isotherms")
    # The posterior's warnings are its notes (the master curve's notes, said once by the
    # command), not warnings raised in the middle of a master curve.
    with warnings.catch_warnings(record=True) as held:
        warnings.simplefilter("always")
        found = certified_posterior(lik, modes, sampler="auto", seed=seed)
    post = found.posterior
    notes = list(found.notes)
    notes += [str(w.message) for w in held if str(w.message) not in notes
              and issubclass(w.category, UserWarning)]
    if not post.converged:
        notes.append(f"{master.name}: the posterior is not certified "
                     f"({'; '.join(post.messages)})")

    # The joint model's draws: the structure's, each paired with a draw of the shifts.
    shifted = ShiftedStructure(master, iso.temperatures, iso.reference, iso.point_isotherm,
                               dissipation_grid(w.min(), w.max()), shifts.vertical,
                               shifts.law, reach)
    joint_lik = Likelihood(shifted, joint, noise=noise, scaling=scaling)
    k = master.n_params
    n_shift = shifted.n_params - k
    rng = np.random.default_rng(seed)
    n = post.samples_scaled.shape[0]
    pick = rng.choice(sp.draws.shape[0], size=n, replace=sp.draws.shape[0] < n)
    theta = np.column_stack([post.samples_scaled[:, :k], sp.draws[pick, :n_shift],
                             post.samples_scaled[:, k:]])
    tr = _Transform(joint_lik)
    u = tr.to_u(theta)
    ok = joint_lik.in_support(theta) & np.all(np.isfinite(u), axis=1)
    if not ok.all():  # a pair outside the joint support (a shift at its prior's edge)
        u = u[ok]
        notes.append(f"{master.name}: {int((~ok).sum())} of {n} paired draws lay outside the "
                     "joint prior's support and were left out")
    if u.shape[0] < 2:
        raise InputError(f"no draw of {master.name} lies in the joint prior's support")
    ess_shifts = float(sp.ess)
    joint_post = result_from_draws(
        joint_lik, u[None], sampler=post.sampler, rhat=post.rhat_max,
        ess_bulk=min(post.ess_bulk_min, ess_shifts), ess_tail=min(post.ess_tail_min, ess_shifts),
        messages=tuple(post.messages) + tuple(sp.messages),
        converged=bool(post.converged and sp.converged), seed=seed)

    physical = np.asarray(joint_post.samples)
    k_all = shifted.n_params
    rows = rng.choice(joint_post.samples_scaled.shape[0],
                      size=min(200, joint_post.samples_scaled.shape[0]), replace=False)
    curves = joint_lik.model(joint_post.samples_scaled[rows, :k_all])
    g = joint_lik.g_scaled
    fitted = np.median(curves.real, axis=0) + 1j * np.median(curves.imag, axis=0)
    isotherm_fit = isotherm_misfit(iso, fitted, g, joint_lik.noise)
    shift_draws = shifted.log_shifts(physical[:, :k_all])
    ev = found.evidence
    return MasterCurve(
        structure=master.name, temperatures=iso.temperatures,
        reference_temperature=iso.temperatures[iso.reference], shift_draws=shift_draws,
        master_draws=physical[:, :k], posterior=joint_post,
        log_evidence=math.nan if ev is None else ev.log_z,
        log_evidence_err=math.nan if ev is None else ev.log_z_err,
        laws=laws_of(shift_draws, iso, sp), data=joint, isotherms=iso.data,
        notes=tuple(notes), tts_checks={"isotherm_fit": isotherm_fit},
        vertical=shifts.vertical,
        vertical_draws=None if shifts.vertical == "none" else shifted.log_vertical(
            physical[:, :k_all]),
        master=master.physical(scaling) if spectral else master, law=shifts.law)


def isotherm_misfit(iso: _Isotherms, fitted, g, noise: str) -> dict:
    """Each isotherm's rms relative residual of the fitted curve ``fitted`` against the data
    ``g`` (both scaled, the joint data's order), of |G*| and, under ``relative_parts`` noise
    (each part's error relative to itself), of each part (storage, loss: a terminal G′ or a
    glassy G″ that |G*| hides); the isotherms missed: an rms over :data:`ISOTHERM_MISFIT` times
    the median isotherm's. Under the other noise models a small part's relative residual is
    large by the noise alone, and |G*| is the measure."""
    rel = np.abs(fitted - g) / np.abs(g)
    with np.errstate(divide="ignore", invalid="ignore"):
        parts = {"storage": np.abs(fitted.real - g.real) / np.abs(g.real),
                 "loss": np.abs(fitted.imag - g.imag) / np.abs(g.imag)}

    def rms(x):
        out = []
        for i in range(len(iso.data)):
            v = x[iso.point_isotherm == i]
            v = v[np.isfinite(v)]
            out.append(math.sqrt(float(np.mean(v ** 2))) if v.size else math.nan)
        return np.array(out)

    total = rms(rel)
    by_part = {k: rms(v) for k, v in parts.items()} if noise == "relative_parts" else {}
    missed = set()
    for values in (total, *by_part.values()):
        med = np.nanmedian(values)
        missed |= {i for i, r in enumerate(values) if np.isfinite(r) and r > ISOTHERM_MISFIT * med}
    return {"temperatures": list(iso.temperatures), "rms_relative": total.tolist(),
            "rms_relative_parts": {k: [None if not np.isfinite(r) else float(r) for r in v]
                                   for k, v in by_part.items()},
            "misfit": [iso.temperatures[i] for i in sorted(missed)]}


def laws_of(shift_draws, iso: _Isotherms, sp) -> dict:
    """WLF and Arrhenius fitted to the shift draws of the isotherms whose shifts the data fix
    (:meth:`~bayesfo.tts.smooth_posterior.ShiftPosterior.undetermined` left out)."""
    gone = set(sp.undetermined())
    if len(iso.temperatures) - len(gone) < 3:  # too few left to fit a law to
        gone = set()
    keep = [i for i in range(len(iso.temperatures)) if i not in gone]
    temps = [iso.temperatures[i] for i in keep]
    ref = keep.index(iso.reference)
    laws = _fit_laws(shift_draws[:, keep], temps, ref, 0)
    for law in laws.values():
        law["left_out"] = [iso.temperatures[i] for i in sorted(gone)]
    return laws
