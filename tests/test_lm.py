"""Language models: linearisers, batching, an overfit-then-reload run, trie scoring, checkpoint integrity."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys

import pytest
import torch
from torch.nn import functional as F

from lmcr.lexicon import load_lexicon
from lmcr.lm import checkpoint as ckpt
from lmcr.lm import score as score_module
from lmcr.lm.data import bucket_batches, split_by_document
from lmcr.lm.linearize import frame_text, linearize, sentence_text, tokens, without_roles
from lmcr.lm.model import LMConfig, RecurrentLM
from lmcr.lm.score import CONTEXT_TOP, NORMS, LMScorer, MixedLM
from lmcr.lm.train import (
    FINAL_LR_FRACTION,
    PrecisionError,
    TrainConfig,
    bf16_unsupported,
    learning_rate,
    perplexity,
    pick_precision,
    train_lm,
)
from lmcr.lm.vocab import Vocab
from lmcr.setting import Setting

CORPUS = [
    "pour the water into the cup",
    "pour the milk into the glass",
    "pour the wine into the glass",
    "fill the pot with water",
    "fry the egg in the pan",
    "heat the oil in the skillet",
    "sprinkle salt on the steak",
    "dip the bread in the soup",
    "blend the banana in the blender",
] * 4


def test_linearisations():
    roles = {"Theme": "water", "Destination": "cup"}
    assert frame_text("pour", roles) == "pour water cup"
    assert sentence_text("pour", roles) == "pour water into the cup"
    assert linearize("sentence", "fill", {"Destination": "pot", "Theme": "water"}) == "fill the pot with water"
    assert frame_text("fill", {"Theme": "water", "Destination": "pot"}) == "fill pot water"  # lexicon role order
    assert frame_text("add", {"Theme": "shallot", "to": "pan"}) == "add shallot pan"
    with pytest.raises(ValueError, match="unfilled"):
        sentence_text("pour", {"Theme": "water", "Destination": None})
    # a role the frame does not have is not said, nor its preposition (a purpose clause's frame)
    assert sentence_text("pour", {"Theme": "water"}) == "pour water"
    assert sentence_text("fill", {"Destination": "pot"}) == "fill the pot"
    assert sentence_text("season", {"Instrument": "salt"}) == "season with salt"
    assert without_roles("put {Theme} away in the {Destination}", ["Destination"]) == "put {Theme} away"
    assert without_roles("dispose of {Theme} in the {Destination}", ["Theme"]) == "dispose in the {Destination}"
    assert tokens("Pour 1 1/2 cups of Milk's foam, then stir.") == [
        "pour",
        "<num>",
        "<num>",
        "cups",
        "of",
        "milk's",
        "foam",
        "then",
        "stir",
    ]


def test_vocab_cutoff_and_unknowns():
    vocab = Vocab.build([["a", "a", "b"], ["a", "c", "c"]], min_freq=2)
    assert vocab.words[:4] == ("<pad>", "<unk>", "<s>", "</s>") and set(vocab.words[4:]) == {"a", "c"}
    assert vocab.encode(["a", "b"]) == [2, vocab.words.index("a"), 1, 3]
    assert vocab.unk_types == 1 and Vocab.build([["x", "y", "z"]], min_freq=2).unk_types == 3


def test_bucketed_batches_waste_little_padding():
    seqs = [[1] * n for n in [3, 9, 4, 8, 3, 9, 5, 4]]
    batches = bucket_batches(seqs, max_tokens=18, seed=0)
    assert sum(b.shape[0] for b in batches) == 8 and all(b.numel() <= 18 for b in batches)
    waste = sum(b.numel() for b in batches) - sum(map(len, seqs))
    naive = sum(2 * max(len(a), len(b)) for a, b in zip(seqs[::2], seqs[1::2])) - sum(map(len, seqs))
    assert waste == 5 and naive == 17  # pairs in input order would pad more than three times as much
    assert bucket_batches(seqs, 18, seed=0)[0].tolist() == batches[0].tolist()  # seeded order


def test_validation_split_keeps_documents_whole():
    keys = [f"recipes:{i // 3}" for i in range(30_000)]
    held = split_by_document(keys)
    assert all(held[i] == held[i - i % 3] for i in range(len(keys)))
    assert 0.03 < sum(held) / len(held) < 0.07


@pytest.fixture(scope="module")
def overfit():
    seqs = [tokens(t) for t in CORPUS]
    vocab = Vocab.build(seqs, min_freq=1)
    ids = [vocab.encode(s) for s in seqs]
    torch.manual_seed(7)  # the initial weights too: otherwise they depend on which tests ran before
    model = RecurrentLM(LMConfig(len(vocab), embedding=32, layers=1, dropout=0.0))
    history = train_lm(model, ids, ids, TrainConfig(max_epochs=60, lr=0.02, batch_tokens=200, patience=60, seed=7))
    return model, vocab, history


def test_tiny_corpus_overfits(overfit):
    _, _, history = overfit
    assert history[-1]["val_ppl"] < 1.6 < history[0]["val_ppl"]


def test_learning_rate_decays_linearly_over_the_last_epochs():
    config = TrainConfig(max_epochs=5, decay_epochs=2, lr=0.004)
    assert [learning_rate(config, e, 0.5) for e in (1, 2, 3)] == [0.004] * 3
    assert learning_rate(config, 4, 0.0) == 0.004
    assert learning_rate(config, 5, 0.0) == pytest.approx(0.004 * (1 - (1 - FINAL_LR_FRACTION) / 2))
    assert learning_rate(config, 5, 1.0) == pytest.approx(0.004 * FINAL_LR_FRACTION)
    assert learning_rate(TrainConfig(max_epochs=5, decay_epochs=0), 5, 0.99) == TrainConfig.lr
    whole = TrainConfig(max_epochs=2, decay_epochs=9)  # more decay epochs than epochs: decays from the start
    assert learning_rate(whole, 1, 0.0) == whole.lr > learning_rate(whole, 1, 0.5) > learning_rate(whole, 2, 0.5)


def test_the_last_epoch_trains_at_a_decaying_rate(overfit):
    _, _, history = overfit
    assert [h["lr_end"] for h in history[:-1]] == [0.02] * (len(history) - 1)
    assert history[-1]["lr_end"] == pytest.approx(0.02 * FINAL_LR_FRACTION)  # the run's last step ends the decay


NO_BF16 = bf16_unsupported(torch.device("cpu"))
needs_bf16 = pytest.mark.skipif(NO_BF16 is not None, reason=f"bf16 path: {NO_BF16}")


@needs_bf16
def test_bf16_autocast_trains_as_well_and_is_recorded(overfit):
    """bf16 autocast (emulated where the CPU lacks it) reaches the fp32 run's overfit; fp32 stays fp32."""
    _, vocab, fp32 = overfit
    ids = [vocab.encode(tokens(t)) for t in CORPUS]
    torch.manual_seed(7)
    model = RecurrentLM(LMConfig(len(vocab), embedding=32, layers=1, dropout=0.0))
    history = train_lm(
        model, ids, ids, TrainConfig(max_epochs=60, lr=0.02, batch_tokens=200, patience=60, seed=7, precision="bf16")
    )
    assert history[-1]["val_ppl"] < 1.6 and {h["precision"] for h in history} == {"bf16"}
    assert all(p.dtype == torch.float32 for p in model.parameters())  # master weights stay fp32
    assert float(torch.tensor([1e-40]) * 1.0) > 0  # denormal flushing ended with the training steps
    exact = perplexity(model, ids, 200, torch.device("cpu"))
    assert perplexity(model, ids, 200, torch.device("cpu"), "bf16") == pytest.approx(exact, rel=0.02)


