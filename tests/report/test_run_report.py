"""The run report's pieces on exact cases: headline, table cells, worst epochs, the map and
GeoJSON, the configuration in degrees, synthetic vs recorded, the definitions."""

from __future__ import annotations

import dataclasses
import json
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.conftest import REPO_ROOT
from tests.helpers.heading_table import plain_heading_table
from vo_doppler.eval.pipelines import PipelineErrors
from vo_doppler.fusion.correction import CorrectionConfig
from vo_doppler.geo import EnuFrame, geodetic_to_ecef
from vo_doppler.gnss.doppler_velocity import MIN_SATELLITES
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.io.sequence import read_manifest, read_sequence
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.heading_figure import build_heading_figure, continuous_course_deg
from vo_doppler.report.provenance import config_rows, describe_data, is_synthetic, main_settings
from vo_doppler.report.run_report import (
    GLOSSARY,
    build_heading_error_figure,
    glossary,
    heading_error_over_time,
    headline,
    table_cell,
    worst_reliable_tight_errors,
)
from vo_doppler.report.trajectory_map import lon_lat, map_html, thinned, write_geojson
from vo_doppler.run import RunConfig
from vo_doppler.units import unit_of

LAT, LON = 35.6938, 139.7034
ENU = EnuFrame.from_ecef(geodetic_to_ecef(np.radians(LAT), np.radians(LON), 77.0))


def _errors(per_100m: float) -> PipelineErrors:
    return PipelineErrors(per_100m, 2 * per_100m, per_100m, 1.0, 0.1, 0.5, 0.9, 1.0, 300.0)


def test_headline_states_the_cut_or_says_plainly_it_did_not_help():
    cut = headline({"vo": _errors(1.2), "vo_gps_tc": _errors(0.3)}, 0.9)
    assert cut == (
        "The tightly coupled Doppler heading gave the VO its lowest error: 0.30 m per 100 m, "
        "4.0× less than the best other, the VO alone (1.20)."
    )
    worse = headline({"vo": _errors(0.2), "vo_gps_tc": _errors(0.23)}, 0.9)
    assert "did not help" in worse and "the VO alone did as well or better, 0.20" in worse
    assert "No ground truth" in headline({}, 0.93) and "93%" in headline({}, 0.93)
    assert headline({}, 0.93, covered_epochs=700).endswith(
        "used by the correction at 93% of the 700 GNSS epochs with vehicle signals (wheel speed "
        "and yaw rate)."
    )
    no_camera = headline(
        {"dr": _errors(2.0), "dr_gps_conv": _errors(0.8), "dr_gps_tc": _errors(0.4)}, 0.9
    )
    assert no_camera == (
        "No camera: The tightly coupled Doppler heading gave the wheel + gyro dead reckoning its "
        "lowest error: 0.40 m per 100 m, 2.0× less than the best other, the wheel + gyro dead "
        "reckoning with the conventional Doppler heading (0.80); the wheel + gyro dead "
        "reckoning alone: 2.00."
    )
    partial = headline({"dr_gps_tc": _errors(0.4)}, 0.9)
    assert partial == "Error per 100 m (m): wheel + gyro DR + GPS (tightly coupled) 0.40."


def test_headline_compares_with_the_best_other_pipeline_not_the_uncorrected_one():
    """Issue 30: a drive where the conventional heading did better (1.40 against 1.64 m per
    100 m) was credited to the tightly coupled one ("3.8× less" than the VO alone)."""
    said = headline(
        {"vo": _errors(6.2), "vo_gps_conv": _errors(1.4), "vo_gps_tc": _errors(1.64)}, 0.9
    )
    assert said == (
        "The tightly coupled Doppler heading did not help on this drive: the VO with the "
        "conventional Doppler heading did as well or better, 1.40 m per 100 m against 1.64 with "
        "the tightly coupled heading; the VO alone: 6.20."
    )
    assert "less" not in said
    tie = headline(
        {"vo": _errors(2.0), "vo_gps_conv": _errors(0.501), "vo_gps_tc": _errors(0.5)}, 1.0
    )
    assert tie.startswith("The tightly coupled Doppler heading did not help on this drive")


