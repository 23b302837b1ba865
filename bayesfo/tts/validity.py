"""Does time–temperature superposition hold? The van Gurp–Palmen test of the isotherms.

A thermorheologically simple material has one master curve: every isotherm is the same function
of reduced frequency, so the loss angle δ is one function of |G*| whatever the shift factors
(van Gurp and Palmen 1998). Plotted as δ against |G*|, the isotherms of a simple material fall on
one curve; where two relaxation processes shift with temperature by different laws, the curves of
neighbouring isotherms part. The test needs no model and no shift: for each pair of neighbouring
isotherms, δ of each is interpolated (linearly in log |G*|) at the other's points where their
|G*| ranges overlap, and the mean difference is compared with

* its standard error, from the scatter of each isotherm's δ about a smooth curve (second
  differences along frequency: noise of sd s gives second differences of sd s√6; curvature only
  adds to it, so the error is if anything too large and the test lenient), and
* :data:`TOLERANCE_DEG`: a vertical (density) shift moves an isotherm along |G*| by a few
  hundredths of a decade, which changes δ at a given |G*| by a fraction of a degree; the phase
  accuracy of rheometers and DMA instruments is of the same order.

A pair fails when its mean difference exceeds both three standard errors and the tolerance;
superposition is judged valid when no tested pair fails. Pairs whose |G*| ranges do not overlap
(or overlap in fewer than :data:`MIN_OVERLAP` points of either) are not tested, and the result
says so: with no pair tested the test has no verdict (``None``).

References
----------
M. van Gurp and J. Palmen (1998), Rheol. Bull. 67, 5–8; J. Dealy and D. Plazek (2009),
Rheol. Bull. 78, 16–31 (time–temperature superposition, a users' guide).
"""

from __future__ import annotations

import math

import numpy as np

from .isotherms import overlay_cost, overlay_shift

#: Difference of the loss angle at equal |G*| [deg] that a pair of isotherms may show before
#: superposition is judged to fail (with three standard errors; see the module).
TOLERANCE_DEG = 1.5
#: Points of each isotherm inside the common |G*| range for a pair to be tested.
MIN_OVERLAP = 2
#: Standard errors a pair's mean difference must exceed to fail.
Z_FAIL = 3.0


def loss_angle_deg(response: np.ndarray, kind: str) -> np.ndarray:
    """The loss angle δ [deg] of complex responses: arg G* for a modulus, −arg J* for a
    compliance (J* = J′ − iJ″)."""
    angle = np.degrees(np.angle(response))
    return angle if kind == "modulus" else -angle


def _curve(data, log_vertical: float = 0.0) -> tuple[np.ndarray, np.ndarray, float]:
    """log10 |G*| (reduced by the isotherm's vertical shift log10 b_T: a modulus times b_T,
    a compliance divided by it) and δ [deg] of an isotherm sorted by |G*|, and the sd of its
    δ from the second differences along frequency."""
    order = np.argsort(data.omega)
    g = data.response[order]
    x, d = np.log10(np.abs(g)), loss_angle_deg(g, data.kind)
    x = x + (log_vertical if data.kind == "modulus" else -log_vertical)
    sd = float(np.std(np.diff(d, 2)) / math.sqrt(6.0)) if d.size >= 4 else math.nan
    by_x = np.argsort(x)
    return x[by_x], d[by_x], sd


