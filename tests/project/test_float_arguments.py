"""Every float argument refuses huge integers, strings, booleans and arrays in one line naming it."""

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits.reachability.dynamics import LinearTrackingDynamics

ENV = qc.paper_clutter(seed=0)

CASES = {
    "goal_bias": lambda v: qc.RRT(goal_bias=v),
    "resolution": lambda v: qc.ExactCheck(ENV.env, resolution=v),
    "goal_radius": lambda v: qc.Problem.build(ENV.env, ENV.start, ENV.goal.centre, v),
    "max_time_s": lambda v: qc.RRT(seed=0).plan(ENV, max_time_s=v, max_rounds=1),
    "MaxWallTime": lambda v: qc.MaxWallTime(v),
    "false_positive": lambda v: qc.OracleErrorModel(false_positive=v),
    "cap_factor": lambda v: qc.BBHT(cap_factor=v),
    "horizon": lambda v: LinearTrackingDynamics.paper(horizon=v),
}
BAD = [10**400, -(10**400), "0.5", True, np.array([0.5, 0.5]), np.array(0.5), complex(0.5, 0)]


@pytest.mark.parametrize("bad", BAD, ids=["huge", "-huge", "string", "bool", "array", "0-d array", "complex"])
@pytest.mark.parametrize("argument", sorted(CASES))
def test_a_bad_float_is_refused_naming_the_argument(argument, bad):
    with pytest.raises((TypeError, ValueError)) as caught:
        CASES[argument](bad)
    message = str(caught.value)
    assert "\n" not in message
    assert (argument if argument != "MaxWallTime" else "max_time_s") in message, message


@pytest.mark.parametrize("argument", sorted(CASES))
def test_numpy_scalars_are_real_numbers(argument):
    CASES[argument](np.float64(0.5)) if argument != "goal_radius" else CASES[argument](np.float32(0.75))


def test_points_as_strings_or_booleans_are_refused():
    """``is_free`` reads numbers only, as the constructors and ``plan`` do."""
    for bad in (["5", "5"], [True, 1.0]):
        with pytest.raises(ValueError, match="points must hold real numbers"):
            ENV.env.is_free(bad)
    assert ENV.env.is_free([5, 5]) == ENV.env.is_free(np.array([5.0, 5.0]))
