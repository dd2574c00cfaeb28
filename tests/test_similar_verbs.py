"""The similar-verbs model: relations from the lexicon, neighbours and pooled counts by hand on tiny
counts, and its queries, cache and scorer on a tiny store."""

from __future__ import annotations

import json
import math
from collections import Counter

import pytest

from lmcr.frame import Frame
from lmcr.lexicon import load_lexicon
from lmcr.scorers.frame_counts import ALPHA
from lmcr.scorers.mixture import Mixture
from lmcr.scorers.registry import make_scorer, scorer_fingerprint
from lmcr.scorers.resources import MethodResources
from lmcr.scorers.similar_verbs import MIN_PAIRS, NEIGHBOURS, WEIGHT, PairTable, Relation, SimilarVerbs, neighbours
from lmcr.store import connect
from lmcr.workspace import Workspace

LEX = load_lexicon()

# (verb, object, preposition, value, n): what `verb_filler_pairs` returns. 'transfer' and 'tip' move food
# into bowls and pots as dump does; 'wash' takes pans 'with' water (not a dump preposition) and 'in' the
# sink; 'cut' acts 'on' boards.
GENERIC = [
    ("transfer", "rice", "into", "bowl", 30),
    ("transfer", "pasta", "into", "pot", 20),
    ("transfer", "salad", "into", "bowl", 10),
    ("tip", "rice", "into", "bowl", 12),
    ("tip", "pasta", "into", "pot", 9),
    ("tip", "water", "into", "sink", 4),
    ("wash", "pan", "with", "water", 40),
    ("wash", "pan", "in", "sink", 25),
    ("wash", "skillet", "in", "sink", 10),
    ("cut", "bread", "on", "cutting board", 30),
    ("cut", "onion", "on", "cutting board", 20),
    ("stir", "sugar", "into", "batter", 3),  # fewer than MIN_PAIRS pairs: never a neighbour
]
# (predicate, given role, given value, role, value, n): `frame_filler_pairs`, both orders of each frame
ROBOT = [
    ("dump", "Theme", "rice", "Destination", "bowl", 1),
    ("dump", "Destination", "bowl", "Theme", "rice", 1),
    ("dump", "Theme", "water", "Destination", "sink", 1),
    ("dump", "Destination", "sink", "Theme", "water", 1),
    ("pour", "Theme", "water", "Destination", "glass", 50),
    ("pour", "Destination", "glass", "Theme", "water", 50),
    ("pour", "Theme", "milk", "Destination", "mug", 20),
    ("pour", "Destination", "mug", "Theme", "milk", 20),
    ("fill", "Destination", "glass", "Theme", "water", 3),
    ("fill", "Theme", "water", "Destination", "glass", 3),
    ("fill", "Destination", "mug", "Theme", "milk", 3),
    ("fill", "Theme", "milk", "Destination", "mug", 3),
]


def test_relations_come_from_the_lexicon():
    assert Relation.of(LEX.predicates["dump"]) == Relation(
        "Theme", "Destination", frozenset(LEX.predicates["dump"].preps["Destination"])
    )
    # fill's object is the container, its Theme comes with 'with'; season's Instrument too
    assert Relation.of(LEX.predicates["fill"]) == Relation("Destination", "Theme", frozenset({"with"}))
    assert Relation.of(LEX.predicates["season"]) == Relation("Theme", "Instrument", frozenset({"with"}))
    frame = Frame.of("fill", {"Theme": "water", "Destination": "glass"})
    assert Relation.of(LEX.predicates["fill"]).filler_pair(frame) == ("glass", "water")
    # a frame with one of the pair's roles (a purpose clause's: "hand me something to fill") has no pair;
    # a role it has but left empty is a bug
    assert Relation.of(LEX.predicates["fill"]).filler_pair(Frame.of("fill", {"Destination": "glass"})) is None
    with pytest.raises(ValueError, match="complete frames"):
        Relation.of(LEX.predicates["fill"]).filler_pair(Frame.of("fill", {"Destination": "glass", "Theme": None}))


