"""From a table whose columns are chosen to checked data sets: numbers parsed, converted to SI,
split into isotherms (block column or temperature column), duplicates handled, the response
formed, and every data set passed through the checks and limits of the contract reader."""

from __future__ import annotations

from collections import Counter
from dataclasses import replace

import numpy as np

from .._io import show
from ..errors import InputError
from .columns import Choice, Column
from .csv_reader import DUPLICATE_ADVICE, MAX_FREQUENCIES, _from_columns, _too_many
from .frequency_response import FREQUENCY_RTOL
from .reading import Isotherm, Reading
from .tables import Table, number_like, to_number
from .temperature import temperature_in_text
from .units import SI

#: Rows within this many °C of the running mean of their isotherm belong to it (a temperature
#: column splits a table into isotherms where it jumps by more).
TEMPERATURE_TOLERANCE = 1.5

#: Largest relative difference between ω and 2π f where a file gives both.
FREQUENCY_AGREEMENT = 1e-3


def assemble_table(table: Table, choice: Choice, cols: list[Column], ctx: dict, label: str,
                   ctx_temperature: tuple) -> list[Isotherm]:
    """The data sets of one table (see the module docstring)."""
    where, decimal = ctx["where"], ctx["decimal"]
    n = len(cols)
    key_cols = [choice.frequency, *choice.response.values()]
    rows, empty = [], []
    for ln in table.rows:
        cells = ln.cells + [""] * max(0, n - len(ln.cells))
        if all(not cells[c.index] for c in key_cols):
            empty.append(ln.number)
        else:
            rows.append((ln.number, cells))
    if not rows:
        return []
    linenos = np.array([ln for ln, _ in rows])
    strict = [*key_cols] + [c for c in (choice.sigma, choice.series, choice.frequency_check) if c]
    vals = {c.index: _numbers(c, rows, decimal, where) for c in strict}

    used = {c.index for c in choice.used()}
    kept, ignored = {}, []
    labels = [c.label for c in cols]
    for c in cols:
        if c.index in used:
            continue
        cells_c = [cells[c.index] for _, cells in rows]
        if not any(cells_c):
            ignored.append(f"{c.label} (no data)")
            continue
        try:
            kept[c] = np.array([to_number(x, decimal) for x in cells_c])
        except ValueError:
            ignored.append(c.label)
    dup_labels = {x for x, n in Counter(labels).items() if n > 1}
    temps = None
    if choice.temperature is not None:
        t = choice.temperature
        raw = np.array([_lenient(cells[t.index], decimal) for _, cells in rows])
        temps = t.unit.to_si(raw) if t.unit is not None else raw

    skipped = list(ctx["skipped"])
    if ctx["preamble"]:
        skipped.insert(0, ctx["preamble"])
    if empty:
        skipped.append(f"{len(empty)} row(s) with empty frequency and response cells "
                       f"({_lines(empty)})")
    out = []
    groups = _groups(choice, rows, temps)
    for glabel, idx, how in groups:
        full = ", ".join(x for x in (label, glabel) if x)
        omega_probe = vals[choice.frequency.index][idx]
        if idx.size > 1 and np.all(omega_probe == omega_probe[0]):
            ctx["skipped"].append(f"{full or 'table'} (lines {linenos[idx[0]]}–"
                                  f"{linenos[idx[-1]]}): one frequency on every row, not a "
                                  "frequency sweep (an amplitude or time sweep?)")
            if len(groups) == 1 and not ctx["several_tables"]:
                raise InputError(f"{where}, lines {linenos[idx[0]]}–{linenos[idx[-1]]}, column "
                                 f"'{choice.frequency.label}': the same frequency on every row; "
                                 "an amplitude or time sweep, not a frequency sweep")
            continue
        if how == "block" and temperature_in_text(glabel) is not None:
            group_temperature = (temperature_in_text(glabel), f"from '{glabel}'")
        else:
            group_temperature = ctx_temperature if len(groups) == 1 else (None, "")
        temperature, source = _temperature(choice, temps, idx, group_temperature)
        out.append(_data_set(choice, cols, ctx, vals, kept, ignored, linenos, idx, full,
                             temperature, source, skipped, table,
                             lambda c: c.label in dup_labels))
    return out


def _numbers(col: Column, rows, decimal: str, where: str) -> np.ndarray:
    out = np.empty(len(rows))
    for r, (lineno, cells) in enumerate(rows):
        try:
            out[r] = to_number(cells[col.index], decimal)
        except ValueError as exc:
            raise InputError(f"{where}, line {lineno}, column '{col.label}': {exc}") from None
    return out


