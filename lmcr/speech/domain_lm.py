"""The recogniser's domain language model, learned from the project's own text.

Two sources, mixed by token share: the corpora's instruction sentences (how kitchen actions are
phrased) and request forms generated from the lexicon (each predicate with its roles' prepositions,
the object vocabulary, recipient pronouns and quantity words, wrapped in generic request frames such
as "could you ..."). A trigram model with interpolated absolute discounting is written as ARPA (which
pocketsphinx reads) beside a pronouncing dictionary of exactly its words, and published as a version
with a manifest like a checkpoint. Words the en-US dictionary lacks are split into dictionary words
("cheesecloth" -> cheese + cloth) with a warning, else left out of the model.
"""

from __future__ import annotations

import hashlib
import json
import math
import random
import re
from collections import Counter, defaultdict
from collections.abc import Callable, Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

import duckdb

from lmcr.files import file_sha256
from lmcr.lexicon import LEXICON_FILES, Lexicon
from lmcr.versions import publish_version, resolve, write_json

FILES = ("domain.lm", "domain.dict", "build.json")
WORD = re.compile(r"[a-z]+(?:'[a-z]+)?")
# Generic English request frames (not sentences of any test set): the spoken form of an instruction.
PREFIXES = (
    "",
    "",
    "please ",
    "could you ",
    "can you ",
    "would you ",
    "could you please ",
    "go ahead and ",
    "i want you to ",
    "now ",
)
SUFFIXES = ("", "", "", " please", " for me", " now")
DETERMINERS = ("the ", "the ", "some ", "a ", "my ", "")


@dataclass(frozen=True)
class SpeechLMConfig:
    """How the domain model is estimated."""

    max_sentences: int = 200_000  # corpus instruction sentences sampled (deterministically)
    request_forms: int = 40_000
    request_share: float = 0.8  # share of the training tokens from the request forms
    discount: float = 0.7
    min_trigram: float = 2.0  # weighted count below which a trigram is pruned (its bigram stays)
    max_vocab: int = 3_000
    min_parts_count: int = 50  # a word outside the dictionary this frequent is pronounced from its parts
    seed: int = 0


def tokenize(text: str) -> list[str]:
    """Lowercase words as the recogniser writes them (digits and punctuation dropped)."""
    return WORD.findall(text.lower().replace("’", "'"))


def lexicon_words(lexicon: Lexicon) -> set[str]:
    """The words of the lexicon's predicates and object names: the ones the robot must hear."""
    return {w for name in (*lexicon.objects, *lexicon.predicates) for w in tokenize(name)}


def corpus_sentences(con: duckdb.DuckDBPyConnection, limit: int, seed: int) -> list[str]:
    """Up to `limit` distinct instruction sentences of the store, a deterministic sample."""
    rows = con.execute(
        "select text from (select distinct text from sentences where kind = 'instruction') "
        "order by hash(text || ?) limit ?",
        [str(seed), limit],
    ).fetchall()
    return [r[0] for r in rows]


def request_forms(lexicon: Lexicon, n: int, seed: int) -> list[str]:
    """`n` requests generated from the lexicon: each predicate with both roles, or one of them, in the
    forms its role prepositions allow, objects drawn uniformly (the model learns wording, not which
    object goes with which verb: that is the completion's job)."""
    rng = random.Random(seed)
    objects = list(lexicon.objects)
    recipients = sorted(lexicon.recipient_pronouns) or ["me"]
    quantities = sorted(lexicon.quantity_nouns)
    forms = []
    for _ in range(n):
        spec = lexicon.predicates[rng.choice(sorted(lexicon.predicates))]
        core = rng.choice(_cores(spec, rng, objects, recipients, quantities))
        forms.append(f"{rng.choice(PREFIXES)}{core}{rng.choice(SUFFIXES)}")
    return forms


def _cores(spec, rng: random.Random, objects: list[str], recipients: list[str], quantities: list[str]) -> list[str]:
    """The ways one request can say `spec`'s predicate: both roles, only the object, only the other."""
    verb, obj_role = spec.name, spec.object_role
    other = next(r for r in spec.roles if r != obj_role)
    a, b = rng.choice(objects), rng.choice(objects)
    det = lambda: rng.choice(DETERMINERS)  # noqa: E731
    prep = rng.choice(sorted(spec.preps.get(other, ())) or ["with"])
    cores = [
        f"{verb} {det()}{a} {prep} {det()}{b}",
        f"{verb} {det()}{a}",
        f"{verb} {prep} {det()}{b}",
        f"{verb} {rng.choice(recipients)} {det()}{a}",
    ]
    if quantities:
        cores.append(f"{verb} {rng.choice(('a', 'some', 'two'))} {rng.choice(quantities)} of {a}")
    if spec.with_role:  # "fill the cup with water", "brush the bread with oil"
        cores.append(f"{verb} {det()}{b} with {det()}{a}")
    return cores


