"""Lemmas on demand: the model's rule lemmatizer run only for verbs, nouns and adjectives, cached.

spaCy's attribute ruler and lemmatizer take about half of en_core_web_sm's time, yet frames need
lemmas only of predicates and argument heads. So the pipeline runs without them and this fills
`token.lemma_` from the same lemmatizer tables, once per distinct (word, tag).
"""

from __future__ import annotations

from spacy.language import Language
from spacy.tokens import Doc

# The lemmatizer's rules are keyed by universal POS, which the (skipped) attribute ruler would set.
UPOS_BY_TAG = {"NNP": "PROPN", "NNPS": "PROPN"}
UPOS_BY_PREFIX = {"N": "NOUN", "V": "VERB", "J": "ADJ"}
# Tags of base forms: the lemma is the word ("glass", not the rule-stripped "glas"; the skipped
# attribute ruler would have said Number=Sing / VerbForm=Inf).
BASE_FORM_TAGS = frozenset({"NN", "NNP", "VB", "VBP", "JJ"})


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
            upos = UPOS_BY_TAG.get(token.tag_) or UPOS_BY_PREFIX.get(token.tag_[:1])
            if upos is None:
                continue
            key = (token.lower_, token.tag_)
            lemma = self.cache.get(key)
            if lemma is None:
                if token.tag_ in BASE_FORM_TAGS:
                    lemma = token.lower_
                else:
                    token.pos_ = upos
                    lemma = self.lemmatizer.rule_lemmatize(token)[0].lower()
                self.cache[key] = lemma
            token.lemma_ = lemma
        return doc
