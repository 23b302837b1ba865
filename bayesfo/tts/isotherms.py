"""The isotherms of a master curve: checked and ordered (:class:`_Isotherms`), the seed shifts
from overlaying neighbouring isotherms, and the data reduced to the reference temperature."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..data import FrequencyResponse
from ..data.frequency_response import FREQUENCY_RTOL
from ..errors import InputError


# ---------------------------------------------------------------------------- inputs
@dataclass(frozen=True)
class _Isotherms:
    """The isotherms in order of temperature, checked."""

    data: tuple[FrequencyResponse, ...]
    temperatures: tuple[float, ...]
    reference: int

    @cached_property
    def joint(self) -> FrequencyResponse:
        omega = np.concatenate([d.omega for d in self.data])
        response = np.concatenate([d.response for d in self.data])
        sigma = (np.concatenate([d.sigma for d in self.data])
                 if all(d.sigma is not None for d in self.data) else None)
        first = self.data[0]
        return FrequencyResponse(
            omega, response, sigma, kind=first.kind, units=first.units,
            name=f"{self.title}: {len(self.data)} isotherms, "
                 f"{min(self.temperatures):g} to {max(self.temperatures):g} °C",
            source=first.source, distinct_frequencies=False, symbol=first.symbol)

    @property
    def title(self) -> str:
        """What the isotherms are called together: the label they share (one file's, before
        the temperature), else the label they share once their numbers are left out
        (oscillation_ps130_data, oscillation_ps145_data: "oscillation_ps_data"), else the
        directory their files share, else the first label."""
        import re
        from pathlib import Path

        bases = {d.label.split(",")[0] for d in self.data}
        if len(bases) == 1:
            return bases.pop()
        number = r"[-+]?\d+(?:[.p]\d+)?(?:\s*°?[CK](?![A-Za-z]))?"  # with its unit, if any
        bare = {re.sub(r"[_\s]{2,}", "_", re.sub(number, "", b)).strip("_ ") for b in bases}
        name = bare.pop() if len(bare) == 1 else ""
        if sum(c.isalpha() for c in name) >= 3:
            return name
        folders = {Path(d.source).parent for d in self.data if d.source}
        if len(folders) == 1 and len(self.data) == sum(bool(d.source) for d in self.data):
            name = folders.pop().resolve().name
            if name:
                return name
        return self.data[0].label.split(",")[0]

    @cached_property
    def point_isotherm(self) -> np.ndarray:
        return np.concatenate([np.full(d.n_frequencies, i) for i, d in enumerate(self.data)])


def _isotherms(isotherms, reference_temperature) -> _Isotherms:
    """Check and sort the isotherms: (FrequencyResponse, temperature) pairs or objects with
    ``data`` and ``temperature`` (:class:`bayesfo.data.Isotherm`)."""
    pairs = []
    for k, item in enumerate(isotherms):
        if hasattr(item, "data") and hasattr(item, "temperature"):
            data, temperature = item.data, item.temperature
        else:
            try:
                data, temperature = item
            except (TypeError, ValueError):
                raise InputError(f"isotherm {k + 1}: give (FrequencyResponse, temperature in °C) "
                                 "or an Isotherm of bayesfo.read_isotherms") from None
        if not isinstance(data, FrequencyResponse):
            raise InputError(f"isotherm {k + 1}: the data must be a FrequencyResponse")
        if temperature is None or not math.isfinite(float(temperature)):
            raise InputError(f"isotherm {k + 1} ({data.label}): no temperature; give each "
                             "isotherm's temperature in °C")
        pairs.append((data, float(temperature)))
    if len(pairs) < 2:
        raise InputError(f"a master curve needs two or more isotherms, got {len(pairs)}")
    pairs.sort(key=lambda p: p[1])
    temps = [t for _, t in pairs]
    for a, b in zip(temps, temps[1:]):
        if abs(a - b) < 0.5:
            raise InputError(f"two isotherms at {a:g} and {b:g} °C: temperatures must differ "
                             "(by 0.5 °C or more); merge or drop one")
    kinds = {d.kind for d, _ in pairs}
    if len(kinds) > 1 or kinds & {"generic"}:
        raise InputError("the isotherms must all be modulus or all compliance data, got "
                         + ", ".join(sorted(kinds)))
    units = {d.units for d, _ in pairs}
    if len(units) > 1:
        raise InputError("the isotherms are in different units (" + ", ".join(sorted(units))
                         + "); convert them to one")
    if reference_temperature is None:
        ref = len(pairs) // 2
    else:
        ref = int(np.argmin([abs(t - reference_temperature) for t in temps]))
        if abs(temps[ref] - reference_temperature) > 0.5:
            raise InputError(f"reference temperature {reference_temperature:g} °C: no isotherm "
                             f"there; the isotherms are at {', '.join(f'{t:g}' for t in temps)} °C")
    return _Isotherms(tuple(d for d, _ in pairs), tuple(temps), ref)


# ---------------------------------------------------------------------------- seeds
def _pair_shift(lower: FrequencyResponse, upper: FrequencyResponse,
                phase_only: bool = False) -> float:
    """log10 of the factor by which ``upper``'s frequencies are multiplied to lie on
    ``lower``'s curve (log|G*| and phase overlaid where the two overlap, or the phase alone,
    which a vertical shift leaves alone), by a grid search."""
    def curve(d):
        order = np.argsort(d.omega)
        return (np.log10(d.omega[order]), np.log10(np.abs(d.response[order])),
                np.angle(d.response[order]))

    xl, ml, pl = curve(lower)
    xu, mu, pu = curve(upper)
    d = (overlay_shift(xl, (pl,), xu, (pu,)) if phase_only
         else overlay_shift(xl, (ml, pl), xu, (mu, pu)))
    return 0.0 if d is None else d


#: Step of the grid of shifts [decades].
GRID_STEP = 0.02


def overlay_cost(xl, yl, xu, yu, d: float, min_inside: int = 2):
    """(cost, inside) of laying the curves ``yu`` (at log10 ω ``xu + d``) on ``yl`` (at ``xl``):
    the sum over the curves of the mean squared difference where they overlap, inf with fewer
    than ``min_inside`` points inside."""
    x = xu + d
    inside = (x >= xl.min()) & (x <= xl.max())
    n = int(inside.sum())
    if n < min_inside:
        return np.inf, inside
    cost = sum(float(np.mean((np.interp(x[inside], xl, a) - b[inside]) ** 2))
               for a, b in zip(yl, yu, strict=True))
    # Fewer overlapping points are worth less: a shift that overlays one point trivially
    # must not beat one that overlays the whole sweep.
    return cost * (1.0 + 1.0 / n), inside


def overlay_shift(xl, yl, xu, yu, *, min_inside: int = 2,
                  refine: bool = False) -> float | None:
    """The shift d [decades] of log10 ω that best lays the curves ``yu`` on ``yl`` (sequences
    of arrays over ``xu`` and ``xl``), by a grid search over every overlap (and, with
    ``refine``, a finer one around its best); None where they never overlap."""
    span = max(xl.max(), xu.max()) - min(xl.min(), xu.min())
    grid = np.arange(-span - 2.0, span + 2.0, GRID_STEP)
    costs = [overlay_cost(xl, yl, xu, yu, d, min_inside)[0] for d in grid]
    k = int(np.argmin(costs))
    if not np.isfinite(costs[k]):
        return None
    if not refine:
        return float(grid[k])
    fine = np.linspace(grid[k] - GRID_STEP, grid[k] + GRID_STEP, 41)
    return float(fine[int(np.argmin([overlay_cost(xl, yl, xu, yu, v, min_inside)[0]
                                     for v in fine]))])


def _seed_shifts(iso: _Isotherms, phase_only: bool = False) -> np.ndarray:
    """log10 a_T of each isotherm from the pairwise overlays (of the phase alone with
    ``phase_only``: seeds for free vertical shifts), 0 at the reference."""
    n = len(iso.data)
    return _chained([_pair_shift(iso.data[i], iso.data[i + 1], phase_only)
                     for i in range(n - 1)], iso.reference)


def _chained(steps, reference: int) -> np.ndarray:
    """Values of every isotherm from the steps between neighbours, 0 at the reference."""
    out = np.zeros(len(steps) + 1)
    for i in range(reference + 1, out.size):
        out[i] = out[i - 1] + steps[i - 1]
    for i in range(reference - 1, -1, -1):
        out[i] = out[i + 1] - steps[i]
    return out


def _vertical_seeds(iso: _Isotherms, log_shifts) -> np.ndarray:
    """log10 b_T of each isotherm (0 at the reference) that lays its log|G*| on its
    neighbour's where the two overlap at the horizontal shifts ``log_shifts``."""
    curves = []
    for d, a in zip(iso.data, log_shifts, strict=True):
        order = np.argsort(d.omega)
        curves.append((np.log10(d.omega[order]) + a, np.log10(np.abs(d.response[order]))))
    steps = []
    for (xl, yl), (xu, yu) in zip(curves, curves[1:]):
        inside = (xu >= xl.min()) & (xu <= xl.max())
        # b_T multiplies a modulus (divides a compliance) onto the reference's scale.
        gap = float(np.mean(np.interp(xu[inside], xl, yl) - yu[inside])) if inside.any() else 0.0
        steps.append(gap if iso.joint.kind == "modulus" else -gap)
    return _chained(steps, iso.reference)


