"""Corpus terms for the count- and vector-based baselines: which verbs and objects a sentence mentions.

A term is a lemma ("cup") or a multiword object ("bell pepper"). A token matches a term when the
spaCy rule lemmatizer, asked for the token as a noun or as a verb, gives the term's lemma ("cups",
"poured"), so counting sees the same words the frame parser sees, without parsing the corpus again.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import lru_cache

from lmcr.lm.linearize import tokens


class Lemmatizer:
    """Noun and verb lemmas of a word from a spaCy pipeline's rule tables, cached per word."""

    def __init__(self, nlp):
        self.nlp = nlp
        self.rules = nlp.get_pipe("lemmatizer")
        self.cache: dict[str, frozenset[str]] = {}

    def lemmas(self, word: str) -> frozenset[str]:
        found = self.cache.get(word)
        if found is None:
            doc = self.nlp.make_doc(word)
            forms = {word}
            for pos in ("NOUN", "VERB"):
                doc[0].pos_ = pos
                forms.update(f.lower() for f in self.rules.rule_lemmatize(doc[0]))
            found = self.cache[word] = frozenset(forms)
        return found


@lru_cache(maxsize=4)
def default_lemmatizer(model: str) -> Lemmatizer:
    import spacy

    return Lemmatizer(spacy.load(model, disable=["parser", "ner", "tagger", "attribute_ruler"]))


class TermMatcher:
    """Finds a fixed set of terms in token sequences."""

    def __init__(self, terms: Iterable[str], lemmatizer: Lemmatizer):
        self.terms = {tuple(t.split()) for t in terms}
        self.lemmatizer = lemmatizer
        self._ending: dict[str, list[tuple[str, ...]]] = {}

    def ending_in(self, word: str) -> list[tuple[str, ...]]:
        """Terms whose last word is a lemma of `word` (earlier words of a multiword term match as written)."""
        found = self._ending.get(word)
        if found is None:
            lemmas = self.lemmatizer.lemmas(word)
            found = self._ending[word] = [t for t in self.terms if t[-1] in lemmas]
        return found

    def find(self, words: list[str]) -> set[str]:
        """The terms mentioned in a tokenised sentence (each at most once)."""
        found = set()
        for i, word in enumerate(words):
            for term in self.ending_in(word):
                start = i - len(term) + 1
                if start >= 0 and tuple(words[start:i]) == term[:-1]:
                    found.add(" ".join(term))
        return found

    def find_text(self, text: str) -> set[str]:
        return self.find(tokens(text))