def test_precision_choices(overfit):
    """fp32 everywhere; auto is what the hardware does natively; bf16 where the CPU cannot is one line."""
    _, _, fp32 = overfit
    assert {h["precision"] for h in fp32} == {pick_precision("auto", torch.device("cpu"))}
    assert pick_precision("fp32", torch.device("cpu")) == "fp32"
    with pytest.raises(ValueError, match="precision must be one of"):
        pick_precision("fp16", torch.device("cpu"))
    if NO_BF16:
        with pytest.raises(PrecisionError, match="precision bf16: this CPU has no bfloat16"):
            pick_precision("bf16", torch.device("cpu"))
    else:
        assert pick_precision("bf16", torch.device("cpu")) == "bf16"


def test_the_lm_tests_pass_on_a_cpu_without_bf16():
    """oneDNN limited to AVX2 is a CPU without bf16 (a laptop, an older EPYC): bf16 is refused in one
    line, its tests skip with the reason, and every fp32 path passes."""
    env = os.environ | {"ONEDNN_MAX_CPU_ISA": "AVX2", "LMCR_INNER_AVX2_RUN": "1"}
    if os.environ.get("LMCR_INNER_AVX2_RUN"):
        pytest.skip("already the inner run")
    run = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-rs", __file__],
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert run.returncode == 0, run.stdout[-3000:]
    assert "bf16 path: this CPU has no bfloat16 support in oneDNN" in run.stdout
    assert " failed" not in run.stdout and " error" not in run.stdout


