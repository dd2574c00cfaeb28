"""The count-based frame model: smoothing by hand on tiny counts, and its queries on an in-memory store."""

from __future__ import annotations

import math

import pytest

from lmcr.counts import FrameCountScorer
from lmcr.store import connect
from lmcr.workspace import Workspace

FILLERS = [("pour", "Theme", "water", 4), ("pour", "Destination", "cup", 3), ("pour", "Destination", "bowl", 1),
           ("cut", "Theme", "water", 2)]
PAIRS = [("pour", "Theme", "water", "Destination", "cup", 3), ("pour", "Destination", "cup", "Theme", "water", 3)]


def test_smoothed_estimates_by_hand():
    m = FrameCountScorer(FILLERS, PAIRS, alpha=2.0)
    assert m.n == 10 and m.types == 3
    p_bowl = (1 + 1) / (10 + 3 + 1)  # add-one over the fillers, one slot for unseen
    assert m.p_value("bowl") == pytest.approx(p_bowl)
    p_bowl_dest = (1 + 2 * p_bowl) / (4 + 2)  # pour's Destination seen 4 times, bowl once
    assert m.p_filler("pour", "Destination", "bowl") == pytest.approx(p_bowl_dest)
    given = (0 + 2 * p_bowl_dest) / (3 + 2)  # water was the theme of 3 frames with a destination, none bowl
    assert m.p_given("pour", "Theme", "water", "Destination", "bowl") == pytest.approx(given)
    p_water_theme = (4 + 2 * m.p_value("water")) / (4 + 2)
    back = (0 + 2 * p_water_theme) / (0 + 2)  # bowl never given: the backoff alone
    assert m.score_frame(("pour", {"Theme": "water", "Destination": "bowl"})) == pytest.approx(math.log(given) + math.log(back))


def test_seen_together_beats_seen_apart_and_unseen():
    m = FrameCountScorer(FILLERS, PAIRS)
    cup, bowl, scissors = m.score_frames([("pour", {"Theme": "water", "Destination": o}) for o in ("cup", "bowl", "scissors")])
    assert cup > bowl > scissors
    assert m.score_frames([("pour", {"Destination": "cup"})])[0] == pytest.approx(math.log(m.p_filler("pour", "Destination", "cup")))


def test_counts_come_from_the_stores_robot_frames(tmp_path):
    db = tmp_path / "lmcr.duckdb"
    con = connect(db, Workspace.from_env().sql_dir)
    frames = [("youcook2", "d1", 0, 0, "pour", True), ("recipes", "d2", 0, 0, "pour", True),
              ("recipes", "d2", 1, 0, "stir", False)]
    con.executemany("insert into frames (corpus, doc_id, sent_id, frame_no, predicate, known, pred_start, pred_end) "
                    "values (?, ?, ?, ?, ?, ?, 0, 1)", frames)
    roles = [("youcook2", "d1", 0, 0, "Theme", "water"), ("youcook2", "d1", 0, 0, "Destination", "cup"),
             ("recipes", "d2", 0, 0, "Theme", "milk"), ("recipes", "d2", 0, 0, "Destination", None),
             ("recipes", "d2", 1, 0, "Theme", "soup")]
    con.executemany("insert into frame_roles (corpus, doc_id, sent_id, frame_no, role, value) values (?, ?, ?, ?, ?, ?)", roles)
    con.close()
    every = FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "all")
    assert every.value == {"water": 1, "cup": 1, "milk": 1}  # no null, no generic predicate
    assert every.pair == {("pour", "Theme", "water", "Destination", "cup"): 1, ("pour", "Destination", "cup", "Theme", "water"): 1}
    assert FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "recipes").value == {"milk": 1}
    with pytest.raises(ValueError, match="no robot-predicate frames for corpus 'nyc'"):
        FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "nyc")
