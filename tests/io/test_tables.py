"""One typed table written as CSV and Parquet: column order and types from the schema, a
missing key or None a null, the same values in both files."""

from __future__ import annotations

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from vo_doppler.io.tables import arrow_table, write_csv_and_parquet

COLUMNS = {"sat": str, "t": float, "n": int}
ROWS = [
    {"n": 3, "t": 1.5, "sat": "G05", "ignored": "x"},
    {"sat": "E11", "t": None},
    {"sat": "R02", "t": -2.25, "n": -1},
]


def test_the_table_has_the_schema_order_types_and_nulls():
    table = arrow_table(COLUMNS, ROWS)
    assert table.schema == pa.schema([("sat", pa.string()), ("t", pa.float64()), ("n", pa.int64())])
    assert table.to_pydict() == {
        "sat": ["G05", "E11", "R02"],
        "t": [1.5, None, -2.25],
        "n": [3, None, -1],
    }


def test_a_value_of_the_wrong_type_is_refused():
    with pytest.raises((pa.ArrowInvalid, pa.ArrowTypeError)):
        arrow_table({"n": int}, [{"n": "three"}])


def test_csv_and_parquet_hold_the_same_table(tmp_path):
    csv_path, parquet_path = tmp_path / "t.csv", tmp_path / "t.parquet"
    write_csv_and_parquet(COLUMNS, ROWS, csv_path, parquet_path)
    assert csv_path.read_text().splitlines() == [
        '"sat","t","n"',
        '"G05",1.5,3',
        '"E11",,',
        '"R02",-2.25,-1',
    ]
    assert pq.read_table(parquet_path).equals(arrow_table(COLUMNS, ROWS))
