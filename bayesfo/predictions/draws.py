"""The posterior draws that everything after a fit evaluates: one :class:`Draws` type for a
comparison's structure, an average over its structures, and a master curve's master structure
with each draw's shifts at a temperature.

:meth:`bayesfo.Comparison.draws` and :meth:`bayesfo.MasterCurve.draws` give it;
:func:`~bayesfo.predictions.predict` (material functions), :func:`long_time_modulus` and
:func:`~bayesfo.predictions.prony_series` take it, so neither asks which kind of result it has.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError

#: Ways of averaging over structures.
AVERAGES = ("bma", "stacking")
#: Posterior draws used per prediction (a random subset where a posterior has more).
MAX_DRAWS = 2000


@dataclass(frozen=True)
class Draws:
    """Posterior draws of one structure, or of a mixture of structures, to evaluate.

    Attributes
    ----------
    data : FrequencyResponse
        The data the draws were fitted to (kind and units of what follows from them).
    parts : tuple of (str, Structure, ndarray)
        ``(name, structure, theta)`` per structure of the mixture, ``theta`` its draws in
        physical units without the noise parameter (n, n_params; none for a structure whose
        share of the mixture rounds to none); one part for a structure or a master curve. The
        draws of the mixture are the parts' rows one after another.
    weights : dict
        ``{name: weight}`` of the mixture, summing to 1 (``{name: 1.0}`` for one structure).
    average : {"bma", "stacking"} or None
        How the weights were found; None for one structure.
    omega : ndarray
        The angular frequencies [rad/s] the data cover at the draws' own temperature: the
        data's, or a master curve's reduced frequencies (:meth:`MasterCurve.reduced_omega`).
    log_a, log_b : ndarray or None
        A master curve's per-draw log10 a_T and log10 b_T at ``temperature``
        (G(ω; T) = G_ref(a_T ω)/b_T); None for a comparison, whose draws are unshifted.
    mean_log_a : float
        The posterior mean of log10 a_T at ``temperature`` over every draw of the posterior
        (0 for a comparison): the data's window at that temperature is ``omega / 10**mean_log_a``.
    temperature : float or None
        [°C] A master curve's temperature of the draws.
    notes : tuple of str
        What to know about the draws (weights that disagree, a structure that misses the data,
        the temperature they were shifted to).
    """

    data: object = field(repr=False)
    parts: tuple = field(repr=False)
    weights: dict
    average: str | None = None
    omega: np.ndarray = field(default=None, repr=False)
    log_a: np.ndarray | None = field(default=None, repr=False)
    log_b: np.ndarray | None = field(default=None, repr=False)
    mean_log_a: float = 0.0
    temperature: float | None = None
    notes: tuple = ()

    @property
    def shifted(self) -> bool:
        """Whether each draw carries its own shifts (a master curve's draws)."""
        return self.log_a is not None

    @property
    def n_draws(self) -> int:
        return sum(theta.shape[0] for _, _, theta in self.parts)

    @property
    def structure(self) -> str | None:
        """The one structure's name; None for an average."""
        return next(iter(self.weights)) if self.average is None else None

    def window(self) -> np.ndarray:
        """The data's angular frequencies at the draws' temperature [rad/s]."""
        return self.omega / 10.0 ** self.mean_log_a


# ---------------------------------------------------------------------- a comparison's
def comparison_draws(result, structure: str | None = None, average: str | None = None, *,
                     seed: int = 0, temperature: float | None = None) -> Draws:
    """:meth:`bayesfo.Comparison.draws`: :data:`MAX_DRAWS` draws of ``structure`` (default the
    best ranked) or of the ``average`` of the ranked structures, each structure's share in
    proportion to its weight."""
    if structure is not None and average is not None:
        raise InputError("predict: give a structure or an average, not both", where="predict")
    if temperature is not None:
        raise InputError("predict: a temperature applies to a master curve only (bayesfo "
                         "mastercurve); a comparison describes the data at their own temperature", where="predict")
    rng = np.random.default_rng(seed)
    notes = []
    if average is None:
        name = structure if structure is not None else _best(result)
        weights = {_usable(result, name).name: 1.0}
    else:
        weights, notes = _weights(result, average)
    # A structure given no draws by the mixture keeps its place, with none.
    parts = tuple((name, result[name].structure,
                   _draws(result[name], n, rng) if n > 0
                   else np.empty((0, result[name].structure.n_params)))
                  for name, n in _draw_counts(weights, rng).items())
    if average is None:
        notes += _misfit_note(result[next(iter(weights))])
    return Draws(data=result.data, parts=parts, weights=weights, average=average,
                 omega=np.asarray(result.data.omega), notes=tuple(notes))


def _best(result) -> str:
    if not result.ranking:
        raise InputError("predict: the comparison has no structure with a posterior", where="predict")
    return result.ranking[0]


def _usable(result, name: str):
    try:
        r = result[name]
    except KeyError:
        raise InputError(f"predict: no structure {name!r} in the comparison; it has "
                         + ", ".join(x.name for x in result.results), where="predict") from None
    if r.error is not None or r.posterior is None:
        raise InputError(f"predict: structure {name!r} has no posterior ({r.error})", where="predict")
    return r


def _weights(result, average: str) -> tuple[dict, list]:
    """``{structure: weight}`` (summing to 1) and notes, for ``average``."""
    if average not in AVERAGES:
        raise InputError(f"predict: average must be one of {', '.join(AVERAGES)}, got "
                         f"{average!r}", where="predict", option="average")
    # Structures the evidence bound left out have no posterior and weigh below e^-10 against
    # the leader: they take no part (their weight in Bayesian model averaging is negligible).
    ranked = [result[n] for n in result.ranking if result[n].posterior is not None]
    if len(ranked) < 2:
        raise InputError("predict: an average needs two or more structures with a posterior", where="predict")
    bma = {r.name: r.probability for r in ranked}
    if any(v is None for v in bma.values()):
        bma = None
    notes = []
    stacking = _stacking(ranked)
    if average == "bma":
        if bma is None:
            raise InputError("predict: some structures have no evidence, so no posterior "
                             "model probabilities; use average='stacking'", where="predict")
        weights = bma
    else:
        if stacking is None:
            raise InputError("predict: stacking needs the pointwise log-likelihood of every "
                             "structure (a comparison loaded from an older run lacks it)", where="predict")
        weights = stacking
    if bma is not None and stacking is not None:
        apart = max(abs(bma[n] - stacking[n]) for n in bma)
        if apart > 0.5:
            notes.append(f"the posterior model probabilities and the stacking weights disagree "
                         f"(by up to {apart:.2f} for one structure): the average depends on "
                         "which is taken")
    for r in ranked:
        adequacy = r.criteria.adequacy
        if weights[r.name] >= 0.1 and adequacy is not None and not adequacy.adequate:
            how = ("misses the data systematically, if by little" if adequacy.misfit_small
                   else "does not fit the data")
            notes.append(f"{r.name} carries weight {weights[r.name]:.2f} but {how} (posterior "
                         "predictive checks)")
    return weights, notes


def _stacking(ranked) -> dict | None:
    """Stacking weights of the structures (arviz-stats on their pointwise log-likelihood)."""
    from arviz_stats import compare

    trees = {r.name: r.posterior.idata for r in ranked}
    if any(t is None or "log_likelihood" not in t.children for t in trees.values()):
        return None
    import warnings

    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")  # Pareto k̂ warnings: compare() flags them already
        table = compare(trees, method="stacking", var_name="G")
    w = {name: float(table.loc[name, "weight"]) for name in trees}
    total = sum(w.values())
    return {k: v / total for k, v in w.items()}


def _misfit_note(r) -> list[str]:
    """A note where the structure predicted from fails the posterior predictive checks: its
    band is the posterior of the model's mean function, which measured values may then leave."""
    adequacy = r.criteria.adequacy
    if adequacy is None or adequacy.adequate:
        return []
    how = ("misses the data systematically, if by little" if adequacy.misfit_small
           else "does not fit the data")
    return [f"{r.name} {how} (posterior predictive checks): the band is the posterior of its "
            "mean function, without the data's scatter or its misfit, so measured values may "
            "lie outside it"]


def _draw_counts(weights: dict, rng) -> dict:
    """How many of :data:`MAX_DRAWS` draws each structure gives to the mixture."""
    names = list(weights)
    p = np.array([weights[n] for n in names], dtype=float)
    p = np.clip(p, 0.0, None) / p.sum()
    counts = rng.multinomial(MAX_DRAWS, p) if len(names) > 1 else [MAX_DRAWS]
    return dict(zip(names, (int(c) for c in counts), strict=True))


def _draws(r, n: int, rng) -> np.ndarray:
    """``n`` posterior draws (physical units, without the noise parameter), without
    replacement where the posterior has as many, else all of them repeated as needed."""
    samples = np.asarray(r.posterior.samples, dtype=float)[:, :r.structure.n_params]
    if samples.shape[0] >= n:
        return samples[np.sort(rng.choice(samples.shape[0], size=n, replace=False))]
    return samples[rng.choice(samples.shape[0], size=n, replace=True)]


# ---------------------------------------------------------------------- a master curve's
def master_draws(mc, structure: str | None = None, average: str | None = None, *,
                 seed: int = 0, temperature: float | None = None) -> Draws:
    """:meth:`bayesfo.MasterCurve.draws`: :data:`MAX_DRAWS` draws of the master structure with
    their log10 shifts (a_T, b_T) at ``temperature`` (default the reference temperature)."""
    if structure is not None and average is not None:
        raise InputError("predict: give a structure or an average, not both", where="predict")
    rng = np.random.default_rng(seed)
    t = mc.reference_temperature if temperature is None else temperature
    if average is not None:
        raise InputError("predict: a master curve holds the posterior of one master "
                         f"structure ({mc.structure}), so there is nothing to average", where="predict")
    if structure is not None and structure != mc.structure:
        raise InputError(f"predict: the master curve's structure is {mc.structure!r}, not "
                         f"{structure!r}", where="predict")
    n = mc.master_draws.shape[0]
    rows = (np.sort(rng.choice(n, size=MAX_DRAWS, replace=False)) if n >= MAX_DRAWS
            else rng.choice(n, size=MAX_DRAWS, replace=True))
    log_a, log_b = mc.shifts_at(t)
    master = mc.master
    if master is None:  # a MasterCurve built by hand, with the structure's name only
        from ..structures import get_structure

        master = get_structure(mc.structure)
    log_a_drawn, log_b_drawn = log_a[rows], log_b[rows]
    notes = [] if temperature is None else [
        f"at {float(t):g} °C from the master curve at {mc.reference_temperature:g} °C with each "
        f"draw's shifts (log10 a_T median {np.median(log_a_drawn):.3g}"
        + ("" if mc.vertical == "none" else f", log10 b_T median {np.median(log_b_drawn):.3g}")
        + ")"]
    if (missed := mc.misfit()):
        notes.append(missed[0].lower() + missed[1:].rstrip(".") + "; the band is the posterior "
                     "of its mean function, without the data's scatter or its misfit, so "
                     "measured values may lie outside it")
    # The window at the posterior mean shift: an isotherm's own frequencies at its own
    # temperature are then inside it.
    return Draws(data=mc.data, parts=((mc.structure, master,
                                       np.asarray(mc.master_draws, float)[rows]),),
                 weights={mc.structure: 1.0}, omega=mc.reduced_omega(), log_a=log_a_drawn,
                 log_b=log_b_drawn, mean_log_a=float(np.mean(log_a)), temperature=float(t),
                 notes=tuple(notes))
