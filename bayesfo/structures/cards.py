"""Structure cards (``bayesfo/models/*.toml``) and the library they make: reading and checking cards,
expanding max-order families and variants, and resolving names and shortcuts."""

from __future__ import annotations

import math
import os
import re
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np

from .._io import read_text_file, show
from ..errors import InputError, StructureError
from ..priors import prior_from_dict
from .physical import Picture
from .structure import Parameter, Structure
from .terms import MAX_DEGREE, Exponent, Inequality, Term, parse_coefficient
from .variants import integer_is_degenerate, integer_variant, inverted_variant

N_MAX_DEFAULT = 3


MODEL_PATH_ENV = "BAYESFO_MODEL_PATH"


def _parse_terms(spec, where: str) -> tuple[Term, ...]:
    if not isinstance(spec, list) or not spec:
        raise StructureError(f"{where}: expected a list of [coefficient, exponent] pairs")
    terms = []
    for i, item in enumerate(spec):
        if not isinstance(item, list) or len(item) != 2:
            raise StructureError(f"{where}, term {i + 1}: expected [coefficient, exponent], got {item!r}")
        coef = parse_coefficient(item[0], f"{where}, term {i + 1}")
        terms.append(Term(coef, Exponent.parse(item[1], f"{where}, term {i + 1}")))
    return tuple(terms)


def _parameters(names, table: dict, where: str, exponent_names) -> tuple[Parameter, ...]:
    params = []
    for name in names:
        spec = table.get(name)
        if spec is None:
            for pattern, s in table.items():
                if pattern.endswith("*") and name.startswith(pattern[:-1]) and name[len(pattern) - 1:].isdigit():
                    spec = s
                    break
        if spec is None:
            raise StructureError(f"{where}: no prior for parameter '{name}'")
        role = "exponent" if name in exponent_names else "coefficient"
        params.append(Parameter(name, role, prior_from_dict(spec, f"{where}, parameter {show(name)}")))
    return tuple(params)


def _common(card: dict, where: str) -> dict:
    constraints = []
    raw = card.get("constraints", [])
    if not isinstance(raw, list):
        raise StructureError(
            f"{where}: 'constraints' must be a list of text, e.g. [\"stable\", \"passive\"], "
            f"got {raw!r}"
        )
    for c in raw:
        if not isinstance(c, str):
            raise StructureError(f"{where}: constraints must be text, got {c!r}")
        constraints.append(c if c in ("stable", "passive") else Inequality.parse(c, where))
    return {
        "title": str(card.get("title", "")),
        "description": str(card.get("description", "")),
        "reference": str(card.get("reference", "")),
        "constraints": tuple(constraints),
    }


CARD_KEYS = {"name", "title", "description", "reference", "numerator", "denominator",
             "constraints", "parameters", "family", "n_max", "order", "aliases", "physical",
             "integer", "inverted"}

_ALIAS = re.compile(r"[a-z][a-z0-9_]*")


def _aliases(card: dict, where: str) -> tuple[str, ...]:
    raw = card.get("aliases", [])
    if not isinstance(raw, list) or not all(isinstance(a, str) for a in raw):
        raise StructureError(f"{where}: 'aliases' must be a list of names, got {raw!r}")
    for a in raw:
        if not _ALIAS.fullmatch(a):
            raise StructureError(f"{where}: alias {show(a)} must be lower-case letters, digits "
                                 "or '_'")
    return tuple(raw)


def _pictures(card: dict, where: str, name: str) -> tuple[Picture, ...]:
    raw = card.get("physical")
    if raw is None:
        return ()
    raw = [raw] if isinstance(raw, dict) else raw
    if not isinstance(raw, list) or not raw:
        raise StructureError(f"{where}: 'physical' must be a table or a list of tables")
    out = []
    for i, spec in enumerate(raw):
        pic = Picture.from_card(spec, f"{where}, physical {i + 1}", name)
        for a in (pic.name,) + pic.aliases:
            if not _ALIAS.fullmatch(a):
                raise StructureError(f"{where}, physical {i + 1}: name {show(a)} must be "
                                     "lower-case letters, digits or '_'")
        out.append(pic)
    return tuple(out)


