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
import math
import queue
import warnings
from concurrent.futures.process import BrokenProcessPool

import numpy as np

from ..errors import InputError
from ..inference import preload_arviz
from ..inference.bound import BOUND_MARGIN, bounded
from ..parallel import settle_worker
from .early import EarlyFits
from .results import StructureResult
from .steps import (
    best_fit,
    best_fits,
    bounded_result,
    conclude,
    fit_and_probe,
    fit_and_screen,
    kept,
    sample_held,
    settle,
)


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
    """Step (1); with a single noise model to sample (and, where the evidence bound applies,
    a posterior promised quick), (2) and (3) follow in the same task. Returns ("result",
    StructureResult) or ("sample", ((fit, screened, noise models), quick, best fits))."""
    if options.sample == "all":
        prepared, quick = fit_and_screen(s, data, options), False
    else:
        prepared, quick = fit_and_probe(s, data, options)
    fit, screened, noises = prepared
    if len(noises) > 1 or _deferred(screened) or (options.sample != "all" and not quick):
        return "sample", (prepared, quick, _bound_of(s, data, fit, options, quick))
    runs = [sample_held(s, data, noises[0], fit, options)]
    return "result", conclude(s, data, fit, screened, runs, options)


def _probe(s, data, options, fitted=None):
    """Step (1) of the automatic schedule (:func:`~.steps.fit_and_probe`) with the best fits
    that bound the structure's ln Z (:func:`_bound_of`): ((fit, screened, noise models),
    quick, best fits or None)."""
    prepared, quick = fit_and_probe(s, data, options, fitted)
    return prepared, quick, _bound_of(s, data, prepared[0], options, quick)


def _bound_of(s, data, fit, options, quick: bool) -> dict | None:
    """``{noise: max ln L}`` that bounds the structure's ln Z (:func:`~.steps.best_fits`,
    polished from the global optimum), where the evidence bound may spare its posterior: not
    with ``sample="all"``, nor where importance sampling promises to certify it quickly (the
    posterior then costs less than the bound)."""
    if options.sample == "all" or quick:
        return None
    try:
        return best_fits(s, data, fit, options)
    except (InputError, ValueError, ArithmeticError, np.linalg.LinAlgError):
        return None  # no bound: the structure is sampled, as without the rule


def _guess(screened) -> float | None:
    """The screen's quick estimate of a structure's ln Z (its best noise model's), or None:
    where it would bound another structure's best fit, that structure's long posterior waits
    for this one's certified ln Z."""
    if screened is None or not screened.quick:
        return None
    return max(q["log_z"] for q in screened.quick.values())


def _certified(result) -> float | None:
    """The ln Z of a result that may bound others: a certified posterior's, less twice its
    Monte Carlo error; None otherwise."""
    post = result.posterior
    if result.error is not None or post is None or not post.converged:
        return None
    z, err = result.log_z, result.log_z_err
    if z is None or not math.isfinite(z):
        return None
    return z - 2.0 * (err if err is not None and math.isfinite(err) else 0.0)


#: In ``outcomes``: a structure the evidence bound has left out (its result is built at the end).
_BOUNDED = ("bounded",)


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


