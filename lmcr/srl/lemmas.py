"""Lemmas on demand: the model's rule lemmatizer run only for inflected words, cached.

spaCy's attribute ruler and lemmatizer take about half of en_core_web_sm's time, yet frames need
lemmas only of predicates and argument heads. So the pipeline runs without them and this fills
`token.lemma_` of inflected nouns, verbs and adjectives from the same lemmatizer tables, once per
distinct (word, tag). Base forms are left empty: read lemmas with `lemma(token)`.
"""

from __future__ import annotations

from spacy.language import Language
from spacy.tokens import Doc, Token

# The lemmatizer's rules are keyed by universal POS, which the (skipped) attribute ruler would set.
UPOS_BY_TAG = {"NNP": "PROPN", "NNPS": "PROPN"}
UPOS_BY_PREFIX = {"N": "NOUN", "V": "VERB", "J": "ADJ"}
# Inflected tags: only these need the lemmatizer. A base form's lemma is the word itself ("glass",
# where the rules alone would strip "glas": the skipped attribute ruler would have said Number=Sing).
INFLECTED_TAGS = frozenset({"NNS", "NNPS", "VBD", "VBG", "VBN", "VBZ", "JJR", "JJS"})


def lemma(token: Token) -> str:
    """Lowercase lemma, whether the pipeline's lemmatizer ran, `LazyLemmas` filled it, or it is a base form."""
    return (token.lemma_ or token.lower_).lower()


class LazyLemmas:
    """Fills lemmas of content words in docs parsed without the lemmatizer."""

    def __init__(self, nlp: Language):
        self.active = "lemmatizer" not in nlp.pipe_names and "lemmatizer" in nlp.component_names
        self.lemmatizer = nlp.get_pipe("lemmatizer") if self.active else None
        self.cache: dict[tuple[str, str], str] = {}

    def fill(self, doc: Doc) -> Doc:
        if not self.active:
            return doc
        for token in doc:
            tag = token.tag_
            if tag not in INFLECTED_TAGS:
                continue
            key = (token.lower_, tag)
            found = self.cache.get(key)
            if found is None:
                token.pos_ = UPOS_BY_TAG.get(tag) or UPOS_BY_PREFIX[tag[0]]
                found = self.cache[key] = self.lemmatizer.rule_lemmatize(token)[0].lower()
            token.lemma_ = found
        return doc
