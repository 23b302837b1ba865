"""The HTML report: verdict, numbers, embedded figures, escaping, no external resources."""

from __future__ import annotations

import base64
import math
import re
import subprocess
import sys
import warnings
from dataclasses import replace
from html.parser import HTMLParser

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from bayesfo.comparison import StructureResult, compare  # noqa: E402
from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.errors import PredictiveWarning
from bayesfo.output.report import render_report, verdict, write_report  # noqa: E402
from bayesfo.plotting import plot_bode, plot_ranking, save_figure  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402

W = np.logspace(-1, 2.5, 20)


@pytest.fixture(scope="module")
def comparison():
    """Fractional Voigt compliance with 3 % noise (σ known); Voigt, Zener and the integer
    Voigt compared."""
    rng = np.random.default_rng(3)
    g = get_structure("voigt").response([1.0, 1e-3, 0.5], W, "compliance")
    sd = 0.03 * np.abs(g)
    noisy = g + sd / np.sqrt(2) * (rng.normal(size=W.size) + 1j * rng.normal(size=W.size))
    data = FrequencyResponse(W, noisy, sd, kind="compliance", units="1/Pa",
                             name="voigt sim", source="sim/voigt.csv")
    structures = [get_structure(n) for n in ("voigt", "zener", "voigt-int")]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = compare(data, structures, seed=2, progress=False)
    assert all(w.category is PredictiveWarning for w in caught), [str(w.message) for w in caught]
    return result


@pytest.fixture(scope="module")
def figures(comparison, tmp_path_factory):
    out = tmp_path_factory.mktemp("figures")
    paths = {}
    for name, drawn in (("ranking", plot_ranking(comparison)),
                        ("bode", plot_bode(comparison))):
        paths[name] = [out / f"{name}.png", out / f"{name}.pdf"]
        for p in paths[name]:
            save_figure(drawn.figure, p)
        plt.close(drawn.figure)
    return paths


class _Cells(HTMLParser):
    """Rows of the tables by their id: ``{row id: [(text, data-value or None), ...]}``."""

    def __init__(self):
        super().__init__()
        self.rows, self._row, self._cell = {}, None, None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "tr" and attrs.get("id"):
            self._row = attrs["id"]
            self.rows[self._row] = []
        elif tag == "td" and self._row is not None:
            self._cell = ["", attrs.get("data-value")]

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            self.rows[self._row].append(tuple(self._cell))
            self._cell = None
        elif tag == "tr":
            self._row = None

    def handle_data(self, data):
        if self._cell is not None:
            self._cell[0] += data


def _verdict_text(text: str) -> str:
    block = re.search(r"<div class='verdict' id='verdict'>(.*?)</div>", text, re.S).group(1)
    return re.sub(r"<[^>]+>", " ", block)


def test_verdict_names_the_structure_with_the_highest_evidence(comparison):
    z = {r.name: r.criteria.evidence.log_z for r in comparison.results}
    best = max(z, key=z.get)
    second = sorted(z, key=z.get)[-2]
    sentences = verdict(comparison)
    # Whether the structures fit comes first (the adequacy sentences, flagged where one
    # misfits), then the evidence.
    first = next(t for t, _ in sentences if "best-supported structure:" in t)
    before = sentences[:[t for t, _ in sentences].index(first)]
    assert all("describe" in t or "fit" in t for t, _ in before), before
    assert first.startswith(f"{best} is the best-supported structure")
    assert f"runner-up, {second}," in first
    assert f"Δln Z = {z[best] - z[second]:.2f}" in first
    p = comparison[best].criteria.posterior_probability
    assert (f"{p:.3f}" if p >= 0.001 else "< 0.001") in first
    q = comparison[best].posterior.summary["q"]
    digits = 1 - math.floor(math.log10(q.sd))
    assert any(f"q = {q.mean:.{digits}f} (sd {q.sd:.2g}, 94 % HDI {q.hdi_low:.{digits}f}–"
               f"{q.hdi_high:.{digits}f})" in t for t, _ in sentences)
    html = render_report(comparison)
    assert html.index("id='verdict'") < html.index("id='data'") < html.index("id='ranking'")
    assert f"{best} is the best-supported structure" in _verdict_text(html)


def test_verdict_says_whether_the_criteria_agree(comparison):
    best = comparison.table()[0]
    ranks = [best[f"rank_{c}"] for c in ("loo", "waic", "aic", "bic")]
    text = " ".join(t for t, _ in verdict(comparison))
    if ranks == [1, 1, 1, 1]:
        assert "The information criteria agree" in text
    else:
        assert "prefer" in text


