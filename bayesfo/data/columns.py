"""Which column of a lab file is what: header aliases, their units, and the response form chosen.

A header cell such as ``"Storage modulus [MPa]"``, ``"G'"``, ``"E_stor"`` (with ``MPa`` in a
units row), ``"Angular Frequency"`` or ``"Tan(delta)"`` is matched, case- and unit-insensitively,
to a *role* (``omega``, ``freq``, ``storage``, ``loss``, ``magnitude``, ``phase``, ``tan_delta``,
``viscosity``, ``eta_dyn``, ``eta_out``, ``real``, ``imag``, ``phase_deg``, ``sigma``, ``series``,
``temperature``, ``block``) and, for a response, to the quantity it measures (a modulus, a
compliance, or either for the contract's own names). :func:`choose` then picks the frequency
column and one complete response form, refusing where two readings are possible.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from .._io import show
from ..errors import InputError
from .units import Unit, parse_unit, split_header

#: Roles a ``columns`` mapping may name (see :func:`bayesfo.data.read`).
ROLES = ("omega", "freq", "storage", "loss", "real", "imag", "magnitude", "phase", "phase_deg",
         "tan_delta", "viscosity", "eta_dyn", "eta_out", "sigma", "series", "temperature", "block")

# The contract's own names keep the contract's meaning (phase_deg is the phase of G itself).
_CONTRACT = {"omega": "omega", "freq": "freq", "real": "real", "imag": "imag",
             "magnitude": "magnitude", "phase_deg": "phase_deg", "storage": "storage",
             "loss": "loss", "sigma": "sigma", "series": "series"}

_M, _C, _ANY = "modulus", "compliance", "any"


def _aliases() -> dict[str, tuple[str, str | None, str]]:
    """Normalised header name -> (role, quantity, modulus letter)."""
    a: dict[str, tuple[str, str | None, str]] = {}

    def add(role, quantity, letter, *names):
        for n in names:
            a[n] = (role, quantity, letter)

    add("omega", None, "", "omega", "ω", "angular frequency", "ang freq", "angular freq",
        "ang frequency", "reduced angular frequency", "shifted angular frequency", "at omega",
        "omega at", "ω at", "at ω", "at w", "w at", "aw", "ωat", "omega rad s")
    add("freq", None, "", "freq", "frequency", "oscillation frequency", "reduced frequency",
        "at f", "f at", "shifted frequency", "frequency hz")
    for letter, key in (("G", "g"), ("E", "e")):
        add("storage", _M, letter, f"{key}'", f"{key}p", f"{key} prime", f"{key} stor",
            f"{key}stor", f"{key} storage", f"{key}' storage modulus", f"storage modulus {key}'")
        add("loss", _M, letter, f"{key}''", f"{key}pp", f"{key} double prime", f"{key} loss",
            f"{key}loss", f"{key}'' loss modulus", f"loss modulus {key}''")
        add("magnitude", _M, letter, f"{key}*", f"abs {key}*", f"{key} star", f"{key}* complex")
    add("storage", _M, "", "storage modulus", "shear storage modulus", "elastic modulus")
    add("storage", _M, "E", "tensile storage modulus", "young's storage modulus")
    add("loss", _M, "", "loss modulus", "shear loss modulus", "viscous modulus")
    add("loss", _M, "E", "tensile loss modulus")
    add("magnitude", _M, "", "complex modulus", "complex shear modulus", "modulus")
    add("magnitude", _M, "E", "complex tensile modulus", "complex young's modulus")
    for key in ("j", "d"):
        add("storage", _C, key.upper(), f"{key}'", f"{key}p", f"{key} stor", f"{key} storage")
        add("loss", _C, key.upper(), f"{key}''", f"{key}pp", f"{key} loss")
        add("magnitude", _C, key.upper(), f"{key}*", f"abs {key}*")
    add("storage", _C, "", "storage compliance", "shear storage compliance")
    add("loss", _C, "", "loss compliance", "shear loss compliance")
    add("magnitude", _C, "", "complex compliance", "complex shear compliance")
    add("phase", None, "", "phase angle", "phase", "delta", "δ", "phaseangle", "loss angle",
        "phase shift")
    add("tan_delta", None, "", "tan delta", "tan δ", "tandelta", "tanδ", "tan d", "loss factor",
        "loss tangent", "damping factor", "tan")
    add("viscosity", _M, "", "complex viscosity", "η*", "eta*", "complex viscosity magnitude",
        "abs η*", "abs eta*")
    add("eta_dyn", _M, "", "dynamic viscosity", "η'", "eta'", "eta prime", "etap")
    add("eta_out", _M, "", "η''", "eta''", "out of phase component of η*", "etapp",
        "out of phase component of eta*")
    add("real", _ANY, "", "real part", "re g", "real g")
    add("imag", _ANY, "", "imaginary part", "im g", "imag g")
    add("series", None, "", "replicate")
    add("temperature", None, "", "temperature", "temp", "t measured", "temperature measured",
        "measured temperature", "sample temperature", "temp measured", "oven temperature")
    add("block", None, "", "set", "step", "step name", "step number", "segment", "interval",
        "isotherm", "block", "curve")
    # Anton Paar and other software write German headers when set to German.
    add("omega", None, "", "kreisfrequenz")
    add("freq", None, "", "frequenz")
    add("storage", _M, "", "speichermodul")
    add("loss", _M, "", "verlustmodul")
    add("magnitude", _M, "", "komplexer schubmodul", "komplexer modul", "betrag g*")
    add("phase", None, "", "phasenwinkel", "verlustwinkel")
    add("tan_delta", None, "", "verlustfaktor")
    add("viscosity", _M, "", "komplexe viskosität", "betrag η*")
    add("temperature", None, "", "temperatur")
    return a


_ALIASES = _aliases()


class NotResponse(InputError):
    """A table without a frequency column or without response columns: not a frequency
    response (a flow curve, a step of other data), skipped where the file has others."""
_SINGLE = {"f": "freq", "w": "omega", "ω": "omega", "T": "temperature", "δ": "phase"}
_PRIMES = str.maketrans({"′": "'", "″": "''", '"': "''", "’": "'", "‘": "'", "´": "'",
                         "|": " ", "(": " ", ")": " ", "·": " ", "ʹ": "'", "ʺ": "''"})


def normalise_name(name: str) -> str:
    """A header name as compared with the aliases: primes unified, lower case, separators as
    single spaces (``"Tan(delta)"`` -> ``"tan delta"``, ``'G"'`` -> ``"g''"``)."""
    key = name.translate(_PRIMES).lower()
    key = re.sub(r"(?<=\w)\*(?=\w)", " ", key)
    key = re.sub(r"[_\-.:,;/]+", " ", key)
    return re.sub(r"\s+", " ", key).strip()


@dataclass(frozen=True)
class Column:
    """A column of a table: where it is, what it is called, its unit and the role it can play."""

    index: int
    header: str
    name: str
    unit_text: str | None
    unit: Unit | None
    role: str | None
    quantity: str | None = None
    letter: str = ""

    @property
    def label(self) -> str:
        """The column as written in the file (name and unit)."""
        return self.header if self.header else f"column {self.index + 1}"


def identify(header: list[str], units_row: list[str] | None) -> list[Column]:
    """The columns of a table from its header cells (and the cells of its units row)."""
    out = []
    for i, cell in enumerate(header):
        cell = cell.strip()
        name, unit_text = split_header(cell)
        if units_row is not None and i < len(units_row) and units_row[i].strip():
            row_unit = units_row[i].strip()
            if row_unit.lower().rstrip(":") not in ("units", "unit"):
                unit_text = unit_text or row_unit.strip("[]()").strip() or None
        role, quantity, letter = _role_of(cell, name)
        out.append(_with_unit(Column(i, cell, name, unit_text, None, role, quantity, letter)))
    return out


def _role_of(cell: str, name: str) -> tuple[str | None, str | None, str]:
    low = cell.strip().lower()
    if low in _CONTRACT:
        role = _CONTRACT[low]
        return role, _ANY if role in ("storage", "loss", "real", "imag", "magnitude") else None, ""
    if name.strip() in _SINGLE:
        return _SINGLE[name.strip()], None, ""
    key = normalise_name(name)
    if key in _ALIASES:
        return _ALIASES[key]
    if key in _CONTRACT:
        role = _CONTRACT[key]
        return role, _ANY if role in ("storage", "loss", "real", "imag", "magnitude") else None, ""
    return None, None, ""


_UNIT_ROLE = {"angular_frequency": ("omega", "freq"), "frequency": ("omega", "freq"),
              "modulus": ("storage", "loss", "magnitude", "real", "imag", "sigma"),
              "compliance": ("storage", "loss", "magnitude", "real", "imag", "sigma"),
              "viscosity": ("viscosity", "eta_dyn", "eta_out"),
              "angle": ("phase", "phase_deg"), "temperature": ("temperature",),
              "dimensionless": ("tan_delta", "block", "series", "real", "imag", "magnitude",
                                "storage", "loss", "sigma")}


def _with_unit(col: Column) -> Column:
    """Attach the parsed unit; a unit that contradicts the role leaves the column unused, so
    that e.g. ``Frequency [Pa]`` is never read as a frequency."""
    unit = parse_unit(col.unit_text) if col.unit_text else None
    role, quantity = col.role, col.quantity
    if unit is not None and role is not None:
        if role not in _UNIT_ROLE.get(unit.quantity, ()):
            return Column(col.index, col.header, col.name, col.unit_text, unit, None)
        if unit.quantity in (_M, _C) and role in ("storage", "loss", "magnitude", "real", "imag"):
            if quantity in (_M, _C) and quantity != unit.quantity:
                return Column(col.index, col.header, col.name, col.unit_text, unit, None)
            quantity = unit.quantity
        if role in ("omega", "freq"):
            role = "omega" if unit.quantity == "angular_frequency" else "freq"
    return Column(col.index, col.header, col.name, col.unit_text, unit, role, quantity, col.letter)


def mapped(columns: list[Column], spec: str, role: str, where: str) -> Column:
    """The column a ``columns`` mapping names for ``role``: a header cell (with or without its
    unit, case-insensitive) or a column number counted from 1; a unit in brackets after the name
    (``"E_stor [Pa]"``) replaces the file's."""
    text = spec.strip()
    name, unit_text = split_header(text)
    unit_given = unit_text if name != text else None
    wanted = [text.lower(), name.lower()]
    hits = [c for c in columns if c.header.lower() in wanted or c.name.lower() in wanted]
    if not hits and re.fullmatch(r"\d+", name) and 1 <= int(name) <= len(columns):
        hits = [columns[int(name) - 1]]
    if not hits and re.fullmatch(r"\d+", name):
        raise InputError(f"{where}: --columns {role}={name}: the table has {len(columns)} "
                         "columns (numbered from 1)")
    if not hits:
        known = ", ".join(quoted(c.label) for c in columns[:30])
        raise InputError(f"{where}: --columns {role}={show(spec)}: no such column; the columns "
                         f"are {known}")
    if len(hits) > 1:
        raise InputError(f"{where}: --columns {role}={show(spec)} matches "
                         f"{len(hits)} columns (numbers {', '.join(str(c.index + 1) for c in hits)}); "
                         "give the column number instead")
    col = hits[0]
    unit_text = unit_given if unit_given is not None else col.unit_text
    quantity = None
    if role in ("viscosity", "eta_dyn", "eta_out"):
        quantity = _M
    elif role in ("storage", "loss", "magnitude", "real", "imag"):
        # what the header says (G' a modulus, J' a compliance), else the unit decides
        quantity = col.quantity if col.quantity in (_M, _C) else _ANY
    if role == "freq" and unit_text is None:
        unit_text = "Hz"
    new = Column(col.index, col.header, col.name, unit_text, None, role, quantity, col.letter)
    unit = parse_unit(unit_text) if unit_text else None
    if unit_text and unit is None and role not in ("block", "series"):
        raise InputError(f"{where}: --columns {role}={show(spec)}: unit {quoted(unit_text)} is not "
                         "one bayesfo converts (e.g. rad/s, Hz, Pa, kPa, MPa, 1/Pa, Pa s, deg, "
                         "rad, °C, K)")
    checked = _with_unit(new)
    if checked.role is None:
        raise InputError(f"{where}: --columns {role}={show(spec)}: a column in {unit_text} "
                         f"cannot be the {role} column")
    return checked


