"""Master curves against two references (issue 30, "Checks"), slow.

1. NREL's raw Eplexor isotherms against the shift factors that come with them. pyvisco's
   ``verification/freq_raw/freq_Eplexor_raw.xls`` (21 tensile DMA isotherms, −50 … 100 °C,
   0.1–100 Hz, 10 points each) and ``freq_Eplexor_raw__shift_factors.csv`` (log10 a_T at
   T_ref = −5 °C; pyvisco's verification notebook loads them as the user's a_T, its own
   ``master.get_aT`` left commented out; every value is a multiple of 0.06 decade) are read from
   the bare git mirror of github:NREL/pyvisco (BSD-3-Clause, commit 252a4b8) into ``tmp_path``;
   skipped without the mirror, and without ``xlrd`` (the .xls needs it; the test extra installs
   it). bayesfo reads the workbook directly.

   What the data fix: from −50 to 32 °C the isotherms are glassy (E′ 2–5.6 GPa, tan δ ≤ 0.091)
   and neighbours barely overlap: up to 17.5 °C the model-free overlays of a pair's G″ or tan δ
   (``bayesfo.tts.validity.shifts_by_part``) give no step or one near 0 (−0.11 … 0), while the
   file steps 1.4–2.2 decades per 7.5 °C (a law, not the data); tan δ gives −2.27 and −2.33 at
   25/32 and 32/40 °C (file −1.62, −1.98). From 40 °C up the G′ overlay fixes every step. So
   the test compares the 9 isotherms from 39.98 to 99.96 °C, at T_ref 62.47 °C (their middle),
   with the file's log10 a_T re-referenced to 62 °C (a difference of log a_T does not depend on
   T_ref).
   At pyvisco's own T_ref −5 °C (measured, BENCHMARKS.md, not run here): the 21 isotherms span
   30.1 decades in the file (+11.10 at −50 °C, −19.02 at 100 °C), beyond bayesfo's uniform prior
   of ±15 decades (``bayesfo/tts/model.py`` SHIFT_RANGE): the spectrum master (814 s, not
   certified) pins 99.96 °C at −14.93 ([−15.00, −14.80]) and is 0.05–0.62 decade from the file
   below −5 °C, 1.1–4.1 above; max-n2m1 (182 s) and fractional_zener_sl (101 s) fit the
   reference isotherm apart from the others (2.5 °C lands 6.5–10 decades above −5 °C, −1.68 in
   the file; the misfit note names −4.97 °C).

   Tolerance: |bayesfo − file| ≤ 0.12 |file| + 3 sd + 0.03 per temperature. The file's steps
   exceed the model-free G′ overlay of the same pairs (``shifts_by_part``) by 2–10 % (measured
   below; the test holds that at ≤ 12 %), and where van Gurp–Palmen fails (70–85 °C) the G′, G″
   and tan δ overlays of a pair differ by up to 0.41 decade, so "the" shift is not unique there;
   0.03 is half the file's 0.06-decade grid; sd is bayesfo's posterior sd. Measured (seed 0):
   spectrum +0.11 … +0.40 above 62 °C, −0.14 … −0.41 below (tolerances 0.22–0.85, smallest
   margin 0.11 at 69.98 °C); max-n2m1 −0.57 … +0.38 (margin ≥ 0.10). The file's factors × 1.25
   or × 0.7, or one temperature moved by ±0.5 decade (69.98 °C), fail; × 0.8 passes (bayesfo's
   steps are 5–12 % below the file's and 2–4 % below the G′ overlay's).

2. pyRheo's polystyrene (GPL, read in place from ``../shared/data/reference-gpl``, skipped when
   absent): five SAOS isotherms 130–190 °C and pyRheo's master curve at 160 °C built with
   ``mastercurves`` (horizontal and vertical shifts on log tan δ). The shift factors are not
   saved, but every master point is a raw point times (a_T, b_T): tan δ is unchanged by both, so
   each raw point is found in the master file exactly (to 1e-15) and pyRheo's shifts follow:
   log10 a_T = 2.422, 1.022, 0, −0.770, −1.356 and log10 b_T = −0.009, −0.002, 0, −0.001, −0.003.

   With free vertical shifts (pyRheo's model) the spectrum master is within 0.013 decade of
   pyRheo's a_T (tolerance 0.05: the G′, G″ and tan δ overlays of the simple pairs 160/175 and
   175/190 differ by up to 0.035 decade, plus bayesfo's sd ≤ 0.016) and within 0.048 decade of
   its b_T (tolerance 0.1, the factor 1.26 beyond which the guide calls a vertical shift
   suspect). Without vertical shifts the horizontal shifts take up the vertical factor: the
   spectrum is 0.113 decade off at 130 °C, fractional_zener_sl 0.124 (tolerance: the largest
   spread of the overlays of G′, G″ and tan δ over the pairs, 0.115 at 130/145 °C, plus 3 sd).
   The reduced master curves: bayesfo's reduced points against pyRheo's master interpolated in
   log–log, median |relative difference| of G′ and G″ 2.1–3.9 %, held to pyRheo's own
   superposition scatter (each of its isotherms against the others' interpolation, median
   5.5 %; pyRheo's raw points at its own shifts give 0.4 %, at a law 15 % steeper or flatter
   14 % / 12 %: caught; one isotherm 0.1 decade off moves the median by nothing: the shift
   comparison catches that). max-n2m1 is not tested: its ln Z is 137 nats below
   fractional_zener_sl's and its shifts are 0.25–0.58 decade off (BENCHMARKS.md).
"""