def test_time_budget_stops_between_epochs(overfit):
    _, vocab, _ = overfit
    ids = [vocab.encode(tokens(t)) for t in CORPUS]
    model = RecurrentLM(LMConfig(len(vocab), embedding=16, layers=1))
    history = train_lm(model, ids, ids, TrainConfig(max_epochs=50, patience=50, max_minutes=1e-9))
    assert len(history) == 1  # the first epoch always runs; the budget stops the next


def test_a_time_budget_moves_the_decay_to_the_last_epoch_that_fits(overfit, monkeypatch):
    """A clock that moves 10 s per reading: an epoch (training and validation) takes 20 s, and a budget
    of 104 s fits three of the ten epochs asked for; the third is the one that decays."""
    _, vocab, _ = overfit
    ids = [vocab.encode(tokens(t)) for t in CORPUS]
    clock = iter(range(0, 10_000, 10))
    monkeypatch.setattr("lmcr.lm.train.time.perf_counter", lambda: next(clock))
    model = RecurrentLM(LMConfig(len(vocab), embedding=16, layers=1))
    config = TrainConfig(max_epochs=10, patience=10, lr=0.02, batch_tokens=200, max_minutes=104 / 60)
    history = train_lm(model, ids, ids, config)
    assert [h["lr_end"] for h in history] == pytest.approx([0.02, 0.02, 0.02 * FINAL_LR_FRACTION])


def test_target_perplexity_stops_training(overfit):
    _, vocab, _ = overfit
    ids = [vocab.encode(tokens(t)) for t in CORPUS]
    model = RecurrentLM(LMConfig(len(vocab), embedding=16, layers=1))
    history = train_lm(
        model, ids, ids, TrainConfig(max_epochs=50, patience=50, lr=0.02, batch_tokens=200, target_ppl=len(vocab) / 2)
    )
    assert 1 <= len(history) < 50 and history[-1]["val_ppl"] <= len(vocab) / 2
    assert all(h["val_ppl"] > len(vocab) / 2 for h in history[:-1])


def test_trie_scores_equal_a_plain_forward_pass(overfit, tmp_path):
    model, vocab, _ = overfit
    path = ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})
    scorer = LMScorer(ckpt.load(path), precision="fp32")
    texts = ["pour water into the cup", "pour water into the scissors", "pour milk into the glass", "fry egg"]
    with torch.no_grad():
        direct = [float(model.token_logprobs(torch.tensor([scorer.encode(t)])).sum()) for t in texts]
    assert [x for x, _ in scorer.logprobs(texts)] == pytest.approx(direct, abs=1e-4)  # no <unk> here
    scorer.vocab = Vocab(vocab.words, unk_types=50)
    unknown = scorer.logprobs(["pour water into the teapot"])[0][0]
    with torch.no_grad():
        pooled = float(model.token_logprobs(torch.tensor([scorer.encode("pour water into the teapot")])).sum())
    assert abs(unknown - (pooled - math.log(50))) < 1e-4  # the rare word's share of <unk>
    scorer.vocab = vocab
    cup, scissors = scorer.score_frames(
        [("pour", {"Theme": "water", "Destination": "cup"}), ("pour", {"Theme": "water", "Destination": "scissors"})]
    )
    assert cup > scissors