def test_neighbours_are_the_verbs_with_alike_fillers():
    model = SimilarVerbs.from_counts(LEX, GENERIC, ROBOT)
    near = model.near["dump"]
    # transfer and tip share dump's fillers; wash shares only the sink (and 'with' is no dump preposition),
    # cut none; stir has too few pairs; pour (a robot predicate with dump's roles) shares the water
    assert set(near) <= {"transfer", "tip", "wash", "pour"} and {"transfer", "tip"} <= set(near)
    assert max(near.values()) == 1.0 and "cut" not in near and "stir" not in near
    assert near["tip"] > near.get("wash", 0.0)
    # "pour milk into the mug" states fill's roles ("fill the mug with milk") by the same names
    assert "pour" in model.near["fill"] and "wash" not in model.near["fill"]


def test_pooled_counts_rank_what_similar_verbs_do():
    model = SimilarVerbs.from_counts(LEX, GENERIC, ROBOT)
    rice, pan, scissors = model.score_frames(
        [Frame.of("dump", {"Theme": t, "Destination": "bowl"}) for t in ("rice", "pan", "scissors")]
    )
    assert rice > pan and rice > scissors
    pot, bowl = model.score_frames([Frame.of("dump", {"Theme": "pasta", "Destination": d}) for d in ("pot", "bowl")])
    assert pot > bowl  # dump saw no pasta at all: its neighbours did
    assert model.score_frames([Frame.of("dump", {"Theme": "pasta"})]) == [0.0]  # a purpose's frame: no pair


def test_pair_table_smoothing_by_hand():
    table = PairTable.of({("rice", "bowl"): 3.0, ("rice", "pot"): 1.0, ("pasta", "pot"): 2.0})
    assert (table.total, table.object_types, table.other_types) == (6.0, 2, 2)
    p_bowl = (3 + 1) / (6 + 2 + 1)
    p_pasta = (2 + 1) / (6 + 2 + 1)
    expected = math.log((0 + ALPHA * p_bowl) / (2 + ALPHA)) + math.log((0 + ALPHA * p_pasta) / (3 + ALPHA))
    assert table.log_p("pasta", "bowl") == pytest.approx(expected)
    small = table.restricted({"rice", "bowl"})
    assert small.pairs == {("rice", "bowl"): 3.0} and small.objects == {"rice": 4.0} and small.total == 6.0
    assert small.log_p("rice", "bowl") == table.log_p("rice", "bowl")
    # objects labelled in the plural are counted as the frames keep them, in the singular
    assert table.log_p("rice", "bowls") == table.log_p("rice", "bowl") != table.log_p("rice", "plates")


def test_neighbour_weights_are_similarities_over_the_best():
    pairs = {
        "dump": {("rice", "bowl"): 2},
        "a": {("rice", "bowl"): 30, ("salt", "cup"): 30},
        "b": {("rice", "bowl"): 25},
        "c": {("salt", "cup"): 25},
        "d": {("egg", "plate"): 200},
    }
    pairs = {v: Counter(c) for v, c in pairs.items()}
    near = neighbours(pairs, "dump", k=5, min_pairs=20)
    # b does what dump does and nothing else; a half of the time; c and d never: no neighbours
    assert near == {"b": 1.0, "a": pytest.approx(near["a"])} and 0.2 < near["a"] < 0.8
    assert neighbours(pairs, "dump", k=1, min_pairs=20) == {"b": 1.0}
    assert neighbours(pairs, "dump", k=5, min_pairs=26) == {"a": 1.0}  # b has too few pairs


