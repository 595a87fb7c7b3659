"""Two rate sensors brought onto one time base: exact cases."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.lowcost.rate_alignment import align_rates


def test_align_rates_different_rates_and_overlap():
    t1 = np.arange(0.0, 10.0, 0.01)
    t2 = np.arange(1.0, 12.0, 0.02)
    aligned = align_rates(t1, 0.5 * t1, t2, 3.0 - 0.25 * t2)
    assert aligned.t[0] == pytest.approx(1.0) and aligned.t[-1] == pytest.approx(9.99)
    np.testing.assert_allclose(aligned.omega2, 3.0 - 0.25 * aligned.t, atol=1e-12)
    assert aligned.report1.rate_hz == pytest.approx(100.0)
    assert aligned.report2.rate_hz == pytest.approx(50.0)
    with pytest.raises(InputError, match="do not overlap"):
        align_rates(t1, t1, t1 + 100.0, t1)
