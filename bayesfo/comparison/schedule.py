"""The steps of a comparison's structures as tasks of an executor
(:func:`bayesfo.parallel.executor`: this process, worker processes, or both).

A structure is run in three steps (:mod:`bayesfo.comparison.steps`): (1) the optimisation and
the noise screen, :func:`~bayesfo.comparison.steps.fit_and_screen`; (2) one posterior per noise
model still in the running, :func:`~bayesfo.comparison.steps.sample_held`; (3) the noise model
chosen by evidence, the evidence and adequacy checks and the result,
:func:`~bayesfo.comparison.steps.conclude`. In one process
(:class:`~bayesfo.parallel.InlineExecutor`) each task runs as it is submitted, so they run one
after the other; with worker processes the parent submits (1) for every
structure, largest first, and as each comes back either has the result (a structure with one
noise model to sample runs (2) and (3) in the task of (1): nothing to ship) or submits (2) for
each noise model at once, and (3) when their posteriors are back. A structure whose screen
cannot choose among the noise models thus costs one posterior on the
comparison's critical path, not two in sequence.

(3) runs in a worker, not in the parent: shipping the two runs to it costs less than the step
itself (the adequacy checks and the evidence check), which in the parent would run one
structure at a time and take a core from the workers (BENCHMARKS.md, "Measurements behind
design choices").

The automatic schedule (``compare(workers=0)``, the command's default; ``here=True`` with a
:class:`~bayesfo.parallel.LazyPool`) starts from the other end: a small job's cost is the
processes, not the arithmetic (a small posterior with ln Z, LOO and adequacy takes less time
than spawning workers that import the libraries: BENCHMARKS.md, "Measurements behind design
choices"). This process runs step (1) of every structure, here with the screen's quick
estimates of every noise model to sample
(:func:`~bayesfo.comparison.steps.fit_and_probe`); where their Pareto k̂ promises that importance
sampling will certify the posterior, it runs (2) and (3) as well, and only the other
structures' (2) and (3) go to the pool, whose processes start with the first of them. Once they
have started (two or more), every step still to come goes to them as well, those queued here
included: this process then only waits, so the comparison never runs more processes than CPUs
while the workers are busy, nor leaves a CPU idle while this process works alone
(BENCHMARKS.md, "Every step goes to the workers once they have started"). The steps for the workers wait here and go to them as
they free up (one queued ahead), the longest first: a posterior without the promise, then the
fits (which find the other long posteriors), then the quick posteriors and the conclusions; a
long posterior found late thus starts before quick steps queued earlier (BENCHMARKS.md,
"The automatic schedule hands the workers the longest steps first"). A wrong promise costs time, never a different number. Where the
pool has a preparation still to run (:meth:`~bayesfo.parallel.LazyPool.prepare`: the command
loads the libraries then), the optimisations begin first, in a process forked from this one
(:mod:`.early`), and each step (1) takes its optimum from there once it has come.

Every step uses the comparison's seed wherever it runs, so the numbers do not depend on the pool
or the worker count. A worker process that dies (killed, out of memory) breaks the pool: its
tasks and every one still waiting are then run in this process, with a warning, so that no
finished structure is lost and the numbers are those of the serial path. Warnings are recorded in the task that raises them and returned with its
value; an :class:`~bayesfo.errors.InputError` in any step gives the structure's
``StructureResult(s, error=...)`` (the first noise model's in the order of the serial path, when
several fail), and its tasks still waiting are cancelled. Tasks are submitted from the parent's
thread (any :class:`concurrent.futures.Executor` will do); the progress bar counts structures.
"""

from __future__ import annotations

import heapq
import itertools
import queue
import warnings
from concurrent.futures.process import BrokenProcessPool

from ..errors import InputError
from ..inference import preload_arviz
from ..parallel import settle_worker
from .early import EarlyFits
from .results import StructureResult
from .steps import conclude, fit_and_probe, fit_and_screen, kept, sample_held, settle


def _task(step, *args):
    """One step in a worker: (value, InputError message or None, warnings as (category,
    message)). A worker process of a pool loads the ArviZ libraries at its first step and
    freezes its objects out of the garbage collector (:func:`~bayesfo.parallel.settle_worker`)."""
    settle_worker(preload_arviz)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            value, error = step(*args), None
        except InputError as exc:
            value, error = None, str(exc)
    return value, error, [(w.category, str(w.message)) for w in caught]


