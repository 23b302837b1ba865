"""Typed criteria and results read back: ``Criteria`` (frozen, read like a dict, unknown keys
refused), ``bf.load`` (a Comparison rebuilt from summary.json and the NetCDF files, without
re-running), the batch rows built from the same ranking rows, and the readable summaries.

Two small comparisons on the 150 °C adhesive isotherm (voigt): the default one, and one with σ
per point and a held-out frequency. Measured: 18 s for the file (2 busy cores).
"""

from __future__ import annotations

import dataclasses
import json
import math
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
from test_stored_run import _diff

import bayesfo as bf
from bayesfo.comparison import Criteria
from bayesfo.errors import InputError
from bayesfo.output import ranking_csv
from bayesfo.output.write import _finite

DATA = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp150C.csv"


def _json(obj):
    """``obj`` as summary.json holds it (no NaN, tuples as lists)."""
    return json.loads(json.dumps(_finite(obj)))


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """The default comparison of voigt on Tp150C and its output directory (no figures)."""
    out = tmp_path_factory.mktemp("voigt")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bf.errors.PredictiveWarning)  # Pareto k, if above 0.7
        # q under constant and proportional noise: 94 % intervals that meet at their ends
        # (0.23-0.244 and 0.244-0.258), which the comparison reports; not what is tested here.
        warnings.simplefilter("ignore", bf.errors.NoiseWarning)
        result = bf.compare(bf.read(DATA), "voigt", workers=1, progress=False, seed=1)
    bf.write_outputs(result, out, figures=False)
    return result, out


@pytest.fixture(scope="module")
def with_sigma(tmp_path_factory):
    """Known σ (2 % of |G|) and one held-out frequency: what summary.json alone does not hold."""
    d = bf.read(DATA)
    data = dataclasses.replace(d, sigma=0.02 * np.abs(d.response))
    out = tmp_path_factory.mktemp("sigma")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", bf.errors.PredictiveWarning)  # Pareto k, if above 0.7
        result = bf.compare(data, "voigt", workers=1, progress=False, seed=2,
                            holdout=[float(d.omega[8])])
    bf.write_outputs(result, out, figures=False)
    return result, out


# ---------------------------------------------------------------------- round trip
def test_load_round_trips_summary_table_and_ranking_csv(written):
    result, out = written
    loaded = bf.load(out)
    stored = json.loads((out / "summary.json").read_text())
    assert _diff(_json(loaded.to_summary()), stored) == []
    assert _diff(_json(stored), _json(loaded.to_summary())) == []  # no key more either
    assert _diff(loaded.table(), result.table()) == []
    assert loaded.ranking == result.ranking == stored["ranking"]
    assert ranking_csv(loaded) == (out / "ranking.csv").read_text()


def test_loaded_posterior_data_and_fit_are_those_of_the_run(written):
    result, out = written
    a, b = result["voigt"], bf.load(out)["voigt"]
    pa, pb = a.posterior, b.posterior
    np.testing.assert_array_equal(pb.samples, pa.samples)
    np.testing.assert_array_equal(pb.log_likelihood, pa.log_likelihood)
    np.testing.assert_array_equal(pb.map_theta, pa.map_theta)
    np.testing.assert_array_equal(pb.tau, pa.tau)
    assert (pb.param_names, pb.noise, pb.sampler, pb.burn, pb.thin, pb.n_walkers, pb.n_steps) \
        == (pa.param_names, pa.noise, pa.sampler, pa.burn, pa.thin, pa.n_walkers, pa.n_steps)
    assert pb.max_log_likelihood == pa.max_log_likelihood
    assert pb.summary == pa.summary
    assert pb.samples_scaled is None  # not stored
    np.testing.assert_array_equal(bf.load(out).data.response, result.data.response)
    assert b.fit.theta.tolist() == a.fit.theta.tolist() and b.fit.scaling == a.fit.scaling
    assert b.fit.optima is None and b.fit.chi2 is None  # the optimiser's details: not stored
    ca, cb = a.criteria, b.criteria
    assert cb.pareto_k == ca.pareto_k and cb.loo_pointwise == ca.loo_pointwise
    assert cb.evidence == ca.evidence
    assert cb.adequacy == ca.adequacy
    assert cb.importance == {k: v for k, v in ca.importance.items() if k != "seconds"}
    # The result's own InferenceData is left as it was: the attributes are on the copy written.
    assert "burn" not in pa.idata.posterior.attrs and pb.idata.posterior.attrs["burn"] == 0


