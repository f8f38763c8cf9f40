"""Every experiment by name: the registry ``qrrt reproduce`` and ``run_experiment`` read."""

from .annealing import Annealing
from .annealing_density import AnnealingDensity
from .coherent_oracle import CoherentOracleExperiment
from .corridor import Corridor
from .corridor_sensitivity import CorridorSensitivity
from .corridor_worlds import CorridorWorlds
from .heatmap_hypotheses import HeatmapHypotheses
from .heatmap_worlds import HeatmapWorlds
from .heatmaps import Heatmaps
from .lemmas import Lemmas
from .noise import Noise
from .oracle_check import OracleCheck
from .oracle_efficiency import OracleEfficiency
from .problems import Problems
from .resources import Resources
from .scaling import Scaling
from .search_policies import SearchPolicies
from .tree_size import TreeSize
from .wallclock import Wallclock

EXPERIMENTS = {
    experiment.name: experiment
    for experiment in (OracleEfficiency(), Wallclock(), Heatmaps(), Corridor(), Annealing(), Lemmas(),
                       Scaling(), OracleCheck(), TreeSize(), HeatmapHypotheses(), HeatmapWorlds(),
                       CorridorSensitivity(), CorridorWorlds(), SearchPolicies(), Noise(), Resources(),
                       AnnealingDensity(), Problems(), CoherentOracleExperiment())
}

__all__ = ["EXPERIMENTS"]
