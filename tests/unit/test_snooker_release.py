"""The DE-snooker patch applies to emcee releases up to the last one without the upstream fix;
a later release's own move is used, with only the null move for undefined proposals added."""

from __future__ import annotations

import numpy as np

from bayesfo.inference import posterior


def test_release_numbers():
    assert posterior._release("3.1.6") == (3, 1, 6)
    assert posterior._release("3.2") == (3, 2, 0)
    assert posterior._release("3.2.0rc1") == (3, 2, 0)
    assert posterior._release("4.0.0+local") == (4, 0, 0)


def test_the_patch_goes_with_the_upstream_fix(monkeypatch):
    import emcee

    monkeypatch.setattr(emcee, "__version__", "3.1.6")
    assert type(posterior._snooker_move()).__name__ == "_SnookerMove"
    monkeypatch.setattr(emcee, "__version__", "3.2.0")
    move = posterior._snooker_move()
    assert type(move).__name__ == "_Guarded"
    # Walkers that all coincide: every proposal passes through the walker's own position and
    # is undefined; each becomes a null move (the walker stays, the factor is 0).
    s = np.ones((4, 3))
    c = [np.ones((4, 3))] * 3
    q, factors = move.get_proposal(s, c, np.random.RandomState(0))
    np.testing.assert_array_equal(q, s)
    np.testing.assert_array_equal(factors, 0.0)
