"""Every bad input gets one clear line (an InputError naming file, line, column or argument):
never a traceback, a MemoryError, a hang or a silent NaN. Each case here reproduces a reported
failure; the messages are asserted from their start."""

from __future__ import annotations

import os
import re
import threading

import numpy as np
import pytest

from bayesfo.data import FrequencyResponse, read_csv
from bayesfo.data import csv_reader as data_module  # where the reader reads its limits
from bayesfo.errors import InputError, StructureError
from bayesfo.identify import identify
from bayesfo.identify.linear import _solve_batch
from bayesfo.identify.scan import fit_linear, q_grid_scan
from bayesfo.structures import get_structure, load_library, resolve_structures
from bayesfo.structures.response import matignon_stable

OK_ROWS = "2,1,-1\n3,1,-1\n4,1,-1\n"


def _error(path, **kwargs) -> str:
    with pytest.raises(InputError) as info:
        read_csv(path, **kwargs)
    return str(info.value)


# ------------------------------------------------------------------ 1, 2: values of the CSV
BAD_VALUES = [
    # 1: what cannot be computed in double precision
    ("omega,real,imag\n1,1e308,1\n" + OK_ROWS,
     ", line 2, column 'real': 1e+308 is outside the magnitudes 1e-30 … 1e+30 bayesfo computes "
     "with in double precision (their squares must stay finite and nonzero); check the units"),
    ("omega,real,imag\n1,1e300,1e300\n2,2e300,1e300\n",
     ", line 2, column 'real': 1e+300 is outside the magnitudes 1e-30 … 1e+30"),
    ("omega,real,imag\n1,0,0\n2,0,0\n3,0,0\n",
     ": the response is 0 at every frequency (columns 'real' and 'imag'): there is nothing to "
     "fit; check that these columns hold the measured response"),
    ("omega,magnitude,phase_deg\n1,0,0\n2,0,10\n",
     ": the response is 0 at every frequency (column 'magnitude'): there is nothing to fit"),
    ("omega,real,imag\n1,1,-1\n2,0,0\n3,1,-0.5\n",
     ", line 3, columns 'real' and 'imag': the response is exactly 0; a measured response never "
     "is (a placeholder for a missing value?), and a zero cannot be scaled, weighted by 1/|G| or "
     "inverted: remove the row"),
    ("omega,real,imag\n1e-323,1,-1\n" + OK_ROWS,
     ", line 2, column 'omega': 9.88131e-324 rad/s is outside 1e-30 … 1e+30 rad/s, the range "
     "bayesfo computes with in double precision; check the units of the column"),
    ("omega,real,imag,sigma\n1,1,-1,1e308\n2,1,-1,1\n",
     ", line 2, column 'sigma': sigma = 1e+308 is more than 100 times the largest |G| of the data "
     "(1.41421); no measurement is that noisy: check that sigma is the standard deviation of G, "
     "in the units of G"),
    ("omega,real,imag,sigma\n1,1,-1,0.1\n2,1,-1,1e-20\n",
     ", line 3, column 'sigma': sigma = 1e-20 is less than 1e-15 times |G| = 1.41421 on this "
     "line, below the precision of a double; give the measurement's real standard deviation"),
    ("omega,real,imag\n1,5e-324,0\n2,5e-324,0\n" + OK_ROWS,
     ", line 2, columns 'real' and 'imag': |G| = 4.94066e-324 is outside the magnitudes 1e-30 … "
     "1e+30"),
    ("omega,magnitude,phase_deg\n1,1e31,0\n2,1,0\n",
     ", line 2, column 'magnitude': |G| = 1e+31 is outside the magnitudes 1e-30 … 1e+30"),
    ("omega,storage,loss\n1,1,1e40\n2,1,1\n",
     ", line 2, column 'loss': 1e+40 is outside the magnitudes 1e-30 … 1e+30"),
    ("omega,real,imag\n1e-16,1,0\n1e16,1,0\n",
     ", column 'omega': the frequencies span 32.0 decades (from 1e-16 rad/s on line 2 to 1e+16 "
     "rad/s on line 3), more than the 30 decades the scaled fits handle in double precision; "
     "remove the outlying rows or check their units"),
    ("omega,real,imag\n1,1e-16,0\n2,1e16,0\n",
     ", columns 'real' and 'imag': |G| spans 32.0 decades (from 1e-16 on line 2 to 1e+16 on "
     "line 3), more than the 30 decades"),
    # 2: what float() accepts but a data file must not hold
    ("omega,real,imag\n1,1_0,1\n2,1,1\n",
     ", line 2, column 'real': '1_0' is not a number: underscores are not allowed in numbers "
     "(write '10')"),
    ("omega,real,imag\n1,\u0661,1\n2,1,1\n", ", line 2, column 'real': '\\u0661' is not a number"),
    ('omega,real,imag\n1,"1,5",1\n2,1,1\n',
     ", line 2, column 'real': '1,5' is not a number: write the decimal point as '.'"),
    ("omega,real,imag\n1,1e999,1\n2,1,1\n",
     ", line 2, column 'real': value is 1e999, not a finite number (beyond 1.8e308, the largest "
     "double)"),
    ("omega,magnitude,phase_deg\n1,1,1e308\n2,1,1\n",
     ", line 2, column 'phase_deg': a phase of 1e+308 degrees is outside ±360; a phase is an "
     "angle within one turn: wrap it into (-180, 180] by adding or subtracting multiples of 360"),
    ("omega,magnitude,phase_deg\n1,1,-45\n2,1,-400\n",
     ", line 3, column 'phase_deg': a phase of -400 degrees is outside ±360"),
    ("freq,real,imag\n1,1,1\n1e308,1,1\n",
     ", line 3, column 'freq': 1e+308 Hz is outside 1.59e-31 … 1.59e+29 Hz, the range bayesfo "
     "computes with in double precision; check the units of the column"),
    # two frequencies that overflow to inf: out of range, not duplicates
    ("freq,real,imag\n1,1,1\n1e308,1,1\n1.5e308,1,1\n",
     ", line 3, column 'freq': 1e+308 Hz is outside"),
    ("omega,real,imag\n1,1,1\n2,1\x00,1\n",
     ", line 3, character 4: a NUL byte (U+0000, invisible); the file may be UTF-16 or binary; "
     "save it as UTF-8 text"),
    ("omega,real,imag\n1,1,1\n\ufeff2,1,1\n",
     ", line 3, character 1: a byte-order mark (U+FEFF, invisible); remove it"),
    ("omega,real,imag\n1,1,\x07\n", ", line 2, character 5: a control character (U+0007, "
                                    "invisible); remove it"),
    ("omega\u200b,real,imag\n1,1,1\n", ", line 1: unknown column 'omega\\u200b'; known columns"),
    ("omega,real,imag\n1,1," + "1" * 200_000 + "\n",
     ", line 2: a cell has more than 131072 characters, far more than any value needs; is it "
     "the right file?"),
    ("omega,real,imag\n1,1," + "1" * 5000 + "\n",
     ", line 2, column 'imag': the cell has 5000 characters, more than any number needs (at "
     "most 1000)"),
    ("omega,real,imag,series\n1,1,1,1\n1,-1,-1,2\n2,1,1,1\n2,1.1,1,2\n",
     ", line 2: the mean of the replicates at omega = 1 rad/s is exactly 0"),
]