@needs_bf16
def test_bf16_scoring_is_within_rounding_of_fp32(overfit, tmp_path):
    """The LSTM and the decoder in bfloat16 (the default where the CPU has it, as in training) move a
    text's log-probability by rounding only; the softmax stays fp32, the checkpoint's model is unchanged."""
    model, vocab, _ = overfit
    loaded = ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {}))
    exact, rounded = LMScorer(loaded, precision="fp32"), LMScorer(loaded, precision="bf16")
    assert rounded._decoder[0].dtype == torch.bfloat16 and loaded.model.decoder.weight.dtype == torch.float32
    assert rounded._rnn.weight_hh_l0.dtype == torch.bfloat16 and loaded.model.rnn.weight_hh_l0.dtype == torch.float32
    assert exact._rnn is loaded.model.rnn
    texts = ["pour water into the cup", "pour water into the scissors", "pour milk into the glass", "fry egg"]
    assert rounded.score(texts) == pytest.approx(exact.score(texts), abs=0.02 * 6)  # ~0.01 a token
    assert rounded.score(texts) != exact.score(texts)  # it did multiply in bf16
    frames = [("pour", {"Theme": "water", "Destination": o}) for o in ("cup", "scissors")]
    assert rounded.score_frames(frames, "for my tea") == pytest.approx(
        exact.score_frames(frames, "for my tea"), abs=0.2
    )
    with pytest.raises(ValueError, match="precision"):
        LMScorer(loaded, precision="fp8")


def test_context_follows_the_frame_and_articles_follow_the_checkpoint(overfit, tmp_path):
    model, vocab, _ = overfit
    frame = ("pour", {"Theme": "water", "Destination": "cup"})
    kept = LMScorer(ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})), precision="fp32")
    assert kept.score_frames([frame], context="") == kept.score(["pour water into the cup"])
    assert kept.score_frames([frame], context="for my tea") == pytest.approx(
        kept.score(["pour water into the cup for my tea"])
    )
    # Past the LM's best CONTEXT_TOP frames, a frame gets the lowest context term of those.
    many = [("pour", {"Theme": "water", "Destination": f"cup{i}"}) for i in range(CONTEXT_TOP + 2)]
    bare, read = kept.score_frames(many), kept.score_frames(many, context="for my tea")
    gains = sorted(zip(bare, [r - b for r, b in zip(read, bare)]), reverse=True)
    assert all(g == pytest.approx(min(x for _, x in gains[:CONTEXT_TOP])) for _, g in gains[CONTEXT_TOP:])
    dropped = ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {}, articles=False))
    assert dropped.articles is False and tokens("Pour the milk into a cup", articles=False) == [
        "pour",
        "milk",
        "into",
        "cup",
    ]
    assert LMScorer(dropped, precision="fp32").score_frames([frame]) == kept.score(["pour water into cup"])


def test_context_read_on_from_the_frames_equals_scoring_the_whole_text(overfit, tmp_path):
    model, vocab, _ = overfit
    scorer = LMScorer(ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})), precision="fp32")
    scorer.vocab = Vocab(vocab.words, unk_types=50)  # "kettle" is unknown: its <unk> share is charged too
    # A frame whose text is inside another's ("pour water into the cup" / "... cup lid"), one that shares
    # no more than the predicate, and a context with an unknown word.
    frames = [
        ("pour", {"Theme": "water", "Destination": "cup"}),
        ("pour", {"Theme": "water", "Destination": "cup lid"}),
        ("pour", {"Theme": "milk", "Destination": "glass"}),
    ]
    texts = ["pour water into the cup", "pour water into the cup lid", "pour milk into the glass"]
    for norm in NORMS:
        whole = scorer.score([f"{t} for the kettle" for t in texts], norm)
        assert scorer.score_frames(frames, context="for the kettle", norm=norm) == pytest.approx(whole, abs=1e-4)
    assert scorer.score_frames([], context="for the kettle") == []