def test_known_sigma_and_held_out_points_are_stored_and_read_back(with_sigma):
    result, out = with_sigma
    loaded = bf.load(out)
    np.testing.assert_array_equal(loaded.data.sigma, result.data.sigma)
    np.testing.assert_array_equal(loaded.holdout.omega, result.holdout.omega)
    np.testing.assert_array_equal(loaded.holdout.response, result.holdout.response)
    np.testing.assert_array_equal(loaded.holdout.sigma, result.holdout.sigma)
    assert loaded["voigt"].posterior.noise == "known"
    assert loaded["voigt"].criteria.holdout_lpd is not None
    stored = json.loads((out / "summary.json").read_text())
    assert _diff(_json(loaded.to_summary()), stored) == []
    assert _diff(loaded.table(), result.table()) == []


def test_a_loaded_comparison_writes_the_same_summary(written, tmp_path):
    _, out = written
    bf.write_outputs(bf.load(out), tmp_path, figures=False)
    assert _diff(json.loads((tmp_path / "summary.json").read_text()),
                 json.loads((out / "summary.json").read_text())) == []


def test_batch_rows_are_the_ranking_rows(written):
    from bayesfo.batch import summary_rows
    from bayesfo.batch.store import _RANKING_COLUMNS

    result, out = written
    summary = json.loads((out / "summary.json").read_text())
    table = {r["structure"]: r for r in bf.load(out).table()}
    for row in summary_rows(summary):
        assert _diff(_json({k: row[k] for k in _RANKING_COLUMNS}),
                     _json({k: table[row["structure"]][k] for k in _RANKING_COLUMNS})) == []


# ---------------------------------------------------------------------- errors
def test_missing_or_damaged_outputs_are_input_errors(written, tmp_path):
    _, out = written
    with pytest.raises(InputError, match="no such directory"):
        bf.load(tmp_path / "nowhere")
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(InputError, match=r"summary\.json': missing"):
        bf.load(empty)
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (copy / "voigt.nc").write_bytes(b"not a NetCDF file")
    # The run recorded its files' digests: a file changed since is refused as such.
    with pytest.raises(InputError, match=r"voigt\.nc' is not the file that the run which wrote"):
        bf.load(copy)
    # Without the record (a run of an earlier version), the reader says what is wrong.
    (copy / ".bayesfo-run.json").unlink()
    with pytest.raises(InputError, match=r"voigt\.nc': cannot be read as NetCDF"):
        bf.load(copy)
    (copy / "voigt.nc").unlink()
    with pytest.raises(InputError, match=r"voigt\.nc': missing"):
        bf.load(copy)
    (copy / "summary.json").write_text('{"structures": [', encoding="utf-8")
    with pytest.raises(InputError, match=r"summary\.json': not valid JSON"):
        bf.load(copy)
    (copy / "summary.json").write_text('{"structures": []}', encoding="utf-8")
    with pytest.raises(InputError, match=r"summary\.json': entry 'data' is missing|no structure"):
        bf.load(copy)


# ---------------------------------------------------------------------- Criteria
def test_criteria_are_frozen_attributes_and_refuse_unknown_keys(written):
    result, _ = written
    r = result["voigt"]
    c = r.criteria
    assert isinstance(c, Criteria)
    assert isinstance(c.warnings, tuple) and c.holdout_lpd is None
    assert r.log_z == c.evidence.log_z and r.log_z_err == c.evidence.log_z_err
    assert r.probability == c.posterior_probability
    assert Criteria.from_dict(c.to_dict()).to_dict().keys() == c.to_dict().keys()
    assert "holdout_lpd" not in c.to_dict() and c.to_dict()["aic"] == c.aic
    with pytest.raises(KeyError, match="unknown criteria key 'posterior_probabilty'"):
        Criteria.from_dict({"posterior_probabilty": 0.5})
    # The mapping interface of earlier releases still reads, with a DeprecationWarning.
    with pytest.warns(DeprecationWarning, match=r"use criteria\.loo"):
        assert c["loo"] == c.loo
    with pytest.warns(DeprecationWarning):
        assert c.get("holdout_lpd", 1.0) == 1.0 and "loo" in c and dict(c)["aic"] == c.aic
    with pytest.warns(DeprecationWarning), pytest.raises(KeyError, match="'lo' is not a criteria key"):
        c.get("lo")
    with pytest.raises(TypeError):
        c["loo"] = 1.0
    with pytest.raises(dataclasses.FrozenInstanceError):
        c.loo = 1.0
    # A dict given to StructureResult becomes Criteria, and a misspelt key fails there.
    assert isinstance(bf.StructureResult(r.structure, criteria={"loo": 1.0}).criteria, Criteria)
    with pytest.raises(KeyError):
        bf.StructureResult(r.structure, criteria={"elpd": 1.0})


