"""Each baseline on a tiny corpus, model-free: a suffix lemmatizer stands in for spaCy's rule tables."""

from __future__ import annotations

import numpy as np
import pytest

from lmcr.scorers.baselines.conceptnet import ConceptNetScorer, read_edges
from lmcr.scorers.baselines.cooccur import CooccurrenceScorer
from lmcr.scorers.baselines.terms import TermMatcher
from lmcr.scorers.baselines.vectors import VectorFileError, VectorScorer, load_vectors, train_word2vec

CORPUS = [
    "Pour the water into the cups.",
    "Pour water into a cup and stir.",
    "Poured the milk into the glass.",
    "Cut the bell peppers with scissors.",
    "Cut paper with the scissors.",
    "Chop one bell pepper.",
] * 5


class SuffixLemmas:
    def lemmas(self, word: str) -> frozenset[str]:
        return frozenset({word, word.removesuffix("s"), word.removesuffix("ed")})


def frame(dest: str) -> tuple[str, dict[str, str]]:
    return "pour", {"Theme": "water", "Destination": dest}


def test_term_matcher_finds_inflected_and_multiword_terms():
    m = TermMatcher(["pour", "cup", "bell pepper", "pepper"], SuffixLemmas())
    assert m.find_text("Poured it into two cups") == {"pour", "cup"}
    assert m.find_text("slice the bell peppers") == {"bell pepper", "pepper"}


def test_cooccurrence_counts_and_scores():
    scorer = CooccurrenceScorer(lambda: iter(CORPUS), SuffixLemmas(), ["pour", "water", "cup"])
    assert scorer.single["cup"] == 10 and scorer.pairs[("cup", "water")] == 10 and scorer.n_sentences == 30
    cup, scissors = scorer.score_frames([frame("cup"), frame("scissors")])  # scissors indexed on demand
    assert cup == pytest.approx(10 / (15 * 10) + 10 / (15 * 10) + 10 / (10 * 10))  # pour 15, water 10, cup 10
    assert scissors == pytest.approx(10 / (15 * 10)) and scorer.single["scissors"] == 10  # only co(pour, water)
    # a purpose clause's frame with one role ("hand me something to pour"): the verb and it, one pair
    (alone,) = scorer.score_frames([("pour", {"Theme": "cup"})])
    assert alone == pytest.approx(10 / (15 * 10))


def test_vectors_from_a_glove_file_with_oov_policy(tmp_path):
    path = tmp_path / "tiny.txt"
    path.write_text("pour 1 0 0\nwater 1 0.1 0\ncup 0.9 0.2 0\nscissors 0 0 1\nbell 0 1 0\npepper 0 1 0.2\n")
    scorer = VectorScorer(load_vectors(path))
    cup, scissors, unknown = scorer.score_frames([frame("cup"), frame("scissors"), frame("spatula")])
    assert cup > unknown > scissors or cup > scissors
    assert scorer.dist("water", "spatula") == 1.0 and scorer.oov(["spatula", "bell pepper"]) == ["spatula"]


def test_word2vec_trained_on_the_corpus_is_saved_atomically(tmp_path):
    out = train_word2vec(lambda: iter(CORPUS * 4), tmp_path / "w2v.bin", dim=8, min_count=1, epochs=3, workers=1)
    kv = load_vectors(out)
    assert {"pour", "water", "scissors"} <= set(kv.key_to_index) and kv.vector_size == 8
    assert sorted(p.name for p in tmp_path.iterdir()) == ["w2v.bin"]


def test_conceptnet_relatedness_from_an_edge_list(tmp_path):
    edges = tmp_path / "train.txt"
    rows = [
        "UsedFor\tcup\tdrink water",
        "AtLocation\twater\tcup",
        "RelatedTo\tpour\twater",
        "RelatedTo\tpour\tcup",
        "UsedFor\tscissors\tcut paper",
        "AtLocation\tscissors\tdrawer",
        "RelatedTo\tknife\tcut",
        "AtLocation\tknife\tdrawer",
        "IsA\tsoy sauce\tsauce",
        "RelatedTo\tsauce\trice",
    ]
    edges.write_text("\n".join(rows) + "\n")
    assert len(read_edges(tmp_path)) == 10
    scorer = ConceptNetScorer.from_path(tmp_path, dim=4)
    cup, scissors, unknown = scorer.score_frames([frame("cup"), frame("scissors"), frame("spatula")])
    assert cup > scissors and scorer.vector("spatula") is None
    assert scorer.vector("soy sauce") is not None


def test_conceptnet_without_english_edges_is_an_error(tmp_path):
    (tmp_path / "train.txt").write_text("RelatedTo\t/c/fr/tasse\t/c/fr/bol\n\n")
    with pytest.raises(ValueError, match="no English ConceptNet edges"):
        read_edges(tmp_path)
    (tmp_path / "train.txt").write_text("RelatedTo\tcup\tmug\nonly one column\n")
    with pytest.raises(ValueError, match="train.txt:2: 1 tab-separated field"):
        read_edges(tmp_path)


