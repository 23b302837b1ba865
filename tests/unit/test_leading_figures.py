"""Which structures get corner figures by default (``structure_figures="leading"``)."""

import math
from types import SimpleNamespace

import pytest

from bayesfo.errors import InputError
from bayesfo.plotting.output import _detailed, leading


def _result(name, log_z, loo=0.0, waic=0.0, aic=0.0, bic=0.0, error=None):
    return SimpleNamespace(name=name, error=error, log_z=log_z, criteria=SimpleNamespace(
        loo=loo, waic=waic, aic=aic, bic=bic))


def _comparison(*results):
    ranked = sorted((r for r in results if r.error is None),
                    key=lambda r: (r.log_z is None, -(r.log_z or 0.0)))
    return SimpleNamespace(results=list(results), ranking=[r.name for r in ranked])


def _names(results):
    return [r.name for r in results]


def test_the_evidence_rules_out_structures_five_below_the_best():
    # ln Z 4.99 below the best is within the Kass-Raftery "strong" band: it leads; 5.0 below
    # is "very strong" evidence against it: it does not.
    c = _comparison(_result("a", -100.0), _result("b", -104.99), _result("c", -105.0),
                    _result("d", -200.0))
    assert _names(leading(c)) == ["a", "b"]
    assert _names(_detailed(c, "leading")) == ["a", "b"]
    assert _names(_detailed(c, 3)) == ["a", "b", "c"]
    assert _names(_detailed(c, None)) == ["a", "b", "c", "d"]


def test_at_most_three_lead_by_the_evidence():
    c = _comparison(*[_result(n, -100.0 - 0.1 * i) for i, n in enumerate("abcdef")])
    assert _names(leading(c)) == ["a", "b", "c"]


def test_a_structure_that_a_criterion_ranks_first_leads_whatever_its_evidence():
    # PSIS-LOO and WAIC: higher is better; AIC and BIC: lower. NaN never wins.
    c = _comparison(_result("a", -100.0, loo=-50.0, waic=-50.0, aic=10.0, bic=10.0),
                    _result("b", -130.0, loo=-40.0, waic=math.nan, aic=11.0, bic=12.0),
                    _result("c", -140.0, loo=-60.0, waic=-60.0, aic=12.0, bic=9.0),
                    _result("d", -150.0, loo=-70.0, waic=-49.0, aic=math.nan, bic=11.0),
                    _result("e", -160.0, loo=-80.0, waic=-80.0, aic=9.5, bic=13.0))
    assert _names(leading(c)) == ["a", "b", "c", "d", "e"]
    c = _comparison(_result("a", -100.0, loo=-50.0, waic=-50.0, aic=10.0, bic=10.0),
                    _result("b", -130.0, loo=-60.0, waic=-60.0, aic=11.0, bic=12.0),
                    _result("c", -140.0, loo=-40.0, waic=-60.0, aic=12.0, bic=12.0))
    assert _names(leading(c)) == ["a", "c"]


def test_without_evidence_the_best_three_lead_and_failed_structures_never():
    c = _comparison(_result("a", None), _result("b", None), _result("c", None),
                    _result("d", None), _result("x", None, error="failed"))
    assert _names(leading(c)) == ["a", "b", "c"]
    c = _comparison(_result("a", -100.0), _result("b", None), _result("x", -1.0, error="no"))
    assert _names(leading(c)) == ["a", "b"]
    assert leading(_comparison()) == []


@pytest.mark.parametrize("bad", [-1, 2.5, "all", "Leading", True])
def test_other_values_are_refused_with_what_is_taken(bad):
    with pytest.raises(InputError, match="must be 'leading', a non-negative integer .* or "
                                         "None"):
        _detailed(_comparison(_result("a", 0.0)), bad)


def test_the_report_names_the_structures_left_without_a_corner_figure():
    from bayesfo.output.report import _without_corner

    c = _comparison(_result("a", -100.0), _result("b/2", -150.0), _result("c", -160.0))
    note = _without_corner({"bode": [], "corner_a": []}, c)
    assert "No corner figure of b/2, c:" in note and "--structure-figures all" in note
    assert _without_corner({"corner_a": [], "corner_b_2": [], "corner_c": []}, c) == ""