def test_vo_alone_heading_use_is_a_dash_not_zero():
    assert table_cell("vo", "heading_availability", 0.0, "{:.0%}") == "—"
    assert table_cell("dr", "heading_availability", 0.0, "{:.0%}") == "—"
    assert table_cell("vo_gps_tc", "heading_availability", 0.93, "{:.0%}") == "93%"
    assert table_cell("vo", "heading_rmse_deg", float("nan"), "{:.2f}") == "—"


def _table(n: int = 40) -> HeadingTable:
    return plain_heading_table(100.0 + 0.1 * np.arange(n), conv_valid=np.zeros(n, bool))


def test_worst_errors_list_reliable_epochs_with_their_use_and_satellites():
    table = _table()
    truth = np.zeros(len(table))
    truth[5], truth[6], truth[30] = np.radians(16.0), np.radians(10.0), np.radians(-3.0)
    table.n_sat_epoch[5] = 1
    table.tc_reliable[30] = False
    used = np.ones(len(table), bool)
    used[5:7] = False
    worst = worst_reliable_tight_errors(table, used, truth, count=3)
    assert [round(w.time_s, 2) for w in worst][:1] == [0.5]
    first = worst[0]
    assert abs(first.error_deg - 16.0) < 1e-9
    assert (first.satellites, first.used) == (1, False)
    # the neighbour 0.1 s later (10°) is within a second: skipped; the unreliable epoch too
    assert all(abs(w.time_s - 0.6) > 1e-9 and abs(w.time_s - 3.0) > 1e-9 for w in worst)


def test_course_is_unwrapped_across_north():
    course = np.radians(np.array([358.0, 359.0, 0.5, 1.5, np.nan, 3.0]))
    shown = continuous_course_deg(course, course)
    np.testing.assert_allclose(shown[[0, 1, 2, 3, 5]], [358.0, 359.0, 360.5, 361.5, 363.0])


def test_heading_figure_has_an_availability_strip_of_its_own():
    table = _table()
    figure = build_heading_figure(table, np.zeros(len(table)), "t", np.ones(len(table), bool))
    strip = figure.axes[1]
    labels = [tick.get_text() for tick in strip.get_yticklabels()]
    assert labels == ["conventional available", "tightly coupled available", "tightly coupled used"]
    assert len(figure.axes) == 4 and figure.axes[0].get_ylim()[0] == 0


def _track(n: int = 50, heading_deg: float = 0.0) -> Trajectory:
    t = np.arange(n, dtype=float)
    positions = np.column_stack([10.0 * t, 5.0 * t, np.zeros(n)])
    return Trajectory(
        t, positions, Rotation.from_euler("z", np.full((n, 1), np.radians(heading_deg)))
    )


def test_heading_error_over_time_is_the_yaw_difference():
    error = heading_error_over_time(_track(heading_deg=2.0), _track())
    np.testing.assert_allclose(np.degrees(error), 2.0, atol=1e-9)


def test_heading_error_axis_turns_logarithmic_only_beside_much_larger_errors():
    truth = _track()
    close = {"vo": _track(heading_deg=0.3), "vo_gps_tc": _track(heading_deg=0.1)}
    assert build_heading_error_figure(close, truth, 0.0, "").axes[0].get_yscale() == "linear"
    apart = {**close, "vo_gps_conv": _track(heading_deg=25.0)}
    ax = build_heading_error_figure(apart, truth, 0.0, "").axes[0]
    assert ax.get_yscale() == "symlog"
    assert any("logarithmic beyond" in text.get_text() for text in ax.texts)


def test_geojson_is_lon_lat_and_starts_at_the_origin(tmp_path):
    track = _track()  # its first position is the origin
    write_geojson(tmp_path / "t.geojson", {"vo": track}, {"vo": "VO alone"}, ENU)
    data = json.loads((tmp_path / "t.geojson").read_text())
    (feature,) = data["features"]
    assert feature["properties"] == {"name": "vo", "label": "VO alone"}
    lon0, lat0 = feature["geometry"]["coordinates"][0]
    assert abs(lon0 - LON) < 1e-8 and abs(lat0 - LAT) < 1e-8
    np.testing.assert_allclose(lon_lat(ENU, np.zeros((1, 3)))[0], [LON, LAT], atol=1e-9)