# ---------------------------------------------------------------------- choosing the columns
#: Response forms, best first within a quantity: (name, roles).
#: The contract's forms (real/imag, magnitude/phase_deg) belong to every quantity: a unit,
#: from the header or from ``columns`` (``real="real [kPa]"``), makes their columns a modulus.
_FORMS = {
    _M: (("storage/loss", ("storage", "loss")), ("magnitude/phase", ("magnitude", "phase")),
         ("magnitude/tan_delta", ("magnitude", "tan_delta")),
         ("viscosity/phase", ("viscosity", "phase")),
         ("viscosity/tan_delta", ("viscosity", "tan_delta")), ("eta", ("eta_dyn", "eta_out")),
         ("real/imag", ("real", "imag")), ("magnitude/phase_deg", ("magnitude", "phase_deg"))),
    _C: (("storage/loss", ("storage", "loss")), ("magnitude/phase", ("magnitude", "phase")),
         ("magnitude/tan_delta", ("magnitude", "tan_delta")),
         ("real/imag", ("real", "imag")), ("magnitude/phase_deg", ("magnitude", "phase_deg"))),
    _ANY: (("storage/loss", ("storage", "loss")), ("real/imag", ("real", "imag")),
           ("magnitude/phase_deg", ("magnitude", "phase_deg")),
           ("magnitude/phase", ("magnitude", "phase")),
           ("magnitude/tan_delta", ("magnitude", "tan_delta"))),
}
_QUANTITY_ROLES = ("storage", "loss", "magnitude", "real", "imag", "viscosity", "eta_dyn",
                   "eta_out")
