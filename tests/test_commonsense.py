"""The commonsense term: a bilinear model trained on a tiny hand-made ConceptNet with hand-made word
vectors (no GloVe, no cn100k), its edges for frames, saving and reloading, and the cache."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lmcr.frame import Frame
from lmcr.scorers.baselines.conceptnet import read_triples
from lmcr.scorers.commonsense import (
    CommonsenseModel,
    CommonsenseModelError,
    KBCConfig,
    commonsense_scorer,
    frame_triples,
    train_model,
    trained_model,
)

RNG = np.random.default_rng(7)
BASE = {w: RNG.normal(size=8).astype(np.float32) for w in "milk butter shirt sock fridge closet knife spoon".split()}
# words the graph never names, near ones it does: what the word vectors carry over
NEAR = {"cheese": "milk", "jeans": "shirt", "refrigerator": "fridge", "wardrobe": "closet", "cleaver": "knife"}
VECTORS = BASE | {w: BASE[near] + 0.05 * RNG.normal(size=8).astype(np.float32) for w, near in NEAR.items()}
VECTORS |= {w: RNG.normal(size=8).astype(np.float32) for w in "cut bread stir soup".split()}

EDGES = [
    "AtLocation\tmilk\tfridge",
    "AtLocation\tbutter\tfridge",
    "AtLocation\tshirt\tcloset",
    "AtLocation\tsock\tcloset",
    "UsedFor\tknife\tcut bread",
    "UsedFor\tspoon\tstir soup",
]
SMALL = KBCConfig(hidden=16, epochs=150, batch=64, lr=0.01, negatives=3)


def lookup(word: str):
    return VECTORS.get(word)


@pytest.fixture(scope="module")
def model() -> CommonsenseModel:
    triples = [tuple(line.split("\t")) for line in EDGES]
    return train_model(triples, lookup, 8, SMALL)


def lp(model: CommonsenseModel, *triple: str) -> float:
    return model.log_prob([triple])[0]


def test_the_model_learns_its_edges(model):
    assert lp(model, "AtLocation", "milk", "fridge") > lp(model, "AtLocation", "milk", "closet")
    assert lp(model, "AtLocation", "sock", "closet") > lp(model, "AtLocation", "sock", "fridge")
    assert lp(model, "UsedFor", "knife", "cut bread") > lp(model, "UsedFor", "spoon", "cut bread")


def test_words_the_graph_never_names_are_read_through_their_vectors(model):
    # cheese and jeans are in no edge: their vectors are near milk's and shirt's
    assert lp(model, "AtLocation", "cheese", "fridge") > lp(model, "AtLocation", "cheese", "closet")
    assert lp(model, "AtLocation", "jeans", "wardrobe") > lp(model, "AtLocation", "jeans", "refrigerator")
    assert lp(model, "UsedFor", "cleaver", "cut bread") > lp(model, "UsedFor", "spoon", "cut bread")


def test_a_frame_claims_one_edge_per_role_with_a_relation():
    put = Frame.of("put away", {"Theme": "milk", "Destination": "fridge"})
    cut = Frame.of("cut", {"Theme": "bread", "Instrument": "knife"})
    assert frame_triples(put) == [("AtLocation", "milk", "fridge")]
    assert frame_triples(cut) == [("UsedFor", "knife", "cut bread")]
    assert frame_triples(Frame.of("heat", {"Instrument": "oven"})) == []  # no Theme, nothing to ask


def test_the_term_prefers_the_learned_place_and_weighs_it(model):
    frames = [Frame.of("store", {"Theme": "butter", "Destination": d}) for d in ("fridge", "closet")]
    fridge, closet = commonsense_scorer(model)(frames)
    assert fridge > closet
    assert commonsense_scorer(model, 2.0)(frames) == pytest.approx([2 * fridge, 2 * closet])
    assert commonsense_scorer(model)([Frame.of("heat", {"Theme": "soup"})]) == [0.0]


def test_the_methods_term_leaves_the_predicates_it_is_not_given_alone(model):
    """The method passes the learned predicates: the eleven's frames (pour, ...) then score 0."""
    frames = [
        Frame.of(p, {"Theme": "butter", "Destination": d}) for p in ("store", "pour") for d in ("fridge", "closet")
    ]
    fridge, closet, *eleven = commonsense_scorer(model, 1.0, frozenset({"store"}))(frames)
    assert fridge > closet and eleven == [0.0, 0.0]
    assert commonsense_scorer(model, 1.0, frozenset({"store"}))(frames)[:2] == commonsense_scorer(model)(frames)[:2]


