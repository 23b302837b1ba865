"""bayesfo compare: the summary.json contract, files, ranking, real data."""

from __future__ import annotations

import csv
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from bayesfo.comparison import compare
from bayesfo.data import FrequencyResponse
from bayesfo.errors import PredictiveWarning
from bayesfo.output import write_outputs
from bayesfo.structures import get_structure, resolve_structures

W = np.logspace(np.log10(0.6), np.log10(300), 25)
ADHESIVE = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"
CONTRACT = {"name", "inverted", "integer", "n_params", "parameters", "log_evidence",
            "log_evidence_err", "evidence_method", "max_log_likelihood", "aic", "aicc", "bic",
            "waic", "loo", "loo_se", "pareto_k_max", "rhat_max", "ess_min", "converged", "rmse",
            "posterior_probability"}


@pytest.fixture(scope="module")
def voigt_comparison(tmp_path_factory):
    rng = np.random.default_rng(0)
    g = get_structure("voigt").response([1.0, 1e-3, 0.5], W, "compliance")
    sd = 0.02 * np.abs(g)
    data = FrequencyResponse(W, g + sd / np.sqrt(2) * (rng.normal(size=25) + 1j * rng.normal(size=25)),
                             sd, kind="compliance", name="simulated voigt")
    # The integer baseline is badly misspecified here: its PSIS-LOO is flagged as unreliable.
    with pytest.warns(PredictiveWarning, match="voigt-int: Pareto k") as record:
        result = compare(data, resolve_structures("voigt,voigt-int,zener"), seed=1, progress=False)
    assert all("voigt-int" in str(w.message) for w in record if w.category is PredictiveWarning)
    assert result["voigt-int"].criteria.pareto_k_max > 0.7
    out = tmp_path_factory.mktemp("cmp")
    write_outputs(result, out, figures=False)  # figures: tests/integration/test_plotting.py and the CLI test
    return result, out


