"""Heading figure: the satellite curve shows the satellites of every epoch, the last included."""

from __future__ import annotations

import matplotlib
import numpy as np

from vo_doppler.heading.conventional import ConventionalVelocity
from vo_doppler.heading.pipeline import heading_pipeline
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.report.heading_figure import build_heading_figure, heading_figure
from vo_doppler.sim.doppler_rows import gyro_from_heading, simulate_doppler

AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0]


def _table(n_sat: list[int]) -> HeadingTable:
    m = len(n_sat)
    yaw = np.linspace(0.0, 0.5, m)
    return HeadingTable(
        t=1000.0 + 0.5 * np.arange(m),
        yaw_tc=yaw,
        sigma_tc=np.full(m, 0.01),
        tc_reliable=np.ones(m, bool),
        n_obs_window=np.cumsum(n_sat),
        n_sat_epoch=np.array(n_sat),
        yaw_conv=yaw,
        conv_valid=np.array(n_sat) >= 4,
        gyro_bias=np.zeros(m),
        wheel_scale=np.ones(m),
    )


def _satellite_line(figure) -> matplotlib.lines.Line2D:
    (line,) = [a for a in figure.axes[0].lines if a.get_label() == "satellites"]
    return line


def test_satellite_curve_is_the_table_count_at_every_epoch(tmp_path):
    table = _table([3, 4, 2, 1, 5, 2])
    line = _satellite_line(build_heading_figure(table, title="t"))
    np.testing.assert_array_equal(line.get_xdata(), table.t - table.t[0])
    np.testing.assert_array_equal(line.get_ydata(), table.n_sat_epoch)
    # Each count is drawn from half-way to the previous epoch to half-way to the next one,
    # the first and last to their own epoch: the last epoch's step is not dropped.
    assert line.get_drawstyle() == "steps-mid"
    heading_figure(tmp_path / "h.png", table, np.zeros(len(table)))
    assert (tmp_path / "h.png").stat().st_size > 10_000


def _table_at_10_mps(t, yaw_rate, n_sat, speed_t, gyro: SensorSeries) -> HeadingTable:
    """Heading table of a 10 m/s drive seen by ``n_sat`` satellites, with the wheel speed
    recorded at ``speed_t`` and the given gyro."""
    scenario = simulate_doppler(
        t, lambda t: 0.3 + yaw_rate * t, lambda t: np.full_like(t, 10.0), AZIMUTH, ELEVATION, n_sat
    )
    velocity = 10.0 * np.stack([np.cos(scenario.yaw), np.sin(scenario.yaw), 0 * t], axis=1)
    speed = SensorSeries(speed_t, np.full(len(speed_t), 10.0))
    conventional = ConventionalVelocity(velocity, np.ones(len(t), bool))
    return heading_pipeline(t, scenario.rows, conventional, VehicleSignals(speed, gyro))


def test_satellites_are_counted_where_the_sensors_have_ended():
    """The urban_canyon_small case: the CAN log ends 2 ms before the last GNSS epoch (and starts
    0.09 ms after the first); the satellites are still observed at those epochs."""
    t = np.arange(0.0, 10.0, 0.1)
    yaw = 0.3 + 0.05 * t
    t_gyro, rate = gyro_from_heading(t, yaw, np.ones(len(t), bool), 0.0, 0.0, 50.0)
    inside = (t_gyro > t[0] + 1e-4) & (t_gyro < t[-1] - 2e-3)
    t_speed = np.arange(1e-4, t[-1] - 2e-3, 0.01)
    table = _table_at_10_mps(t, 0.05, 3, t_speed, SensorSeries(t_gyro[inside], rate[inside]))
    assert np.isnan(table.yaw_tc[[0, -1]]).all()  # no sensor data: no tightly coupled heading
    np.testing.assert_array_equal(table.n_sat_epoch, np.full(len(t), 3))
    line = _satellite_line(build_heading_figure(table))
    assert line.get_ydata()[-1] == 3


def test_satellites_are_counted_when_no_epoch_has_sensor_data():
    t = np.arange(0.0, 5.0, 0.1)
    later = np.arange(100.0, 110.0, 0.01)  # sensors recorded over another interval entirely
    table = _table_at_10_mps(t, 0.0, 2, later, SensorSeries(later, np.zeros(len(later))))
    assert not np.any(table.tc_available)
    np.testing.assert_array_equal(table.n_sat_epoch, np.full(len(t), 2))
