"""The context term: sentence counts from a tiny store, by hand, and what a purpose does to a ranking."""

from __future__ import annotations

import json
import math

import pytest

from lmcr.frame import Frame
from lmcr.scorers.context_pmi import ESTIMATE, MIN_SENTENCES, WEIGHT, ContextCooccurrence
from lmcr.scorers.registry import make_scorer, scorer_fingerprint
from lmcr.scorers.resources import MethodResources
from lmcr.store import connect
from lmcr.workspace import Workspace

DOCUMENTS = [  # (corpus, document, its sentences)
    (
        "recipes",
        "apple pie",
        ["Apple Pie", "Toss the apples with cinnamon for the pie.", "Season with a pinch of salt."],
    ),
    ("recipes", "cherry pie", ["Stir cinnamon into the cherry pie filling."]),
    ("recipes", "soup", ["Season the soup with salt.", "Simmer in a pot."]),
    ("recipes", "pasta", ["Boil the pasta in a pot of salted water.", "Season with salt and black pepper."]),
    ("household", "P01_01", ["boil water in pot", "pour water into cup"]),
]
OBJECTS = ["cinnamon", "salt", "black pepper", "pot", "cup", "pasta", "apple"]


@pytest.fixture
def store(tmp_path):
    db = tmp_path / "lmcr.duckdb"
    sql_dir = Workspace.from_env().sql_dir
    con = connect(db, sql_dir)
    rows = [
        (corpus, doc, i, text, len(text.split())) for corpus, doc, texts in DOCUMENTS for i, text in enumerate(texts)
    ]
    con.executemany("insert into sentences values (?, 's', ?, ?, 'instruction', ?, ?, 'f', 0, null, null)", rows)
    con.close()
    return db, sql_dir


def test_sentences_are_counted_with_plurals(store):
    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_sentences=1)
    assert counts.sentences == 10
    # 'apples' is the apple, 'salted' no salt
    assert counts.object_sentences == {
        "cinnamon": 2,
        "salt": 3,
        "black pepper": 1,
        "pot": 3,
        "cup": 1,
        "pasta": 1,
        "apple": 2,
    }
    assert (
        counts.word_sentences["pie"] == 3 and counts.word_sentences["boil"] == 2 and counts.word_sentences["the"] == 4
    )
    assert counts.pair_sentences["cinnamon"]["pie"] == 2
    # a word and an object in different sentences of one document do not count together (the apple pie's salt)
    assert "pie" not in counts.pair_sentences["salt"] and "pie" not in counts.pair_sentences["pot"]
    common = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_sentences=3).word_sentences
    assert common.keys() == {"pie", "the", "with", "in", "a", "salt", "pot", "season", "water"}


def test_a_purpose_lifts_the_filler_named_with_it(store):
    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_sentences=1)
    frames = [Frame.of("season", {"Theme": "apple", "Instrument": spice}) for spice in ("salt", "cinnamon")]
    salt, cinnamon = counts.score(frames, "for the pie")
    assert cinnamon > salt
    # N = 10; pie: 3 sentences; cinnamon: 2, both with pie (0.6 expected); salt: 3, none with pie (0.9
    # expected); the apple: 2, one with pie
    assert cinnamon - salt == pytest.approx(WEIGHT * (math.log(3 / 1.6) - math.log(1 / 1.9)))
    assert counts.score(frames, "") == [0.0, 0.0]  # no context: as without the term
    assert counts.score(frames, "for the") == [0.0, 0.0]  # stop words say nothing


def test_an_object_no_sentence_names_says_nothing_of_a_purpose(store):
    """A filler outside the counted objects, or counted in no sentence, scores 0 for every word: no
    evidence either way (the add-one estimate gave it log(N / n(w)), more than an object the corpora
    name with the word). A pair expected in well under a sentence and not seen is about 0 too."""
    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_sentences=1)
    assert counts.pmi("pie", "landfill bin") == 0.0 and counts.pmi("boil", "landfill bin") == 0.0
    assert counts.pmi("pie", "cinnamon") > 0.0 > counts.pmi("pie", "salt")
    assert counts.pmi("cherry", "black pepper") == pytest.approx(math.log(1 / 1.1))  # 1 and 1 in 10 sentences
    frames = [Frame.of("season", {"Theme": "apple", "Instrument": spice}) for spice in ("cinnamon", "landfill bin")]
    cinnamon, unknown = counts.score(frames, "for the pie")
    assert cinnamon > unknown


