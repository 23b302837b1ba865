"""The tolerant reader of lab files (bayesfo.read, bayesfo.data.read_isotherms): every fixture in
tests/data/lab/ read to the exact ω [rad/s] and response [Pa] written in it, round trips through
every supported form, precise errors, the choices recorded, the command line and the batch.

The fixtures are written for these tests (their values are below), except
``ares_trios_lims.txt``, an excerpt of the MIT-licensed hermes-rheo file (see README.md there).
"""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bayesfo as bf
from bayesfo.data import (
    FrequencyResponse,
    columns_from_text,
    contract_text,
    is_contract_csv,
    read,
    read_csv,
    read_isotherms,
)
from bayesfo.data.units import parse_unit, split_header
from bayesfo.errors import InputError

LAB = Path(__file__).parents[1] / "data" / "lab"
TAU = 2 * np.pi


def _assert_data(fr, omega, response, kind, rtol=1e-15):
    np.testing.assert_allclose(fr.omega, omega, rtol=rtol, atol=0)
    np.testing.assert_allclose(fr.response.real, np.real(response), rtol=rtol, atol=0)
    np.testing.assert_allclose(fr.response.imag, np.imag(response), rtol=rtol, atol=0)
    assert fr.kind == kind


# ---------------------------------------------------------------------- each fixture, exactly
def test_ares_trios_lims_excerpt_two_steps():
    sets = read_isotherms(LAB / "ares_trios_lims.txt")
    assert [s.label for s in sets] == ["Frequency sweep (150.0 °C)", "Frequency sweep (-40.0 °C)"]
    assert [s.temperature for s in sets] == [150.0, -40.0]
    hot, cold = sets
    _assert_data(hot.data, [0.628318548202515, 0.873045802116394, 125.663711547852],
                 np.array([10044.287109375, 10917.3349609375, 33547.12109375])
                 + 1j * np.array([3285.56372070313, 3621.35009765625, 12430.166015625]),
                 "modulus")
    _assert_data(cold.data, [0.628318548202515, 0.873045802116394, 125.663711547852],
                 np.array([260040528, 269178528, 546905280])
                 + 1j * np.array([75069952, 76434480, -29868376.0]), "modulus")
    r = hot.reading
    assert r.format == "TA Instruments TRIOS (LIMS text export)" and r.delimiter == "tab"
    assert dict(r.columns)["omega"] == "Angular frequency [rad/s]"
    assert dict(r.columns)["storage"] == "Storage modulus [Pa]"
    assert dict(r.columns)["frequency check"] == "Frequency [Hz]"
    assert any(x.startswith("storage/loss ('Storage compliance'") for x in r.not_used)
    assert "Status bits" in r.columns_ignored and "Oscillation strain" in r.columns_kept
    np.testing.assert_array_equal(r.extra["Oscillation strain"],
                                  [1.00105442106724, 1.49388983845711, 4.86422963440418])
    assert hot.data.units == "Pa" and hot.data.dissipation_violations().size == 0
    assert cold.data.dissipation_violations().tolist() == [2]  # the known glassy artefact
    # The compliance columns on request, J* = J' - iJ'' in 1/Pa.
    j = read(LAB / "ares_trios_lims.txt", kind="compliance", block=1)
    _assert_data(j, hot.data.omega, 1e-6 * (np.array([89.935987489298, 82.518054114189,
                                                      26.2103621935239])
                                            - 1j * np.array([29.418753911159, 27.3717669188045,
                                                             9.71168719843263])), "compliance")


def test_trios_csv_steps_skip_flow_and_amplitude_sweeps():
    sets = read_isotherms(LAB / "trios_steps.csv")
    assert [s.label for s in sets] == ["Frequency sweep - 2", "Frequency sweep - 3"]
    assert [s.temperature for s in sets] == [25.0, 60.0]
    _assert_data(sets[0].data, [1.0, 10.0, 100.0],
                 1e3 * (np.array([12.5, 20.0, 31.25]) + 1j * np.array([3.75, 8.0, 15.5])),
                 "modulus")
    _assert_data(sets[1].data, [1.0, 10.0, 100.0],
                 1e3 * (np.array([6.25, 10.0, 16.0]) + 1j * np.array([2.5, 5.0, 9.0])), "modulus")
    r = sets[0].reading
    assert r.format == "TA Instruments TRIOS export" and r.delimiter == "comma"
    assert "'Storage modulus': kPa → Pa (× 1000)" in r.units_converted
    skipped = " | ".join(r.rows_skipped)
    assert "Peak hold - 1" in skipped and "no frequency column" in skipped
    assert "Amplitude sweep - 4" in skipped and "one frequency on every row" in skipped


def test_rheocompass_utf16_tabs_decimal_commas_and_thousands():
    sets = read_isotherms(LAB / "rheocompass_utf16.csv")
    assert [s.label for s in sets] == ["interval 1", "interval 2"]
    assert [s.temperature for s in sets] == [20.0, 40.0]
    _assert_data(sets[0].data, [0.1, 1.0, 10.0],
                 np.array([1234.5, 2345.25, 3456.0]) + 1j * np.array([456.75, 567.5, 678.125]),
                 "modulus")
    _assert_data(sets[1].data, [0.1, 1.0, 10.0],
                 np.array([1111.5, 2222.75, 3333.0]) + 1j * np.array([444.25, 555.5, 666.625]),
                 "modulus")
    r = sets[0].reading
    assert (r.format, r.encoding, r.delimiter, r.decimal) == (
        "Anton Paar RheoCompass export", "UTF-16", "tab", ",")
    assert dict(r.columns)["omega"] == "Angular Frequency [1/s]"


def test_reptate_tts_and_osc():
    tts = read(LAB / "reptate.tts")
    _assert_data(tts, [0.1, 1.0, 10.0], np.array([100.0, 2500.0, 5e4])
                 + 1j * np.array([1000.0, 4000.0, 2e4]), "modulus")
    assert any("RepTate's convention: columns 1–3 are ω [rad/s]" in n for n in tts.notes)
    osc = read_isotherms(LAB / "reptate_latin1.osc")
    assert len(osc) == 1 and osc[0].temperature == 30.0
    _assert_data(osc[0].data, [46.416, 68.129, 100.0],
                 np.array([3.6205e5, 3.7631e5, 3.9164e5]) + 1j * np.array([70832, 74797, 82274.0]),
                 "modulus")
    r = osc[0].reading
    assert r.encoding == "Windows-1252 (Latin-1)" and r.delimiter == "spaces"
    assert "Temp (no data)" in r.columns_ignored and "Torque (no data)" in r.columns_ignored


