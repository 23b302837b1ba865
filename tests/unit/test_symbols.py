"""The letter of the measured quantity (issue 33): tensile DMA data (E′, E″) are read as symbol E
and keep it through every copy, shear data as G, and bayesfo's texts are rewritten in it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import bayesfo as bf
from bayesfo.data import FrequencyResponse, contract_text, read, read_csv, read_isotherms
from bayesfo.data.symbols import (
    describe,
    in_symbol,
    parameter_label,
    parts,
    response_symbol,
)
from bayesfo.errors import InputError
from bayesfo.plotting.style import quantity_symbol
from bayesfo.structures.physical import display_name

ROOT = Path(__file__).parents[2]
LAB = ROOT / "tests" / "data" / "lab"
NREL = ROOT / "examples" / "data" / "nrel_dma_master.csv"


def _tensile(**kw) -> FrequencyResponse:
    w = np.logspace(-1, 2, 6)
    return FrequencyResponse(w, 1e6 * (1 + (1j * w) ** 0.4), 1e4 * np.ones(6), kind="modulus",
                             units="Pa", name="dma", symbol="E", **kw)


# ---------------------------------------------------------------------- reading
def test_the_bundled_nrel_master_curve_is_a_tensile_modulus():
    assert read_csv(NREL).symbol == "E"
    data = bf.read(NREL)
    assert (data.symbol, data.kind, data.response_symbol) == ("E", "modulus", "E")
    assert data.to_dict()["symbol"] == "E"


def test_pyvisco_columns_e_stor_e_loss_give_symbol_e_for_every_isotherm():
    sets = read_isotherms(LAB / "pyvisco_raw.csv")
    assert [s.data.symbol for s in sets] == ["E", "E"]
    assert read(LAB / "pyvisco_raw.csv", block=1).symbol == "E"


@pytest.mark.parametrize("name", ["semicolon_comma.csv", "trios_steps.csv",
                                  "reptate_latin1.osc", "temperature_column.csv"])
def test_shear_files_and_files_without_a_letter_give_symbol_g(name):
    assert {s.data.symbol for s in read_isotherms(LAB / name)} == {"G"}


def test_compliance_columns_give_their_letter_and_the_choice_of_columns_decides():
    data = read(LAB / "compliance.csv")
    assert (data.kind, data.symbol, data.response_symbol) == ("compliance", "J", "J")
    assert read(LAB / "ambiguous.csv", columns={"storage": "E'", "loss": "E''"}).symbol == "E"
    assert read(LAB / "ambiguous.csv", columns={"storage": "G'", "loss": "G''"}).symbol == "G"


@pytest.mark.parametrize("header", ["Storage Modulus E' [MPa],Loss Modulus E'' [MPa]",
                                    "Tensile storage modulus [MPa],Tensile loss modulus [MPa]",
                                    "E' (MPa),E'' (MPa)", "D' [1/MPa],D'' [1/MPa]"])
def test_tensile_headers_are_recognised(tmp_path, header):
    path = tmp_path / "dma.csv"
    path.write_text(f"Frequency [Hz],{header}\n1,10,2\n10,20,3\n100,40,5\n")
    data = read(path)
    assert data.symbol == ("D" if header.startswith("D") else "E")
    assert data.response_symbol == data.symbol


def test_a_symbol_line_names_the_quantity_of_a_file_without_letters(tmp_path):
    path = tmp_path / "x.csv"
    path.write_text("# symbol: E\nomega,storage,loss\n1,10,2\n10,20,3\n")
    assert read_csv(path).symbol == "E"
    lab = tmp_path / "lab.csv"
    lab.write_text("# symbol: E\nAngular frequency [rad/s],Storage modulus [Pa],"
                   "Loss modulus [Pa]\n1,10,2\n10,20,3\n")
    assert read(lab).symbol == "E"
    path.write_text("# symbol: X\nomega,storage,loss\n1,10,2\n10,20,3\n")
    with pytest.raises(InputError, match=r"x.csv': the '# symbol:' line must say G \(shear "
                                         r"modulus\), E \(tensile modulus\), J \(shear "
                                         r"compliance\) or D \(tensile compliance\), got 'X'"):
        read_csv(path)


# ---------------------------------------------------------------------- the attribute
def test_symbol_defaults_to_g_and_is_checked():
    w = np.array([1.0, 2.0])
    assert FrequencyResponse(w, [1 + 1j, 2 + 1j]).symbol == "G"
    with pytest.raises(InputError, match=r"argument 'symbol' must be one of G, E, J, D \(shear "
                                         r"modulus, tensile modulus, shear compliance, tensile "
                                         r"compliance\), got 'e'"):
        FrequencyResponse(w, [1 + 1j, 2 + 1j], symbol="e")


def test_every_copy_keeps_the_symbol(tmp_path):
    data = _tensile()
    train, test = data.split([data.omega[2]])
    assert {d.symbol for d in (data.sorted(), data.select(data.omega > 1), train, test,
                               data.with_kind("generic"),
                               dataclasses.replace(data, name="other"))} == {"E"}
    assert data.to_dict()["symbol"] == "E"
    text = data.to_csv_text()
    assert text.splitlines()[:4] == ["# name: dma", "# kind: modulus", "# units: Pa",
                                     "# symbol: E"]
    path = tmp_path / "back.csv"
    path.write_text(contract_text(data, temperature=20.0))
    back = read_csv(path)
    assert back.symbol == "E"
    np.testing.assert_array_equal(back.response, data.response)
    # shear data write no symbol line: files of earlier versions stay as they were
    assert "# symbol" not in dataclasses.replace(data, symbol="G").to_csv_text()
    rep = FrequencyResponse.from_replicates(data.omega, [data.response, 1.01 * data.response],
                                            kind="modulus", symbol="E")
    assert rep.symbol == "E"


def test_the_reciprocal_of_a_tensile_modulus_is_a_tensile_compliance():
    data = _tensile()
    inv = data.reciprocal()
    assert (inv.kind, inv.symbol, inv.response_symbol) == ("compliance", "D", "D")
    assert inv.reciprocal().symbol == "E"
    shear = dataclasses.replace(data, symbol="G").reciprocal()
    assert (shear.symbol, shear.response_symbol) == ("J", "J")
    generic = dataclasses.replace(data, kind="generic")
    assert generic.reciprocal().symbol == "E"


# ---------------------------------------------------------------------- texts
def test_texts_in_the_letters_of_the_data():
    assert response_symbol("E", "modulus") == "E"
    assert response_symbol("E", "compliance") == "D"
    assert response_symbol("G", "compliance") == "J"
    assert response_symbol("D", "modulus") == "E"
    assert parts("E", "modulus") == ("E′", "E″")
    assert parts("G", "compliance") == ("J′", "J″")
    assert describe("E", "modulus") == "tensile modulus E* = E′ + iE″"
    assert describe("G", "compliance") == "shear compliance J* = J′ − iJ″"
    assert describe("E", "generic") == ""
    text = ("G*(s) = G_e + 1/(1/G_m + 1/(c_q s^q)), sampled as the card's compliance J(s); "
            "|G| in GPa, [G] s^q, G′, G″, G(t), J(t), Gamma")
    assert in_symbol(text, "E") == (
        "E*(s) = E_e + 1/(1/E_m + 1/(c_q s^q)), sampled as the card's compliance D(s); "
        "|E| in GPa, [E] s^q, E′, E″, E(t), D(t), Gamma")
    assert in_symbol(text, "G") == text
    assert in_symbol(text, "J") == text
    assert [parameter_label(n, "E") for n in ("G_e", "G_m", "G_k", "c_q", "eta", "E", "q")] == \
        ["E_e", "E_m", "E_k", "c_q", "eta", "E", "q"]
    assert parameter_label("G_e", "G") == "G_e"
    assert display_name("G_g", "D") == "E_g"


def test_figure_quantity_symbols():
    assert quantity_symbol("modulus") == "G^*"
    assert quantity_symbol("modulus", "E") == "E^*"
    assert quantity_symbol("compliance", "E") == "D^*"
    assert quantity_symbol("compliance") == "J^*"
    assert quantity_symbol("generic") == "G"


def test_the_data_warning_names_the_loss_in_the_letter_of_the_data():
    from bayesfo.comparison.results import data_problems

    w = np.array([1.0, 2.0, 3.0])
    data = FrequencyResponse(w, [1 - 1j, 1 + 1j, 1 + 1j], kind="modulus", name="dma", symbol="E")
    assert data_problems(data) == [
        "dma: 1 of 3 points have negative loss (Im E < 0), impossible for a passive modulus, "
        "at omega = 1 rad/s; no passive structure can fit them"]