def test_ranking_table_numbers_match_the_comparison(comparison):
    parser = _Cells()
    parser.feed(render_report(comparison))
    table = comparison.table()
    columns = {"log_evidence": 3, "log_evidence_err": 4, "delta_log_evidence": 5,
               "posterior_probability": 6, "loo": 7, "loo_se": 8, "aic": 9,
               "bic": 10, "rmse": 11, "rhat_max": 13}
    # WAIC is not a column (it is in ranking.csv): PSIS-LOO with its Pareto k stands for both.
    assert "elpd WAIC" not in render_report(comparison)
    # The RMSE is in the data's unit (a compliance in 1/Pa here; no unit without one).
    assert "<th>RMSE [1/Pa]</th>" in render_report(comparison)
    bare = replace(comparison, data=replace(comparison.data, units=""))
    assert "<th>RMSE [a.u.]</th>" in render_report(bare) and "[J]" not in render_report(bare)
    for rank, row in enumerate(table, start=1):
        cells = parser.rows[f"row-{row['structure']}"]
        assert cells[0][0] == str(rank) and cells[1][0] == row["structure"]
        assert cells[2][0] == str(row["n_params"])
        for key, i in columns.items():
            text, value = cells[i]
            if row[key] is None or not math.isfinite(row[key]):
                # Undefined for this posterior (R-hat of importance draws): a dash, no value.
                assert value is None and text == "–", key
                continue
            assert float(value) == row[key], key
            if key in ("log_evidence", "loo", "bic"):
                # A ln Z from the tempered ladder is marked L (as in the terminal table).
                mark = " L" if key == "log_evidence" and row["evidence_method"] == "ladder" else ""
                assert text == f"{row[key]:.2f}{mark}"
        assert cells[-2][0] == ("yes" if row["converged"] else "NO")
        # The posterior predictive checks, as the terminal says them.
        assert cells[-1][0] == (row["fits"] or "–").replace("no", "NO")
        # Every fractional order by its symbol, as in ranking.csv (none for integer orders).
        assert cells[-3][0] == (row["orders"] or "–")
    assert any("q " in parser.rows[f"row-{r['structure']}"][-3][0] for r in table)
    assert any(parser.rows[f"row-{r['structure']}"][-1][0] in ("yes", "small", "partly", "NO")
               for r in table)


def test_parameter_summaries_and_priors_are_listed(comparison):
    text = render_report(comparison)
    for r in comparison.results:
        assert f"<h3>{r.name}</h3>" in text
        for name, s in r.posterior.summary.items():
            assert f'data-value="{float(s.mean)!r}">{s.mean:.4g}<' in text
        assert r.structure.formula in text
    assert "log-uniform" in text and "[0, 1]" in text  # the prior of q
    assert "known: the data give sigma per point" in text
    assert "sim/voigt.csv" in text and "1/Pa" in text
    # Compliance data: the priors under the card's J(s); modulus data also name G*(s) in the
    # physical parameters, each integer variant with its orders as fixed.
    assert "<p class='small'>J(s) = b0 / (1 + a1 s^q)." in text
    modulus = replace(comparison, data=replace(comparison.data, kind="modulus", units="Pa"))
    text = render_report(modulus)
    assert ("G*(s) = G_e + c_q s^q, sampled as the card&#x27;s compliance J(s) = b0 / (1 + a1 "
            "s^q).") in text
    assert "G*(s) = G_e + c_q s, sampled as the card&#x27;s compliance J(s) = b0 / (1 + a1 s)." \
        in text
    # The physical parameters say what each is, in a last column.
    assert "<th class='text'>meaning</th>" in text
    assert '<td class="text">retardation time, tau^q = c_q/G_e</td>' in text
    assert '<td class="text">order of the springpot c_q</td>' in text


def test_figures_are_embedded_and_nothing_is_external(comparison, figures):
    text = render_report(comparison, figures)
    uris = re.findall(r"<img src='data:image/png;base64,([A-Za-z0-9+/=]+)'", text)
    assert len(uris) == 2
    assert base64.b64decode(uris[1]) == figures["bode"][0].read_bytes()
    assert "Magnitude and phase of the data" in text
    # No resource from elsewhere: every src/href is a data URI, no scripts or style links.
    assert not re.search(r"(?:src|href)\s*=\s*['\"](?!data:)", text)
    assert not re.search(r"https?://", text)
    assert "<script" not in text and "<link" not in text


def test_sections_come_in_the_order_a_reader_needs_them(comparison, figures):
    # Verdict (adequacy first), ranking, figures; then parameters, priors and diagnostics.
    text = render_report(comparison, figures)
    ids = ["verdict", "data", "ranking", "figures", "parameters", "priors", "diagnostics"]
    at = [text.index(f"id='{i}'") for i in ids]
    assert at == sorted(at)


