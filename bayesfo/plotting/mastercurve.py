"""Figures of a master curve: the isotherms on the reduced frequency axis with the master
structure's band, and the shift factors against temperature with the fitted laws."""

from __future__ import annotations

import numpy as np

from ..data.symbols import parts as parts_of
from ..data.symbols import response_symbol
from ..predictions import evaluate
from ..structures import get_structure
from ..structures.physical import in_brackets
from ..tts import arrhenius, wlf
from ..tts.joint import ISOTHERM_MISFIT
from ..tts.validity import loss_angle_deg
from ._base import Drawn, axes_or_new, new_figure
from .style import COLUMN_WIDTH, style, temperature_colormap


def plot_mastercurve(mc, *, fig=None, n_grid: int = 200) -> Drawn:
    """G′ and G″ (or J′ and J″) of every isotherm against a_T·ω at the posterior mean shifts,
    coloured by temperature, with the master structure's posterior median and 94 % band; and
    log10 a_T against temperature (posterior mean and 94 % HDI) with the WLF and Arrhenius
    laws at their posterior means.

    Returns
    -------
    Drawn
        Axes: (storage, loss, shifts). Values: ``"omega_reduced"``, ``"storage_median"``,
        ``"loss_median"`` (the master's median on a grid), ``"temperature"``,
        ``"log10_aT_mean"``, ``"log10_aT_low"``, ``"log10_aT_high"``.
    """
    import matplotlib as mpl


    fig = new_figure(fig, (11.0, 3.8))
    axes = fig.subplots(1, 3)
    _apart(fig)
    modulus = mc.data.kind == "modulus"
    parts = ("storage", "loss") if modulus else ("storage_compliance", "loss_compliance")
    symbols = parts_of(mc.data.symbol, mc.data.kind)
    letter = response_symbol(mc.data.symbol, mc.data.kind)
    unit = mc.data.units or f"[{letter}]"
    temps = np.asarray(mc.temperatures)
    cmap = temperature_colormap()
    norm = mpl.colors.Normalize(temps.min(), temps.max())
    shifts = mc.log_shift_mean
    vertical = (np.zeros(len(temps)) if getattr(mc, "vertical_draws", None) is None
                else mc.vertical_draws.mean(axis=0))
    lo_w, hi_w = np.inf, 0.0
    artists = {}
    for i, (d, t) in enumerate(zip(mc.isotherms, temps, strict=True)):
        w = d.omega * 10.0 ** shifts[i]
        lo_w, hi_w = min(lo_w, w.min()), max(hi_w, w.max())
        # b_T G(ω) (a compliance divided by b_T) lies on the master curve.
        y = d.response * 10.0 ** (vertical[i] if modulus else -vertical[i])
        loss = y.imag if modulus else -y.imag
        for ax, name, part in zip(axes[:2], ("storage", "loss"), (y.real, loss),
                                  strict=True):
            artists[f"{t:g}/{name}"] = ax.loglog(w, np.abs(part), "o", ms=3,
                                                 color=cmap(norm(t)), alpha=0.8)[0]
    grid = np.logspace(np.log10(lo_w), np.log10(hi_w), n_grid)
    structure = mc.master if mc.master is not None else get_structure(mc.structure)
    rng = np.random.default_rng(0)
    rows = rng.choice(mc.master_draws.shape[0], size=min(500, mc.master_draws.shape[0]),
                      replace=False)
    values = {"omega_reduced": grid}
    for ax, q, sym in zip(axes[:2], parts, symbols, strict=True):
        v = evaluate(structure, mc.master_draws[rows], q, grid)
        med = np.median(v, axis=0)
        lo, hi = np.percentile(v, [3, 97], axis=0)
        ax.fill_between(grid, lo, hi, color="0.3", alpha=0.25, lw=0)
        ax.loglog(grid, med, "k-", lw=1.2, label=f"{mc.structure} (median, 94 %)")
        ax.set_xlabel(f"a_T ω [rad/s] (T_ref = {mc.reference_temperature:g} °C)")
        ax.set_ylabel(f"{'b_T ' if vertical.any() and modulus else ''}{sym}"
                      f"{' / b_T' if vertical.any() and not modulus else ''}{in_brackets(unit)}")
        values[f"{q.split('_')[0]}_median"] = med
    axes[0].legend(loc="best", fontsize=8)
    fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cmap), ax=axes[1], label="T [°C]")
    factors = mc.shift_factors()
    mean = np.array([f["log10_aT"]["mean"] for f in factors])
    low = np.array([f["log10_aT"]["hdi_low"] for f in factors])
    high = np.array([f["log10_aT"]["hdi_high"] for f in factors])
    ax = axes[2]
    shifts = {"free": "", "wlf": ", WLF sampled", "arrhenius": ", Arrhenius sampled"}[mc.law]
    if mc.law == "free" and mc.shifts_from == "smooth":
        shifts = ", each isotherm's own"
    elif mc.law == "free" and mc.law_evidence:
        shifts = f"; free shifts P {mc.law_evidence['free']['probability']:.2f}"
    ax.errorbar(temps, mean, yerr=[mean - low, high - mean], fmt="o", color="k", ms=3,
                capsize=2, label=f"posterior (94 % HDI{shifts})")
    tt = np.linspace(temps.min(), temps.max(), 200)
    laws = mc.laws
    c1, c2 = (laws["wlf"]["parameters"][k]["mean"] for k in ("C1", "C2"))
    ea = laws["arrhenius"]["parameters"]["Ea"]["mean"]
    t_ref = mc.reference_temperature
    # The laws' probabilities: from ln Z where the laws were fitted inside the posterior
    # (law="auto", against free shifts too), else from BIC on the shifts.
    p = ({k: v["probability"] for k, v in mc.law_evidence.items()} if mc.law_evidence
         else {k: v["probability"] for k, v in laws.items()})
    # A law with as many constants as free shifts passes through them: they cannot test it.
    untested = {k: ", untested" if laws[k].get("dof", 1) <= 0 else "" for k in laws}
    ax.plot(tt, wlf(tt, t_ref, c1, c2), "-", color="#0072B2",
            label=f"WLF C1 {c1:.3g}, C2 {c2:.3g} °C (P {p['wlf']:.2f}{untested['wlf']})")
    ax.plot(tt, arrhenius(tt, t_ref, ea), "--", color="#D55E00",
            label=f"Arrhenius Ea {ea / 1e3:.3g} kJ/mol (P {p['arrhenius']:.2f}"
                  f"{untested['arrhenius']})")
    ax.set_xlabel("T [°C]")
    ax.set_ylabel("log10 a_T")
    ax.legend(loc="best", fontsize=7)
    values.update(temperature=temps, log10_aT_mean=mean, log10_aT_low=low, log10_aT_high=high)
    return Drawn.build(fig, axes, values, artists)


