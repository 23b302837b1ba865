"""Fuzz tests of the two readers of user files: the CSV reader and the structure-card loader.

The only allowed outcomes are success or an :class:`~bayesfo.errors.InputError` (a
StructureError is one) with a one-line message; any other exception, a RuntimeWarning (an
overflow computed silently) or a result holding NaN fails. The default versions run a fixed,
derandomised set of examples in a few seconds; the ``slow`` versions run many more
(``make test-slow``).
"""

from __future__ import annotations

import json
import math
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bayesfo.data import KNOWN_COLUMNS, MAX_FREQUENCIES, MAX_SPAN, VALUE_RANGE, read_csv
from bayesfo.errors import InputError
from bayesfo.identify.scan import q_grid_scan
from bayesfo.structures import CARD_KEYS, load_library, structures_from_card

FAST = settings(max_examples=150, deadline=None, derandomize=True, database=None,
                suppress_health_check=list(HealthCheck))
SLOW = settings(max_examples=3000, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))

_DIR = tempfile.TemporaryDirectory(prefix="bayesfo-fuzz-")


def _file(name: str) -> Path:
    return Path(_DIR.name) / name


def _check_message(exc: InputError) -> None:
    text = str(exc)
    assert text and "\n" not in text and "Traceback" not in text, repr(text)
    assert len(text) < 2000, text[:200]


# ---------------------------------------------------------------------- CSV
_JUNK_COLUMNS = ["", "foo", " omega ", "OMEGA", "Real", "omega\u200b", "ω", "time", "path"]
_LONG = ["9" * 140_000, "1" * 5000, "x" * 2000, "1e" + "9" * 400, "0." + "3" * 1200]

_finite = st.floats(allow_nan=False, allow_infinity=False)
_positive = st.one_of(st.floats(min_value=1e-3, max_value=1e3).map(repr),
                      st.floats(min_value=1e-3, max_value=1e3).map(lambda x: f"{x:.4g}"),
                      st.integers(1, 1000).map(str))
_signed = st.one_of(st.floats(min_value=-1e3, max_value=1e3).map(repr),
                    st.floats(min_value=-1e3, max_value=1e3).map(lambda x: f"{x:.4g}"))
_PLAUSIBLE = {
    "omega": _positive, "freq": _positive, "magnitude": _positive, "sigma": _positive,
    "phase_deg": st.floats(min_value=-180, max_value=180).map(lambda x: f"{x:.3f}"),
    "series": st.integers(1, 3).map(str),
}
_plausible = st.one_of(_positive, _signed)
_nasty = st.one_of(
    _finite.map(repr),
    _finite.map(lambda x: f"{x:g}"),
    st.floats().map(lambda x: f"{x:.3e}"),
    st.sampled_from(["0", "-0", "1e308", "1e-323", "5e-324", "1e999", "nan", "inf", "-inf",
                     "1_0", "0x10", "\u0661", "\uff11", '"1,5"', ".5", "5.", "+1", "--1", "1e",
                     "e5", "1e30", "1e-30", "1e31", "360", "-361", "1e300", " 1 ", "", '"',
                     "1e-16", "1e16", "1e15", "1e-15"]),
    st.text(max_size=8).filter(lambda t: "," not in t and '"' not in t),
)
_comments = st.one_of(
    st.sampled_from(["# kind: modulus", "# kind: compliance", "# kind: generic", "# kind: fluid",
                     "# units: Pa", "# name: sample 3", "#", "# kind:", "#:", "# name: x",
                     "# kind: modulus", "# kind: compliance", "# units: 1/MPa", "#,omega"]),
    st.text(max_size=20).map(lambda t: "#" + t),
)
_cells = st.one_of(_plausible, _nasty)


