"""A comparison read back from its output directory (:func:`load`), and what
:func:`~bayesfo.output.write.write_outputs` stores in each structure's NetCDF so that it can
be (:func:`netcdf_for`).

``summary.json`` holds every number of the contract; each ``<structure>.nc`` holds the draws,
the pointwise log-likelihood, the posterior predictive and the data. Besides arviz' groups, each
NetCDF carries these attributes (format :data:`~bayesfo.inference.results.NETCDF_FORMAT`):

``posterior``
    ``bayesfo_format``; the sampler's ``n_steps``, ``burn``, ``thin``, ``acceptance`` and
    ``tau`` (per parameter); the evidence's ``evidence_n_likelihood``, ``evidence_seconds``
    and, for a tempered ladder, ``evidence_reached_log_likelihood``.
``log_likelihood``
    ``pareto_k`` and ``loo_pointwise``: PSIS-LOO's Pareto k̂ and elpd per frequency.
``observed_data``
    ``sigma`` (per frequency) when the data carry σ; with held-out frequencies their
    ``holdout_omega``, ``holdout_real``, ``holdout_imag`` (and ``holdout_sigma``).
"""

from __future__ import annotations

import dataclasses
import json
import math
import warnings
from pathlib import Path

import numpy as np

from ..data import FrequencyResponse
from ..errors import InputError, StructureError
from ..identify.optimize import FitResult
from ..inference import PosteriorResult, external_storage, group_names, open_tree
from ..inference.adequacy import Adequacy
from ..inference.evidence import Evidence
from ..inference.likelihood import NOISE_MODELS
from ..inference.results import NETCDF_FORMAT, ParameterSummary, draws_digest
from ..outdir import one_run
from ..structures import Scaling, default_library, get_structure, load_library
from ..tts import MasterCurve
from ..tts.joint import VERTICAL
from ..tts.model import LAWS, SHIFT_MARGIN, SHIFT_RANGE, ShiftedStructure
from ..tts.spectrum import NAME as SPECTRUM
from ..tts.spectrum import Spectrum
from .criteria_types import Criteria
from .results import Comparison, StructureResult

#: Criteria that summary.json holds as plain numbers (null where not finite).
_NUMBERS = ("max_log_likelihood", "aic", "aicc", "bic", "waic", "waic_se", "loo", "loo_se",
            "pareto_k_max", "rmse")
_HOLDOUT = ("holdout_lpd", "holdout_rmse", "holdout_lpd_pointwise", "holdout_omega")


# ---------------------------------------------------------------------- writing
def netcdf_for(comparison: Comparison, result: StructureResult):
    """The DataTree of ``result`` as its NetCDF stores it: a shallow copy of
    ``result.posterior.idata`` (the result is left as it was) with the attributes
    :func:`load` needs (see the module's docstring)."""
    post = result.posterior
    copy = post.idata.copy(deep=False)
    stats = {"bayesfo_format": NETCDF_FORMAT, "n_steps": int(post.n_steps),
             "burn": int(post.burn), "thin": int(post.thin),
             "acceptance": float(post.acceptance),
             "tau": np.asarray(post.tau, dtype=float).ravel()}
    ev = result.criteria.evidence
    if ev is not None:
        for key, value in (("n_likelihood", ev.n_likelihood), ("seconds", ev.seconds),
                           ("reached_log_likelihood", ev.reached_log_likelihood)):
            if value is not None:
                stats[f"evidence_{key}"] = value
    copy.posterior.attrs.update(stats)
    loo = {k: np.asarray(getattr(result.criteria, k), dtype=float)
           for k in ("pareto_k", "loo_pointwise") if getattr(result.criteria, k) is not None}
    copy.log_likelihood.attrs.update(loo)
    data, held = comparison.data, comparison.holdout
    observed = {}
    if data.sigma is not None:
        observed["sigma"] = np.asarray(data.sigma, dtype=float)
    if held is not None:
        observed.update(holdout_omega=held.omega, holdout_real=held.response.real,
                        holdout_imag=held.response.imag)
        if held.sigma is not None:
            observed["holdout_sigma"] = np.asarray(held.sigma, dtype=float)
    copy.observed_data.attrs.update(observed)
    return copy