def _lenient(cell: str, decimal: str) -> float:
    try:
        return to_number(cell, decimal)
    except ValueError:
        return float("nan")


def _lines(numbers) -> str:
    """``line 5`` or ``lines 5, 7, 9`` (the first eight, and how many in all)."""
    numbers = list(numbers)
    shown = ", ".join(str(x) for x in numbers[:8])
    word = "line" if len(numbers) == 1 else "lines"
    return f"{word} {shown}" + (f", … ({len(numbers)} in all)" if len(numbers) > 8 else "")


def _groups(choice: Choice, rows, temps) -> list[tuple[str, np.ndarray, str]]:
    """(label, row indices, how) of each data set of the table."""
    if choice.block is not None:
        keys = [cells[choice.block.index] for _, cells in rows]
        order = list(dict.fromkeys(keys))
        if len(order) > 1:
            name = choice.block.name
            return [(f"{name} {k}" if number_like(k) else k or f"{name} (empty)",
                     np.array([i for i, x in enumerate(keys) if x == k]), "block")
                    for k in order]
    if temps is not None and np.isfinite(temps).any():
        groups, current, total = [], [], 0.0
        for i, t in enumerate(temps):
            if current and np.isfinite(t) and abs(t - total / _finite_count(temps, current)) \
                    > TEMPERATURE_TOLERANCE:
                groups.append(current)
                current, total = [], 0.0
            current.append(i)
            total += t if np.isfinite(t) else 0.0
        groups.append(current)
        if len(groups) > 1:
            out = []
            for g in groups:
                mean = np.nanmean(temps[g]) if np.isfinite(temps[g]).any() else np.nan
                out.append((f"{mean:.4g} °C", np.array(g), "temperature"))
            return out
    return [("", np.arange(len(rows)), "")]


def _finite_count(temps, idx) -> int:
    return max(1, int(np.isfinite(temps[idx]).sum()))


def _temperature(choice, temps, idx, nominal_temperature):
    nominal, source = nominal_temperature
    measured = ""
    if temps is not None and np.isfinite(temps[idx]).any():
        t = temps[idx][np.isfinite(temps[idx])]
        unit = "" if choice.temperature.unit is not None else ", no unit given: taken in °C"
        measured = (f"column '{choice.temperature.label}' {t.min():.6g} … {t.max():.6g} °C"
                    f"{unit}")
        mean = round(float(np.mean(t)), 2)
    if nominal is not None:
        return nominal, source + (f"; {measured}" if measured else "")
    if measured:
        return mean, f"mean of {measured}"
    return None, ""


def _data_set(choice, cols, ctx, vals, kept, ignored, linenos_all, idx, label, temperature,
              temp_source, skipped, table, labels_dup) -> Isotherm:
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        return _data_set_(choice, cols, ctx, vals, kept, ignored, linenos_all, idx, label,
                          temperature, temp_source, skipped, table, labels_dup)


