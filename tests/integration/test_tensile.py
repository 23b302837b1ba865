"""Tensile data in the rheologist's language (issue 33): a DMA's E′, E″ are labelled E′, E″,
|E*|, E(t), E_e in the figures, the report and the terminal, summary.json carries the symbol
and bf.load reads it back (G for a summary.json of an earlier version).

One comparison: the fractional Voigt on simulated tensile modulus data (12 frequencies, σ
known); a few seconds.
"""

from __future__ import annotations

import dataclasses
import json
import shutil
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import bayesfo as bf  # noqa: E402
from bayesfo.cli import main  # noqa: E402
from bayesfo.comparison import compare  # noqa: E402
from bayesfo.data import FrequencyResponse  # noqa: E402
from bayesfo.errors import PredictiveWarning  # noqa: E402
from bayesfo.output.report import render_report  # noqa: E402
from bayesfo.plotting import plot_bode, plot_corner, plot_moduli, save_figure  # noqa: E402
from bayesfo.plotting.material import plot_time_functions  # noqa: E402
from bayesfo.structures import get_structure  # noqa: E402

W = np.logspace(-1, 2.5, 12)
NREL = Path(__file__).parents[2] / "examples" / "data" / "nrel_dma_master.csv"


def _data() -> FrequencyResponse:
    rng = np.random.default_rng(5)
    g = get_structure("voigt").response([1.0, 1e-6, 0.4], W, "modulus")  # E_e = 1 MPa
    sd = 0.02 * np.abs(g)
    noisy = g + sd / np.sqrt(2) * (rng.normal(size=W.size) + 1j * rng.normal(size=W.size))
    return FrequencyResponse(W, noisy, sd, kind="modulus", units="Pa", name="dma sim",
                             symbol="E")


@pytest.fixture(scope="module")
def comparison():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PredictiveWarning)
        return compare(_data(), ["voigt"], seed=1, progress=False)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def test_the_results_learn_the_symbol_of_the_data(comparison):
    assert comparison.data.symbol == "E"
    assert comparison["voigt"].data_symbol == "E"
    assert comparison.to_summary()["data"]["symbol"] == "E"


def test_figure_labels_say_e_for_tensile_data(comparison):
    moduli = plot_moduli(comparison)
    assert [ax.get_ylabel() for ax in moduli.figure.axes] == ["E′ [Pa]", "E″ [Pa]",
                                                              r"tan $\delta$"]
    bode = plot_bode(comparison)
    assert [ax.get_ylabel() for ax in bode.figure.axes] == ["|$E^*$| [Pa]", "arg $E^*$ [deg]"]
    times = plot_time_functions(comparison)
    assert [ax.get_ylabel() for ax in times.figure.axes] == ["E(t) [Pa]", "D(t) [1/Pa]"]
    corner = plot_corner(comparison["voigt"])
    labels = {ax.get_xlabel() for ax in corner.figure.axes} | {ax.get_ylabel()
                                                               for ax in corner.figure.axes}
    assert "log$_{10}$ $E_{e}$ [Pa]" in labels
    assert not any("G_" in t for t in labels)


def test_shear_data_keep_g(comparison):
    shear = dataclasses.replace(comparison, data=dataclasses.replace(comparison.data, symbol="G"))
    assert shear["voigt"].data_symbol == "G"
    assert [ax.get_ylabel() for ax in plot_moduli(shear).figure.axes][:2] == ["G′ [Pa]",
                                                                             "G″ [Pa]"]


def test_the_report_says_e_and_not_g(comparison, tmp_path):
    png = tmp_path / "moduli.png"
    save_figure(plot_moduli(comparison).figure, png)
    text = render_report(comparison, {"moduli": [png]})
    assert "tensile modulus E* = E′ + iE″" in text
    assert ("Storage part E′, loss part E″ and loss tangent tan δ = E″/E′ of the data" in text)
    assert "E*(s) = E_e + c_q s^q" in text
    assert "<td class=\"text\">E_e</td>" in text
    assert "name them as the structure&#x27;s card does (G_e, G_m)" in text
    body = text.replace("(G_e, G_m)", "")
    for shear in ("G′", "G″", "G_e", "G*", "J(s)"):
        assert shear not in body, shear
    shear = dataclasses.replace(comparison, data=dataclasses.replace(comparison.data, symbol="G"))
    text = render_report(shear, {"moduli": [png]})
    assert "Storage part G′, loss part G″" in text and "E′" not in text


def test_summary_json_round_trip_through_load(comparison, tmp_path):
    out = tmp_path / "run"
    bf.write_outputs(comparison, out, figures=False)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["data"]["symbol"] == "E"
    loaded = bf.load(out)
    assert loaded.data.symbol == "E" and loaded["voigt"].data_symbol == "E"
    assert loaded.to_summary()["data"]["symbol"] == "E"
    # a summary.json written before the symbol existed is shear data (a run of an earlier
    # version: no digests recorded)
    from bayesfo.outdir import MANIFEST

    old = tmp_path / "old"
    shutil.copytree(out, old)
    (old / MANIFEST).unlink()
    del summary["data"]["symbol"]
    (old / "summary.json").write_text(json.dumps(summary))
    assert bf.load(old).data.symbol == "G"


def test_terminal_lines_of_inspect_and_compare(comparison, tmp_path, capsys):
    assert main(["inspect", str(NREL)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == ("NREL PV-module polymer, DMA master curve (reference -5 °C): 205 "
                        "frequencies, 6.283e-12 to 6.283e+14 rad/s, kind modulus (tensile "
                        "modulus E* = E′ + iE″), units MPa")
    assert lines[1].startswith("|E*| from 89.42 to 9585 MPa; ")  # with the data's unit
    path = tmp_path / "dma.csv"
    path.write_text(_data().to_csv_text())
    assert main(["compare", str(path), "--structures", "voigt", "--no-figures",
                 "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert ("dma sim: 12 frequencies fitted, kind modulus (tensile: E′, E″); ranked by "
            "log-evidence") in out


def test_predictions_and_prony_files_speak_the_tensile_letter(comparison):
    from bayesfo.predictions import predict, prony_series

    p = predict(comparison, "relaxation_modulus", [0.1, 1.0])
    assert p.symbol == "E(t)" and p.to_dict()["symbol"] == "E(t)"
    assert predict(comparison, "storage", [1.0]).symbol == "E′"
    assert predict(comparison, "creep_compliance", [1.0]).symbol == "D(t)"
    prony = prony_series(comparison)
    assert prony.symbol == "E"
    head = prony.text("abaqus").splitlines()[0]
    assert "tensile modulus E in" in head
    text = prony.text("abaqus")
    assert "max |dE''|/E'' = " in text and "max |dE(t)|/E(t) = " in text and "G(t)" not in text
    assert "stand for the shear ratios the code takes under a constant Poisson's ratio" in text
    assert (f"instantaneous modulus E0 = {prony.g_0:.10g}: give it with Poisson's ratio nu in "
            "*ELASTIC, MODULI=INSTANTANEOUS") in text
    # The Voigt's modulus grows without bound: g_0 is the model two decades past the data,
    # and the file says how far above the largest measured |E*| it lies.
    assert prony.g_0 > 1.5 * prony.measured_max
    assert f"{prony.g_0 / prony.measured_max:.3g} x the largest measured |E*|" in text