@st.composite
def csv_bytes(draw) -> bytes:
    """A readable data file with a few faults: nasty cells, rows of the wrong width, junk
    headers, comments, long cells, invisible characters, line endings, BOMs, UTF-16."""
    header = draw(st.sampled_from([
        ["omega", "real", "imag"], ["freq", "magnitude", "phase_deg"],
        ["omega", "storage", "loss", "sigma"], ["omega", "real", "imag", "series"],
        ["freq", "real", "imag", "sigma", "series"], ["omega", "magnitude", "phase_deg", "sigma"],
    ]))
    if draw(st.integers(0, 9)) == 0:  # a header with junk or known names in any order
        header = draw(st.lists(st.sampled_from(list(KNOWN_COLUMNS) + _JUNK_COLUMNS),
                               min_size=1, max_size=6))
    rows = []
    for _ in range(draw(st.integers(1, 12))):
        rows.append([draw(_PLAUSIBLE.get(col, _signed)) for col in header])
    for _ in range(draw(st.integers(0, 3))):  # faults
        row = rows[draw(st.integers(0, len(rows) - 1))]
        fault = draw(st.integers(0, 9))
        if fault == 0:
            row.append(draw(_cells))
        elif fault == 1 and row:
            row.pop()
        elif row:
            row[draw(st.integers(0, len(row) - 1))] = draw(_nasty)
    lines = [",".join(header)] + [",".join(row) for row in rows]
    for _ in range(draw(st.sampled_from([0, 0, 0, 1, 2, 3]))):
        lines.insert(draw(st.integers(0, len(lines))), draw(_comments))
    if draw(st.integers(0, 29)) == 0:
        lines.insert(draw(st.integers(1, len(lines))), "1,1," + draw(st.sampled_from(_LONG)))
    newline = draw(st.sampled_from(["\n", "\r\n", "\r", "\n"]))
    text = newline.join(lines) + draw(st.sampled_from(["", newline]))
    if draw(st.integers(0, 19)) == 0:  # an invisible character somewhere
        pos = draw(st.integers(0, len(text)))
        text = text[:pos] + draw(st.sampled_from(["\x00", "\ufeff", "\x07", "\u200b"])) + text[pos:]
    encoding = draw(st.sampled_from(["utf-8"] * 12 + ["utf-8-sig", "utf-16"]))
    return text.encode(encoding, errors="surrogatepass")


def _read_fuzzed(content: bytes) -> None:
    path = _file("fuzz.csv")
    path.write_bytes(content)
    with warnings.catch_warnings():
        # A UserWarning (single replicate) is an allowed outcome; numerical warnings are not.
        warnings.simplefilter("ignore", UserWarning)
        warnings.simplefilter("error", RuntimeWarning)
        try:
            fr = read_csv(path)
        except InputError as exc:
            _check_message(exc)
            return
    lo, hi = VALUE_RANGE
    assert 1 <= fr.n_frequencies <= MAX_FREQUENCIES
    assert np.all(np.isfinite(fr.omega)) and np.all(np.isfinite(fr.response))
    assert np.all(np.diff(fr.omega) > 0)
    assert np.all((fr.omega >= lo) & (fr.omega <= hi))
    mag = np.abs(fr.response)
    assert np.all(mag > 0) and mag.max() <= MAX_SPAN * mag.min()
    assert fr.omega.max() <= MAX_SPAN * fr.omega.min()
    if fr.sigma is not None:
        assert np.all(np.isfinite(fr.sigma)) and np.all(fr.sigma > 0)
    assert math.isfinite(fr.omega_ref) and math.isfinite(fr.g_ref) and fr.g_ref > 0
    # What the fits do first with accepted data must not fail or compute non-finite scales.
    inv = fr.reciprocal()
    assert np.all(np.isfinite(inv.response))
    assert inv.sigma is None or np.all(np.isfinite(inv.sigma) & (inv.sigma > 0))
    if fr.n_frequencies >= 2:
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            scan = q_grid_scan(fr, 1, 1, 3, q_grid=[0.3, 0.9])
        assert np.all(~np.isnan(scan.rmse))


@FAST
@given(csv_bytes())
def test_fuzz_csv_reader(content):
    _read_fuzzed(content)


@pytest.mark.slow
@SLOW
@given(csv_bytes())
def test_fuzz_csv_reader_many(content):
    _read_fuzzed(content)


# ---------------------------------------------------------------------- structure cards
_names = st.sampled_from(["a1", "a2", "b0", "b1", "b2", "q", "alpha", "beta", "c", "nan", "inf",
                          "1x", "", "a*", "b*"])
_exponents = st.one_of(
    st.sampled_from(["q", "2*q", "0.5*q", "1..2*q", "99999999999*q", "6*q", "7*q", "alpha",
                     "inf", "nan", "-1*q", "1e400*q", "1_0*q", "*q", "q*", "2**q", " 2 * q ",
                     "beta", "0", "1", "-1"]),
    st.integers(-10, 10),
    st.floats(),
    st.booleans(),
    st.lists(st.integers(), max_size=2),
    st.text(max_size=6),
)
_coefs = st.one_of(_names, st.floats(), st.integers(-3, 3), st.booleans(),
                   st.sampled_from(["1", "1e999", "nan", "inf", "-2.5"]), st.none())
