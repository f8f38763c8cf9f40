"""The optional oracle error model (DESIGN §2, the paper's Lemmas 4-6)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .._support.validation import check_probability, check_seed


@dataclass(frozen=True)
class OracleErrorModel:
    """Oracle mistakes applied to the marks only (the verification uses the true predicate).

    Each truly unreachable entry is marked good with probability ``false_positive`` and each
    reachable one is marked bad with probability ``false_negative``. (The paper's q = (1 - m1)/m is
    a typo for q = (m - m1)/m.) Of the m marked entries m1 are then truly good, and m2 truly good
    entries are marked bad: the setting of the paper's Lemmas 4-6
    (``probability.prob_true_solution``, ``prob_all_same_with_errors``,
    ``expected_workers_with_errors``).

    Args:
        false_positive: Probability in [0, 1] that an unreachable entry is marked good (default 0).
        false_negative: Probability in [0, 1] that a reachable entry is marked bad (default 0).
        seed: Seed (integer >= 0) of the model's own generator, used when ``apply`` gets none; None
            (default) for fresh entropy.

    Raises:
        TypeError: A non-real probability or a non-integer ``seed``.
        ValueError: A probability outside [0, 1] or a negative ``seed``.

    Example:
        >>> import numpy as np
        >>> from qrrt_circuits import OracleErrorModel
        >>> always_wrong = OracleErrorModel(false_positive=1.0, false_negative=1.0)
        >>> always_wrong.apply(np.array([True, False, False]), np.random.default_rng(0))
        array([False,  True,  True])
        >>> OracleErrorModel().is_exact
        True
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
        """Whether both error probabilities are 0 (``apply`` returns the truth unchanged)."""
        return self.false_positive == 0.0 and self.false_negative == 0.0

    def describe(self) -> dict:
        """The model as JSON-able settings: ``false_positive`` and ``false_negative``."""
        return {"false_positive": self.false_positive, "false_negative": self.false_negative}

    def apply(self, truth: np.ndarray, rng: np.random.Generator | None = None) -> np.ndarray:
        """Noisy marks for the true reachability ``truth`` (bool array).

        Args:
            truth: Boolean array of the true reachability of each entry.
            rng: The generator of the flips; None (default) for the model's own (seeded by
                ``seed``).

        Returns:
            A new boolean array of the same shape: each true entry kept with probability
            1 - ``false_negative``, each false entry set with probability ``false_positive``.
        """
        truth = np.asarray(truth, dtype=bool)
        if self.is_exact:
            return truth.copy()
        rng = self._rng if rng is None else rng
        flips = rng.random(truth.shape)
        return np.where(truth, flips >= self.false_negative, flips < self.false_positive)
