"""What becomes of each data set: its directory in the output directory (stored as one unit),
its rows of the summary tables, and the combined tables and figures."""

from __future__ import annotations

import csv
import io
import json
import time
from dataclasses import dataclass, field
from pathlib import Path

from .._io import atomic_write_text
from ..outdir import changed_file, is_output_path, recover, staged_run
from .datasets import DataSet
from .task import INPUT_ERROR, INTERNAL_ERROR, OK

BATCH_FIELDS = ("dataset", "path", "temperature_C", "status", "structure", "rank", "best",
                "n_params", "log_evidence", "log_evidence_err", "delta_log_evidence",
                "posterior_probability", "loo", "loo_se", "waic", "aic", "aicc", "bic",
                "max_log_likelihood", "rmse", "q_parameter", "q_mean", "q_sd", "q_hdi_low",
                "q_hdi_high", "q_map", "rhat_max", "ess_min", "converged", "pareto_k_max",
                "noise", "kind", "n_frequencies", "sampler", "adequate",
                "max_phase_error_deg", "warnings", "error")


TEMPERATURE_FIELDS = ("temperature_C", "dataset", "structure", "rank", "best", "best_structure",
                      "log_evidence", "log_evidence_err", "posterior_probability", "q_parameter",
                      "q_mean", "q_sd", "q_hdi_low", "q_hdi_high", "converged")


_BATCH_JSON = "batch.json"


_ERROR_TXT = "error.txt"


_FORMAT = 1  # version of batch.json


@dataclass(frozen=True, eq=False)
class Outcome:
    """What became of one data set.

    Attributes
    ----------
    dataset : DataSet
    status : str
        ``"ok"``, ``"input_error"`` or ``"internal_error"``.
    error : str or None
    reused : bool
        Complete from an earlier run (not recomputed).
    rows : tuple of dict
        Its rows of ``batch_summary.csv``.
    warnings : tuple of str
    compare_seconds, compare_cpu_seconds, task_seconds : float or None
        Wall and CPU time of the comparison alone, and wall time of the whole task in the
        worker (None when reused).
    """

    dataset: DataSet
    status: str
    error: str | None = None
    reused: bool = False
    rows: tuple = ()
    warnings: tuple = ()
    compare_seconds: float | None = None
    compare_cpu_seconds: float | None = None
    task_seconds: float | None = None


@dataclass(frozen=True, eq=False)
class BatchResult:
    """Result of :func:`run_batch`.

    Attributes
    ----------
    out_dir : Path
    outcomes : tuple of Outcome
        In the order of the data sets.
    executor : str
        ``"in-process"``, ``"processes (N)"``, ``"dask (ADDRESS)"``, or
        ``"none (every data set complete)"``.
    wall_seconds : float
        Wall time of the run, combined outputs included.
    written : dict
        Combined output files by name.
    """

    out_dir: Path
    outcomes: tuple
    executor: str
    wall_seconds: float
    written: dict = field(default_factory=dict)

    @property
    def rows(self) -> list[dict]:
        """The rows of ``batch_summary.csv``."""
        return [row for o in self.outcomes for row in o.rows]

    @property
    def failed(self) -> list[Outcome]:
        return [o for o in self.outcomes if o.status != OK]

    @property
    def exit_status(self) -> int:
        """0 if every data set was compared, 1 if one had an internal error, else 2 if one had
        bad input."""
        statuses = {o.status for o in self.outcomes}
        if INTERNAL_ERROR in statuses:
            return 1
        return 2 if INPUT_ERROR in statuses else 0


#: The columns of ``batch_summary.csv`` that are those of the ranking table
#: (:func:`~bayesfo.comparison.results.ranking_rows`).
_RANKING_COLUMNS = ("rank", "n_params", "log_evidence", "log_evidence_err", "delta_log_evidence",
                    "posterior_probability", "loo", "loo_se", "waic", "aic", "aicc", "bic",
                    "max_log_likelihood", "rmse", "q_mean", "q_sd", "rhat_max", "ess_min",
                    "converged", "pareto_k_max", "sampler", "adequate", "max_phase_error_deg")