@pytest.fixture
def store(tmp_path):
    """Frames of a tiny store: dump once, transfer, wash and cut often (recipes), tip in the household."""
    db = tmp_path / "lmcr.duckdb"
    sql_dir = Workspace.from_env().sql_dir
    con = connect(db, sql_dir)
    frames, roles, n = [], [], 0
    for verb, theme, prep, value, count in GENERIC:
        corpus = "household" if verb == "tip" else "recipes"
        for _ in range(count):
            n += 1
            frames.append((corpus, f"d{n}", 0, 0, verb, False))
            roles += [(corpus, f"d{n}", 0, 0, "Theme", theme), (corpus, f"d{n}", 0, 0, prep, value)]
    frames.append(("recipes", "r1", 0, 0, "dump", True))
    roles += [("recipes", "r1", 0, 0, "Theme", "rice"), ("recipes", "r1", 0, 0, "Destination", "bowl")]
    con.executemany(
        "insert into frames (corpus, doc_id, sent_id, frame_no, predicate, known, pred_start, pred_end) "
        "values (?, ?, ?, ?, ?, ?, 0, 1)",
        frames,
    )
    con.executemany(
        "insert into frame_roles (corpus, doc_id, sent_id, frame_no, role, value) values (?, ?, ?, ?, ?, ?)", roles
    )
    con.close()
    return db, sql_dir


def test_counts_come_from_the_stores_frames_weighted_by_the_mixture(store):
    db, sql_dir = store
    model = SimilarVerbs.count(db, sql_dir, LEX)
    assert set(model.near["dump"]) == {"transfer", "tip"}  # wash shares nothing with dump's one frame
    assert model.tables["dump"].pairs[("rice", "bowl")] == pytest.approx(
        sum(
            w * n
            for (v, a, p, o, n) in GENERIC
            for u, w in model.near["dump"].items()
            if v == u and (a, o) == ("rice", "bowl")
        )
    )
    # tip's frames are the household's: a mixture that weighs them 3 times pools them 3 times (water into
    # the sink is tip's alone)
    mixed = SimilarVerbs.count(db, sql_dir, LEX, "all", Mixture.of({"household": 3}))
    assert set(mixed.near["dump"]) == {"transfer", "tip"}
    assert model.tables["dump"].pairs[("water", "sink")] == pytest.approx(model.near["dump"]["tip"] * 4)
    assert mixed.tables["dump"].pairs[("water", "sink")] == pytest.approx(mixed.near["dump"]["tip"] * 4 * 3)
    with pytest.raises(ValueError, match="no robot-predicate frames for corpus 'household'"):
        SimilarVerbs.count(db, sql_dir, LEX, "household")


def test_scorer_caches_the_objects_and_counts_others_in_full(store, tmp_path):
    db, sql_dir = store
    res = MethodResources(checkpoints=db.parent, db=db, sql_dir=sql_dir, cache_dir=tmp_path / "cache")
    frames = [Frame.of("dump", {"Theme": t, "Destination": "bowl"}) for t in ("rice", "salad", "pan")]
    first = make_scorer("similar_verbs", res)(frames)
    [cache] = (tmp_path / "cache").glob(f"similar-verbs-all-plain-*-{NEIGHBOURS}-{MIN_PAIRS}.json")
    saved = json.loads(cache.read_text())
    assert saved["words"] == sorted(LEX.objects) and set(saved["neighbours"]["dump"]) == {"transfer", "tip"}
    assert make_scorer("similar_verbs", res)(frames) == first  # read back from the cache
    full = SimilarVerbs.count(db, sql_dir, LEX)
    assert first == pytest.approx(full.score_frames(frames))
    assert first[0] > first[2] and first[1] > first[2]  # rice and salad go into bowls, pans do not
    # a filler outside the robot's objects is scored from the complete counts, made when first needed
    odd = [Frame.of("dump", {"Theme": "rice", "Destination": "colander"})]
    assert make_scorer("similar_verbs", res)(odd) == pytest.approx(full.score_frames(odd))
    # a cache that is not one (truncated) is counted again
    cache.write_text(cache.read_text()[:100])
    assert make_scorer("similar_verbs", res)(frames) == pytest.approx(first)
    assert json.loads(cache.read_text())["words"] == sorted(LEX.objects)
    assert scorer_fingerprint("similar_verbs", res).endswith(f"*{WEIGHT:g}/{NEIGHBOURS}/{MIN_PAIRS}")


def test_a_missing_store_is_one_clear_error(tmp_path):
    res = MethodResources(checkpoints=tmp_path, db=tmp_path / "none.duckdb")
    with pytest.raises(ValueError, match="similar_verbs needs the store's frames: no store at"):
        make_scorer("similar_verbs", res)