def test_summary_contract_and_files(voigt_comparison):
    result, out = voigt_comparison
    summary = json.loads((out / "summary.json").read_text())
    assert summary["data"]["n_frequencies"] == 25 and summary["data"]["kind"] == "compliance"
    assert {s["name"] for s in summary["structures"]} == {"voigt", "voigt-int", "zener"}
    for s in summary["structures"]:
        assert CONTRACT <= set(s)
        for p in s["parameters"].values():
            assert {"mean", "sd", "hdi_low", "hdi_high", "map"} <= set(p)
            assert p["hdi_low"] <= p["mean"] <= p["hdi_high"]
        assert s["n_params"] == get_structure(s["name"]).n_params
        nc = xr.open_datatree(out / f"{s['name']}.nc")  # as arviz 1.x users read it
        assert nc.log_likelihood["G"].shape[-1] == 25
    # The true q = 0.5 structure beats its integer baseline clearly, by every criterion, and the
    # ranking follows ln Z with probabilities from it (equal prior odds).
    assert summary["ranking"].index("voigt") < summary["ranking"].index("voigt-int")
    z = {s["name"]: s["log_evidence"] for s in summary["structures"]}
    assert summary["ranking"] == sorted(z, key=lambda n: -z[n])
    p = {s["name"]: s["posterior_probability"] for s in summary["structures"]}
    assert p["voigt"] / p["zener"] == pytest.approx(np.exp(z["voigt"] - z["zener"]), rel=1e-9)
    assert sum(p.values()) == pytest.approx(1.0)
    v, vi = (next(s for s in summary["structures"] if s["name"] == n) for n in ("voigt", "voigt-int"))
    assert vi["parent"] == "voigt" and v["parent"] is None
    assert v["loo"] > vi["loo"] + 10 and v["bic"] < vi["bic"] - 10
    q = v["parameters"]["q"]
    assert abs(q["mean"] - 0.5) < 4 * q["sd"] and q["sd"] < 0.01
    # The baseline sits next to its parent: the ln Z difference, and q = 1 outside the HDI.
    (pair,) = summary["baselines"]
    assert (pair["parent"], pair["baseline"], pair["order"]) == ("voigt", "voigt-int", "q")
    assert pair["delta_log_evidence"] == pytest.approx(z["voigt"] - z["voigt-int"])
    assert pair["delta_log_evidence"] > 10 and not pair["order_hdi_includes_1"]
    assert pair["order_hdi"] == [q["hdi_low"], q["hdi_high"]]
    assert pair["orders"] == [{"name": "q", "symbol": "q", "mean": q["mean"],
                               "hdi": [q["hdi_low"], q["hdi_high"]], "hdi_includes_1": False}]
    with (out / "ranking.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["structure"] for r in rows] == summary["ranking"]


def test_criteria_are_consistent(voigt_comparison):
    result, _ = voigt_comparison
    r = result["voigt"]
    k, n = 3, 50  # known sigma: no noise parameter; 25 complex points = 50 real numbers
    c = r.criteria
    assert c.aic == pytest.approx(2 * k - 2 * c.max_log_likelihood)
    assert c.bic == pytest.approx(k * np.log(n) - 2 * c.max_log_likelihood)
    assert c.aicc == pytest.approx(c.aic + 2 * k * (k + 1) / (n - k - 1))
    # elpd estimates lie below the maximum log-likelihood by about the number of parameters.
    assert c.max_log_likelihood - 10 < c.loo < c.max_log_likelihood
    assert c.rmse < 0.05 * 1e-3


def test_interrupted_write_leaves_no_summary(voigt_comparison, tmp_path, monkeypatch):
    result, _ = voigt_comparison
    import bayesfo.output.write as cmp

    def boom(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(cmp.json, "dumps", boom)
    with pytest.raises(KeyboardInterrupt):
        write_outputs(result, tmp_path)
    assert not (tmp_path / "summary.json").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


# Whether PSIS-LOO flags the lowest frequency of these 17 points (Pareto k near 0.7) depends on
# the draws; this test is about the command's outputs, so that warning is not an error here.
@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_cli_compare_on_real_adhesive_data(run_cli, tmp_path):
    out = tmp_path / "adhesive"
    status, stdout, err = run_cli("compare", ADHESIVE, "--structures", "voigt,zener-int",
                                  "--out", out, "--prior", "q=uniform:0.2:1")
    assert status == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["data"]["kind"] == "modulus" and summary["data"]["n_frequencies"] == 17
    voigt = next(s for s in summary["structures"] if s["name"] == "voigt")
    assert voigt["priors"]["q"] == {"prior": "uniform", "low": 0.2, "high": 1.0}
    # No sigma in the file: the noise model with the largest evidence (constant, by about 7
    # nats over proportional and 9.6 over relative_parts on this isotherm), each stated.
    assert voigt["noise_models"]["chosen"] == voigt["noise"] == "constant"
    assert set(voigt["noise_models"]["models"]) == {"constant", "proportional", "relative_parts"}
    assert "chosen by evidence" in voigt["noise_reason"]
    assert voigt["converged"] and 0.5 < voigt["parameters"]["q"]["mean"] < 0.6
    assert "ranked by log-evidence" in stdout
    # A well-posed structure: posterior and ln Z by certified importance sampling.
    assert summary["ranked_by"] == "log_evidence" and voigt["evidence_method"] == "importance"
    assert voigt["sampler"] == "importance"
    assert voigt["log_evidence"] < voigt["max_log_likelihood"]
    assert sum(s["posterior_probability"] for s in summary["structures"]) == pytest.approx(1.0)
    # The report names the winner by ln Z, and the figures it embeds are on disk.
    report = (out / "report.html").read_text()
    assert f"{summary['ranking'][0]} is the best-supported structure" in report
    assert report.count("data:image/png;base64,") == len(list((out / "figures").glob("*.png")))
    # PNG by default (the report embeds it); PDF where asked for.
    assert not list((out / "figures").glob("*.pdf"))
    assert str(out / "report.html") in stdout


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--prior", "q=uniform:0.2"], "NAME=TYPE:A:B"),
        (["--prior", "q=beta:0:1"], "unknown prior 'beta'"),
        (["--prior", "zeta=uniform:0:1"], "no selected structure has"),
        (["--prior", "qq=uniform:0:1"], "did you mean 'q'? the selected structures' parameters "
                                        "(as sampled, on the scaled problem) are: "),
        (["--structures", "voigt,nope"], "unknown structure 'nope'"),
    ],
)
def test_cli_compare_bad_options(run_cli, tmp_path, argv, message):
    status, _, err = run_cli("compare", ADHESIVE, "--out", tmp_path / "x", *argv)
    assert status == 2 and message in err and len(err.strip().splitlines()) == 1


