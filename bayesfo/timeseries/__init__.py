"""Time series: sine records → frequency response, and fitted structures in the time domain.

``sine`` (one record: harmonic analysis, nonlinearity) → ``records`` (many record files → a
:class:`~bayesfo.data.FrequencyResponse`); ``timedomain`` simulates fitted structures for
validation (Oustaloup and rational approximations).
"""
