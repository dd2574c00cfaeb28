"""From an argument's head token to its value: lowercase singular head lemma with fixed compounds kept.

Determiners, numbers, possessives and ordinary adjectives are dropped ("the melted chocolate" ->
"chocolate"); compounds stay ("bell pepper", "soy sauce"); a noun-tagged or compound-marked modifier
is part of the name ("frying pan", "piping bag") while a participle adjective is not ("remaining
butter"); measure and quantity nouns give way to their of-phrase ("3 tablespoons of olive oil" ->
"olive oil"), and a counted measure before a noun is no part of its name ("2 tablespoons oil" ->
"oil"); pronouns stay as written.
"""

from __future__ import annotations

from spacy.tokens import Token

from lmcr.lexicon import Lexicon
from lmcr.srl.compounds import Compounds
from lmcr.srl.lemmas import lemma as lemma_of

NOUN_TAGS = frozenset({"NN", "NNS", "NNP", "NNPS"})
HEAD_TAGS = NOUN_TAGS | {"JJ", "VBG"}


def _of_object(token: Token) -> Token | None:
    for child in token.children:
        if child.dep_ == "prep" and child.lower_ == "of":
            return next((g for g in child.children if g.dep_ == "pobj"), None)
    return None


def resolve_head(token: Token, lex: Lexicon) -> Token | None:
    """Follow measure/quantity nouns and numbers to their of-object ("1/4 of the pepper"); None where
    nothing nameable is left."""
    for _ in range(4):  # "half of a cup of milk": at most a few hops
        lemma = lemma_of(token)
        quantity = lemma in lex.quantity_nouns or token.lower_ in lex.quantity_nouns or token.tag_ == "CD"
        if lemma in lex.measure_nouns or quantity:
            inner = _of_object(token)
            if inner is not None:
                token = inner
                continue
            if quantity:
                return None
        break
    if token.tag_ == "PRP" or token.lower_ in lex.object_pronouns:
        return token
    # The parse says this is an object; the small tagger often calls such nouns adjectives or
    # gerunds ("with rosemary/JJ", "with frosting/VBG"), so those heads count too.
    return token if token.tag_ in HEAD_TAGS or token.pos_ in ("NOUN", "PROPN") else None


def _counted_measure(token: Token, lex: Lexicon) -> bool:
    """A unit with a number of its own ("2 tablespoons", "1 cup", "9-inch"): a quantity, not a name's
    part. A plural unit before a noun is counted too ("tablespoons oil"); an uncounted one may name a
    kind of thing ("loaf pan", "glass jar")."""
    if lemma_of(token) not in lex.measure_nouns:
        return False
    before = [t for t in token.doc[max(token.i - 2, 0) : token.i] if t.text != "-"]
    return token.tag_ == "NNS" or bool(before) and (before[-1].like_num or before[-1].tag_ == "CD")


def _is_name_part(child: Token, head: Token, lex: Lexicon, compounds: Compounds | None) -> bool:
    if child.dep_ not in ("compound", "amod", "nmod") or not child.is_alpha or _counted_measure(child, lex):
        return False
    # A past participle describes the thing ("boiled water", "chopped garlic"), whatever its tag.
    if child._.participle or child.tag_ in ("VBN", "VBD"):
        return False
    # A common-noun tag stands ("bell/NN pepper", spaCy often marks it amod: "frying/NN pan"); so does
    # the parser's compound label on a word without the corpus statistics to judge it ("piping/VBG bag").
    if child.tag_ in ("NN", "NNS"):
        return True
    if compounds is None:
        return child.dep_ == "compound"
    # Adjective-, gerund- and proper-noun-tagged modifiers ("olive/JJ oil", "leftover/NNP rice"): the
    # corpus decides ("olive oil" joins, "hot oil" does not).
    return compounds.joins(child.lower_, head.lower_)


def _singular(token: Token) -> str:
    lemma = lemma_of(token)
    return lemma if token.tag_ in NOUN_TAGS and lemma.isalpha() else token.lower_


def noun_gerund(token: Token) -> bool:
    """A gerund that is the last word of a name ("the steak seasoning", "the dish rack drying"): tagged as a
    verb hung on the noun right before it, with nothing of its own but a particle. Not a verb of the request."""
    return (
        token.tag_ == "VBG"
        and token.dep_ == "acl"
        and token.head.i == token.i - 1
        and token.head.tag_.startswith("NN")
        and all(c.dep_ == "prt" for c in token.children)
    )


def misread_name_end(token: Token, compounds: Compounds | None) -> bool:
    """A word tagged as a verb right after a noun with which the corpus makes a fixed name ("put the bay
    leaves/VBZ away", "the vanilla extract/VB", "the ranch dressing/VBG"): the name's last word, not a verb
    of the request. Without the learned compounds no word is."""
    if compounds is None or token.i == 0 or not token.tag_.startswith("VB"):
        return False
    before = token.doc[token.i - 1]
    return before.tag_.startswith("NN") and f"{before.lower_} {token.lower_}" in compounds.strong_bigrams


def argument_value(token: Token, lex: Lexicon, compounds: Compounds | None = None) -> tuple[str, int, int] | None:
    """(value, start_char, end_char) of the argument headed by `token`, or None if it names nothing."""
    head = resolve_head(token, lex)
    if head is not None and head.lower_ in lex.courtesy_words:
        # "a mug of coffee please" read as a compound ending in please: the name ends before it
        before = head.doc[head.i - 1] if head.i else None
        head = (
            before if before is not None and before.head.i == head.i and before.dep_ in ("compound", "amod") else None
        )
    if head is None:
        return None
    if head.tag_ == "PRP" or head.lower_ in lex.object_pronouns:
        return head.lower_, head.idx, head.idx + len(head)
    parts: list[Token] = []
    # Name parts right before the head, each a modifier of the head or of a part ("ice cube tray").
    while head.i - len(parts) > 0:
        child = head.doc[head.i - len(parts) - 1]
        if child.head.i not in {head.i, *(p.i for p in parts)} or not _is_name_part(child, head, lex, compounds):
            break
        parts.insert(0, child)
    start = parts[0].idx if parts else head.idx
    # "the steak seasoning": a gerund that ends the name is its head word; so is a word misread as a verb
    # that the corpus says ends the name ("the bay leaves/VBZ")
    after = head.doc[head.i + 1] if head.i + 1 < len(head.doc) else None
    if after is not None and misread_name_end(after, compounds):
        last = after
    else:
        last = next((c for c in head.children if noun_gerund(c)), None)
    if last is not None:
        value = " ".join([p.lower_ for p in parts] + [head.lower_, last.lower_])
        return value, start, last.idx + len(last)
    value = " ".join([p.lower_ for p in parts] + [_singular(head)])
    return value, start, head.idx + len(head)