def test_holdout_log_predictive_density_and_families():
    from scipy import stats
    from scipy.special import logsumexp

    rng = np.random.default_rng(4)
    s = get_structure("voigt")
    g = s.response([1.0, 1e-3, 0.5], W, "compliance")
    sd = 0.02 * np.abs(g)
    data = FrequencyResponse(W, g + sd / np.sqrt(2) * (rng.normal(size=25) + 1j * rng.normal(size=25)),
                             sd, kind="compliance")
    held = [W[3], W[17]]
    with pytest.warns(PredictiveWarning):
        result = compare(data, resolve_structures("voigt,voigt-int"), seed=2, progress=False,
                         holdout=held)
    assert result.data.n_frequencies == 23
    np.testing.assert_allclose(result.holdout.omega, held)
    v = result["voigt"]
    # Independent computation from the physical draws with scipy: mean predictive density.
    draws = v.posterior.samples
    model = s.response(draws, np.array(held), "compliance")
    obs = data.response[[3, 17]]
    logp = (stats.norm.logpdf(obs.real, model.real, sd[[3, 17]] / np.sqrt(2))
            + stats.norm.logpdf(obs.imag, model.imag, sd[[3, 17]] / np.sqrt(2)))
    expected = (logsumexp(logp, axis=0) - np.log(draws.shape[0])).sum()
    assert v.criteria.holdout_lpd == pytest.approx(expected, rel=1e-9)
    assert v.criteria.holdout_lpd > result["voigt-int"].criteria.holdout_lpd + 5
    assert v.criteria.holdout_rmse < 0.05 * np.abs(obs).max()
    (family,) = result.families()
    z = [result[n].criteria.evidence.log_z for n in ("voigt", "voigt-int")]
    assert family["log_evidence"] == pytest.approx(np.logaddexp(*z) - np.log(2))


def test_tables_of_several_comparisons_combine(voigt_comparison):
    import pandas as pd

    result, _ = voigt_comparison
    frame = result.to_dataframe()
    rows = result.table()
    assert list(frame["structure"]) == [r["structure"] for r in rows]
    assert np.allclose(frame["log_evidence"], [r["log_evidence"] for r in rows])
    both = pd.concat([frame, frame.assign(data="copy")], ignore_index=True)
    assert both.groupby("data")["log_evidence"].max().nunique() == 1 and len(both) == 2 * len(rows)


def test_worker_processes_give_the_same_numbers(voigt_comparison):
    result, _ = voigt_comparison
    data = result.data
    with pytest.warns(PredictiveWarning, match="voigt-int: Pareto k"):
        parallel = compare(data, resolve_structures("voigt,voigt-int"), seed=1, progress=False,
                           workers=2)
    for name in ("voigt", "voigt-int"):
        a, b = result[name], parallel[name]
        assert a.criteria.evidence.log_z == b.criteria.evidence.log_z
        assert np.array_equal(a.posterior.samples, b.posterior.samples)
    with pytest.raises(ValueError, match="workers"):
        compare(data, resolve_structures("voigt"), workers=-1)


