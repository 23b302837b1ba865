"""FrequencyResponse and the CSV reader: every form of the contract and every bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from bayesfo.data import FrequencyResponse, read_csv
from bayesfo.errors import InputError

W = np.array([0.5, 1.0, 2.0, 4.0])
G = 1.0 / (1.0 + (1j * W) ** 0.5)


def test_real_imag_sorted_and_metadata(write_csv):
    path = write_csv(
        """
        # name: sample A
        # kind: compliance
        # units: 1/MPa
        omega,real,imag
        2.0,0.5,-0.25
        0.5,0.9,-0.1
        1.0,0.7,-0.2
        """
    )
    fr = read_csv(path)
    np.testing.assert_array_equal(fr.omega, [0.5, 1.0, 2.0])
    np.testing.assert_array_equal(fr.response, [0.9 - 0.1j, 0.7 - 0.2j, 0.5 - 0.25j])
    assert (fr.kind, fr.units, fr.name, fr.sigma) == ("compliance", "1/MPa", "sample A", None)
    assert read_csv(path, kind="generic").kind == "generic"


def test_freq_in_hz_magnitude_phase_and_sigma(write_csv):
    path = write_csv(
        """
        freq,magnitude,phase_deg,sigma
        1.0,2.0,-90,0.1
        10.0,1.0,45,0.2
        """
    )
    fr = read_csv(path)
    np.testing.assert_allclose(fr.omega, [2 * np.pi, 20 * np.pi], rtol=1e-15)
    np.testing.assert_allclose(fr.response, [-2.0j, np.sqrt(0.5) * (1 + 1j)], atol=1e-15)
    np.testing.assert_array_equal(fr.sigma, [0.1, 0.2])


@pytest.mark.parametrize("kind, sign", [("modulus", 1), ("generic", 1), ("compliance", -1)])
def test_storage_loss_sign_follows_kind(write_csv, kind, sign):
    # G* = G' + jG'' for a modulus; J* = J' - jJ'' for a compliance (J'' >= 0).
    fr = read_csv(write_csv("omega,storage,loss\n1.0,3.0,0.5\n"), kind=kind)
    assert fr.response[0] == 3.0 + sign * 0.5j


def test_replicate_series_mean_and_standard_error(write_csv):
    rows = ["omega,real,imag,series"]
    reps = {1.0: [1.0 + 0.0j, 1.2 - 0.2j, 0.8 + 0.1j], 2.0: [0.5 - 0.5j, 0.6 - 0.4j, 0.7 - 0.6j]}
    for r in range(3):
        for w, vals in reps.items():
            rows.append(f"{w},{vals[r].real},{vals[r].imag},{r}")
    fr = read_csv(write_csv("\n".join(rows)))
    for k, vals in enumerate(reps.values()):
        vals = np.array(vals)
        mean = vals.mean()
        se = np.sqrt(np.sum(np.abs(vals - mean) ** 2) / 2 / 3)
        assert fr.response[k] == pytest.approx(mean, abs=1e-15)
        assert fr.sigma[k] == pytest.approx(se, rel=1e-12)
    assert "mean of 3 replicate series" in fr.notes


def test_replicates_with_sigma_are_inverse_variance_weighted(write_csv):
    path = write_csv("omega,real,imag,sigma,series\n1,1.0,0,0.1,a\n1,2.0,0,0.2,b\n")
    with pytest.raises(InputError, match="column 'series': 'a' is not a number"):
        read_csv(path)
    fr = read_csv(write_csv("omega,real,imag,sigma,series\n1,1.0,0,0.1,1\n1,2.0,0,0.2,2\n"))
    w = np.array([100.0, 25.0])
    assert fr.response[0] == pytest.approx((w @ [1.0, 2.0]) / w.sum())
    assert fr.sigma[0] == pytest.approx(1 / np.sqrt(w.sum()))


def test_single_replicate_gives_no_sigma_with_warning(write_csv):
    path = write_csv("omega,real,imag,series\n1,1,0,1\n1,2,0,2\n2,1,0,1\n")
    with pytest.warns(UserWarning, match="single replicate"):
        fr = read_csv(path)
    assert fr.sigma is None
    np.testing.assert_allclose(fr.response, [1.5, 1.0])


def test_from_replicates_matches_numpy():
    rng = np.random.default_rng(1)
    reps = G + 0.01 * (rng.normal(size=(5, 4)) + 1j * rng.normal(size=(5, 4)))
    fr = FrequencyResponse.from_replicates(W, reps)
    np.testing.assert_allclose(fr.response, reps.mean(axis=0), rtol=1e-14)
    expected = np.sqrt((np.abs(reps - reps.mean(axis=0)) ** 2).sum(axis=0) / 4 / 5)
    np.testing.assert_allclose(fr.sigma, expected, rtol=1e-12)


def test_reciprocal_values_sigma_and_kind():
    fr = FrequencyResponse(W, G, sigma=np.full(4, 0.01), kind="compliance", units="1/Pa")
    inv = fr.reciprocal()
    np.testing.assert_allclose(inv.response, 1 + (1j * W) ** 0.5, rtol=1e-14)
    np.testing.assert_allclose(inv.sigma, 0.01 / np.abs(G) ** 2, rtol=1e-14)
    assert (inv.kind, inv.units) == ("modulus", "Pa")  # not 1/(1/Pa)
    assert (inv.reciprocal().kind, inv.reciprocal().units) == ("compliance", "1/Pa")
    generic = FrequencyResponse(W, G, kind="generic", units="m/N").reciprocal()
    assert generic.units == "1/(m/N)" and generic.reciprocal().units == "m/N"


def test_reciprocal_sigma_first_order_against_monte_carlo():
    # The propagated sigma is the first-order (delta-method) value: small noise agrees with
    # the spread of 1/(G + noise) to a few per cent (Monte Carlo error ~ 1/sqrt(2n) = 0.7 %).
    rng = np.random.default_rng(7)
    g, s, n = 0.3 - 0.4j, 1e-3, 10_000
    noise = s * (rng.normal(size=n) + 1j * rng.normal(size=n)) / np.sqrt(2)
    spread = np.sqrt(np.mean(np.abs(1 / (g + noise) - 1 / g) ** 2))
    predicted = FrequencyResponse([1.0], [g], [s]).reciprocal().sigma[0]
    assert spread == pytest.approx(predicted, rel=0.03)


def test_reciprocal_of_zero_response_names_the_point():
    fr = FrequencyResponse([1.0, 2.0], [1.0, 0.0], source="x.csv")
    with pytest.raises(InputError, match=r"file 'x.csv'.*zero at omega = 2 rad/s \(point 2 of 2\)"):
        fr.reciprocal()


def test_split_by_frequency():
    fr = FrequencyResponse(W, G)
    train, test = fr.split([1.0, 4.0])
    np.testing.assert_array_equal(train.omega, [0.5, 2.0])
    np.testing.assert_array_equal(test.omega, [1.0, 4.0])
    np.testing.assert_array_equal(test.response, G[[1, 3]])
    with pytest.raises(InputError, match="hold-out frequency 3 rad/s is not among"):
        fr.split([3.0])
    # The nearest measured frequencies, on a log scale, closest first (3 is nearer to 4 than
    # to 2 by ratio), to give back as they are.
    with pytest.raises(InputError, match=r"the nearest measured: 4, 2 rad/s$"):
        fr.split([3.0])
    with pytest.raises(InputError, match=r"the nearest measured: 0.5 rad/s$"):
        fr.split([0.0])
    with pytest.raises(InputError, match="nothing is left to fit"):
        fr.split(W)


def test_scaling_references():
    fr = FrequencyResponse(W, G)
    assert fr.omega_ref == pytest.approx(np.exp(np.mean(np.log(W))))
    assert fr.g_ref == pytest.approx(np.median(np.abs(G)))


def test_to_csv_round_trip(tmp_path):
    fr = FrequencyResponse(W, G, np.full(4, 1e-3), kind="compliance", units="1/MPa", name="x")
    back = read_csv(fr.to_csv(tmp_path / "out.csv"))
    np.testing.assert_array_equal(back.omega, fr.omega)
    np.testing.assert_array_equal(back.response, fr.response)
    np.testing.assert_array_equal(back.sigma, fr.sigma)
    assert (back.kind, back.units, back.name) == ("compliance", "1/MPa", "x")


def test_enough_points():
    fr = FrequencyResponse(W[:3], G[:3], source="d.csv")
    fr.check_enough_points(3, "structure 'zener'")
    with pytest.raises(InputError, match="file 'd.csv' has 3 frequencies, fewer than the 4 "
                                         "parameters of structure 'zener': measure more "
                                         "frequencies, or choose structures of fewer"):
        fr.check_enough_points(4, "structure 'zener'")


# ---------------------------------------------------------------- bad input: each one named
BAD_CSV = [
    ("omega,real\n1,2\n", "missing column 'imag'"),
    ("real,imag\n1,2\n", "missing frequency column"),
    ("omega,freq,real,imag\n1,1,1,1\n", "either 'omega' or 'freq'"),
    ("omega,real,imag,temperature\n1,1,1,20\n", "line 1: unknown column 'temperature'"),
    ("omega,real,imag,magnitude\n1,1,1,1\n", "mix two response forms"),
    ("omega,real,real\n1,1,1\n", "column 'real' appears twice"),
    ("omega,real,imag\n", "no data rows"),
    ("# only a comment\n", "is empty"),
    ("omega,real,imag\n1,1,1\n2,abc,1\n", "line 3, column 'real': 'abc' is not a number"),
    ("omega,real,imag\n1,1,1\n2,,1\n", "line 3, column 'real': the cell is empty"),
    ("omega,real,imag\n1,1,nan\n", "line 2, column 'imag': value is nan"),
    ("omega,real,imag\n1,1,1\n2,inf,1\n", "line 3, column 'real': value is inf"),
    ("omega,real,imag\n1,1,1\n0,1,1\n", "line 3, column 'omega': frequency must be positive"),
    ("freq,real,imag\n-1,1,1\n", "line 2, column 'freq': frequency must be positive"),
    ("omega,real,imag\n1,1,1\n2,1,1\n1,3,3\n", "line 4, column 'omega': the frequency 1 rad/s repeats line 2"),
    ("omega,real,imag\n1,1,1\n2,1\n", "line 3: expected 3 cells"),
    ("omega,magnitude,phase_deg\n1,-1,0\n", "line 2, column 'magnitude': magnitude is negative"),
    ("omega,real,imag,sigma\n1,1,1,0\n", "line 2, column 'sigma': sigma must be positive"),
    ("omega,real,imag,series\n1,1,1,1\n1,1,1,1\n", "line 3, column 'omega': the frequency 1 rad/s repeats line 2"),
    ("# kind: viscous\nomega,real,imag\n1,1,1\n", "kind must be one of"),
]


@pytest.mark.parametrize("text, message", BAD_CSV)
def test_bad_csv_is_named(write_csv, text, message):
    path = write_csv(text)
    with pytest.raises(InputError, match=message) as info:
        read_csv(path)
    assert str(path) in str(info.value)


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(InputError, match="does not exist"):
        read_csv(tmp_path / "nope.csv")
    with pytest.raises(InputError, match="is a directory: give a file of it \\(bayesfo batch "
                                         "and bayesfo mastercurve take a directory"):
        read_csv(tmp_path)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(omega=[1, 2], response=[1]), "same length"),
        (dict(omega=[1, -2], response=[1, 1]), r"omega\[1\] = -2"),
        (dict(omega=[1, 1], response=[1, 1]), "frequency 1 rad/s twice"),
        (dict(omega=[1, np.nan], response=[1, 1]), "NaN or infinity at index 1"),
        (dict(omega=[1, 2], response=[1, np.inf]), "'response' contains NaN or infinity"),
        (dict(omega=[1, 2], response=[1, 1], sigma=[1, 0]), r"sigma\[1\] = 0"),
        (dict(omega=[1, 2], response=[1, 1], kind="fluid"), "'kind' must be one of"),
        (dict(omega=[[1, 2]], response=[[1, 1]]), "one-dimensional"),
        (dict(omega=[], response=[]), "empty"),
    ],
)
def test_constructor_checks(kwargs, message):
    with pytest.raises(InputError, match=message):
        FrequencyResponse(**kwargs)


# A temperature column is read by the tolerant reader (bayesfo.read) that the command line uses.
@pytest.mark.parametrize("text, message", [c for c in BAD_CSV if "temperature" not in c[0]])
def test_cli_bad_input_exit_2_one_line(write_csv, run_cli, text, message):
    path = write_csv(text)
    status, out, err = run_cli("inspect", path)
    assert status == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("bayesfo: error: ")
    assert "Traceback" not in err


def test_cli_too_few_points_and_zero_reciprocal(write_csv, run_cli):
    path = write_csv("omega,real,imag\n1,1,-1\n2,0.7,-0.4\n3,0.5,-0.2\n")
    status, _, err = run_cli("inspect", path, "--structures", "zener")
    assert status == 2
    assert "has 3 frequencies, fewer than the 4 parameters of structure 'zener'" in err
    status, out, _ = run_cli("inspect", path, "--structures", "voigt", "--json")
    assert status == 0 and '"voigt": 3' in out
    # A response of exactly 0 cannot be a measured point (no reciprocal, no relative noise):
    # the reader names it (the reciprocal of a zero built in the API: test_reciprocal_*).
    zero = write_csv("omega,real,imag\n1,1,-1\n2,0,0\n3,0.5,-0.2\n", name="zero.csv")
    status, _, err = run_cli("inspect", zero, "--reciprocal")
    assert status == 2 and "line 3, columns 'real' and 'imag': the response is exactly 0" in err


def test_dissipation_violations_follow_kind():
    fr = FrequencyResponse([1.0, 2.0, 3.0], [1 + 0.1j, 1 - 0.2j, 1 + 0j], kind="modulus")
    np.testing.assert_array_equal(fr.dissipation_violations(), [1])
    np.testing.assert_array_equal(fr.with_kind("compliance").dissipation_violations(), [0])
    assert fr.with_kind("generic").dissipation_violations().size == 0


def test_cli_inspect_reports_negative_loss_of_bundled_glassy_isotherm(run_cli):
    # The -40 °C isotherm of the 3M 468MP data has one negative G'' (a known artefact).
    path = Path(__file__).parents[2] / "examples" / "data" / "adhesive_468mp" / "Tm040C.csv"
    status, out, _ = run_cli("inspect", path, "--json")
    info = json.loads(out)
    assert status == 0 and info["n_frequencies"] == 17 and info["kind"] == "modulus"
    assert len(info["dissipation_violations"]) == 1


def test_storage_and_loss_mean_a_modulus_unless_told_otherwise(write_csv):
    text = "omega,storage,loss\n1,100,30\n2,150,40\n3,180,45\n"
    fr = read_csv(write_csv(text))
    assert fr.kind == "modulus" and fr.response[0] == 100 + 30j
    assert fr.notes[0].startswith("kind modulus: storage and loss columns are the parts of a")
    j = read_csv(write_csv("# kind: compliance\n" + text, name="j.csv"))
    assert j.kind == "compliance" and j.response[0] == 100 - 30j and not j.notes
    g = read_csv(write_csv(text, name="g.csv"), kind="generic")
    assert g.kind == "generic" and not g.notes
    # Other forms stay generic unless told.
    assert read_csv(write_csv("omega,real,imag\n1,1,-1\n2,2,-1\n", name="r.csv")).kind == "generic"