def test_text_is_escaped(comparison):
    data = replace(comparison.data, name="<b>bold & 'quoted'</b>")
    text = render_report(replace(comparison, data=data))
    assert "<b>bold" not in text
    assert "&lt;b&gt;bold &amp; &#x27;quoted&#x27;&lt;/b&gt;" in text


def test_flags_poor_order_non_convergence_and_failures(comparison):
    best = comparison.ranking[0]
    r = comparison[best]
    q = replace(r.posterior.summary["q"], poorly_determined=True)
    post = replace(r.posterior, summary={**r.posterior.summary, "q": q}, converged=False)
    flagged = StructureResult(r.structure, r.fit, post, r.criteria)
    failed = StructureResult(get_structure("maxwell"), error="nothing admissible (test)")
    results = tuple(flagged if x.name == best else x for x in comparison.results) + (failed,)
    sentences = verdict(replace(comparison, results=results))
    flagged_text = " ".join(t for t, f in sentences if f)
    assert "poorly determined" in flagged_text
    assert f"Caution: the posterior of {best} did not converge" in flagged_text
    runner_up = comparison.ranking[1]
    assert f"whose posterior converged is {runner_up} " in flagged_text
    assert "maxwell (nothing admissible (test))" in flagged_text
    text = render_report(replace(comparison, results=results))
    assert "failed: nothing admissible (test)" in text
    # A runner-up's poorly determined order is named with its structure.
    second = comparison[runner_up]
    q2 = replace(second.posterior.summary["q"], poorly_determined=True)
    post2 = replace(second.posterior, summary={**second.posterior.summary, "q": q2})
    vague = StructureResult(second.structure, second.fit, post2, second.criteria)
    sentences = verdict(replace(comparison, results=tuple(
        vague if x.name == runner_up else x for x in comparison.results)))
    assert (f"Fractional orders poorly determined (HDI wider than half the prior range): "
            f"{runner_up} (q).") in " ".join(t for t, f in sentences if f)


def test_write_report_is_atomic_and_complete(comparison, figures, tmp_path):
    path = write_report(comparison, tmp_path / "out", figures)
    assert path == tmp_path / "out" / "report.html"
    assert path.read_text(encoding="utf-8") == render_report(comparison, figures)
    assert [p.name for p in path.parent.iterdir()] == ["report.html"]


def test_report_module_does_not_import_matplotlib():
    code = "import sys, bayesfo.output.report; sys.exit(int('matplotlib' in sys.modules))"
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


def test_bayes_factor_wording():
    from bayesfo.output.report import _bayes_factor, _strength

    assert _strength(0.5).startswith("not worth") and _strength(2.0) == "positive"
    assert _strength(4.0) == "strong" and _strength(7.0) == "very strong"
    assert _bayes_factor(1.0) == f"{math.e:.3g}" and _bayes_factor(1431.3) == "about 10^622"


@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_verdict_names_a_springpot_models_order_alpha():
    # The fractional Maxwell gel's one order is alpha: the verdict states it as α, not β.
    s = get_structure("fractional_maxwell_gel")
    w = np.logspace(-1, 2, 20)
    rng = np.random.default_rng(4)
    g = s.response(np.array([1.0, 2.0, 0.6]), w, "modulus")
    noisy = g * (1 + 0.01 * (rng.normal(size=w.size) + 1j * rng.normal(size=w.size)))
    result = compare(FrequencyResponse(w, noisy, kind="modulus"), "fractional_maxwell_gel",
                     workers=1, seed=0, progress=False)
    texts = [t for t, _ in verdict(result) if "fractional order" in t]
    assert texts and "is α = " in texts[0] and "β" not in texts[0], texts


def test_the_verdict_says_when_the_data_fail_the_kramers_kronig_test():
    """G′ of one Zener with G″ of one relaxing three times slower: no causal structure can fit
    both, and the verdict says so first, with the size of the inconsistency."""
    w = np.logspace(-1, 2, 25)
    z = get_structure("zener")
    theta = [2.0, 1.0, 0.1, 0.6]
    g = (z.response(theta, w, "modulus").real
         + 1j * z.response([6.0, 1.0, 0.3, 0.6], w, "modulus").imag)
    rng = np.random.default_rng(0)
    g = g * (1 + 0.005 / np.sqrt(2) * (rng.normal(size=25) + 1j * rng.normal(size=25)))
    data = FrequencyResponse(w, g, kind="modulus", units="Pa")
    kk = data.kramers_kronig()
    assert not kk.consistent
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        comparison = compare(data, [get_structure("zener")], seed=0, progress=False, workers=1)
    sentences = verdict(comparison)
    text, flagged = sentences[0]
    assert flagged and text.startswith("Data: the real and imaginary parts are not consistent")
    assert f"{100 * kk.misfit_rms:.2g} % rms" in text