def _integer_option(card: dict, where: str):
    value = card.get("integer", "auto")
    if isinstance(value, bool) or value == "auto":
        return value
    if isinstance(value, str) and re.fullmatch(r"[a-z][a-z0-9_-]*", value):
        return value
    raise StructureError(f"{where}: 'integer' must be true, false, \"auto\" or the name of the "
                         f"structure that is the integer-order baseline, got {value!r}")


def structures_from_card(card: dict, source: str = "", n_max: int | None = None) -> list[Structure]:
    """All structures a card declares, including the generated ``-int`` and ``-inv`` variants.

    Raises
    ------
    StructureError
        Naming the card and the entry that cannot be used.
    """
    if not isinstance(card, dict):
        raise StructureError(f"card '{source}': expected a table of keys, got {type(card).__name__}")
    name = card.get("name")
    where = f"card '{source or name}'"
    if not isinstance(name, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", name):
        raise StructureError(f"{where}: 'name' must be lower-case letters, digits or '_', got {name!r}")
    unknown = set(card) - CARD_KEYS
    if unknown:
        raise StructureError(f"{where}: unknown key {show(sorted(unknown)[0])}")
    table = card.get("parameters", {})
    if not isinstance(table, dict):
        raise StructureError(f"{where}: 'parameters' must be a table")
    common = _common(card, where)
    family = card.get("family")
    inverted = card.get("inverted", True)
    if not isinstance(inverted, bool):
        raise StructureError(f"{where}: 'inverted' must be true or false, got {inverted!r}")
    integer = _integer_option(card, where)
    out: list[Structure] = []
    if family is None:
        num = _parse_terms(card.get("numerator"), f"{where}, numerator")
        den = _parse_terms(card.get("denominator"), f"{where}, denominator")
        expo = {p for t in num + den for p in t.exponent.params}
        used = [n for n in table if not n.endswith("*")]
        params = _parameters(used, table, where, expo)
        pics = _pictures(card, where, name)
        aliases = _aliases(card, where) + tuple(
            a for p in pics for a in (p.name,) + p.aliases if a != name)
        base = Structure(name, num, den, params, family=name, card=source, pictures=pics,
                         aliases=aliases, baseline=integer if isinstance(integer, str)
                         and integer != "auto" else "", **common)
        for i, pic in enumerate(pics):
            pic.check(base, f"{where}, physical {i + 1}")
        bases = [(base, True, inverted)]
    elif family == "max-order":
        for key in ("physical", "aliases"):
            if key in card:
                raise StructureError(f"{where}: {key!r} is not available for a family card")
        if n_max is not None:
            nmax = _check_n_max(n_max, "argument 'n_max'")
        else:
            nmax = _check_n_max(card.get("n_max", N_MAX_DEFAULT), f"{where}: 'n_max'")
        bases = []
        pairs = {(n, m) for n in range(1, nmax + 1) for m in range(n + 1)}
        inv_pairs = {(n, m) for m in range(1, nmax + 1) for n in range(m + 1)}
        for n, m in sorted(pairs | inv_pairs, key=lambda p: (max(p), p[0], p[1])):
            num = tuple(Term(f"b{k}", Exponent.of("q", k) if k else Exponent()) for k in range(m + 1))
            den = (Term(1.0, Exponent()),) + tuple(
                Term(f"a{k}", Exponent.of("q", k)) for k in range(1, n + 1)
            )
            names = [f"a{k}" for k in range(1, n + 1)] + [f"b{k}" for k in range(m + 1)] + ["q"]
            params = _parameters(names, table, where, {"q"})
            s = Structure(
                f"{name}-n{n}m{m}", num, den, params, family=name, degrees=(n, m), card=source,
                **common,
            )
            bases.append((s, (n, m) in pairs, inverted and (n, m) in inv_pairs))
    else:
        raise StructureError(f"{where}: unknown family {family!r}; known: 'max-order'")
    for base, plain, inverse in bases:
        variants = []
        if plain:
            variants.append(base)
        if inverse:
            variants.append(inverted_variant(base))
        make_int = bool(base.exponent_params) and (
            integer is True or (family is not None and integer == "auto")
            or (integer == "auto" and not integer_is_degenerate(base, integer_variant(base))))
        for v in variants:
            out.append(v)
            if make_int:
                out.append(integer_variant(v))
    return out


def _check_n_max(value, what: str) -> int:
    """``value`` as the highest degree of a max-order family: an integer 1..MAX_DEGREE."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise StructureError(
            f"{what} must be a whole number from 1 to {MAX_DEGREE}, got {value!r}"
        )
    if not 1 <= value <= MAX_DEGREE:
        raise StructureError(
            f"{what} must be from 1 to {MAX_DEGREE} (the highest degree of a max-order member; "
            f"the thesis uses 3), got {value}"
        )
    return int(value)


def card_paths(extra=()) -> list[Path]:
    """The card files: the packaged ``models/``, then ``$BAYESFO_MODEL_PATH``, then ``extra``.

    ``extra`` entries may be card files or directories of cards.
    """
    paths = sorted(
        Path(str(p)) for p in resources.files("bayesfo.models").iterdir() if p.name.endswith(".toml")
    )
    dirs = [d for d in os.environ.get(MODEL_PATH_ENV, "").split(os.pathsep) if d]
    for entry in [*dirs, *extra]:
        entry = Path(entry)
        if entry.is_dir():
            paths.extend(sorted(entry.glob("*.toml")))
        elif entry.is_file():
            paths.append(entry)
        elif entry.exists():
            raise StructureError(f"model card path '{entry}' is not a regular file or a directory")
        else:
            raise StructureError(f"model card path '{entry}' does not exist")
    return paths


#: Largest card file (bytes): a card is a few dozen lines.
MAX_CARD_BYTES = 1024 * 1024


#: Structures of recently read cards by (path, text, n_max): structures are immutable, and
#: checking a card (units, pictures, integer baselines) costs more than reading it.
_CARD_CACHE: dict[tuple, list[Structure]] = {}


def _card_structures(card: dict, source: str, n_max, text: str) -> list[Structure]:
    key = (source, text, n_max)
    if key not in _CARD_CACHE:
        if len(_CARD_CACHE) > 256:
            _CARD_CACHE.clear()
        _CARD_CACHE[key] = structures_from_card(card, source=source, n_max=n_max)
    return _CARD_CACHE[key]


class Library(dict):
    """Structures by name (a dict), with their aliases.

    ``aliases`` maps another name to ``(structure name, picture name or None)``: the names
    users of rheology packages know (``fractional_kelvin_voigt_s`` for ``voigt``), the pictures
    of a card (``fractional_poynting_thomson`` for ``zener`` read as a spring in series with a
    fractional Kelvin–Voigt element) and integer baselines that are other structures
    (``fractional_maxwell_gel-int`` is ``maxwell-int``). A structure's own name always wins over
    an alias; of two cards claiming one alias the first loaded keeps it.
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.aliases: dict[str, tuple[str, str | None]] = {}

    def lookup(self, name: str) -> tuple[Structure, str | None] | None:
        """``(structure, picture)`` for a name or an alias (also with ``-int``/``-inv``
        suffixes, e.g. ``fkv-int``), or None."""
        if name in self:
            return self[name], None
        if name in self.aliases:
            target, picture = self.aliases[name]
            return (self[target], picture) if target in self else None
        for suffix in ("-inv-int", "-int", "-inv"):
            if name.endswith(suffix) and name[: -len(suffix)] in self.aliases:
                target, picture = self.aliases[name[: -len(suffix)]]
                found = self.lookup(target + suffix)
                if found is not None:
                    return found[0], picture if suffix == "-int" else found[1]
        return None


def load_library(extra=(), n_max: int | None = None) -> Library:
    """Every structure of every card, by name (a :class:`Library`, a dict with aliases).

    Parameters
    ----------
    extra : sequence of path-like
        Additional card files or directories (a user's own structures).
    n_max : int, optional
        Highest order of the max-order family (default: the card's ``n_max``, 3).

    Raises
    ------
    StructureError
        For an unreadable card, two cards declaring the same structure name, or an integer
        baseline naming an unknown structure.
    """
    if n_max is not None:
        _check_n_max(n_max, "argument 'n_max'")
    library = Library()
    cards = []
    for i, path in enumerate(card_paths(extra)):
        try:
            text = read_text_file(path, "card", max_bytes=MAX_CARD_BYTES)
        except InputError as exc:
            raise StructureError(str(exc)) from None
        try:
            card = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise StructureError(f"card '{path}' is not valid TOML: {exc}") from None
        except RecursionError:
            raise StructureError(f"card '{path}' is not valid TOML: arrays or tables nested "
                                 "too deeply") from None
        order = card.get("order", 1000)
        if isinstance(order, bool) or not isinstance(order, (int, float)) or not math.isfinite(order):
            raise StructureError(f"card '{path}': 'order' must be a finite number, got {order!r}")
        cards.append((order, i, path, card, text))
    aliases: dict[str, tuple[str, str | None]] = {}
    for _, _, path, card, text in sorted(cards, key=lambda c: c[:2]):
        for s in _card_structures(card, str(path), n_max, text):
            if s.name in library:
                raise StructureError(
                    f"card '{path}' declares structure '{s.name}', already declared by "
                    f"card '{library[s.name].card}'"
                )
            library[s.name] = s
            if s.inverted or s.integer:
                continue
            for a in s.aliases:
                picture = next((p.name for p in s.pictures if a == p.name or a in p.aliases),
                               None)
                aliases.setdefault(a, (s.name, picture))
            if s.baseline:
                aliases.setdefault(f"{s.name}-int", (s.baseline, None))
    for s in library.values():
        if s.baseline and s.baseline not in library:
            raise StructureError(f"card '{s.card}': 'integer' names {show(s.baseline)}, which "
                                 "is not a structure of the library")
    library.aliases = {a: t for a, t in aliases.items() if a not in library}
    return library


_DEFAULT_LIBRARY: Library | None = None


def default_library() -> Library:
    """The packaged structures (cached)."""
    global _DEFAULT_LIBRARY
    if _DEFAULT_LIBRARY is None:
        _DEFAULT_LIBRARY = load_library()
    return _DEFAULT_LIBRARY


def list_structures(models=()):
    """The structures available to :func:`~bayesfo.comparison.compare`, one row each.

    Parameters
    ----------
    models : sequence of path-like, optional
        Additional card files or directories (a user's own structures), as ``--models``.

    Returns
    -------
    pandas.DataFrame
        Columns ``name``, ``title``, ``formula`` (compliance form of the card), ``n_params``,
        ``parameters`` (comma list), ``family``, ``integer`` and ``inverted`` (the variants of
        a card), ``aliases`` (other names ``compare`` accepts, comma list) and ``picture`` (the
        mechanical model of its physical parameters; empty without one).

    Examples
    --------
    >>> import bayesfo as bf
    >>> table = bf.list_structures()
    >>> table.set_index("name").loc["fractional_kelvin_voigt", "aliases"]
    'fkv, fractional_kelvin_voigt_model'
    >>> bool((table["name"] == "maxwell-int").any())
    True
    """
    import pandas as pd

    lib = load_library(extra=models) if models else default_library()
    rows = []
    for s in lib.values():
        rows.append({
            "name": s.name, "title": s.title, "formula": s.formula, "n_params": s.n_params,
            "parameters": ", ".join(s.param_names), "family": s.family, "integer": s.integer,
            "inverted": s.inverted, "aliases": ", ".join(s.aliases),
            "picture": s.pictures[0].title if s.pictures else "",
        })
    return pd.DataFrame(rows)


def get_structure(name: str, library: dict[str, Structure] | None = None) -> Structure:
    """The structure called ``name`` (e.g. ``"zener"``, ``"max-n2m1"``, ``"zener-inv-int"``)
    or one of its aliases (``"fractional_kelvin_voigt"``, ``"fzss"``)."""
    library = default_library() if library is None else library
    found = _find(name, library)
    if found is not None:
        return found[0]
    raise StructureError(
        f"unknown structure {show(str(name))}{_did_you_mean(name, library)}; known structures: "
        f"{', '.join(_short_list(library))}"
    )


def _find(name, library) -> tuple[Structure, str | None] | None:
    """``(structure, picture)`` for ``name`` as given, else in lower case with ``_`` for
    spaces (``Voigt``, ``Fractional Kelvin Voigt``); None where neither names one."""
    if not isinstance(name, str):
        return None
    for candidate in dict.fromkeys((name, name.strip().lower().replace(" ", "_"))):
        if candidate in library:
            return library[candidate], None
        found = library.lookup(candidate) if isinstance(library, Library) else None
        if found is not None:
            return found
    return None


def _did_you_mean(name, library) -> str:
    """``" (did you mean 'zener'?)"`` for the closest known names, or an empty string."""
    import difflib

    known = list(library) + list(getattr(library, "aliases", {}))
    close = difflib.get_close_matches(str(name).strip().lower(), known, n=3, cutoff=0.6)
    return f" (did you mean {' or '.join(show(c) for c in close)}?)" if close else ""


def picture_for(name: str, library: dict[str, Structure] | None = None) -> str | None:
    """The picture an alias names (``"fractional_poynting_thomson"`` → the Poynting–Thomson
    picture of ``zener``), None for a structure's own name or an alias without a picture."""
    library = default_library() if library is None else library
    found = _find(name, library)
    return None if found is None else found[1]


def _short_list(library) -> list[str]:
    bases = [n for n, s in library.items() if not (s.inverted or s.integer)]
    return bases + ["NAME-int", "NAME-inv", "maxN", "all"]


def resolve_structures(spec: str | list[str], library: dict[str, Structure] | None = None) -> list[Structure]:
    """Structures named by a comma list with the shortcuts ``maxN`` and ``all``.

    ``maxN`` is every max-order member with n ≤ N (``maxN-inv``: the inverted members with
    m ≤ N); ``all`` is every structure of the library with all its variants.
    """
    library = default_library() if library is None else library
    if isinstance(spec, str):
        names = spec.split(",")
    elif isinstance(spec, (list, tuple)) and all(isinstance(n, str) for n in spec):
        names = list(spec)
    else:
        raise StructureError(f"structures must be given as a comma list of names, got {spec!r}")
    out: list[Structure] = []
    for raw in names:
        name = raw.strip()
        if not name:
            raise StructureError(f"empty structure name in {spec!r}")
        m = re.fullmatch(r"max([0-9]+)(-inv)?(-int)?", name.lower())
        if name.lower() == "all":
            chosen = list(library.values())
        elif m:
            limit, inv, integer = int(m.group(1)), bool(m.group(2)), bool(m.group(3))
            members = [s for s in library.values() if s.degrees is not None and s.family == "max"]
            if not members:
                raise StructureError(
                    f"'{name}': the library has no max-order family (a card with "
                    "name = \"max\" and family = \"max-order\")"
                )
            top = max(s.degrees[1] if s.inverted else s.degrees[0] for s in members)
            if not 1 <= limit <= top:
                raise StructureError(
                    f"'{name}' asks for the max-order members up to degree {limit}, but the "
                    f"library has them up to {top}: use max1 to max{top}, or raise n_max in "
                    f"the card '{members[0].card}' (at most {MAX_DEGREE})"
                )
            chosen = [
                s for s in members
                if s.inverted == inv and s.integer == integer
                and (s.degrees[1] if inv else s.degrees[0]) <= limit
            ]
        else:
            s = get_structure(name, library)
            # An alias that names a picture (fpt: the Poynting–Thomson picture of zener)
            # reports the physical parameters of that picture.
            picture = picture_for(name, library)
            chosen = [s if picture is None else s.with_picture(picture)]
        for s in chosen:
            same = next((o for o in out if o.name == s.name), None)
            if same is None:
                out.append(s)
            elif same != s:
                raise StructureError(
                    f"'{name}' and an earlier name in {spec!r} are the same structure "
                    f"'{s.name}' with different pictures; give it once")
    return out

