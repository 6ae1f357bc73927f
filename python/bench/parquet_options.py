"""Sizes and write times of one results file written with other lossless Parquet settings
(float64 kept): zstd levels, brotli, byte-stream split or plain, the time column as an integer
step index with DELTA_BINARY_PACKED; float32 (lossy) for comparison only. pyarrow uses the
same zstd library and the same encodings as the master's writer; xz gives an idea of how far
any general-purpose lossless compressor gets.

    .venv/bin/python python/bench/parquet_options.py RESULTS.parquet [CSV_100HZ]
"""

from __future__ import annotations

import io
import lzma
import os
import sys
import time

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq


def written(table: pa.Table, **options) -> "tuple[int, float]":
    best = float("inf")
    for _ in range(3):
        buf = io.BytesIO()
        started = time.perf_counter()
        pq.write_table(table, buf, **options)
        best = min(best, time.perf_counter() - started)
    return buf.tell(), best


def main(path: str, csv: "str | None") -> None:
    table = pq.read_table(path)
    meta = table.schema.metadata
    time_col = table.column_names[0]
    floats = [n for n in table.column_names[1:] if pa.types.is_float64(table.schema.field(n).type) and table.column(n).null_count == 0]
    rows = table.num_rows
    print(f"{path}: {rows} rows, {len(table.column_names)} columns, {os.path.getsize(path)} bytes as written; load {os.getloadavg()}")
    bss = {"use_byte_stream_split": floats + [time_col], "use_dictionary": False}
    cases = [
        ("zstd 3, byte-stream split (the master's)", dict(compression="zstd", compression_level=3, **bss)),
        ("zstd 9, byte-stream split", dict(compression="zstd", compression_level=9, **bss)),
        ("zstd 12, byte-stream split", dict(compression="zstd", compression_level=12, **bss)),
        ("zstd 19, byte-stream split", dict(compression="zstd", compression_level=19, **bss)),
        ("zstd 3, plain", dict(compression="zstd", compression_level=3, use_dictionary=False)),
        ("brotli 11, byte-stream split", dict(compression="brotli", compression_level=11, **bss)),
        ("zstd 3, byte-stream split and dictionary", dict(compression="zstd", compression_level=3, use_byte_stream_split=floats + [time_col])),
    ]
    for what, options in cases:
        size, secs = written(table, **options)
        print(f"  {what}: {size} bytes ({size / rows / len(table.column_names):.2f} per value), written in {secs * 1e3:.1f} ms")
    steps = pa.table({"step": pa.array(np.arange(rows, dtype=np.int64))})
    size, _ = written(steps, compression="zstd", use_dictionary=False, column_encoding={"step": "DELTA_BINARY_PACKED"})
    size_t, _ = written(table.select([time_col]), compression="zstd", **bss)
    print(f"  time column: {size_t} bytes as float64; {size} bytes as an int64 step index (DELTA_BINARY_PACKED)")
    # not a Parquet codec: how far a strong general compressor gets on the same bytes
    split = b"".join(np.ascontiguousarray(table.column(n).to_numpy()).view(np.uint8).reshape(-1, 8).T.tobytes() for n in floats)
    size = len(lzma.compress(split, preset=9 | lzma.PRESET_EXTREME))
    print(f"  xz -9e of the byte-split float64 columns (not readable as Parquet): {size} bytes ({size / rows / len(floats):.2f} per value)")
    lossy = pa.table({n: pa.array(table.column(n).to_numpy().astype(np.float32)) for n in floats}).replace_schema_metadata(meta)
    size, _ = written(lossy, compression="zstd", compression_level=3, use_byte_stream_split=floats, use_dictionary=False)
    print(f"  float32 signals (lossy, comparison only): {size} bytes")
    if csv:
        print(f"  {csv}: {os.path.getsize(csv)} bytes")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2] if len(sys.argv) > 2 else None)
