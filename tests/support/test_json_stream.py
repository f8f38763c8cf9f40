"""``json_stream.dump_streamed`` and ``PlanResult.write_json``: the same JSON value as
``json.dumps`` of the lists (``PlanResult.to_dict``), for every array shape, across chunk and
line boundaries, with the arrays' values read back exactly."""

from __future__ import annotations

import io
import json
import math

import numpy as np
import pytest

import qrrt_circuits as qc
from qrrt_circuits._support import json_stream


def streamed(data) -> str:
    handle = io.StringIO()
    json_stream.dump_streamed(data, handle)
    return handle.getvalue()


def as_lists(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, dict):
        return {key: as_lists(item) for key, item in value.items()}
    return value


@pytest.mark.parametrize("chunk_rows", [1, 3, 4096])
@pytest.mark.parametrize("rows", [0, 1, 2, 3, 15, 16, 17, 33])
def test_arrays_of_every_rank_read_back_as_their_lists(monkeypatch, chunk_rows, rows):
    monkeypatch.setattr(json_stream, "CHUNK_ROWS", chunk_rows)
    rng = np.random.default_rng(rows)
    data = {
        "floats": rng.normal(size=(rows, 2)) * 10.0 ** rng.integers(-300, 300, size=(rows, 2)),
        "ints": rng.integers(-2**62, 2**62, size=rows),
        "flags": rng.random(rows) < 0.5,
        "cube": rng.random((rows, 2, 3)),
        "wide": rng.random((rows, 5)),
        "scalar": np.float64(0.1) * np.ones(()),
        "small": {"text": "two\nlines \u00e9", "list": [1, 2.5, None], "empty": {}},
        "nested": {"inner": np.arange(rows), "label": "x"},
    }
    text = streamed(data)
    assert json.loads(text) == json.loads(json.dumps(as_lists(data)))
    read = json.loads(text)
    np.testing.assert_array_equal(np.array(read["floats"]).reshape(rows, 2), data["floats"])  # bit for bit


def test_lines_hold_one_row_or_sixteen_values():
    text = streamed({"nodes": np.arange(10.0).reshape(5, 2), "parents": np.arange(40)})
    lines = text.splitlines()
    assert "  [0.0, 1.0]," in lines and "  [8.0, 9.0]" in lines
    assert "  " + ", ".join(str(value) for value in range(16)) + "," in lines
    assert "  " + ", ".join(str(value) for value in range(32, 40)) in lines


def test_non_finite_values_are_written_as_json_dumps_writes_them():
    text = streamed({"values": np.array([math.nan, math.inf, -math.inf, -0.0])})
    read = json.loads(text)["values"]
    assert math.isnan(read[0]) and read[1:3] == [math.inf, -math.inf] and math.copysign(1.0, read[3]) == -1.0


def test_an_empty_mapping_and_an_unserialisable_value():
    assert json.loads(streamed({})) == {}
    with pytest.raises(TypeError):
        streamed({"value": object()})


@pytest.mark.parametrize("make", [
    lambda env: qc.RRT(seed=1),
    lambda env: qc.ParallelRRT(workers=4, seed=1),
    lambda env: qc.QRRT(backend=qc.StatevectorBackend(seed=1), seed=1, search_policy=qc.PaperIterations()),
    lambda env: qc.PQRRT(workers=4, backend=qc.StatevectorBackend(seed=1), seed=1,
                         search_policy=qc.PaperIterations()),
])
def test_write_json_is_to_dict(make):
    """Plans ended by their node limit (no path) and, with 400 nodes, reached for the first three
    planners (a path), every planner."""
    env = qc.paper_clutter(seed=1)
    paths = []
    for max_nodes in (3, 400):
        result = make(env).plan(env, max_nodes=max_nodes)
        handle = io.StringIO()
        result.write_json(handle)
        assert json.loads(handle.getvalue()) == json.loads(json.dumps(result.to_dict(), indent=1))
        paths.append(result.path is not None)
    assert paths[0] is False and paths[1] == (make(env).__class__ is not qc.PQRRT)


def test_write_json_holds_one_chunk_not_the_tree(tmp_path):
    """Writing 50 000 nodes allocates one chunk's lists (tracemalloc's peak), where
    ``json.dump`` of ``to_dict()`` holds every node as Python lists (about 176 B per node)."""
    import dataclasses
    import tracemalloc

    small = qc.RRT(seed=1).plan(qc.paper_clutter(seed=1), max_nodes=3)
    rows = 50_000
    rng = np.random.default_rng(0)
    big = dataclasses.replace(small, nodes=rng.random((rows, 2)), parents=rng.integers(0, rows, rows))
    peaks = {}
    for name, write in (("stream", big.write_json),
                        ("dump", lambda handle: json.dump(big.to_dict(), handle, indent=1))):
        with (tmp_path / f"{name}.json").open("w") as handle:
            tracemalloc.start()
            write(handle)
            peaks[name] = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
    assert peaks["stream"] < 3 << 20  # about 1.6 MiB (one chunk)
    assert peaks["dump"] > 6 << 20  # about 8 MiB (every node)
    assert json.loads((tmp_path / "stream.json").read_text()) == json.loads((tmp_path / "dump.json").read_text())


def test_keys_are_written_as_json_writes_them():
    """Non-string keys become strings as in ``json.dumps``; a key it refuses is refused."""
    data = {7: np.arange(3), 2.5: {"x": np.ones(2)}, False: "f", None: 0}
    assert json.loads(streamed(data)) == json.loads(json.dumps(as_lists(data)))
    with pytest.raises(TypeError):
        streamed({(1, 2): np.arange(2)})


def test_string_arrays_holding_the_row_separator_stay_valid():
    data = {"text": np.array([["a], [b", "c\n"], ["], [", "d"]]),
            "objects": np.array([[{"k": "], ["}]], dtype=object)}
    assert json.loads(streamed(data)) == json.loads(json.dumps(as_lists(data)))


def test_to_dict_takes_scalars_with_tolist_as_before():
    import dataclasses

    small = qc.RRT(seed=1).plan(qc.paper_clutter(seed=1), max_nodes=3)
    odd = dataclasses.replace(small, history={"x": np.int64(3), "y": np.float64(0.5)})
    assert odd.to_dict()["history"] == {"x": 3, "y": 0.5}
    handle = io.StringIO()
    odd.write_json(handle)
    assert json.loads(handle.getvalue())["history"] == {"x": 3, "y": 0.5}
