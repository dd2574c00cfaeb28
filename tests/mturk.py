"""MTurk batch-results files for tests: the single-item header and a writer of rows in its order."""

from __future__ import annotations

import csv
from collections.abc import Iterable
from pathlib import Path

from lmcr.frame import FRAME_COLUMNS

RESULTS_HEADER = [
    "HITId",
    "AssignmentId",
    "WorkerId",
    "AssignmentStatus",
    *(f"Input.{column}" for column in FRAME_COLUMNS),
    "Answer.rating",
]


def write_results(path: Path, rows: Iterable[list]) -> Path:
    """A results CSV of single-item HITs: each row is HIT, assignment, worker, status, the five frame
    columns and the rating, in `RESULTS_HEADER`'s order."""
    with open(path, "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(RESULTS_HEADER)
        writer.writerows(rows)
    return path