_FREE_ROLES = ("phase", "phase_deg", "tan_delta")


@dataclass(frozen=True)
class Choice:
    """The columns chosen in one table, and why.

    ``response`` maps the roles of the chosen form to their columns; ``quantity`` is
    ``"modulus"``, ``"compliance"`` or ``"any"`` (the contract's own names); ``others`` lists the
    other complete response forms in the file (not used); ``frequency_check`` is a second
    frequency column (ω and f both given) that must agree with the first.
    """

    frequency: Column
    form: str
    response: dict
    quantity: str
    kind: str
    kind_reason: str
    others: tuple[str, ...] = ()
    frequency_check: Column | None = None
    temperature: Column | None = None
    block: Column | None = None
    sigma: Column | None = None
    series: Column | None = None

    @property
    def symbol(self) -> str:
        """The letter the response columns give the measured quantity (``"E"`` for ``E'`` and
        ``E''`` or ``"Tensile storage modulus"``, ``"G"``, ``"J"``, ``"D"``), or ``""`` where
        they give none or disagree."""
        letters = {c.letter for c in self.response.values() if c.letter}
        return next(iter(letters)) if len(letters) == 1 else ""

    def used(self) -> list[Column]:
        cols = [self.frequency, *self.response.values(), self.sigma, self.series,
                self.temperature, self.block, self.frequency_check]
        return [c for c in cols if c is not None]