def plot_van_gurp_palmen(mc, *, ax=None) -> Drawn:
    """The van Gurp–Palmen plot: the loss angle δ against |G*| (or |J*|) of every isotherm,
    coloured by temperature, without any shift (:mod:`bayesfo.tts.validity`). The isotherms of
    a thermorheologically simple material fall on one curve; the pairs that the test finds
    parting are named in the title.

    Returns
    -------
    Drawn
        Axes: (ax,). Values: per isotherm ``"<T>/magnitude"`` and ``"<T>/delta_deg"`` (sorted
        by frequency). Artists: ``"<T>"`` (``Line2D``), ``"title"``.
    """
    import matplotlib as mpl


    with style():
        fig, ax = axes_or_new(ax, (COLUMN_WIDTH + 0.6, 3.2))
        temps = np.asarray(mc.temperatures)
        cmap = temperature_colormap()
        norm = mpl.colors.Normalize(temps.min(), temps.max())
        values, artists = {}, {}
        for d, t in zip(mc.isotherms, temps, strict=True):
            order = np.argsort(d.omega)
            g = d.response[order]
            mag, delta = np.abs(g), loss_angle_deg(g, d.kind)
            values[f"{t:g}/magnitude"], values[f"{t:g}/delta_deg"] = mag, delta
            (artists[f"{t:g}"],) = ax.plot(mag, delta, "o-", ms=2.5, lw=0.7,
                                           color=cmap(norm(t)))
        ax.set_xscale("log")
        sym = response_symbol(mc.data.symbol, mc.data.kind)
        unit = f" [{mc.data.units}]" if mc.data.units else ""
        ax.set_xlabel(f"|{sym}*|{unit}")
        ax.set_ylabel("loss angle δ [deg]")
        fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, label="T [°C]")
        check = mc.tts_checks.get("van_gurp_palmen") or {}
        if check.get("valid") is False:
            title = ("parting: " + ", ".join(f"{a:g}/{b:g} °C" for a, b in check["failing"]))
        elif check.get("valid"):
            title = "one curve: superposition holds"
        else:
            title = "no overlap in |G*|: not tested"
        artists["title"] = ax.set_title(title, fontsize=8)
    return Drawn.build(fig, (ax,), values, artists)


