"""The model of a joint time–temperature superposition: a master structure seen through the
isotherms (:class:`ShiftedStructure`), each point at its isotherm's reduced frequency a_T·ω and
divided by b_T (see :mod:`bayesfo.tts.joint`). It offers what the inference routes use of a
:class:`~bayesfo.structures.Structure`, so a certified posterior comes from
:func:`bayesfo.inference.certified_posterior` as for any structure.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import InputError
from ..priors import LogUniform, Uniform
from ..structures.parameters import Parameter, Parametrised
from .laws import arrhenius, wlf

#: Prior of each log10 a_T: uniform over ±SHIFT_RANGE decades around the reference, or wider
#: where the seed shifts reach beyond SHIFT_RANGE − SHIFT_MARGIN (isotherms spanning 30
#: decades): ± (largest seed + SHIFT_MARGIN).
SHIFT_RANGE = 15.0
SHIFT_MARGIN = 5.0
#: Prior of each free log10 b_T: uniform over ±VERTICAL_RANGE decades (vertical factors are
#: density and temperature ratios, a few tens of per cent).
VERTICAL_RANGE = 1.0
KELVIN = 273.15
#: How the shifts are modelled: one free log10 a_T per isotherm, or a shift law whose
#: parameters are sampled with the master's.
LAWS = ("free", "wlf", "arrhenius")
#: Priors of a shift law inside the joint model: WLF's C1 uniform on (0, WLF_C1_MAX], C2
#: uniform from just above T_ref − T_min (C2 + T − T_ref > 0 at every isotherm) to
#: WLF_C2_MAX °C; Arrhenius' E_a log-uniform on [EA_MIN, EA_MAX] J/mol.
WLF_C1_MAX = 100.0
WLF_C2_MAX = 2000.0
EA_MIN, EA_MAX = 1e3, 1e7


def shift_name(temperature: float, factor: str = "aT") -> str:
    """The parameter name of the shift of the isotherm at ``temperature`` [°C]:
    ``log10_aT_80C``, ``log10_aT_m40C``, ``log10_aT_12p5C``; ``factor="bT"`` for the vertical
    shift (``log10_bT_80C``)."""
    text = f"{temperature:g}".replace("-", "m").replace(".", "p")
    return f"log10_{factor}_{text}C"


def log_shifts(theta, temperatures, reference: int, law: str, start: int) -> np.ndarray:
    """log10 a_T of every isotherm (0 at the reference), shape (n_sets, n_isotherms), from
    parameter sets whose shift parameters begin at column ``start``: one free log10 a_T per
    isotherm but the reference, or a law's constants (``wlf``: C1, C2 [°C]; ``arrhenius``:
    E_a [J/mol])."""
    theta = np.atleast_2d(np.asarray(theta, float))
    temps = np.asarray(temperatures, float)[None, :]
    t_ref = temperatures[reference]
    if law == "wlf":
        with np.errstate(all="ignore"):
            return wlf(temps, t_ref, theta[:, start:start + 1], theta[:, start + 1:start + 2])
    if law == "arrhenius":
        return arrhenius(temps, t_ref, theta[:, start:start + 1])
    shifted = [i for i in range(len(temperatures)) if i != reference]
    out = np.zeros((theta.shape[0], len(temperatures)))
    out[:, shifted] = theta[:, start:start + len(shifted)]
    return out


def log_vertical(theta, temperatures, reference: int, vertical: str, start: int) -> np.ndarray:
    """log10 b_T of every isotherm (0 at the reference), shape (n_sets, n_isotherms): 0, the
    density correction T_ref/T [K], or free ones from column ``start`` of the parameter sets
    (one per isotherm but the reference)."""
    theta = np.atleast_2d(np.asarray(theta, float))
    out = np.zeros((theta.shape[0], len(temperatures)))
    if vertical == "density":
        t = np.asarray(temperatures) + KELVIN
        out[:] = np.log10(t[reference] / t)
    elif vertical == "free":
        shifted = [i for i in range(len(temperatures)) if i != reference]
        out[:, shifted] = theta[:, start:start + len(shifted)]
    return out


@dataclass(frozen=True, eq=False)
class ShiftedStructure(Parametrised):
    """A master structure seen through the isotherms: the structure's parameters followed by
    one log10 a_T per isotherm other than the reference, evaluated on the joint data's points
    (each at its own isotherm's reduced frequency). It offers what the inference routes use of
    a :class:`~bayesfo.structures.Structure`.

    Attributes
    ----------
    master : Structure
        The master structure.
    temperatures : tuple of float
        The isotherms' temperatures [°C], ascending.
    reference : int
        The isotherm at the reference temperature (a_T = 1, no shift parameter).
    point_isotherm : ndarray of int
        The isotherm of each point of the joint data, in its order.
    master_grid : ndarray or None
        The dissipation grid of the master (scaled), spanning the reduced window.
    vertical : {"none", "density", "free"}
        The vertical shift b_T (see the module).
    shift_range : float
        Each free log10 a_T is uniform over ± this many decades.
    law : {"free", "wlf", "arrhenius"}
        One free log10 a_T per isotherm other than the reference, or the shifts of a law
        whose parameters (``wlf_C1``, ``wlf_C2`` [°C]; ``Ea`` [J/mol]) are sampled instead
        (:data:`LAWS`).
    """

    master: object
    temperatures: tuple[float, ...]
    reference: int
    point_isotherm: np.ndarray
    master_grid: np.ndarray | None = None
    vertical: str = "none"
    law: str = "free"
    shift_range: float = SHIFT_RANGE

    @property
    def name(self) -> str:
        return self.master.name

    @property
    def shifted(self) -> tuple[int, ...]:
        """Isotherms with a shift parameter (all but the reference), in parameter order."""
        return tuple(i for i in range(len(self.temperatures)) if i != self.reference)

    @cached_property
    def horizontal(self) -> tuple:
        """The parameters of the horizontal shifts: one per shifted isotherm, or the law's."""
        temps = np.asarray(self.temperatures, float)
        t_ref = temps[self.reference]
        if self.law == "wlf":
            c2_min = max(t_ref - temps.min(), 0.0) + 1.0
            return (Parameter("wlf_C1", "shift", Uniform(0.0, WLF_C1_MAX)),
                    Parameter("wlf_C2", "shift", Uniform(c2_min, WLF_C2_MAX)))
        if self.law == "arrhenius":
            return (Parameter("Ea", "shift", LogUniform(EA_MIN, EA_MAX)),)
        if self.law != "free":
            raise InputError(f"law must be one of {', '.join(LAWS)}, got {self.law!r}")
        return tuple(Parameter(shift_name(self.temperatures[i]), "shift",
                               Uniform(-self.shift_range, self.shift_range))
                     for i in self.shifted)

    @cached_property
    def parameters(self) -> tuple:
        shifts = self.horizontal
        if self.vertical == "free":
            shifts += tuple(Parameter(shift_name(self.temperatures[i], "bT"), "shift",
                                      Uniform(-VERTICAL_RANGE, VERTICAL_RANGE))
                            for i in self.shifted)
        return tuple(self.master.parameters) + shifts

    @property
    def fixed(self) -> dict:
        return self.master.fixed

    @property
    def inverted(self) -> bool:
        return self.master.inverted

    @property
    def commensurate_order(self):
        return None

    def check_data(self, data) -> None:
        if data.n_frequencies < self.n_params + 1:
            raise InputError(f"{data.n_frequencies} points for {self.n_params} parameters of "
                             f"the master curve of {self.name}: too few")

    def with_priors(self, priors: dict) -> ShiftedStructure:
        from dataclasses import replace

        own = {k: v for k, v in priors.items() if k in self.master.param_names}
        if set(priors) - set(own):
            raise InputError("priors of the shifts cannot be overridden")
        return replace(self, master=self.master.with_priors(own))

    def log_shifts(self, theta) -> np.ndarray:
        """log10 a_T of every isotherm (0 at the reference), shape (n_sets, n_isotherms)."""
        return log_shifts(theta, self.temperatures, self.reference, self.law,
                          self.master.n_params)

    def log_vertical(self, theta) -> np.ndarray:
        """log10 b_T of every isotherm (0 at the reference), shape (n_sets, n_isotherms)."""
        return log_vertical(theta, self.temperatures, self.reference, self.vertical,
                            self.master.n_params + len(self.horizontal))

    def response(self, theta, omega, kind: str = "compliance") -> np.ndarray:
        """The master's response at each point's reduced frequency a_T·ω, divided by b_T
        (a compliance multiplied by it); ``omega`` are the joint data's points, in their
        order."""
        theta2 = np.atleast_2d(np.asarray(theta, float))
        omega = np.asarray(omega, float)
        if omega.shape != self.point_isotherm.shape:
            raise InputError("a master curve is evaluated on its own data's points only")
        a = 10.0 ** self.log_shifts(theta2)[:, self.point_isotherm]
        with np.errstate(all="ignore"):
            c = self.master.laplace(theta2[:, :self.master.n_params], 1j * omega * a,
                                    per_set=True)
            if self.vertical != "none":  # the likelihood's path: no work without b_T
                c = c * 10.0 ** self.log_vertical(theta2)[:, self.point_isotherm]
            out = 1.0 / c if kind == "modulus" else c
        return out[0] if np.ndim(theta) == 1 else out

    def in_support(self, theta) -> np.ndarray:
        """True where the master's parameters lie in its prior support and every shift (and
        law) parameter in its prior range."""
        theta2 = np.atleast_2d(np.asarray(theta, float))
        k = self.master.n_params
        ok = np.atleast_1d(self.master.in_support(theta2[:, :k])).copy()
        for j, p in enumerate(self.parameters[k:], start=k):
            ok &= p.prior.contains(theta2[:, j])
        return ok if np.ndim(theta) == 2 else ok[0]

    def constraints_hold(self, theta, kind: str, omega_grid=None, where=None) -> np.ndarray:
        theta2 = np.atleast_2d(np.asarray(theta, float))
        return self.master.constraints_hold(theta2[:, :self.master.n_params], kind,
                                            self.master_grid, where=where)

    def admissible(self, theta, kind: str, omega_grid=None) -> np.ndarray:
        theta2 = np.atleast_2d(np.asarray(theta, float))
        ok = self.in_support(theta2)
        ok &= self.constraints_hold(theta2, kind, where=ok)
        return ok if np.ndim(theta) == 2 else ok[0]

    def _convert(self, theta, scaling, to_physical: bool) -> np.ndarray:
        theta2 = np.atleast_2d(np.asarray(theta, float))
        out = theta2.copy()
        k = self.master.n_params
        convert = self.master.to_physical if to_physical else self.master.to_scaled
        out[:, :k] = convert(theta2[:, :k], scaling)  # a_T is a ratio: no units
        return out if np.ndim(theta) == 2 else out[0]

    def to_physical(self, theta, scaling) -> np.ndarray:
        return self._convert(theta, scaling, True)

    def to_scaled(self, theta, scaling) -> np.ndarray:
        return self._convert(theta, scaling, False)
