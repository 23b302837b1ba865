"""Measured frequency responses: the :class:`FrequencyResponse` container, the reader of the CSV
contract (:func:`read_csv`) and the tolerant reader of lab files (:func:`read`,
:func:`read_isotherms`: rheometer and DMA exports, units, delimiters, temperature columns; see
``docs/lab_files.md``).

A frequency response is a set of angular frequencies ω [rad/s] with the complex value G(jω) of a
transfer function at each, and optionally the standard deviation σ of each complex value. The
CSV contract (see DESIGN.md) is:

* a header row, comma separated, ``#`` comment lines allowed anywhere;
* a frequency column ``omega`` [rad/s] or ``freq`` [Hz];
* the response as ``real``, ``imag`` or ``magnitude``, ``phase_deg`` or ``storage``, ``loss``;
* optionally ``sigma`` (standard deviation of the complex value) and ``series`` (an identifier of
  a replicate series: replicates are averaged per frequency, and σ is estimated from their spread).

Comment lines of the form ``# kind: modulus``, ``# units: MPa``, ``# name: PP sample 3`` or
``# symbol: E`` (the measured quantity's letter: G shear or E tensile modulus, J or D their
compliances, :mod:`~bayesfo.data.symbols`) set the metadata of the response. Lab files give the
letter by their column names (``E'``, ``E_stor``, ``Tensile storage modulus``).

Limits
------
The reader refuses, naming the file, line and column, what cannot be computed in double
precision or in reasonable time (see :func:`read_csv` for the reasons):

* ω from 1e-30 to 1e30 rad/s and |G| from 1e-30 to 1e30 (never exactly 0), each spanning at
  most 30 decades within one data set (:data:`VALUE_RANGE`, :data:`MAX_SPAN`);
* σ at most 100 times the largest |G| and at least 1e-15 times |G| on its line
  (:data:`SIGMA_MAX_RATIO`, :data:`SIGMA_MIN_RATIO`);
* phases within ±360 degrees (:data:`MAX_PHASE_DEG`);
* at most 1000 frequencies (:data:`MAX_FREQUENCIES`), 100 000 data rows and 32 MiB;
* numbers in plain ASCII decimal notation (no ``1_0``, no ``inf``/``nan``), no invisible
  control characters, and only regular files (not a FIFO).
"""

from .csv_reader import (
                         FREQUENCY_COLUMNS,
                         KNOWN_COLUMNS,
                         MAX_FILE_BYTES,
                         MAX_FREQUENCIES,
                         MAX_PHASE_DEG,
                         MAX_ROWS,
                         MAX_SPAN,
                         OPTIONAL_COLUMNS,
                         RESPONSE_FORMS,
                         SIGMA_MAX_RATIO,
                         VALUE_RANGE,
                         read_csv,
)
from .frequency_response import FREQUENCY_RTOL, KINDS, SIGMA_MIN_RATIO, FrequencyResponse
from .lab import DUPLICATES, columns_from_text, is_contract_csv, read, read_isotherms, select
from .reading import Isotherm, Reading, contract_text

__all__ = ["FREQUENCY_COLUMNS", "FREQUENCY_RTOL", "KINDS", "KNOWN_COLUMNS", "MAX_FILE_BYTES",
           "MAX_FREQUENCIES", "MAX_PHASE_DEG", "MAX_ROWS", "MAX_SPAN", "OPTIONAL_COLUMNS",
           "RESPONSE_FORMS", "SIGMA_MAX_RATIO", "SIGMA_MIN_RATIO", "VALUE_RANGE",
           "DUPLICATES", "FrequencyResponse", "Isotherm", "Reading", "columns_from_text",
           "contract_text", "is_contract_csv", "read", "read_csv", "read_isotherms", "select"]