def test_groups_read_in_one_pass_score_as_each_group_alone(overfit, tmp_path):
    """A completion's frames and the stated_pmi term's masked frames are read in one walk and one context
    read: each group's scores, the context read after its own best CONTEXT_TOP, are those it gets alone."""
    model, vocab, _ = overfit
    scorer = LMScorer(ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})), precision="fp32")
    cups = [("pour", {"Theme": "water", "Destination": f"cup{i}"}) for i in range(CONTEXT_TOP + 2)]
    masked = [("pour", {"Theme": "it", "Destination": "cup"}), ("pour", {"Theme": "it", "Destination": "glass"})]
    groups = [cups, masked, [], cups[:1]]
    for context in ("", "for my tea"):
        together = scorer.score_frame_groups(groups, context)
        alone = [scorer.score_frames(group, context) for group in groups]
        assert [len(g) for g in together] == [len(g) for g in groups]
        for one, other in zip(together, alone):
            assert one == pytest.approx(other, abs=1e-4)
    mixed = MixedLM([(0.7, scorer), (0.3, scorer)])
    together = mixed.score_frame_groups(groups, "for my tea")
    for one, group in zip(together, groups):
        assert one == pytest.approx(mixed.score_frames(group, "for my tea"), abs=1e-4)


def test_a_corpus_mixture_interpolates_the_household_lm(overfit, tmp_path, monkeypatch):
    from lmcr.scorers import lm_checkpoints
    from lmcr.scorers.mixture import Mixture
    from lmcr.scorers.registry import make_scorer, scorer_fingerprint
    from lmcr.scorers.resources import MethodResources

    model, vocab, _ = overfit
    torch.manual_seed(3)
    untrained = RecurrentLM(LMConfig(len(vocab), embedding=32, layers=1, dropout=0.0))
    ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})
    ckpt.publish(tmp_path, Setting("sentence", "household"), untrained, vocab, {}, {})
    monkeypatch.setattr(lm_checkpoints, "corpus_words", lambda res: {"recipes": 99, "household": 1})
    frames = [("pour", {"Theme": "water", "Destination": o}) for o in ("cup", "scissors")]
    plain = MethodResources(checkpoints=tmp_path)
    mixed = MethodResources(checkpoints=tmp_path, mixture=Mixture.of({"household": 9}))
    share = 9 / (99 + 9)  # household weighted 9 is 9 of 108 weighted words
    all_lm = make_scorer("sentence_lm", plain)
    p_all = [math.exp(x) for x in all_lm(frames)]
    p_house = [math.exp(x) for x in LMScorer(ckpt.load(tmp_path / "sentence-household")).score_frames(frames)]
    purpose = [a - b for a, b in zip(all_lm(frames, "for tea"), all_lm(frames))]  # log P_all(context | frame)
    expected = [math.log((1 - share) * a + share * h) + g for a, h, g in zip(p_all, p_house, purpose)]
    assert make_scorer("sentence_lm", mixed)(frames, "for tea") == pytest.approx(expected, rel=1e-5)
    assert lm_checkpoints.lm_experts(mixed) == [("all", pytest.approx(1 - share)), ("household", pytest.approx(share))]
    assert scorer_fingerprint("sentence_lm", mixed).endswith("@household=9")
    assert "@" not in scorer_fingerprint("sentence_lm", plain)
    house = LMScorer(ckpt.load(tmp_path / "sentence-household"))
    house.lex = load_lexicon(learned=False)  # reads frames with another lexicon than the first expert's
    with pytest.raises(ValueError, match="same text"):
        MixedLM([(1.0, LMScorer(ckpt.load(tmp_path / "sentence-household"))), (1.0, house)])