def quoted(text: str) -> str:
    """``text`` in quotes for a message: readable units and symbols (°, η, ′) kept, invisible
    characters escaped."""
    return f"'{text}'" if text.isprintable() else show(text, limit=80)


def _names(cols) -> str:
    return ", ".join(quoted(c.label) for c in cols)


def candidates(columns: list[Column], mapping: dict, where: str) -> dict[str, list[Column]]:
    """Role -> columns that can play it: the mapped column where ``mapping`` names one (None
    or "" for none), else every column whose header matches the role."""
    cands: dict[str, list[Column]] = {r: [] for r in ROLES}
    taken = {}
    for role, spec in mapping.items():
        if spec is None or str(spec).strip() == "":
            continue
        col = mapped(columns, str(spec), role, where)
        if col.index in taken:
            raise InputError(f"{where}: --columns names column {quoted(col.label)} for both "
                             f"{taken[col.index]} and {role}")
        taken[col.index] = role
        cands[role] = [col]
    for col in columns:
        if col.role is not None and col.role not in mapping and col.index not in taken:
            cands[col.role].append(col)
    return cands


def choose(columns: list[Column], mapping: dict, kind: str | None, file_kind: str | None,
           where: str) -> Choice:
    """Pick the frequency column and one response form (see the module docstring).

    Raises
    ------
    InputError
        If no frequency column or no complete response form is found, or two columns could
        play the same part (two storage moduli, G' and E', two angular frequencies), or the
        columns contradict ``kind`` (compliance columns with kind modulus and vice versa).
    """
    cands = candidates(columns, mapping, where)
    hint = ("name the columns with --columns (columns= in the API), e.g. --columns "
            "omega=\"Ang. Freq.\",storage=\"G'\",loss=\"G''\"")
    omega, freq = cands["omega"], cands["freq"]
    for role, cols in (("omega", omega), ("freq", freq)):
        if len(cols) > 1:
            raise InputError(f"{where}: columns {_names(cols)} could each be the "
                             f"{'angular frequency' if role == 'omega' else 'frequency'}; {hint}")
    if not omega and not freq:
        raise NotResponse(f"{where}: no frequency column among {_names(columns[:30])}: need an "
                         f"angular frequency [rad/s] or a frequency [Hz]; {hint}")
    if omega:
        frequency, check = omega[0], (freq[0] if freq and "freq" not in mapping
                                      and "omega" not in mapping else None)
    else:
        frequency, check = freq[0], None

    wanted_kind = kind if kind is not None else file_kind
    order = ((_C, _ANY, _M) if wanted_kind == "compliance" else (_M, _ANY, _C))
    mapped_roles = {r for r, s in mapping.items() if s not in (None, "") and
                    r in _QUANTITY_ROLES + _FREE_ROLES}
    options = []
    for quantity in order:
        for form, roles in _FORMS[quantity]:
            if not mapped_roles <= set(roles):
                continue
            picked = {}
            for role in roles:
                cols = cands[role]
                if role in _QUANTITY_ROLES:
                    cols = [c for c in cols if c.quantity == quantity]
                picked[role] = cols
            if all(picked.values()):
                options.append((quantity, form, picked))
    if not options:
        _refuse_mixed_units(cands, mapping, where)
        raise NotResponse(f"{where}: no response columns among {_names(columns[:30])}: need "
                         "storage and loss modulus (G', G'' or E', E''), storage and loss "
                         "compliance (J', J''), |G*| with the phase angle or tan δ, complex "
                         f"viscosity with the phase angle or tan δ, or real and imag; {hint}")
    quantity, form, picked = options[0]
    for role, cols in picked.items():
        if len(cols) > 1:
            raise InputError(f"{where}: columns {_names(cols)} could each be the {role} "
                             f"column; {hint}")
    response = {role: cols[0] for role, cols in picked.items()}
    for col in (frequency, check, *response.values()):
        if col is not None and col.unit_text and col.unit is None:
            _unknown_unit(col, col.role, where)
    used = {c.index for c in response.values()}
    others = tuple(f"{f} ({_names(c[0] for c in p.values())})" for q, f, p in options[1:]
                   if not {c[0].index for c in p.values()} <= used)
    kind, reason = _kind(quantity, form, response, kind, file_kind, where)

    def one(role):
        cols = cands[role]
        if len(cols) > 1 and role in ("sigma", "series", "block"):
            raise InputError(f"{where}: columns {_names(cols)} could each be the {role} "
                             f"column; {hint}")
        return cols[0] if cols else None

    chosen = {r: one(r) for r in ("temperature", "block", "sigma", "series")}
    for role in ("temperature", "sigma"):
        col = chosen[role]
        if col is not None and col.unit_text and col.unit is None:
            _unknown_unit(col, role, where)
    return Choice(frequency, form, response, quantity, kind, reason, others, check,
                  chosen["temperature"], chosen["block"], chosen["sigma"], chosen["series"])