def van_gurp_palmen(isotherms, temperatures, *, tolerance_deg: float = TOLERANCE_DEG,
                    log_vertical=None) -> dict:
    """The van Gurp–Palmen test of neighbouring isotherms (see the module).

    Parameters
    ----------
    isotherms : sequence of FrequencyResponse
        Modulus or compliance data, in the order of ``temperatures``.
    temperatures : sequence of float
        [°C], ascending.
    tolerance_deg : float
    log_vertical : sequence of float, optional
        log10 b_T of each isotherm (the master curve's vertical shifts): |G*| is compared on
        the reference's scale, δ unchanged (a vertical shift scales G′ and G″ alike). Without
        it the isotherms are compared as measured.

    Returns
    -------
    dict
        ``valid`` (True, False, or None where no pair could be tested), ``tolerance_deg``,
        ``pairs``: per neighbouring pair ``temperatures``, ``tested``, and where tested
        ``n_overlap`` (points compared), ``delta_deg`` (mean δ of the warmer minus the colder
        isotherm at equal |G*|), ``se_deg``, ``passes``; ``failing``: the temperature pairs
        that fail; ``untested``: those without overlap.
    """
    shifts = np.zeros(len(isotherms)) if log_vertical is None else np.asarray(log_vertical)
    curves = [_curve(d, float(b)) for d, b in zip(isotherms, shifts, strict=True)]
    pairs = []
    for i in range(len(curves) - 1):
        (xa, da, sa), (xb, db, sb) = curves[i], curves[i + 1]
        lo, hi = max(xa.min(), xb.min()), min(xa.max(), xb.max())
        in_a = (xa >= lo) & (xa <= hi)
        in_b = (xb >= lo) & (xb <= hi)
        pair = {"temperatures": [float(temperatures[i]), float(temperatures[i + 1])],
                "tested": bool(hi > lo and in_a.sum() >= MIN_OVERLAP
                               and in_b.sum() >= MIN_OVERLAP)}
        if pair["tested"]:
            # The warmer minus the colder isotherm, both ways round, at each one's own points.
            diff = np.r_[db[in_b] - np.interp(xb[in_b], xa, da),
                         np.interp(xa[in_a], xb, db) - da[in_a]]
            n_a, n_b = int(in_a.sum()), int(in_b.sum())
            # Each difference carries one point's noise of each curve (interpolation between
            # two neighbours only lowers the other's): the mean's error from both sds.
            se = math.sqrt((sa**2 + sb**2) / min(n_a, n_b)) if math.isfinite(sa + sb) else 0.0
            delta = float(diff.mean())
            pair.update(n_overlap=n_a + n_b, delta_deg=delta, se_deg=se,
                        passes=bool(abs(delta) <= max(tolerance_deg, Z_FAIL * se)))
        pairs.append(pair)
    tested = [p for p in pairs if p["tested"]]
    failing = [p["temperatures"] for p in tested if not p["passes"]]
    return {"valid": None if not tested else not failing, "tolerance_deg": tolerance_deg,
            "pairs": pairs, "failing": failing,
            "untested": [p["temperatures"] for p in pairs if not p["tested"]]}


def describe(check: dict) -> str:
    """The test's result in words, for the terminal and the notes."""
    if check["valid"] is None:
        return ("the van Gurp–Palmen test could not be made: no two neighbouring isotherms "
                "overlap in |G*|")
    n = sum(p["tested"] for p in check["pairs"])
    if check["valid"]:
        text = (f"superposition holds by the van Gurp–Palmen test: the loss angles of all {n} "
                f"tested pairs of neighbouring isotherms agree at equal |G*| (within "
                f"{check['tolerance_deg']:g}° or three standard errors)")
    else:
        worst = max((p for p in check["pairs"] if p["tested"] and not p["passes"]),
                    key=lambda p: abs(p["delta_deg"]))
        where = "; ".join(f"{a:g}/{b:g} °C" for a, b in check["failing"])
        text = (f"superposition fails the van Gurp–Palmen test: the loss angles of neighbouring "
                f"isotherms part at equal |G*| ({where}; up to {worst['delta_deg']:+.1f}° ± "
                f"{worst['se_deg']:.1f}°), so the material is not thermorheologically simple "
                "there and shifted data mix processes that shift differently")
    if check["untested"]:
        text += (f"; {len(check['untested'])} pair(s) without overlap in |G*| were not tested")
    return text


#: Disagreement [decades] between the horizontal shifts that G′, G″ and tan δ give a pair of
#: isotherms, beyond which (and beyond three standard errors) they are judged to differ.
PARTS_TOLERANCE = 0.1
#: A part whose log changes by less than this per decade of ω over the overlap is too flat to
#: give a shift (a plateau of G′, a flat tan δ): that part is left out for the pair.
MIN_SLOPE = 0.05
#: The parts compared, by name.
PARTS = ("storage", "loss", "tan_delta")