def read_cmudict(path: Path) -> dict[str, list[str]]:
    """word -> pronunciations (alternates `word(2)` folded in)."""
    prons: dict[str, list[str]] = defaultdict(list)
    for line in path.read_text(encoding="utf-8", errors="replace").splitlines():
        parts = line.split(" ", 1)
        if len(parts) == 2 and parts[0]:
            prons[re.sub(r"\(\d+\)$", "", parts[0])].append(parts[1].split("#")[0].strip())
    return dict(prons)


def compound_pronunciation(word: str, prons: dict[str, list[str]]) -> str | None:
    """A pronunciation for a word the dictionary lacks, from dictionary words it splits into (longest
    first part first), or None."""
    if word in prons:
        return prons[word][0]
    for cut in range(len(word) - 2, 1, -1):
        head, tail = word[:cut], word[cut:]
        if head in prons:
            rest = compound_pronunciation(tail, prons)
            if rest:
                return f"{prons[head][0]} {rest}"
    return None


def count_ngrams(sentences: Iterable[tuple[list[str], float]], vocab: set[str]) -> list[Counter]:
    """Weighted 1-, 2-, 3-gram counts; a word outside `vocab` ends the stretch it is in (no <unk>)."""
    counts = [Counter(), Counter(), Counter()]
    for words, weight in sentences:
        run: list[str] = []
        for word in [*words, None]:
            if word is not None and word in vocab:
                run.append(word)
                continue
            if run:
                padded = ["<s>", *run, "</s>"]
                for n in (1, 2, 3):
                    for i in range(len(padded) - n + 1):
                        counts[n - 1][tuple(padded[i : i + n])] += weight
            run = []
    return counts


def estimate(counts: list[Counter], discount: float, min_trigram: float) -> list[dict[tuple, tuple[float, float]]]:
    """ARPA entries per order: n-gram -> (log10 prob, log10 backoff), interpolated absolute discounting
    written in backoff form (a seen n-gram's probability includes the lower order's share)."""
    unigrams = {k: v for k, v in counts[0].items() if k != ("<s>",)}
    total, size = sum(unigrams.values()), len(unigrams)
    probs: list[dict] = [{k: (c + 0.5) / (total + 0.5 * size) for k, c in unigrams.items()}, {}, {}]
    probs[0][("<s>",)] = 0.0
    backoff: list[dict] = [{}, {}, {}]
    for order in (1, 2):
        grams = {k: c for k, c in counts[order].items() if order < 2 or c >= min_trigram}
        context_total: Counter = Counter()
        followers: Counter = Counter()
        for gram, c in grams.items():
            context_total[gram[:-1]] += c
            followers[gram[:-1]] += 1
        for gram, c in grams.items():
            ctx = gram[:-1]
            alpha = discount * followers[ctx] / context_total[ctx]
            lower = probs[order - 1].get(gram[1:]) or _backed_off(gram[1:], probs, backoff)
            probs[order][gram] = max(c - discount, 0.0) / context_total[ctx] + alpha * lower
        for ctx in context_total:
            backoff[order - 1][ctx] = discount * followers[ctx] / context_total[ctx]
    return [{g: (_log10(p), _log10(backoff[i].get(g, 1.0))) for g, p in probs[i].items()} for i in range(3)]


def _backed_off(gram: tuple, probs: list[dict], backoff: list[dict]) -> float:
    """P(gram) from a lower order when the gram itself was not kept."""
    if len(gram) == 1:
        return probs[0].get(gram, 1e-9)
    return backoff[len(gram) - 2].get(gram[:-1], 1.0) * (
        probs[len(gram) - 2].get(gram[1:]) or _backed_off(gram[1:], probs, backoff)
    )


def _log10(p: float) -> float:
    return -99.0 if p <= 0 else math.log10(p)


def write_arpa(entries: list[dict[tuple, tuple[float, float]]], path: Path) -> None:
    """The ARPA text format: counts header, then each order's log10 prob, n-gram, log10 backoff."""
    with path.open("w", encoding="utf-8") as out:
        out.write("\\data\\\n" + "".join(f"ngram {n}={len(e)}\n" for n, e in enumerate(entries, 1)) + "\n")
        for n, grams in enumerate(entries, 1):
            out.write(f"\\{n}-grams:\n")
            for gram in sorted(grams):
                prob, bow = grams[gram]
                out.write(f"{prob:.4f}\t{' '.join(gram)}" + (f"\t{bow:.4f}\n" if n < 3 else "\n"))
            out.write("\n")
        out.write("\\end\\\n")


def _built_from(model_dir: Path, fingerprint: str) -> Path | None:
    """The latest version in `model_dir` when it was built from inputs with this fingerprint, else None."""
    if not (model_dir / "LATEST").exists():
        return None
    current = resolve(model_dir)
    if (current / "build.json").exists() and load_build(current).get("inputs_sha256") == fingerprint:
        return current
    return None


