"""heading.csv values no estimator can produce (a negative σ, HDOP −1, a wheel scale of 0 or
−1, counts of −5 or 1e30, a gyro bias of 1e9 °/s, a flag of 2) are an InputError naming the
file, the line and the column; every value within the bounds reads."""

from __future__ import annotations

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import shared_data_dir
from vo_doppler.errors import InputError
from vo_doppler.io.heading_csv import COLUMNS, OPTIONAL_COLUMNS, RANGES, read_heading_csv

NAMES = COLUMNS + OPTIONAL_COLUMNS
ROW = "1000.000,10.0,0.5,1,8,6,10.0,1,0.3,1.02,0,1,3,0.05,0.9,0.8,1,0.9"
GOOD = dict(zip(NAMES, ROW.split(","), strict=True))


def write(tmp_path, rows: list[dict[str, str]]):
    path = tmp_path / "heading.csv"
    lines = [",".join(NAMES)] + [",".join(row[n] for n in NAMES) for row in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def rows_with(column: str, value: str, line: int = 3) -> list[dict[str, str]]:
    rows = [dict(GOOD, gps_time_s=f"{1000.0 + 0.05 * k:.3f}") for k in range(4)]
    rows[line - 2][column] = value
    return rows


BAD = [
    ("heading_tc_sigma_deg", "-1.0"),
    ("heading_conv_sigma_deg", "-0.5"),
    ("heading_conv_gnss_sigma_deg", "0"),
    ("conv_speed_sigma_mps", "-0.05"),
    ("heading_tc_sigma_deg", "500"),
    ("conv_hdop", "-1"),
    ("wheel_scale", "0"),
    ("wheel_scale", "-1"),
    ("wheel_scale", "5e3"),
    ("n_obs_window", "-5"),
    ("n_sat_epoch", "1e30"),
    ("rejected_rows", "2.5"),
    ("gyro_bias_dps", "1e9"),
    ("heading_conv_deg", "1000"),
    ("tc_reliable", "2"),
    ("conv_gnss_valid", "-1"),
]


@pytest.mark.parametrize("scale", ["0.287", "0.447", "3.6"])
def test_a_wheel_scale_the_calibration_gives_for_a_wrong_unit_reads(tmp_path, scale):
    """``heading`` on wheel speeds in km/h warns and writes the scale it calibrated (0.287 on
    the simulated km/h drive); its headings are right, so ``correct`` must read the file."""
    table = read_heading_csv(write(tmp_path, rows_with("wheel_scale", scale)))
    assert table.wheel_scale[1] == float(scale)


@pytest.mark.parametrize(("column", "value"), BAD)
def test_an_impossible_value_names_file_line_and_column(tmp_path, column, value):
    path = write(tmp_path, rows_with(column, value, line=4))
    with pytest.raises(InputError, match=rf"heading\.csv:4: heading CSV column {column}: "):
        read_heading_csv(path)


def test_the_shared_minimal_file_is_refused_at_its_first_bad_value():
    path = shared_data_dir() / "bad_inputs_found" / "heading_negative_sigma.csv"
    if not path.is_file():
        pytest.skip(f"{path} absent")
    with pytest.raises(InputError, match=r":2: heading CSV column heading_tc_sigma_deg: -1 "):
        read_heading_csv(path)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    column=st.sampled_from(sorted(RANGES)),
    fraction=st.floats(0.0, 1.0),
)
def test_every_value_within_the_bounds_reads(tmp_path, column, fraction):
    bounds = RANGES[column]
    value = bounds.low + fraction * (bounds.high - bounds.low)
    table = read_heading_csv(write(tmp_path, rows_with(column, repr(value))))
    assert len(table) == 4


def test_missing_optional_values_still_read(tmp_path):
    rows = rows_with("heading_conv_sigma_deg", "nan")
    rows[0]["conv_hdop"] = "nan"
    assert len(read_heading_csv(write(tmp_path, rows))) == 4
