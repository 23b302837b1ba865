"""The remedies a non-converged posterior names are options: ``--max-steps`` and ``--walkers``
reach emcee (``compare`` and ``batch``), and bad values are refused before any work."""

import json
import re
from pathlib import Path

import pytest

from bayesfo.errors import InputError
from bayesfo.options import check_options, check_sampler_settings, sampler_options

DATA = "examples/data/adhesive_468mp/Tp020C.csv"


@pytest.mark.parametrize("settings, message", [
    ({"max_steps": 10}, "max_steps (--max-steps) must be an integer of at least 100, got 10"),
    ({"walkers": 3}, "walkers (--walkers) must be an integer of at least 8, got 3"),
    ({"walkers": True}, "walkers (--walkers) must be an integer"),
    ({"max_steps": 2.5e3}, "got 2500.0"),
])
def test_bad_settings_are_refused(settings, message):
    with pytest.raises(InputError, match=r"^manifest, line 2: .*" + re.escape(message)):
        check_sampler_settings(settings, "manifest, line 2")


def test_settings_travel_as_emcee_arguments():
    opts = check_options({"max_steps": 400, "walkers": 40}, "here")
    assert (opts["max_steps"], opts["walkers"]) == (400, 40)
    assert sampler_options(opts) == {"max_steps": 400, "n_walkers": 40}
    assert sampler_options(check_options({}, "here")) == {}


# 200 steps cannot converge: the run says so (and the ladder may certify the posterior).
@pytest.mark.filterwarnings("ignore::bayesfo.errors.ConvergenceWarning")
@pytest.mark.filterwarnings("ignore::bayesfo.errors.CertifiedWarning")
@pytest.mark.filterwarnings("ignore::bayesfo.errors.PredictiveWarning")
def test_cli_flags_reach_the_sampler(run_cli, tmp_path):
    # emcee forced, 200 steps of 40 walkers: the run stops at the cap and says so.
    status, out, err = run_cli("compare", DATA, "--structures", "voigt", "--sampler", "emcee",
                               "--max-steps", "200", "--walkers", "40", "--no-figures",
                               "--quiet", "--out", tmp_path / "o")
    assert status == 0, err
    voigt = json.loads((tmp_path / "o" / "summary.json").read_text())["structures"][0]
    assert voigt["sampler"] in ("emcee", "ladder")
    if voigt["sampler"] == "emcee":
        assert voigt["n_steps"] <= 200
    status, _, err = run_cli("compare", DATA, "--max-steps", "5", "--out", tmp_path / "p")
    assert status == 2
    assert "max_steps (--max-steps) must be an integer of at least 100, got 5" in err
    assert not (tmp_path / "p").exists()


def test_manifest_columns_set_the_sampler_per_data_set(tmp_path):
    from bayesfo.batch import expand_inputs

    data = tmp_path / "a.csv"
    data.write_bytes(Path(DATA).read_bytes())
    manifest = tmp_path / "m.csv"
    manifest.write_text("path,max_steps,walkers\na.csv,20000,48\n")
    (ds,) = expand_inputs([], manifests=[manifest], options={"structures": "voigt"}, seed=1)
    assert sampler_options(ds.options) == {"max_steps": 20000, "n_walkers": 48}
    manifest.write_text("path,max_steps\na.csv,lots\n")
    with pytest.raises(InputError, match=r"line 2, column 'max_steps': max_steps must be an "
                                         r"integer, got 'lots'"):
        expand_inputs([], manifests=[manifest], options={}, seed=1)
    manifest.write_text("path,walkers\na.csv,2\n")
    with pytest.raises(InputError, match=r"line 2: walkers \(--walkers\) must be an integer of "
                                         r"at least 8, got 2"):
        expand_inputs([], manifests=[manifest], options={}, seed=1)
