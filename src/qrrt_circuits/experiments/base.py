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
from typing import Any, TypeAlias

import numpy as np

#: record columns that measure time: excluded when records are compared across executors
TIMING_SUFFIX = "_s"

#: an experiment's settings: JSON scalars and lists, stored in ``settings.json``
Settings: TypeAlias = dict[str, Any]
#: one trial's record: a flat mapping of column name to JSON scalar (one ``records.csv`` row);
#: its columns differ per experiment, so it stays a plain dict
Record: TypeAlias = dict[str, Any]
#: an experiment's summary (``summary.json``): ``{"ours": ..., "paper": ...}`` plus what each
#: experiment keeps (nested JSON whose shape differs per experiment)
Summary: TypeAlias = dict[str, Any]


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
    HEATMAP_WORLDS = 15
    # corridor-sensitivity: the runs of its factorial design (a block of runs is one trial)
    CORRIDOR_SENSITIVITY = 17
    # corridor-worlds: the runs of its cells in each clutter draw (a block of runs is one trial)
    CORRIDOR_WORLDS = 18
    # annealing-density: its worlds (one per replicate and density) and planner seeds
    ANNEALING_DENSITY_WORLDS = 19
    ANNEALING_DENSITY_PLANNERS = 20
    # problems: the planner seeds of its replicates (its worlds are fixed, or seeded by replicate)
    PROBLEMS_PLANNERS = 21
    # noise and resources: numbered from 31, apart from the streams above
    NOISE_SWEEP = 31
    NOISE_WORLDS = 32
    NOISE_PLANNERS = 33
    RESOURCES_WORLDS = 34
    RESOURCES_PLANNERS = 35
    # search-policies
    SEARCH_POLICIES_WORLDS = 36
    SEARCH_POLICIES_PLANNERS = 37
    # summaries' own draws (no trial uses them)
    PAPER_DESIGN = 41
    AUTHORS_CODE = 42
    # coherent-oracle: the worlds of its verification and Grover replicates
    COHERENT_ORACLE = 43
    COHERENT_ORACLE_PLANS = 44


@dataclass(frozen=True)
class Trial:
    """One unit of work: a unique id, its parameters (JSON-able scalars) and its seed.

    Attributes:
        id: Unique within the experiment (``records.csv`` is keyed by it).
        params: The trial's parameters, copied into its record.
        seed: The trial's seed (from ``replicate_seed``).
    """

    id: str
    params: dict[str, Any] = field(default_factory=dict)
    seed: int = 0


def replicate_seed(root_seed: int, replicate: int, stream: int = 0) -> int:
    """The seed of replicate ``replicate``: SeedSequence(root_seed) spawned at (stream, replicate).

    Args:
        root_seed: The experiment's ``--seed``.
        replicate: The replicate index (0-based).
        stream: The ``TrialStream`` the seed is drawn from.

    Returns:
        The first 32-bit word of ``SeedSequence(root_seed, spawn_key=(stream, replicate))``.
    """
    sequence = np.random.SeedSequence(int(root_seed), spawn_key=(int(stream), int(replicate)))
    return int(sequence.generate_state(1, dtype=np.uint32)[0])


def paired_trials(settings: Settings, variants: list[tuple[str, dict[str, Any]]], world_stream: int,
                  seed_stream: int) -> list[Trial]:
    """One world per replicate, shared by every variant (so variants are compared on the same
    worlds): trial ``f"{label}-{replicate}"`` with ``params`` plus ``replicate`` and ``world_seed``;
    all variants of a replicate share its seed too.

    Args:
        settings: The experiment's settings (``trials`` replicates, root ``seed``).
        variants: ``(label, params)`` for each variant run on every replicate.
        world_stream: The ``TrialStream`` of the world seeds.
        seed_stream: The ``TrialStream`` of the planner seeds.

    Returns:
        ``settings["trials"] * len(variants)`` trials, replicate by replicate.
    """
    trials = []
    for replicate in range(settings["trials"]):
        world_seed = replicate_seed(settings["seed"], replicate, world_stream)
        seed = replicate_seed(settings["seed"], replicate, seed_stream)
        for label, params in variants:
            trials.append(Trial(f"{label}-{replicate}",
                                {**params, "replicate": replicate, "world_seed": world_seed}, seed))
    return trials