def _refuse_mixed_units(cands: dict, mapping: dict, where: str) -> None:
    """Refuse, by name, the two parts of a response of which ``columns`` gave one a unit and
    the other none or one of another quantity (``real="real [kPa]"`` beside a bare ``imag``):
    they would be read in different units."""
    for pair in (("storage", "loss"), ("real", "imag")):
        cols = [cands[r][0] if len(cands[r]) == 1 else None for r in pair]
        if None in cols or not any(mapping.get(r) for r in pair):
            continue
        a, b = cols
        if a.quantity == b.quantity:
            continue
        unit = next(c.unit_text for c in cols if c.quantity in (_M, _C))

        def what(c):
            return f"in {quoted(c.unit_text)}" if c.unit_text else "without a unit"

        text = (f"{where}: the {pair[0]} column {quoted(a.name)} is {what(a)} but the {pair[1]} "
                f"column {quoted(b.name)} is {what(b)}; both parts of the response must be in "
                "one unit: give both, e.g. ")
        raise InputError(
            text + f"columns={{{pair[0]!r}: '{a.name} [{unit}]', {pair[1]!r}: "
                   f"'{b.name} [{unit}]'}}",
            command_line=text + f'--columns {pair[0]}="{a.name} [{unit}]",'
                                f'{pair[1]}="{b.name} [{unit}]"')