def _part(data, name: str) -> tuple[np.ndarray, np.ndarray]:
    order = np.argsort(data.omega)
    g = data.response[order]
    if data.kind == "compliance":
        g = np.conj(g)  # J* = J′ − iJ″: the loss part positive, as for a modulus
    with np.errstate(divide="ignore", invalid="ignore"):
        y = {"storage": np.log10(g.real), "loss": np.log10(g.imag),
             "tan_delta": np.log10(g.imag / g.real)}[name]
    return np.log10(data.omega[order]), y


def _shift_of(xl, yl, xu, yu) -> dict | None:
    """The shift d (decades) that lays (xu + d, yu) on (xl, yl), by a grid search and a local
    refinement, with its standard error from the residual scatter and the mean slope; None
    where the curves do not overlap or the part is too flat there."""
    ok_l, ok_u = np.isfinite(yl), np.isfinite(yu)
    xl, yl, xu, yu = xl[ok_l], yl[ok_l], xu[ok_u], yu[ok_u]
    if xl.size < 3 or xu.size < 3:
        return None
    # No value in common: no horizontal shift lays one curve on the other (the overlay's
    # search would end at its window's edge, where the curves come closest, and "agree").
    if max(yl.min(), yu.min()) >= min(yl.max(), yu.max()):
        return None
    d = overlay_shift(xl, (yl,), xu, (yu,), min_inside=3, refine=True)
    if d is None:
        return None
    _, inside = overlay_cost(xl, (yl,), xu, (yu,), d, 3)
    x = xu[inside] + d
    slope = float(np.mean(np.gradient(np.interp(x, xl, yl), x))) if x.size > 1 else 0.0
    if abs(slope) < MIN_SLOPE:
        return None
    r = np.interp(x, xl, yl) - yu[inside]
    se = float(np.std(r, ddof=1) / abs(slope) / math.sqrt(inside.sum()))
    return {"log_shift": d, "se": se, "n_overlap": int(inside.sum())}


def shifts_by_part(isotherms, temperatures, *, tolerance: float = PARTS_TOLERANCE) -> dict:
    """The horizontal shift between neighbouring isotherms from G′, from G″ and from tan δ
    alone, compared.

    For a thermorheologically simple material without vertical shift the three agree; tan δ
    is free of any vertical shift (a density or temperature factor scales G′ and G″ alike), so
    G′ and G″ shifts that agree with each other but not with tan δ's point to a vertical
    shift, and parts that disagree among themselves to a material that is not simple.

    Returns
    -------
    dict
        ``consistent`` (True, False, or None where no pair had two parts to compare),
        ``tolerance`` [decades], ``pairs``: per neighbouring pair ``temperatures``, per part
        (``storage``, ``loss``, ``tan_delta``) ``{"log_shift", "se"}`` or None (no overlap,
        or too flat there), ``spread`` (largest difference between the parts' shifts) and
        ``agree``; ``disagreeing``: the temperature pairs whose parts differ.
    """
    pairs = []
    for i in range(len(isotherms) - 1):
        lower, upper = isotherms[i], isotherms[i + 1]
        parts = {}
        for name in PARTS:
            xl, yl = _part(lower, name)
            xu, yu = _part(upper, name)
            found = _shift_of(xl, yl, xu, yu)
            parts[name] = None if found is None else {"log_shift": found["log_shift"],
                                                      "se": found["se"]}
        have = [p for p in parts.values() if p is not None]
        pair = {"temperatures": [float(temperatures[i]), float(temperatures[i + 1])],
                **parts}
        if len(have) >= 2:
            worst, agree = 0.0, True
            for a in range(len(have)):
                for b in range(a + 1, len(have)):
                    diff = abs(have[a]["log_shift"] - have[b]["log_shift"])
                    worst = max(worst, diff)
                    limit = max(tolerance, Z_FAIL * math.hypot(have[a]["se"], have[b]["se"]))
                    agree &= diff <= limit
            pair.update(spread=worst, agree=bool(agree))
        pairs.append(pair)
    compared = [p for p in pairs if "agree" in p]
    return {"consistent": None if not compared else all(p["agree"] for p in compared),
            "tolerance": tolerance, "pairs": pairs,
            "disagreeing": [p["temperatures"] for p in compared if not p["agree"]]}


