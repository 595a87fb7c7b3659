"""A receiver's own solution: one fix per time, its length the number of fixes."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vo_doppler.model.receiver_solution import ReceiverSolution


def _solution(n: int) -> ReceiverSolution:
    values = {f.name: np.zeros(n) for f in dataclasses.fields(ReceiverSolution)}
    values["velocity_ned"] = np.zeros((n, 3))
    values["t"] = 100.0 + np.arange(n)
    return ReceiverSolution(**values)


def test_its_length_is_the_number_of_fixes():
    assert len(_solution(3)) == 3
    assert len(_solution(0)) == 0


def test_it_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        _solution(2).t = np.zeros(2)
