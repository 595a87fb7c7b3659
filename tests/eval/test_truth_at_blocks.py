"""Ground truth interpolated a block of times at a time (issue 30: a Slerp over a 30-min ground
truth took about 20 MiB per pipeline evaluated) gives the rotations of one Slerp over every
row, bit for bit, at the truth's own times too."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from vo_doppler.eval import pipelines
from vo_doppler.eval.pipelines import truth_at
from vo_doppler.model.trajectory import Trajectory


def test_blocks_of_times_give_the_rotations_of_one_slerp(monkeypatch):
    rng = np.random.default_rng(11)
    n = 2000
    t = 1.0e9 + np.cumsum(rng.uniform(0.005, 0.02, n))
    truth = Trajectory(t, rng.normal(size=(n, 3)), Rotation.random(n, random_state=5))
    queries = np.sort(
        np.concatenate(
            [t[[0, 1, 17, 400, 401, -2, -1]], rng.uniform(t[0] - 1.0, t[-1] + 1.0, 3000)]
        )
    )
    monkeypatch.setattr(pipelines, "SLERP_BLOCK", 7)
    blocks, inside = truth_at(truth, queries)
    whole = Slerp(truth.t, truth.orientations)(queries[inside])
    assert inside.sum() > 2000 and not inside.all()
    np.testing.assert_array_equal(blocks.orientations.as_quat(), whole.as_quat())
    np.testing.assert_array_equal(blocks.t, queries[inside])
    single, _ = truth_at(truth, t[400:401])
    at_row = Slerp(truth.t, truth.orientations)(t[400:401])
    np.testing.assert_array_equal(single.orientations.as_quat(), at_row.as_quat())
    empty, _ = truth_at(truth, np.array([t[0] - 5.0]))
    assert len(empty) == 0