@pytest.mark.parametrize("text, message", BAD_VALUES, ids=range(len(BAD_VALUES)))
def test_bad_values_are_named_by_file_line_and_column(tmp_path, text, message):
    path = tmp_path / "d.csv"
    path.write_text(text, encoding="utf-8")
    assert _error(path).startswith(f"file '{path}'{message}")


@pytest.mark.parametrize("text, message", BAD_VALUES[:14], ids=range(14))
def test_cli_bad_values_exit_2_with_one_line(tmp_path, run_cli, text, message):
    path = tmp_path / "d.csv"
    path.write_text(text, encoding="utf-8")
    status, out, err = run_cli("inspect", path)
    assert status == 2 and out == ""
    assert err == f"bayesfo: error: {_error(path)}\n"


def test_utf16_file_is_named(tmp_path):
    path = tmp_path / "d.csv"
    path.write_bytes("omega,real,imag\n1,1,1\n".encode("utf-16"))
    assert _error(path) == (f"file '{path}' is not a UTF-8 text file (it looks like UTF-16): "
                            "undecodable byte at line 1; save it as UTF-8 text")


def test_line_numbers_count_only_line_breaks(tmp_path):
    # str.splitlines() also splits at form feeds and U+2028; an editor does not.
    path = tmp_path / "d.csv"
    path.write_text("omega,real,imag\r\n1,1,1\r\n2,1\u20282,1\r\n", encoding="utf-8")
    assert _error(path) == f"file '{path}', line 3, column 'real': '1\\u20282' is not a number"


