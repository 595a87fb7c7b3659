import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.io.doppler_sigma import HEADER, read_doppler_sigma, write_doppler_sigma
from vo_doppler.model.doppler_sigma import ReportedSigma

HEAD = ",".join(HEADER) + "\n"


@settings(max_examples=40, deadline=None)
@given(
    st.lists(
        st.tuples(
            st.integers(0, 10**9),
            st.sampled_from(["G01", "G32", "E36", "C05", "R24", "J02"]),
            st.sampled_from(["D1C", "D5Q", "D2"]),
            st.floats(1e-4, 1e3),
        ),
        max_size=30,
        unique_by=lambda row: (row[0], row[1], row[2]),
    )
)
def test_round_trip_keeps_every_row(tmp_path_factory, rows):
    t = np.array([r[0] * 1e-3 for r in rows], dtype=float)
    table = ReportedSigma(
        t,
        np.array([r[1] for r in rows], dtype="U3"),
        np.array([r[2] for r in rows], dtype="U3"),
        np.array([r[3] for r in rows], dtype=float),
    )
    path = tmp_path_factory.mktemp("sigma") / "doppler_sigma.csv"
    write_doppler_sigma(path, table)
    back = read_doppler_sigma(path)
    assert back.t.tolist() == pytest.approx(t.tolist(), abs=5e-4)
    assert back.sat_id.tolist() == table.sat_id.tolist()
    assert back.code.tolist() == table.code.tolist()
    assert back.sigma_mps == pytest.approx(table.sigma_mps, rel=1e-5)


@pytest.mark.parametrize(
    "row, message",
    [
        ("1000.0,G05,D1C", "3 fields"),
        ("x,G05,D1C,0.1", "not a number"),
        ("nan,G05,D1C,0.1", "not a GPS time"),
        ("-1,G05,D1C,0.1", "not a GPS time"),
        ("1e12,G05,D1C,0.1", "not a GPS time"),
        ("1000.0,G99,D1C,0.1", "no satellite 'G99'"),
        ("1000.0,X05,D1C,0.1", "no satellite"),
        ("1000.0,G5,D1C,0.1", "no satellite"),
        ("1000.0,G05,C1C,0.1", "not a RINEX Doppler code"),
        ("1000.0,G05,D1C,0", "not a finite positive"),
        ("1000.0,G05,D1C,-0.2", "not a finite positive"),
        ("1000.0,G05,D1C,inf", "not a finite positive"),
        ("1000.0,G05,D1C,nan", "not a finite positive"),
    ],
)
def test_a_bad_row_is_an_error_naming_its_line(tmp_path, row, message):
    path = tmp_path / "doppler_sigma.csv"
    path.write_text(HEAD + "999.0,G01,D1C,0.05\n" + row + "\n")
    with pytest.raises(InputError, match=message) as caught:
        read_doppler_sigma(path)
    assert f"{path}:3" in str(caught.value)


def test_a_repeated_row_names_both_lines(tmp_path):
    path = tmp_path / "doppler_sigma.csv"
    path.write_text(HEAD + "1000.0,G05,D1C,0.05\n1000.0,G07,D1C,0.05\n1000.0004,G05,D1C,0.07\n")
    with pytest.raises(InputError, match="line 2") as caught:
        read_doppler_sigma(path)
    assert f"{path}:4" in str(caught.value)


def test_a_wrong_header_is_named_at_line_one(tmp_path):
    path = tmp_path / "doppler_sigma.csv"
    path.write_text("t,sat,code,sigma\n1000.0,G05,D1C,0.05\n")
    with pytest.raises(InputError, match="header") as caught:
        read_doppler_sigma(path)
    assert f"{path}:1" in str(caught.value)