def test_map_is_inline_svg_and_loads_no_tile_until_asked():
    page = map_html({"truth": _track(), "vo": _track()}, {"vo": "VO alone"}, ENU)
    assert page.count("<polyline") == 2 and "<svg id='map'" in page
    assert "tile.openstreetmap.org" in page and "<image" not in page
    assert "if (!osm.checked) return;" in page


def test_the_evaluated_tracks_are_a_hidden_layer_of_their_own():
    moved = _track().transformed(np.eye(3), np.full(3, 5.0))
    page = map_html({"truth": _track(), "vo": _track()}, {"vo": "VO alone"}, ENU, {"vo": moved})
    layer = page[page.index("<g id='evaluated-tracks' display='none'>") :]
    assert layer.count("<polyline") == 1 and "VO alone, as evaluated" in layer
    assert page.count("<polyline") == 3 and "id='evaluated'" in page
    plain = map_html({"vo": _track()}, {"vo": "VO alone"}, ENU)
    assert "<g id='evaluated-tracks'" not in plain and "id='evaluated'" not in plain


def test_the_definition_of_available_needs_the_satellites_the_velocity_test_needs():
    """A conventional velocity is verified with more than ``MIN_SATELLITES`` satellites."""
    available = dict(GLOSSARY)["available"]
    assert MIN_SATELLITES == 4 and "(5 or more satellites" in available


def test_long_tracks_are_thinned_keeping_the_last_pose():
    rows = thinned(np.arange(10_001.0)[:, None], 1000)
    assert len(rows) <= 1001 and rows[-1, 0] == 10_000.0 and rows[0, 0] == 0.0


def test_configuration_is_in_degrees_for_people():
    rows = dict(config_rows(RunConfig()))
    assert rows["elevation_mask_deg"] == "10 deg"
    assert rows["heading.gate.max_yaw_jump_deg"] == "2 deg"
    assert rows["heading.gate.max_yaw_drift_deg_s"] == "1 deg/s"
    assert rows["heading.backfill_bias_sigma_deg_s"] == "0.05 deg/s"
    assert rows["heading.tight_calibration_max_sigma_deg"] == "5 deg"
    assert rows["heading.fixed_gyro_bias_deg_s"] == "None"
    assert rows["correction.blend.default_sigma_distance_deg_per_sqrt_m"] == "0.1146 deg/√m"
    assert dict(main_settings(RunConfig()))["elevation mask"] == "10.0 deg"


def _angle_fields(config, prefix: str = "") -> dict[str, tuple[float | None, str]]:
    """Every angle of a configuration by its dotted name in people units: its value in radians
    and its people unit, found by the unit its name ends in (:func:`vo_doppler.units.unit_of`)."""
    angles = {}
    for f in dataclasses.fields(config):
        value = getattr(config, f.name)
        if dataclasses.is_dataclass(value):
            angles |= _angle_fields(value, f"{prefix}{f.name}.")
        elif (unit := unit_of(f.name)) is not None and unit.people_suffix is not None:
            shown = prefix + f.name[: -len(unit.suffix)] + unit.people_suffix
            angles[shown] = value, unit.people_symbol
    return angles


def test_the_full_configuration_table_shows_every_angle_in_degrees():
    """The report's table (RunConfig, every stage) had raw radians where a hand list of angle
    fields had not followed a new one: ``heading.backfill_bias_sigma 0.0008727``."""
    config = RunConfig(
        heading=HeadingPipelineConfig(fixed_gyro_bias_rad_s=np.radians(0.25)),
        correction=CorrectionConfig(gate_rad=np.radians(30.0)),
    )
    rows = dict(config_rows(config))
    assert not [name for name in rows if unit_of(name) and unit_of(name).symbol.startswith("rad")]
    angles = _angle_fields(config)
    assert len(angles) >= 26
    for name, (radians, people) in angles.items():
        if radians is None:
            assert rows[name] == "None"
            continue
        value, symbol = rows[name].split(" ")
        assert symbol == people and symbol.startswith("deg")
        assert float(value) == pytest.approx(np.degrees(radians), rel=5e-4)
    assert rows["heading.fixed_gyro_bias_deg_s"] == "0.25 deg/s"
    assert rows["correction.gate_deg"] == "30 deg"