def _read_in_thread(path):
    outcome = {}

    def run():
        try:
            read_csv(path)
        except Exception as exc:  # noqa: BLE001 - the outcome is what is tested
            outcome["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(timeout=10)
    assert not thread.is_alive(), "read_csv blocked on a FIFO"
    return outcome["error"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_fifo_is_not_a_regular_file(tmp_path, run_cli):
    path = tmp_path / "pipe.csv"
    os.mkfifo(path)
    exc = _read_in_thread(path)
    assert isinstance(exc, InputError)
    assert str(exc) == (f"file '{path}' is not a regular file (a FIFO (named pipe)); save the "
                        "data to a file and give its path")
    status, _, err = run_cli("compare", path, "--structures", "voigt", "--no-figures",
                             "--out", tmp_path / "out", "--workers", "1")
    assert status == 2 and err == f"bayesfo: error: {exc}\n"


def test_file_larger_than_the_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(data_module, "MAX_FILE_BYTES", 100)
    path = tmp_path / "d.csv"
    path.write_text("omega,real,imag\n" + "1,1,1\n" * 30)
    assert _error(path) == (f"file '{path}' has 196 bytes, more than the 100 a text data file "
                            "of bayesfo can have; is it the right file?")


# ------------------------------------------------------------------ 3: too many frequencies
def _rows(n):
    w = np.logspace(-2, 3, n)
    return "".join(f"{x!r},{1 / (1 + x):.6g},{-x / (1 + x * x):.6g}\n" for x in w.tolist())


def test_too_many_frequencies_say_how_to_thin(tmp_path, run_cli):
    path = tmp_path / "big.csv"
    path.write_text("omega,real,imag\n" + _rows(100_000))
    message = (f"file '{path}' has 100000 frequencies, more than the 1000 a comparison handles "
               "in reasonable time (the samplers' cost grows with the number of frequencies): "
               "thin the data (e.g. 10 to 50 log-spaced frequencies per decade), or average "
               "neighbouring frequencies, before the comparison")
    assert _error(path) == message
    status, _, err = run_cli("compare", path, "--structures", "voigt", "--no-figures",
                             "--out", tmp_path / "out", "--workers", "1")
    assert status == 2 and err == f"bayesfo: error: {message}\n"


def test_the_limit_applies_after_averaging_replicates(tmp_path):
    path = tmp_path / "rep.csv"
    w = np.logspace(-2, 3, 1001).tolist()
    rows = "".join(f"{x!r},1,-1,{s}\n" for s in (1, 2) for x in w)
    path.write_text("omega,real,imag,series\n" + rows)
    with pytest.warns(UserWarning, match="single replicate"):
        message = _error(path)
    assert message.startswith(f"file '{path}' has 1001 frequencies, more than the 1000")
    ok = tmp_path / "ok.csv"
    ok.write_text("omega,real,imag,series\n"
                  + "".join(f"{x!r},1,-1,{s}\n" for s in (1, 2) for x in w[:1000]))
    with pytest.warns(UserWarning, match="single replicate"):
        assert read_csv(ok).n_frequencies == 1000


def test_more_rows_than_the_row_limit_stop_reading(tmp_path, monkeypatch):
    monkeypatch.setattr(data_module, "MAX_ROWS", 50)
    path = tmp_path / "rows.csv"
    path.write_text("omega,real,imag,series\n" + "1,1,1,1\n" * 60)
    assert _error(path) == (f"file '{path}', line 52: more than 50 data rows; a data set may "
                            "have at most 1000 frequencies: thin the data (e.g. 10 to 50 "
                            "log-spaced frequencies per decade), or average neighbouring "
                            "frequencies, before the comparison")


def test_bounds_leave_real_data_alone():
    # The bundled master curve spans 26 decades of frequency: inside the 30-decade bound.
    fr = read_csv("examples/data/nrel_dma_master.csv")
    assert fr.n_frequencies == 205
    assert np.log10(fr.omega.max() / fr.omega.min()) == pytest.approx(26.0)


def test_constructor_rejects_an_all_zero_response():
    with pytest.raises(InputError, match=r"^argument 'response' is 0 at every frequency: there "
                                         r"is nothing to fit$"):
        FrequencyResponse([1.0, 2.0], [0.0, 0.0])


# ------------------------------------------------------------------ 4: structure cards
FAMILY = """
name = "mx"
family = "max-order"
n_max = 2
constraints = ["stable"]
[parameters]
"a*" = { prior = "uniform", low = -100.0, high = 100.0 }
"b*" = { prior = "uniform", low = -100.0, high = 100.0 }
q = { prior = "uniform", low = 0.0, high = 1.0 }
"""

SINGLE = """
name = "sp"
numerator = [["b0", 0]]
denominator = [[1, 0], ["a1", "q"]]
constraints = ["passive"]
[parameters]
a1 = { prior = "log-uniform", low = 1e-3, high = 1e3 }
b0 = { prior = "log-uniform", low = 1e-3, high = 1e3 }
q = { prior = "uniform", low = 0, high = 1 }
"""

BAD_CARDS = [
    (FAMILY, "n_max = 2", 'n_max = "x"', ": 'n_max' must be a whole number from 1 to 6, got 'x'"),
    (FAMILY, "n_max = 2", "n_max = inf", ": 'n_max' must be a whole number from 1 to 6, got inf"),
    (FAMILY, "n_max = 2", "n_max = 2.5", ": 'n_max' must be a whole number from 1 to 6, got 2.5"),
    (FAMILY, "n_max = 2", "n_max = true",
     ": 'n_max' must be a whole number from 1 to 6, got True"),
    (FAMILY, "n_max = 2", "n_max = -1",
     ": 'n_max' must be from 1 to 6 (the highest degree of a max-order member; the thesis uses "
     "3), got -1"),
    (FAMILY, "n_max = 2", "n_max = 1000000000", ": 'n_max' must be from 1 to 6"),
    (FAMILY, 'constraints = ["stable"]', "constraints = true",
     ": 'constraints' must be a list of text, e.g. [\"stable\", \"passive\"], got True"),
    (FAMILY, 'constraints = ["stable"]', 'constraints = "stable"',
     ": 'constraints' must be a list of text, e.g. [\"stable\", \"passive\"], got 'stable'"),
    (SINGLE, '["a1", "q"]', '["a1", "1..2*q"]',
     ", denominator, term 2: cannot read exponent '1..2*q'; write a finite number or a "
     "parameter with an optional non-negative multiplier, e.g. 0.5, 'q', '2*q'"),
    (SINGLE, '["a1", "q"]', '["a1", "99999999999*q"]',
     ", denominator, term 2: exponent '99999999999*q': the multiplier of an exponent must be "
     "within ±6 (a pseudo-polynomial of degree at most 6), got 1e+11"),
    (SINGLE, '["a1", "q"]', '["a1", 1e300]',
     ", denominator, term 2: exponent 1e+300: a constant exponent must be within ±6"),
    (SINGLE, '["a1", "q"]', '["a1", "inf"]',
     ", denominator, term 2: exponent must be a finite number, got 'inf'"),
    (SINGLE, '["a1", "q"]', '["a1", nan]',
     ", denominator, term 2: exponent must be a finite number, got nan"),
    (SINGLE, '["a1", "q"]', '["a1", "1_0*q"]', ", denominator, term 2: cannot read exponent '1_0*q'"),
    (SINGLE, '[1, 0], ["a1"', '[inf, 0], ["a1"',
     ", denominator, term 1: a constant coefficient must be a finite number, got inf"),
    (SINGLE, '[1, 0], ["a1"', '["nan", 0], ["a1"',
     ", denominator, term 1: bad coefficient 'nan'; write a parameter name"),
    (SINGLE, 'constraints = ["passive"]', 'constraints = ["a1 <= nan"]',
     ": cannot read 'nan' in the constraint 'a1 <= nan'; write parameter names and finite "
     "numbers joined by '*', e.g. 'b1 <= a1*b0'"),
    (SINGLE, "low = 1e-3, high = 1e3 }\nb0", "low = 1e-300, high = 1e300 }\nb0",
     ", parameter 'a1': log-uniform prior needs a ratio high/low that is a finite double, got "
     "low = 1e-300, high = 1e+300"),
    (SINGLE, "low = 0, high = 1 }", "low = -1e308, high = 1e308 }",
     ", parameter 'q': uniform prior needs a width high - low that is a finite double"),
    (SINGLE, "low = 0, high = 1 }", "low = false, high = 1 }",
     ", parameter 'q': prior arguments must be numbers, got low = False"),
    (SINGLE, "low = 0, high = 1 }", 'low = "0", high = 1 }',
     ", parameter 'q': prior arguments must be numbers, got low = '0'"),
    (SINGLE, 'prior = "uniform"', "prior = 3", ", parameter 'q': unknown prior 3; known priors"),
    (SINGLE, 'name = "sp"', 'name = "sp"\norder = nan', ": 'order' must be a finite number, got nan"),
]


@pytest.mark.parametrize("card, old, new, message", BAD_CARDS, ids=range(len(BAD_CARDS)))
def test_bad_cards_are_named(tmp_path, card, old, new, message):
    assert old in card
    path = tmp_path / "bad.toml"
    path.write_text(card.replace(old, new, 1))
    with pytest.raises(StructureError) as info:
        load_library(extra=[path])
    assert str(info.value).startswith(f"card '{path}'{message}")


@pytest.mark.parametrize("card, old, new, message", BAD_CARDS[:3] + BAD_CARDS[6:10],
                         ids=range(7))
def test_cli_bad_cards_exit_2_with_one_line(tmp_path, run_cli, card, old, new, message):
    path = tmp_path / "bad.toml"
    path.write_text(card.replace(old, new, 1))
    status, out, err = run_cli("--models", path, "structures")
    assert status == 2 and out == ""
    assert err.startswith(f"bayesfo: error: card '{path}'{message}") and err.count("\n") == 1


def test_load_library_checks_its_n_max_argument():
    with pytest.raises(StructureError, match=r"^argument 'n_max' must be from 1 to 6 \(the "
                                             r"highest degree of a max-order member; the thesis "
                                             r"uses 3\), got 99999$"):
        load_library(n_max=99999)


def test_card_path_that_is_not_a_file(tmp_path):
    if not hasattr(os, "mkfifo"):
        pytest.skip("needs FIFOs")
    path = tmp_path / "pipe.toml"
    os.mkfifo(path)
    with pytest.raises(StructureError, match="is not a regular file or a directory$"):
        load_library(extra=[path])
    with pytest.raises(StructureError, match=r"^card '.*pipe.toml' is not a regular file \(a "
                                             r"FIFO \(named pipe\)\)"):
        load_library(extra=[tmp_path])


def test_highest_multiplier_is_accepted(tmp_path):
    path = tmp_path / "ok.toml"
    path.write_text(SINGLE.replace('["a1", "q"]', '["a1", "6*q"]'))
    assert load_library(extra=[path])["sp"].formula == "b0 / (1 + a1 s^(6q))"


# ------------------------------------------------------------------ 5: shortcuts beyond the library
@pytest.mark.parametrize("spec, top, message", [
    ("max9", 3, "'max9' asks for the max-order members up to degree 9, but the library has them "
                "up to 3: use max1 to max3, or raise n_max in the card"),
    ("voigt,max4-inv", 3, "'max4-inv' asks for the max-order members up to degree 4, but the "
                          "library has them up to 3: use max1 to max3"),
    ("max0", 3, "'max0' asks for the max-order members up to degree 0"),
    ("max3", 2, "'max3' asks for the max-order members up to degree 3, but the library has them "
                "up to 2: use max1 to max2"),
])
def test_max_shortcut_beyond_the_library_is_an_error(spec, top, message):
    library = load_library() if top == 3 else load_library(n_max=top)
    with pytest.raises(StructureError) as info:
        resolve_structures(spec, library)
    assert str(info.value).startswith(message)
    assert len(resolve_structures(f"max{top}", library)) == top * (top + 3) // 2


def test_cli_max9_exit_2(run_cli):
    status, _, err = run_cli("inspect", "examples/data/pp_compliance.csv", "--structures", "max9")
    assert status == 2
    assert err.startswith("bayesfo: error: 'max9' asks for the max-order members up to degree 9")


# ------------------------------------------------------------------ 6: identify --q outside the prior
def _voigt_data():
    w = np.logspace(-1, 2, 12)
    return FrequencyResponse(w, 2.0 / (1 + 0.5 * (1j * w) ** 0.6), kind="compliance")


@pytest.mark.parametrize("method", ["2", "4", "opt"])
@pytest.mark.parametrize("q, message", [
    (1.7, "argument 'q' = 1.7 is outside the prior uniform(0, 1) of q in structure 'voigt': "
          "give a q from 0 to 1"),
    (-0.5, "argument 'q' = -0.5 is outside the prior uniform(0, 1) of q in structure 'voigt'"),
    (float("nan"), "argument 'q' must be a finite number, got nan"),
    (float("inf"), "argument 'q' must be a finite number, got inf"),
])
def test_identify_q_outside_the_prior(method, q, message):
    with pytest.raises(InputError) as info:
        identify(_voigt_data(), get_structure("voigt"), method=method, q=q)
    assert str(info.value).startswith(message)


def test_identify_q_inside_the_prior_still_works():
    out = identify(_voigt_data(), get_structure("voigt"), method="2", q=0.6)
    assert out["q"] == 0.6 and out["stable"]


def test_cli_identify_q_outside_the_prior(tmp_path, run_cli):
    path = tmp_path / "d.csv"
    _voigt_data().to_csv(path)
    status, _, err = run_cli("identify", path, "--structure", "voigt", "--method", "2",
                             "--q", "1.7")
    assert status == 2
    assert err == ("bayesfo: error: argument 'q' = 1.7 is outside the prior uniform(0, 1) of q "
                   "in structure 'voigt': give a q from 0 to 1\n")


# ------------------------------------------------------------------ robustness under the reader
def test_linear_solve_marks_singular_and_non_finite_systems_nan():
    A = np.array([np.eye(2), np.zeros((2, 2)), [[np.inf, 0], [0, 1]], 2 * np.eye(2)])
    b = np.ones((4, 2))
    x = _solve_batch(A, b)
    np.testing.assert_array_equal(x[0], [1, 1])
    np.testing.assert_array_equal(x[3], [0.5, 0.5])
    assert np.isnan(x[1]).all() and np.isnan(x[2]).all()


def test_q_scan_survives_a_singular_q():
    # A response that is 0 at every point but one: the Levy regressors -λG vanish there and
    # the normal equations are singular for every q. Before, one singular q failed the scan.
    w = np.logspace(-1, 1, 6)
    fr = FrequencyResponse(w, np.r_[1.0, np.zeros(5)])
    scan = q_grid_scan(fr, 2, 1, 3, q_grid=[0.3, 0.6])
    assert scan.best is None and np.all(np.isinf(scan.rmse))


def test_overflowing_powers_are_rejected_not_raised():
    # 30 decades and q = 1.9, degree 6: λ^6 overflows at the ends; that q is rejected.
    w = np.logspace(-15, 15, 16)
    fr = FrequencyResponse(w, 1.0 / (1.0 + (1j * w) ** 0.5))
    fits = fit_linear(fr, 6, 6, 2, [0.5, 1.9])
    assert np.isinf(fits[1].rmse) and not fits[1].stable


def test_matignon_stability_of_non_finite_coefficients_is_false():
    a = np.array([[1.0, 2.0, np.nan], [1.0, np.inf, 1.0], [1.0, 3.0, 2.0]])
    np.testing.assert_array_equal(matignon_stable(a, np.array([0.5, 0.5, 0.5])),
                                  [False, False, True])


@pytest.mark.parametrize("settings, message", [
    ({"walkers": 10_000_000}, "walkers (--walkers) must be at most 10,000, got 10,000,000"),
    ({"max_steps": 1_000_000_000}, "must be at most 10,000,000, got 1,000,000,000"),
    ({"walkers": 1000, "max_steps": 1_000_000}, "1,000,000,000 chain positions, more than"),
])
def test_sampler_settings_that_exhaust_memory_are_refused_before_work(settings, message):
    from bayesfo.options import check_sampler_settings

    with pytest.raises(InputError, match=re.escape(message)):
        check_sampler_settings(settings, "compare")
    check_sampler_settings({"walkers": 64, "max_steps": 20_000}, "compare")  # ordinary: fine


def test_a_file_of_many_columns_is_read_in_linear_time_and_noted_briefly(tmp_path):
    # 20 000 extra columns: the reader once counted duplicate labels quadratically (minutes at
    # 100 000 columns); the note names the first columns and how many more.
    from bayesfo.data import read

    n = 20_000
    path = tmp_path / "wide.csv"
    path.write_text("omega,storage,loss," + ",".join(f"x{i}" for i in range(n)) + "\n"
                    + "".join(f"{k},{k + 1},{k}," + ",".join("1" * n) + "\n"
                              for k in (1, 2, 3)))
    data = read(path)
    note = next(x for x in data.notes if x.startswith("other columns kept as metadata"))
    assert note.startswith(f"other columns kept as metadata ({n}): 'x0', 'x1'")
    assert note.endswith(f"'x19' and {n - 20} more")


def test_a_prior_of_no_parameter_is_refused_by_the_api_before_any_work():
    """Through the API as on the command line: a misspelt prior is an error naming the option,
    not a prior left unused."""
    import bayesfo as bf
    from bayesfo.priors import Uniform

    omega = np.logspace(-1, 2, 12)
    data = FrequencyResponse(omega, 1.0 / (1.0 + 1j * omega), kind="compliance")
    with pytest.raises(InputError, match=r"^argument 'priors' names 'qq', which no selected "
                                         r"structure has; did you mean 'q'\?") as info:
        bf.compare(data, "voigt", priors={"qq": Uniform(0.2, 1.0)}, workers=1)
    assert info.value.option == "priors"
    assert info.value.in_command_line({"priors": "--prior"}).startswith(
        "--prior names 'qq', which no selected structure has")


@pytest.mark.parametrize("error, said", [
    (InputError("workers must be a non-negative integer, got -1", option="workers"),
     "--workers must be a non-negative integer, got -1"),
    (InputError("argument 'per_decade' must be from 1 to 10", option="per_decade"),
     "--per-decade must be from 1 to 10"),
    (InputError("predict: average must be one of bma, stacking", where="predict",
                option="average"), "--average must be one of bma, stacking"),
    (InputError("predict: the times must be finite", where="predict"), "the times must be finite"),
    (InputError("block=2 is not there", command_line="--block 2 is not there"),
     "--block 2 is not there"),
])
def test_an_input_error_is_said_in_the_words_of_the_command_line(error, said):
    assert error.in_command_line() == said