def test_model_probabilities_make_new_results():
    from types import SimpleNamespace

    from bayesfo.comparison.criteria import _model_probabilities
    from bayesfo.structures import get_structure

    ev = [SimpleNamespace(log_z=z, log_z_err=0.1, method="bridge") for z in (-10.0, -10.0 - math.log(3))]
    results = [bf.StructureResult(get_structure(n), criteria={"evidence": e})
               for n, e in zip(("voigt", "zener"), ev, strict=True)]
    new = _model_probabilities(results, {})
    assert [r.criteria.posterior_probability for r in results] == [None, None]
    assert [r.criteria.posterior_probability for r in new] == pytest.approx([0.75, 0.25])


# ---------------------------------------------------------------------- summaries
def test_repr_and_summary_of_a_comparison_and_a_structure(written):
    result, _ = written
    text = repr(result)
    assert text.startswith("<Comparison of 1 structure(s) on '") and "best voigt (P = 1.000)" in text
    lines = result.summary().splitlines()
    assert "17 frequencies" in lines[0] and "ln Z" in lines[1] and lines[1].split()[-2] == "ok"
    ev = result["voigt"].criteria.evidence
    assert lines[2].split()[:3] == ["1", "voigt", "3"]
    assert f"{ev.log_z:.2f} ± {ev.log_z_err:.2f}" in lines[2] and lines[2].split()[-1] == "small"
    r = result["voigt"]
    assert repr(r).startswith("<StructureResult voigt: ln Z = ") and "fits: small" in repr(r)
    detail = r.summary()
    assert detail.splitlines()[0] == f"voigt: {r.structure.formula}"
    q = r.physical["physical"]["q"]
    assert f"[{q['hdi_low']:.4g}, {q['hdi_high']:.4g}]" in detail
    assert "G_e" in detail and " Pa" in detail and "sigma_rel" in detail
    failed = bf.StructureResult(r.structure, error="nothing admissible (test)")
    assert repr(failed) == "<StructureResult voigt: failed: nothing admissible (test)>"
    assert "failed: nothing admissible (test)" in failed.summary()
    both = dataclasses.replace(result, results=(r, failed))
    assert "1 failed" in repr(both) and "failed: nothing admissible" in both.summary()


def test_the_picture_an_alias_chose_is_read_back(tmp_path):
    data = bf.read(DATA)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = bf.compare(data, "fpt", workers=1, progress=False, seed=1)
    bf.write_outputs(result, tmp_path, figures=False)
    stored = json.loads((tmp_path / "summary.json").read_text())
    assert stored["structures"][0]["picture"] == "fractional_poynting_thomson"
    assert _diff(_json(bf.load(tmp_path).to_summary()), stored) == []


@pytest.mark.parametrize("name", ["../../x", "a/b", "..", "", 7])
def test_a_structure_name_that_leaves_the_directory_is_refused(written, tmp_path, name):
    """A summary.json whose structure name is a path ("../../x") was not written by a run:
    load refuses it instead of opening DIR/../../x.nc (a run without digests, as earlier
    versions wrote, is checked the same way)."""
    from bayesfo.outdir import MANIFEST

    _, out = written
    copy = tmp_path / "run"
    shutil.copytree(out, copy)
    (copy / MANIFEST).unlink()
    summary = json.loads((copy / "summary.json").read_text())
    summary["structures"][0]["name"] = name
    (copy / "summary.json").write_text(json.dumps(summary))
    (tmp_path / "x.nc").write_bytes(b"not to be opened")
    with pytest.raises(InputError, match=r"structure name .* is not a file name in the directory"):
        bf.load(copy)
