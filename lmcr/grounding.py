"""Grounding what an instruction says in what the robot sees: a stated filler names a detected object (by
its label, its label's last words, the same noun in either number, its head word, the whole label said
in the instruction, or its first words: "the trash" for a trash can) or a word of the robot's object
vocabulary; a pronoun names an object said before it; "a glass of water" names the glass it is served
in; "bring me the soap" and "hand it to her" name the person as where it goes."""

from __future__ import annotations

import re

from lmcr.srl.context import antecedents, predicate_token, recipient, served_in
from lmcr.srl.mentions import FrameMention
from lmcr.srl.parser import FrameParser
from lmcr.text import plural_forms


def grounded(value: str, known: set[str]) -> str | None:
    """The longest ending of a stated filler that names a known object ("leftover pizza" -> pizza: a
    modifier the parser kept does not hide the object), or None."""
    words = value.split()
    return next((" ".join(words[i:]) for i in range(len(words)) if " ".join(words[i:]) in known), None)


def conjoined(doc, frame: FrameMention, detected: list[str]) -> set[str]:
    """Detected objects the request names in coordination with a stated filler ("mix the flour and sugar":
    the sugar is mixed too): they share its role, so none of them is what a missing role asks for (the
    tool to mix with). English coordination, read from the parse."""
    seen, found = set(detected), set()
    for start, end in frame.spans.values():
        inside = [t for t in doc if start <= t.idx < end]
        for conj in (c for t in inside for c in t.conjuncts if not start <= c.idx < end and c.tag_.startswith("NN")):
            name = grounded(doc[conj.left_edge.i : conj.i + 1].text.lower(), seen)
            found |= {name} if name else set()
    return found


def referents(parser: FrameParser, doc, frame: FrameMention, detected: list[str]) -> dict[str, str]:
    """Pronoun roles that refer back to a detected object the instruction named before them ("I'd love
    some wine, could you pour it?": Theme wine): the first of `antecedents` that names one and that no
    other role states."""
    seen, stated = set(detected), {v for v in frame.roles.values() if v and v not in parser.lex.object_pronouns}
    referred: dict[str, str] = {}
    for role in frame.roles:
        for name in antecedents(doc, frame, role, parser.lex, parser.compounds):
            # the antecedent is a lemma: "these chips are stale, toss them" names the chips
            obj = grounded(name, seen) or named_by_head(name, detected)
            if obj is not None and obj not in stated and obj not in referred.values():
                referred[role] = obj
                break
    return referred


# learned classes of motion whose Destination is where the verb makes something ("cut me a slice" into a
# bowl, "bake me a cake" in the oven), not who gets it (`lmcr.frame_corpus.predicates.MOTION_CLASSES`)
MADE_AT_DESTINATION = frozenset({"cut", "cook"})


def speaker_destination(parser: FrameParser, doc, frame: FrameMention, detected: list[str]) -> dict[str, str]:
    """ "bring me the soap", "hand the towel to her", "get me something to drink from", "bring it here": a
    learned verb said to a person as its recipient (`srl.context.recipient`), or to where the person who
    asks is (`Lexicon.speaker_places`: "here"), puts its Theme in their hands, so the detected object
    that is a person (`Lexicon.speaker_labels`) fills its Destination, open or stated as that pronoun, or
    as the subject of a request ("can I have the soap": `srl.instruction.with_requests`).
    Not for a verb of a class that makes something at its Destination (`MADE_AT_DESTINATION`); the
    paper's verbs keep their own reading ("pour me some water": into a cup)."""
    lex, open_role = parser.lex, "Destination"
    spec = lex.predicates.get(frame.predicate)
    if frame.predicate not in lex.learned or spec is None or spec.motion in MADE_AT_DESTINATION:
        return {}
    if open_role not in frame.roles:
        return {}
    said = frame.roles[open_role]
    if said is None:
        verb = predicate_token(doc, frame)
        here = verb is not None and any(c.dep_ == "advmod" and c.lower_ in lex.speaker_places for c in verb.children)
        if verb is None or not (here or recipient(verb, lex)):
            return {}
    elif said not in lex.person_words:  # "to her"; "can I have" (`with_requests`)
        return {}
    person = next((o for o in detected if o in lex.speaker_labels), None)
    return {open_role: person} if person else {}


def served_vessel(
    parser: FrameParser, doc, frame: FrameMention, detected: list[str], taken: dict[str, str]
) -> dict[str, str]:
    """The open role a vessel is poured into, filled with the vessel the request serves in ("pour me a
    glass of water": Destination glass) when a detected object names it and no role states it."""
    vessel = served_in(doc, frame, parser.lex)
    obj = vessel and grounded(vessel, set(detected))
    if not obj or obj in frame.roles.values() or obj in taken.values():
        return {}
    template = parser.lex.predicates[frame.predicate].template(frame.roles)
    into = [r for r, v in frame.roles.items() if v is None and r not in taken and f"into the {{{r}}}" in template]
    return {into[0]: obj} if into else {}