def describe_parts(check: dict) -> str:
    """The comparison of the parts' shifts in words."""
    if check["consistent"] is None:
        return "the shifts of G′, G″ and tan δ could not be compared (no pair with two parts)"
    n = sum("agree" in p for p in check["pairs"])
    if check["consistent"]:
        return (f"the horizontal shifts that G′, G″ and tan δ give each of {n} pairs of "
                f"neighbouring isotherms agree (within {check['tolerance']:g} decade or three "
                "standard errors)")
    worst = max((p for p in check["pairs"] if "agree" in p and not p["agree"]),
                key=lambda p: p["spread"])
    shown = ", ".join(f"{name.replace('_', ' ')} {worst[name]['log_shift']:+.2f}"
                      for name in PARTS if worst[name] is not None)
    where = "; ".join(f"{a:g}/{b:g} °C" for a, b in check["disagreeing"])
    low, high = worst["temperatures"]
    return (f"the horizontal shifts that G′, G″ and tan δ give disagree for {where} (the "
            f"{high:g} °C isotherm laid onto the {low:g} °C one by {shown} decades of ω, "
            f"log10 a_T({high:g} °C) − log10 a_T({low:g} °C)): a vertical shift (tan δ is free "
            "of it) or a material that is not thermorheologically simple")


def joint_against_parts(parts: dict, shift_draws, tolerance: float = PARTS_TOLERANCE) -> dict:
    """The joint fit's shift between each pair of neighbouring isotherms against the shift
    that the isotherms themselves give (:func:`shifts_by_part`: the overlay of G′, G″ and
    tan δ, without a model), where the parts agree. A master function that misses the
    isotherms moves the shifts to where it misfits least, which the overlay does not.

    ``shift_draws``: the joint posterior's log10 a_T (draws, isotherms), the isotherms in the
    order of ``parts``. Returns ``pairs`` (per pair compared: ``temperatures``, the joint
    difference log10 a_T(upper) − log10 a_T(lower) as ``joint`` mean and ``joint_sd``, the
    overlay's inverse-variance mean ``overlay`` and ``overlay_se``, and ``apart``: the two
    differ by more than ``tolerance`` decades and three standard errors) and ``apart``, the
    pairs' temperatures where they differ."""
    draws = np.asarray(shift_draws, float)
    out = []
    for i, pair in enumerate(parts["pairs"]):
        have = [pair[name] for name in PARTS if pair.get(name) is not None]
        if not have or pair.get("agree") is False or i + 1 >= draws.shape[1]:
            continue
        w = np.array([1.0 / max(p["se"], 1e-6) ** 2 for p in have])
        overlay = float(np.sum(w * [p["log_shift"] for p in have]) / w.sum())
        overlay_se = float(1.0 / math.sqrt(w.sum()))
        diff = draws[:, i + 1] - draws[:, i]
        joint, sd = float(np.mean(diff)), float(np.std(diff))
        apart = abs(joint - overlay) > max(tolerance, Z_FAIL * math.hypot(sd, overlay_se))
        out.append({"temperatures": pair["temperatures"], "joint": joint, "joint_sd": sd,
                    "overlay": overlay, "overlay_se": overlay_se, "apart": bool(apart)})
    return {"pairs": out, "apart": [p["temperatures"] for p in out if p["apart"]]}


def describe_joint_against_parts(check: dict, structure: str, law: str = "free") -> str:
    """The pairs whose joint shift differs from the overlay, in words (``law``: the shift law
    the joint shifts follow, or ``"free"``); empty where none."""
    apart = [p for p in check["pairs"] if p["apart"]]
    if not apart:
        return ""
    shown = "; ".join(f"{low:g}/{high:g} °C: {p['joint']:+.3f} ± {p['joint_sd']:.3f} against "
                      f"{p['overlay']:+.3f} ± {p['overlay_se']:.3f}"
                      for p in apart for low, high in [p["temperatures"]])
    return (f"the joint fit's shifts between neighbouring isotherms differ from those the "
            f"isotherms' own overlay gives (log10 a_T(upper) − log10 a_T(lower), joint against "
            f"overlay: {shown}): "
            + (f"{structure}'s misfit moves the shifts; a master function that describes the "
               "isotherms gives shifts nearer the overlay's" if law == "free" else
               f"the {'WLF' if law == 'wlf' else 'Arrhenius'} law that the shifts follow, or "
               f"{structure}'s misfit, moves them there"))
