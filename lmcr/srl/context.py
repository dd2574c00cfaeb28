"""The rest of an instruction: what is said besides its frame ("pour the milk for my tea", "fill the
bowl, the dog is thirsty", "heat the butter so it melts"). The purpose tells a listener which object is
meant; completion hands it to the scorer, which reads it after the filled frame ("pour milk into mug for
my tea"). Left out: the predicate, its stated roles with their determiners and prepositions, and the
request around the predicate ("could you", "I need you to", "go ahead and", "please"). What is left is
context only when it holds a content word: "for me" or "a little" leave the instruction as it was.

A pronoun role may point back to a thing named before it ("I'd love some wine, could you pour it?",
"take the strawberries and dip them in the chocolate"): `antecedents` lists what it may refer to. A
request that serves someone may name the vessel as the measure of what it serves ("pour me a glass of
water"): `served_in` finds it. A request that names only what a thing is for ("hand me something to cut
the bread with") says it as a frame of its own: `purpose_of` finds it.
"""

from __future__ import annotations

from dataclasses import dataclass

from spacy.tokens import Doc, Token

from lmcr.lexicon import Lexicon
from lmcr.srl.arguments import NOUN_TAGS, argument_value
from lmcr.srl.compounds import Compounds
from lmcr.srl.lemmas import lemma as lemma_of
from lmcr.srl.mentions import NOUN_CLAUSE_DEPS, FrameMention, extract_frames

CONTENT_TAGS = ("NN", "VB", "JJ")  # nouns, verbs, adjectives (Penn tags: hand-built Docs have no POS)
CLAUSE_BREAKS = frozenset({",", ";", ":", ".", "!", "?"})
# Pronouns that point back to a thing named before them, by grammatical number: "it" to a singular or
# mass noun ("some wine"), "them" to a plural ("the strawberries"). English grammar, not knowledge of things.
ANAPHOR_PLURAL = {"it": False, "this": False, "that": False, "them": True, "these": True, "those": True}


def _covered(token: Token, spans: list[tuple[int, int]]) -> bool:
    return any(start <= token.idx < end for start, end in spans)


def predicate_token(doc: Doc, mention: FrameMention) -> Token | None:
    """The token of the mention's predicate in `doc`."""
    return next((t for t in doc if t.idx <= mention.start < t.idx + max(len(t), 1)), None)


def _clauses_before(doc: Doc, predicate: Token) -> list[list[int]]:
    """The word indices before the predicate in its sentence, cut at clause breaks, nearest first (the
    predicate's own clause may be empty); each earlier clause holds the break that ends it."""
    clauses: list[list[int]] = [[]]
    for token in reversed(doc[predicate.sent.start : predicate.i]):
        if token.text in CLAUSE_BREAKS:
            clauses.append([])
        clauses[-1].append(token.i)
    return clauses


def _request_before(doc: Doc, predicate: Token) -> set[int]:
    """Indices of the words before the predicate that wrap the request around it: its own clause
    ("could you", "go ahead and") and, back across clause breaks, clauses without a content word
    ("please, pour the wine"). A clause that says something ("I'm thirsty, pour me some water") ends
    the request: it is context, as is anything in an earlier sentence."""
    own, *earlier = _clauses_before(doc, predicate)
    request = set(own)
    for clause in earlier:
        if any(is_content(doc[i]) for i in clause):
            break
        request |= set(clause)
    return request


def _role_words(doc: Doc, mention: FrameMention, predicate: Token, said: frozenset[str] = frozenset()) -> set[int]:
    """The stated roles' words, their left modifiers ("some oil") and the prepositions heading them; the
    predicate's particle ("rub it in"), its object when that is no role ("dip a few", "dump some") and
    the person it is done for as a pronoun ("pour me some water"): the addressee of the request, which
    the frame's text has no place for ("pour water into the mug me for my tea"). The roles in `said`
    are not the frame's: their words are left to the context."""
    frame_spans = [span for role, span in mention.spans.items() if role not in said]
    said_spans = [span for role, span in mention.spans.items() if role in said]
    heads = [t for t in doc if _covered(t, frame_spans)]
    words = {t.i for t in heads}
    said_words = {t.i for t in doc if _covered(t, said_spans)}
    for child in predicate.children:
        if child.dep_ == "prt" or child.tag_ == "RP" or child.dep_ == "dative" and child.tag_ == "PRP":
            words.add(child.i)
        elif child.dep_ == "dobj" and child.i not in words and child.i not in said_words:
            words |= {t.i for t in child.subtree}
    for head in heads:
        words |= {t.i for t in head.lefts}
        if head.head.dep_ == "prep" or head.head.tag_ in ("IN", "RP"):
            words.add(head.head.i)
    return words


def is_content(token: Token) -> bool:
    """A word that can say what the instruction is for: a noun, verb or adjective, not a stop word."""
    return token.tag_.startswith(CONTENT_TAGS) and not token.is_stop and token.is_alpha


def utterance_context(doc: Doc, mention: FrameMention, said: frozenset[str] = frozenset()) -> str:
    """The instruction's words besides the frame and the request, lowercased in their order ("for my
    tea"); "" when none of them is a content word. `doc` is a parse of the text `mention` came from.
    The roles in `said` count as words of the utterance, not of the frame ("pour milk in my coffee"
    with no coffee to pour it into: "in my coffee")."""
    predicate = predicate_token(doc, mention)
    if predicate is None:
        return ""
    skip = _request_before(doc, predicate) | _role_words(doc, mention, predicate, said) | {predicate.i}
    words = [t for t in doc if t.i not in skip and not t.is_punct and not t.is_space]
    if not any(is_content(t) for t in words):
        return ""
    return " ".join(t.lower_ for t in words)