def test_settings_and_definitions_of_what_did_not_run_are_left_out():
    """Issue 30: a drive without a camera showed "VO window 20 frames" and the VO's
    definitions."""
    config = RunConfig()
    assert "VO window" in dict(main_settings(config))
    no_camera = dict(main_settings(config, camera=False))
    assert "VO window" not in no_camera and "GNSS systems" in no_camera
    assert "dead-reckoning heading compared as" in no_camera
    assert not [name for name, _ in config_rows(config, camera=False) if name.startswith("vo.")]
    assert dict(config_rows(config, camera=False))["correction.method"] == "kalman"
    terms = dict(glossary(camera=False))
    assert "VO alone / + GPS" not in terms and "available" in terms
    assert "wheel + gyro DR alone / + GPS" in terms
    no_gnss = dict(main_settings(config, gnss=False))
    assert set(no_gnss) == {"VO window", "dead-reckoning rate"}
    assert not [
        name
        for name, _ in config_rows(config, gnss=False)
        if name.startswith(("heading.", "correction.", "systems", "elevation_mask"))
    ]
    assert set(dict(glossary(gnss=False))) & {"available", "reliable", "σ (sigma)"} == set()
    assert glossary() == list(GLOSSARY)


def test_a_manifest_with_the_simulators_keys_is_synthetic():
    assert is_synthetic({"scenario": "urban-canyon", "command": "vo-doppler simulate"})
    assert not is_synthetic({"name": "drive"}) and not is_synthetic(None)


def test_the_sample_is_described_as_a_synthetic_drive_with_its_sensors():
    folder = REPO_ROOT / "sample_sequences" / "urban_canyon_small"
    sequence, manifest = read_sequence(folder), read_manifest(folder)
    data = describe_data(sequence, manifest)
    assert data.kind == "synthetic" and "vo-doppler simulate --scenario urban-canyon" in data.origin
    assert abs(data.distance_m - manifest["stats"]["path_length_m"]) < 1.0
    assert data.distance_source == "ground truth"
    assert abs(data.duration_s - manifest["duration_s"]) < 0.5
    assert data.sensors[0] == "monocular camera (570 images, 15.0 frames/s)"
    assert any(s.startswith("GNSS receiver (761 epochs, systems EG") for s in data.sensors)
    unstated = describe_data(sequence, None, driven_m=300.0)
    assert unstated.kind == "" and unstated.origin.startswith("not stated")


def test_the_report_shows_the_heading_settings_that_ran():
    """``--heading-method auto`` resolved for the recording's GNSS rate: a 1-Hz recording's
    report says robust (and its configuration table the robust values), a 20-Hz one's snooping;
    an unresolved configuration states auto's rule."""
    auto = RunConfig()
    assert dict(main_settings(auto))["tight heading settings"] == (
        "auto: robust below 10 Hz GNSS, else snooping"
    )
    for step_s, words, window in (
        (1.0, "robust, smoothed through the gyro", "8"),
        (0.05, "snooping", "2"),
    ):
        recording = SimpleNamespace(
            has_gnss=True,
            observations=SimpleNamespace(epoch_time=1000.0 + np.arange(0.0, 30.0, step_s)),
        )
        ran = auto.for_sequence(recording)
        assert dict(main_settings(ran))["tight heading settings"] == words
        rows = dict(config_rows(ran))
        assert rows["heading.method"] == words.split(",")[0]
        assert rows["heading.tight.max_window_s"].split()[0] == window
    assert auto.for_sequence(SimpleNamespace(has_gnss=False)) is auto
