"""The commands that tests/test_time_origin.py does not reach through ``run_sequence`` give the
same figures with every input time shifted by 1,653 GPS weeks (issue 30): ``gnss spp``'s fixes
(the sample, the comma2k19 minute, a 1-Hz drive), ``correct`` and ``eval`` as commands on files
(the 1-Hz drive's dead-reckoning track and heading table), and ``deadreckon`` as a command on
CSVs (the comma2k19 minute's IMU and CAN yaw rates with its fixes, as the README runs it, and a
generated two-gyro record with 1-Hz GPS).

Tolerances: the times written into the files are rounded to their float64 grid at 10⁹ s
(1.2·10⁻⁷ s), which moves a gyro's integrated heading over a 12-minute loop by ~10⁻⁵ rad; the
figures compared are printed with two to six decimals, and every one agrees far inside that."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import re

import numpy as np
import pytest

from tests.conftest import REPO_ROOT, require_shared
from tests.helpers.comma2k19 import COMMA, imported_comma2k19
from tests.helpers.time_shift import WEEKS_NEAR_1E9_S, shifted_sequence
from vo_doppler.cli import main
from vo_doppler.gnss.pipeline import gnss_position
from vo_doppler.io.comma2k19 import read_lowcost_inputs
from vo_doppler.io.gps_fixes import write_gps_csv
from vo_doppler.io.heading_csv import write_heading_csv
from vo_doppler.io.sensor_csv import YAW_RATE_COLUMN, write_sensor_csv
from vo_doppler.io.sequence import read_sequence
from vo_doppler.io.trajectory import read_tum, write_tum
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.run import run_sequence
from vo_doppler.sim.two_gyro import TwoGyroSpec, generate_two_gyro, write_two_gyro

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("time_origin")]

SHIFT = WEEKS_NEAR_1E9_S
ORIGINS = {"own": 0.0, "shifted": SHIFT}


@pytest.fixture(scope="module")
def drive_1hz(drive_1hz_folder) -> Sequence:
    return read_sequence(drive_1hz_folder)


def _recording(name: str, drive_1hz: Sequence, tmp_path_factory) -> Sequence:
    if name == "sample":
        return read_sequence(REPO_ROOT / "sample_sequences" / "urban_canyon_small")
    if name == "comma2k19":
        return imported_comma2k19(tmp_path_factory)
    return drive_1hz


SPP_RANGE_TOLERANCE_M = 1e-3
"""A satellite moves ~2 mm over the rounding of an epoch's time near 2.4·10⁹ s (4.8·10⁻⁷ s),
its range ~0.4 mm: residuals agree within 1 mm, a fix and its clock biases within 1 mm × PDOP
(3 mm measured at a valid fix of the sample, 18 mm at a rejected one of PDOP 200)."""
SPP_SIGMA_RTOL = 1e-4
"""σ and protection levels scale with the noise law fitted to every residual (4·10⁻⁵ measured)."""


def _assert_same_fixes(name: str, first: SppSolution, second: SppSolution) -> None:
    """Flags and counts exactly; times less :data:`SHIFT`; metres within the tolerances above,
    absolute for positions (a relative tolerance on ECEF coordinates would allow metres)."""
    np.testing.assert_allclose(second.t - SHIFT, first.t, rtol=0, atol=1e-6)
    for field in ("valid", "n_sat", "verified"):
        np.testing.assert_array_equal(getattr(second, field), getattr(first, field), err_msg=field)
    assert second.n_no_ephemeris == first.n_no_ephemeris
    np.testing.assert_allclose(second.pdop, first.pdop, rtol=1e-6, err_msg="pdop")
    moved = np.linalg.norm(second.position_ecef - first.position_ecef, axis=1)
    bound = SPP_RANGE_TOLERANCE_M * np.maximum(first.pdop, 1.0)
    assert np.array_equal(np.isnan(moved), np.isnan(first.position_ecef[:, 0])), name
    assert (moved[np.isfinite(moved)] <= bound[np.isfinite(moved)]).all(), np.nanmax(moved / bound)
    np.testing.assert_allclose(
        second.residual_rms_m, first.residual_rms_m, rtol=0, atol=SPP_RANGE_TOLERANCE_M
    )
    for field in ("horizontal_sigma_m", "vertical_sigma_m", "horizontal_protection_m"):
        np.testing.assert_allclose(
            getattr(second, field), getattr(first, field), rtol=SPP_SIGMA_RTOL, err_msg=field
        )
    np.testing.assert_allclose(
        second.vertical_protection_m, first.vertical_protection_m, rtol=SPP_SIGMA_RTOL
    )
    assert first.clock_bias_m.keys() == second.clock_bias_m.keys()
    for system, bias in first.clock_bias_m.items():
        moved = np.abs(second.clock_bias_m[system] - bias)
        assert np.array_equal(np.isnan(moved), np.isnan(bias)), system
        assert (moved[np.isfinite(moved)] <= bound[np.isfinite(moved)]).all(), system


@pytest.mark.parametrize("name", ["sample", "comma2k19", "drive_1hz"])
def test_gnss_spp_gives_the_same_fixes_at_another_time_origin(name, drive_1hz, tmp_path_factory):
    """`gnss spp`'s solution (:func:`gnss_position`: fitted pseudorange σ, chi-square test,
    protection levels, the check along the Doppler velocities) at both origins: positions,
    σ, protection levels and validity equal."""
    sequence = _recording(name, drive_1hz, tmp_path_factory)
    shifted = shifted_sequence(sequence, SHIFT)
    first = gnss_position(sequence.observations, sequence.navigation)
    second = gnss_position(shifted.observations, shifted.navigation)
    assert first.valid.any() and np.isfinite(first.position_ecef).all(axis=1).sum() >= 10
    _assert_same_fixes(name, first, second)


def _numbers(value, path="") -> dict[str, float]:
    """Every number of a JSON value by its path."""
    if isinstance(value, dict):
        return {
            k: v for key, item in value.items() for k, v in _numbers(item, f"{path}.{key}").items()
        }
    if isinstance(value, list):
        return {
            k: v for i, item in enumerate(value) for k, v in _numbers(item, f"{path}[{i}]").items()
        }
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return {path: float(value)}
    return {}


def _assert_same_numbers(first: dict, second: dict, times: str | None, tolerance: float):
    """The numbers of two JSON summaries equal within ``tolerance`` (relative or absolute), those
    whose path matches the pattern ``times`` less :data:`SHIFT`; the same keys."""
    a, b = _numbers(first), _numbers(second)
    assert a.keys() == b.keys()
    for key, value in a.items():
        other = b[key] - SHIFT if times and re.search(times, key) else b[key]
        assert other == pytest.approx(value, rel=tolerance, abs=tolerance, nan_ok=True), key


@pytest.fixture(scope="module")
def correct_inputs(drive_1hz, tmp_path_factory):
    """The 1-Hz drive's dead-reckoning track (vehicle poses, level), its heading table and its
    ground truth, written as files at both origins."""
    result = run_sequence(drive_1hz)
    folders = {}
    for origin, dt in ORIGINS.items():
        folder = tmp_path_factory.mktemp(origin)
        track = result.trajectories["dr"]
        write_tum(folder / "dr.tum", dataclasses.replace(track, t=track.t + dt))
        write_heading_csv(
            folder / "heading.csv", dataclasses.replace(result.heading, t=result.heading.t + dt)
        )
        truth = drive_1hz.truth
        write_tum(folder / "truth.tum", dataclasses.replace(truth, t=truth.t + dt))
        folders[origin] = folder
    return folders


def _json_output(argv, capsys) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out.strip().splitlines()[-1])


@pytest.mark.parametrize("correction", ["kalman", "window"])
def test_correct_and_eval_give_the_same_figures_at_another_time_origin(
    correct_inputs, correction, capsys
):
    """`correct` of the same track with the same headings, then `eval` of the result against
    the truth with every alignment: the same summary (turns, poses with an absolute heading, the
    Kalman blend's fitted noise), the same corrected poses within 1 mm, the same errors."""
    summaries, corrected, scores = {}, {}, {}
    for origin, folder in correct_inputs.items():
        out = folder / f"corrected_{correction}.tum"
        argv = ["-q", "correct", str(folder / "dr.tum"), "--heading", str(folder / "heading.csv")]
        argv += ["--world", "level", "--correction", correction, "-o", str(out)]
        summaries[origin] = _json_output(argv, capsys)
        corrected[origin] = read_tum(out)
        scores[origin] = {
            align: _eval_json(out, folder, align, capsys)
            for align in ("none", "start", "se2", "sim3")
        }
    assert summaries["own"]["poses_with_absolute_heading"] > 0.8 * summaries["own"]["poses"]
    _assert_same_numbers(summaries["own"], summaries["shifted"], None, 1e-6)
    np.testing.assert_allclose(corrected["shifted"].t - SHIFT, corrected["own"].t, atol=1e-6)
    np.testing.assert_allclose(
        corrected["shifted"].positions, corrected["own"].positions, atol=1e-3
    )
    for align, own in scores["own"].items():
        assert own["path_length_m"] > 100.0, align
        _assert_same_numbers(own, scores["shifted"][align], None, 1e-6)


def _eval_json(trajectory, folder, align: str, capsys) -> dict:
    argv = ["-q", "eval", str(trajectory), str(folder / "truth.tum"), "--align", align, "--json"]
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def _deadreckon(paths: dict, folder, extra: list[str]) -> tuple[dict, str]:
    out = folder / "out"
    argv = ["-q", "deadreckon", "--gyro1", str(paths["gyro1"]), "--gyro2", str(paths["gyro2"])]
    assert main([*argv, "--gps", str(paths["gps"]), "-o", str(out), *extra]) == 0
    summary = json.loads((out / "deadreckon_summary.json").read_text())
    return summary, (out / "drift_table.csv").read_text()


DEADRECKON_TIMES = r"^\.standstills?\[|\.t[01]_s$"
"""The summary's GPS times (shifted with the inputs): the standstill or straight stretch, the
standstills found, the span the initial heading was fitted over."""


def _assert_same_deadreckoning(runs: dict) -> None:
    """Both origins: the same drift table as written (within 1e-5 of its six decimals of deg/min
    and degrees, four of metres: a value on a rounding edge may print one unit apart) and the
    same summary numbers."""
    (own, own_table), (shifted, shifted_table) = runs["own"], runs["shifted"]
    rows = [list(csv.reader(io.StringIO(table))) for table in (own_table, shifted_table)]
    assert [r[0] for r in rows[0]] == [r[0] for r in rows[1]] and rows[0][0] == rows[1][0]
    numbers = [np.array([r[1:] for r in table[1:]], dtype=float) for table in rows]
    np.testing.assert_allclose(numbers[1], numbers[0], rtol=1e-5, atol=1e-5)
    _assert_same_numbers(own, shifted, DEADRECKON_TIMES, 1e-5)


def test_deadreckon_on_the_comma2k19_minute_is_the_same_at_another_time_origin(tmp_path):
    """The README's run: IMU gyro and CAN yaw rate as the two gyros, the u-blox fixes, k and ε0
    over the first 5 s of straight driving (`--straight T0,T0+5`)."""
    _, fixes, gyro, can = read_lowcost_inputs(require_shared(COMMA))
    start = max(gyro[0][0], can[0][0], fixes.t[0])
    runs = {}
    for origin, dt in ORIGINS.items():
        folder = tmp_path / origin
        folder.mkdir()
        paths = {name: folder / f"{name}.csv" for name in ("gyro1", "gyro2", "gps")}
        for name, (t, rate) in (("gyro1", gyro), ("gyro2", can)):
            write_sensor_csv(paths[name], SensorSeries(t + dt, rate), YAW_RATE_COLUMN)
        t, lat, lon = fixes.as_tuple()
        write_gps_csv(paths["gps"], t + dt, lat, lon)
        straight = f"{float(start + dt)!r},{float(start + dt + 5.0)!r}"
        runs[origin] = _deadreckon(paths, folder, ["--straight", straight])
    assert runs["own"][0]["initial_heading"]["fixes"] >= 40
    _assert_same_deadreckoning(runs)


def test_deadreckon_on_a_generated_two_gyro_record_is_the_same_at_another_time_origin(tmp_path):
    """10 min of standstill (found from the GPS speed), a closed loop with 1-Hz GPS."""
    record = generate_two_gyro(TwoGyroSpec(t_start=0.0))
    runs = {}
    for origin, dt in ORIGINS.items():
        moved = dataclasses.replace(
            record,
            gyro1=(record.gyro1[0] + dt, record.gyro1[1]),
            gyro2=(record.gyro2[0] + dt, record.gyro2[1]),
            gps=(record.gps[0] + dt, *record.gps[1:]),
        )
        runs[origin] = _deadreckon(write_two_gyro(moved, tmp_path / origin), tmp_path / origin, [])
    assert runs["own"][0]["route_closes"]
    _assert_same_deadreckoning(runs)