def antecedents(
    doc: Doc, mention: FrameMention, role: str, lex: Lexicon, compounds: Compounds | None = None
) -> list[str]:
    """The names a pronoun role may refer back to, most likely first: the heads of the noun phrases
    before the pronoun, outside the frame's own words, that agree with it in number ("I'd love some
    wine, could you pour it?" -> ["wine"]); [] when the role is no such pronoun. A verb's subject or
    object comes before a preposition's ("take the pan from the sink and heat oil in it": the pan),
    then the nearer before the farther. Which one the speaker meant is for the caller to judge
    (completion takes the first the robot sees)."""
    pronoun = mention.roles.get(role)
    if pronoun not in ANAPHOR_PLURAL or role not in mention.spans:
        return []
    predicate = predicate_token(doc, mention)
    frame_words = _role_words(doc, mention, predicate) if predicate is not None else set()
    found: list[tuple[bool, int, str]] = []
    for token in doc:
        if (
            token.idx >= mention.spans[role][0]
            or token.i in frame_words
            or token.tag_ not in NOUN_TAGS
            or token.dep_ == "compound"
            or (token.tag_ in ("NNS", "NNPS")) != ANAPHOR_PLURAL[pronoun]
        ):
            continue
        value = argument_value(token, lex, compounds)
        if value is not None:
            found.append((token.dep_ == "pobj", -token.i, value[0]))
    return list(dict.fromkeys(name for *_, name in sorted(found)))


def recipient(verb: Token, lex: Lexicon, preps: tuple[str, ...] = ("to",)) -> str | None:
    """The person's pronoun (`Lexicon.recipient_pronouns`) a verb is said with as its recipient, as its
    indirect object ("grab me a towel", "give her the knife") or after one of `preps` ("hand the towel to
    me"; with "for": "fetch the milk for her"); None when it has none. English grammar."""
    objects = [c for c in verb.children if c.dep_ == "dobj"]
    for child in verb.children:
        # "pass me the spatula" is sometimes parsed with two objects: the pronoun before the other is who gets it
        first_of_two = child.dep_ == "dobj" and len(objects) > 1 and child.i == objects[0].i
        if (child.dep_ == "dative" or first_of_two) and child.lower_ in lex.recipient_pronouns:
            return child.lower_
        if child.dep_ in ("dative", "prep") and child.lower_ in preps:
            found = next((c for c in child.children if c.dep_ == "pobj" and c.lower_ in lex.recipient_pronouns), None)
            if found is not None:
                return found.lower_
    return None


# Dependents of a measure noun that count or divide it ("two glasses", "half a cup"): then it is a quantity.
COUNTING_DEPS = frozenset({"nummod", "predet", "quantmod"})


def served_in(doc: Doc, mention: FrameMention, lex: Lexicon) -> str | None:
    """The vessel a request serves its Theme in, named as its measure: "pour me a glass of water" ->
    "glass"; None otherwise. English grammar, not knowledge of things: the verb has two objects, a
    recipient pronoun (the person served) and one uncounted measure noun with an of-phrase (the parser
    gives its role to the of-phrase, "water"). A measure alone is a quantity ("pour a cup of milk into
    the batter", "pour me half a cup of milk", "pour us two glasses of wine")."""
    predicate = predicate_token(doc, mention)
    if predicate is None:
        return None
    objects = [c for c in predicate.children if c.dep_ in ("dative", "dobj")]
    if len(objects) != 2 or objects[0].lower_ not in lex.recipient_pronouns:
        return None
    measure, name = objects[1], lemma_of(objects[1])
    counted = any(c.dep_ in COUNTING_DEPS for c in measure.children)
    has_of = any(c.dep_ == "prep" and c.lower_ == "of" for c in measure.children)
    return name if measure.tag_ == "NN" and not counted and has_of and name in lex.measure_nouns else None


@dataclass(frozen=True)
class Purpose:
    """What a thing asked for is for, as a frame of its own: the purpose clause's predicate, the roles the
    clause states, and the role the thing fills in it (`gap`)."""

    predicate: str
    roles: dict[str, str]
    gap: str


def purpose_of(doc: Doc, mention: FrameMention, lex: Lexicon, compounds: Compounds | None = None) -> Purpose | None:
    """ "hand me something to cut the bread with": the request's object is an indefinite pronoun
    ("something") with a clause that says what it is for; the thing is the role of that clause's frame
    its stranded preposition introduces (cut, Theme bread: the Instrument, "with"), or the clause verb's
    object when no preposition is stranded ("something to eat"). None when the request says no such
    thing or the clause's verb is no predicate the robot knows. English grammar, not knowledge of things."""
    verb = predicate_token(doc, mention)
    thing = (
        next((c for c in verb.children if c.dep_ == "dobj" and c.lower_ in lex.object_pronouns), None) if verb else None
    )
    clause = next((c for c in thing.children if c.dep_ in NOUN_CLAUSE_DEPS), None) if thing is not None else None
    found = next((f for f in extract_frames(doc, lex, compounds) if f.start == clause.idx), None) if clause else None
    spec = lex.predicates.get(found.predicate) if found is not None else None
    if spec is None:
        return None
    stranded = [c.lower_ for c in clause.children if c.dep_ == "prep" and not any(g.dep_ == "pobj" for g in c.children)]
    gap = spec.prep_role(stranded[0]) if stranded else spec.object_role
    if (
        gap is None
        or gap not in (*spec.roles, *spec.alternatives)
        or found.roles.get(gap) not in (None, *lex.object_pronouns)
    ):
        return None  # no role the thing could fill, or the clause states it ("to season the steak with salt")
    roles = {r: v for r, v in found.roles.items() if v and r != gap and v not in lex.object_pronouns}
    return Purpose(found.predicate, roles, gap)
