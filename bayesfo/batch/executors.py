"""Where the data sets run: in this process, in local worker processes, or on a Dask cluster;
:func:`run_batch` resumes, runs and stores."""

from __future__ import annotations

import os
import sys
import time
from concurrent.futures import FIRST_COMPLETED, wait

from ..errors import InputError, OutputError
from ..outdir import check_output_directory
from ..parallel import check_workers, new_pool, terminate, worker_environment
from .store import BatchResult, Outcome, _lost, _store, _stored_rows, write_batch_outputs
from .task import INPUT_ERROR, OK, run_task

#: Seconds to wait for a Dask scheduler to answer.
SCHEDULER_TIMEOUT = 15.0


def _run_in_process(todo, on_result):
    for ds in todo:
        on_result(ds, run_task(ds.task()))


def _run_pool(todo, workers, on_result, task=run_task) -> list:
    """Run ``task`` (:func:`run_task`) on ``todo`` in one pool of ``workers`` processes; return
    the data sets whose pool broke (a worker died) before they finished, each with the
    exception."""
    from concurrent.futures.process import BrokenProcessPool


    broken = []
    with worker_environment():  # processes are spawned while tasks are submitted
        pool = new_pool(workers)
        try:
            futures = {pool.submit(task, ds.task()): ds for ds in todo}
            pending = set(futures)
            while pending:
                done, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    ds = futures.pop(fut)  # drop the future and its output files once stored
                    try:
                        result = fut.result()
                    except BrokenProcessPool as exc:
                        broken.append((ds, exc))
                        continue
                    except Exception as exc:  # e.g. a result that cannot be unpickled
                        result = _lost(ds, exc)
                    on_result(ds, result)
                del done
        except BaseException:
            terminate(pool)
            raise
        if broken:
            terminate(pool)
        else:
            pool.shutdown(wait=True)
    return broken


def _run_processes(todo, workers, on_result, task=run_task):
    """Run the data sets in worker processes. When a worker dies (killed, out of memory, a
    crash in native code), the pool breaks and every unfinished data set is run again in a new
    pool; if that breaks too, the rest run one by one, each in a pool of its own, so that only
    the data set whose worker dies is recorded as failed."""
    broken = _run_pool(todo, workers, on_result, task)
    if broken:
        broken = _run_pool([ds for ds, _ in broken], min(workers, len(broken)), on_result, task)
    for ds, _ in broken:
        again = _run_pool([ds], 1, on_result, task)
        for ds_, exc in again:
            on_result(ds_, _lost(ds_, exc, "its worker process died in each of three attempts "
                                           "(killed, out of memory, or a crash in native code)"))


def _dask_client(scheduler):
    """A connected :class:`distributed.Client` and whether we own it."""
    if hasattr(scheduler, "submit"):  # a Client given by the caller
        return scheduler, False
    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler needs dask.distributed: pip install 'bayesfo[cluster]' "
                         "(or pip install distributed)") from None
    try:
        client = Client(scheduler, timeout=SCHEDULER_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"--scheduler: cannot reach the Dask scheduler at '{scheduler}': "
                         f"{type(exc).__name__}: {exc}") from None
    return client, True


def _run_dask(todo, client, on_result):
    from distributed import as_completed

    futures = {}
    for ds in todo:
        fut = client.submit(run_task, ds.task(), pure=False,
                            key=f"bayesfo-batch-{ds.id}-{os.urandom(4).hex()}")
        futures[fut] = ds
    try:
        for fut in as_completed(list(futures), loop=client.loop):
            ds = futures.pop(fut)
            try:
                result = fut.result()
            except Exception as exc:  # KilledWorker, lost connection
                result = _lost(ds, exc)
            fut.release()  # the cluster may forget the output files
            on_result(ds, result)
    except BaseException:
        client.cancel(list(futures))
        raise