def plot_isotherm_residuals(mc, *, fig=None, n_draws: int = 200, seed: int = 0) -> Drawn:
    """How well the joint fit describes each isotherm: the relative residuals of the storage
    and loss parts, (data − model)/|model| in per cent, against a_T·ω (each draw's own
    shifts; the model is the median over draws at each point), coloured by temperature; and
    each isotherm's rms relative residual against temperature (``tts_checks["isotherm_fit"]``)
    with the level above which an isotherm is named as missed
    (:data:`~bayesfo.tts.joint.ISOTHERM_MISFIT` times the median isotherm's).

    Returns
    -------
    Drawn
        Axes: (storage, loss, rms). Values: per isotherm ``"<T>/omega_reduced"``,
        ``"<T>/storage_pct"``, ``"<T>/loss_pct"``; ``"temperature"``, ``"rms_relative"``,
        ``"misfit_level"``. Artists: ``"<T>/storage"``, ``"<T>/loss"``, ``"rms"``,
        ``"level"``.
    """
    import matplotlib as mpl


    fig = new_figure(fig, (11.0, 3.6))
    axes = fig.subplots(1, 3)
    _apart(fig)
    modulus = mc.data.kind == "modulus"
    symbols = parts_of(mc.data.symbol, mc.data.kind)
    temps = np.asarray(mc.temperatures)
    cmap = temperature_colormap()
    norm = mpl.colors.Normalize(temps.min(), temps.max())
    structure = mc.master if mc.master is not None else get_structure(mc.structure)
    rng = np.random.default_rng(seed)
    rows = rng.choice(mc.master_draws.shape[0], size=min(n_draws, mc.master_draws.shape[0]),
                      replace=False)
    theta = mc.master_draws[rows]
    vertical = (None if getattr(mc, "vertical_draws", None) is None
                else mc.vertical_draws[rows])
    values, artists = {}, {}
    for i, (d, t) in enumerate(zip(mc.isotherms, temps, strict=True)):
        shifts = mc.shift_draws[rows, i]
        w = d.omega[None, :] * 10.0 ** shifts[:, None]
        quantity = ("storage", "loss") if modulus else ("storage_compliance", "loss_compliance")
        parts = [evaluate(structure, theta, q, w) for q in quantity]
        if vertical is not None:  # the model of the isotherm: the master divided by b_T
            scale = 10.0 ** (-vertical[:, i] if modulus else vertical[:, i])
            parts = [p * scale[:, None] for p in parts]
        storage, loss = (np.median(p, axis=0) for p in parts)
        magnitude = np.hypot(storage, loss)
        measured = (d.response.real, d.response.imag if modulus else -d.response.imag)
        reduced = d.omega * 10.0 ** mc.log_shift_mean[i]
        values[f"{t:g}/omega_reduced"] = reduced
        for ax, name, data, model in zip(axes[:2], ("storage", "loss"), measured,
                                         (storage, loss), strict=True):
            pct = 100.0 * (data - model) / magnitude
            values[f"{t:g}/{name}_pct"] = pct
            (artists[f"{t:g}/{name}"],) = ax.semilogx(reduced, pct, "o-", ms=2.5, lw=0.6,
                                                      color=cmap(norm(t)), alpha=0.85)
    for ax, sym in zip(axes[:2], symbols, strict=True):
        ax.axhline(0.0, color="k", lw=0.8)
        ax.set_xlabel(f"a_T ω [rad/s] (T_ref = {mc.reference_temperature:g} °C)")
        ax.set_ylabel(f"{sym}: (data − model) / |model| [%]")
    fig.colorbar(mpl.cm.ScalarMappable(norm=norm, cmap=cmap), ax=axes[1], label="T [°C]")
    fit = mc.tts_checks.get("isotherm_fit") or {}
    ax = axes[2]
    if fit.get("rms_relative"):
        rms = 100.0 * np.asarray(fit["rms_relative"], dtype=float)
        level = ISOTHERM_MISFIT * float(np.median(rms))
        missed = set(fit.get("misfit") or ())
        colours = ["#D55E00" if t in missed else "k" for t in fit["temperatures"]]
        artists["rms"] = ax.scatter(fit["temperatures"], rms, c=colours, s=14, zorder=3)
        artists["level"] = ax.axhline(level, color="#D55E00", ls="--", lw=0.9,
                                      label=f"{ISOTHERM_MISFIT:g} × the median isotherm's")
        ax.set_ylim(0.0, 1.1 * max(float(rms.max()), level))
        ax.legend(loc="upper left", fontsize=7)
        values.update(temperature=np.asarray(fit["temperatures"], dtype=float),
                      rms_relative=rms / 100.0, misfit_level=level / 100.0)
    ax.set_xlabel("T [°C]")
    ax.set_ylabel("rms relative residual [%]")
    ax.set_title("missed isotherms in red" if fit.get("misfit") else
                 "no isotherm missed", fontsize=8)
    return Drawn.build(fig, tuple(axes), values, artists)


def _apart(fig) -> None:
    """Room between the panels: the colour bar's label beside the second panel otherwise runs
    into the third panel's axis label."""
    engine = fig.get_layout_engine()
    if engine is not None and hasattr(engine, "set"):
        engine.set(wspace=0.08)