@dataclass(frozen=True)
class PaperNumber:
    """One number an experiment compares with the paper.

    Attributes:
        label: What it is, short (a planner, a planner and a cut).
        ours: Our value.
        interval: Our 95 % interval, ``(low, high)``.
        paper: The paper's value.
    """

    label: str
    ours: float
    interval: tuple[float, float]
    paper: float


@dataclass(frozen=True)
class PaperComparison:
    """The numbers of one summary that its experiment compares with the paper, all of one quantity.

    Attributes:
        title: The experiment's title (which figure of the paper).
        quantity: What the numbers measure, with their unit (an axis label).
        numbers: The numbers, in the order they are drawn.
    """

    title: str
    quantity: str
    numbers: tuple[PaperNumber, ...]


class Experiment:
    """Base class; subclasses define the five methods below (and ``name``, ``title``).

    Attributes:
        name: The experiment's name (``qrrt reproduce NAME``, its folder under ``--out``).
        title: A one-line title naming the paper's figure or table it reproduces.
        uses_predicate: Whether its planners take the predicate chosen by ``--predicate``.
        paper: What the paper reports (filled by subclasses).
    """

    name = "experiment"
    title = ""
    #: whether the experiment's planners take the reachability predicate chosen by ``--predicate``
    uses_predicate = True
    #: what the paper reports (filled by subclasses)
    paper: dict[str, Any] = {}

    def settings(self, quick: bool, trials: int | None, seed: int) -> Settings:
        """The settings of a run (stored in ``settings.json``; a resumed run must match them).

        Args:
            quick: Small settings, for a quick check of the whole pipeline.
            trials: Trials per variant, or None for the experiment's default.
            seed: The root seed of every trial's seed.

        Returns:
            JSON-able settings.
        """
        raise NotImplementedError

    def trials(self, settings: Settings) -> list[Trial]:
        """The independent units of work, with unique ids and their seeds.

        Args:
            settings: As returned by ``settings``.

        Returns:
            The trials, in a fixed order (summaries follow it).
        """
        raise NotImplementedError

    def run_trial(self, trial: Trial, settings: Settings) -> Record:
        """Run one trial.

        Args:
            trial: One of ``trials(settings)``.
            settings: As returned by ``settings``.

        Returns:
            The trial's measurements (flat JSON scalars; the runner adds the id, seed and params).
        """
        raise NotImplementedError

    def summarize(self, records: list[Record], settings: Settings) -> Summary:
        """Summarize all records against the paper's numbers.

        Args:
            records: One record per trial, in ``trials`` order.
            settings: As returned by ``settings``.

        Returns:
            At least ``{"ours": ..., "paper": ...}`` (plus anything else worth keeping).
        """
        raise NotImplementedError

    def plot(self, records: list[Record], settings: Settings, summary: Summary, out_dir: Path) -> list[Path]:
        """Draw the experiment's figures.

        Args:
            records: One record per trial, in ``trials`` order.
            settings: As returned by ``settings``.
            summary: As returned by ``summarize`` (with the runner's keys added).
            out_dir: The folder the figures are written to.

        Returns:
            The paths of the figures written.
        """
        raise NotImplementedError

    def paper_comparison(self, summary: Summary) -> PaperComparison | None:
        """The numbers of a summary that this experiment compares with the paper, for a figure
        that sets several runs (one per reachability check, say) beside the paper's numbers
        (``qrrt compare-checks``); read from the summary only, never from records.

        Args:
            summary: A complete ``summary.json`` of this experiment.

        Returns:
            The comparison, or None (the default) for an experiment that has none to draw.
        """
        return None