@pytest.mark.parametrize(
    "texts",
    [
        ["pour water into the cup", "pour water into the glass", "pour water into the bell pepper"],  # shared prefix
        ["pour water into the cup"],  # one text: all prefix
        ["pour water", "pour water into the cup", "pour water into the cup"],  # a text inside another, a duplicate
        ["fill the pot with water", "fill the pot with water"],  # identical texts
    ],
)
def test_shared_prefix_scoring_equals_a_plain_forward_pass(overfit, tmp_path, texts):
    model, vocab, _ = overfit
    scorer = LMScorer(ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})), precision="fp32")
    with torch.no_grad():
        direct = [float(model.token_logprobs(torch.tensor([scorer.encode(t)])).sum()) for t in texts]
    before = torch.backends.mkldnn.enabled
    assert [x for x, _ in scorer.logprobs(texts)] == pytest.approx(direct, abs=1e-4)
    assert torch.backends.mkldnn.enabled == before  # the native-LSTM switch is undone


def test_publish_reload_identical_and_latest(overfit, tmp_path):
    model, vocab, history = overfit
    first = ckpt.publish(tmp_path, Setting("frame"), model, vocab, {"history": history}, {"corpus": "x"})
    reloaded = ckpt.load(tmp_path / "frame-all")  # through LATEST
    assert reloaded.path == first and reloaded.linearization == "frame"
    texts = ["pour water cup", "pour water glass"]
    assert LMScorer(reloaded).score(texts) == LMScorer(ckpt.load(first)).score(texts)
    for name, tensor in model.state_dict().items():
        assert torch.equal(tensor.cpu(), reloaded.model.state_dict()[name])
    second = ckpt.publish(tmp_path, Setting("frame"), model, vocab, {}, {}, promote=False)
    assert ckpt.resolve(tmp_path / "frame-all") == first and second.exists()
    assert not list((tmp_path / "frame-all").glob(".*.tmp"))


def test_tampered_checkpoint_is_refused(overfit, tmp_path):
    model, vocab, _ = overfit
    path = ckpt.publish(tmp_path, Setting("frame"), model, vocab, {}, {})
    (path / "vocab.json").write_text(json.dumps({"words": list(vocab.words)[::-1], "unk_types": 1}))
    with pytest.raises(ckpt.CheckpointError, match="vocab.json: sha256 differs"):
        ckpt.load(path)
    (path / "manifest.json").unlink()
    with pytest.raises(ckpt.CheckpointError, match="no manifest.json"):
        ckpt.load(path)


def test_setting_reads_both_spellings():
    from lmcr.setting import ALL_SETTINGS, Setting, SettingError

    assert Setting.parse("sentence-all") == Setting.parse("sentence_lm/all") == Setting("sentence", "all")
    assert Setting.parse("frame_lm/recipes").name == "frame-recipes" and Setting.parse("frame").label == "frame_lm/all"
    assert len(ALL_SETTINGS) == 8 and all(Setting.parse(s.name) == s == Setting.parse(s.label) for s in ALL_SETTINGS)
    for bad, reason in (
        ("nope-all", "unknown setting"),
        ("sentence-recipe", "corpus must be one of"),
        ("frame_lm/x", "corpus must be one of"),
    ):
        with pytest.raises(SettingError, match=reason):  # an LMCRError and a ValueError
            Setting.parse(bad)


def test_decoder_blocks_give_the_scores_of_one_pass(overfit, tmp_path, monkeypatch):
    """An evaluation's many rows go through the decoder a block at a time; a completion's few in one."""
    model, vocab, _ = overfit
    scorer = LMScorer(ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {})))
    texts = ["pour water into the cup", "pour water into the glass", "fill the pot with water", "pour milk"]
    whole = scorer.score(texts)
    monkeypatch.setattr(score_module, "DECODER_BLOCK", 3)
    assert scorer.score(texts) == pytest.approx(whole, abs=1e-6)


HALF = score_module._half_weights(torch.zeros(1, 1)) is not None
needs_half = pytest.mark.skipif(not HALF, reason="this torch build has no fbgemm fp16 product")