def test_ladder_evidence_where_the_posterior_did_not_converge(voigt_comparison):
    import math
    import warnings

    from bayesfo.errors import InputError

    result, _ = voigt_comparison
    data, voigt = result.data, resolve_structures("voigt")
    bridge = result["voigt"].criteria.evidence
    ladder = compare(data, voigt, seed=1, progress=False, evidence="ladder")["voigt"]
    ev = ladder.criteria.evidence
    assert ev.method == "ladder" and ladder.posterior.converged
    # Two independent estimators of the same integral.
    assert abs(ev.log_z - bridge.log_z) < 4 * math.hypot(ev.log_z_err, bridge.log_z_err) + 0.02
    # 100 steps are too few for the convergence check: "auto" then takes the ladder's value.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        short = compare(data, voigt, seed=1, progress=False, max_steps=100,
                        sampler="emcee")["voigt"]
    assert short.criteria.evidence.method == "ladder"
    # ... and the ladder's particles, whose two runs agree, are the posterior reported.
    assert short.posterior.sampler == "ladder" and short.posterior.converged
    # The ladder's guide (the draws) differs, its integral does not.
    other = short.criteria.evidence
    assert abs(other.log_z - ev.log_z) < 4 * math.hypot(other.log_z_err, ev.log_z_err) + 0.02
    assert not any("unreliable" in w for w in short.criteria.warnings)
    # The report marks the ladder's value and says how it was computed.
    from bayesfo.output.report import render_report

    html = render_report(compare(data, voigt, seed=1, progress=False, evidence="ladder"))
    assert f"{ev.log_z:.2f} L</td>" in html and "ln Z from a tempered ladder" in html
    # A ladder run that ends well below the best fit is flagged (its ln Z may be too low).
    from bayesfo.errors import EvidenceWarning
    from bayesfo.inference import Likelihood
    from bayesfo.inference.certified import _evidence

    lik, best = Likelihood(voigt[0], data), result["voigt"].criteria.max_log_likelihood
    assert abs(best - ev.reached_log_likelihood) < 2
    ok = _evidence(lik, result["voigt"].posterior, 1, "ladder", best_log_likelihood=best)
    assert not ok["warnings"]
    with pytest.warns(EvidenceWarning, match="ended 1[0-9].[0-9] nats below the best fit"):
        _evidence(lik, result["voigt"].posterior, 1, "ladder",
                  best_log_likelihood=ev.reached_log_likelihood + 12)
    # The default route: importance weights where they certify the posterior, else the ladder
    # whose runs agree (bridge sampling only follows emcee, which neither needed here).
    assert {row["evidence_method"] for row in result.table()} <= {"importance", "ladder"}
    with pytest.raises(InputError, match="evidence must be"):
        compare(data, voigt, evidence="nested")


# The flipped point is also an outlier for PSIS-LOO (Pareto k above 0.7 there), as it should be.
@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_data_problems_are_warned_and_stated(tmp_path):
    """A point of negative loss (G'' < 0) in modulus data: warned by compare, stated in
    summary.json and first in the report's verdict."""
    from bayesfo.data import read_csv
    from bayesfo.errors import DataWarning
    from bayesfo.output.report import verdict

    lines = (Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" /
             "Tp150C.csv").read_text().splitlines()
    first = next(i for i, line in enumerate(lines) if line and line[0].isdigit())
    cells = lines[first + 2].split(",")
    cells[2] = str(-float(cells[2]))  # the loss modulus of the third frequency
    lines[first + 2] = ",".join(cells)
    path = tmp_path / "flipped.csv"
    path.write_text("\n".join(lines) + "\n")
    data = read_csv(path)
    w3 = data.omega[2]
    message = (f"{data.label}: 1 of 17 points have negative loss (Im G < 0), impossible for a "
               f"passive modulus, at omega = {w3:.4g} rad/s; no passive structure can fit them")
    with pytest.warns(DataWarning) as record:
        result = compare(data, "voigt", seed=1, workers=1, progress=False)
    assert [str(w.message) for w in record if w.category is DataWarning] == [message]
    summary = result.to_summary()
    assert summary["data"]["warnings"] == [message]
    assert summary["data"]["dissipation_violations_omega"] == [w3]
    text, flagged = verdict(result)[0]
    assert flagged and text.startswith("Data: 1 of 17 points have negative loss")