def test_a_runner_up_whose_exponents_hang_on_an_undecided_noise_model_is_named():
    """Non-overlapping intervals under the two noise models, and evidence that gives the
    chosen one less than NOISE_DECISIVE: named with both intervals; decided, or not sensitive:
    nothing (the polystyrene's zener at 160 °C: q 0.236–0.259 against 0.463–0.549, 0.891)."""
    from types import SimpleNamespace

    from bayesfo.output.verdict import _undecided_noise

    def result(p, sensitive=True):
        models = {"constant": {"probability": p, "hdi": {"q": [0.236, 0.259]}},
                  "proportional": {"probability": 1 - p, "hdi": {"q": [0.463, 0.549]}}}
        record = {"chosen": "constant", "models": models, "sensitive": sensitive,
                  "sensitive_parameters": ["q"] if sensitive else []}
        return SimpleNamespace(criteria=SimpleNamespace(noise_models=record))

    assert _undecided_noise("zener", result(0.891)) == (
        "zener (q 0.236–0.259 under constant noise, 0.463–0.549 under proportional; "
        "probability 0.891 for constant)")
    assert _undecided_noise("zener", result(0.995)) == ""
    assert _undecided_noise("zener", result(0.891, sensitive=False)) == ""
    assert _undecided_noise("zener", SimpleNamespace(
        criteria=SimpleNamespace(noise_models=None))) == ""


def test_a_best_structure_that_misses_by_little_is_said_so_first():
    """Every structure fails the checks: where the best one's misfit is small, the verdict
    leads with that, not with "none describes these data" (a new user read the two as
    contradicting each other); where it is not small, "none describes" stays."""
    from types import SimpleNamespace

    from bayesfo.output.verdict import _adequacy_sentences

    def check(small):
        return SimpleNamespace(adequate=False, misfit_small=small, level=0.01,
                               reasons=["residuals are correlated along frequency"])

    def sentences(best_small, other_small):
        results = {"maxwell": SimpleNamespace(adequacy=check(best_small)),
                   "zener": SimpleNamespace(adequacy=check(other_small))}
        rows = [{"structure": "maxwell"}, {"structure": "zener"}]
        return _adequacy_sentences(results, rows)

    [(text, flagged)] = sentences(True, True)
    assert flagged and text.startswith(
        "No candidate passes the posterior predictive checks at the 1 % level, but the best "
        "supported, maxwell, misses the data by little (within 2° in phase and 3.5 % in "
        "magnitude)")
    assert text.endswith("The misfit is as small for zener.")
    [(text, flagged)] = sentences(False, True)
    assert flagged and text.startswith("None of the candidates describes these data")
    assert text.endswith("The misfit is small (within 2° in phase and 3.5 % in magnitude) for "
                         "zener.")


def test_a_time_beyond_the_data_window_is_flagged_as_extrapolation():
    """A time whose HDI lies wholly outside 1/ω_max … 1/ω_min (the Zener's τ = 1.5e-4 s on the
    adhesive at 150 °C, measured over 0.63-126 rad/s), or a modulus wholly above 1.5 times the
    largest measured |G*|, is the model's extrapolation, however narrow; one overlapping the
    data's, or an undetermined one, is not flagged."""
    from types import SimpleNamespace

    from bayesfo.comparison.parameters import extrapolated

    data = SimpleNamespace(omega=np.array([0.628, 125.7]), kind="modulus", units="Pa",
                           symbol="G", response=np.array([1e4 + 2e4j, 2e4 + 3e4j]))
    block = {"tau": {"unit": "s", "hdi_low": 1.0e-4, "hdi_high": 2.1e-4},
             "tau_k": {"unit": "s", "hdi_low": 5e-3, "hdi_high": 2e-2},
             "tau_m": {"unit": "s", "hdi_low": 10.0, "hdi_high": 20.0, "not_determined": True},
             "G_m": {"unit": "Pa", "hdi_low": 1e5, "hdi_high": 2e5},
             "G_e": {"unit": "Pa", "hdi_low": 1e4, "hdi_high": 2e4}}
    # The Zener's G_m on the adhesive at 150 °C: four times the largest |G*| (3.6e4 there).
    assert extrapolated(block, data) == {
        "tau": "beyond the data window (t = 1/ω from 0.00796 to 1.59 s): the model's "
               "extrapolation",
        "G_m": "above every measured |G*| (at most 3.61e+04): the model's extrapolation past "
               "the highest frequency"}
