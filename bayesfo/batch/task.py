"""The function a worker runs for one data set: read, compare, return the output files."""

from __future__ import annotations

import os
import socket
import tempfile
import time
import traceback
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..options import parse_priors, sampler_options

#: Status of a data set: compared, bad input, or anything else that went wrong.
OK, INPUT_ERROR, INTERNAL_ERROR = "ok", "input_error", "internal_error"


def _read_task_data(task: dict, read_csv):
    """The data of a task, from the bytes it carries (through a private copy with the file's
    name), with the original path as its source and in error messages."""
    kind = task["options"]["kind"]
    if task.get("content") is None:
        data = read_csv(task["path"], kind=kind)
    else:
        with tempfile.TemporaryDirectory(prefix="bayesfo-batch-") as tmp:
            copy = Path(tmp) / Path(task["path"]).name
            copy.write_bytes(task["content"])
            try:
                data = read_csv(copy, kind=kind)
            except InputError as exc:
                raise InputError(str(exc).replace(str(copy), task["path"])) from None
        data = replace(data, source=task["path"])
    if task.get("notes"):  # how a lab file was read (DataSet.notes)
        data = replace(data, notes=tuple(task["notes"]) + tuple(data.notes))
    return data


def run_task(task: dict) -> dict:
    """Compare the structures on one data set: the function a worker runs.

    Reads the CSV, runs :func:`~bayesfo.comparison.compare`, writes its outputs
    (:func:`~bayesfo.output.write_outputs`) into a private temporary directory and returns them.
    Never raises for a failure of the data set (only for ``KeyboardInterrupt`` and the like).

    Parameters
    ----------
    task : dict
        ``{"id", "path" (absolute), "content" (the file's bytes, or None to read ``path``),
        "options" (see :func:`check_options`), "seed"}``: plain, picklable data, as made by
        :meth:`DataSet.task`.

    Returns
    -------
    dict
        ``id``; ``status`` (``"ok"``, ``"input_error"``, ``"internal_error"``); ``error`` (the
        message, or None); ``traceback`` (internal errors); ``files`` ({file name: bytes}, empty on
        failure; names relative to the data set's directory, e.g. ``figures/bode.png``);
        ``warnings`` (messages raised during the comparison, each once);
        ``compare_seconds`` (wall time of the comparison alone), ``compare_cpu_seconds`` (CPU
        time of the worker process during it: much less than the wall time means the worker
        waited for a core), ``task_seconds`` (the whole task), ``host`` and ``pid``.
    """
    t0 = time.perf_counter()
    out = {"id": task["id"], "status": OK, "error": None, "traceback": None, "files": {},
           "warnings": [], "compare_seconds": None, "compare_cpu_seconds": None,
           "task_seconds": None, "host": socket.gethostname(), "pid": os.getpid()}
    opts = task["options"]
    caught = []
    try:
        with warnings.catch_warnings(record=True) as caught, np.errstate(all="ignore"):
            warnings.simplefilter("always")
            from ..comparison import compare
            from ..data import read_csv
            from ..output import write_outputs
            from ..output.write import preload
            from ..parallel import settle_worker
            from ..structures import default_library, load_library, resolve_structures

            # In a pool's worker, once: what every data set's comparison and outputs use,
            # then frozen out of the garbage collector.
            settle_worker(lambda: preload(opts["figure_formats"] if opts["figures"] else ()))

            data = _read_task_data(task, read_csv)
            if opts["reciprocal"]:
                data = data.reciprocal()
            library = load_library(extra=opts["models"]) if opts["models"] else default_library()
            structures = resolve_structures(list(opts["structures"]), library)
            priors = parse_priors(opts["priors"])
            t1, c1 = time.perf_counter(), time.process_time()
            # One process per data set: the batch runs data sets side by side (and a Dask
            # worker, a daemonic process, could not start compare's own process pool).
            comparison = compare(data, structures, noise=opts["noise"], seed=task["seed"],
                                 priors=priors, progress=False,
                                 evidence=opts["evidence"], sampler=opts["sampler"],
                                 evidence_check=opts["evidence_check"],
                                 sample=opts.get("sample", "needed"),
                                 holdout=list(opts["holdout"]) if opts["holdout"] else None,
                                 workers=1, **sampler_options(opts))
            out["compare_seconds"] = time.perf_counter() - t1
            out["compare_cpu_seconds"] = time.process_time() - c1
            with tempfile.TemporaryDirectory(prefix="bayesfo-batch-") as tmp:
                write_outputs(comparison, tmp, figures=opts["figures"],
                              formats=opts["figure_formats"],
                              structure_figures=opts["structure_figures"])
                # The outputs, without the bookkeeping of the run's own output directory
                # (manifest, lock), which the store writes for the data set's directory.
                out["files"] = {f.relative_to(tmp).as_posix(): f.read_bytes()
                                for f in sorted(Path(tmp).rglob("*"))
                                if f.is_file() and not f.name.startswith(".bayesfo-")}
    except InputError as exc:
        out.update(status=INPUT_ERROR, error=str(exc), files={})
    except Exception as exc:  # recorded per data set: one failure never stops the batch
        out.update(status=INTERNAL_ERROR, error=f"{type(exc).__name__}: {exc}",
                   traceback=traceback.format_exc(), files={})
    seen = []
    for w in caught:
        msg = f"{w.category.__name__}: {w.message}"
        if msg not in seen:
            seen.append(msg)
    out["warnings"] = seen
    out["task_seconds"] = time.perf_counter() - t0
    return out