def test_pickled_vector_files_are_refused_without_being_opened(tmp_path):
    # A .kv file is a pickle: loading it would run whatever it holds. It is refused by format, unread.
    marker = tmp_path / "ran"
    evil = tmp_path / "vectors.kv"
    import pickle

    class Payload:
        def __reduce__(self):
            return (marker.write_text, ("pwned",))

    evil.write_bytes(pickle.dumps(Payload()))
    with pytest.raises(VectorFileError, match="pickle-based"):
        load_vectors(evil)
    assert not marker.exists()


def test_npy_vectors_with_a_word_list_load_without_pickle(tmp_path):
    np.save(tmp_path / "glove.npy", np.array([[1.0, 0.0], [0.9, 0.1], [0.0, 1.0]], dtype=np.float32))
    (tmp_path / "glove.words.txt").write_text("water\ncup\nscissors\n", encoding="utf-8")
    kv = load_vectors(tmp_path / "glove.npy")
    assert kv.index_to_key == ["water", "cup", "scissors"] and kv.vector_size == 2
    (tmp_path / "glove.words.txt").write_text("water\ncup\n", encoding="utf-8")
    with pytest.raises(VectorFileError, match="does not match 2 words"):
        load_vectors(tmp_path / "glove.npy")


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        (b"pour 1 0\nwater 1 nope\n", "v.txt:2: not a word and 2 numbers"),
        (b"pour 1 0\nwater 1\n", "v.txt:2: 1 numbers where the vectors have 2"),  # gensim repeated the 1
        (b"2 2\npour 1 0\nwater 1 0 3\n", "v.txt:3: 3 numbers where the vectors have 2"),
        (b"pour 1 0\nwater nan 0\n", "v.txt:2: a value is not a finite number"),
        (b"pour\n", "v.txt:1: a word without numbers"),
        (b"\xff\xfe", "v.txt: not a readable vector file"),
        (b"\n\n", "v.txt: no vectors"),
    ],
)
def test_a_malformed_vector_file_is_a_vector_file_error_naming_the_line(tmp_path, text, reason):
    bad = tmp_path / "v.txt"
    bad.write_bytes(text)
    with pytest.raises(VectorFileError, match=reason):
        load_vectors(bad)
    np.save(tmp_path / "m.npy", np.array([[1.0, 0.0], [np.inf, 0.1]], dtype=np.float32))
    (tmp_path / "m.words.txt").write_text("water\ncup\n", encoding="utf-8")
    with pytest.raises(VectorFileError, match="m.npy: row 1 is not finite"):
        load_vectors(tmp_path / "m.npy")


def test_glove_and_word2vec_text_load_alike(tmp_path):
    (tmp_path / "g.txt").write_text("water 1 0\ncup 0.5 -0.5 \n\n", encoding="utf-8")
    (tmp_path / "w.txt").write_text("2 2\nwater 1 0\ncup 0.5 -0.5\n", encoding="utf-8")
    for name in ("g.txt", "w.txt"):
        kv = load_vectors(tmp_path / name)
        assert kv.index_to_key == ["water", "cup"] and kv["cup"].tolist() == [0.5, -0.5]


def _tiny_vectors(words: dict[str, list[float]]):
    from gensim.models import KeyedVectors

    kv = KeyedVectors(2)
    kv.add_vectors(list(words), np.array(list(words.values()), dtype=np.float32))
    return kv


def test_retrofitting_pulls_neighbours_together_and_lends_vectors():
    from lmcr.scorers.baselines.retrofit import retrofit

    glove = _tiny_vectors({"milk": [1, 0], "mug": [0, 1], "bowl": [0.6, -0.8], "tea": [-1, 0], "sky": [0.3, 0.3]})
    edges = [("milk", "mug", 1.0), ("mug", "tea", 1.0), ("milk", "mug", 1.0), ("tea", "teapot lid", 1.0)]
    out = retrofit(edges, glove)

    def cos(kv, a, b):
        x, y = kv[a], kv[b]
        return float(x @ y / np.linalg.norm(x) / np.linalg.norm(y))

    assert cos(out, "milk", "mug") > cos(glove, "milk", "mug") + 0.2  # neighbours move together
    assert cos(out, "milk", "bowl") < cos(out, "milk", "mug")
    assert cos(out, "teapot lid", "tea") > 0.99  # no word known: (nearly) its one neighbour
    assert np.allclose(out["sky"], glove["sky"]) and np.allclose(out["bowl"], glove["bowl"])  # off the graph


def test_npy_vectors_with_a_parquet_word_index(tmp_path):
    import duckdb

    from lmcr.scorers.baselines.vectors import VectorFileError, load_vectors

    np.save(tmp_path / "emb.npy", np.array([[1, 0], [0, 1], [1, 1]], dtype=np.float32))
    duckdb.sql(
        "copy (select * from (values ('milk'), ('mug'), ('soy')) t(index)) to "
        f"'{tmp_path / 'index.parquet'}' (format parquet)"
    )
    kv = load_vectors(tmp_path / "emb.npy")
    assert kv.index_to_key == ["milk", "mug", "soy"] and np.allclose(kv["soy"], [1, 1])
    duckdb.sql(f"copy (select 1 as a) to '{tmp_path / 'index.parquet'}' (format parquet)")
    with pytest.raises(VectorFileError, match="one text column"):
        load_vectors(tmp_path / "emb.npy")