def run_batch(datasets, out_dir, *, workers: int | None = None, scheduler=None,
              progress: bool | None = None, write_combined: bool = True) -> BatchResult:
    """Compare the structures on every data set; resume, record failures, write the tables.

    Parameters
    ----------
    datasets : sequence of DataSet
        From :func:`expand_inputs`.
    out_dir : path-like
        Output directory (created); one sub-directory per data set.
    workers : int, optional
        Local worker processes, each running one data set at a time (default, or 0: one per
        available CPU), at most one per data set to run; 1 runs in this process. Not with
        ``scheduler``. A script that calls this with several workers needs the usual
        ``if __name__ == "__main__":`` guard (the workers are spawned).
    scheduler : str or distributed.Client, optional
        Address of a Dask scheduler (``tcp://host:8786``), or a connected client, to run the
        tasks on a Dask cluster instead.
    progress : bool, optional
        A progress bar over data sets (default: when stderr is a terminal).
    write_combined : bool
        Write ``batch_summary.csv``, the temperature table and the figures
        (:func:`write_batch_outputs`).

    Returns
    -------
    BatchResult

    Raises
    ------
    InputError
        For a bad ``workers``, both ``workers`` and ``scheduler``, duplicate ids, distributed
        not installed or a scheduler that cannot be reached. Failures of data sets are not
        raised: they are in the result.
    """
    from tqdm.auto import tqdm

    t0 = time.perf_counter()
    datasets = list(datasets)
    ids = [ds.id.lower() for ds in datasets]
    if len(set(ids)) != len(ids):
        raise InputError("two data sets have the same id")
    if workers is not None and scheduler is not None:
        raise InputError("--workers applies to local processes; with --scheduler the Dask "
                         "cluster's workers run the tasks")
    if workers is not None:
        check_workers(workers, "--workers")
    out_dir = check_output_directory(out_dir)

    outcomes: dict[str, Outcome] = {}
    fingerprints = {}
    todo = []
    for ds in datasets:
        fingerprints[ds.id] = fp = ds.fingerprint()
        if ds.error is not None:
            outcomes[ds.id] = _store(ds, {"id": ds.id, "status": INPUT_ERROR, "error": ds.error,
                                          "files": {}, "warnings": []}, out_dir, fp)
        elif (rows := _stored_rows(ds, out_dir, fp)) is not None:
            outcomes[ds.id] = Outcome(ds, OK, None, True, rows)
        else:
            todo.append(ds)

    if progress is None:
        progress = sys.stderr.isatty()
    bar = tqdm(total=len(datasets), initial=len(datasets) - len(todo), desc="data sets",
               unit="set", disable=not progress, leave=False)

    def on_result(ds, result):
        outcomes[ds.id] = _store(ds, result, out_dir, fingerprints[ds.id])
        bar.update(1)

    try:
        if not todo:
            executor = "none (every data set complete)"
        elif scheduler is not None:
            client, own = _dask_client(scheduler)
            try:
                executor = f"dask ({client.scheduler.address})"
                _run_dask(todo, client, on_result)
            finally:
                if own:
                    client.close()
        else:
            from ..parallel import available_cpus

            n = min(workers or available_cpus(), len(todo))
            if n == 1:
                executor = "in-process"
                _run_in_process(todo, on_result)
            else:
                executor = f"processes ({n})"
                _run_processes(todo, n, on_result)
    except OutputError as exc:
        # The output directory cannot take more (no space left, ...): the batch stops, the
        # data sets finished so far stay, and the summary lists them if it can be written.
        done = [outcomes[ds.id] for ds in datasets if ds.id in outcomes]
        listed = ""
        if write_combined and done:
            order = list(dict.fromkeys(n for ds in datasets for n in ds.options["structures"]))
            try:
                write_batch_outputs([r for o in done for r in o.rows], out_dir, order,
                                    _combined_formats(datasets))
                listed = ", listed in batch_summary.csv"
            except OSError:
                pass
        raise OutputError(f"{exc}; the batch stopped after {len(done)} of {len(datasets)} data "
                          f"sets, whose outputs are kept{listed}; free space and run the same "
                          "command again: it resumes") from None
    finally:
        bar.close()

    ordered = tuple(outcomes[ds.id] for ds in datasets)
    written = {}
    if write_combined:
        order = list(dict.fromkeys(n for ds in datasets for n in ds.options["structures"]))
        written = write_batch_outputs([r for o in ordered for r in o.rows], out_dir, order,
                                      _combined_formats(datasets))
    return BatchResult(out_dir, ordered, executor, time.perf_counter() - t0, written)


def _combined_formats(datasets) -> tuple[str, ...]:
    """The file formats of the combined figures: those the data sets' figures are asked in
    (``--figure-formats``, PNG by default)."""
    from ..options import DEFAULT_OPTIONS

    default = DEFAULT_OPTIONS["figure_formats"]
    out: dict[str, None] = {}
    for ds in datasets:
        out.update(dict.fromkeys(ds.options.get("figure_formats") or default))
    return tuple(out) or default