def summary_rows(summary: dict) -> list[dict]:
    """Rows of ``batch_summary.csv`` for one data set from its ``summary.json`` (without the
    data-set columns), ranked by ln Z; structures that could not be run come last.

    Each row is the ranking row of the structure (:func:`~bayesfo.comparison.results.ranking_rows`,
    the rows of ``Comparison.table`` and ``ranking.csv``), with what a batch adds: whether it
    is the best, the order parameter's HDI and MAP, the noise model, the data's kind and size
    and the warnings."""
    from ..comparison.table import order_parameter, ranking_rows

    structures = {s["name"]: s for s in summary["structures"]}
    ranking = list(summary.get("ranking", []))
    best = ranking[0] if ranking else None
    data = {"kind": summary["data"].get("kind"),
            "n_frequencies": summary["data"].get("n_frequencies")}
    rows = []
    for table_row in ranking_rows(list(structures.values()), ranking):
        name = table_row["structure"]
        s = structures[name]
        row = {"structure": name, "n_params": table_row["n_params"], **data}
        if "error" in s:
            row["error"] = s["error"]
            rows.append(row)
            continue
        row.update({k: table_row[k] for k in _RANKING_COLUMNS})
        params = s.get("parameters", {})
        q_name = order_parameter(params)
        q = params.get(q_name, {}) if q_name else {}
        row.update(best=name == best, q_parameter=q_name, q_hdi_low=q.get("hdi_low"),
                   q_hdi_high=q.get("hdi_high"), q_map=q.get("map"), noise=s.get("noise"),
                   warnings="; ".join(s.get("warnings", [])),
                   # For the terminal table (not columns of batch_summary.csv): whether the
                   # structure describes the data, and every order by its symbol.
                   fits=table_row.get("fits"), orders=table_row.get("orders") or "",
                   # and for the figures, every order of the natural form (as ``orders``).
                   order_summaries=_order_summaries(s))
        rows.append(row)
    return rows


def _order_summaries(s: dict) -> dict:
    """``{order: {"mean", "hdi_low", "hdi_high"}}`` of every fractional order of a structure
    record in the form natural to the data (none for an integer structure)."""
    from ..comparison.parameters import natural_block
    from ..comparison.table import order_parameters

    if s.get("integer"):
        return {}
    block = natural_block(s)
    out = {}
    for k in order_parameters(block):
        p = block[k] or {}
        if all(p.get(f) is not None for f in ("mean", "hdi_low", "hdi_high")):
            out[k] = {f: p[f] for f in ("mean", "hdi_low", "hdi_high")}
    return out


def _dataset_rows(ds: DataSet, status: str, error: str | None, rows=()) -> tuple:
    head = {"dataset": ds.id, "path": ds.path, "temperature_C": ds.temperature, "status": status}
    if status != OK:
        return ({**head, "error": error},)
    return tuple({**head, **row} for row in rows)


def _csv_text(rows, fields) -> str:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=fields, extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: "" if row.get(k) is None else row.get(k) for k in fields})
    return buf.getvalue()


def batch_summary_csv(rows) -> str:
    """The text of ``batch_summary.csv`` (columns :data:`BATCH_FIELDS`)."""
    return _csv_text(rows, BATCH_FIELDS)


def temperature_rows(rows) -> list[dict]:
    """Rows of ``temperature_summary.csv``: the structures of every compared data set with a
    temperature, by temperature then rank, with the best structure of each data set."""
    out = []
    best = {r["dataset"]: r["structure"] for r in rows if r.get("best")}
    for r in rows:
        if r.get("status") != OK or r.get("temperature_C") is None or r.get("rank") is None:
            continue
        out.append({k: r.get(k) for k in TEMPERATURE_FIELDS if k in r}
                   | {"best_structure": best.get(r["dataset"])}
                   # every order, for the figure (not a column of the csv)
                   | ({"order_summaries": r["order_summaries"]} if "order_summaries" in r
                      else {}))
    return sorted(out, key=lambda r: (r["temperature_C"], r["dataset"], r["rank"]))


def _stored_rows(ds: DataSet, out_dir: Path, fingerprint: dict) -> tuple | None:
    """The rows of a data set whose stored result is complete for ``fingerprint``, else None."""
    sub = out_dir / ds.id
    if sub.is_symlink():  # never followed: its files would lie outside the output directory
        return None
    try:
        recover(sub)  # a swap that an interrupted run left half done
        record = json.loads((sub / _BATCH_JSON).read_text(encoding="utf-8"))
        if (record.get("format") != _FORMAT or record.get("status") != OK
                or record.get("task") != fingerprint):
            return None
        files = record.get("files")
        if not isinstance(files, list) or not all(
                is_output_path(name) and (sub / name).is_file() for name in files):
            return None
        if changed_file(sub) is not None:  # truncated, changed or copied in since
            return None
        summary = json.loads((sub / "summary.json").read_text(encoding="utf-8"))
        return _dataset_rows(ds, OK, None, summary_rows(summary))
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        return None  # not complete (or not readable as bayesfo wrote it): run it again


