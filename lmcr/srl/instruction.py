"""An instruction's frame: of all the frames a spoken instruction holds, the one the robot is asked to do
(`parse_instruction`), or a one-line refusal naming why there is none (`NoPredicateError`)."""

from __future__ import annotations

from spacy.tokens import Doc, Token

from lmcr.errors import LMCRError
from lmcr.jsonl import check_text
from lmcr.lexicon import PREP_ROLES, Lexicon
from lmcr.srl.arguments import argument_value
from lmcr.srl.context import recipient
from lmcr.srl.lemmas import lemma as lemma_of
from lmcr.srl.mentions import NOUN_CLAUSE_DEPS, FrameMention, is_negated
from lmcr.srl.parser import FrameParser


class NoPredicateError(LMCRError, ValueError):
    """An instruction with none of the robot's predicates."""


class NothingAskedError(NoPredicateError):
    """An instruction that only says what not to do ("don't pour the milk"); `negated` is that predicate."""

    def __init__(self, message: str, negated: str):
        super().__init__(message)
        self.negated = negated


def parse_instruction(parser: FrameParser, text: str) -> FrameMention:
    """The first frame of a robot predicate in a spoken instruction; missing roles are None. Text the
    parser cannot take (over MAX_TEXT_CHARS, lone surrogates) raises InputError."""
    return read_instruction(parser, text)[0]


def read_instruction(parser: FrameParser, text: str) -> tuple[FrameMention, Doc]:
    """`parse_instruction`'s frame and the instruction's Doc (for the rest of what it says)."""
    frames, doc = parser.parse_with_doc(check_text(text, "instruction"))
    return _first_known(parser, text, with_requests(parser, doc, frames)), doc


def with_requests(parser: FrameParser, doc: Doc, frames: list[FrameMention]) -> list[FrameMention]:
    """The frames, with a request for a thing for a person read as the robot bringing it to them: the
    person who asks saying they want it ("can I have an apple?", "I'd like the salt", "we need something
    to open this with": a verb of `Lexicon.request_verbs` with one of `Lexicon.speaker_subjects` as its
    subject), or a verb the robot does not know said with a person as recipient ("grab me a towel",
    "fetch the milk for her": `srl.context.recipient`). With an object and no place or tool said, it is
    `Lexicon.request_predicate` (when the store learned it), its Theme that object, its Destination the
    word for the person ("i", "her"), which names them (`grounding.speaker_destination`). English grammar,
    not knowledge of things."""
    lex = parser.lex
    spec = lex.predicates.get(lex.request_predicate or "")
    if spec is None or spec.name not in lex.learned or "Destination" not in spec.roles:
        return frames
    at = {f.start: f for f in frames}
    for verb in doc:
        said = at.get(verb.idx)
        unknown = said is not None and not said.known  # "grab me a towel": a verb the robot does not know
        wanting = _wanting(verb, lex)
        person = wanting or (recipient(verb, lex, ("to", "for")) if unknown else None)
        thing = next((c for c in verb.children if c.dep_ == "dobj" and c.lower_ not in lex.recipient_pronouns), None)
        found = person is not None and thing is not None and argument_value(thing, lex, parser.compounds)
        if not found or _says_where(verb, lex) or _says_where(thing, lex):  # "some milk in my coffee": pouring
            continue
        at[verb.idx] = FrameMention(
            spec.name,
            {spec.object_role: found[0], "Destination": person},
            True,
            verb.idx,
            verb.idx + len(verb),
            {spec.object_role: found[1:]},
            # "I need the bowl" is said of the asker, not to the robot: a request said to it comes first
            # ("I need the bowl for the salad, put the apples in the fridge")
            addressed=not wanting and (said is None or said.addressed),
            negated=is_negated(verb),
            describes=verb.dep_ in NOUN_CLAUSE_DEPS,
        )
    return sorted(at.values(), key=lambda f: f.start)


def _says_where(word: Token, lex: Lexicon) -> bool:
    """Whether the word (the verb, or its object) has a phrase English gives a place or a tool
    (`PREP_ROLES`) that names no person: "in my coffee", "into the sink", "with the knife"."""
    for child in word.children:
        roles = PREP_ROLES.get(child.lower_, ()) if child.dep_ == "prep" else ()
        named = [c for c in child.children if c.dep_ == "pobj" and c.lower_ not in lex.recipient_pronouns]
        if named and {"Destination", "Instrument"} & set(roles):
            return True
    return False


def _wanting(verb: Token, lex: Lexicon) -> str | None:
    """The subject ("i", "we") of a verb of `Lexicon.request_verbs` the person who asks says ("can I have"),
    or None."""
    subject = next((c for c in verb.children if c.dep_ == "nsubj"), None)
    wanted = lemma_of(verb) in lex.request_verbs and subject is not None and subject.lower_ in lex.speaker_subjects
    return subject.lower_ if wanted else None


def _open_rate(lex: Lexicon, frame: FrameMention) -> float:
    """How often the frame's verb states the roles the frame leaves open (the highest of their learned
    rates; 0 for a hand-written predicate, which has none)."""
    spec = lex.predicates.get(frame.predicate)
    rates = spec.rates if spec is not None else {}
    return max((rates.get(role, 0.0) for role, value in frame.roles.items() if value is None), default=0.0)


def _first_known(parser: FrameParser, text: str, frames: list[FrameMention]) -> FrameMention:
    known = [f for f in frames if f.known and not f.negated]  # "don't pour the milk" asks for nothing
    if known:
        # not a clause that says what a thing is for ("get me something to pour the water into" asks to get
        # it; the clause is read only when nothing else is known: a misparse may hang the request there);
        # then the robot's own predicates ("I'd love some wine, could you pour it?", "I like my coffee with
        # milk, pour some in"), then one that says something ("can you help me put the milk away": help
        # says nothing, put away is the task), then what is said to
        # the robot ("I drank it already. Can you dispose of it?"), then what leaves something to do, then
        # what leaves open the role its verb states most often ("take the plates and put them": put states
        # a destination far more often than take); else the first
        return min(
            known,
            key=lambda f: (
                f.describes,
                f.predicate in parser.lex.learned,
                not any(f.roles.values()),
                not f.addressed,
                not f.missing(),
                -_open_rate(parser.lex, f),
            ),
        )
    negated = [f.predicate for f in frames if f.known and f.negated]
    if negated:
        raise NothingAskedError(f"nothing to do in {text!r}: it asks the robot not to {negated[0]}", negated[0])
    raise NoPredicateError(no_predicate(parser.lex, text, frames))


def no_predicate(lex: Lexicon, text: str, frames: list[FrameMention]) -> str:
    """Why a text with none of the robot's predicates has none, in one line: a verb the corpora say too
    little about (named, with its evidence), else none of the learned verbs, else the hand-written ones."""
    refused = [f.predicate for f in frames if f.predicate in lex.refused]
    if refused:
        return f"no known predicate in {text!r}: {lex.refusal(refused[0])}"
    if lex.learned:
        return (
            f"no known predicate in {text!r}: none of the {len(lex.predicates):,} verbs the robot learned"
            " from its corpora (`lmcr predicates` lists them)"
        )
    return f"no known predicate in {text!r}: the robot can {', '.join(lex.hand_written)}"
