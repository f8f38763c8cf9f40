"""Lemmas 1-6 against shot frequencies on AerBackend, over a grid of workers p, marked m and
qubits n, with and without oracle errors.

Each trial runs one Aer search of a random database with p x R shots (R groups of p workers; the
shots are independent preparations) and reads off: all p on the same solution (Lemma 1), all
different (Lemma 2), a truly good entry measured (Lemma 4), all p on the same truly good entry
(Lemma 5). Reading the shots in order as draws of a coupon collector gives the number of workers
needed to find all m (Lemma 3) or all m1 truly good marked entries (Lemma 6). k is the optimal
count for the oracle's m. Standard errors are binomial (or the sample standard deviation of the
collection times).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, SupportsFloat

import numpy as np

from .. import probability as pr
from ..reachability.oracle_errors import OracleErrorModel
from ..search.oracles import LookupOracle
from .base import Experiment, Record, Settings, Summary, Trial, TrialStream, replicate_seed
from .figures import new_figure, save, with_intervals
from .intervals import binomial_interval, rounded_interval
from .planners import make_backend

LEMMAS = ("lemma1", "lemma2", "lemma3", "lemma4", "lemma5", "lemma6")
#: Lemmas 3 and 6 are expected numbers of workers (means of collection times), the others probabilities
MEANS = ("lemma3", "lemma6")
#: P(|z| <= 3) for a standard normal z
THREE_SIGMA = math.erf(3 / math.sqrt(2))
GRID_QUBITS = (4, 6)
GRID_MARKED = (1, 2, 4, 8)
GRID_WORKERS = (2, 4, 8)
ERRORS = ((0.0, 0.0), (0.05, 0.2))


def point_interval(lemma: str, observed: float, stderr: float, repeats: int) -> tuple[float, float]:
    """The 95 % interval of one grid point's measured value.

    Lemmas 1, 2, 4, 5 (probabilities, ``observed`` = successes / ``repeats`` groups): the exact
    (Clopper-Pearson) interval. Lemmas 3, 6 (mean collection times over many collections):
    ``observed`` +- 1.96 ``stderr`` (the central limit theorem; every grid point has over a hundred
    collections).

    Args:
        lemma: ``"lemma1"`` ... ``"lemma6"``.
        observed: The measured frequency or mean.
        stderr: Its standard error (the sample standard deviation over sqrt(collections) for 3, 6).
        repeats: The groups of p workers (R).

    Returns:
        ``(low, high)``.
    """
    if lemma in MEANS:
        half = 1.959963984540054 * stderr
        return observed - half, observed + half
    return binomial_interval(round(observed * repeats), repeats)


def max_abs_z_range(points: int, level: float = 0.95) -> tuple[float, float]:
    """The central ``level`` range of max |z_i| over ``points`` independent standard normal z_i:
    P(max |z| <= x) = (2 Phi(x) - 1)^points, so x_q = Phi^-1((1 + q^(1/points)) / 2).

    Args:
        points: How many z (at least 1).
        level: The range's probability.

    Returns:
        ``(x_low, x_high)`` for q = (1 - level) / 2 and (1 + level) / 2; NaNs for no points.
    """
    if points < 1:
        return math.nan, math.nan
    from scipy.stats import norm  # a slow import: only this summary needs it

    tail = (1.0 - level) / 2.0
    low, high = (float(norm.ppf((1.0 + q ** (1.0 / points)) / 2.0)) for q in (tail, 1.0 - tail))
    return low, high


def _collection_times(indices: np.ndarray, targets: np.ndarray) -> list[int]:
    """Draws needed to see every target index, restarting after each completed collection."""
    wanted = set(int(t) for t in targets)
    if not wanted:
        return []
    times, seen, count = [], set(), 0
    for index in indices:
        count += 1
        if int(index) in wanted:
            seen.add(int(index))
            if len(seen) == len(wanted):
                times.append(count)
                seen, count = set(), 0
    return times


class Lemmas(Experiment):
    """Lemmas 1-6 of the paper against Aer shot frequencies (see the module docstring).

    A trial is one point (n, m, p, false-positive and false-negative rates) of the grid: one Aer
    search with p x R shots, read as R groups of p workers. Its record holds, for each lemma, the
    observed frequency, the ``qrrt_circuits.probability`` value and the standard error. The summary
    gives, per point and lemma, the measured value's 95 % interval (``point_interval``) against the
    lemma's value; per lemma (``ours``), the share of points whose interval holds the lemma (at least
    0.95 if it is exact) and the share within 3 standard errors (0.997), each with its exact binomial
    interval over the points; and the largest |z| = |observed - theory| / stderr with the range it
    has if the lemma is exact (``max_abs_z_range``).
    """

    name = "lemmas"
    uses_predicate = False  # no planner: random marked databases
    title = "Lemmas 1-6 against Aer shot frequencies"
    paper = {"lemma1": "P(G)^p m^(1-p)", "lemma2": "P(G)^p m! / (m^p (m-p)!)",
             "lemma3": "m H_m / P(G)", "lemma4": "(m1/m) P(G) + (m2/(N-m)) (1-P(G))",
             "lemma5": "m1 (P(G)/m)^p + m2 ((1-P(G))/(N-m))^p", "lemma6": "m1 H_m1 / ((m1/m) P(G))"}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        grid = [[n, m, p, fp, fn] for n in GRID_QUBITS for m in GRID_MARKED for p in GRID_WORKERS
                for fp, fn in ERRORS if m <= 2**n]
        if quick:
            grid = grid[:: max(len(grid) // 8, 1)]
        return {"repeats": trials or (400 if quick else 3000), "grid": grid, "backend": "aer",
                "seed": seed, "quick": quick}

    def trials(self, settings: Settings) -> list[Trial]:
        return [Trial(f"n{n}-m{m}-p{p}-fp{fp}-fn{fn}", {"qubits": n, "marked": m, "workers": p,
                                                         "false_positive": fp, "false_negative": fn},
                      replicate_seed(settings["seed"], i, TrialStream.LEMMAS))
                for i, (n, m, p, fp, fn) in enumerate(settings["grid"])]

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        n, m, p = trial.params["qubits"], trial.params["marked"], trial.params["workers"]
        size = 2**n
        rng = np.random.default_rng(trial.seed)
        truth = np.zeros(size, dtype=bool)
        truth[rng.choice(size, m, replace=False)] = True
        errors = OracleErrorModel(trial.params["false_positive"], trial.params["false_negative"])
        marks = errors.apply(truth, rng)
        m_oracle = int(marks.sum())
        m1 = int((marks & truth).sum())
        m2 = int((~marks & truth).sum())
        k = pr.optimal_iterations(size, m_oracle)
        p_good = pr.success_probability(size, m_oracle, k)
        repeats = settings["repeats"]
        backend = make_backend(settings["backend"])
        indices = backend.search(LookupOracle(marks), k, shots=p * repeats, seed=int(rng.integers(2**62))).indices
        groups = indices.reshape(repeats, p)
        good = marks[groups].all(axis=1)
        same = good & (groups == groups[:, :1]).all(axis=1)
        different = good & np.array([len(set(row)) == p for row in groups])
        true_hit = truth[groups[:, 0]]
        same_true = truth[groups].all(axis=1) & (groups == groups[:, :1]).all(axis=1)
        record: Record = {"iterations": k, "oracle_marked": m_oracle, "true_marked": m1, "missed_good": m2,
                  "p_good": p_good, "repeats": repeats}

        def put(name: str, observed: SupportsFloat, theory: SupportsFloat, stderr: SupportsFloat) -> None:
            record[f"{name}_observed"] = float(observed)
            record[f"{name}_theory"] = float(theory)
            record[f"{name}_stderr"] = float(stderr)

        def binomial(observed: float, theory: float) -> float:
            return math.sqrt(max(theory * (1 - theory), 1.0 / repeats) / repeats)

        lemma1 = pr.prob_all_same(p, m_oracle, p_good) if m_oracle else 0.0
        lemma2 = pr.prob_all_different(p, m_oracle, p_good) if m_oracle else 0.0
        put("lemma1", same.mean(), lemma1, binomial(same.mean(), lemma1))
        put("lemma2", different.mean(), lemma2, binomial(different.mean(), lemma2))
        lemma4 = pr.prob_true_solution(size, m_oracle, m1, m2, p_good)
        put("lemma4", true_hit.mean(), lemma4, binomial(true_hit.mean(), lemma4))
        lemma5 = pr.prob_all_same_with_errors(p, size, m_oracle, m1, m2, p_good)
        put("lemma5", same_true.mean(), lemma5, binomial(same_true.mean(), lemma5))
        # coupon collection over the shot sequence (Lemma 3: all m marked; Lemma 6: all m1 truly good)
        for name, targets, theory in (
            ("lemma3", np.flatnonzero(marks), pr.expected_workers_all_found(m_oracle, p_good)),
            ("lemma6", np.flatnonzero(marks & truth), pr.expected_workers_with_errors(m_oracle, m1, p_good)),
        ):
            times = _collection_times(indices, targets)
            if len(times) >= 5 and math.isfinite(theory):
                put(name, np.mean(times), theory, np.std(times, ddof=1) / math.sqrt(len(times)))
            else:
                put(name, float("nan"), theory, float("nan"))
        return record

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        ours: dict[str, dict[str, float | None]] = {}
        interval: dict[str, dict[str, list[float]]] = {}
        z_scores: dict[str, dict[str, Any]] = {}
        per_point: dict[str, dict[str, dict[str, Any]]] = {r["trial_id"]: {} for r in records}
        for lemma in LEMMAS:
            z, inside = [], []
            for r in records:
                observed, theory, stderr = r[f"{lemma}_observed"], r[f"{lemma}_theory"], r[f"{lemma}_stderr"]
                if observed is None or not np.isfinite(observed) or not stderr:
                    continue
                z.append((observed - theory) / stderr)
                low, high = point_interval(lemma, observed, stderr, int(r["repeats"]))
                inside.append(bool(low <= theory <= high))
                per_point[r["trial_id"]][lemma] = {"observed": observed, "interval_95": [low, high],
                                                   "lemma": theory, "inside": inside[-1]}
            z = np.abs(np.array(z))
            ours[lemma] = {"within_3_sigma": round(float(np.mean(z <= 3)), 3) if z.size else None,
                           "inside_interval_95": round(float(np.mean(inside)), 3) if inside else None}
            interval[lemma] = {
                "within_3_sigma": rounded_interval(binomial_interval(int(np.sum(z <= 3)), int(z.size)), 3),
                "inside_interval_95": rounded_interval(binomial_interval(int(np.sum(inside)), len(inside)), 3)}
            z_scores[lemma] = {"points": int(z.size), "max_abs_z": round(float(z.max()), 2) if z.size else None,
                               "max_abs_z_range_if_exact_95": [round(v, 2) for v in max_abs_z_range(int(z.size))]}
        return {"ours": ours, "paper": self.paper, "interval_95": interval, "z_scores": z_scores,
                "expected_if_exact": {"within_3_sigma": round(THREE_SIGMA, 4), "inside_interval_95": "at least 0.95"},
                "per_point": per_point,
                "note": "per grid point: the measured value with its 95 % interval (exact binomial over the R groups "
                        "for Lemmas 1, 2, 4, 5; mean +- 1.96 standard errors over the collections for Lemmas 3, 6) "
                        "against the lemma's value; ours: the share of points whose interval holds the lemma "
                        "(inside_interval_95, at least 0.95 if the lemma is exact) and of points within 3 standard "
                        "errors (within_3_sigma, 0.997 if exact), each with its exact binomial interval over the "
                        "points; z_scores: the largest |z| with the 95 % range of the largest of that many "
                        "independent standard normal |z|"}

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Per lemma, each grid point's measured value with its 95 % interval (``point_interval``)
        against the lemma's value, and the shares of points whose interval holds the lemma and that
        lie within 3 standard errors, with their intervals."""
        fig, axes = new_figure(2, 3, (14, 9.5))
        for ax, lemma in zip(axes.ravel(), LEMMAS, strict=True):
            points = [(r, summary["per_point"][r["trial_id"]][lemma]) for r in records
                      if lemma in summary["per_point"][r["trial_id"]]]
            theory = np.array([p["lemma"] for _, p in points])
            observed = np.array([p["observed"] for _, p in points])
            spans = np.array([p["interval_95"] for _, p in points], dtype=float).reshape(-1, 2)
            errors = np.array([r["false_positive"] > 0 for r, _ in points], dtype=bool)
            for mask, color, label in ((~errors, "tab:blue", "exact oracle"), (errors, "tab:red", "oracle errors")):
                if mask.any():
                    with_intervals(ax, theory[mask], observed[mask], spans[mask], fmt="o", ms=3, color=color,
                                   label=f"{label} (95 % interval)", capsize=2)
            if theory.size:
                lim = [min(theory.min(), observed.min()), max(theory.max(), observed.max())]
                ax.plot(lim, lim, "k--", lw=0.8)
            stats, spans_of = summary["ours"][lemma], summary["interval_95"][lemma]
            inside, within = spans_of["inside_interval_95"], spans_of["within_3_sigma"]
            ax.set_title(f"Lemma {lemma[-1]}: {self.paper[lemma]}\n"
                         f"interval holds the lemma: {stats['inside_interval_95']} [{inside[0]}, {inside[1]}]\n"
                         f"within 3 sigma: {stats['within_3_sigma']} [{within[0]}, {within[1]}]", fontsize=8.5)
            ax.set_xlabel("lemma")
            ax.set_ylabel("Aer shots")
            ax.legend(fontsize=7)
            ax.grid(alpha=0.3)
        return [save(fig, out_dir / "lemmas.png")]