@needs_half
def test_fp16_weights_products_and_lstm_steps_are_within_rounding_of_fp32():
    """fbgemm's product with fp16 weights (fp32 sums) is F.linear to fp16 rounding, and the step-at-a-time
    LSTM with them reads a whole sequence from zeros as `nn.LSTM` does."""
    from lmcr.lm.score import _half_weights, _OneStep

    torch.manual_seed(0)
    weight, bias, rows = torch.randn(40, 16), torch.randn(40), torch.randn(5, 16)
    assert torch.allclose(_half_weights(weight, bias)(rows), F.linear(rows, weight, bias), atol=0.01)
    assert torch.allclose(_half_weights(weight)(rows), F.linear(rows, weight), atol=0.01)
    rnn = torch.nn.LSTM(16, 16, 2, batch_first=True)
    x = torch.randn(3, 4, 16)
    with torch.no_grad():
        out, (h1, c1) = rnn(x)
        for step, tol in ((_OneStep(rnn), 1e-5), (_OneStep(rnn, half=True), 0.01)):
            mine, (h2, c2) = step(x)
            for a, b in ((out, mine), (h1, h2), (c1, c2)):
                assert torch.allclose(a, b, atol=tol)


@pytest.mark.skipif(not NO_BF16 or not HALF, reason="auto is bf16 on this CPU, or no fbgemm")
def test_auto_precision_without_bf16_reads_fp16_weights_and_scores_as_fp32_does(overfit, tmp_path, monkeypatch):
    """Where the CPU has no bf16, "auto" holds the decoder's and the LSTM's weights in fp16 (fbgemm's
    kernels): a frame's score moves by rounding only, with and without a context; "fp32" stays exact, and
    a build without the kernels scores in fp32."""
    model, vocab, _ = overfit
    loaded = ckpt.load(ckpt.publish(tmp_path, Setting("sentence"), model, vocab, {}, {}))
    exact, half = LMScorer(loaded, precision="fp32"), LMScorer(loaded)
    assert half.half and not exact.half and half.precision == exact.precision == "fp32"
    frames = [("pour", {"Theme": "water", "Destination": o}) for o in ("cup", "scissors", "glass")]
    texts = ["pour water into the cup", "pour milk into the glass", "fry egg"]
    assert half.score(texts) == pytest.approx(exact.score(texts), abs=0.01)
    assert half.score(texts) != exact.score(texts)  # it did read fp16 weights
    assert half.score_frames(frames, "for my tea") == pytest.approx(exact.score_frames(frames, "for my tea"), abs=0.02)

    def missing(*args):
        raise RuntimeError("no fbgemm")

    for op in ("linear_dynamic_fp16", "linear_prepack_fp16"):  # a CPU it cannot run on; a build without it
        monkeypatch.setattr(torch.ops.quantized, op, missing)
        fallback = LMScorer(loaded)
        assert not fallback.half and fallback.score(texts) == pytest.approx(exact.score(texts), abs=1e-5)


@pytest.mark.parametrize("dtype", [torch.float32, pytest.param(torch.bfloat16, marks=needs_bf16)])
def test_one_step_and_prepacked_products_equal_torchs_own(dtype):
    """The trie walk's one-step LSTM and the decoder's product, with weights laid out once, give what
    `nn.LSTM` and `F.linear` give: to float rounding in fp32, to bfloat16 rounding in bf16."""
    from lmcr.lm.score import _OneStep, _prepacked

    torch.manual_seed(0)
    rnn = torch.nn.LSTM(16, 16, 2, batch_first=True).to(dtype)
    x, h, c = torch.randn(3, 1, 16), torch.randn(2, 3, 16), torch.randn(2, 3, 16)
    tol = 1e-5 if dtype == torch.float32 else 0.05
    with torch.no_grad():
        out, (h1, c1) = rnn(x.to(dtype), (h.to(dtype), c.to(dtype)))
        mine, (h2, c2) = _OneStep(rnn)(x, (h, c))
        assert mine.dtype == h2.dtype == c2.dtype == torch.float32
        for a, b in ((out, mine), (h1, h2), (c1, c2)):
            assert torch.allclose(a.float(), b, atol=tol)
        weight, rows = torch.randn(40, 16).to(dtype), torch.randn(5, 16).to(dtype)
        assert torch.allclose(_prepacked(weight)(rows).float(), F.linear(rows, weight).float(), atol=tol)