def _reduced(iso: _Isotherms, log_shifts, log_vertical=None) -> FrequencyResponse:
    """The isotherms on one reduced frequency axis (a_T ω), each multiplied by b_T (a
    compliance divided by it), sorted; points that land on the same frequency averaged."""
    j = iso.joint
    omega = j.omega * 10.0 ** np.asarray(log_shifts)[iso.point_isotherm]
    b = np.ones_like(omega) if log_vertical is None else \
        10.0 ** np.asarray(log_vertical)[iso.point_isotherm]
    scale = b if j.kind == "modulus" else 1.0 / b
    order = np.argsort(omega)
    omega, response = omega[order], (j.response * scale)[order]
    # The same frequency as FrequencyResponse counts it (a shift that is a whole number of
    # the grid's steps lands points within rounding of each other).
    keep = np.r_[True, ~np.isclose(omega[1:], omega[:-1], rtol=FREQUENCY_RTOL, atol=0.0)]
    groups = np.cumsum(keep) - 1
    n = groups[-1] + 1
    r = np.zeros(n, complex)
    np.add.at(r, groups, response)
    r /= np.bincount(groups)
    sigma = None
    if j.sigma is not None:
        s2 = np.zeros(n)
        np.add.at(s2, groups, (j.sigma * scale)[order] ** 2)
        sigma = np.sqrt(s2) / np.bincount(groups)
    return FrequencyResponse(omega[keep], r, sigma, kind=j.kind, units=j.units,
                             name=f"master curve of {j.label}", source=j.source,
                             symbol=j.symbol)
