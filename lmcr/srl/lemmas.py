"""Lemmas on demand: the model's rule lemmatizer run only for inflected words, cached.

spaCy's attribute ruler and lemmatizer take about half of en_core_web_sm's time, yet frames need
lemmas only of predicates and argument heads. So the pipeline runs without them and this fills
`token.lemma_` of inflected nouns, verbs and adjectives from the same lemmatizer tables, once per
distinct (word, tag). Base forms are left empty: read lemmas with `lemma(token)`.

Two things the rules alone get wrong, settled by how the corpus uses the words (`singular_counts`,
learned with the compounds: how often a word follows a singular determiner, "a cookie", "a leaf"):
- several candidates ("cookies" -> cooky or cookie, "leaves" -> leaf or leave): the one the corpus
  uses as a singular noun most; without counts the longest (the least stripped) one;
- a plural the tagger calls singular ("the pancakes/NN"): the word ending in -s is read as a plural
  when a singular candidate is used as a singular noun more often than the word itself; without
  counts, when the word is not a noun lemma of the lemmatizer's own index and a candidate is.

It also marks past participles among noun modifiers (`token._.participle`: "chopped/JJ garlic",
"frozen/VBN peas"), by the tag or by the lemmatizer reading the word as a form of a known verb.
"""

from __future__ import annotations

from collections.abc import Mapping

from spacy.language import Language
from spacy.tokens import Doc, Token

if not Token.has_extension("participle"):
    Token.set_extension("participle", default=False)

# The lemmatizer's rules are keyed by universal POS, which the (skipped) attribute ruler would set.
UPOS_BY_TAG = {"NNP": "PROPN", "NNPS": "PROPN"}
UPOS_BY_PREFIX = {"N": "NOUN", "V": "VERB", "J": "ADJ"}
# Inflected tags: only these need the lemmatizer. A base form's lemma is the word itself ("glass",
# where the rules alone would strip "glas": the skipped attribute ruler would have said Number=Sing).
INFLECTED_TAGS = frozenset({"NNS", "NNPS", "VBD", "VBG", "VBN", "VBZ", "JJR", "JJS"})
# Endings of singular nouns that look plural ("glass", "hummus", "basis"): never read as plurals.
SINGULAR_S_ENDINGS = ("ss", "us", "is")
MODIFIER_DEPS = frozenset({"amod", "compound", "nmod"})


def lemma(token: Token) -> str:
    """Lowercase lemma, whether the pipeline's lemmatizer ran, `LazyLemmas` filled it, or it is a base form."""
    return (token.lemma_ or token.lower_).lower()


class LazyLemmas:
    """Fills lemmas of content words in docs parsed without the lemmatizer."""

    def __init__(self, nlp: Language, singular_counts: Mapping[str, int] | None = None):
        self.active = "lemmatizer" not in nlp.pipe_names and "lemmatizer" in nlp.component_names
        self.lemmatizer = nlp.get_pipe("lemmatizer") if self.active else None
        self.singular_counts = singular_counts
        self.noun_index = (
            frozenset(self.lemmatizer.lookups.get_table("lemma_index").get("noun", ())) if self.active else frozenset()
        )
        lookups = self.lemmatizer.lookups if self.active else None
        self.verb_index = frozenset(lookups.get_table("lemma_index").get("verb", ())) if lookups else frozenset()
        self.verb_exceptions = frozenset(lookups.get_table("lemma_exc").get("verb", {})) if lookups else frozenset()
        self.cache: dict[tuple[str, str, bool], str] = {}
        self.participles: dict[str, bool] = {}

    def fill(self, doc: Doc) -> Doc:
        if not self.active:
            return doc
        for token in doc:
            tag = token.tag_
            plural = self._maybe_plural(token)
            if tag not in INFLECTED_TAGS and not plural:
                continue
            # the lemma depends on the case too ("Apples/NNPS" a name, "apples/NNPS" a misread plural): keyed
            # without it, whichever came first decided for both, and a build depended on the texts' order
            key = (token.lower_, tag, plural)
            found = self.cache.get(key)
            if found is None:
                found = self.cache[key] = self._lemmatize(token)
            if found != token.lower_:
                token.lemma_ = found
        for token in doc:
            if token.dep_ in MODIFIER_DEPS and token.i < len(doc) - 1:
                token._.participle = self._participle(token)
        return doc

    def _participle(self, token: Token) -> bool:
        """A past participle: tagged one, or an -ed/-en word (or an irregular verb form: "ground") the
        lemmatizer reads as a form of a known verb ("chopped/JJ" -> chop); never an -ing word."""
        word = token.lower_
        if word.endswith("ing"):
            return False
        if token.tag_ in ("VBN", "VBD"):
            return True
        if word not in self.participles:
            candidates: list[str] = []
            if word.endswith(("ed", "en")) or word in self.verb_exceptions:
                tag, pos = token.tag_, token.pos_
                token.tag_, token.pos_ = "VBN", "VERB"
                candidates = self.lemmatizer.rule_lemmatize(token)
                token.tag_, token.pos_ = tag, pos
            self.participles[word] = any(c != word and c in self.verb_index for c in candidates)
        return self.participles[word]

    @staticmethod
    def _maybe_plural(token: Token) -> bool:
        """A singular or proper-noun tag on a lowercase word ending in -s ("the tortillas/NNP")."""
        return (
            token.tag_ in ("NN", "NNP", "NNPS")
            and token.text.islower()
            and token.lower_.endswith("s")
            and not token.lower_.endswith(SINGULAR_S_ENDINGS)
        )

    def _lemmatize(self, token: Token) -> str:
        if self._maybe_plural(token):  # a plural the tagger called singular: the candidates of the plural
            tag = token.tag_
            token.tag_, token.pos_ = "NNS", "NOUN"
            candidates = self.lemmatizer.rule_lemmatize(token)
            token.tag_ = tag
            return self._plural_or_word(token.lower_, candidates)
        token.pos_ = UPOS_BY_TAG.get(token.tag_) or UPOS_BY_PREFIX[token.tag_[0]]
        return self._best(self.lemmatizer.rule_lemmatize(token)).lower()

    def _uses(self, word: str) -> int:
        return self.singular_counts.get(word, 0) if self.singular_counts is not None else 0

    def _best(self, candidates: list[str]) -> str:
        """The candidate most used as a singular noun, then the longest, then the first alphabetically
        (the lemmatizer returns them in set order, which changes from run to run)."""
        return min(candidates, key=lambda c: (-self._uses(c.lower()), -len(c), c))

    def _plural_or_word(self, word: str, candidates: list[str]) -> str:
        singular = [c.lower() for c in candidates if c.lower() != word]
        if not singular:
            return word
        best = self._best(singular)
        if self.singular_counts is not None:
            return best if self._uses(best) > self._uses(word) else word
        return best if word not in self.noun_index and best in self.noun_index else word