def test_pyvisco_units_row_sets_and_temperatures():
    sets = read_isotherms(LAB / "pyvisco_raw.csv")
    assert [s.label for s in sets] == ["Set 0", "Set 1"]
    assert [s.temperature for s in sets] == [round((-49.96 - 49.95 - 49.74) / 3, 2),
                                             round((-20.01 - 19.98 - 20.02) / 3, 2)]
    _assert_data(sets[0].data, TAU * np.array([0.1, 1.0, 10.0]),
                 1e6 * (np.array([8097.5, 8576.75, 8725.125]) + 1j * np.array([93.25, 118.5,
                                                                               124.75])),
                 "modulus")
    r = sets[0].reading
    assert r.format == "pyvisco CSV" and r.units_line == 2
    assert r.units_converted[0] == "'f': Hz → rad/s (ω = 2π f)"
    assert "'E_stor': MPa → Pa (× 1e+06)" in r.units_converted
    assert "tensile modulus" in r.kind_reason
    with pytest.raises(InputError, match=r"holds 2 data sets \(1: Set 0 \(-49.88 °C\), 2: Set 1"):
        read(LAB / "pyvisco_raw.csv")
    assert read(LAB / "pyvisco_raw.csv", block=2).n_frequencies == 3
    assert read(LAB / "pyvisco_raw.csv", block="set 1").n_frequencies == 3


def test_semicolons_decimal_commas_and_units_in_the_header():
    fr = read(LAB / "semicolon_comma.csv")
    _assert_data(fr, [0.1, 1.0, 10.0], 1e3 * (np.array([1.5, 12.75, 101.25])
                                              + 1j * np.array([2.25, 8.5, 40.125])), "modulus")
    assert fr.name == "PP melt, semicolon export" and fr.units == "Pa"
    assert any(n.startswith("other columns kept as metadata (") and "'Torque [µNm]'" in n
               for n in fr.notes)


def test_magnitude_with_tan_delta_in_runs_of_spaces():
    fr = read(LAB / "tand_spaces.txt")
    mag, tan = 1e6 * np.array([2.5, 4.0, 5.0]), np.array([0.75, 0.5, 0.25])
    delta = np.arctan(tan)
    _assert_data(fr, [0.5, 5.0, 50.0], mag * np.exp(1j * delta), "modulus", rtol=1e-14)


def test_complex_viscosity_phase_angle_and_hz():
    iso = read_isotherms(LAB / "complex_viscosity.csv")[0]
    w = TAU * np.array([0.1, 1.0, 10.0])
    g = w * np.array([1000.0, 500.0, 100.0]) * np.exp(1j * np.radians([80.0, 70.0, 60.0]))
    _assert_data(iso.data, w, g, "modulus", rtol=1e-14)
    assert iso.temperature == 190.0 and iso.data.units == "Pa"


def test_compliance_columns_are_a_compliance_in_one_over_pascal():
    fr = read(LAB / "compliance.csv")
    _assert_data(fr, TAU * np.array([0.01, 0.1, 1.0]),
                 1e-6 * (np.array([2.0, 1.5, 1.25]) - 1j * np.array([0.5, 0.25, 0.125])),
                 "compliance")
    assert fr.units == "1/Pa" and fr.dissipation_violations().size == 0
    with pytest.raises(InputError, match="kind modulus was asked, but columns 'J' \\[1/MPa\\]'"):
        read(LAB / "compliance.csv", kind="modulus")


def test_temperature_column_splits_isotherms():
    sets = read_isotherms(LAB / "temperature_column.csv")
    assert [(s.label, s.temperature) for s in sets] == [("20 °C", 20.0), ("40 °C", 40.0)]
    _assert_data(sets[1].data, [1.0, 2.0], np.array([80.0, 120.0]) + 1j * np.array([35.0, 45.0]),
                 "modulus")
    # One data set when the user says the temperatures do not split it: then 1 rad/s repeats.
    with pytest.raises(InputError, match=r"line 4, column 'omega': the frequency 1 rad/s "
                                         r"repeats line 2"):
        read(LAB / "temperature_column.csv", columns={"temperature": None})
    mean = read(LAB / "temperature_column.csv", columns={"temperature": None}, duplicates="mean")
    _assert_data(mean, [1.0, 2.0], np.array([90.0, 135.0]) + 1j * np.array([32.5, 42.5]),
                 "modulus")
    first = read(LAB / "temperature_column.csv", columns={"temperature": None},
                 duplicates="first")
    _assert_data(first, [1.0, 2.0], np.array([100.0, 150.0]) + 1j * np.array([30.0, 40.0]),
                 "modulus")


def test_headerless_numbers_need_columns_by_number():
    with pytest.raises(InputError, match=r"headerless.txt', line 1: numbers without a header "
                                         r"row; name the columns by number"):
        read(LAB / "headerless.txt")
    fr = read(LAB / "headerless.txt", columns={"freq": "1", "storage": "2 [kPa]",
                                               "loss": "3 [kPa]"})
    _assert_data(fr, TAU * np.array([0.1, 1.0, 10.0]),
                 1e3 * (np.array([10.0, 20.0, 30.0]) + 1j * np.array([5.0, 8.0, 12.0])),
                 "modulus")


LAB_ROWS = ["Angular Frequency,Storage Modulus,Loss Modulus"] + [
    f"{w:g},{100 + 10 * k},{50 + 5 * k}" for k, w in enumerate([100, 30, 10, 3, 1, 0.3, 0.1])]


@pytest.mark.parametrize("damaged, cells", [("1,000,130,65", 4), ("1,130", 2),
                                            ("1,130,65,1\n0.3,140,70,2", 4)])