_terms = st.one_of(
    st.lists(st.one_of(st.tuples(_coefs, _exponents).map(list),
                       st.lists(_coefs, max_size=3), _coefs), max_size=4),
    _coefs,
)
_prior_values = st.one_of(st.floats(), st.integers(-10**20, 10**20), st.booleans(),
                          st.sampled_from(["0", "x", None]),
                          st.sampled_from([0.0, 1.0, 1e-4, 1e4, -100.0, 100.0, 1e-300, 1e300]))
_priors = st.one_of(
    st.fixed_dictionaries(
        {"prior": st.sampled_from(["uniform", "log-uniform", "normal", "beta", 3])},
        optional={"low": _prior_values, "high": _prior_values, "mu": _prior_values,
                  "sd": _prior_values, "extra": _prior_values},
    ),
    _prior_values,
    st.lists(_prior_values, max_size=2),
)
_GOOD_PRIORS = {
    "a1": {"prior": "log-uniform", "low": 1e-4, "high": 1e4},
    "b0": {"prior": "log-uniform", "low": 1e-4, "high": 1e4},
    "b1": {"prior": "log-uniform", "low": 1e-4, "high": 1e4},
    "q": {"prior": "uniform", "low": 0.0, "high": 1.0},
    "a*": {"prior": "uniform", "low": -100.0, "high": 100.0},
    "b*": {"prior": "uniform", "low": -100.0, "high": 100.0},
}
_constraints = st.one_of(
    st.lists(st.one_of(st.sampled_from(["stable", "passive", "b1 <= a1*b0", "alpha <= beta",
                                        "a1 <= nan", "q < 1", "a1 <=", "<= b0", "q <= 2*q",
                                        "a1 * b0 > 1e999", "causal"]),
                       st.text(max_size=8), st.integers()), max_size=3),
    st.booleans(), st.text(max_size=8), st.integers(),
)


_TEMPLATES = [
    {"name": "fz", "numerator": [["b0", 0]], "denominator": [[1, 0], ["a1", "q"]],
     "constraints": ["stable", "passive"],
     "parameters": {k: _GOOD_PRIORS[k] for k in ("a1", "b0", "q")}},
    {"name": "fz", "numerator": [["b0", 0], ["b1", "q"]], "denominator": [[1, 0], ["a1", "q"]],
     "constraints": ["stable", "passive", "b1 <= a1*b0"],
     "parameters": {k: _GOOD_PRIORS[k] for k in ("a1", "b0", "b1", "q")}},
    {"name": "fz", "numerator": [[1, 0], ["b1", "alpha"]], "denominator": [["a1", "beta"]],
     "constraints": ["stable", "passive", "alpha <= beta"],
     "parameters": {"a1": _GOOD_PRIORS["a1"], "b1": _GOOD_PRIORS["b1"],
                    "alpha": _GOOD_PRIORS["q"], "beta": _GOOD_PRIORS["q"]}},
    {"name": "fz", "family": "max-order", "n_max": 2, "constraints": ["stable", "passive"],
     "parameters": {k: _GOOD_PRIORS[k] for k in ("a*", "b*", "q")}},
]


@st.composite
def cards(draw) -> dict:
    """A valid card with a few of its entries replaced by nasty values."""
    card = json.loads(json.dumps(draw(st.sampled_from(_TEMPLATES))))
    for _ in range(draw(st.integers(0, 3))):
        what = draw(st.sampled_from(["name", "term", "side", "exponent", "coefficient", "n_max",
                                     "constraints", "prior", "prior value", "parameters",
                                     "drop", "extra key", "family"]))
        if what == "name":
            card["name"] = draw(st.one_of(st.sampled_from(["voigt", "Bad", "", "fz_2"]),
                                          st.integers(), st.text(max_size=5)))
        elif what in ("term", "exponent", "coefficient") and "numerator" in card:
            side = card.get(draw(st.sampled_from(["numerator", "denominator"])))
            if not isinstance(side, list) or not side:
                continue
            i = draw(st.integers(0, len(side) - 1))
            if not isinstance(side[i], list) or len(side[i]) != 2:
                continue
            if what == "term":
                side[i] = draw(st.one_of(st.tuples(_coefs, _exponents).map(list),
                                         st.lists(_coefs, max_size=3), _coefs))
            elif what == "exponent":
                side[i] = [side[i][0], draw(_exponents)]
            else:
                side[i] = [draw(_coefs), side[i][1]]
        elif what == "side":
            card[draw(st.sampled_from(["numerator", "denominator"]))] = draw(_terms)
        elif what == "n_max":
            card["n_max"] = draw(st.one_of(st.integers(-2, 8), st.floats(), st.text(max_size=3),
                                           st.booleans(), st.integers()))
        elif what == "constraints":
            card["constraints"] = draw(_constraints)
        elif what == "prior" and isinstance(card.get("parameters"), dict):
            key = draw(st.one_of(st.sampled_from(sorted(card["parameters"]) + ["c", "a2", "q"]),
                                 st.text(max_size=4)))
            card["parameters"][key] = draw(_priors)
        elif what == "prior value" and isinstance(card.get("parameters"), dict):
            key = draw(st.sampled_from(sorted(card["parameters"])))
            if isinstance(card["parameters"][key], dict):
                field = draw(st.sampled_from(["low", "high", "mu", "sd", "prior"]))
                card["parameters"][key][field] = draw(_prior_values)
        elif what == "parameters":
            card["parameters"] = draw(_prior_values)
        elif what == "drop":
            card.pop(draw(st.sampled_from(sorted(card))), None)
        elif what == "extra key":
            key = st.one_of(st.sampled_from(sorted(CARD_KEYS) + ["colour"]), st.text(max_size=4))
            card[draw(key)] = draw(st.one_of(
                st.text(max_size=4), st.floats(), st.integers(), st.booleans(),
                st.lists(st.integers(), max_size=2)))
        elif what == "family":
            card["family"] = draw(st.sampled_from(["max-order", "other", 3, None]))
    return card


