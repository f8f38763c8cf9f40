"""``check_measured``: a backend's measured indices are refused unless they are one integer index
in [0, 2^n) per shot."""

from __future__ import annotations

import numpy as np
import pytest

from qrrt_circuits.search.requests import check_measured


@pytest.mark.parametrize("dtype", [np.int64, np.int32, np.uint8, np.uint64])
def test_indices_inside_the_database_pass(dtype):
    check_measured(np.array([0, 7, 255], dtype=dtype), 3, 256, "test")
    check_measured(np.zeros(0, dtype=dtype), 0, 256, "test")


@pytest.mark.parametrize("indices", [[256], [-1], [3, 300], [0, 2**40], [5, 255, -7]])
def test_an_index_outside_the_database_is_refused(indices):
    with pytest.raises(RuntimeError, match=r"the test backend measured an index outside \[0, 256\)"):
        check_measured(np.array(indices, dtype=np.int64), len(indices), 256, "test")


def test_a_large_unsigned_index_is_refused():
    with pytest.raises(RuntimeError, match="outside"):
        check_measured(np.array([2**64 - 1], dtype=np.uint64), 1, 256, "test")


@pytest.mark.parametrize("indices, shots", [(np.array([1, 2]), 3), (np.array([1.0]), 1), ([1], 1),
                                            (np.array([[1]]), 1)])
def test_a_wrong_shape_or_type_is_refused(indices, shots):
    with pytest.raises(RuntimeError, match="expected an integer array of shape"):
        check_measured(indices, shots, 256, "test")