def test_a_damaged_row_inside_a_table_is_an_error_naming_its_line(tmp_path, damaged, cells):
    # A stray delimiter (a thousands separator) or a missing cell used to end the table at that
    # line: the rows after it, without a header, were skipped with a note, and the data set
    # came out shorter, silently. Up to three such lines between rows of the table are named.
    rows = list(LAB_ROWS)
    rows[5:7] = damaged.split("\n")
    path = tmp_path / "sweep.csv"
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(InputError, match=rf"sweep.csv', line 6: {cells} cells where the rows "
                                         r"above and below it have 3: a stray delimiter"):
        read(path)
    # The same rows after a blank line are a table of their own, as before (no error).
    rows = LAB_ROWS[:5] + [""] + [damaged.split("\n")[0]] * 2
    path.write_text("\n".join(rows) + "\n")
    assert read(path).omega.size == 4
    # Intact, all seven rows are read.
    path.write_text("\n".join(LAB_ROWS) + "\n")
    assert read(path).omega.size == 7


def test_two_moduli_need_columns_to_choose():
    with pytest.raises(InputError, match=r"ambiguous.csv', line 1: columns 'G'', 'E'' could each "
                                         r"be the storage column"):
        read(LAB / "ambiguous.csv")
    fr = read(LAB / "ambiguous.csv", columns={"storage": "E'", "loss": "E''"})
    _assert_data(fr, [1.0, 2.0], np.array([30.0, 36.0]) + 1j * np.array([15.0, 18.0]), "modulus")
    assert any(n.startswith("kind modulus: columns 'E'', 'E''' are a tensile") for n in fr.notes)


# ---------------------------------------------------------------------- the contract, unchanged
def test_contract_files_read_exactly_as_read_csv():
    for path in sorted((Path(__file__).parents[2] / "examples" / "data").rglob("*.csv")):
        if "sine_records" in path.parts:
            continue
        a, b = read(path), read_csv(path)
        np.testing.assert_array_equal(a.omega, b.omega)
        np.testing.assert_array_equal(a.response, b.response)
        assert (a.kind, a.units, a.name, a.notes) == (b.kind, b.units, b.name, b.notes)
    assert bf.read is read


def test_contract_errors_are_read_csv_errors(tmp_path):
    from test_data import BAD_CSV
    from test_input_errors import BAD_VALUES

    compared = 0
    for k, (text, _) in enumerate(BAD_CSV + BAD_VALUES):
        path = tmp_path / f"bad{k}.csv"
        path.write_text(text, encoding="utf-8")
        if "temperature" in text or "\u200b" in text:  # not contract headers: read, or
            assert not is_contract_csv(path)  # refused by the tolerant reader's own message
            continue
        compared += 1
        with pytest.raises(InputError) as strict:
            read_csv(path)
        with pytest.raises(InputError) as tolerant:
            read(path)
        assert str(tolerant.value) == str(strict.value)
    assert compared == len(BAD_CSV) + len(BAD_VALUES) - 2