def _unknown_unit(col: Column, role: str, where: str) -> None:
    raise InputError(
        f"{where}, column {quoted(col.label)}: unit {quoted(col.unit_text)} is not one bayesfo "
        "converts (rad/s, 1/s, Hz, Pa, kPa, MPa, GPa, 1/Pa, 1/MPa, Pa s, mPa s, deg, rad, °C, K, "
        f"...); give the column with a unit it knows, e.g. --columns {role}=\"{col.name} [Pa]\" "
        "(columns= in the API)")


def _kind(quantity, form, response, kind, file_kind, where) -> tuple[str, str]:
    cols = _names(response.values())
    letters = {c.letter for c in response.values() if c.letter}
    symbol = {"G": "shear", "E": "tensile", "J": "shear", "D": "tensile"}
    if quantity in (_M, _C):
        what = " ".join(x for x in (symbol.get(next(iter(letters)), "") if len(letters) == 1
                                    else "", quantity) if x)
        if kind is not None and kind != "generic" and kind != quantity:
            other = "compliance" if quantity == _M else "modulus"
            raise InputError(
                f"{where}: kind {kind} was asked, but columns {cols} are a {what}; read them "
                f"as --kind {quantity} (the default) and add --reciprocal to compare the "
                f"{other} 1/G, or name {kind} columns with --columns")
        if kind is not None:
            return kind, f"kind {kind} as asked (columns {cols} are a {what})"
        if file_kind is not None and file_kind != quantity:
            raise InputError(f"{where}: the file's '# kind: {file_kind}' line contradicts "
                             f"columns {cols}, which are a {what}")
        return quantity, f"kind {quantity}: columns {cols} are a {what}"
    if kind is not None:
        return kind, f"kind {kind} as asked"
    if file_kind is not None:
        return file_kind, f"kind {file_kind} from the file's '# kind:' line"
    if form == "storage/loss":
        return "modulus", (f"kind modulus: storage and loss columns ({cols}) are the parts of a "
                           "modulus (G', G''); for a compliance J', J'' give --kind compliance")
    return "generic", (f"kind generic: columns {cols} do not say whether the response is a "
                       "modulus or a compliance; give --kind to say")