def test_adequacy_of_every_structure(voigt_comparison):
    """Posterior predictive checks on Voigt data (2 % noise, σ known): the Voigt and its
    superset the Zener describe them, the integer Voigt misses the phase by tens of degrees."""
    import dataclasses

    from bayesfo.output.report import verdict

    result, out = voigt_comparison
    fits = {r.name: r.fits for r in result.results}
    assert fits == {"voigt": "yes", "zener": "yes", "voigt-int": "no"}
    bad = result["voigt-int"].adequacy
    assert bad.p_values["autocorrelation"] < 1e-3 and bad.max_phase_error_deg > 30
    assert bad.systematic_at_omega and bad.reasons[0].startswith("residuals are correlated")
    summary = json.loads((out / "summary.json").read_text())
    blocks = {s["name"]: s["adequacy"] for s in summary["structures"]}
    assert blocks["voigt"]["adequate"] is True and blocks["voigt-int"]["adequate"] is False
    assert set(blocks["voigt"]["p_values"]) == {"chi2", "autocorrelation", "scan"}
    with open(out / "ranking.csv", newline="") as fh:
        rows = {r["structure"]: r for r in csv.DictReader(fh)}
    assert rows["voigt-int"]["fits"] == "no" and rows["voigt"]["adequate"] == "True"
    best = result.ranking[0]
    assert (f"{best} describes the data: its posterior predictive checks pass at the 1 % level"
            in " ".join(t for t, _ in verdict(result)))
    # With only the misspecified structure, the verdict says that nothing describes the data.
    alone = dataclasses.replace(result, results=(result["voigt-int"],))
    text, flagged = next((t, f) for t, f in verdict(alone) if t.startswith("None of"))
    assert flagged and "voigt-int: residuals are correlated along frequency" in text
    # A pass that rests on noise-dominated points is flagged, in the verdict and the tables.
    masked = dataclasses.replace(result[best].adequacy, misfit_masked=True,
                                 caution="at ω = 0.1–0.3 rad/s (3 of 20 points) the fitted noise")
    crit = dataclasses.replace(result[best].criteria, adequacy=masked)
    swapped = dataclasses.replace(result, results=tuple(
        dataclasses.replace(r, criteria=crit) if r.name == best else r for r in result.results))
    assert swapped[best].fits == "partly"
    assert {r["structure"]: r["fits"] for r in swapped.table()}[best] == "partly"
    text, flagged = next((t, f) for t, f in verdict(swapped) if "predictive checks" in t)
    assert flagged and text.startswith(f"{best} passes its posterior predictive checks at the "
                                       "1 % level, but at ω = 0.1–0.3 rad/s (3 of 20 points)")


def test_ranking_figure_names_the_structures_that_misfit(voigt_comparison):
    import matplotlib

    matplotlib.use("Agg")
    from bayesfo.plotting import plot_ranking

    result, _ = voigt_comparison
    drawn = plot_ranking(result)
    labels = {t.get_text().split("\n")[0]: t.get_text() for t in drawn.axes[1].get_yticklabels()}
    assert labels["voigt-int"].endswith("misfits the data")
    assert labels["voigt"] == "voigt" and labels["zener"] == "zener"
    assert list(drawn.values["fits"]) == [result[n].fits for n in result.ranking]


def test_every_order_of_a_two_springpot_model_is_named(tmp_path):
    """The Maxwell card has two orders (α, β; in its physical form the springpots' β and
    δ = β − α): the baseline line names both, and ranking.csv's orders cell gives every order
    of the physical form with its mean and 94 % HDI."""
    from bayesfo.comparison.table import orders_text, ranking_rows

    rng = np.random.default_rng(3)
    w = np.logspace(-2, 2, 25)
    g = get_structure("maxwell").response([1.0, 0.5, 0.3, 0.8], w, "compliance")
    sd = 0.02 * np.abs(g)
    data = FrequencyResponse(w, g + sd / np.sqrt(2) * (rng.normal(size=25) + 1j * rng.normal(size=25)),
                             sd, kind="compliance")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = compare(data, resolve_structures("maxwell,maxwell-int"), seed=0, progress=False,
                         noise="known")
    (pair,) = result.baselines()
    summary = result["maxwell"].posterior.summary
    assert [(o["name"], o["symbol"]) for o in pair["orders"]] == [("alpha", "α"), ("beta", "β")]
    for o in pair["orders"]:
        s = summary[o["name"]]
        assert o["hdi"] == [s.hdi_low, s.hdi_high] and o["mean"] == s.mean
    record = next(s for s in result.to_summary()["structures"] if s["name"] == "maxwell")
    row = next(r for r in ranking_rows(result.to_summary()["structures"], result.ranking)
               if r["structure"] == "maxwell")
    block = record["parameters_physical"] if record["natural_form"] == "physical" \
        else record["parameters"]
    assert row["orders"] == orders_text(block)
    symbols = [part.split()[0] for part in row["orders"].split("; ")]
    assert symbols == [{"alpha": "α", "beta": "β", "delta": "δ"}[k] for k in block
                       if k in ("alpha", "beta", "delta")]
    assert "δ" in symbols or record["natural_form"] != "physical"
    d = block.get("delta") or block["beta"]
    assert f"{d['mean']:.3f} [{d['hdi_low']:.3f}–{d['hdi_high']:.3f}]" in row["orders"]