def _exercise(structures) -> None:
    """What the command line does next with a loaded structure: describe it, evaluate it at the
    prior medians and test its constraints. None of it may raise."""
    omega = np.logspace(-2, 2, 5)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        for s in structures:
            json.dumps(s.describe())
            assert s.formula
            theta = np.array([p.prior.ppf(0.5) for p in s.parameters], dtype=float)
            s.response(theta, omega, "compliance")
            s.admissible(theta, "modulus")


def _load_fuzzed(card: dict) -> None:
    try:
        structures = structures_from_card(card, source="fuzz.toml")
    except InputError as exc:
        _check_message(exc)
        return
    _exercise(structures)


@FAST
@given(cards())
def test_fuzz_structure_cards(card):
    _load_fuzzed(card)


@pytest.mark.slow
@SLOW
@given(cards())
def test_fuzz_structure_cards_many(card):
    _load_fuzzed(card)


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value) if abs(value) < 2**63 else json.dumps(str(value))
    if isinstance(value, float):
        return "nan" if math.isnan(value) else ("inf" if value > 0 else "-inf") \
            if math.isinf(value) else repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_value(v) for v in value if v is not None) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{json.dumps(str(k))} = {_toml_value(v)}"
                               for k, v in value.items() if v is not None) + "}"
    return json.dumps(str(value))


def _toml(card: dict) -> str:
    return "\n".join(f"{json.dumps(str(k))} = {_toml_value(v)}"
                     for k, v in card.items() if v is not None) + "\n"


_MUTATIONS = st.lists(st.tuples(st.integers(0, 10_000), st.integers(0, 3),
                                st.sampled_from(["", "[", "]", "\"", "=", "\n", "x", "9", "*",
                                                 "{", "}", ",", "#", "\x00", "inf", "-"])),
                      max_size=3)


def _load_card_text(text: str) -> None:
    path = _file("fuzz.toml")
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    try:
        library = load_library(extra=[path])
    except InputError as exc:
        _check_message(exc)
        return
    _exercise([s for s in library.values() if s.card == str(path)])


def _mutated_card(card, mutations) -> None:
    """A card's TOML text with bytes cut and inserted, loaded: success or an InputError."""
    text = _toml(card)
    for pos, cut, insert in mutations:
        pos = pos % (len(text) + 1)
        text = text[:pos] + insert + text[pos + cut:]
    _load_card_text(text)


@FAST
@given(cards(), _MUTATIONS)
def test_fuzz_card_files(card, mutations):
    _mutated_card(card, mutations)


@pytest.mark.slow
@SLOW
@given(cards(), _MUTATIONS)
def test_fuzz_card_files_many(card, mutations):
    _mutated_card(card, mutations)


def test_fuzzers_reach_success():
    """The generators are not all rejection: each reader also succeeds on a plain input."""
    path = _file("plain.csv")
    path.write_text("# kind: compliance\nomega,real,imag\n1,1,-1\n2,0.8,-0.7\n")
    assert read_csv(path).n_frequencies == 2
    card = {"name": "fz", "numerator": [["b0", 0]], "denominator": [[1, 0], ["a1", "q"]],
            "parameters": {k: _GOOD_PRIORS[k] for k in ("a1", "b0", "q")},
            "constraints": ["stable", "passive"]}
    assert [s.name for s in structures_from_card(card)] == ["fz", "fz-int", "fz-inv", "fz-inv-int"]
    _load_card_text(_toml(card))
