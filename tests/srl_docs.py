"""Hand-built parsed Docs for model-free SRL tests: "word/TAG/dep/head[/lemma]" per token."""

from __future__ import annotations

import spacy
from spacy.tokens import Doc

VOCAB = spacy.blank("en").vocab  # English lexical attributes (is_alpha, ...) without a model


def make_doc(spec: str) -> Doc:
    """A parsed Doc from tokens written `word/TAG/dep/head[/lemma]` (head = absolute index)."""
    words, tags, deps, heads, lemmas = [], [], [], [], []
    for item in spec.split():
        word, tag, dep, head, *lemma = item.split("/")
        words.append(word.replace("_", " "))
        tags.append(tag)
        deps.append(dep)
        heads.append(int(head))
        lemmas.append(lemma[0] if lemma else word.lower())
    return Doc(VOCAB, words=words, tags=tags, deps=deps, heads=heads, lemmas=lemmas)
