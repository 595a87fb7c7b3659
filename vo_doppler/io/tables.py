"""Flat tables written as CSV and Parquet (Apache Arrow), with one typed schema for both."""

from __future__ import annotations

from pathlib import Path

import pyarrow as pa
import pyarrow.csv as pa_csv
import pyarrow.parquet as pq

ARROW_TYPES = {str: pa.string(), float: pa.float64(), int: pa.int64()}


def arrow_table(columns: dict[str, type], rows: list[dict]) -> pa.Table:
    """Rows (dictionaries; a missing key or None is a null) as a table with ``columns``
    (name → ``str``, ``float`` or ``int``), in that order."""
    schema = pa.schema([(name, ARROW_TYPES[kind]) for name, kind in columns.items()])
    return pa.Table.from_pylist([{k: row.get(k) for k in columns} for row in rows], schema=schema)


def write_csv_and_parquet(
    columns: dict[str, type], rows: list[dict], csv_path: Path, parquet_path: Path
) -> None:
    """The same table twice: CSV (header line, empty cells for nulls) and Parquet."""
    table = arrow_table(columns, rows)
    pa_csv.write_csv(table, csv_path)
    pq.write_table(table, parquet_path)