# ---------------------------------------------------------------------- reading
def load(directory, *, models=()):
    """The :class:`Comparison` that wrote ``directory`` (``bf.write_outputs`` or
    ``bayesfo compare --out DIR``), read from its ``summary.json`` and NetCDF files without
    running anything; or the :class:`~bayesfo.tts.MasterCurve` of a directory that
    ``bayesfo mastercurve`` wrote (its shifts, laws, checks and joint posterior, from which
    :func:`bayesfo.predict` and :func:`bayesfo.predictions.prony_series` follow).

    Everything comes from those files: the data (frequencies, response, σ, held-out points,
    kind, units, name, source and notes), each structure's posterior (the draws, the
    pointwise log-likelihood and the DataTree as stored; summaries, diagnostics, noise
    model and sampler details), its criteria (with the evidence, the nested-sampling check,
    the noise-model record, the adequacy checks and the warnings) and the optimiser's optimum.
    ``load(d).to_summary()`` is the ``summary.json`` of ``d``, and ``load(d).table()`` the
    rows of the comparison that wrote it. Numbers that ``summary.json`` holds as null (not
    finite) come back as NaN.

    What is not stored is None: ``FitResult.theta_scaled``, ``chi2``, ``weighting``,
    ``n_admissible`` and ``optima`` (the optimiser's details; its ``scaling`` is recomputed
    from the data, as ``compare`` computes it); ``PosteriorResult.samples_scaled`` (the draws on
    the scaled problem). The evidence's ``n_likelihood``, ``seconds`` and
    ``reached_log_likelihood`` are None when the NetCDF does not hold them.

    Parameters
    ----------
    directory : path
        The output directory.
    models : sequence of path, optional
        Card files or directories of structures that are not packaged (``--models``).

    Raises
    ------
    InputError
        A missing directory, ``summary.json`` or NetCDF file, or one that cannot be read or is
        not what ``compare`` writes: the message names the file and what is wrong.
    """
    d = Path(directory)
    if not d.is_dir():
        raise InputError(f"'{d}': " + ("not a directory" if d.exists() else "no such directory")
                         + "; give the output directory of bayesfo compare")
    # The summary and the NetCDF files of one run (a swap under way is waited for, one that a
    # killed run left half-done is completed, and files another run wrote are refused).
    with one_run(d, lambda name: name == "summary.json" or name.endswith(".nc")):
        return _load(d, models)