def test_the_term_ranks_fillers_within_a_role_and_leaves_the_role_choice_alone(model):
    # centred per (predicate, roles): the Destination frames and the Instrument frames each sum to 0
    frames = [
        Frame.of("put", {"Theme": "milk", "Destination": "fridge"}),
        Frame.of("put", {"Theme": "milk", "Destination": "closet"}),
        Frame.of("put", {"Theme": "milk", "Instrument": "knife"}),
        Frame.of("put", {"Theme": "milk", "Instrument": "spoon"}),
    ]
    fridge, closet, knife, spoon = commonsense_scorer(model)(frames)
    assert fridge > closet and fridge + closet == pytest.approx(0) and knife + spoon == pytest.approx(0)
    learned = lp(model, "AtLocation", "milk", "fridge") - lp(model, "AtLocation", "milk", "closet")
    assert fridge - closet == pytest.approx(learned)


def test_a_saved_model_reloads_with_the_same_scores(model, tmp_path):
    path = tmp_path / "model.pt"
    model.save(path)
    again = CommonsenseModel.load(path, lookup)
    triples = [("AtLocation", "cheese", "fridge"), ("UsedFor", "spoon", "stir soup")]
    assert np.allclose(again.logits(triples), model.logits(triples), atol=1e-6)
    assert again.config == SMALL and again.metrics["train_triples"] == len(EDGES)


def test_a_file_that_is_no_model_is_refused_in_one_line(tmp_path):
    path = tmp_path / "model.pt"
    path.write_bytes(b"not a torch file")
    with pytest.raises(CommonsenseModelError, match="model.pt: not a commonsense model") as err:
        CommonsenseModel.load(path, lookup)
    assert "\n" not in str(err.value)


def test_relations_are_read_from_both_edge_formats(tmp_path):
    cn100k = tmp_path / "train.txt"
    cn100k.write_text("AtLocation\tmilk\tfridge\n\n")
    csv_file = tmp_path / "assertions.csv"
    csv_file.write_text("/a/x\t/r/UsedFor\t/c/en/knife/n\t/c/en/cut_bread\t{}\n/a/y\t/r/IsA\t/c/fr/a\t/c/en/b\t{}\n")
    assert read_triples(tmp_path) == [("AtLocation", "milk", "fridge")]
    assert read_triples(csv_file) == [("UsedFor", "knife", "cut bread")]


def test_the_model_is_trained_once_per_edge_and_vector_file(tmp_path):
    edges = tmp_path / "edges.txt"
    edges.write_text("\n".join(EDGES) + "\n")
    vectors = tmp_path / "vectors.txt"
    vectors.write_text("".join(f"{w} {' '.join(f'{x:.5f}' for x in v)}\n" for w, v in VECTORS.items()))
    epochs: list[str] = []
    first = trained_model(edges, vectors, tmp_path / "cache", epochs.append, SMALL)
    assert len(epochs) == SMALL.epochs and len(list(Path(tmp_path / "cache").glob("commonsense-*.pt"))) == 1
    second = trained_model(edges, vectors, tmp_path / "cache", epochs.append, SMALL)
    assert len(epochs) == SMALL.epochs  # read, not trained again
    assert second.log_prob([("AtLocation", "milk", "fridge")]) == pytest.approx(
        first.log_prob([("AtLocation", "milk", "fridge")]), abs=1e-6
    )
    edges.write_text("\n".join(EDGES[:4]) + "\n")
    trained_model(edges, vectors, tmp_path / "cache", epochs.append, SMALL)
    assert len(epochs) == 2 * SMALL.epochs  # a changed edge file is a new model
    for missing in (tmp_path / "none.txt", tmp_path / "empty-folder"):
        (tmp_path / "empty-folder").mkdir(exist_ok=True)
        with pytest.raises(ValueError, match="cannot be read") as err:
            trained_model(missing, vectors, tmp_path / "cache", epochs.append, SMALL)
        assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="vectors.bin: cannot be read"):
        trained_model(edges, tmp_path / "vectors.bin", tmp_path / "cache", epochs.append, SMALL)
