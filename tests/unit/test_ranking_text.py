"""The ranking in text (bayesfo.comparison.table.ranking_lines): one renderer for the command
and Comparison.summary, aligned whatever the size of its numbers."""

from __future__ import annotations

from bayesfo.comparison.table import ranking_lines


def _row(rank, name, log_z, *, method="importance", orders="", error=None):
    return {"rank": rank, "structure": name, "n_params": 3, "log_evidence": log_z,
            "log_evidence_err": 0.05, "evidence_method": method, "delta_log_evidence": 0.0,
            "posterior_probability": 0.5, "loo": -20.0, "bic": 45.5, "orders": orders,
            "rhat_max": 1.001, "converged": True, "fits": "no", "error": error}


def _ends(line: str) -> list[int]:
    """Where each right-aligned cell ends: the index after each run of non-blanks."""
    return [i + 1 for i in range(len(line)) if line[i] != " " and (i + 1 == len(line)
                                                                   or line[i + 1] == " ")]


def test_a_huge_log_evidence_widens_its_column_and_keeps_the_others_aligned():
    rows = [_row(1, "zener", -12.5, orders="q 0.412 [0.400–0.424]"),
            _row(2, "voigt-int", -12783543861852.73, method="ladder")]
    header, first, second = ranking_lines(rows)
    assert "-12783543861852.73 ± 0.05 L" in second
    assert len(header) == len(first) == len(second)
    # Every column after ln Z ends at the same place in the three lines.
    for right in ("dlnZ", "P", "elpd_loo", "BIC", "R-hat", "ok", "fits"):
        end = header.index(right) + len(right)
        assert first[end - 1] != " " and second[end - 1] != " ", right
        assert end in _ends(first) and end in _ends(second), right
    assert "q 0.412" in first and first.split()[-1] == "NO"


def test_the_default_widths_are_kept_for_ordinary_numbers():
    header, line = ranking_lines([_row(1, "zener", -12.5)])
    assert header == (" # structure         k               ln Z     dlnZ      P   elpd_loo "
                      "       BIC orders (mean)  R-hat  ok   fits")
    assert line.startswith(" 1 zener             3    -12.50 ± 0.05       0.00  0.500")


def test_a_structure_that_failed_is_listed_last_with_its_reason():
    rows = [_row(1, "zener", -12.5), _row(None, "a-very-long-structure-name", None,
                                         error="nothing admissible")]
    lines = ranking_lines(rows)
    assert lines[-1].endswith("failed: nothing admissible")
    assert lines[-1].startswith(" - a-very-long-structure-name")
    assert lines[1].index(" 3 ") == lines[-1].index(" 3 ")