def _load(d: Path, models) -> Comparison:
    path = d / "summary.json"
    if not path.is_file():
        raise InputError(f"'{path}': " + ("not a regular file" if path.exists() else "missing")
                         + f", so '{d}' holds no complete output of bayesfo compare")
    size = path.stat().st_size
    if size > MAX_SUMMARY_BYTES:
        raise InputError(f"'{path}': {size} bytes, more than the {MAX_SUMMARY_BYTES} a "
                         "summary.json of bayesfo can have; is it the right directory?")
    try:
        summary = json.loads(path.read_text(encoding="utf-8"))
    except UnicodeDecodeError as exc:
        raise InputError(f"'{path}': not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except ValueError as exc:
        raise InputError(f"'{path}': not valid JSON ({exc})") from None
    except RecursionError:
        raise InputError(f"'{path}': nested too deeply to be a summary.json of bayesfo") \
            from None
    except OSError as exc:
        raise InputError(f"'{path}': cannot be read ({exc.strerror or exc})") from None
    library = load_library(extra=list(models)) if models else default_library()
    try:
        if isinstance(summary, dict) and "shift_factors" in summary:
            return _mastercurve(summary, d, library)
        return _comparison(summary, d, library)
    except InputError:
        raise
    except KeyError as exc:
        raise InputError(f"'{path}': entry {exc} is missing: not a summary.json of bayesfo "
                         "compare") from None
    except (TypeError, ValueError, AttributeError, IndexError) as exc:
        raise InputError(f"'{path}': unexpected content ({exc}): not a summary.json of "
                         "bayesfo compare") from None


def _num(value) -> float:
    """A number of summary.json: null (not finite when written) is NaN."""
    return math.nan if value is None else float(value)


#: Largest number of values of one variable of a NetCDF that :func:`load` reads (draws ×
#: frequencies: 4 000 draws of 200 isotherms × 50 points are 4e7); a file that declares more is
#: refused before anything is read.
MAX_NETCDF_VALUES = 50_000_000
#: Largest summary.json that :func:`load` reads [bytes] (a master curve of 200 isotherms writes
#: a few megabytes).
MAX_SUMMARY_BYTES = 64 * 1024 * 1024


def _read_netcdf(path: Path, name: str, s: dict | None = None, n_frequencies=None):
    """The DataTree of ``path``: with ``s`` (the structure's block of summary.json), only the
    groups and variables bayesfo writes, each checked against the numbers of draws and
    frequencies that summary.json gives before it is read; a file whose datasets lie in other
    files (HDF5 external or virtual storage) is refused."""
    import stat


    try:
        info = path.stat()
    except OSError:
        info = None
    if info is None or not stat.S_ISREG(info.st_mode):
        raise InputError(f"'{path}': " + ("missing" if info is None else "not a regular file")
                         + f" (summary.json lists structure '{name}' with a posterior); run the "
                         "command that wrote the directory again")
    keep = sizes = None
    if s is not None:
        params = list(s["parameters"])
        keep = {"posterior": params + ["model_real", "model_imag"], "log_likelihood": ["G"],
                "observed_data": ["G_real", "G_imag"],
                "posterior_predictive": ["G_real", "G_imag"], "sample_stats": ["lp"]}
        sizes = {"chain": None, "draw": None, "omega": int(n_frequencies),
                 "draws": int(s["n_draws"])}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            outside = external_storage(path)
            if outside is not None:
                raise InputError(f"'{path}': its dataset '{outside}' is stored in other files "
                                 "(HDF5 external or virtual storage), which bayesfo never "
                                 "writes; it is not read. Run the command that wrote the "
                                 "directory again")
            idata = open_tree(path, keep, sizes, MAX_NETCDF_VALUES)
    except InputError:
        raise
    except Exception as exc:  # netCDF4 and xarray raise many kinds on a damaged file
        raise InputError(f"'{path}': cannot be read as NetCDF ({type(exc).__name__}: "
                         f"{exc})") from None
    missing = [g for g in ("posterior", "log_likelihood", "observed_data")
               if g not in group_names(idata)]
    if missing:
        raise InputError(f"'{path}': no '{missing[0]}' group: not a NetCDF of bayesfo compare")
    if idata.posterior.attrs.get("bayesfo_format") is None:
        raise InputError(f"'{path}': written by an earlier version of bayesfo, without what "
                         "load needs (burn-in, thinning, σ, PSIS-LOO per frequency); run "
                         "compare again")
    return idata


def _data(summary: dict, idata, path: Path) -> tuple[FrequencyResponse, FrequencyResponse | None]:
    meta = summary["data"]
    obs = idata.observed_data
    omega = np.asarray(obs["omega"].values, dtype=float)
    response = np.empty(omega.shape, dtype=complex)
    response.real = obs["G_real"].values
    response.imag = obs["G_imag"].values
    # NetCDF gives an attribute of one element back as a scalar.
    attrs = {k: np.atleast_1d(v) if k == "sigma" or k.startswith("holdout_") else v
             for k, v in obs.attrs.items()}
    # "symbol" came with the tensile labels (issue 33): an older summary.json means shear, G.
    common = dict(kind=meta["kind"], units=meta.get("units") or "", name=meta["name"],
                  source=meta.get("path") or "", symbol=meta.get("symbol") or "G")
    data = FrequencyResponse(omega, response, attrs.get("sigma"), notes=tuple(meta["notes"]),
                             **common)
    if isinstance(meta["n_frequencies"], bool) or not isinstance(meta["n_frequencies"], int):
        raise _tampered(path.parent / "summary.json", f"'n_frequencies' is "
                        f"{meta['n_frequencies']!r}, not a whole number")
    if data.n_frequencies != meta["n_frequencies"]:
        raise InputError(f"'{path}': {data.n_frequencies} frequencies, but summary.json says "
                         f"{meta['n_frequencies']}")
    if "holdout_omega" not in meta:
        return data, None
    if "holdout_omega" not in attrs:
        raise InputError(f"'{path}': summary.json names held-out frequencies, but the NetCDF "
                         "does not hold them")
    held = np.empty(np.size(attrs["holdout_omega"]), dtype=complex)
    held.real = attrs["holdout_real"]
    held.imag = attrs["holdout_imag"]
    holdout = FrequencyResponse(attrs["holdout_omega"], held,
                                attrs.get("holdout_sigma"), notes=data.notes, **common)
    return data, holdout


def _check_name(name, d: Path) -> None:
    """A structure name is a file stem in this directory: one that reaches elsewhere ("../x",
    "a/b") was not written by a run, and no file outside the directory is opened for it."""
    if not isinstance(name, str) or not name or name in (".", "..") \
            or any(c in name for c in "/\\\0") or Path(name).name != name:
        raise InputError(f"'{d / 'summary.json'}': structure name {name!r} is not a file "
                         "name in the directory; the file was not written by a run")


def _comparison(summary: dict, d: Path, library) -> Comparison:
    entries = summary["structures"]
    where = d / "summary.json"
    for s in entries:
        _check_name(s.get("name"), d)
    names = [s["name"] for s in entries]
    if len(set(names)) != len(names):
        twice = next(n for n in names if names.count(n) > 1)
        raise _tampered(where, f"structure '{twice}' is listed twice")
    for s in entries:
        if "error" in s:
            continue
        _check_noise(s, where)
        p = s.get("posterior_probability")
        if p is not None and not _is_probability(p):
            raise _tampered(where, f"the posterior probability of '{s['name']}' is {p!r}, not "
                                   "a number from 0 to 1")
    files = {}
    for s in entries:
        if "error" not in s and s.get("sampled", True):
            files[s["name"]] = _read_netcdf(d / f"{s['name']}.nc", s["name"], s,
                                            summary["data"]["n_frequencies"])
    if not files:
        raise InputError(f"'{d / 'summary.json'}': no structure has a posterior")
    first = next(iter(files))
    data, holdout = _data(summary, files[first], d / f"{first}.nc")
    results = []
    for s in entries:
        name = s["name"]
        try:
            structure = get_structure(name, library)
        except InputError as exc:
            raise InputError(f"'{d / 'summary.json'}': structure '{name}' is not in the "
                             f"library ({exc}); give its card with models=") from None
        if s.get("picture") and structure.pictures:
            # The picture the run reported (an alias such as fpt chooses one).
            try:
                structure = structure.with_picture(s["picture"])
            except StructureError as exc:
                raise InputError(f"'{d / 'summary.json'}': {exc}") from None
        if structure.n_params != s["n_params"] or structure.formula != s["formula"]:
            raise InputError(f"'{d / 'summary.json'}': the card of '{name}' differs from the "
                             "one the run used (parameters or formula)")
        if "error" in s:
            results.append(StructureResult(structure, error=s["error"]))
            continue
        if not s.get("sampled", True):  # left out by the evidence bound: no NetCDF
            results.append(StructureResult(structure, _fit(s, data), None, _bounded(s)))
            continue
        path = d / f"{name}.nc"
        idata = files[name]
        if not np.array_equal(np.asarray(idata.observed_data["omega"].values), data.omega):
            raise InputError(f"'{path}': its frequencies differ from those of '{first}.nc'")
        if not (np.array_equal(np.asarray(idata.observed_data["G_real"].values),
                               data.response.real)
                and np.array_equal(np.asarray(idata.observed_data["G_imag"].values),
                                   data.response.imag)):
            raise InputError(f"'{path}': its data differ from those of '{first}.nc' (the files "
                             "of two runs); run the command that wrote "
                             f"'{d}' again, or copy the whole directory")
        post = _posterior(s, idata, data, path)
        results.append(StructureResult(structure, _fit(s, data), post,
                                       _criteria(s, idata)))
    return Comparison(data, tuple(results), int(summary["seed"]),
                      ranked_by=summary.get("ranked_by", "log_evidence"), holdout=holdout,
                      evidence_bound=summary.get("evidence_bound"))


def _mastercurve(summary: dict, d: Path, library):
    """The :class:`~bayesfo.tts.MasterCurve` that ``bayesfo mastercurve`` wrote into ``d``
    (what it stores: :mod:`bayesfo.tts.stored`)."""
    where = d / "summary.json"
    if "posterior" not in summary or "isotherms" not in summary:
        raise InputError(f"'{where}': a master curve written by an earlier version of bayesfo, "
                         "without its posterior; run bayesfo mastercurve again")
    _check_master_summary(summary, where)
    name = summary["structure"]
    _check_name(name, d)
    path = d / f"{name}.nc"
    idata = _read_netcdf(path, name, summary["posterior"],
                         sum(int(m["n_frequencies"]) for m in summary["isotherms"]))
    try:
        master = (Spectrum(tuple(float(t) for t in summary["spectrum"]["tau_s"]))
                  if name == SPECTRUM else get_structure(name, library))
    except InputError as exc:
        raise InputError(f"'{where}': structure '{name}' is not in the library ({exc}); give "
                         "its card with models=") from None
    meta, iso = summary["data"], summary["isotherms"]
    obs = idata.observed_data
    omega = np.asarray(obs["omega"].values, dtype=float)
    response = np.asarray(obs["G_real"].values, dtype=float) \
        + 1j * np.asarray(obs["G_imag"].values, dtype=float)
    point = np.atleast_1d(np.asarray(obs.attrs.get("point_isotherm", []), dtype=int))
    counts = [int(m["n_frequencies"]) for m in iso]
    if point.shape != omega.shape or point.size != sum(counts) \
            or np.bincount(point, minlength=len(iso)).tolist() != counts:
        raise InputError(f"'{path}': its points do not match the isotherms summary.json lists")
    sigma = obs.attrs.get("sigma")
    sigma = None if sigma is None else np.atleast_1d(np.asarray(sigma, dtype=float))
    common = dict(kind=meta["kind"], units=meta.get("units") or "",
                  source=meta.get("path") or "", symbol=meta.get("symbol") or "G")
    isotherms = tuple(
        FrequencyResponse(omega[point == i], response[point == i],
                          None if sigma is None else sigma[point == i], name=m["name"],
                          **common)
        for i, m in enumerate(iso))
    joint = FrequencyResponse(omega, response, sigma, name=meta["name"],
                              notes=tuple(meta["notes"]), distinct_frequencies=False, **common)
    temperatures = tuple(float(m["temperature"]) for m in iso)
    if float(summary["reference_temperature"]) not in temperatures:
        raise _tampered(where, f"the reference temperature {summary['reference_temperature']!r} "
                               "is not among the isotherms' temperatures")
    vertical, law = summary.get("vertical", "none"), summary.get("law", "free")
    shifted = ShiftedStructure(master, temperatures,
                               temperatures.index(float(summary["reference_temperature"])),
                               point, None, vertical, law)
    post = _posterior(summary["posterior"], idata, joint, path)
    if post.param_names[:shifted.n_params] != shifted.param_names:
        raise InputError(f"'{path}': its parameters are not those of the master curve of "
                         f"{name} over the isotherms summary.json lists")
    theta = post.samples[:, :shifted.n_params]
    shifts = shifted.log_shifts(theta)
    if not np.all(np.abs(shifts) <= SHIFT_RANGE + SHIFT_MARGIN):
        raise InputError(f"'{path}': shift draws of log10 a_T that are not finite or beyond "
                         f"±{SHIFT_RANGE + SHIFT_MARGIN:g} decades, which no run writes; run "
                         f"bayesfo mastercurve again into '{d}'")
    return MasterCurve(
        structure=name, temperatures=temperatures,
        reference_temperature=float(summary["reference_temperature"]),
        shift_draws=shifts, master_draws=theta[:, :master.n_params],
        posterior=post, log_evidence=_num(summary["log_evidence"]),
        log_evidence_err=_num(summary["log_evidence_err"]), laws=summary["laws"], data=joint,
        isotherms=isotherms, notes=tuple(summary["notes"]), ranking=tuple(summary["structures"]),
        tts_checks=summary["tts_checks"], vertical=vertical,
        vertical_draws=None if vertical == "none" else shifted.log_vertical(theta),
        master=master, law=law, law_evidence=summary.get("law_evidence") or {},
        shifts_from=summary.get("shifts_from") or "joint",
        vertical_evidence=summary.get("vertical_evidence") or {},
        shift_evidence=summary.get("shift_evidence") or {})


def _tampered(where: Path, what: str):
    return InputError(f"'{where}': {what}, which bayesfo never writes (edited?); run the "
                      f"command that wrote '{where.parent}' again")


def _check_master_summary(summary: dict, where: Path) -> None:
    """The blocks of a master curve's summary.json that load passes on unread, checked now
    (a tampered file failed later, in predict or export, with AttributeError or ValueError)."""
    laws = summary.get("laws")
    if not isinstance(laws, dict) or not all(
            isinstance(v, dict) and isinstance(v.get("parameters"), dict)
            and _is_probability(v.get("probability")) for v in laws.values()):
        raise _tampered(where, "'laws' is not a table of shift laws with their parameters and "
                               "probabilities")
    checks = summary.get("tts_checks")
    if not isinstance(checks, dict) or not all(isinstance(v, dict) for v in checks.values()):
        raise _tampered(where, "'tts_checks' is not a table of checks")
    if summary.get("vertical", "none") not in VERTICAL:
        raise _tampered(where, f"'vertical' is {summary.get('vertical')!r}, not one of "
                               f"{', '.join(VERTICAL)}")
    if summary.get("law", "free") not in LAWS or (
            summary.get("law", "free") != "free" and summary["law"] not in laws):
        raise _tampered(where, f"'law' is {summary.get('law')!r}, not one of {', '.join(LAWS)} "
                               "with its entry in 'laws'")
    _check_noise(summary["posterior"], where)


def _is_probability(value) -> bool:
    return (isinstance(value, (int, float)) and not isinstance(value, bool)
            and 0.0 <= value <= 1.0)


def _check_noise(s: dict, where: Path) -> None:
    if s.get("noise") not in NOISE_MODELS:
        raise _tampered(where, f"the noise model of '{s.get('name')}' is {s.get('noise')!r}, "
                               f"not one of {', '.join(NOISE_MODELS)}")


def _posterior(s: dict, idata, data: FrequencyResponse, path: Path) -> PosteriorResult:
    params = s["parameters"]
    names = tuple(params)
    draws = idata.posterior
    missing = [n for n in names if n not in draws]
    if missing:
        raise InputError(f"'{path}': no draws of parameter '{missing[0]}'")
    samples = np.column_stack([np.asarray(draws[n].values, dtype=float).reshape(-1)
                               for n in names])
    if samples.shape[0] != s["n_draws"]:
        raise InputError(f"'{path}': {samples.shape[0]} draws, but summary.json says "
                         f"{s['n_draws']}")
    if not np.all(np.isfinite(samples)):
        raise InputError(f"'{path}': draws that are not finite numbers, which no run writes; "
                         f"run the command that wrote '{path.parent}' again")
    recorded = s.get("draws_sha256")  # runs written before it was recorded have none
    if recorded is not None and recorded != draws_digest(samples):
        raise InputError(f"'{path}': its draws are not those that '{path.parent / 'summary.json'}' "
                         "describes (the file of another run, copied in?); run the command "
                         f"that wrote '{path.parent}' again, or copy the whole directory")
    pointwise = np.asarray(idata.log_likelihood["G"].values, dtype=float)
    loglik = pointwise.reshape(-1, data.n_frequencies).sum(axis=1)
    fields = [f.name for f in dataclasses.fields(ParameterSummary)]
    # A run written before a field existed lacks it: its default (at_prior_bound "").
    summary = {n: ParameterSummary(**{
        f: bool(params[n][f]) if f in ("poorly_determined", "multimodal")
        else str(params[n][f]) if f == "at_prior_bound" else _num(params[n][f])
        for f in fields if f in params[n]}) for n in names}
    attrs = draws.attrs
    return PosteriorResult(
        structure=s["name"], param_names=names, noise=s["noise"], noise_reason=s["noise_reason"],
        samples=samples, samples_scaled=None, log_likelihood=loglik, summary=summary,
        map_theta=np.array([_num(params[n]["map"]) for n in names]),
        max_log_likelihood=float(loglik.max()),
        tau=np.atleast_1d(np.asarray(attrs["tau"], dtype=float)), n_steps=int(s["n_steps"]),
        burn=int(attrs["burn"]), thin=int(attrs["thin"]), n_walkers=int(draws.sizes["chain"]),
        acceptance=float(attrs["acceptance"]), rhat_max=_num(s["rhat_max"]),
        ess_bulk_min=_num(s["ess_bulk_min"]), ess_tail_min=_num(s["ess_tail_min"]),
        converged=bool(s["converged"]), messages=tuple(s["messages"]), idata=idata,
        sampler=s["sampler"])


def _fit(s: dict, data: FrequencyResponse) -> FitResult:
    opt = s["optimum"]
    return FitResult(
        structure=s["name"], param_names=tuple(opt["parameters"]),
        theta=np.array([_num(v) for v in opt["parameters"].values()]), theta_scaled=None,
        rmse=_num(opt["rmse"]), chi2=None, weighting=None, admissible=bool(opt["admissible"]),
        n_starts=int(opt["starts"]), n_admissible=None, n_at_best=int(opt["starts_at_optimum"]),
        optima=None, scaling=Scaling.from_data(data),
        linear={k: np.array([_num(v[n]) for n in opt["parameters"]])
                for k, v in opt.get("linear_methods", {}).items()})


def _evidence(block: dict | None, attrs=None) -> Evidence | None:
    if block is None:
        return None
    attrs = attrs or {}

    def extra(key, cast):
        value = block.get(key, attrs.get(f"evidence_{key}"))
        return None if value is None else cast(value)

    return Evidence(log_z=_num(block["log_z"]), log_z_err=_num(block["log_z_err"]),
                    method=block["method"], log_support=_num(block["log_support"]),
                    n_likelihood=extra("n_likelihood", int), seconds=extra("seconds", float),
                    reached_log_likelihood=extra("reached_log_likelihood", float))


def _adequacy(block: dict | None) -> Adequacy | None:
    if block is None:
        return None
    return Adequacy(
        adequate=bool(block["adequate"]),
        p_values={k: _num(v) for k, v in block["p_values"].items()},
        statistics={k: _num(v) for k, v in block["statistics"].items()},
        level=_num(block["level"]), max_phase_error_deg=_num(block["max_phase_error_deg"]),
        max_phase_error_omega=_num(block["max_phase_error_omega"]),
        max_log10_magnitude_error=_num(block["max_log10_magnitude_error"]),
        max_log10_magnitude_error_omega=_num(block["max_log10_magnitude_error_omega"]),
        systematic_at_omega=tuple(_num(w) for w in block["systematic_at_omega"]),
        systematic_bands=tuple((_num(b["omega_low"]), _num(b["omega_high"]), b["description"])
                               for b in block["systematic_bands"]),
        outside_band_omega=tuple(_num(w) for w in block["outside_band_omega"]),
        noise=block["noise"],
        noise_scale=None if block["noise_scale"] is None else float(block["noise_scale"]),
        noise_scale_implausible=bool(block["noise_scale_implausible"]),
        misfit_small=bool(block["misfit_small"]), reasons=tuple(block["reasons"]),
        summary=block["summary"], n_draws=int(block["n_draws"]),
        n_reference=int(block["n_reference"]), seed=int(block["seed"]),
        # Runs stored before the noise-dominated points were checked have no such keys.
        noise_dominated_omega=tuple(_num(w) for w in block.get("noise_dominated_omega", ())),
        misfit_masked=bool(block.get("misfit_masked", False)),
        masked_phase_error_deg=_num(block.get("masked_phase_error_deg", 0.0)),
        masked_log10_magnitude_error=_num(block.get("masked_log10_magnitude_error", 0.0)),
        caution=block.get("caution", ""))


def _bounded(s: dict) -> Criteria:
    """The criteria of a structure the evidence bound left out (``"sampled": false``)."""
    bound = s.get("bound")
    if not isinstance(bound, dict) or not isinstance(bound.get("log_evidence_bound"),
                                                     (int, float)):
        raise InputError(f"structure '{s['name']}' is not sampled but has no bound of its "
                         "ln Z: not a summary.json of bayesfo compare")
    return Criteria.from_dict({k: _num(s[k]) for k in ("max_log_likelihood", "aic", "aicc",
                                                        "bic", "rmse")}
                              | {"priors": s.get("priors"), "warnings": tuple(s["warnings"]),
                                 "bound": bound, "adequacy": _adequacy(s.get("adequacy"))})


def _criteria(s: dict, idata) -> Criteria:
    values = {k: _num(s[k]) for k in _NUMBERS}
    loo = idata.log_likelihood.attrs
    for key in ("pareto_k", "loo_pointwise"):
        if key in loo:
            values[key] = tuple(float(v) for v in np.atleast_1d(loo[key]))
    method = s.get("evidence_method")
    main = None if method is None else {
        "log_z": s["log_evidence"], "log_z_err": s["log_evidence_err"], "method": method,
        "log_support": s["log_prior_support"]}
    evidence = _evidence(main, idata.posterior.attrs)
    noise_models = s.get("noise_models")
    if evidence is not None and noise_models and "marginal" in noise_models:
        # ln Z marginalised over the noise models; the chosen model's own estimate beside it.
        given = noise_models["models"][noise_models["chosen"]]
        evidence = dataclasses.replace(evidence, given_noise=dataclasses.replace(
            evidence, log_z=_num(given["log_evidence"]),
            log_z_err=_num(given["log_evidence_err"])))
    values.update(
        priors=s["priors"], warnings=tuple(s["warnings"]), importance=s.get("importance"),
        evidence=evidence,
        evidence_check=_evidence(s.get("evidence_check")),
        evidence_agree=s.get("evidence_agree"), noise_models=s.get("noise_models"),
        adequacy=_adequacy(s.get("adequacy")),
        posterior_probability=s.get("posterior_probability"),
        delta_loo_se=s.get("delta_loo_se"))
    for key in _HOLDOUT:
        if key in s:
            values[key] = _num(s[key]) if key in ("holdout_lpd", "holdout_rmse") else s[key]
    return Criteria.from_dict(values)
