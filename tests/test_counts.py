"""The count-based frame model: smoothing by hand on tiny counts, and its queries on an in-memory store."""

from __future__ import annotations

import math

import pytest

from lmcr.scorers.frame_counts import FrameCountScorer
from lmcr.scorers.mixture import Mixture, MixtureError, load, save
from lmcr.store import connect
from lmcr.workspace import Workspace

FILLERS = [
    ("pour", "Theme", "water", 4),
    ("pour", "Destination", "cup", 3),
    ("pour", "Destination", "bowl", 1),
    ("cut", "Theme", "water", 2),
]
PAIRS = [("pour", "Theme", "water", "Destination", "cup", 3), ("pour", "Destination", "cup", "Theme", "water", 3)]


def counted(frames: list[tuple[str, dict[str, str], int]]) -> tuple[list, list]:
    """The filler rows and the pair rows (both orders) of frames (predicate, roles, how often), as the
    store's count queries give them."""
    fillers = [(v, role, value, n) for v, roles, n in frames for role, value in roles.items()]
    pairs = [(v, r, a, m, o, n) for v, roles, n in frames for r, a in roles.items() for m, o in roles.items() if r != m]
    return fillers, pairs


def test_smoothed_estimates_by_hand():
    m = FrameCountScorer(FILLERS, PAIRS, alpha=2.0)
    assert m.n == 10 and m.types == 3
    p_bowl = (1 + 1) / (10 + 3 + 1)  # add-one over the fillers, one slot for unseen
    assert m.p_value("bowl") == pytest.approx(p_bowl)
    bowl_a_dest = (1 + 2 * p_bowl) / (4 + 2)  # every predicate's Destinations: 4, bowl once
    assert m.p_in_role("Destination", "bowl") == pytest.approx(bowl_a_dest)
    p_bowl_dest = (1 + 2 * bowl_a_dest) / (4 + 2)  # pour's Destination seen 4 times, bowl once
    assert m.p_filler("pour", "Destination", "bowl") == pytest.approx(p_bowl_dest)
    given = (0 + 2 * p_bowl_dest) / (3 + 2)  # water was the theme of 3 frames with a destination, none bowl
    assert m.p_given("pour", "Theme", "water", "Destination", "bowl") == pytest.approx(given)
    water_a_theme = (6 + 2 * m.p_value("water")) / (6 + 2)  # pour's 4 and cut's 2 Themes
    p_water_theme = (4 + 2 * water_a_theme) / (4 + 2)
    back = (0 + 2 * p_water_theme) / (0 + 2)  # bowl never given: the backoff alone
    assert m.score_frame(("pour", {"Theme": "water", "Destination": "bowl"})) == pytest.approx(
        math.log(given) + math.log(back)
    )


def test_an_object_labelled_in_the_plural_is_scored_as_the_corpus_counts_it():
    """The frame corpus keeps a filler's head as its lemma ("whisk the eggs" counts egg): a label in the
    plural ("eggs", "plates") is scored as its singular where the counts know that form better, else as
    it is ("glass" is no plural of "glas")."""
    fillers, pairs = counted(
        [("whisk", {"Theme": "egg", "Destination": "bowl"}, 5), ("pour", {"Theme": "water", "Destination": "glass"}, 2)]
    )
    m = FrameCountScorer(fillers, pairs, alpha=2.0)
    singular = ("whisk", {"Theme": "egg", "Destination": "bowl"})
    assert m.score_frame(("whisk", {"Theme": "eggs", "Destination": "bowls"})) == m.score_frame(singular)
    assert m.score_frame(("pour", {"Theme": "water", "Destination": "glass"})) > m.score_frame(
        ("pour", {"Theme": "water", "Destination": "cup"})
    )
    assert m.form("glass") == "glass" and m.form("knives") == "knives"  # no knife counted: as labelled