def test_extra_temperature_column_of_a_contract_file_is_read(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("omega,real,imag,temperature\n1,1,1,20\n2,1,0.5,20\n", encoding="utf-8")
    (iso,) = read_isotherms(path)
    assert iso.temperature == 20.0 and iso.data.kind == "generic"
    _assert_data(iso.data, [1.0, 2.0], [1 + 1j, 1 + 0.5j], "generic")
    assert "kind generic: columns 'real', 'imag' do not say" in iso.reading.kind_reason


def test_columns_with_a_unit_on_a_bayesfo_csv_are_honoured(tmp_path, run_cli):
    """--columns real="real [kPa]",imag="imag [kPa]" on the contract's own columns: the unit makes
    them a modulus in kPa (they used to be refused as 'no response columns')."""
    path = tmp_path / "g.csv"
    path.write_text("# kind: modulus\nomega,real,imag,sigma\n0.1,1.5,0.25,0.01\n"
                    "1,2.5,0.75,0.01\n10,4,1.5,0.01\n", encoding="utf-8")
    fr = read(path, columns={"real": "real [kPa]", "imag": "imag [kPa]"})
    _assert_data(fr, [0.1, 1.0, 10.0], 1e3 * np.array([1.5 + 0.25j, 2.5 + 0.75j, 4 + 1.5j]),
                 "modulus")
    np.testing.assert_array_equal(fr.sigma, [10.0, 10.0, 10.0])  # in the response's unit
    assert fr.units == "Pa"
    status, out, err = run_cli("inspect", path, "--columns", 'real="real [kPa]",imag="imag [kPa]"',
                               "--json")
    assert status == 0, err
    info = json.loads(out)
    assert info["magnitude_max"] == pytest.approx(1e3 * abs(4 + 1.5j), rel=1e-15)
    assert info["reading"]["columns"]["real"] == "real [kPa]"
    # the contract's magnitude/phase_deg in a compliance unit; a unit in the header needs no
    # --columns
    path.write_text("omega,magnitude,phase_deg\n1,2,-10\n2,3,-20\n", encoding="utf-8")
    fr = read(path, columns={"magnitude": "magnitude [1/kPa]"})
    _assert_data(fr, [1.0, 2.0], 1e-3 * np.array([2, 3]) * np.exp(-1j * np.radians([10, 20])),
                 "compliance", rtol=1e-14)
    path.write_text("omega,real [Pa],imag [Pa]\n1,2,1\n2,3,1\n", encoding="utf-8")
    _assert_data(read(path), [1.0, 2.0], [2 + 1j, 3 + 1j], "modulus")


def test_columns_with_a_unit_on_one_part_only_are_refused_by_name(tmp_path, run_cli):
    path = tmp_path / "g.csv"
    path.write_text("omega,real,imag\n1,2,1\n2,3,1\n", encoding="utf-8")
    text = (f"file '{path}', line 1: the real column 'real' is in 'kPa' but the imag column "
            "'imag' is without a unit; both parts of the response must be in one unit: give "
            "both, e.g. ")
    status, _, err = run_cli("inspect", path, "--columns", 'real="real [kPa]"')
    assert status == 2
    assert err == f'bayesfo: error: {text}--columns real="real [kPa]",imag="imag [kPa]"\n'
    with pytest.raises(InputError) as info:
        read(path, columns={"real": "real [kPa]"})
    assert str(info.value) == text + "columns={'real': 'real [kPa]', 'imag': 'imag [kPa]'}"


def test_columns_text_keeps_the_primes_inside_quotes():
    assert columns_from_text("""storage="G'",loss="G''",omega='w',block=""") == {
        "storage": "G'", "loss": "G''", "omega": "w", "block": None}
    fr = read(LAB / "ambiguous.csv", columns=columns_from_text('storage="E\'",loss="E\'\'"'))
    _assert_data(fr, [1.0, 2.0], np.array([30.0, 36.0]) + 1j * np.array([15.0, 18.0]), "modulus")


# ---------------------------------------------------------------------- round trips
W = np.array([0.0314, 0.5, 2.0, 7.5, 31.4, 150.0])
G = (np.array([1.2e4, 2.5e4, 4.1e4, 6.6e4, 9.9e4, 1.4e5])
     + 1j * np.array([8.1e3, 1.1e4, 1.6e4, 2.2e4, 3.0e4, 3.7e4]))
J = 1.0 / G


def _fmt(x, comma=False):
    s = repr(float(x))
    return s.replace(".", ",") if comma else s


def _writers():
    f = W / TAU
    g1, g2 = G.real, G.imag
    mag, delta = np.abs(G), np.angle(G)
    eta = G / (1j * W)
    rows = lambda cols, sep=",", comma=False: "\n".join(  # noqa: E731
        sep.join(_fmt(c[k], comma) for c in cols) for k in range(W.size)) + "\n"
    return {
        "contract.csv": ("utf-8", "omega,storage,loss\n" + rows([W, g1, g2]), G),
        "semicolon_kpa.csv": ("utf-8", "Angular frequency [rad/s];G' [kPa];G'' [kPa]\n"
                              + rows([W, g1 / 1e3, g2 / 1e3], ";", True), G),
        "trios.txt": ("utf-8", "[step]\nFrequency sweep - 1\nFrequency\tStorage modulus\t"
                      "Loss modulus\nHz\tMPa\tMPa\n" + rows([f, g1 / 1e6, g2 / 1e6], "\t"), G),
        "rheocompass.csv": ("utf-16", "Project:\tx\nInterval data:\tPoint No.\tAngular Frequency"
                            "\tStorage Modulus\tLoss Modulus\n\t[]\t[1/s]\t[Pa]\t[Pa]\n"
                            + "\n".join(f"\t{k + 1}\t" + "\t".join(_fmt(c[k], True)
                                                                   for c in (W, g1, g2))
                                        for k in range(W.size)) + "\n", G),
        "reptate.tts": ("utf-8", "T=20;Mw=1;\n" + rows([W, g1, g2], "   "), G),
        "reptate.osc": ("latin-1", "T=20;\nFreq\tG'\tG\"\tTemp\nrad/s\tPa\tPa\t°C\n"
                        + rows([W, g1, g2, np.full(W.size, 20.0)], "    "), G),
        "pyvisco.csv": ("utf-8-sig", "f,E_stor,E_loss,T,Set\nHz,MPa,MPa,C,-\n"
                        + rows([f, g1 / 1e6, g2 / 1e6, np.full(W.size, 20.0),
                                np.zeros(W.size)]), G),
        "phase_rad.csv": ("utf-8", "omega,|G*| [Pa],phase angle [rad]\n" + rows([W, mag, delta]),
                          G),
        "tan_delta.csv": ("utf-8", "omega,complex modulus [GPa],tan(delta)\n"
                          + rows([W, mag / 1e9, g2 / g1]), G),
        "viscosity.csv": ("utf-8", "Angular frequency (rad/s),|η*| (mPa·s),δ (°)\n"
                          + rows([W, np.abs(eta) * 1e3, np.degrees(delta)]), G),
        "eta_parts.csv": ("utf-8", "omega [rad/s],eta' [Pa s],eta'' [Pa s]\n"
                          + rows([W, eta.real, -eta.imag]), G),
        "compliance.csv": ("utf-8", "w,J' [1/MPa],J'' [1/MPa]\n"
                           + rows([W, J.real * 1e6, -J.imag * 1e6]), J),
        "contract_real_imag.csv": ("utf-8", "# kind: compliance\nomega,real,imag\n"
                                   + rows([W, J.real, J.imag]), J),
    }


@pytest.mark.parametrize("name", list(_writers()))
def test_round_trip_through_every_form(tmp_path, name):
    encoding, text, expected = _writers()[name]
    path = tmp_path / name
    path.write_bytes(text.encode(encoding))
    fr = read(path)
    np.testing.assert_allclose(fr.omega, W, rtol=1e-12, atol=0)
    np.testing.assert_allclose(fr.response, expected, rtol=1e-12, atol=0)
    assert fr.kind == ("compliance" if expected is J else "modulus")
    # ... and written back as a contract CSV, read again: identical.
    again = tmp_path / "again.csv"
    again.write_text(contract_text(fr), encoding="utf-8")
    back = read(again)
    np.testing.assert_array_equal(back.omega, fr.omega)
    np.testing.assert_array_equal(back.response, fr.response)
    assert back.kind == fr.kind


def test_round_trip_through_excel(tmp_path):
    pytest.importorskip("openpyxl")
    import pandas as pd

    path = tmp_path / "sweep.xlsx"
    frame = pd.DataFrame({"Angular Frequency [rad/s]": W, "Storage Modulus [kPa]": G.real / 1e3,
                          "Loss Modulus [kPa]": G.imag / 1e3})
    frame.to_excel(path, index=False, sheet_name="Frequency sweep")
    iso = read_isotherms(path)
    assert len(iso) == 1 and iso[0].reading.format == "Excel workbook (sheet 'Frequency sweep')"
    np.testing.assert_allclose(iso[0].data.response, G, rtol=1e-12, atol=0)


def test_excel_without_openpyxl_says_what_to_install(tmp_path, monkeypatch):
    import builtins

    real_import = builtins.__import__

    def fake(name, *args, **kwargs):
        if name == "openpyxl":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake)
    path = tmp_path / "a.xlsx"
    path.write_bytes(b"PK")
    with pytest.raises(InputError, match=r"a.xlsx': reading Excel workbooks needs the package "
                                         r"openpyxl \(pip install openpyxl, or pip install 'bayesfo\[excel\]'\)"):
        read(path)