def ground_roles(
    roles: dict[str, str | None],
    vocabulary: tuple[str, ...],
    detected: list[str],
    said: str = "",
    spans: dict[str, tuple[int, int]] | None = None,
) -> tuple[dict[str, str | None], dict[str, str]]:
    """Stated fillers grounded in the detected objects or the robot's object vocabulary, and the ones
    the robot cannot ground ("fry two sunny side up" -> Theme 'side'), which are filled from the
    objects like a missing role. Without a vocabulary in the lexicon every stated filler is kept.
    `said` is the instruction: an object whose whole label it says names the filler the parser cut
    short ("put the tank top away": Theme 'tank'), and so does one it says in full where the filler's
    phrase ends (`spans`, role -> the phrase's characters: "serve the soup in the blue bowl", 'bowl')."""
    if not vocabulary:
        return roles, {}
    seen, words = set(detected), set(vocabulary)

    def ground(role: str, value: str) -> str | None:  # what the person sees first, then what the robot knows
        end = (spans or {}).get(role, (0, 0))[1]
        found = said_before(end, value, detected, said) or grounded(value, seen) or named_by_head(value, detected)
        found = found or said_in_full(value, detected, said) or named_by_modifier(value, detected)
        return found or grounded(value, words)

    named = {r: v and ground(r, v) for r, v in roles.items()}
    unresolved = {r: v for r, v in roles.items() if v and named[r] is None}
    return named, unresolved


def same_noun(word: str, other: str) -> bool:
    """The same noun in either number: carrot / carrots, dish / dishes, patty / patties."""
    if word == other:
        return True
    one, two = sorted((word, other), key=len)
    return two in plural_forms(one)


def named_by_head(value: str, detected: list[str]) -> str | None:
    """The one detected object a stated filler names by its head word or its letters: "the chips" with
    kettle chips on the table, "the soda" with an orange soda, "RedBull" for red bull, the lemma "carrot"
    for the carrots; None when no object or several match (which of them is then the robot's question)."""
    found = objects_named(value, detected)
    return found[0] if len(found) == 1 else None


def objects_named(value: str, detected: list[str]) -> list[str]:
    """Every detected object a stated filler names by its head word or its letters (see `named_by_head`),
    in the order detected: "the chips" with kettle chips and jalapeno chips names both."""
    words = value.split()
    squeezed = value.replace(" ", "")

    def names(obj: str) -> bool:
        label = obj.split()
        if obj.replace(" ", "") == squeezed:
            return True
        if label[:-1] == words[:-1] and same_noun(label[-1], words[-1]):  # the same name, another number
            return True
        return len(label) > 1 and same_noun(label[-1], words[-1])

    return [o for o in detected if names(o)]


def named_by_modifier(value: str, detected: list[str]) -> str | None:
    """The one detected object whose label is the stated filler with a noun after it: "throw it in the
    trash" with a trash can on the floor, "take the clothes to the laundry" with a laundry basket, "put it
    in the recycling" with a recycling bin; None when no object or several are so named."""
    found = [o for o in detected if o.startswith(f"{value} ")]
    return found[0] if len(found) == 1 else None


def said_before(end: int, value: str, detected: list[str], said: str) -> str | None:
    """The one detected object, its label longer than the filler, that the instruction says in full
    ending at character `end`, where the filler's phrase ends ("the blue bowl": the parser kept 'bowl',
    and a blue bowl is on the table beside a bowl); None when none or several are."""
    words = re.findall(r"[a-z0-9']+", said[:end].lower())

    def ends_with(label: list[str]) -> bool:
        tail = words[-len(label) :]
        return len(tail) == len(label) and tail[:-1] == label[:-1] and same_noun(tail[-1], label[-1])

    longer = [o for o in detected if len(o.split()) > len(value.split()) and ends_with(o.split())]
    return longer[0] if len(longer) == 1 else None


def said_in_full(value: str, detected: list[str], said: str) -> str | None:
    """The longest detected object whose whole label the instruction says and whose words hold every
    word of the filler ("stainless steel" in "put the stainless steel spoon away"), if only one is that
    long."""
    text = f" {' '.join(re.findall(r'[a-z0-9]+', said.lower()))} "
    words = value.split()
    found = [o for o in detected if f" {o} " in text and all(any(same_noun(w, x) for x in o.split()) for w in words)]
    longest = [o for o in found if len(o) == max(map(len, found))] if found else []
    return longest[0] if len(longest) == 1 else None