def run_in_pool(pool, structures, data, options, bar, *, here: bool = False,
                record: dict | None = None) -> list:
    """Run the structures' steps as tasks of ``pool``; returns (result, warnings) per structure
    in the order given.

    With ``here``, this process runs every structure's step (1) itself
    (:func:`~bayesfo.comparison.steps.fit_and_probe`) and then steps (2) and (3) of the
    structures whose screen promises a quick certified posterior; only the others' steps go to
    ``pool`` (a :class:`~bayesfo.parallel.LazyPool` then starts no process for a comparison
    that has none), and, once its processes have started (two or more), every step still to
    come. The step-(1) tasks of this process come before its others, so that the long
    structures reach the pool early.

    The evidence bound (``options.sample`` ``"needed"``; :mod:`bayesfo.inference.bound`): a
    structure whose posterior is not promised quick has its best fit under every noise model
    (step 1); before its posterior runs, and whenever a structure's certified ln Z comes in,
    it is left out where its best fit lies more than the margin below the best certified
    ln Z so far (confirmed by a global optimisation under every noise model), and it waits
    while another structure whose quick estimate of ln Z would rule it out is still running
    (the likely leader is certified first). At the end the same rule is applied with the
    final leader, so that which structures are left out does not depend on the order in which
    they ran (a posterior that ran before the leader's ln Z was known is then set aside), and
    the structures left out are re-checked where a sampled structure's draws reached a higher
    log-likelihood than the optimiser found for it: their bounds are raised by that shortfall,
    and those then within the margin are sampled. ``record`` (a dict) receives what was
    decided (``leader``, ``leader_log_evidence``, ``optimiser_shortfall``, ``rechecked``)."""
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
    # The evidence bound: each candidate's best fits (polished; confirmed by a global search
    # when they would rule it out), the fits and step-(1) values kept to the end, the steps
    # held for a likely leader, and what was left out by which leader.
    bests = [None] * n
    confirmed = {}
    fits = [None] * n
    firsts = [None] * n
    guesses = [None] * n
    n_caught = [0] * n
    held = {}  # structure index -> [(what, step and its arguments)]
    bounded_by = {}  # structure index -> (leader index, its certified ln Z)
    forced = set()  # re-checked: sampled whatever the bound
    counted = set()
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

    def count(i):
        # The progress bar counts structures, each once (a re-checked one is not counted again).
        if i not in counted:
            counted.add(i)
            bar.update()

    def leader():
        # (index, certified ln Z) of the best structure concluded so far, or None.
        found = [(z, j) for j, o in enumerate(outcomes) if o is not None and o is not _BOUNDED
                 and (z := _certified(o[0])) is not None]
        return None if not found else max(found)[::-1]

    def rules_out(i, lead, widen=0.0) -> bool:
        # Whether ``lead`` rules structure i out: its polished best fits, then (computed once)
        # those of a global optimisation under every noise model, raised by ``widen``.
        if bests[i] is None or i in forced or lead is None or lead[0] == i:
            return False
        if not bounded(max(bests[i].values()) + widen, lead[1]):
            return False
        if i not in confirmed:
            try:
                found = best_fits(structures[i], data, fits[i], options, search=True)
            except (InputError, ValueError, ArithmeticError, np.linalg.LinAlgError):
                found = {k: math.inf for k in bests[i]}  # not confirmed: sampled
            confirmed[i] = {k: max(v, bests[i].get(k, -math.inf)) for k, v in found.items()}
        return bounded(max(confirmed[i].values()) + widen, lead[1])

    def leave_out(i, lead):
        outcomes[i] = _BOUNDED
        bounded_by[i] = lead
        runs[i] = prepared[i] = None
        held.pop(i, None)
        del caught[i][n_caught[i]:]  # only step (1)'s warnings: those of every order
        count(i)
        for future, (j, _, _) in live.items():
            if j == i:
                future.cancel()

    def try_bound(i) -> bool:
        if outcomes[i] is not None or bests[i] is None:
            return outcomes[i] is _BOUNDED
        lead = leader()
        if rules_out(i, lead):
            leave_out(i, lead)
            return True
        return False

    def holder(i) -> bool:
        # Another structure still running whose quick ln Z would rule this one out.
        top = max(bests[i].values())
        return any(outcomes[j] is None and j != i and guesses[j] is not None
                   and bounded(top, guesses[j]) for j in range(n))

    def release():
        for i in list(held):
            if i not in held:
                continue
            if outcomes[i] is not None:
                held.pop(i, None)
            elif not try_bound(i) and not holder(i):
                for what, args in held.pop(i):
                    submit(i, what, *args, hold=False)

    def submit(i, what, *args, hold=True):
        if what not in ("first", "conclude") and bests[i] is not None:
            if try_bound(i):
                return None
            if hold and (i in held or holder(i)):
                held.setdefault(i, []).append((what, args))
                return None
        if broken or not (in_pool[i] or pool_open()):
            return run_here(i, what, args)
        if cap is None:
            return send(i, what, args)
        rank = _rank(what, quick=not in_pool[i])
        # Among the long posteriors, the structure whose best fit reaches highest first: the
        # likely leader, whose ln Z may spare the others.
        ahead = -max(bests[i].values()) if bests[i] is not None and rank == 0 else 0.0
        heapq.heappush(waiting, (rank, ahead, next(order), i, what, args))
        dispatch()

    def dispatch():
        # Steps go to the workers as they free up, the first by rank, so that a long
        # posterior found late does not wait behind quick steps queued before it.
        while waiting and (broken or len(live) < cap):
            _, _, _, i, what, args = heapq.heappop(waiting)
            if outcomes[i] is not None:  # its structure has ended
                continue
            if what not in ("first", "conclude") and try_bound(i):
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
        count(i)
        for future, (j, _, _) in live.items():
            if j == i:  # e.g. the other noise model's posterior, after an error in one
                future.cancel()
        if held:  # a certified ln Z (or a structure that no longer holds others back)
            release()

    def first_back(i, value):
        # Step (1)'s value: ((fit, screened, noise models), quick, best fits).
        (fit, screened, noises), quick, best = value
        prepared[i] = firsts[i] = (fit, screened, noises)
        fits[i], bests[i], guesses[i] = fit, best, _guess(screened)
        n_caught[i] = len(caught[i])
        return quick

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
            in_pool[i] = not first_back(i, value)
            sample(i)
        elif value[0] == "result":
            end(i, value[1])
        else:
            first_back(i, value[1])
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

    def drain():
        while live or local or waiting or held:
            if held:
                release()
                if not held:
                    continue
            if not (live or local or waiting):
                # Nothing runs: the structure held back whose best fit reaches highest goes on.
                i = max(held, key=lambda j: max(bests[j].values()))
                for what, args in held.pop(i):
                    submit(i, what, *args, hold=False)
                continue
            while True:  # what the pool has finished, without waiting
                try:
                    collect(finished.get_nowait())
                except queue.Empty:
                    break
            dispatch()
            if local:
                _, _, i, what, args = heapq.heappop(local)
                if outcomes[i] is None:
                    if what not in ("first", "conclude") and try_bound(i):
                        continue
                    if pool_open():  # queued here before the workers started
                        submit(i, what, *args)
                    else:
                        if what == "first" and early is not None:
                            args = with_fit(i, args, wait=True)
                        done(i, what, *_task(*args))
            elif live:
                collect(finished.get())

    def settle_bounds() -> bool:
        # The rule with the final leader, and the re-check; True where more is to sample.
        lead = leader()
        if lead is None:
            return False
        for i in range(n):  # posteriors that ran before the leader's ln Z was known
            o = outcomes[i]
            if o is not None and o is not _BOUNDED and o[0].error is None \
                    and rules_out(i, lead):
                leave_out(i, lead)
        out = [i for i in range(n) if outcomes[i] is _BOUNDED]
        if not out:
            return False
        shortfall = 0.0
        for i, o in enumerate(outcomes):
            if o is None or o is _BOUNDED or o[0].posterior is None:
                continue
            post = o[0].posterior
            top = (bests[i] or {}).get(post.noise)
            if top is None:
                top = best_fit(structures[i], data, post.noise, o[0].fit, options)
            if math.isfinite(top) and math.isfinite(post.max_log_likelihood):
                shortfall = max(shortfall, float(post.max_log_likelihood) - top)
        if record is not None:
            record["optimiser_shortfall"] = shortfall
        again = [i for i in out if shortfall > 0 and not rules_out(i, lead, widen=shortfall)]
        for i in again:  # the optimiser missed somewhere: sampled after all
            forced.add(i)
            bounded_by.pop(i)
            outcomes[i] = None
            prepared[i], runs[i], in_pool[i] = firsts[i], {}, True
            if record is not None:
                record.setdefault("rechecked", []).append(structures[i].name)
            sample(i)
        return bool(again)

    try:
        for i in first:
            if here:
                submit(i, "first", _probe, structures[i], data, options)
            else:
                submit(i, "first", _first, structures[i], data, options)
        drain()
        while options.sample != "all" and settle_bounds():
            drain()
    except BaseException:
        for future in live:
            future.cancel()
        raise
    finally:
        if early is not None:
            early.stop()
    lead = leader()
    if record is not None and lead is not None:
        record.update(leader=structures[lead[0]].name, leader_log_evidence=lead[1])
    for i in bounded_by:
        # Stated against the final leader (whichever ruled it out first, which may depend on
        # the order the structures ran in): the rule holds for it too, its ln Z being higher.
        result = bounded_result(structures[i], data, fits[i], confirmed[i],
                                structures[lead[0]].name, lead[1], options, margin=BOUND_MARGIN)
        outcomes[i] = (result, kept(structures[i].name, caught[i]))
    return outcomes
