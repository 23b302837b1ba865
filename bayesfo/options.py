"""Options of a comparison, checked before any work: the same checks for ``compare``, ``batch``
(command line and manifests) and the API.

The options travel as a plain dict (picklable, JSON for a batch task's fingerprint); every value
is checked and put in canonical form by :func:`check_options`, so a misspelt option or a bad
value fails at once, naming where it came from, and never inside a worker.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ._io import parse_number, show
from .data.frequency_response import KINDS  # noqa: F401  (the kinds an option may name)
from .errors import InputError

DEFAULT_STRUCTURES = "voigt,zener,maxwell,fractional_kelvin_voigt,voigt-int,zener-int,maxwell-int"
#: Which structures get their own corner (and trace) figures by default: the leading ones (the
#: combined figures show every structure). Besides it, a number (the best that many by the
#: ranking) or None (every structure).
LEADING = "leading"
STRUCTURE_FIGURES = LEADING
#: Of the structures that the evidence does not rule out, at most this many lead.
LEADING_STRUCTURES = 3
#: ln B from which the evidence for one structure over another is "very strong" (Kass & Raftery
#: 1995: 2 ln B above 10): a structure that far below the best is ruled out (here, where the
#: command line's help can name it without importing the comparison).
VERY_STRONG = 5.0


def parse_floats(text: str, option: str) -> list[float]:
    try:
        return [parse_number(v) for v in text.split(",") if v.strip()]
    except ValueError as exc:
        raise InputError(f"{option} takes comma-separated numbers, got {show(text)}: "
                         f"{exc}") from None


def parse_priors(specs) -> dict:
    from .priors import prior_from_dict

    out = {}
    for spec in specs:
        name, _, rest = spec.partition("=")
        parts = rest.split(":")
        if not name or len(parts) != 3:
            raise InputError(f"--prior takes NAME=TYPE:A:B (e.g. q=uniform:0.2:1), got {spec!r}")
        kind, a, b = parts
        keys = ("mu", "sd") if kind == "normal" else ("low", "high")
        try:
            values = {keys[0]: parse_number(a), keys[1]: parse_number(b)}
        except ValueError as exc:
            raise InputError(f"--prior {show(spec)}: the bounds must be numbers ({exc})") \
                from None
        if name.strip() in out:
            raise InputError(f"--prior {spec!r}: a prior for '{name.strip()}' is already given; "
                             "give one --prior per parameter")
        out[name.strip()] = prior_from_dict({"prior": kind, **values}, f"--prior {spec!r}")
    return out



#: Options of one data set, with the defaults of ``bayesfo compare``.
DEFAULT_OPTIONS = {
    "kind": None,            # None: the file's '# kind:' line, else generic
    "reciprocal": False,     # compare 1/G of the data
    "structures": None,      # comma list; None: DEFAULT_STRUCTURES of the command line
    "noise": "auto",
    "priors": (),            # NAME=TYPE:A:B specifications
    "holdout": None,         # angular frequencies [rad/s] left out of the fit
    "evidence": "auto",      # ln Z from the emcee draws (bridge), a tempered ladder, or auto
    "sampler": "auto",       # importance sampling where certified, else emcee; or emcee
    "evidence_check": False,
    "max_steps": None,       # emcee's cap on steps (None: 10 000)
    "walkers": None,         # emcee walkers (None: max(32, 4 x parameters))
    "models": (),            # extra structure cards (paths)
    "figures": True,         # per-data-set figures and report.html, as bayesfo compare
    "figure_formats": ("png",),  # their file formats
    "structure_figures": STRUCTURE_FIGURES,  # corner (trace) figures: "leading", N best, None: all
    "sample": "needed",      # "all": sample every structure, also those the evidence bound rules out
}

#: Options added after batch directories were first written: a data set's record leaves them
#: out at these values, so that directories written before they existed stay complete.
LATER_OPTIONS = {k: DEFAULT_OPTIONS[k] for k in ("figure_formats", "structure_figures",
                                                  "sample")}

EVIDENCE_ROUTES = ("auto", "bridge", "ladder")
SAMPLERS = ("auto", "emcee")
#: Which structures a comparison samples: ``"needed"`` leaves out those whose best fit bounds
#: their ln Z far below the leader's (:mod:`bayesfo.inference.bound`); ``"all"`` samples every one.
SAMPLE = ("needed", "all")


NOISE_MODELS = ("auto", "known", "constant", "proportional", "relative_parts")


#: What ``structure_figures`` takes, for the messages that refuse another value.
STRUCTURE_FIGURES_TAKES = (f"'{LEADING}', a non-negative integer (the best that many) or None "
                           "(every structure)")


def structure_figures_ok(value) -> bool:
    """Whether ``value`` is a ``structure_figures`` option: :data:`LEADING`, a non-negative
    integer or None."""
    return value is None or value == LEADING or (
        isinstance(value, int) and not isinstance(value, bool) and value >= 0)


def figure_format_names(formats, argument: str) -> tuple[str, ...]:
    """Figure file formats as given (a name or a sequence of names) in lower case without dots,
    each once; :class:`InputError` naming ``argument`` when none is given or ``formats`` is
    not a name or a sequence of them. Whether matplotlib writes them is
    :func:`bayesfo.plotting.output.check_formats`'s to say."""
    if isinstance(formats, str):
        formats = (formats,)
    if not isinstance(formats, (tuple, list)):
        raise InputError(f"{argument} must be a sequence of file formats (e.g. ('png', "
                         f"'pdf')), got {formats!r}")
    formats = tuple(dict.fromkeys(str(f).strip().lower().lstrip(".") for f in formats))
    if not formats:
        raise InputError(f"{argument} is empty")
    return formats


