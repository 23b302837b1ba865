"""Labels in the data's letter and unit: "G′ [a.u.]", not "G′ [G]", for data without a unit, the
Maxwell modulus in the data's letter, "°C", and no negative zero."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import bayesfo as bf
from bayesfo.comparison.table import number
from bayesfo.data.symbols import parameter_label
from bayesfo.predictions import prony_series
from bayesfo.structures.physical import in_brackets, stress_unit

DATA = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tp020C.csv"


@pytest.fixture(scope="module")
def unitless(tmp_path_factory):
    """The adhesive at 20 °C without its '# units:' line, compared and written."""
    root = tmp_path_factory.mktemp("unitless")
    lines = [x for x in DATA.read_text().splitlines() if not x.startswith("# units")]
    (root / "bare.csv").write_text("\n".join(lines) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = bf.compare(bf.read(root / "bare.csv"), "zener,maxwell-int", workers=1,
                            progress=False, seed=0)
    bf.write_outputs(result, root / "run", figures=False)
    return result, root / "run"


def test_the_placeholder_of_no_unit_is_not_a_unit():
    assert stress_unit("modulus", "") == "a.u." and stress_unit("compliance", "") == "1/a.u."
    assert in_brackets("a.u.") == " [a.u.]" and in_brackets("Pa") == " [Pa]"
    # The placeholder stored by earlier versions reads as the arbitrary unit.
    assert in_brackets("[G]") == " [a.u.]" and in_brackets("[G] s^q") == " [a.u. s^q]"
    assert in_brackets("1/[J]") == " [1/a.u.]"


def test_the_maxwell_modulus_takes_the_data_letter():
    assert parameter_label("E", "G") == "G" and parameter_label("E", "E") == "E"
    assert parameter_label("G_e", "E") == "E_e" and parameter_label("c_q", "G") == "c_q"


def test_no_negative_zero():
    assert number(-1e-17, ".3f") == "0.000" and number(-4e-4, ".3f") == "0.000"
    assert number(-5e-3, ".3f") == "-0.005" and number(-2.5e-17, ".3g") == "-2.5e-17"
    assert number(0.0, ".3f") == "0.000"


def test_data_without_a_unit_say_so(unitless, run_cli):
    """predict, the report and export on data without a unit: "G′ [a.u.]", not "G′ [G]"; the
    parameters in a.u.; decks say the data give no unit, not "in [G]"; the Maxwell modulus of
    shear data is G."""
    result, out = unitless
    status, text, err = run_cli("predict", out, "--quantity", "storage", "--omega", "1,10")
    assert status == 0, err
    assert text.startswith("G′ [a.u.] of structure zener") and "[G]" not in text
    from bayesfo.output import render_report

    report = render_report(result)
    assert "[G]" not in report and "[J]" not in report and " a.u." in report
    assert "<td class=\"text\">E</td>" not in report
    prony = prony_series(result, per_decade=1)
    for fmt in ("csv", "abaqus", "ansys", "lsdyna"):
        deck = prony.text(fmt)
        assert "[G]" not in deck and "(the data give no unit)" in deck
    t = np.array([1.0])
    assert np.isfinite(prony.relaxation(t)).all()