# ---------------------------------------------------------------------- bad input, precisely
BAD = [
    ("omega;storage;loss\n1;2;3\n2;3;4\n", {"delimiter": ","},
     r"line 2: found one column '1;2;3': the delimiter looks like semicolon \(';'\); give "
     r"delimiter=';' \(--delimiter ;\)"),
    # A header and a units row without data: said so, not taken for a wrong delimiter.
    ("Angular Frequency\tStorage Modulus\tLoss Modulus\nrad/s\tPa\tPa\n", {},
     r"no rows of numbers \(at least two numbers per row\) found after its header: the file "
     r"has no data rows"),
    ("Angular Frequency,Storage,Loss\n1,2,3\n2,3,x\n", {},
     r"line 3, column 'Loss': 'x' is not a number"),
    ("Angular Frequency,Torque,Strain\n1,2,3\n2,3,4\n", {},
     r"line 1: no response columns among 'Angular Frequency', 'Torque', 'Strain'"),
    ("Time,G',G''\n1,2,3\n2,3,4\n", {}, r"no frequency column among 'Time', 'G'', 'G'''"),
    ("omega,G',E',G'',E''\n1,10,30,5,15\n2,12,36,6,18\n", {},
     r"columns 'G'', 'E'' could each be the storage column; name the columns with --columns"),
    ("Angular frequency [rad/s],Frequency [Hz],G',G''\n1,1,2,3\n2,2,3,4\n", {},
     r"line 2: columns 'Angular frequency \[rad/s\]' \(ω = 1 rad/s\) and 'Frequency \[Hz\]' "
     r"\(ω = 6.28319 rad/s\) disagree"),
    ("omega,G',G''\n1,2,3\n", {"columns": {"storage": "G_stor"}},
     r"--columns storage='G_stor': no such column; the columns are 'omega', 'G'', 'G'''"),
    ("omega,G',G''\n1,2,3\n", {"columns": {"stroage": "G'"}},
     r"argument 'columns': unknown role 'stroage'"),
    ("omega,G' [furlong],G''\n1,2,3\n2,3,4\n", {},
     r"line 1, column 'G' \[furlong\]': unit 'furlong' is not one bayesfo converts"),
    ("omega,G',G''\n1,2,3\n2,3,4\n", {"columns": {"storage": "G' [furlong]"}},
     r"unit 'furlong' is not one bayesfo converts"),
    ("omega,G',G''\n1;5,2,3\n", {}, r"no rows of numbers|'1;5' is not a number"),
    ("w,G',G''\n1,2,3\n1.0000000001,3,4\n", {},
     r"line 3, column 'w': the frequency 1 rad/s repeats line 2"),
    ("f,G',G''\n0,2,3\n1,3,4\n", {}, r"line 2, column 'f': frequency must be positive"),
    ("omega,G' [Pa],G'' [Pa]\n1,1e40,3\n2,3,4\n", {},
     r"line 2, column 'G' \[Pa\]': 1e\+40 is outside the magnitudes 1e-30"),
    ("omega,G',G''\n" + "".join(f"{k + 1},1,1\n" for k in range(1001)), {},
     r"has 1001 frequencies, more than the 1000"),
    ("omega,G',G''\n1,2,3\n2,3,4\n", {"kind": "viscous"}, r"argument 'kind' must be one of"),
    ("omega,G',G''\n1,2,3\n2,3,4\n", {"decimal": ";"}, r"argument 'decimal' must be"),
    ("omega;G';G''\n1,234;2;3\n2,345;3;4\n", {},
     r"numbers such as '1,234' could have a decimal comma or a thousands separator"),
    ("omega,G',G''\n1,1,1\n", {"block": 3}, r"block 3 does not exist; the file holds 1"),
]


@pytest.mark.parametrize("text, kwargs, message", BAD, ids=range(len(BAD)))
def test_bad_lab_files_name_file_line_column_and_fix(tmp_path, text, kwargs, message):
    path = tmp_path / "lab.txt"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InputError, match=message) as info:
        read(path, **kwargs)
    if "argument" not in message:
        assert str(info.value).startswith(f"file '{path}'")


def test_shift_factor_file_is_not_a_frequency_response(tmp_path):
    path = tmp_path / "shift.csv"
    path.write_text("T,log_aT\nC, -\n100,-11.7\n92,-10.92\n", encoding="utf-8")
    with pytest.raises(InputError, match=r"no frequency column among 'T', 'log_aT'"):
        read(path)


_CELLS = st.one_of(
    st.sampled_from(["omega", "freq", "f [Hz]", "G'", "G''", "E_stor", "MPa", "Hz", "rad/s",
                     "tan(delta)", "|G*|", "T", "Set", "[step]", "", "#", "1,5", "-0", "1e3",
                     "nan", "°C", "Temperature", "phase angle [rad]", "J'", "J''", "1.234,5",
                     "Units", "Data point", "Interval data:", "[Pa]", "series", "1,234"]),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-5, 1000).map(str))
_HEADERS = [["omega", "G'", "G''"], ["f [Hz]", "E_stor [MPa]", "E_loss [MPa]", "T", "Set"],
            ["Angular Frequency", "|G*| (kPa)", "tan(delta)"],
            ["w", "J' [1/Pa]", "J'' [1/Pa]", "Temperature [°C]"],
            ["Frequency", "Complex viscosity [Pa s]", "Phase angle [rad]"],
            ["omega", "real", "imag", "sigma"], ["freq", "magnitude", "phase_deg", "series"]]
_NUMBER = st.one_of(st.floats(1e-3, 1e4).map(lambda x: f"{x:.6g}"), st.integers(-3, 50).map(str),
                    st.sampled_from(["", "x", "1,5", "nan", "1e400", "0", "-1", "1.234,5",
                                     "1e305"]))


def _table(header):
    return st.tuples(st.just(header), st.lists(st.lists(_NUMBER, min_size=len(header),
                                                        max_size=len(header)),
                                               min_size=1, max_size=8),
                     st.sampled_from([",", ";", "\t", "   "]), st.booleans())


def _render(args):
    header, rows, delim, comma = args
    if comma and delim != ",":
        rows = [[c.replace(".", ",") for c in r] for r in rows]
    return "\n".join([delim.join(header)] + [delim.join(r) for r in rows]) + "\n"


