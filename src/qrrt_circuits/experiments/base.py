"""The experiment interface and its trial type.

An experiment is a list of independent trials (the unit of work), a function that runs one trial
and returns a flat record (one CSV row), a summary of all records against the paper's numbers,
and its figures. Trials carry parameters and a seed, never circuits or planners, so any executor
can run them. Per-trial seeds come from one ``numpy.random.SeedSequence``: trial seeds depend on
the root seed and the trial's replicate index only, never on the order trials run in.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import IntEnum
from pathlib import Path

import numpy as np

#: record columns that measure time: excluded when records are compared across executors
TIMING_SUFFIX = "_s"


class TrialStream(IntEnum):
    """The seed streams of the experiments' trials (``SeedSequence(root).spawn_key[0]``). They are
    part of the reproducibility contract: changing one changes the published results."""

    PAPER_WORLDS = 1  # oracle-efficiency and wallclock share their worlds ...
    PAPER_PLANNERS = 2  # ... and their planner seeds
    HEATMAPS = 3
    CORRIDOR = 4
    ANNEALING_WORLDS = 5
    ANNEALING_PLANNERS = 6
    LEMMAS = 7
    SCALING_WORLDS = 8
    SCALING_PLANNERS = 9
    ORACLE_CHECK = 10
    TREE_SIZE_WORLDS = 11
    TREE_SIZE_PLANNERS = 12
    HEATMAP_HYPOTHESES = 13
    CORRIDOR_SENSITIVITY = 14
    # noise and resources (issue 12); numbered apart from the other streams added beside them
    NOISE_SWEEP = 31
    NOISE_WORLDS = 32
    NOISE_PLANNERS = 33
    RESOURCES_WORLDS = 34
    RESOURCES_PLANNERS = 35
    # search-policies (issue 12)
    SEARCH_POLICIES_WORLDS = 36
    SEARCH_POLICIES_PLANNERS = 37


@dataclass(frozen=True)
class Trial:
    """One unit of work: a unique id, its parameters (JSON-able scalars) and its seed."""

    id: str
    params: dict = field(default_factory=dict)
    seed: int = 0


def replicate_seed(root_seed: int, replicate: int, stream: int = 0) -> int:
    """The seed of replicate ``replicate``: SeedSequence(root_seed) spawned at (stream, replicate)."""
    sequence = np.random.SeedSequence(int(root_seed), spawn_key=(int(stream), int(replicate)))
    return int(sequence.generate_state(1, dtype=np.uint32)[0])


def paired_trials(settings: dict, variants: list[tuple[str, dict]], world_stream: int,
                  seed_stream: int) -> list[Trial]:
    """One world per replicate, shared by every variant (so variants are compared on the same
    worlds): trial ``f"{label}-{replicate}"`` with ``params`` plus ``replicate`` and ``world_seed``;
    all variants of a replicate share its seed too."""
    trials = []
    for replicate in range(settings["trials"]):
        world_seed = replicate_seed(settings["seed"], replicate, world_stream)
        seed = replicate_seed(settings["seed"], replicate, seed_stream)
        for label, params in variants:
            trials.append(Trial(f"{label}-{replicate}",
                                {**params, "replicate": replicate, "world_seed": world_seed}, seed))
    return trials


class Experiment:
    """Base class; subclasses define the five methods below (and ``name``, ``title``)."""

    name = "experiment"
    title = ""
    #: whether the experiment's planners take the reachability predicate chosen by ``--predicate``
    uses_predicate = True
    #: what the paper reports (filled by subclasses)
    paper: dict = {}

    def settings(self, quick: bool, trials: int | None, seed: int) -> dict:
        raise NotImplementedError

    def trials(self, settings: dict) -> list[Trial]:
        raise NotImplementedError

    def run_trial(self, trial: Trial, settings: dict) -> dict:
        raise NotImplementedError

    def summarize(self, records: list[dict], settings: dict) -> dict:
        """Return at least {"ours": ..., "paper": ...} (plus anything else worth keeping)."""
        raise NotImplementedError

    def plot(self, records: list[dict], settings: dict, summary: dict, out_dir: Path) -> list[Path]:
        raise NotImplementedError