def check_options(options: dict, where: str) -> dict:
    """Check the options of one data set before any work and put them in canonical form.

    Parameters
    ----------
    options : dict
        Keys of :data:`DEFAULT_OPTIONS` (missing keys take the defaults).
    where : str
        Names the source of the options in messages (e.g. ``"manifest 'm.csv', line 3"``).

    Returns
    -------
    dict
        The options with ``structures`` as a tuple of structure names, ``priors`` a tuple of
        specifications, ``holdout`` a tuple of floats or None, ``models`` a tuple of absolute
        paths.

    Raises
    ------
    InputError
        For an unknown option, kind, noise model or structure, a malformed or unused prior, or a
        hold-out frequency that is not a positive number; the message starts with ``where``.
    """
    from .structures import default_library, load_library, resolve_structures

    unknown = set(options) - set(DEFAULT_OPTIONS)
    if unknown:
        raise InputError(f"{where}: unknown option '{sorted(unknown)[0]}'")
    opts = {**DEFAULT_OPTIONS, **options}
    if opts["kind"] is not None and opts["kind"] not in KINDS:
        raise InputError(f"{where}: kind must be one of {', '.join(KINDS)}, got {opts['kind']!r}")
    check_routes(opts["sampler"], opts["evidence"], where)
    check_sample(opts["sample"], where)
    if opts["noise"] not in NOISE_MODELS:
        raise InputError(f"{where}: noise must be one of {', '.join(NOISE_MODELS)}, "
                         f"got {opts['noise']!r}")
    check_sampler_settings(opts, where)
    models = tuple(str(Path(m).resolve()) for m in opts["models"])
    try:
        library = load_library(extra=models) if models else default_library()
        spec = opts["structures"] or DEFAULT_STRUCTURES
        names = spec if isinstance(spec, str) else ",".join(spec)
        structures = resolve_structures(names, library)
        priors = tuple(opts["priors"])
        parsed = parse_priors(priors)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    known = {p for s in structures for p in s.param_names} | {"sigma", "sigma_rel"}
    unused = [k for k in parsed if k not in known]
    if unused:
        raise InputError(f"{where}: prior '{unused[0]}' names a parameter no selected "
                         "structure has")
    detail = opts["structure_figures"]
    # Whether matplotlib writes each format is checked where the figures are drawn (and by the
    # command line before any work): this layer does not import the plotting.
    formats = (figure_format_names(opts["figure_formats"], f"{where}: figure_formats")
               if opts["figures"] else DEFAULT_OPTIONS["figure_formats"])
    if not structure_figures_ok(detail):
        raise InputError(f"{where}: structure_figures must be {STRUCTURE_FIGURES_TAKES}, got "
                         f"{detail!r}")
    holdout = opts["holdout"]
    if holdout is not None:
        holdout = tuple(float(w) for w in holdout)
        if not holdout:
            holdout = None
        elif not all(math.isfinite(w) and w > 0 for w in holdout):
            raise InputError(f"{where}: hold-out frequencies must be positive numbers, "
                             f"got {holdout}")
    return {"kind": opts["kind"], "reciprocal": bool(opts["reciprocal"]),
            "structures": tuple(s.name for s in structures), "noise": opts["noise"],
            "priors": priors, "holdout": holdout, "evidence": opts["evidence"],
            "sampler": opts["sampler"],
            "evidence_check": bool(opts["evidence_check"]),
            "max_steps": opts["max_steps"], "walkers": opts["walkers"],
            "models": models, "figures": bool(opts["figures"]),
            "figure_formats": formats, "structure_figures": detail, "sample": opts["sample"]}


#: Seeds are 32-bit: every random generator in the chain (numpy, scipy, emcee) accepts them.
MAX_SEED = 2**32 - 1


