"""MTurk results ingestion: both layouts, every defect class, idempotent re-ingest, counts balance."""

from __future__ import annotations

import csv

import pytest

from lmcr.annotate.results import ingest_ratings
from lmcr.jsonl import InputError
from lmcr.store import check_contracts

META = [
    "HITId",
    "HITTypeId",
    "Title",
    "Reward",
    "MaxAssignments",
    "AssignmentId",
    "WorkerId",
    "AssignmentStatus",
    "WorkTimeInSeconds",
]


def item(k, verb="pour", arg1="water", arg2="cup"):
    return {
        f"Input.verb_{k}": verb,
        f"Input.role1_{k}": "Theme",
        f"Input.arg1_{k}": arg1,
        f"Input.role2_{k}": "Destination",
        f"Input.arg2_{k}": arg2,
        f"Input.sentence_{k}": f"{verb} {arg1} {arg2}",
    }


def row(aid, worker, ratings, status="Approved", hit="H1", items=None):
    out = {
        "HITId": hit,
        "HITTypeId": "T",
        "Title": "Rate",
        "Reward": "$0.30",
        "MaxAssignments": "3",
        "AssignmentId": aid,
        "WorkerId": worker,
        "AssignmentStatus": status,
        "WorkTimeInSeconds": "60",
    }
    for k, r in enumerate(ratings, 1):
        out.update((items or {}).get(k, item(k, arg2=["cup", "scissors"][k - 1])))
        out[f"Answer.rating_{k}"] = r
    return out


def write(path, rows):
    columns = list(dict.fromkeys(c for r in rows for c in r))
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=columns)
        writer.writeheader()
        writer.writerows(rows)
    return path


def test_multi_item_file_with_every_defect(con, paths, tmp_path):
    rows = [
        row("A1", "W1", ["5", "1"]),
        row("A2", "W2", ["4", "2"]),
        row("A3", "W3", ["5", "1"]),
        row("A4", "SPAM", ["1", "5"], status="Rejected"),
        row("A2", "W2", ["4", "2"], status="Approved"),  # the same download twice
        row("A5", "W5", ["7", "1"]),  # out of range
        row("A6", "W6", ["3", "3"], items={2: {**item(2), "Input.arg2_2": ""}}),  # missing input
        row("A7", "W7", ["5", ""], items={2: {k: "" for k in item(2)}}),
    ]  # empty slot: not an item
    counts = ingest_ratings(con, write(tmp_path / "batch.csv", rows))
    assert counts["layout"] == "multi" and counts["rows_in"] == 8
    assert counts["items_in"] == 15 and counts["items_duplicate"] == 2 and counts["items_quarantined"] == 2
    assert counts["items_loaded"] == 11 and counts["assignments_duplicate"] == 1
    reasons = [r for (r,) in con.execute("select reason from quarantine where stage = 'ratings' order by 1").fetchall()]
    assert "'7' is not an integer rating 1-5" in reasons[0] and "missing required input Input.arg2_2" in reasons[1]
    assert check_contracts(con, paths.sql_dir, "ratings") == {"ratings_counts_balance": 0, "ratings_keys": 0}
    by_frame = dict(con.execute("select arg2, round(mean, 3) from frame_ratings").fetchall())
    assert by_frame == {"cup": round((5 + 4 + 5 + 3 + 5) / 5, 3), "scissors": round((1 + 2 + 1 + 1) / 4, 3)}
    labels = dict(con.execute("select arg2, label from frame_labels(1.0)").fetchall())
    assert labels == {"cup": "positive", "scissors": "negative"}  # the rejected spammer's ratings never count
    assert ingest_ratings(con, tmp_path / "batch.csv") == {"source_file": str(tmp_path / "batch.csv"), "skipped": True}
    assert con.execute("select count(*) from ratings").fetchone() == (11,)


def test_a_conflicting_redownload_is_flagged_and_leaves_the_aggregates(con, tmp_path):
    ingest_ratings(con, write(tmp_path / "a.csv", [row("A1", "W1", ["5", "1"]), row("A2", "W2", ["4", "1"])]))
    counts = ingest_ratings(con, write(tmp_path / "b.csv", [row("A1", "W1", ["1", "5"])]))
    assert counts["assignments_conflicting"] == 1 and counts["items_loaded"] == 0
    conflict = con.execute("select conflict from assignments where assignment_id = 'A1'").fetchone()[0]
    assert "b.csv:2: a later download has different answers" in conflict
    assert con.execute("select n, mean from frame_ratings where arg2 = 'cup'").fetchone() == (1, 4.0)


def test_single_item_layout(con, tmp_path):
    rows = [
        {
            "HITId": "H",
            "AssignmentId": f"A{i}",
            "WorkerId": f"W{i}",
            "AssignmentStatus": "Submitted",
            "Input.verb": "fill",
            "Input.role1": "Destination",
            "Input.arg1": "Cup",
            "Input.role2": "Theme",
            "Input.arg2": "water",
            "Input.sentence": "Fill the cup with water.",
            "Answer.rating": r,
        }
        for i, r in enumerate(["5", "4", "x"])
    ]
    counts = ingest_ratings(con, write(tmp_path / "single.csv", rows))
    assert counts["layout"] == "single" and counts["items_loaded"] == 2 and counts["items_quarantined"] == 1
    assert con.execute("select verb, arg1, n, mean from frame_ratings").fetchall() == [("fill", "cup", 2, 4.5)]


def test_a_file_that_is_not_mturk_results_names_file_and_line(con, tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("a,b\n1,2\n")
    with pytest.raises(InputError, match=r"bad.csv:1: not an MTurk batch-results file"):
        ingest_ratings(con, path)


def test_dev_ratings_defects(con, shared_dir):
    counts = ingest_ratings(con, shared_dir / "eval" / "dev_ratings_mturk.csv")
    assert counts["assignments_duplicate"] == 1 and counts["items_quarantined"] == 1
    assert counts["items_in"] == counts["items_loaded"] + counts["items_quarantined"] + counts["items_duplicate"]
    assert con.execute("select count(*) from frame_ratings").fetchone() == (1155,)
    assert con.execute("select count(*) from assignments where status = 'Rejected'").fetchone()[0] >= 1