def test_a_learned_verbs_pairs_back_off_to_its_class_by_hand():
    # "put away" put a book in a box once and never stated milk's place; "store", of the same class, put milk
    # in the fridge twice
    fillers, pairs = counted(
        [
            ("put away", {"Theme": "milk"}, 1),
            ("put away", {"Theme": "book", "Destination": "box"}, 1),
            ("store", {"Theme": "milk", "Destination": "fridge"}, 2),
        ]
    )
    m = FrameCountScorer(fillers, pairs, alpha=2.0, classes={"put away": "place", "store": "place"})
    flat = FrameCountScorer(fillers, pairs, alpha=2.0)
    own = m.p_filler("put away", "Destination", "fridge")
    kind = (2 + 2 * own) / (2 + 2)  # the class's places given milk: store's fridge twice
    assert m.p_given("put away", "Theme", "milk", "Destination", "fridge") == pytest.approx(kind)  # put away: none
    assert flat.p_given("put away", "Theme", "milk", "Destination", "fridge") == pytest.approx(own)
    # without the class, milk goes where put away put anything (the box); with it, into the fridge
    frames = [("put away", {"Theme": "milk", "Destination": d}) for d in ("fridge", "box")]
    fridge, box = m.score_frames(frames)
    assert fridge > box
    fridge, box = flat.score_frames(frames)
    assert box > fridge
    # a predicate of no class scores as without classes
    plain = ("pour", {"Theme": "water", "Destination": "cup"})
    with_classes = FrameCountScorer(FILLERS, PAIRS, classes={"put away": "place"})
    assert with_classes.score_frame(plain) == FrameCountScorer(FILLERS, PAIRS).score_frame(plain)


def test_a_learned_verbs_own_fillers_against_its_class_by_hand():
    # "chill" put things in the refrigerator 6 times and never chilled an apple; "store", of the same class,
    # put apples in cups 8 times: the class's pairs choose the cup, the verb's own fillers the refrigerator
    fillers, pairs = counted(
        [
            ("chill", {"Theme": "dough", "Destination": "refrigerator"}, 6),
            ("store", {"Theme": "apple", "Destination": "cup"}, 8),
            ("store", {"Theme": "jam", "Destination": "refrigerator"}, 1),
        ]
    )
    m = FrameCountScorer(fillers, pairs, alpha=2.0, classes={"chill": "place", "store": "place"})
    frames = [("chill", {"Theme": "apple", "Destination": d}) for d in ("refrigerator", "cup")]
    fridge, cup = m.score_frames(frames)
    assert cup > fridge  # the class level outvotes chill's own places
    in_role = m.p_in_role("Destination", "refrigerator")
    of_class = (7 + 2 * in_role) / (15 + 2)  # the class's 15 places: the refrigerator 7 times
    own = (6 + 2 * of_class) / (6 + 2)  # chill's 6, all the refrigerator
    apple_class = m.p_class_filler("place", "Theme", "apple")
    apple_own = (0 + 2 * apple_class) / (6 + 2)  # chill never chilled an apple
    fridge, cup = (m.verb_preference(f) for f in frames)
    assert fridge == pytest.approx(math.log(own / of_class) + math.log(apple_own / apple_class))
    assert fridge > cup  # within the Destination, the refrigerator now leads (the apple's term is both's)
    # a verb of no class prefers nothing, nor a verb in a role it was never seen with (its class's, then)
    assert m.verb_preference(("pour", {"Theme": "water", "Destination": "cup"})) == 0.0
    assert m.verb_preference(("chill", {"Instrument": "spoon"})) == pytest.approx(0.0)


