"""The output of a sweep: the rows as CSV (floats exactly) and as Parquet
where pyarrow is installed."""

import os

def cell(value):
    """Text of one CSV cell: floats exactly (repr), arrays space-separated."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return " ".join(cell(v) for v in value)
    return str(value)


def write_csv(path, rows, cols):
    import csv

    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for r in rows:
            w.writerow([cell(r[c]) for c in cols])


def write_parquet(path, rows, cols):
    """Parquet next to the CSV when pyarrow is installed; returns whether it was written."""
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return False
    table = pa.table({c: [r[c] for r in rows] for c in cols})
    pq.write_table(table, path)
    return True