#: Limits of the emcee settings, checked before any work: emcee keeps the whole chain in memory
#: (walkers × steps × parameters × 8 bytes, allocated for max_steps at the start), so their
#: product is capped too (2·10^7 positions: 1.6 GB at ten parameters, 60 times the defaults).
MAX_WALKERS = 10_000
MAX_STEPS = 10_000_000
MAX_CHAIN = 20_000_000


#: The names of the sampled noise scales (of the noise models ``constant``; ``proportional``
#: and ``relative_parts``), which a prior may name beside the structures' parameters.
NOISE_PARAMETERS = ("sigma", "sigma_rel")


def check_prior_names(priors, structures) -> None:
    """Check that every prior of ``priors`` (``{name: Prior}``) names a parameter of one of
    ``structures`` or a noise scale (:data:`NOISE_PARAMETERS`), before any work: a misspelt
    name is refused, not left unused.

    Raises
    ------
    InputError
        Naming the parameter and the closest real one (``option="priors"``).
    """
    known = {p for s in structures for p in s.param_names} | set(NOISE_PARAMETERS)
    unknown = [k for k in (priors or {}) if k not in known]
    if unknown:
        import difflib

        names = sorted(known)
        close = difflib.get_close_matches(unknown[0], names, n=1)
        hint = f"did you mean '{close[0]}'? " if close else ""
        raise InputError(f"argument 'priors' names '{unknown[0]}', which no selected structure "
                         f"has; {hint}the selected structures' parameters (as sampled, on the "
                         f"scaled problem) are: {', '.join(names)}", option="priors")


def check_sample(sample, where: str | None = None) -> None:
    """Check which structures to sample, ``sample`` (:data:`SAMPLE`); the message starts with
    ``where`` where given.

    Raises
    ------
    InputError
        Naming the option (``option="sample"``).
    """
    if sample not in SAMPLE:
        at = f"{where}: " if where else ""
        raise InputError(f"{at}sample must be one of {', '.join(SAMPLE)}, got {sample!r}",
                         option="sample", where=where)


def check_routes(sampler, evidence, where: str | None = None) -> None:
    """Check the posterior route ``sampler`` (:data:`SAMPLERS`) and the ln Z route
    ``evidence`` (:data:`EVIDENCE_ROUTES`); the message starts with ``where`` where given.

    Raises
    ------
    InputError
        Naming the option (``option="sampler"`` or ``"evidence"``).
    """
    at = f"{where}: " if where else ""
    if sampler not in SAMPLERS:
        raise InputError(f"{at}sampler must be one of {', '.join(SAMPLERS)}, got {sampler!r}",
                         option="sampler", where=where)
    if evidence not in EVIDENCE_ROUTES:
        raise InputError(f"{at}evidence must be one of {', '.join(EVIDENCE_ROUTES)}, "
                         f"got {evidence!r}", option="evidence", where=where)


def check_sampler_settings(options: dict, where: str) -> None:
    """``max_steps`` (100 to :data:`MAX_STEPS`) and ``walkers`` (8 to :data:`MAX_WALKERS`) are
    integers or None, and together within :data:`MAX_CHAIN` positions."""
    for key, least, most in (("max_steps", 100, MAX_STEPS), ("walkers", 8, MAX_WALKERS)):
        value = options.get(key)
        flag = "--" + key.replace("_", "-")
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)
                                  or value < least):
            raise InputError(f"{where}: {key} ({flag}) must be an integer of at least {least}, "
                             f"got {value!r}")
        if value is not None and value > most:
            raise InputError(f"{where}: {key} ({flag}) must be at most {most:,}, got {value:,}")
    steps, walkers = options.get("max_steps"), options.get("walkers")
    if steps is not None and walkers is not None and steps * walkers > MAX_CHAIN:
        raise InputError(f"{where}: --walkers {walkers:,} × --max-steps {steps:,} = "
                         f"{steps * walkers:,} chain positions, more than the {MAX_CHAIN:,} that "
                         "fit in memory; lower one of them")


def sampler_options(options: dict) -> dict:
    """The emcee options of checked ``options`` (:func:`check_options`) as keyword arguments of
    :func:`~bayesfo.comparison.compare`: only those the user set."""
    out = {}
    if options.get("max_steps") is not None:
        out["max_steps"] = options["max_steps"]
    if options.get("walkers") is not None:
        out["n_walkers"] = options["walkers"]
    return out


def check_seed(seed, where: str) -> int:
    if (isinstance(seed, bool) or not isinstance(seed, (int, np.integer))
            or not 0 <= seed <= MAX_SEED):
        raise InputError(f"{where}: the seed must be an integer from 0 to {MAX_SEED}, "
                         f"got {seed!r}")
    return int(seed)


def seed_argument(text: str) -> int:
    """argparse type of ``--seed``."""
    import argparse

    try:
        value = int(text)
    except ValueError:
        value = None
    if value is None or not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"expected an integer from 0 to {MAX_SEED}, got {text!r}")
    return value

