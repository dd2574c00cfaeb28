"""The offline-LM peer of the external benchmark (lmcr/evaluate/peer.py): its prompt, its scorings, KnowNo's
calibration of its prediction set on the other sets, its batched log-probabilities against one sequence at a
time on a tiny random model, and its one-line refusals."""

from __future__ import annotations

import subprocess
import sys

import pytest

from lmcr.checkout import REPO_ROOT
from lmcr.evaluate import peer
from lmcr.evaluate.external import ExternalItem
from lmcr.jsonl import InputError


def item(id_: str, objects: tuple[str, ...], right: str, missing: str = "Destination") -> ExternalItem:
    return ExternalItem(id_, "put the milk away", objects, "put away", missing, (missing,), (right,))


def fixed_lm(table: dict[str, tuple[float, int]]):
    """A log-probability function reading each continuation's (sum, tokens) from `table`."""
    return lambda prefix, continuations: [table[c.strip()] for c in continuations]


def test_the_prompt_names_the_objects_the_request_and_the_missing_role():
    text = peer.prompt(item("a", ("fridge", "trash can"), "fridge"))
    assert "sees these objects: fridge, trash can." in text and 'Request: "put the milk away"' in text
    assert "Where should it go?" in text and text.endswith("Answer: the")
    assert "Which object should the robot use?" in peer.prompt(item("b", ("pan",), "pan", "Instrument"))


def test_sum_and_mean_scorings_differ_on_long_names():
    lm = fixed_lm({"fridge": (-4.0, 1), "compost bin": (-6.0, 3)})
    answered = peer.answer(lm, item("a", ("fridge", "compost bin"), "compost bin"))
    assert answered.scores["sum"] == (-4.0, -6.0) and answered.scores["mean"] == (-4.0, -2.0)
    assert answered.ms >= 0 and answered.to_json()["objects"] == ("fridge", "compost bin")


def test_the_conformal_threshold_is_knowno_quantile():
    # n = 4, alpha 0.1: the ceil(5 * 0.9) = 5th, capped at the 4th, smallest of 1 - p: 0.8
    assert peer.conformal_threshold([0.9, 0.8, 0.5, 0.2]) == pytest.approx(0.2)
    # n = 20: the 19th of 1 - p
    probs = [k / 20 for k in range(1, 21)]
    assert peer.conformal_threshold(probs) == pytest.approx(0.1)
    with pytest.raises(InputError, match="no calibration items"):
        peer.conformal_threshold([])


def test_a_set_is_summarised_and_calibrated_on_the_other_sets():
    objects = ("fridge", "drawer", "bin")
    sure = peer.PeerAnswer("s", objects, {"sum": (0.0, -9.0, -9.0), "mean": (0.0, -9.0, -9.0)}, 3.0)
    torn = peer.PeerAnswer("t", objects, {"sum": (0.0, 0.0, -9.0), "mean": (0.0, 0.0, -9.0)}, 5.0)
    sets = {"a": [item("s", objects, "fridge"), item("t", objects, "drawer")], "b": [item("u", objects, "fridge")]}
    answers = {"a": [sure, torn], "b": [sure]}
    rows = peer.peer_rows(sets, answers, "sum")
    # set a is calibrated on b (p(right) ~1: threshold ~1, only the sure object), b on a (p(right) 0.5 in one)
    assert rows["a"]["set threshold"] == pytest.approx(1.0, abs=1e-3)
    assert rows["b"]["set threshold"] == pytest.approx(0.5, abs=1e-3)
    a = rows["a"]
    assert a["items"] == 2 and a["top guess right"] == 0.5  # the torn item's tie goes to the first, fridge
    assert a["set holds a right object"] == 0.5 and a["questions asked"] == 0.5 and a["mean set size"] == 0.5
    assert a["p50 ms"] == 3.0 and a["p90 ms"] == 5.0
    b = rows["b"]
    assert b["top guess right"] == 1.0 and b["set holds a right object"] == 1.0 and b["questions asked"] == 0.0


def test_batched_log_probabilities_match_one_sequence_at_a_time():
    torch = pytest.importorskip("torch")
    transformers = pytest.importorskip("transformers")
    from tokenizers import Tokenizer, models, pre_tokenizers

    words = ["[PAD]", "[UNK]", "the", "milk", "goes", "in", "fridge", "compost", "bin", "a", "big", "drawer"]
    raw = Tokenizer(models.WordLevel({w: k for k, w in enumerate(words)}, unk_token="[UNK]"))
    raw.pre_tokenizer = pre_tokenizers.Whitespace()
    tokenizer = transformers.PreTrainedTokenizerFast(tokenizer_object=raw, pad_token="[PAD]", unk_token="[UNK]")
    torch.manual_seed(0)
    config = transformers.GPT2Config(vocab_size=len(words), n_positions=32, n_embd=16, n_layer=2, n_head=2)
    model = transformers.GPT2LMHeadModel(config)
    lm = peer.CausalLM(model, tokenizer)
    prefix, continuations = "the milk goes in the", [" fridge", " a big compost bin", " drawer"]
    batched = lm.logprob(prefix, continuations)
    for cont, (total, tokens) in zip(continuations, batched):
        ids = tokenizer(prefix + cont).input_ids
        start = len(tokenizer(prefix).input_ids)
        with torch.no_grad():
            logits = model(torch.tensor([ids])).logits.log_softmax(-1)[0]
        alone = sum(logits[i - 1, ids[i]].item() for i in range(start, len(ids)))
        assert tokens == len(cont.split()) and total == pytest.approx(alone, abs=1e-4)


def test_a_file_that_is_not_a_model_is_refused_in_one_line(tmp_path):
    with pytest.raises(InputError, match="no such model file"):
        peer.load_peer(tmp_path / "none.gguf")
    junk = tmp_path / "junk.gguf"
    junk.write_bytes(b"not a gguf file")
    pytest.importorskip("transformers")
    with pytest.raises(InputError) as caught:
        peer.load_peer(junk)
    assert str(caught.value).startswith(str(junk)) and "\n" not in str(caught.value)


def test_the_benchmark_refuses_a_missing_peer_model_in_one_line(tmp_path):
    sets = tmp_path / "sets"
    sets.mkdir()
    line = '{"id": "a", "instruction": "put the milk away", "objects": ["milk", "fridge"], "missing": "Destination", "expected_any": ["fridge"], "verb": "put away"}\n'  # noqa: E501
    (sets / "tiny.jsonl").write_text(line, encoding="utf-8")
    argv = ["--sets", str(sets), "--data-dir", str(tmp_path), "--peer", str(tmp_path / "none.gguf"), "--peer-only"]
    done = subprocess.run(
        [sys.executable, str(REPO_ROOT / "bench" / "bench_external.py"), *argv, "--json", ""],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 1 and done.stderr.strip() == f"error: {tmp_path / 'none.gguf'}: no such model file"