def _store(ds: DataSet, result: dict, out_dir: Path, fingerprint: dict) -> Outcome:
    """Write a worker's result into ``out_dir/<id>/`` as one unit (:func:`bayesfo.outdir.staged_run`):
    the outputs of an earlier run there are replaced by this one's, ``batch.json`` included."""
    sub = out_dir / ds.id
    files = (result.get("files") or {}) if result["status"] == OK else {}
    for name in files:
        if not is_output_path(name):
            raise ValueError(f"output file name {name!r} leaves the data set's directory")
    if sub.is_symlink():  # a link in the output directory is replaced, never followed
        sub.unlink()
    with staged_run(sub) as stage:
        for name in files:
            target = stage / name
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(files[name])
        if result["status"] == OK:
            summary = json.loads(files["summary.json"].decode("utf-8"))
            rows = _dataset_rows(ds, OK, None, summary_rows(summary))
        else:
            text = f"{result['error']}\n"
            if result.get("traceback"):
                text += "\n" + result["traceback"]
            (stage / _ERROR_TXT).write_text(text, encoding="utf-8")
            rows = _dataset_rows(ds, result["status"], result["error"])
        record = {
            "format": _FORMAT, "id": ds.id, "path": ds.path, "temperature_C": ds.temperature,
            "task": fingerprint, "status": result["status"], "error": result["error"],
            "warnings": result.get("warnings", []), "files": sorted(files),
            "compare_seconds": result.get("compare_seconds"),
            "compare_cpu_seconds": result.get("compare_cpu_seconds"),
            "task_seconds": result.get("task_seconds"), "host": result.get("host"),
            "pid": result.get("pid"), "finished": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        }
        (stage / _BATCH_JSON).write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
    return Outcome(ds, result["status"], result["error"], False, rows,
                   tuple(result.get("warnings", [])), result.get("compare_seconds"),
                   result.get("compare_cpu_seconds"), result.get("task_seconds"))


def _lost(ds: DataSet, exc: BaseException, why: str = "the worker failed") -> dict:
    """The result of a task whose worker failed (died, or lost its connection)."""
    return {"id": ds.id, "status": INTERNAL_ERROR, "files": {}, "warnings": [],
            "error": f"{why}: {type(exc).__name__}: {exc}", "traceback": None}


def write_batch_outputs(result_rows, out_dir, structures=None,
                        formats=("png", "pdf")) -> dict[str, Path]:
    """Write the combined outputs: ``batch_summary.csv`` and its figure, and, when data sets have
    temperatures, ``temperature_summary.csv`` and the figure of q against temperature.

    Each file is written through a temporary file and a rename; ``structures`` orders the
    structures in the figures, ``formats`` are the figures' file formats (none: no figures).
    Returns the written files by name.
    """
    out_dir = Path(out_dir)
    rows = list(result_rows)
    written = {"batch_summary.csv": atomic_write_text(out_dir / "batch_summary.csv",
                                                      batch_summary_csv(rows))}
    trows = temperature_rows(rows)
    if trows:
        written["temperature_summary.csv"] = atomic_write_text(
            out_dir / "temperature_summary.csv", _csv_text(trows, TEMPERATURE_FIELDS))
    if not formats or not any(r.get("status") == OK for r in rows):
        return written
    from ..plotting import save_figure
    from ..plotting.batch import plot_batch_summary, plot_q_temperature

    fig = plot_batch_summary(rows, structures)
    for suffix in formats:
        save_figure(fig, out_dir / f"batch_summary.{suffix}")
        written[f"batch_summary.{suffix}"] = out_dir / f"batch_summary.{suffix}"
    if trows:
        fig = plot_q_temperature(trows, structures)
        for suffix in formats:
            save_figure(fig, out_dir / f"temperature_q.{suffix}")
            written[f"temperature_q.{suffix}"] = out_dir / f"temperature_q.{suffix}"
    return written

