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
from ..priors import Uniform
from ..structures.structure import Parameter

#: Prior of each log10 a_T: uniform over ±SHIFT_RANGE decades around the reference.
SHIFT_RANGE = 15.0
#: Prior of each free log10 b_T: uniform over ±VERTICAL_RANGE decades (vertical factors are
#: density and temperature ratios, a few tens of per cent).
VERTICAL_RANGE = 1.0
KELVIN = 273.15


def shift_name(temperature: float, factor: str = "aT") -> str:
    """The parameter name of the shift of the isotherm at ``temperature`` [°C]:
    ``log10_aT_80C``, ``log10_aT_m40C``, ``log10_aT_12p5C``; ``factor="bT"`` for the vertical
    shift (``log10_bT_80C``)."""
    text = f"{temperature:g}".replace("-", "m").replace(".", "p")
    return f"log10_{factor}_{text}C"


@dataclass(frozen=True, eq=False)
class ShiftedStructure:
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
    """

    master: object
    temperatures: tuple[float, ...]
    reference: int
    point_isotherm: np.ndarray
    master_grid: np.ndarray | None = None
    vertical: str = "none"

    @property
    def name(self) -> str:
        return self.master.name

    @property
    def shifted(self) -> tuple[int, ...]:
        """Isotherms with a shift parameter (all but the reference), in parameter order."""
        return tuple(i for i in range(len(self.temperatures)) if i != self.reference)

    @cached_property
    def parameters(self) -> tuple:
        shifts = tuple(Parameter(shift_name(self.temperatures[i]), "shift",
                                 Uniform(-SHIFT_RANGE, SHIFT_RANGE)) for i in self.shifted)
        if self.vertical == "free":
            shifts += tuple(Parameter(shift_name(self.temperatures[i], "bT"), "shift",
                                      Uniform(-VERTICAL_RANGE, VERTICAL_RANGE))
                            for i in self.shifted)
        return tuple(self.master.parameters) + shifts

    @property
    def param_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    @property
    def n_params(self) -> int:
        return len(self.parameters)

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
        theta = np.atleast_2d(np.asarray(theta, float))
        k = self.master.n_params
        out = np.zeros((theta.shape[0], len(self.temperatures)))
        out[:, list(self.shifted)] = theta[:, k:k + len(self.shifted)]
        return out

    def log_vertical(self, theta) -> np.ndarray:
        """log10 b_T of every isotherm (0 at the reference), shape (n_sets, n_isotherms)."""
        theta = np.atleast_2d(np.asarray(theta, float))
        out = np.zeros((theta.shape[0], len(self.temperatures)))
        if self.vertical == "density":
            t = np.asarray(self.temperatures) + KELVIN
            out[:] = np.log10(t[self.reference] / t)
        elif self.vertical == "free":
            start = self.master.n_params + len(self.shifted)
            out[:, list(self.shifted)] = theta[:, start:start + len(self.shifted)]
        return out

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
        theta2 = np.atleast_2d(np.asarray(theta, float))
        k = self.master.n_params
        ok = np.atleast_1d(self.master.in_support(theta2[:, :k])).copy()
        n = len(self.shifted)
        ok &= np.all(np.abs(theta2[:, k:k + n]) <= SHIFT_RANGE, axis=1)
        ok &= np.all(np.abs(theta2[:, k + n:]) <= VERTICAL_RANGE, axis=1)
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
