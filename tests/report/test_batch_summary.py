"""The batch aggregate keeps each recording's warnings: counted and joined in the table, listed
in the HTML page under the recording's name, summed in the overall row."""

from __future__ import annotations

from vo_doppler.report.batch_summary import (
    COLUMNS,
    OVERALL,
    WARNING_SEPARATOR,
    overall_row,
    recording_row,
    warnings_status,
    write_batch_html,
)

KMH = "wheel scale: the calibration gives 0.275 (km/h reads 0.278) <check>"
CLOCK = "CAN clock: residual offset 0.3 s"


def _rows() -> list[dict]:
    warned = recording_row("kmh", "done", None, None, 7.0, {"warnings": [KMH, CLOCK]})
    clean = recording_row("clean", "done", None, None, 5.0, {"warnings": []})
    failed = recording_row("bad", "failed", "input-error", "bad.obs:3: no header", 0.0, None)
    rows = [warned, clean, failed]
    return [*rows, overall_row(rows)]


def test_rows_count_and_join_the_warnings_and_the_overall_row_sums_them():
    warned, clean, failed, overall = _rows()
    assert {"warnings", "warning_texts"} <= set(COLUMNS)
    assert warned["warnings"] == 2 and warned["warning_texts"] == KMH + WARNING_SEPARATOR + CLOCK
    assert clean["warnings"] == 0 and clean["warning_texts"] is None
    assert failed.get("warnings") is None
    assert overall["recording"] == OVERALL and overall["warnings"] == 2


def test_the_page_lists_each_recordings_warnings_under_its_name(tmp_path):
    page_path = tmp_path / "batch_summary.html"
    write_batch_html(page_path, _rows())
    page = page_path.read_text()
    warnings = page[page.index("<h2>Warnings</h2>") :]
    assert "<a href='kmh/report.html'>kmh</a>" in warnings and "clean" not in warnings
    assert "<li>wheel scale: the calibration gives 0.275 (km/h reads 0.278) &lt;check&gt;</li>" in (
        warnings
    )
    assert f"<li>{CLOCK}</li>" in warnings
    assert "<th>warnings</th>" in page and "<td>2</td>" in page


def test_a_status_says_how_many_warnings():
    assert warnings_status("done", 0) == "done"
    assert warnings_status("done", 1) == "done, 1 warning"
    assert warnings_status("skipped", 3) == "skipped, 3 warnings"
