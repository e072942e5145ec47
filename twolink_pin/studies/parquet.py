"""A sweep's rows as a Parquet dataset: ``runs/part-<first run>.parquet``, one file per chunk.

* :func:`table_schema` — the columns typed (``run`` int64, the flags :data:`FLAGS` bool,
  :data:`TEXTS` strings, every other column float64 and nullable), each with its SI unit in its field metadata
  (``b"unit"``), and the sweep's configuration as JSON in the schema metadata under
  :data:`METADATA_KEY`;
* :func:`chunk_table` and :func:`write_part` — one chunk's rows, NaN as null (a diverged
  run's metrics, ``diverged_at`` of a run that did not diverge: SQL's aggregates skip them),
  to its file (zstd);
* :func:`read_part`, :func:`read_columns`, :func:`read_metadata` — back, file by file, in
  run order (the file names sort in run order).

pandas (``read_parquet(out / "runs")``), polars (``read_parquet(out / "runs/*.parquet")``)
and DuckDB (``FROM 'out/runs/*.parquet'``) read the folder as one table.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from twolink_pin.errors import InvalidParameterError

METADATA_KEY = b"twolink_pin.sweep"
"""Schema-metadata key of the sweep's configuration (JSON) in every Parquet file."""
RUNS_FOLDER = "runs"
"""The dataset's folder in a sweep's output folder."""
FLAGS = ("limit_exceeded", "diverged", "position_crossed", "velocity_crossed")
"""The boolean columns."""
RUN = "run"
"""The int64 column: the run's index."""
REASON = "diverged_reason"
"""The text column: why a run ended early (its law's reason, e.g. an ``mpc`` replan that could
not hold its limits, or the state that became non-finite); null for a run that went to its end."""
TEXTS = (REASON,)
"""The string columns (nullable): given beside a chunk's numbers (:func:`chunk_table`)."""


def part_name(start: int) -> str:
    """File name of the chunk whose first run is ``start`` (sorts in run order)."""
    return f"part-{start:07d}.parquet"


def part_starts(folder: str | Path) -> list[int]:
    """First runs of the chunk files in ``folder``, in order."""
    return sorted(int(p.name[len("part-") : -len(".parquet")]) for p in Path(folder).glob("part-*.parquet"))


def table_schema(columns: Sequence[str], units: Mapping[str, str], metadata: Mapping[str, Any]) -> Any:
    """The ``pyarrow.Schema`` of a sweep's rows (see the module docstring)."""
    import pyarrow as pa

    types = {RUN: pa.int64(), **{name: pa.bool_() for name in FLAGS}, **{name: pa.string() for name in TEXTS}}
    fields = [
        pa.field(
            name,
            types.get(name, pa.float64()),
            nullable=name not in types or name in TEXTS,
            metadata={b"unit": units[name].encode()} if units.get(name) else None,
        )
        for name in columns
    ]
    return pa.schema(fields, metadata={METADATA_KEY: json.dumps(dict(metadata), allow_nan=False).encode()})


def chunk_table(
    values: np.ndarray, schema: Any, texts: Mapping[str, Sequence[str | None]] | None = None
) -> Any:
    """The ``pyarrow.Table`` of one chunk from its rows as floats, shape (n, columns) in the
    schema's order without the :data:`TEXTS` columns (the run index and the flags as numbers
    too; NaN becomes null), and the text columns' values (None: null; absent: all null)."""
    import pyarrow as pa

    arrays = []
    j = 0
    for column in schema:
        if column.name in TEXTS:
            given = (texts or {}).get(column.name)
            arrays.append(
                pa.array(list(given) if given is not None else [None] * values.shape[0], type=pa.string())
            )
            continue
        x = np.ascontiguousarray(values[:, j])
        j += 1
        if column.name == RUN:
            arrays.append(pa.array(x.astype(np.int64)))
        elif column.name in FLAGS:
            arrays.append(pa.array(x != 0))
        else:
            arrays.append(pa.array(x, type=pa.float64(), mask=np.isnan(x)))
    return pa.Table.from_arrays(arrays, schema=schema)


def write_part(table: Any, folder: Path, start: int) -> Path:
    """Write a chunk's table to ``folder / part_name(start)`` (zstd)."""
    import pyarrow.parquet as pq

    path = folder / part_name(start)
    pq.write_table(table, path, compression="zstd")
    return path


def read_part(folder: str | Path, start: int, schema: Any = None) -> Any:
    """The table of the chunk whose first run is ``start``."""
    import pyarrow.parquet as pq

    return pq.read_table(Path(folder) / part_name(start), schema=schema)


def read_metadata(path: str | Path) -> dict[str, Any]:
    """The sweep's configuration stored in a Parquet file of ``runs/`` (or in the folder's first).

    Raises:
        InvalidParameterError: no Parquet file of a sweep there.
    """
    import pyarrow.parquet as pq

    file = Path(path)
    expected = "a sweep's runs/ folder (part-*.parquet files) or one of its files"
    if file.is_dir():
        starts = part_starts(file)
        if not starts:
            raise InvalidParameterError("folder", str(file), expected)
        file = file / part_name(starts[0])
    if not file.is_file():
        raise InvalidParameterError("path", str(file), expected)
    metadata = pq.read_schema(file).metadata or {}
    if METADATA_KEY not in metadata:
        raise InvalidParameterError(
            "file", str(file), f"a sweep's Parquet file (schema metadata {METADATA_KEY!r})"
        )
    return dict(json.loads(metadata[METADATA_KEY]))


def read_columns(folder: str | Path, names: Sequence[str], every: int = 1) -> dict[str, np.ndarray]:
    """Columns ``names`` of the dataset in ``folder`` in run order, of runs ``0, every,
    2·every, ...``: floats (nulls as NaN), bools (the flags) or ints (``run``). Reads file
    by file into arrays of their final size (memory: the columns, plus one chunk's).

    Raises:
        InvalidParameterError: the files do not hold the sweep's runs (some missing).
    """
    import pyarrow.parquet as pq

    root = Path(folder)
    total = int(read_metadata(root)["samples"])
    kept = len(range(0, total, every))
    kinds = {RUN: np.int64, **{name: bool for name in FLAGS}}
    out = {name: np.empty(kept, dtype=kinds.get(name, float)) for name in names}
    position = 0
    for start in part_starts(root):
        table = pq.read_table(root / part_name(start), columns=list(names) or [RUN])
        count = len(range((-start) % every, table.num_rows, every))
        for name in names:
            values = table.column(name).to_numpy(zero_copy_only=False)[(-start) % every :: every]
            out[name][position : position + count] = values
        position += count
    if position != kept:
        raise InvalidParameterError("folder", str(root), f"the {total} runs of its sweep, got {position}")
    return out


__all__ = [
    "FLAGS",
    "METADATA_KEY",
    "REASON",
    "RUN",
    "RUNS_FOLDER",
    "TEXTS",
    "chunk_table",
    "part_name",
    "part_starts",
    "read_columns",
    "read_metadata",
    "read_part",
    "table_schema",
    "write_part",
]