def _first(s, data, options):
    """Step (1); with a single noise model to sample, (2) and (3) follow in the same task.
    Returns ("result", StructureResult) or ("sample", (fit, screened, noise models))."""
    fit, screened, noises = fit_and_screen(s, data, options)
    if len(noises) > 1 or _deferred(screened):
        return "sample", (fit, screened, noises)
    runs = [sample_held(s, data, noises[0], fit, options)]
    return "result", conclude(s, data, fit, screened, runs, options)


def _deferred(screened) -> tuple:
    """The noise models that wait for the leader's ln Z (:func:`~.steps.settle`)."""
    return () if screened is None else screened.deferred


def _rank(what: str, *, quick: bool) -> int:
    """The order in which the automatic schedule hands steps to free workers (lowest first):
    a posterior (``what`` a noise model) of a structure without the quick promise, then a fit
    (``"first"``; it finds the other long posteriors), then quick posteriors and conclusions."""
    if what == "first":
        return 1
    return 0 if what != "conclude" and not quick else 2


def run_in_pool(pool, structures, data, options, bar, *, here: bool = False) -> list:
    """Run the structures' steps as tasks of ``pool``; returns (result, warnings) per structure
    in the order given.

    With ``here``, this process runs every structure's step (1) itself
    (:func:`~bayesfo.comparison.steps.fit_and_probe`) and then steps (2) and (3) of the
    structures whose screen promises a quick certified posterior; only the others' steps go to
    ``pool`` (a :class:`~bayesfo.parallel.LazyPool` then starts no process for a comparison
    that has none), and, once its processes have started (two or more), every step still to
    come. The step-(1) tasks of this process come before its others, so that the long
    structures reach the pool early."""
    n = len(structures)
    finished = queue.SimpleQueue()  # futures done, from the pool's threads to this one
    live = {}  # future -> (structure index, "first", a noise model, or "conclude")
    local = []  # (priority, order, structure index, what, step and its arguments), for here
    outcomes = [None] * n
    caught = [[] for _ in range(n)]
    prepared = [None] * n  # (fit, screened, noise models) once (1) is back
    runs = [{} for _ in range(n)]  # noise model -> (run, error) once its (2) is back
    in_pool = [not here] * n  # where (2) and (3) of each structure run
    order = itertools.count()
    broken = []  # the pool's failure, once a worker died
    # On the automatic schedule the steps for the workers wait here (``waiting``, by rank)
    # until fewer than ``cap`` are with the executor: one per worker and one queued ahead,
    # which a worker starts without waiting for this process to send it (the executor's own
    # queue is first come, first served); elsewhere they go to the executor as they come.
    waiting = []  # (rank, order, structure index, what, step and its arguments)
    cap = pool.workers + 1 if here else None
    # Larger structures first (they take longest); results keep the order given.
    first = sorted(range(n), key=lambda i: -structures[i].n_params)
    early = None
    if here and not getattr(pool, "prepared", True):
        # The optimisations begin in a process forked before this one loads the libraries
        # that the pool's workers share (LazyPool.prepare).
        early = EarlyFits.start([structures[i] for i in first], data, options)
        pool.prepare()

    def with_fit(i, args, *, wait):
        # Step (1) with the optimum of the early process where it has come; when a worker
        # would wait for it, the workers have overtaken that process, which is then ended.
        fitted = early.take(structures[i].name, wait=wait)
        if fitted is None and not wait:
            early.stop()
        return args if fitted is None else (*args, fitted)

    def run_here(i, what, args):
        # Step (1) first; otherwise first come, first run.
        heapq.heappush(local, (what != "first", next(order), i, what, args))

    def pool_open():
        # Once a long structure has started the workers (two or more), every step still to
        # come goes to them too: this process would otherwise compute beside them, one process
        # more than CPUs while they are busy and one CPU idle once they are not.
        return here and not broken and pool.started and pool.workers > 1

    def submit(i, what, *args):
        if broken or not (in_pool[i] or pool_open()):
            return run_here(i, what, args)
        if cap is None:
            return send(i, what, args)
        rank = _rank(what, quick=not in_pool[i])
        heapq.heappush(waiting, (rank, next(order), i, what, args))
        dispatch()

    def dispatch():
        # Steps go to the workers as they free up, the first by rank, so that a long
        # posterior found late does not wait behind quick steps queued before it.
        while waiting and (broken or len(live) < cap):
            _, _, i, what, args = heapq.heappop(waiting)
            if outcomes[i] is not None:  # its structure has ended
                continue
            if broken:
                run_here(i, what, args)
            else:
                send(i, what, args)

    def send(i, what, args):
        if what == "first" and early is not None:
            args = with_fit(i, args, wait=False)
        try:
            future = pool.submit(_task, *args)
        except BrokenProcessPool as exc:
            lost(exc)
            return run_here(i, what, args)
        live[future] = (i, what, args)
        future.add_done_callback(finished.put)

    def lost(exc):
        if not broken:
            broken.append(exc)
            warnings.warn("a worker process ended unexpectedly (killed or out of memory); the "
                          "structures it and the other workers still held are run in this "
                          "process", RuntimeWarning, stacklevel=4)

    def end(i, result):
        outcomes[i] = (result, kept(structures[i].name, caught[i]))
        runs[i] = prepared[i] = None
        bar.update()
        for future, (j, _, _) in live.items():
            if j == i:  # e.g. the other noise model's posterior, after an error in one
                future.cancel()

    def sample(i):
        # Step (2) of every noise model to sample now; the leader's run also finds whether the
        # deferred ones can be set aside (steps.settle).
        fit, screened, noises = prepared[i]
        for noise in noises:
            submit(i, noise, sample_held, structures[i], data, noise, fit, options,
                   _deferred(screened) if noise == noises[0] else ())

    def after_sample(i):
        s, (fit, screened, noises) = structures[i], prepared[i]
        for noise in noises:  # in order, so the error reported is the serial path's
            if noise not in runs[i]:
                return
            if runs[i][noise][1] is not None:
                return end(i, StructureResult(s, error=runs[i][noise][1]))
        if _deferred(screened):
            screened, rest = settle(screened, runs[i][noises[0]][0])
            if rest:  # not set aside: sampled after all
                prepared[i] = (fit, screened, [*noises, *rest])
                for noise in rest:
                    submit(i, noise, sample_held, s, data, noise, fit, options)
                return None
        submit(i, "conclude", conclude, s, data, fit, screened,
               [runs[i][noise][0] for noise in noises], options)

    def done(i, what, value, error, new):
        if outcomes[i] is not None:  # its structure has ended
            return
        if what not in ("first", "conclude"):  # a posterior: its warnings are in the run
            runs[i][what] = (value, error)
            return after_sample(i)
        caught[i].extend(new)
        if error is not None:
            end(i, StructureResult(structures[i], error=error))
        elif what == "conclude":
            end(i, value)
        elif here:
            prepared[i], quick = value
            in_pool[i] = not quick
            sample(i)
        elif value[0] == "result":
            end(i, value[1])
        else:
            prepared[i] = value[1]
            sample(i)

    def collect(future):
        i, what, args = live.pop(future)
        if future.cancelled() or outcomes[i] is not None:  # its structure has ended
            return
        try:
            value = future.result()
        except BrokenProcessPool as exc:  # its worker died: the task runs here instead
            lost(exc)
            return run_here(i, what, args)
        done(i, what, *value)

    try:
        for i in first:
            if here:
                submit(i, "first", fit_and_probe, structures[i], data, options)
            else:
                submit(i, "first", _first, structures[i], data, options)
        while live or local or waiting:
            while True:  # what the pool has finished, without waiting
                try:
                    collect(finished.get_nowait())
                except queue.Empty:
                    break
            dispatch()
            if local:
                _, _, i, what, args = heapq.heappop(local)
                if outcomes[i] is None:
                    if pool_open():  # queued here before the workers started
                        submit(i, what, *args)
                    else:
                        if what == "first" and early is not None:
                            args = with_fit(i, args, wait=True)
                        done(i, what, *_task(*args))
            elif live:
                collect(finished.get())
    except BaseException:
        for future in live:
            future.cancel()
        raise
    finally:
        if early is not None:
            early.stop()
    return outcomes