def test_a_phrasal_verbs_pairs_back_off_to_its_base_verbs_first():
    # "warm up" stated its place only for soup (the pot); "warm" warms milk in the microwave; the class
    # (placing verbs, which put milk in the fridge) comes after the base verb
    fillers, pairs = counted(
        [
            ("warm up", {"Theme": "soup", "Destination": "pot"}, 2),
            ("warm", {"Theme": "milk", "Destination": "microwave"}, 3),
            ("store", {"Theme": "milk", "Destination": "fridge"}, 30),
        ]
    )
    m = FrameCountScorer(fillers, pairs, alpha=2.0, classes={"warm up": "place", "store": "place"})
    assert m.base == {"warm up": "warm"}
    own = m.p_filler("warm up", "Destination", "microwave")
    kind = (0 + 2 * own) / (30 + 2)  # the class's places given milk: the fridge 30 times, no microwave
    base = (3 + 2 * kind) / (3 + 2)  # warm warmed milk in the microwave 3 times
    assert m.p_given("warm up", "Theme", "milk", "Destination", "microwave") == pytest.approx((0 + 2 * base) / 2)
    scores = m.score_frames([("warm up", {"Theme": "milk", "Destination": d}) for d in ("microwave", "fridge", "pot")])
    assert scores[0] == max(scores)


def test_a_verb_never_seen_with_a_filler_backs_off_to_what_fills_the_role():
    m = FrameCountScorer(FILLERS, PAIRS)
    # cut never had a Destination: a cup (a Destination of pour, 3 times) outscores water (only ever a Theme)
    assert m.p_filler("cut", "Destination", "cup") > m.p_filler("cut", "Destination", "water")
    # as a Theme it is the other way round (cut's own Themes are all water, so compare a verb with none)
    assert m.p_filler("fry", "Theme", "water") > m.p_filler("fry", "Theme", "cup")
    assert m.p_filler("fry", "Destination", "cup") > m.p_filler("fry", "Destination", "water")


def test_seen_together_beats_seen_apart_and_unseen():
    m = FrameCountScorer(FILLERS, PAIRS)
    cup, bowl, scissors = m.score_frames(
        [("pour", {"Theme": "water", "Destination": o}) for o in ("cup", "bowl", "scissors")]
    )
    assert cup > bowl > scissors
    assert m.score_frames([("pour", {"Destination": "cup"})])[0] == pytest.approx(
        math.log(m.p_filler("pour", "Destination", "cup"))
    )


def test_counts_come_from_the_stores_robot_frames(tmp_path):
    db = tmp_path / "lmcr.duckdb"
    con = connect(db, Workspace.from_env().sql_dir)
    frames = [
        ("youcook2", "d1", 0, 0, "pour", True),
        ("recipes", "d2", 0, 0, "pour", True),
        ("recipes", "d2", 1, 0, "stir", False),
    ]
    con.executemany(
        "insert into frames (corpus, doc_id, sent_id, frame_no, predicate, known, pred_start, pred_end) "
        "values (?, ?, ?, ?, ?, ?, 0, 1)",
        frames,
    )
    roles = [
        ("youcook2", "d1", 0, 0, "Theme", "water"),
        ("youcook2", "d1", 0, 0, "Destination", "cup"),
        ("recipes", "d2", 0, 0, "Theme", "milk"),
        ("recipes", "d2", 0, 0, "Destination", None),
        ("recipes", "d2", 1, 0, "Theme", "soup"),
    ]
    con.executemany(
        "insert into frame_roles (corpus, doc_id, sent_id, frame_no, role, value) values (?, ?, ?, ?, ?, ?)", roles
    )
    con.close()
    every = FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "all")
    assert every.value == {"water": 1, "cup": 1, "milk": 1}  # no null, no generic predicate
    assert every.pair == {
        ("pour", "Theme", "water", "Destination", "cup"): 1,
        ("pour", "Destination", "cup", "Theme", "water"): 1,
    }
    assert FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "recipes").value == {"milk": 1}
    with pytest.raises(ValueError, match="no robot-predicate frames for corpus 'nyc'"):
        FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "nyc")
    # A mixture weighs each corpus's frames: recipes counting 3 times, youcook2 once.
    mixed = FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "all", mixture=Mixture.of({"recipes": 3}))
    assert mixed.value == {"water": 1, "cup": 1, "milk": 3} and mixed.n == 5
    assert FrameCountScorer.from_store(
        db, Workspace.from_env().sql_dir, "youcook2", mixture=Mixture.of({"recipes": 3})
    ).value == {"water": 1, "cup": 1}
    # Kept counts: the first read writes them, a later one reads them (the store's rows no longer matter),
    # and a file that is not a table of counts is counted afresh and replaced.
    cache = tmp_path / "baselines" / "frame-counts-x"
    kept = FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "all", cache=cache)
    files = sorted(p.name for p in cache.parent.iterdir())
    assert files == ["frame-counts-x-frame_filler_pairs.parquet", "frame-counts-x-frame_fillers.parquet"]
    assert (kept.value, kept.pair) == (every.value, every.pair)
    con = connect(db, Workspace.from_env().sql_dir)
    con.execute("delete from frame_roles where value = 'milk'")
    con.close()
    assert FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "all", cache=cache).value == every.value
    (cache.parent / files[1]).write_text("not parquet")
    assert FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "all", cache=cache).value == {
        "water": 1,
        "cup": 1,
    }
    assert sorted(p.name for p in cache.parent.iterdir()) == files  # replaced under the same name, no temp left
    # where the counts cannot be kept (a file stands where the cache folder would be), they are used unkept
    (tmp_path / "not-a-folder").write_text("")
    unkept = FrameCountScorer.from_store(db, Workspace.from_env().sql_dir, "all", cache=tmp_path / "not-a-folder" / "x")
    assert unkept.value == {"water": 1, "cup": 1} and (tmp_path / "not-a-folder").read_text() == ""


