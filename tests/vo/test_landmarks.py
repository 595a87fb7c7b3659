"""The VO map in sorted arrays against a plain dictionary model of the same operations."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.vo.landmarks import LandmarkMap

track_ids = st.lists(st.integers(0, 60), max_size=25, unique=True)
operations = st.lists(
    st.tuples(st.sampled_from(["set", "remove", "retain", "clear"]), track_ids), max_size=12
)


@settings(max_examples=150, deadline=None)
@given(operations, track_ids)
def test_map_matches_a_dictionary(ops, queried):
    landmarks, model = LandmarkMap(), {}
    for step, (op, ids) in enumerate(ops):
        if op == "set":
            xyz = np.array([[i, step, -i] for i in ids], float).reshape(-1, 3)
            landmarks.set(np.array(ids, np.int64), xyz)
            model.update({i: xyz[k] for k, i in enumerate(ids)})
        elif op == "remove":
            landmarks.remove(np.array(ids, np.int64))
            model = {i: p for i, p in model.items() if i not in ids}
        elif op == "retain":
            landmarks.retain(np.array(ids, np.int64))
            model = {i: p for i, p in model.items() if i in ids}
        else:
            landmarks.clear()
            model = {}
        assert len(landmarks) == len(model)
        assert landmarks.ids.tolist() == sorted(model)
    found, points = landmarks.lookup(np.array(queried, np.int64))
    assert found.tolist() == [i in model for i in queried]
    expected = [model[i] for i in queried if i in model]
    np.testing.assert_array_equal(points, np.array(expected).reshape(-1, 3))
    assert landmarks.contains(np.array(queried, np.int64)).tolist() == found.tolist()


def test_rows_address_the_stored_points():
    landmarks = LandmarkMap()
    landmarks.set(np.array([7, 3, 11]), np.arange(9.0).reshape(3, 3))
    found, rows = landmarks.rows(np.array([11, 4, 3, 12]))
    assert found.tolist() == [True, False, True, False]
    np.testing.assert_array_equal(landmarks.xyz[rows[found]], [[6.0, 7.0, 8.0], [3.0, 4.0, 5.0]])
    landmarks.xyz[rows[0]] = [-1.0, -2.0, -3.0]
    np.testing.assert_array_equal(landmarks.lookup(np.array([11]))[1], [[-1.0, -2.0, -3.0]])
