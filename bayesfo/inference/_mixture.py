"""Mixture of multivariate normals fitted to draws: the proposal of bridge sampling and of the
tempered ladder's independence moves."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from functools import cached_property

import numpy as np


@dataclass(frozen=True)
class _GaussianMixture:
    """Proposal of bridge sampling: a mixture of multivariate normals fitted to posterior draws.

    A single normal is a poor proposal for posteriors with several modes (the q ↔ q/2 modes
    of max-order members) or a curved ridge; k-means clusters (k = 1 … 4, chosen by BIC on the
    draws it is fitted to) each get their mean and covariance.
    """

    weights: np.ndarray
    means: np.ndarray
    chols: np.ndarray

    @classmethod
    def fit(cls, x: np.ndarray, rng: np.random.Generator, max_components: int = 4):
        from scipy.cluster.vq import kmeans2

        n, d = x.shape
        scale = x.std(axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        best, best_bic = None, np.inf
        for k in range(1, max_components + 1):
            if k == 1:
                labels = np.zeros(n, dtype=int)
            else:
                with warnings.catch_warnings():
                    # An empty cluster means k is too many: the count check below stops there.
                    warnings.filterwarnings("ignore", "One of the clusters is empty")
                    _, labels = kmeans2(x / scale, k, seed=rng, minit="++")
            counts = np.bincount(labels, minlength=k)
            if np.any(counts < 5 * d):  # too few draws for a covariance
                break
            means = np.array([x[labels == j].mean(axis=0) for j in range(k)])
            chols = []
            for j in range(k):
                cov = np.atleast_2d(np.cov(x[labels == j], rowvar=False))
                cov = cov + 1e-12 * np.diag(np.diag(cov) + 1e-300)
                chols.append(np.linalg.cholesky(cov))
            mix = cls(counts / n, means, np.array(chols))
            n_params = k * (d + d * (d + 1) / 2) + k - 1
            bic = -2 * float(np.sum(mix.log_pdf(x))) + n_params * math.log(n)
            if bic < best_bic:
                best, best_bic = mix, bic
        return best

    @cached_property
    def _whitening(self) -> tuple[np.ndarray, np.ndarray]:
        """The inverse Cholesky factor of each component and its log weight plus the log of its
        normalising constant, computed once: the tempered ladder evaluates each mixture on
        every step of a rung, and multiplying by the inverses is faster than solving with the
        factors (BENCHMARKS.md, "Measurements behind design choices")."""
        d = self.means.shape[1]
        inverses = np.array([np.linalg.inv(c) for c in self.chols])
        consts = np.array([math.log(w) - np.sum(np.log(np.diag(c))) - 0.5 * d * math.log(2 * math.pi)
                           for w, c in zip(self.weights, self.chols, strict=True)])
        return inverses, consts

    def log_pdf(self, x: np.ndarray) -> np.ndarray:
        inverses, consts = self._whitening
        terms = np.empty((len(consts), x.shape[0]))
        for j, (mean, inverse) in enumerate(zip(self.means, inverses, strict=True)):
            z = (x - mean) @ inverse.T
            terms[j] = consts[j] - 0.5 * np.einsum("ij,ij->i", z, z)
        if len(consts) == 1:
            return terms[0]
        top = terms.max(axis=0)
        top = np.where(np.isfinite(top), top, 0.0)
        with np.errstate(divide="ignore"):
            return top + np.log(np.exp(terms - top).sum(axis=0))

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:
        which = rng.choice(len(self.weights), size=n, p=self.weights)
        z = rng.standard_normal((n, self.means.shape[1]))
        return self.means[which] + np.einsum("nij,nj->ni", self.chols[which], z)