from __future__ import annotations

import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

import bayesfo as bf
from bayesfo.data import read_isotherms
from bayesfo.tts.validity import shifts_by_part

pytestmark = pytest.mark.slow

PYVISCO = Path("/work/.mirror/NREL+pyvisco/repo")
PYVISCO_COMMIT = "252a4b8e6f43756deb6194bd211a2842ba866025"
EPLEXOR = "verification/freq_raw/freq_Eplexor_raw.xls"
EPLEXOR_SHIFTS = "verification/freq_raw/freq_Eplexor_raw__shift_factors.csv"
PS = (Path(__file__).parents[3] / "shared" / "data" / "reference-gpl"
      / "pyrheo_polystyrene_saos" / "original")
PS_TEMPERATURES = (130, 145, 160, 175, 190)

#: NREL: the isotherms whose neighbours overlap (every step fixed by a model-free overlay).
NREL_FROM = 39.0
NREL_REFERENCE = 62.47
#: The file's steps exceed the model-free G′ overlay by up to 9.9 %; this much is allowed.
NREL_FRACTION = 0.12
#: Half the 0.06-decade grid of the file's values.
NREL_GRID = 0.03
#: Polystyrene with free vertical shifts: the overlays' spread on the simple pairs (0.035) and
#: bayesfo's sd (≤ 0.016).
PS_TOL_FREE = 0.05
#: A vertical factor beyond 10^0.1 = 1.26 is suspect (the guide): bayesfo's and pyRheo's b_T
#: must agree within that.
PS_TOL_VERTICAL = 0.1


