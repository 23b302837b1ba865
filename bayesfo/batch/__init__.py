"""Many data sets: :func:`~bayesfo.comparison.compare` on each, on local processes or a Dask cluster.

``bayesfo batch INPUT... --out DIR`` expands its inputs (files, directories of ``*.csv``, glob
patterns, manifests) into data sets, runs the comparison of each in a worker, and writes

* ``DIR/<id>/`` per data set: what ``bayesfo compare`` writes (``summary.json``, ``ranking.csv``,
  one NetCDF per structure, and unless ``--no-figures`` the figures and ``report.html``), plus
  ``batch.json`` (the task: data-file hash, options, seed, bayesfo version; the status,
  warnings and timings) and, for a data set that failed, ``error.txt``;
* ``DIR/batch_summary.csv``: one row per data set and structure (ln Z, posterior probability,
  criteria, posterior of q), and one row with the error for a data set that failed;
* ``DIR/batch_summary.png`` (and the other ``--figure-formats``): the posterior model
  probabilities and the posterior of q per data set;
* when the data sets have temperatures (isotherms), ``DIR/temperature_summary.csv`` and
  ``DIR/temperature_q.png`` (and the other formats): the posterior of q (mean, 94 % HDI)
  against temperature per structure, and the best structure at each temperature.

Design
------
*Tasks are plain data.* A task is a dict of the data file's path and bytes, the options and the
seed; the worker (:func:`run_task`) reads the CSV itself, runs the comparison, writes its outputs
into a private temporary directory and returns their bytes. Only the client process writes into
``DIR``, each file through a temporary file and a rename, ``summary.json`` after the NetCDF files
and ``batch.json`` last, so workers need no shared file system and an interrupted run never
leaves a data set that looks complete but is not.

*Resume.* A data set is complete when ``DIR/<id>/batch.json`` records status ``ok`` for the same
task (SHA-256 of the data file, options, seed, bayesfo version) and the files it lists exist. A
re-run reads such data sets back from their ``summary.json`` and runs the others, including
those that failed before.

*Failures are per data set.* Bad input (:class:`~bayesfo.errors.InputError`: an unreadable file,
a bad cell, too few points for every structure) and internal errors are caught in the worker
and recorded in ``error.txt``, ``batch.json`` and the summary table; a worker that dies is
recorded the same way. The others always finish.

*Seeds.* Every data set runs with the same seed (the ``--seed`` of the command, or its
manifest's ``seed`` cell), so numbers do not depend on the number of workers, on the executor or
on the order in which tasks finish, and ``DIR/<id>/`` holds what ``bayesfo compare FILE --seed N``
would write for that file.

*Executors.* ``workers=1``: in this process. ``workers > 1``: a
:class:`concurrent.futures.ProcessPoolExecutor` with the ``spawn`` start method, one
single-threaded BLAS per worker. ``scheduler=ADDRESS``: a :class:`distributed.Client` connected to
a running Dask scheduler (``client.submit`` and ``distributed.as_completed``); workers should run
one thread each (``dask worker ADDRESS --nthreads 1``), as the comparison holds the GIL most of
the time and its warnings are captured per process. With ``--models``, the card paths must be
readable on the workers.
"""

from ..data.temperature import parse_temperature, temperature_from_stem, temperature_of_file
from .datasets import COMBINED_FILES, MANIFEST_COLUMNS, DataSet, expand_inputs
from .executors import SCHEDULER_TIMEOUT, run_batch
from .store import (
                    BATCH_FIELDS,
                    TEMPERATURE_FIELDS,
                    BatchResult,
                    Outcome,
                    batch_summary_csv,
                    summary_rows,
                    temperature_rows,
                    write_batch_outputs,
)
from .task import INPUT_ERROR, INTERNAL_ERROR, OK, run_task

__all__ = ["BATCH_FIELDS", "COMBINED_FILES", "INPUT_ERROR", "INTERNAL_ERROR", "MANIFEST_COLUMNS",
           "OK", "SCHEDULER_TIMEOUT", "TEMPERATURE_FIELDS", "BatchResult", "DataSet", "Outcome",
           "batch_summary_csv", "expand_inputs", "parse_temperature", "run_batch", "run_task",
           "summary_rows", "temperature_from_stem", "temperature_of_file", "temperature_rows",
           "write_batch_outputs"]