@settings(max_examples=100, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(st.one_of(
    st.text(max_size=300),
    st.lists(st.lists(_CELLS, min_size=1, max_size=6), min_size=1, max_size=8).flatmap(
        lambda rows: st.sampled_from([",", ";", "\t", "   "]).map(
            lambda d: "\n".join(d.join(r) for r in rows) + "\n")),
    st.sampled_from(_HEADERS).flatmap(_table).map(_render),
))
def test_fuzz_any_text_reads_or_raises_input_error(tmp_path, text):
    path = tmp_path / "fuzz.txt"
    path.write_text(text, encoding="utf-8")
    try:
        with warnings.catch_warnings():
            # a replicate series without replicates is read, with this warning
            warnings.filterwarnings("ignore", ".*some frequency has a single replicate")
            sets = read_isotherms(path)
    except InputError:
        return
    for s in sets:
        assert isinstance(s.data, FrequencyResponse) and np.all(np.isfinite(s.data.omega))
        assert np.all(np.isfinite(s.data.response)) and s.data.kind in ("modulus",
                                                                        "compliance", "generic")


# ---------------------------------------------------------------------- the pieces
@pytest.mark.parametrize("text, quantity, factor", [
    ("[MPa]", "modulus", 1e6), ("kPa", "modulus", 1e3), ("1/MPa", "compliance", 1e-6),
    ("MPa-1", "compliance", 1e-6), ("Pa·s", "viscosity", 1.0), ("mPa s", "viscosity", 1e-3),
    ("rad/s", "angular_frequency", 1.0), ("1/s", "angular_frequency", 1.0),
    ("Hz", "frequency", 1.0), ("rad", "angle", 180 / math.pi), ("°", "angle", 1.0),
    ("dyn/cm²", "modulus", 0.1), ("K", "temperature", 1.0),
])
def test_units(text, quantity, factor):
    unit = parse_unit(text)
    assert unit.quantity == quantity and unit.factor == pytest.approx(factor, rel=1e-15)
    assert parse_unit("furlong") is None and parse_unit("K").to_si(293.15) == pytest.approx(20.0)


@pytest.mark.parametrize("cell, expected", [
    ("Storage modulus [MPa]", ("Storage modulus", "MPa")), ("G' (kPa)", ("G'", "kPa")),
    ("G'' in kPa", ("G''", "kPa")), ("omega_rad_s", ("omega", "rad/s")),
    ("Gp_Pa", ("Gp", "Pa")), ("Raw phase (torque)", ("Raw phase (torque)", None)),
])
def test_header_units(cell, expected):
    assert split_header(cell) == expected


# ---------------------------------------------------------------------- command line
def test_cli_inspect_prints_every_choice(run_cli):
    status, out, _ = run_cli("inspect", LAB / "pyvisco_raw.csv")
    assert status == 0 and "2 data sets, read as pyvisco CSV (comma-separated" in out
    assert "[1] Set 0 (-49.88 °C)" in out
    assert "note: columns used: freq ← 'f [Hz]'; storage ← 'E_stor [MPa]'" in out
    assert "note: units converted to SI: 'f': Hz → rad/s (ω = 2π f); 'E_stor': MPa → Pa" in out
    assert "note: kind modulus: columns 'E_stor', 'E_loss' are a tensile modulus" in out
    status, out, _ = run_cli("inspect", LAB / "pyvisco_raw.csv", "--json")
    info = json.loads(out)
    assert status == 0 and [i["block"] for i in info] == ["Set 0", "Set 1"]
    assert info[0]["units"] == "Pa" and info[0]["reading"]["delimiter"] == "comma"
    assert info[0]["omega_min"] == TAU * 0.1 and info[0]["magnitude_max"] > 8.7e9


def test_cli_columns_block_and_errors(run_cli):
    status, out, _ = run_cli("inspect", LAB / "headerless.txt", "--columns",
                             'omega=1,storage="2 [kPa]",loss=3 [kPa]', "--json")
    info = json.loads(out)
    assert status == 0 and info["reading"]["columns"]["storage"] == "column 2 [kPa]"
    status, out, _ = run_cli("inspect", LAB / "trios_steps.csv", "--block", "2", "--json")
    assert status == 0 and json.loads(out)["temperature_C"] == 60.0
    status, _, err = run_cli("compare", LAB / "trios_steps.csv", "--structures", "voigt")
    assert status == 2 and "holds 2 data sets" in err and "--block N" in err
    status, _, err = run_cli("inspect", LAB / "headerless.txt", "--columns", "frequency=1")
    assert status == 2 and "--columns: unknown role 'frequency'" in err


def test_block_by_temperature_and_unicode_in_the_message(run_cli):
    # trios_steps.csv: two frequency sweeps, the second at 60 °C. A temperature names the data
    # set within 0.5 °C of it ("60 °C", "60C", "59.8C"); an unknown one is refused with the degree sign as
    # typed (not escaped as \xb0) and what to give instead.
    for block in ("60 °C", "60C", "60.0 °C", "59.8C"):  # measured temperatures within 0.5 °C
        status, out, _ = run_cli("inspect", LAB / "trios_steps.csv", "--block", block, "--json")
        assert status == 0 and json.loads(out)["temperature_C"] == 60.0, block
    status, _, err = run_cli("inspect", LAB / "trios_steps.csv", "--block", "61 °C")
    assert status == 2 and "no data set '61 °C'" in err and "\\xb0" not in err
    assert 'the temperature (e.g. --block "20 °C")' in err and "block=" not in err


def test_a_bare_number_that_is_also_a_temperature_is_refused(run_cli, tmp_path):
    """On a file of isotherms, --block 30 could be the 30th set or the one at 30 °C: refused
    where they differ, with both spellings; "#3" is the number, "30 °C" the temperature, and a
    temperature below zero may follow --block without '='."""
    rows = ["omega,G',G'',T"]
    for t, g in ((-5, 10.0), (2, 5.0), (30, 1.0)):
        rows += [f"{w},{g * w},{g * w / 2},{t}" for w in (0.1, 1.0, 10.0)]
    path = tmp_path / "isotherms.csv"
    path.write_text("\n".join(rows) + "\n")
    # The second set is the one at 2 °C: both readings agree, nothing to refuse.
    status, out, _ = run_cli("inspect", path, "--block", "2", "--json")
    assert status == 0 and json.loads(out)["temperature_C"] == 2.0
    with pytest.raises(InputError, match=r"block 30 is ambiguous: there is no data set 30, and "
                                         r"a data set is at 30 °C; give block='30 °C'"):
        read(path, block="30")
    status, _, err = run_cli("inspect", path, "--block", "30")
    assert status == 2 and '--block "30 °C" for the temperature or --block "#30"' in err
    for block, temperature in (("#3", 30.0), ("30 °C", 30.0), ("-5C", -5.0), ("1", -5.0)):
        status, out, err = run_cli("inspect", path, "--block", block, "--json")
        assert status == 0 and json.loads(out)["temperature_C"] == temperature, (block, err)
    assert read(path, block=3).n_frequencies == 3  # an int is the number


def test_several_data_sets_are_refused_in_the_words_of_the_caller(run_cli):
    """The command line names --block and --columns only; the API names block= and columns=."""
    path = LAB / "trios_steps.csv"
    head = (f"file '{path}' holds 2 data sets (1: Frequency sweep - 2 (25 °C), "
            "2: Frequency sweep - 3 (60 °C)); ")
    tail = "; or, if the rows form one data set such as a master curve, ignore the grouping with "
    status, _, err = run_cli("compare", path, "--structures", "voigt")
    assert status == 2
    assert err == (f"bayesfo: error: {head}choose one with --block N (N from 1, e.g. --block 1) "
                   f'or its temperature (--block "25 °C"), every one with bayesfo batch FILE'
                   f"{tail}--columns temperature=,block=\n")
    with pytest.raises(InputError) as info:
        read(path)
    assert str(info.value) == (
        f"{head}read one with block=N (N from 1, e.g. block=1) or its temperature "
        f"(block='25 °C'), every one with bayesfo.data.read_isotherms{tail}"
        "columns={'temperature': None, 'block': None}")
    assert read(path, block="25 °C").n_frequencies == read(path, block=1).n_frequencies
    status, out, _ = run_cli("inspect", path, "--block", "25 °C", "--json")
    assert status == 0 and json.loads(out)["temperature_C"] == 25.0
    with pytest.raises(InputError, match=r"e\.g\. block='20 °C'\)$"):
        read(path, block="61 °C")


def test_inspect_of_several_data_sets_prints_each_note_once(run_cli):
    status, out, _ = run_cli("inspect", LAB / "trios_steps.csv")
    assert status == 0
    notes = [line for line in out.splitlines() if line.startswith("note: ")]
    assert len(notes) == len(set(notes))  # the second set's shared notes are not repeated
    assert "note: and 7 note(s) as for the data sets above" in notes
    assert "[2] Frequency sweep - 3 (60 °C)" in out.splitlines()
    status, out, _ = run_cli("inspect", LAB / "trios_steps.csv", "--block", "2")
    assert "note: units converted to SI: 'Storage modulus': kPa → Pa (× 1000)" in out.replace(
        "; 'Loss modulus': kPa → Pa (× 1000)", "")  # one data set: every note


# ---------------------------------------------------------------------- batch: a temperature series
def test_batch_expands_a_lab_file_into_isotherms(tmp_path):
    from bayesfo.batch import expand_inputs
    from bayesfo.batch.task import _read_task_data

    datasets = expand_inputs([LAB / "ares_trios_lims.txt", LAB / "compliance.csv"],
                             options={"structures": "voigt"})
    assert [(d.id, d.temperature, d.block) for d in datasets] == [
        ("ares_trios_lims-Tp150C", 150.0, "Frequency sweep (150.0 °C)"),
        ("ares_trios_lims-Tm040C", -40.0, "Frequency sweep (-40.0 °C)"),
        ("compliance", None, None)]
    expected = read_isotherms(LAB / "ares_trios_lims.txt")
    for ds, iso in zip(datasets, expected):
        data = _read_task_data(dict(ds.task(), path="/elsewhere/ares.txt"), read_csv)
        np.testing.assert_array_equal(data.omega, iso.data.omega)
        np.testing.assert_array_equal(data.response, iso.data.response)
        assert data.kind == "modulus" and data.source == "/elsewhere/ares.txt"
        assert ds.fingerprint()["block"] == iso.label
        assert ds.task()["notes"] == list(iso.data.notes)
    data = _read_task_data(datasets[2].task(), read_csv)
    assert data.kind == "compliance" and data.units == "1/Pa"
    bad = tmp_path / "bad.txt"
    bad.write_text("Time,Torque\n1,2\n2,3\n", encoding="utf-8")
    (only,) = expand_inputs([bad], options={"structures": "voigt"})
    assert only.error.startswith(f"file '{bad}', line 1: no frequency column")


def test_an_excel_sheet_with_a_stray_cell_far_out_is_refused_before_it_is_read(tmp_path):
    """A stray cell at XFD200000 declares 3.3e9 cells: refused from the sheet's dimension,
    naming the cell, instead of being padded row by row."""
    openpyxl = pytest.importorskip("openpyxl")
    path = tmp_path / "far.xlsx"
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.append(["Angular Frequency [rad/s]", "Storage Modulus [Pa]", "Loss Modulus [Pa]"])
    for w, g in zip(W, G, strict=True):
        sheet.append([float(w), float(g.real), float(g.imag)])
    sheet["XFD200000"] = 1.0
    book.save(path)
    with pytest.raises(InputError, match=r"spans 200000 rows × 16384 columns \(to cell "
                                         r"XFD200000\).*delete the cells beyond the data"):
        read_isotherms(path)
    del sheet["XFD200000"]  # openpyxl keeps the dimension of the cells left
    book.save(path)
    np.testing.assert_allclose(read_isotherms(path)[0].data.response, G, rtol=1e-12)


def test_an_excel_sheet_of_too_many_rows_stops_at_the_cap(tmp_path, monkeypatch):
    """Without a declared dimension (a write-only workbook), the rows are counted as they are
    read and reading stops at the cap."""
    openpyxl = pytest.importorskip("openpyxl")
    from bayesfo.data import tables

    path = tmp_path / "long.xlsx"
    book = openpyxl.Workbook(write_only=True)
    sheet = book.create_sheet("sweep")
    sheet.append(["omega", "G'", "G''"])
    for i in range(1, 301):
        sheet.append([float(i), 1.0, 2.0])
    book.save(path)
    monkeypatch.setattr(tables, "EXCEL_MAX_LINES", 100)
    with pytest.raises(InputError, match=r"sheet 'sweep': more than 100 rows \(row 101 read\)"):
        read_isotherms(path)


def test_an_oversized_sheet_beside_the_data_is_left_out_with_a_warning(tmp_path):
    """An instrument's log sheet with a stray far cell does not stop the data sheet from being
    read; a warning names what was left out."""
    openpyxl = pytest.importorskip("openpyxl")
    from bayesfo.errors import DataWarning

    path = tmp_path / "two.xlsx"
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.title = "sweep"
    sheet.append(["Angular Frequency [rad/s]", "Storage Modulus [Pa]", "Loss Modulus [Pa]"])
    for w, g in zip(W, G, strict=True):
        sheet.append([float(w), float(g.real), float(g.imag)])
    log = book.create_sheet("log")
    log["XFD200000"] = "end"
    book.save(path)
    with pytest.warns(DataWarning, match=r"sheet 'log': the sheet spans 200000 rows .* left out"):
        iso = read_isotherms(path)
    assert iso[0].reading.format == "Excel workbook (sheet 'sweep')"
    np.testing.assert_allclose(iso[0].data.response, G, rtol=1e-12)


def test_a_sheet_of_numbers_without_a_frequency_is_left_out_beside_the_data(tmp_path):
    """An instrument's header sheet (numbers, no frequency column, as the Eplexor export's
    'Data header') beside the data sheet is left out with a warning; alone, it is the error."""
    openpyxl = pytest.importorskip("openpyxl")
    from bayesfo.errors import DataWarning

    path = tmp_path / "eplexor.xlsx"
    book = openpyxl.Workbook()
    head = book.active
    head.title = "Data header"
    head.append(["Sample thickness [mm]", "Sample width [mm]"])
    head.append([2.0, 10.0])
    head.append([2.1, 10.2])
    head.append([2.2, 10.1])
    data = book.create_sheet("Exported Data")
    data.append(["Angular Frequency [rad/s]", "Storage Modulus [Pa]", "Loss Modulus [Pa]"])
    for w, g in zip(W, G, strict=True):
        data.append([float(w), float(g.real), float(g.imag)])
    book.save(path)
    with pytest.warns(DataWarning, match=r"sheet 'Data header'.*the sheet is left out"):
        iso = read_isotherms(path)
    assert len(iso) == 1 and iso[0].reading.format == "Excel workbook (sheet 'Exported Data')"
    np.testing.assert_allclose(iso[0].data.response, G, rtol=1e-12)
    del book["Exported Data"]
    book.save(path)
    with pytest.raises(InputError, match="sheet 'Data header'"):
        read_isotherms(path)


def test_repeated_frequencies_get_one_piece_of_advice_from_every_reader(tmp_path):
    from bayesfo.data.csv_reader import DUPLICATE_ADVICE

    contract = tmp_path / "contract.csv"
    contract.write_text("# kind: modulus\n# units: Pa\nomega,storage,loss\n1,100,30\n2,150,40\n"
                        "1,80,35\n", encoding="utf-8")
    lab = tmp_path / "lab.txt"
    lab.write_text("Angular frequency (rad/s)\tStorage modulus (Pa)\tLoss modulus (Pa)\n"
                   "1\t100\t30\n2\t150\t40\n1\t80\t35\n", encoding="utf-8")
    for path, line in ((contract, 6), (lab, 4)):
        with pytest.raises(InputError) as info:
            read(path)
        message = str(info.value)
        assert f"line {line}, column" in message and "the frequency 1 rad/s repeats" in message
        assert message.endswith(DUPLICATE_ADVICE)
    # ... and --duplicates works on both: the contract file read as the lab file is.
    for how, storage, loss in (("first", [100.0, 150.0], [30.0, 40.0]),
                               ("mean", [90.0, 150.0], [32.5, 40.0])):
        a, b = read(contract, duplicates=how), read(lab, duplicates=how)
        for d in (a, b):
            _assert_data(d, [1.0, 2.0], np.array(storage) + 1j * np.array(loss), "modulus")
        assert a.units == b.units == "Pa"


def test_an_eplexor_xls_workbook_is_read_directly():
    # The Eplexor's Excel 97 export (.xls): 21 tensile isotherms of 10 frequencies; its "Data
    # header" sheet of test settings (numbers, no frequency column) is left out, said once.
    pytest.importorskip("xlrd")
    import xlrd

    path = LAB / "eplexor_raw.xls"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sets = read_isotherms(path)
    from bayesfo.errors import DataWarning

    notes = [str(w.message) for w in caught if issubclass(w.category, DataWarning)]
    assert len(notes) == 1 and "sheet 'Data header'" in notes[0]
    assert len(sets) == 21 and all(s.data.n_frequencies == 10 for s in sets)
    assert all(s.data.symbol == "E" and s.data.kind == "modulus" and s.data.units == "Pa"
               for s in sets)
    # Against the sheet's cells read by xlrd alone: f [Hz], T [°C], E', E'' [MPa].
    sheet = xlrd.open_workbook(str(path)).sheet_by_name("Exported Data")
    head = sheet.row_values(0)
    rows = np.array([[float(sheet.cell_value(i, head.index(c))) for c in ("f", "T", "E'", "E''")]
                     for i in range(2, sheet.nrows)])
    first = sets[0]
    assert first.temperature == pytest.approx(rows[:10, 1].mean(), abs=0.05)
    np.testing.assert_allclose(first.data.omega, 2 * np.pi * rows[:10, 0], rtol=1e-12)
    np.testing.assert_allclose(first.data.response, 1e6 * (rows[:10, 2] + 1j * rows[:10, 3]),
                               rtol=1e-12)
    assert sets[-1].temperature == pytest.approx(100.0, abs=0.1)


def test_a_temperature_without_unit_that_reads_as_kelvin_is_warned_of(tmp_path):
    """'# temperature: 293.15' was read as 293.15 °C without a word (issue 65): the master
    curve of it beside '273.15 K' and '10 C' gave WLF C1 0.80."""
    import warnings as _warnings

    from bayesfo.data import read_isotherms
    from bayesfo.data.temperature import temperature_of_file
    from bayesfo.errors import DataWarning

    path = tmp_path / "k.csv"
    path.write_text("# temperature: 293.15\nomega,storage,loss\n1,1,1\n2,2,2\n3,3,3\n")
    for reader in (lambda: read_isotherms(path)[0].temperature, lambda: temperature_of_file(path)):
        with pytest.warns(DataWarning, match=r"'# temperature: 293.15' has no unit and is read "
                                             r"as 293.15 °C, yet it looks like kelvin \(20 °C\)"):
            assert reader() == 293.15
    for text in ("20", "150", "293.15 K", "20.15"):
        path.write_text(f"# temperature: {text}\nomega,storage,loss\n1,1,1\n2,2,2\n3,3,3\n")
        with _warnings.catch_warnings():
            _warnings.simplefilter("error", DataWarning)
            read_isotherms(path)
            temperature_of_file(path)