def test_the_default_methods_two_count_terms_read_the_counts_once(tmp_path, monkeypatch):
    """`verb_fillers` reads the model `frame_counts` built for the same counts; alone first (fillers only),
    it leaves `frame_counts` to build one with the pairs; another mixture is other counts."""
    from lmcr.scorers import registry
    from lmcr.scorers.resources import MethodResources

    db = tmp_path / "lmcr.duckdb"
    con = connect(db, Workspace.from_env().sql_dir)
    con.execute(
        "insert into frames (corpus, doc_id, sent_id, frame_no, predicate, known, pred_start, pred_end) "
        "values ('recipes', 'd', 0, 0, 'pour', true, 0, 1)"
    )
    con.execute("insert into frame_roles values ('recipes', 'd', 0, 0, 'Theme', 'water', 0, 1)")
    con.close()
    built = []
    real = FrameCountScorer.from_store.__func__
    monkeypatch.setattr(
        FrameCountScorer, "from_store", classmethod(lambda cls, *a, **k: built.append(k["pairs"]) or real(cls, *a, **k))
    )
    res = MethodResources(tmp_path / "ckpt", db=db, predicates=False)
    registry._LAST_MODEL.clear()
    registry.make_scorer("frame_counts+verb_fillers", res)
    assert built == [True]
    registry._LAST_MODEL.clear()
    registry.make_scorer("verb_fillers+frame_counts", res)
    assert built == [True, False, True]
    registry.make_scorer(
        "frame_counts", MethodResources(tmp_path / "ckpt", db=db, predicates=False, mixture=Mixture.of({"recipes": 3}))
    )
    assert built == [True, False, True, True]


def test_mixture_weights_parse_label_and_shares():
    mixture = Mixture.parse("household=30, youcook2=1")
    assert (mixture.weights, mixture.label, mixture.weight("recipes")) == ((("household", 30.0),), "household=30", 1.0)
    assert Mixture.parse("plain").plain and Mixture.parse("").plain and Mixture.of({"household": 1}).plain
    # household 1% of the words, weighted 30: its share of the weighted text is 30/129
    assert mixture.shares({"recipes": 90, "youcook2": 9, "household": 1}) == {"household": pytest.approx(30 / 129)}
    for bad, message in (
        ("household", "write corpus=weight"),
        ("household=x", "must be a number"),
        ("household=0", "positive"),
        ("nyc=2", "unknown corpus 'nyc'"),
        ("household=inf", "positive"),
    ):
        with pytest.raises(MixtureError, match=message):
            Mixture.parse(bad)


