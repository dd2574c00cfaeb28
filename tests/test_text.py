"""Normalisation and sentence splitting: fixed cases and properties."""

import re

from hypothesis import given
from hypothesis import strategies as st

from lmcr.text import counted_form, normalize, plural_forms, singular_forms, split_sentences


def test_normalize_fractions_quotes_dashes_spaces():
    assert normalize("1½ cups “sugar” – 2¼\u00a0lb flour") == '1 1/2 cups "sugar" - 2 1/4 lb flour'
    assert normalize("¾ cup") == "3/4 cup"
    assert normalize("1\u20442 tsp") == "1/2 tsp"
    assert normalize("  350 F  ") == "350 F"


def test_split_keeps_quantities_and_abbreviations():
    text = "Preheat oven to 350 F. Mix 1/2 cup flour with 1 1/2 tsp. salt. Bake 2.5 hrs."
    assert split_sentences(text) == [
        "Preheat oven to 350 F.",
        "Mix 1/2 cup flour with 1 1/2 tsp. salt.",
        "Bake 2.5 hrs.",
    ]
    assert split_sentences("Mrs. A. Smith says: stir") == ["Mrs. A. Smith says: stir"]
    assert split_sentences("Add 2 T. Butter. Mix.") == ["Add 2 T. Butter.", "Mix."]
    assert split_sentences("Heat to 180 C. Add eggs.") == ["Heat to 180 C.", "Add eggs."]
    assert split_sentences("Bake 10 min. Let cool.") == ["Bake 10 min.", "Let cool."]


def test_split_leaves_lowercase_steps_whole():
    assert split_sentences("spread margarine on two slices of white bread") == [
        "spread margarine on two slices of white bread"
    ]
    assert split_sentences("   ") == []


words = st.text(alphabet="abcdefghijklmnopqrstuvwxyzABCDEFGHIJ0123456789/.,!?;½¼ ", min_size=0, max_size=80)


@given(words)
def test_normalize_is_idempotent(text):
    assert normalize(normalize(text)) == normalize(text)


@given(st.lists(words, max_size=6))
def test_split_loses_no_characters(parts):
    text = ". ".join(parts)
    sentences = split_sentences(text)
    assert "".join(sentences).replace(" ", "") == normalize(text).replace(" ", "")
    assert all(s == s.strip() and s for s in sentences)


@given(st.integers(1, 20), st.integers(2, 16), st.sampled_from(["cup", "tsp.", "lb.", "F"]))
def test_fractions_and_numbers_never_split(whole, denominator, unit):
    text = f"Add {whole} 1/{denominator} {unit} of flour and {whole}.5 cups water. Stir well."
    sentences = split_sentences(text)
    assert any(f"{whole} 1/{denominator}" in s for s in sentences)
    assert any(f"{whole}.5 cups" in s for s in sentences)
    assert not any(re.fullmatch(r"\d+", s) for s in sentences)


@given(st.from_regex(r"[a-z]{2,8}", fullmatch=True))
def test_a_singular_is_among_the_singular_forms_of_each_of_its_plurals(word):
    for plural in plural_forms(word):
        assert word in singular_forms(plural)
        # the counts decide: the singular where it is counted more, the label where it is not
        assert counted_form(f"kettle {plural}", {f"kettle {word}": 2.0}) == f"kettle {word}"
        assert counted_form(plural, {plural: 2.0, word: 1.0}) == plural
    assert counted_form(word, {}) == word