def _pronounced_vocabulary(
    frequency: Counter, needed: set[str], prons: dict[str, list], config: SpeechLMConfig
) -> tuple[dict[str, list], list[str], list[str]]:
    """The vocabulary, most frequent words first, up to `config.max_vocab` (the lexicon's words always),
    each with its pronunciations; returns it with the words pronounced from their parts and the words
    dropped for want of a pronunciation."""
    vocab, fallback, missing = {}, [], []
    for word, _ in frequency.most_common():
        if len(vocab) >= config.max_vocab and word not in needed:
            continue
        # Parts only for words worth it: the lexicon's, and frequent ones (rare ones are mostly typos).
        worth_parts = word in needed or frequency[word] >= config.min_parts_count
        pron = prons[word][0] if word in prons else compound_pronunciation(word, prons) if worth_parts else None
        if pron is None:
            missing.append(word)
            continue
        if word not in prons:
            fallback.append(word)
        vocab[word] = [pron] if word not in prons else prons[word]
    return vocab, fallback, missing


def build_speech_lm(
    con: duckdb.DuckDBPyConnection,
    lexicon: Lexicon,
    cmudict: Path,
    model_dir: Path,
    config: SpeechLMConfig = SpeechLMConfig(),
    log: Callable[[str], None] = print,
) -> Path:
    """Estimate the domain model from the store and the lexicon and publish a version of it in
    `model_dir` (the workspace's `speech` folder); when
    the latest version was built from the same inputs (ingested files, lexicon, dictionary, settings),
    return it instead (re-running the stage is free)."""
    fingerprint = inputs_fingerprint(con, cmudict, config)
    current = _built_from(model_dir, fingerprint)
    if current is not None:
        log(f"speech model {current}: inputs unchanged (kept)")
        return current
    corpus = [tokenize(s) for s in corpus_sentences(con, config.max_sentences, config.seed)]
    requests = [tokenize(s) for s in request_forms(lexicon, config.request_forms, config.seed)]
    corpus_tokens, request_tokens = sum(map(len, corpus)) or 1, sum(map(len, requests)) or 1
    ratio = config.request_share * corpus_tokens / ((1 - config.request_share) * request_tokens)
    w_corpus, w_request = (1.0, ratio) if ratio >= 1 else (1 / ratio, 1.0)  # weights >= 1: discounts stay sound
    prons = read_cmudict(cmudict)
    needed = lexicon_words(lexicon)
    frequency = Counter(w for words in corpus for w in words)
    for words in requests:  # weighted like the n-gram counts: every occurrence counts w_request
        for w in words:
            frequency[w] += w_request
    vocab, fallback, missing = _pronounced_vocabulary(frequency, needed, prons, config)
    for word in sorted(needed - set(vocab)):
        log(f"warning: lexicon word {word!r} has no pronunciation; the recogniser cannot hear it")
    if fallback:
        log(f"warning: {len(fallback)} words pronounced from their parts: {', '.join(sorted(fallback)[:10])}")
    counts = count_ngrams([(w, w_corpus) for w in corpus] + [(w, w_request) for w in requests], set(vocab))
    entries = estimate(counts, config.discount, config.min_trigram)
    build = {
        "inputs_sha256": fingerprint,
        "config": asdict(config),
        "corpus_sentences": len(corpus),
        "request_forms": len(requests),
        "corpus_tokens": corpus_tokens,
        "request_tokens": request_tokens,
        "weights": [w_corpus, w_request],
        "vocabulary": len(vocab),
        "ngrams": [len(e) for e in entries],
        "pronounced_from_parts": sorted(fallback),
        "dropped_without_pronunciation": len(missing),
    }

    def write(folder: Path) -> None:
        write_arpa(entries, folder / "domain.lm")
        lines = [f"{w}{'' if i == 0 else f'({i + 1})'} {p}" for w in sorted(vocab) for i, p in enumerate(vocab[w])]
        (folder / "domain.dict").write_text("\n".join(lines) + "\n", encoding="utf-8")
        write_json(folder / "build.json", build)

    path = publish_version(model_dir.parent, model_dir.name, FILES, write)
    log(
        f"speech model {path}: {len(vocab):,} words, n-grams {build['ngrams']}, "
        f"{len(corpus):,} corpus sentences + {len(requests):,} request forms"
    )
    return path


def inputs_fingerprint(con: duckdb.DuckDBPyConnection, cmudict: Path, config: SpeechLMConfig) -> str:
    """What a speech model is built from: the ingested files' hashes, the lexicon, the dictionary, the
    settings and this module."""
    digest = hashlib.sha256(
        repr((con.execute("select sha256 from ingested_files order by 1").fetchall(), asdict(config))).encode()
    )
    for path in (*LEXICON_FILES, cmudict, Path(__file__)):
        digest.update(file_sha256(path).encode())
    return digest.hexdigest()


def load_build(path: Path) -> dict:
    """The build record of a published speech model version."""
    return json.loads((path / "build.json").read_text(encoding="utf-8"))