def _data_set_(choice, cols, ctx, vals, kept, ignored, linenos_all, idx, label, temperature,
               temp_source, skipped, table, labels_dup) -> Isotherm:
    where = ctx["where"]
    converted, assumed = [], []
    values, labels = {}, {}
    lines = linenos_all[idx]

    def si(col: Column, no_unit: str) -> np.ndarray:
        v = vals[col.index][idx]
        if col.unit is None:
            if no_unit:
                assumed.append(f"'{col.label}': {no_unit}")
            return v
        if not col.unit.is_si:
            converted.append(f"'{col.label}': {col.unit.describe()}")
        return col.unit.to_si(v)

    f = choice.frequency
    if f.role == "omega":
        omega = si(f, "rad/s (no unit given; an angular frequency)")
        values["omega"], labels["omega"] = omega, f.label
    else:
        hz = si(f, "Hz (no unit given; a frequency)")
        values["freq"], labels["freq"] = hz, f.label
        converted.append(f"'{f.label}': Hz → rad/s (ω = 2π f)")
        with np.errstate(over="ignore"):
            omega = 2 * np.pi * hz
    if choice.frequency_check is not None:
        _check_frequencies(choice, omega, vals, idx, lines, where)

    q, r = choice.quantity, choice.response
    sign = -1.0 if q == "compliance" else 1.0
    what = {"modulus": "a modulus", "compliance": "a compliance"}.get(q, "the response")
    no_unit = f"no unit given: used as written ({what} in {SI.get(q, 'SI units')} if SI)"
    form = choice.form
    if form in ("viscosity/phase", "viscosity/tan_delta", "eta"):
        converted.append("complex viscosity → modulus: G* = jω η* (|G*| = ω|η*|, G' = ω η'', "
                         "G'' = ω η')")
    if form == "storage/loss" and q == "any":
        values["storage"], values["loss"] = si(r["storage"], no_unit), si(r["loss"], no_unit)
        labels.update(storage=r["storage"].label, loss=r["loss"].label)
    elif form == "storage/loss":
        values["real"], values["imag"] = si(r["storage"], no_unit), sign * si(r["loss"], no_unit)
        labels.update(real=r["storage"].label, imag=r["loss"].label)
    elif form == "real/imag":
        values["real"], values["imag"] = si(r["real"], no_unit), si(r["imag"], no_unit)
        labels.update(real=r["real"].label, imag=r["imag"].label)
    elif form == "eta":
        values["real"] = omega * si(r["eta_out"], "Pa s (no unit given)")
        values["imag"] = omega * si(r["eta_dyn"], "Pa s (no unit given)")
        labels.update(real=r["eta_out"].label, imag=r["eta_dyn"].label)
    else:
        mag_col = r.get("magnitude") or r.get("viscosity")
        mag = si(mag_col, no_unit if "magnitude" in r else "Pa s (no unit given)")
        if "viscosity" in r:
            mag = omega * mag
        if "tan_delta" in r:
            tan = si(r["tan_delta"], "")
            real = mag / np.sqrt(1.0 + tan * tan)
            values["real"], values["imag"] = real, sign * real * tan
            labels.update(real=mag_col.label, imag=r["tan_delta"].label)
        else:
            pcol = r.get("phase") or r.get("phase_deg")
            phase = si(pcol, "degrees (no unit given)")
            values["magnitude"] = mag
            values["phase_deg"] = phase if "phase_deg" in r else sign * phase
            labels.update(magnitude=mag_col.label, phase_deg=pcol.label)
    resp_cols = [c for c in r.values() if c.role not in ("phase", "phase_deg", "tan_delta")]
    units = ctx["units"]
    if units is None:
        units = (SI[resp_cols[0].unit.quantity] if all(c.unit is not None for c in resp_cols)
                 else ctx["meta"].get("units", ""))
        if form in ("viscosity/phase", "viscosity/tan_delta", "eta") and units:
            units = "Pa"
    t = choice.temperature
    if t is not None and t.unit is not None and not t.unit.is_si:
        converted.append(f"'{t.label}': {t.unit.describe()}")
    if choice.sigma is not None:
        s = choice.sigma
        if s.unit is None and resp_cols[0].unit is not None and not resp_cols[0].unit.is_si:
            values["sigma"] = vals[s.index][idx] * resp_cols[0].unit.factor
            converted.append(f"'{s.label}': no unit given, taken in the units of the response "
                             f"({resp_cols[0].unit.describe()})")
        else:
            values["sigma"] = si(s, "")
        labels["sigma"] = s.label
    if choice.series is not None:
        values["series"], labels["series"] = vals[choice.series.index][idx], choice.series.label

    local_skipped = list(skipped)
    extra = {(f"{c.label} (column {c.index + 1})" if labels_dup(c) else c.label): v[idx]
             for c, v in kept.items()}
    if choice.series is None:
        values, lines, extra, note = _duplicates(values, omega, lines, extra, ctx["duplicates"],
                                                 where, f.label, choice.kind)
        if note:
            local_skipped.append(note)
        if lines.size > MAX_FREQUENCIES:
            _too_many(where, lines.size)
    for key, v in values.items():
        bad = np.flatnonzero(~np.isfinite(v))
        if bad.size:
            raise InputError(
                f"{where}, line {lines[bad[0]]}, column '{labels.get(key, key)}': the value "
                "is not finite in SI units (beyond the range of a double after converting "
                "its unit); check the unit of the column")
    fr = _from_columns(values, lines, where, kind=choice.kind,
                       meta={k: v for k, v in ctx["meta"].items() if k == "symbol"}, units=units,
                       name=_name(ctx, label), source=str(ctx["path"]), labels=labels,
                       symbol=choice.symbol or None)
    if choice.series is None:
        w = values["omega"] if "omega" in values else 2 * np.pi * values["freq"]
        order = np.argsort(w, kind="stable")
        extra = {k: v[order] for k, v in extra.items()}
    else:
        extra = {}
    roles = [("omega" if f.role == "omega" else "freq", _shown(f))]
    roles += [(role, _shown(c)) for role, c in r.items()]
    roles += [(role, _shown(c)) for role, c in (("sigma", choice.sigma), ("series", choice.series),
                                              ("temperature", choice.temperature),
                                              ("block", choice.block),
                                              ("frequency check", choice.frequency_check)) if c]
    reading = Reading(
        str(ctx["path"]), ctx["format"], ctx["encoding"], ctx["delimiter"], ctx["decimal"],
        label, 1, (int(lines.min()), int(lines.max())), table.header_line, table.units_line,
        tuple(roles), tuple(dict.fromkeys(converted)), tuple(dict.fromkeys(assumed)),
        fr.kind, choice.kind_reason, temperature, temp_source, tuple(local_skipped),
        tuple(ignored), tuple(extra) if choice.series is None else (), choice.others, extra)
    fr = replace(fr, notes=reading.notes() + fr.notes)
    return Isotherm(fr, temperature, label, reading)