def test_words_of_the_filler_itself_do_not_count(store):
    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_sentences=1)
    assert counts.context_words("so I can boil the pasta, the pasta and the pastas!") == [
        "boil",
        "pasta",
    ]  # no sentence says pastas
    pot, pasta = counts.score(
        [Frame.of("fill", {"Theme": "water", "Destination": d}) for d in ("pot", "pasta")], "so I can boil the pasta"
    )
    # the pasta is credited for 'boil' only, the pot for 'boil' and 'pasta' (each with the water too)
    assert pasta == pytest.approx(
        WEIGHT * (counts.pmi("boil", "pasta") + counts.pmi("boil", "water") + counts.pmi("pasta", "water"))
    )
    assert pot == pytest.approx(WEIGHT * sum(counts.pmi(w, o) for w in ("boil", "pasta") for o in ("pot", "water")))


def test_a_mixture_weighs_each_corpus_sentences(store):
    plain = ContextCooccurrence.count(*store, OBJECTS, {"recipes": 1.0, "household": 1.0}, min_sentences=1)
    mixed = ContextCooccurrence.count(*store, OBJECTS, {"recipes": 1.0, "household": 3.0}, min_sentences=1)
    assert plain.sentences == 10 and mixed.sentences == 8 + 2 * 3
    assert plain.object_sentences["cup"] == 1 and mixed.object_sentences["cup"] == 3
    assert mixed.pair_sentences["pot"]["boil"] == 1 + 3


def test_context_pmi_is_a_context_reading_term_with_a_cache(store, tmp_path):
    db, sql_dir = store
    res = MethodResources(checkpoints=db.parent, db=db, sql_dir=sql_dir, cache_dir=tmp_path / "cache")
    frames = [Frame.of("season", {"Theme": "apple", "Instrument": s}) for s in ("salt", "cinnamon")]
    term = make_scorer("context_pmi", res)
    assert term(frames) == [0.0, 0.0] and not (tmp_path / "cache").exists()  # nothing counted without context
    assert term(frames, "for my tea") == [0.0, 0.0]  # 'tea' is in fewer than MIN_SENTENCES sentences
    [cache] = (tmp_path / "cache").glob("context-sentences-all-plain-*.json")
    assert json.loads(cache.read_text())["sentences"] == 10
    summed = make_scorer("random+context_pmi", res)(frames, "for my tea")
    assert summed == pytest.approx(make_scorer("random", res)(frames))
    assert scorer_fingerprint("context_pmi", res).endswith(f"*{WEIGHT:g}/{MIN_SENTENCES}/sentences/{ESTIMATE}")


def test_a_chosen_context_weight_scales_the_term_and_names_its_calibration(store, tmp_path, monkeypatch):
    from dataclasses import replace

    from lmcr.scorers.mixture import Mixture, save

    counts = ContextCooccurrence.count(*store, OBJECTS, {"all": 1.0}, min_sentences=1)
    frames = [Frame.of("season", {"Theme": "apple", "Instrument": spice}) for spice in ("salt", "cinnamon")]
    unscaled = counts.score(frames, "for the pie")
    assert counts.score(frames, "for the pie", weight=2.0) == pytest.approx([2 * s for s in unscaled])
    db, sql_dir = store
    res = MethodResources(checkpoints=db.parent, db=db, sql_dir=sql_dir, cache_dir=tmp_path / "cache")
    assert res.context_weight == WEIGHT
    assert scorer_fingerprint("context_pmi", replace(res, context_weight=2.0)).endswith(
        f"*2/{MIN_SENTENCES}/sentences/{ESTIMATE}"
    )
    # `lmcr mixture` saves the weight it chose; every scorer the workspace builds reads it
    monkeypatch.setenv("LMCR_DATA_DIR", str(tmp_path))
    assert Workspace.from_env().resources().context_weight == WEIGHT
    save(tmp_path, Mixture.of({"household": 3}), {}, context_weight=0.5)
    assert Workspace.from_env().resources().context_weight == 0.5


def test_a_sentence_is_keyed_by_its_source_too(tmp_path):
    """Document ids are unique within a source: two sources' "doc 1, sentence 0" are two sentences."""
    db, sql_dir = tmp_path / "lmcr.duckdb", Workspace.from_env().sql_dir
    con = connect(db, sql_dir)
    con.executemany(
        "insert into sentences values ('recipes', ?, '1', 0, 'instruction', ?, 3, 'f', 0, null, null)",
        [("web:a", "boil the water"), ("web:b", "wash the pot")],
    )
    con.close()
    counts = ContextCooccurrence.count(db, sql_dir, ["pot", "water"], {"all": 1.0}, min_sentences=1)
    assert counts.sentences == 2 and "boil" not in counts.pair_sentences["pot"]
    assert counts.pair_sentences["water"]["boil"] == 1