def quiet(fn, *args, **kwargs):
    """bayesfo warns about misfits and not-simple materials; they are known here."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fn(*args, **kwargs)


# --------------------------------------------------------------------------------------------
# 1. NREL Eplexor isotherms against the file's shift factors
# --------------------------------------------------------------------------------------------

def _git_show(path: str, target: Path) -> Path:
    if not PYVISCO.is_dir() or shutil.which("git") is None:
        pytest.skip(f"pyvisco's git mirror {PYVISCO} (github:NREL/pyvisco) is not available")
    done = subprocess.run(["git", f"--git-dir={PYVISCO}", "show", f"{PYVISCO_COMMIT}:{path}"],
                          capture_output=True, check=False)
    if done.returncode != 0:
        pytest.skip(f"{path} at {PYVISCO_COMMIT[:7]} is not in {PYVISCO}: "
                    f"{done.stderr.decode(errors='replace').strip()}")
    target.write_bytes(done.stdout)
    return target


def _eplexor_isotherms(xls: Path) -> tuple[list, str]:
    """The isotherms of the Eplexor workbook, and how they were read: by ``read_isotherms``
    itself (xlrd), its "Data header" sheet of test settings left out with a DataWarning."""
    return quiet(read_isotherms, xls), "read_isotherms(.xls)"


@pytest.fixture(scope="module")
def nrel(tmp_path_factory):
    pytest.importorskip("xlrd", reason="the Eplexor .xls needs xlrd (pip install 'bayesfo[excel]')")
    tmp = tmp_path_factory.mktemp("pyvisco")
    xls = _git_show(EPLEXOR, tmp / "freq_Eplexor_raw.xls")
    shifts = _git_show(EPLEXOR_SHIFTS, tmp / "shift_factors.csv")
    table = np.loadtxt(shifts, delimiter=",", skiprows=2, encoding="utf-8-sig")
    isotherms, how = _eplexor_isotherms(xls)
    return {"isotherms": isotherms, "how": how, "file": {float(t): a for t, a in table}}


def _file_shift(file: dict, temperature: float) -> float:
    """The file's log10 a_T at the isotherm's temperature (the file rounds the set's mean)."""
    t = min(file, key=lambda x: abs(x - temperature))
    assert abs(t - temperature) <= 1.0, (temperature, t)
    return file[t]


def test_the_eplexor_file_and_its_shift_factors(nrel):
    iso = nrel["isotherms"]
    assert len(iso) == 21 and all(len(i.data.omega) == 10 for i in iso), nrel["how"]
    temps = sorted(i.temperature for i in iso)
    assert temps[0] == pytest.approx(-49.9, abs=0.1) and temps[-1] == pytest.approx(100, abs=0.1)
    file = nrel["file"]
    assert len(file) == 21 and file[-5.0] == 0.0
    assert file[100.0] == -19.02 and file[-50.0] == 11.1  # 30.1 decades: beyond ±15 from any T
    # every value on a 0.06-decade grid
    assert all(abs(a / 0.06 - round(a / 0.06)) < 1e-6 for a in file.values())


def test_file_steps_against_a_model_free_overlay(nrel):
    """Where every neighbour overlaps (≥ 40 °C), the file's step exceeds the G′ overlay's by
    2–10 %: the scale of NREL_FRACTION."""
    iso = sorted((i for i in nrel["isotherms"] if i.temperature >= NREL_FROM),
                 key=lambda i: i.temperature)
    temps = [i.temperature for i in iso]
    parts = shifts_by_part([i.data for i in iso], temps)
    excess = []
    for pair in parts["pairs"]:
        lo, hi = pair["temperatures"]
        step = _file_shift(nrel["file"], hi) - _file_shift(nrel["file"], lo)
        assert pair["storage"] is not None, pair
        excess.append(step / pair["storage"]["log_shift"] - 1)
    print("file step / G' overlay step - 1:", np.round(excess, 3))
    assert 0 < min(excess) and max(excess) <= NREL_FRACTION


def _nrel_within(shift_factors, file, *, scale=1.0, moved=None):
    """Per temperature: (T, bayesfo mean, file re-referenced, difference, tolerance)."""
    ref = _file_shift(file, NREL_REFERENCE)
    rows = []
    for sf in shift_factors:
        t, a = sf["temperature"], sf["log10_aT"]
        expected = scale * (_file_shift(file, t) - ref)
        if moved is not None and abs(t - moved[0]) < 0.5:
            expected += moved[1]
        tol = NREL_FRACTION * abs(expected) + 3 * a["sd"] + NREL_GRID
        rows.append((t, a["mean"], expected, a["mean"] - expected, tol))
    return rows


@pytest.fixture(scope="module", params=["spectrum", "max-n2m1"])
def nrel_master(request, nrel):
    iso = [i for i in nrel["isotherms"] if i.temperature >= NREL_FROM]
    ref = min((i.temperature for i in iso), key=lambda t: abs(t - NREL_REFERENCE))
    # The joint route (shifts sampled with each structure) against the references; the
    # model-free master's shifts are measured by benchmarks/bench_mastercurve_real.py.
    return quiet(bf.mastercurve, iso, request.param, reference_temperature=ref, law="free",
                 seed=0, shifts="joint", noise="proportional", vertical="none")


def test_nrel_shifts_against_the_file(nrel_master, nrel):
    mc = nrel_master
    assert mc.posterior.converged
    assert mc.reference_temperature == pytest.approx(NREL_REFERENCE)
    rows = _nrel_within(mc.shift_factors(), nrel["file"])
    for t, mean, expected, diff, tol in rows:
        print(f"{mc.structure} {t:7.2f} °C: bayesfo {mean:+.3f}, file {expected:+.3f}, "
              f"diff {diff:+.3f}, tolerance {tol:.3f}")
    assert all(abs(d) <= tol for *_, d, tol in rows)
    # told apart: a temperature dependence 25 % steeper or 30 % flatter, one temperature moved
    # by half a decade either way (not 20 % flatter: bayesfo's steps are 5-12 % below the
    # file's, 2-4 % below the G' overlay's)
    for wrong in ({"scale": 1.25}, {"scale": 0.7}, {"moved": (69.98, 0.5)},
                  {"moved": (69.98, -0.5)}):
        bad = _nrel_within(mc.shift_factors(), nrel["file"], **wrong)
        assert any(abs(d) > tol for *_, d, tol in bad), wrong


# --------------------------------------------------------------------------------------------
# 2. pyRheo's polystyrene master curve
# --------------------------------------------------------------------------------------------

def _ps_path(name: str) -> Path:
    path = PS / name
    if not path.exists():
        pytest.skip(f"{path} is not available (pyRheo's polystyrene data, GPL, read in place)")
    return path


@pytest.fixture(scope="module")
def ps():
    raw = {t: np.loadtxt(_ps_path(f"oscillation_ps{t}_data.csv"), delimiter="\t", skiprows=1)
           for t in PS_TEMPERATURES}
    master = np.loadtxt(_ps_path("master_curve_ps_oscillation_data.csv"), delimiter=",",
                        skiprows=1)
    # each raw point in the master file: tan δ is unchanged by both shifts
    tan_master = master[:, 2] / master[:, 1]
    owner = np.full(len(master), -1)
    log_a, log_b = {}, {}
    for k, t in enumerate(PS_TEMPERATURES):
        r = raw[t]
        at = [int(np.argmin(np.abs(np.log(tan_master / x)))) for x in r[:, 2] / r[:, 1]]
        assert np.allclose(tan_master[at], r[:, 2] / r[:, 1], rtol=1e-12, atol=0)
        assert np.all(owner[at] == -1)
        owner[at] = k
        a = np.log10(master[at, 0] / r[:, 0])
        b = np.log10(master[at, 1] / r[:, 1])
        assert np.ptp(a) < 1e-12 and np.ptp(b) < 1e-12  # one (a_T, b_T) per isotherm
        log_a[t], log_b[t] = float(a.mean()), float(b.mean())
    assert np.all(owner >= 0)
    isotherms = [(quiet(bf.read, _ps_path(f"oscillation_ps{t}_data.csv")), float(t))
                 for t in PS_TEMPERATURES]
    return {"raw": raw, "master": master, "owner": owner, "log_a": log_a, "log_b": log_b,
            "isotherms": isotherms}


def test_pyrheo_shifts_recovered_from_its_master_file(ps):
    assert [round(ps["log_a"][t], 3) for t in PS_TEMPERATURES] == [2.422, 1.022, 0.0, -0.77,
                                                                   -1.356]
    assert max(abs(v) for v in ps["log_b"].values()) < 0.01


def _log_interp(x, xs, ys):
    order = np.argsort(xs)
    return 10 ** np.interp(np.log10(x), np.log10(xs[order]), np.log10(ys[order]))


def _pyrheo_scatter(ps) -> float:
    """pyRheo's own superposition scatter: median |relative difference| of each isotherm's
    master points (G′ and G″) from the other isotherms' points interpolated in log–log."""
    m, owner, rel = ps["master"], ps["owner"], []
    for k in range(len(PS_TEMPERATURES)):
        mine, others = m[owner == k], m[owner != k]
        inside = (mine[:, 0] >= others[:, 0].min()) & (mine[:, 0] <= others[:, 0].max())
        for c in (1, 2):
            ref = _log_interp(mine[inside, 0], others[:, 0], others[:, c])
            rel.append(mine[inside, c] / ref - 1)
    return float(np.median(np.abs(np.concatenate(rel))))


def _master_difference(mc, ps) -> tuple[float, float]:
    """Median |relative difference| of G′ and G″ between bayesfo's reduced points and pyRheo's
    master interpolated there (log–log), over pyRheo's reduced window."""
    data, m = mc.master_data(), ps["master"]
    inside = (data.omega >= m[:, 0].min()) & (data.omega <= m[:, 0].max())
    out = []
    for c, part in ((1, data.response.real), (2, data.response.imag)):
        ref = _log_interp(data.omega[inside], m[:, 0], m[:, c])
        out.append(float(np.median(np.abs(part[inside] / ref - 1))))
    return out[0], out[1]


def _ps_spread(ps) -> float:
    """The largest spread of the G′, G″ and tan δ overlays of a neighbouring pair."""
    parts = shifts_by_part([d for d, _ in ps["isotherms"]], list(PS_TEMPERATURES))
    return max(p["spread"] for p in parts["pairs"] if "spread" in p)


PS_CASES = [("spectrum", "free"), ("spectrum", "none"), ("fractional_zener_sl", "none")]


@pytest.fixture(scope="module", params=PS_CASES, ids=[f"{s}-{v}" for s, v in PS_CASES])
def ps_master(request, ps):
    structure, vertical = request.param
    return quiet(bf.mastercurve, ps["isotherms"], structure, reference_temperature=160.0,
                 law="free", vertical=vertical, seed=0, shifts="joint", noise="proportional")


def _ps_rows(mc, log_a, tol_of):
    rows = []
    for sf in mc.shift_factors():
        t, a = sf["temperature"], sf["log10_aT"]
        expected = log_a[int(round(t))]
        rows.append((t, a["mean"], expected, a["mean"] - expected, tol_of(a["sd"]),
                     sf["log10_bT"]["mean"]))
    return rows


def test_polystyrene_against_pyrheo(ps_master, ps):
    mc = ps_master
    assert mc.posterior.converged
    if mc.vertical == "free":
        def tol_of(sd):
            return PS_TOL_FREE
    else:
        spread = _ps_spread(ps)
        assert spread < 0.15

        def tol_of(sd):
            return spread + 3 * sd
    rows = _ps_rows(mc, ps["log_a"], tol_of)
    for t, mean, expected, diff, tol, b in rows:
        print(f"{mc.structure}/{mc.vertical} {t:5.0f} °C: log10 a_T {mean:+.3f} against pyRheo "
              f"{expected:+.3f}: {diff:+.3f} (tolerance {tol:.3f}); log10 b_T {b:+.3f} against "
              f"{ps['log_b'][int(round(t))]:+.4f}")
    assert all(abs(d) <= tol for _, _, _, d, tol, _ in rows)
    if mc.vertical == "free":
        assert all(abs(b - ps["log_b"][int(round(t))]) <= PS_TOL_VERTICAL
                   for t, *_, b in rows)
    # told apart: one temperature moved either way by 0.1 decade (free vertical shifts) or 0.5
    # (none: the tolerance holds the vertical factor), or a law steeper or flatter by 15 % / 25 %
    step, scale = (0.1, 1.15) if mc.vertical == "free" else (0.5, 1.25)
    for wrong in ({130: step}, {130: -step}, {190: step}, {190: -step}, scale, 1 / scale):
        moved = ({t: a * wrong for t, a in ps["log_a"].items()} if isinstance(wrong, float)
                 else {t: a + wrong.get(t, 0.0) for t, a in ps["log_a"].items()})
        bad = _ps_rows(mc, moved, tol_of)
        assert any(abs(d) > tol for _, _, _, d, tol, _ in bad), wrong
    # the reduced master curves
    scatter = _pyrheo_scatter(ps)
    storage, loss = _master_difference(mc, ps)
    print(f"{mc.structure}/{mc.vertical}: median |rel. diff| to pyRheo's master G' {storage:.3f}, "
          f"G'' {loss:.3f}; pyRheo's own scatter {scatter:.3f}")
    assert max(storage, loss) <= scatter