def test_mixture_file_round_trip_and_bad_file(tmp_path):
    assert load(tmp_path).plain
    save(tmp_path, Mixture.of({"household": 10}), {"accuracy": {"1": 0.8, "10": 0.9}})
    assert load(tmp_path) == Mixture.of({"household": 10})
    (tmp_path / "mixture.json").write_text('{"weights": {"household": -1}}')
    with pytest.raises(MixtureError, match="mixture.json: not a mixture file"):
        load(tmp_path)


def test_the_weights_with_the_best_mean_over_the_dev_sets_win():
    from lmcr.evaluate.choose_mixture import best_choice

    # dev ratings alone: the best Table I, and no context weight (the rated frames have no context)
    assert best_choice({1: {"table1": 0.924}, 3: {"table1": 0.922}}) == (1, None)
    # with instructions: the best mean of the two, over the corpus and context weights together
    both = {
        1: {"table1": 0.924, "instructions": {0.5: 0.933, 1: 0.933, 2: 0.933}},
        3: {"table1": 0.922, "instructions": {0.5: 0.933, 1: 0.933, 2: 0.950}},
        10: {"table1": 0.912, "instructions": {0.5: 0.950, 1: 0.950, 2: 0.950}},
    }
    assert best_choice(both) == (3, 2)
    # ties: the smaller corpus weight (the plain pool), then the unscaled context term, then the smaller
    assert best_choice({1: {"table1": 0.9}, 3: {"table1": 0.9}, 10: {"table1": 0.9}}) == (1, None)
    tied = {
        1: {"table1": 0.9, "instructions": {0.5: 0.9, 1: 0.9, 2: 0.9}},
        3: {"table1": 0.9, "instructions": {0.5: 0.9, 1: 0.9, 2: 0.9}},
    }
    assert best_choice(tied) == (1, 1)
    assert best_choice({1: {"table1": 0.9, "instructions": {0.5: 0.95, 2: 0.95}}}) == (1, 0.5)


def test_the_context_weights_share_one_scoring_of_each_candidate_set(monkeypatch, tmp_path):
    """The grid scores the rest of the method and the unscaled term once per (frames, context)."""
    from lmcr.evaluate import choose_mixture as choosing
    from lmcr.frame import Frame
    from lmcr.scorers.resources import MethodResources

    calls = []

    def stand_in(method, res):
        assert method == "context_pmi" and res.context_weight == 1 or method == "sentence_lm+rarity"
        return lambda frames, context="": (
            calls.append(method) or [0.5 if method == "context_pmi" else 1.0] * len(frames)
        )

    monkeypatch.setattr(choosing, "make_scorer", stand_in)
    at = choosing._context_weighted("sentence_lm+rarity+context_pmi", MethodResources(checkpoints=tmp_path))
    frames = [Frame.of("pour", {"Theme": "water", "Destination": d}) for d in ("cup", "pot")]
    assert at(2.0)(frames, "for my tea") == [2.0, 2.0] and at(0.5)(frames, "for my tea") == [1.25, 1.25]
    assert calls == ["sentence_lm+rarity", "context_pmi"]  # once each, for both weights
    at(1.0)(frames[:1], "for my tea")
    assert len(calls) == 4  # another candidate set is scored afresh


def test_the_context_weight_round_trips_in_the_mixture_file(tmp_path):
    from lmcr.scorers.mixture import load_choice

    assert load_choice(tmp_path)[1] is None  # nothing chosen: the unscaled term
    save(tmp_path, Mixture.of({"household": 3}), {}, context_weight=2.0)
    assert (load(tmp_path), load_choice(tmp_path)[1]) == (Mixture.of({"household": 3}), 2.0)
    save(tmp_path, Mixture.of({"household": 3}), {})  # chosen on rated frames alone: none
    assert load_choice(tmp_path)[1] is None
    for bad in (
        '{"weights": {}, "context_weight": 0}',
        '{"weights": {}, "context_weight": "2"}',
        '{"weights": {}, "context_weight": true}',
        "[1, 2]",
        '{"weights"',
    ):
        (tmp_path / "mixture.json").write_text(bad)
        with pytest.raises(MixtureError, match="mixture.json: (context_weight must be|not a mixture file)"):
            load_choice(tmp_path)