def _shown(col: Column) -> str:
    """A column as written, with the unit of its units row."""
    if col.unit_text and col.unit_text not in col.label:
        return f"{col.label} [{col.unit_text}]"
    return col.label


def _name(ctx, label: str) -> str:
    if ctx["name"]:
        return ctx["name"] + (f", {label}" if label else "")
    return f"{ctx['path'].stem}, {label}" if label else ""


def _check_frequencies(choice, omega, vals, idx, lines, where) -> None:
    c = choice.frequency_check
    other = vals[c.index][idx]
    other = c.unit.to_si(other) if c.unit is not None else other
    other_omega = other if c.role == "omega" else 2 * np.pi * other
    with np.errstate(invalid="ignore", divide="ignore"):
        bad = np.flatnonzero(~(np.abs(other_omega - omega) <= FREQUENCY_AGREEMENT * np.abs(omega)))
    if bad.size:
        k = bad[0]
        raise InputError(
            f"{where}, line {lines[k]}: columns '{choice.frequency.label}' (ω = {omega[k]:g} "
            f"rad/s) and '{c.label}' (ω = {other_omega[k]:g} rad/s) disagree; check their units, "
            f"or name the one to use with --columns omega={show(choice.frequency.label)[1:-1]} "
            f"or freq={show(c.label)[1:-1]} (columns= in the API)")


def _duplicates(values, omega, lines, extra, how, where, fcol, kind):
    """Rows that repeat a frequency: refused, the first kept, or averaged."""
    order = np.argsort(omega, kind="stable")
    groups, cur = [], [order[0]]
    for a, b in zip(order[:-1], order[1:]):
        if np.isclose(omega[b], omega[a], rtol=FREQUENCY_RTOL, atol=0.0):
            cur.append(b)
        else:
            groups.append(cur)
            cur = [b]
    groups.append(cur)
    dups = [sorted(g) for g in groups if len(g) > 1]
    if not dups:
        return values, lines, extra, ""
    if how == "error":
        g = dups[0]
        shown = (f"{values['freq'][g[1]]:g} Hz" if "freq" in values
                 else f"{omega[g[1]]:g} rad/s")
        raise InputError(
            f"{where}, line {lines[g[1]]}, column '{fcol}': the frequency {shown} "
            f"repeats line {lines[g[0]]} ({sum(len(d) - 1 for d in dups)} repeated row(s) in "
            f"all); {DUPLICATE_ADVICE}")
    firsts = np.array(sorted(g[0] for g in groups))
    dropped = [int(lines[i]) for g in dups for i in g[1:]]
    if how == "first":
        keep = firsts
        new = {k: v[keep] for k, v in values.items()}
        note = (f"{len(dropped)} row(s) repeating a frequency of an earlier row (duplicates="
                f"'first'): {_lines(sorted(dropped))}")
    else:
        members = {g[0] if len(g) == 1 else sorted(g)[0]: sorted(g) for g in groups}
        new = {k: np.empty(len(firsts)) for k in values}
        for j, first in enumerate(firsts):
            g = members[first]
            for k in values:
                new[k][j] = np.mean(values[k][g])
            if "magnitude" in values:
                z = values["magnitude"][g] * np.exp(1j * np.radians(values["phase_deg"][g]))
                m = np.mean(z)
                new["magnitude"][j], new["phase_deg"][j] = abs(m), np.degrees(np.angle(m))
            if "sigma" in values:
                new["sigma"][j] = np.sqrt(np.sum(values["sigma"][g] ** 2)) / len(g)
        keep = firsts
        note = (f"{len(dropped)} row(s) repeating a frequency averaged with the first of their "
                f"frequency (duplicates='mean'): {_lines(sorted(dropped))}")
    return new, lines[keep], {k: v[keep] for k, v in extra.items()}, note
