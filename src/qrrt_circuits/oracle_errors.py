"""The optional oracle error model (DESIGN §2, the paper's Lemmas 4-6)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .validation import check_probability, check_seed


@dataclass(frozen=True)
class OracleErrorModel:
    """Oracle mistakes applied to the marks only (the verification uses the true predicate).

    Each truly unreachable entry is marked good with probability ``false_positive`` and each
    reachable one is marked bad with probability ``false_negative``. (The paper's q = (1 - m1)/m is
    a typo for q = (m - m1)/m.)
    """

    false_positive: float = 0.0
    false_negative: float = 0.0
    seed: int | None = None
    _rng: np.random.Generator = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        for name in ("false_positive", "false_negative"):
            object.__setattr__(self, name, check_probability(getattr(self, name), name))
        check_seed(self.seed)
        object.__setattr__(self, "_rng", np.random.default_rng(self.seed))

    @property
    def is_exact(self) -> bool:
        return self.false_positive == 0.0 and self.false_negative == 0.0

    def describe(self) -> dict:
        return {"false_positive": self.false_positive, "false_negative": self.false_negative}

    def apply(self, truth: np.ndarray, rng: np.random.Generator | None = None) -> np.ndarray:
        """Noisy marks for the true reachability ``truth`` (bool array)."""
        truth = np.asarray(truth, dtype=bool)
        if self.is_exact:
            return truth.copy()
        rng = self._rng if rng is None else rng
        flips = rng.random(truth.shape)
        return np.where(truth, flips >= self.false_negative, flips < self.false_positive)
