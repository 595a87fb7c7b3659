"""A DBC whose signal has a unit without an SI conversion (``deg/h``) is an error naming the
DBC, whether the log is decoded or the DBC only checked."""

from __future__ import annotations

import pytest

from tests.conftest import REPO_ROOT
from vo_doppler.errors import InputError
from vo_doppler.io.can import check_dbc, read_can_motion

SAMPLE = REPO_ROOT / "sample_sequences" / "urban_canyon_small" / "can"
YAW_RATE = "VEHICLE_DYNAMICS.YAW_RATE"
WHEELS = "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR"


@pytest.mark.parametrize("unit", ["deg/h", "furlong/fortnight", ""])
def test_a_unit_without_si_conversion_names_the_dbc(tmp_path, unit):
    dbc = tmp_path / "vehicle.dbc"
    text = (SAMPLE / "vehicle.dbc").read_text()
    dbc.write_text(text.replace('[-327.68|327.67] "deg/s"', f'[-327.68|327.67] "{unit}"'))
    with pytest.raises(InputError, match=rf"^{dbc}: signal {YAW_RATE} has unit"):
        read_can_motion(SAMPLE / "vehicle.log", dbc, YAW_RATE, WHEELS)
    with pytest.raises(InputError, match=rf"^{dbc}: signal {YAW_RATE} has unit"):
        check_dbc(dbc, YAW_RATE, WHEELS)
