"""Raw files read directly give the ω [rad/s], response [Pa] and kind of their hand-converted
counterparts (slow: they read the real data in ../shared/data, skipped when absent).

* the bundled adhesive isotherms (examples/data/adhesive_468mp) against the original TA ARES-G2
  TRIOS export and against the tidy CSV derived from it;
* the bundled NREL master curve (examples/data/nrel_dma_master.csv, MPa) against pyvisco's file;
* the GPL reference files (read here, never copied into the project): RepTate .tts against the
  derived CSVs, and the other raw files against an independent parse with pandas.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from bayesfo.data import read, read_csv, read_isotherms

pytestmark = pytest.mark.slow

ROOT = Path(__file__).parents[2]
SHARED = Path(__file__).parents[3] / "shared" / "data"
REAL = SHARED / "real"
GPL = SHARED / "reference-gpl"
RTOL = 1e-9
TAU = 2 * np.pi


def _needs(path: Path) -> Path:
    if not path.exists():
        pytest.skip(f"{path} is not available")
    return path


def _same(fr, omega, response, kind="modulus"):
    np.testing.assert_allclose(fr.omega, omega, rtol=RTOL, atol=0)
    np.testing.assert_allclose(fr.response.real, np.real(response), rtol=RTOL, atol=0)
    np.testing.assert_allclose(fr.response.imag, np.imag(response), rtol=RTOL,
                               atol=RTOL * np.abs(response).max())
    assert fr.kind == kind


def _stem(t: float) -> str:
    return f"T{'m' if t < 0 else 'p'}{abs(int(round(t))):03d}C"


# ---------------------------------------------------------------------- bundled, real
def test_ares_trios_export_gives_the_bundled_isotherms():
    raw = _needs(REAL / "hermes_3m468mp_psa" / "original" / "test_frequency_sweep_tts_ARES.txt")
    sets = read_isotherms(raw)
    assert len(sets) == 20
    assert [s.temperature for s in sets] == [float(t) for t in range(150, -41, -10)]
    for iso in sets:
        ref = read_csv(ROOT / "examples" / "data" / "adhesive_468mp" /
                       f"{_stem(iso.temperature)}.csv")
        _same(iso.data, ref.omega, ref.response, ref.kind)
        assert iso.data.units == "Pa" and ref.units == "Pa"


def test_tidy_derived_csv_gives_the_same_isotherms():
    tidy = _needs(REAL / "hermes_3m468mp_psa" / "derived" / "468MP_freqsweeps_tidy.csv")
    sets = read_isotherms(tidy)
    assert [s.temperature for s in sets] == [float(t) for t in range(150, -41, -10)]
    for iso in sets:
        ref = read_csv(ROOT / "examples" / "data" / "adhesive_468mp" /
                       f"{_stem(iso.temperature)}.csv")
        _same(iso.data, ref.omega, ref.response, ref.kind)


def test_pyvisco_master_curve_gives_the_bundled_one_in_pascal():
    raw = _needs(REAL / "pyvisco_nrel_dma" / "original" / "examples" / "freq_user_master.csv")
    ref = read_csv(ROOT / "examples" / "data" / "nrel_dma_master.csv")  # MPa, as the source
    fr = read(raw, duplicates="first")  # the bundled file drops the second of two rows
    assert ref.units == "MPa" and fr.units == "Pa"
    _same(fr, ref.omega, 1e6 * ref.response, ref.kind)
    assert any("'E_stor': MPa → Pa" in n for n in fr.notes)


def test_pyvisco_raw_isotherms_against_pandas():
    raw = _needs(REAL / "pyvisco_nrel_dma" / "original" / "examples" / "freq_user_raw.csv")
    frame = pd.read_csv(raw, skiprows=[1], encoding="utf-8-sig", skipinitialspace=True)
    sets = read_isotherms(raw)
    assert len(sets) == 21
    for iso, (key, rows) in zip(sets, frame.groupby("Set", sort=False)):
        assert iso.label == f"Set {key}"
        assert iso.temperature == pytest.approx(rows["T"].mean(), abs=0.005)
        _same(iso.data, TAU * rows["f"].to_numpy(),
              1e6 * (rows["E_stor"].to_numpy() + 1j * rows["E_loss"].to_numpy()))


def test_shift_factor_file_is_refused():
    path = _needs(REAL / "pyvisco_nrel_dma" / "original" / "examples" /
                  "freq_user_master__shift_factors.csv")
    with pytest.raises(ValueError, match="no frequency column among 'T', 'log_aT'"):
        read(path)


# ---------------------------------------------------------------------- GPL reference files
def _pyrheo_files():
    return sorted(GPL.glob("pyrheo_*/original/*.csv")) if GPL.exists() else []


@pytest.mark.parametrize("path", [p for p in _pyrheo_files() if "pyviscoe" not in p.name],
                         ids=lambda p: p.name)
def test_pyrheo_files_against_pandas(path):
    frame = pd.read_csv(path, sep=None, engine="python")
    fr = read(path)
    order = np.argsort(frame["Angular Frequency"].to_numpy(), kind="stable")
    _same(fr, frame["Angular Frequency"].to_numpy()[order],
          (frame["Storage Modulus"].to_numpy() + 1j * frame["Loss Modulus"].to_numpy())[order])
    assert fr.units == ""  # the files state no unit: used as written, and said so
    assert any("'Storage Modulus': no unit given" in n for n in fr.notes)


def test_pyviscoe_labels_are_followed_hz_and_mpa():
    # The file labels the numbers of its rad/s, Pa sibling as Hz and MPa: read as labelled,
    # so ω is 2π and the moduli 1e6 times the sibling's, and inspect shows why.
    base = _needs(GPL / "pyrheo_polystyrene_saos" / "original")
    sibling = read(base / "master_curve_ps_oscillation_data.csv")
    fr = read(base / "master_curve_ps_oscillation_data_pyviscoe.csv")
    _same(fr, TAU * sibling.omega, 1e6 * sibling.response)
    assert any(n.startswith("units converted to SI: 'f': Hz → rad/s (ω = 2π f); 'E_stor': "
                            "MPa → Pa") for n in fr.notes)


@pytest.mark.parametrize("path", sorted(GPL.glob("reptate_pi_linear/original/tts_mastercurves/"
                                                 "*.tts")) if GPL.exists() else [],
                         ids=lambda p: p.name)
def test_reptate_master_curves_against_the_derived_csvs(path):
    # Some master curves hold two rows at one shifted frequency (overlapping sweeps): refused
    # unless told; averaged here, in the raw file, the derived CSV and pandas alike.
    derived = GPL / "reptate_pi_linear" / "derived" / (path.stem + ".csv")
    frame = pd.read_csv(derived).groupby("omega_rad_s", sort=True).mean()
    ref = read(derived, duplicates="mean")  # omega_rad_s, Gp_Pa, Gpp_Pa: read directly too
    fr = read(path, duplicates="mean")
    _same(fr, ref.omega, ref.response)
    _same(fr, frame.index.to_numpy(), frame["Gp_Pa"].to_numpy() + 1j * frame["Gpp_Pa"].to_numpy())
    if len(frame) < len(pd.read_csv(derived)):
        with pytest.raises(ValueError, match="repeats line"):
            read(path)


def test_reptate_silk_feedstock():
    path = _needs(GPL / "reptate_silk_feedstock" / "original" / "silk_feedstock.tts")
    frame = pd.read_csv(path, sep=r"\s+", skiprows=1, header=None)
    fr = read(path)
    _same(fr, frame[0].to_numpy(), frame[1].to_numpy() + 1j * frame[2].to_numpy())


@pytest.mark.parametrize("path", sorted(GPL.glob("reptate_pi_linear/original/osc_raw_PI88K-09/"
                                                 "*.osc")) if GPL.exists() else [],
                         ids=lambda p: p.name)
def test_reptate_osc_isotherms_against_pandas(path):
    frame = pd.read_csv(path, sep=r"\s+", skiprows=3, header=None, encoding="latin-1")
    (iso,) = read_isotherms(path)
    order = np.argsort(frame[0].to_numpy(), kind="stable")
    _same(iso.data, frame[0].to_numpy()[order],
          (frame[1].to_numpy() + 1j * frame[2].to_numpy())[order])
    nominal = float(re.search(r"_(-?\d+)C_", path.name).group(1))
    assert iso.temperature == pytest.approx(nominal, abs=0.1)
