"""Parse repair: a compound whose plural head the small parser read as a verb or a second object.

"sprinkle the bay leaves over the stew" comes out as "bay" subject of a verb "leaves"; "pour the hot
oil over the chili flakes" as "flakes" a verb coordinated with "pour"; "sprinkle the bread crumbs"
as two objects. When the two words are a strong bigram of the corpus (`Compounds.strong_bigrams`:
"bay leaves", "chili flakes", "bread crumbs"), the plural is the head noun and the word before it a
modifier, and the tree is mended so: the plural takes the place of the noun phrase, the noun becomes
its compound. Terse narrations bring a fourth: "pour oil in frying pan" comes out as a gerund "frying"
with the object "pan" (a fry frame of the pan, and no destination for the pour); when the two words are
a strong bigram ("frying pan", "measuring cup", "cutting board") the noun takes the gerund's place and
the gerund becomes its compound. Without learned compounds nothing is changed.

A noun that is also a modal verb ("can") is read as the modal after the words of its noun phrase: "dispose of
that empty can" leaves "empty" the object and "can" a modal with no verb to govern. A modal that follows
a determiner, an adjective or a noun and is followed by no verb is a noun (English: a modal always
governs a verb, and a determiner never precedes one): it takes the place of the phrase's head, whose
words become its modifiers (`mend_modal_nouns`). That is grammar, the same for every word.
"""

from __future__ import annotations

from spacy.tokens import Doc, Token

from lmcr.srl.compounds import Compounds

CLAUSE_DEPS = frozenset({"ccomp", "conj", "dep", "xcomp", "advcl"})
PHRASE_DEPS = frozenset({"dobj", "pobj", "nsubjpass", "obj"})
# Where a gerund read as a verb stood, and what its noun is there: a preposition's object ("in frying
# pan"), a verb's object ("stir frying pan"), the sentence's head ("frying pan on the hob").
GERUND_PLACES = {"pcomp": "pobj", "xcomp": "dobj", "ROOT": "ROOT"}


def _split(noun: Token, plural: Token) -> str | None:
    """Which misreading `noun plural` is, or None: 'subject' (bay/nsubj leaves/VBZ), 'verb' (chili/pobj
    flakes/VBZ, a clause of its own), 'objects' (bread/dobj crumbs/dobj, siblings)."""
    if plural.tag_ == "VBZ" and noun.head.i == plural.i and noun.dep_ == "nsubj" and plural.dep_ in CLAUSE_DEPS:
        return "subject"
    if (
        plural.tag_ == "VBZ"
        and noun.dep_ in PHRASE_DEPS
        and plural.dep_ in CLAUSE_DEPS
        and plural.n_lefts + plural.n_rights == 0
    ):
        return "verb"
    if plural.tag_ == "NNS" and noun.dep_ == plural.dep_ == "dobj" and noun.head.i == plural.head.i:
        return "objects"
    return None


def _rejoin_gerund(gerund: Token, noun: Token) -> None:
    """ "frying/VBG pan/dobj" -> "frying/NN pan": the noun takes the gerund's place, with its other words."""
    noun.dep_ = GERUND_PLACES[gerund.dep_]
    noun.head = noun if gerund.dep_ == "ROOT" else gerund.head
    for child in list(gerund.children):
        if child.i != noun.i:
            child.head = noun
    gerund.head, gerund.dep_ = noun, "compound"
    gerund.tag_, gerund.pos_ = "NN", "NOUN"


def rejoin_split_compounds(doc: Doc, compounds: Compounds | None) -> Doc:
    """Mend the misreadings of a corpus compound: three with a plural head, and a gerund read as a verb
    with its object (module docstring)."""
    if compounds is None:
        return doc
    for gerund, noun in zip(doc[:-1], doc[1:]):
        if (
            gerund.tag_ == "VBG"
            and gerund.dep_ in GERUND_PLACES
            and noun.head.i == gerund.i
            and noun.dep_ == "dobj"
            and noun.tag_.startswith("NN")
            and f"{gerund.lower_} {noun.lower_}" in compounds.strong_bigrams
        ):
            _rejoin_gerund(gerund, noun)
    for noun, plural in zip(doc[:-1], doc[1:]):
        if (
            noun.tag_ not in ("NN", "NNP")
            or not plural.lower_.endswith("s")
            or f"{noun.lower_} {plural.lower_}" not in compounds.strong_bigrams
        ):
            continue
        kind = _split(noun, plural)
        if kind is None:
            continue
        if kind == "subject":
            plural.dep_ = "dobj"
        elif kind == "verb":
            plural.head, plural.dep_ = noun.head, noun.dep_
        noun.head, noun.dep_ = plural, "compound"
        plural.tag_, plural.pos_ = "NNS", "NOUN"
    return doc


NOMINAL_TAGS = frozenset({"DT", "JJ", "NN", "NNS", "NNP", "PRP$", "CD"})


def mend_modal_nouns(doc: Doc) -> Doc:
    """Make each modal that stands where a noun does (after a noun phrase's words, before no verb) the noun
    it is: "recycle the soda can", "throw out the empty can", "dispose of that empty can" (module docstring)."""
    for token in doc:
        if token.tag_ != "MD" or token.i == 0 or doc[token.i - 1].tag_ not in NOMINAL_TAGS:
            continue
        after = doc[token.i + 1] if token.i + 1 < len(doc) else None
        if after is not None and (after.tag_.startswith("VB") or after.tag_ in ("RB", "PRP", "TO", "MD")):
            continue  # a modal governing a verb: "you can pour", "it can be", "can you"
        _as_noun(token, doc[token.i - 1])
    return doc


def _as_noun(modal: Token, before: Token) -> None:
    """The modal becomes the noun heading the phrase `before` ends: in its place when the parser made `before`
    the phrase's head ("the empty/dobj can/punct"), with its determiner and modifiers."""
    head = before if before.dep_ in PHRASE_DEPS else None
    if modal.dep_ == "ROOT":  # "dispose/nsubj of the empty/pobj can/ROOT": the verb is the sentence's head
        verb = next((c for c in modal.children if c.dep_ == "nsubj" and c.i < modal.i), None)
        if verb is None or head is None:
            return
        verb.head, verb.dep_, verb.tag_, verb.pos_ = verb, "ROOT", "VB", "VERB"
        for child in list(modal.children):
            if child.i != verb.i:
                child.head = verb
    if head is not None:
        modal.head, modal.dep_ = head.head, head.dep_
        for child in list(head.children):
            child.head = modal
        head.head, head.dep_ = modal, "amod" if head.tag_ == "JJ" else "compound"
    modal.tag_, modal.pos_ = "NN", "NOUN"
