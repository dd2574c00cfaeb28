"""Text normalisation and sentence splitting for recipe text.

Normalisation makes equal text look equal (unicode forms, quotes, dashes, vulgar fractions, whitespace)
without touching what recipes rely on: "1/2 cup", "1 1/2 cups", "350 F", "2.5 kg", "9x13-inch".
"""

from __future__ import annotations

import re
import unicodedata
from collections.abc import Mapping

# Vulgar fractions become ASCII so "1½ cups" and "1 1/2 cups" are one form; NFKC alone would give
# "1⁄2" with a fraction slash and glue it to the whole number.
_FRACTIONS = {
    "½": "1/2",
    "⅓": "1/3",
    "⅔": "2/3",
    "¼": "1/4",
    "¾": "3/4",
    "⅕": "1/5",
    "⅖": "2/5",
    "⅗": "3/5",
    "⅘": "4/5",
    "⅙": "1/6",
    "⅚": "5/6",
    "⅛": "1/8",
    "⅜": "3/8",
    "⅝": "5/8",
    "⅞": "7/8",
}
_FRACTION_RE = re.compile(r"(\d?)([" + "".join(_FRACTIONS) + r"])")
_PUNCT = str.maketrans(
    {
        "\u2018": "'",
        "\u2019": "'",
        "\u201a": "'",
        "\u201b": "'",
        "\u2032": "'",
        "\u201c": '"',
        "\u201d": '"',
        "\u201e": '"',
        "\u2033": '"',
        "\u2010": "-",
        "\u2011": "-",
        "\u2012": "-",
        "\u2013": "-",
        "\u2014": " - ",
        "\u2015": " - ",
        "\u2044": "/",
        "\u2215": "/",
        "\u00a0": " ",
        "\u2009": " ",
        "\u202f": " ",
        "\u2026": "...",
    }
)
_CONTROL_RE = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u200b-\u200d\ufeff]")
_SPACE_RE = re.compile(r"\s+")


def _fraction(match: re.Match[str]) -> str:
    whole, frac = match.group(1), _FRACTIONS[match.group(2)]
    return f"{whole} {frac}" if whole else frac


def normalize(text: str) -> str:
    """Canonical form of a piece of recipe text: NFKC, ASCII quotes/dashes/fractions, single spaces."""
    text = _FRACTION_RE.sub(_fraction, text)
    text = unicodedata.normalize("NFKC", text).translate(_PUNCT)
    text = _CONTROL_RE.sub(" ", text)
    return _SPACE_RE.sub(" ", text).strip()


# Abbreviations that end with a period inside a sentence in recipe text ("1 tsp. salt", "approx. 2 lb.").
# Time units are left out on purpose: "Bake 10 min. Let cool." ends a sentence far more often than
# "10 min." precedes a capitalised word inside one.
ABBREVIATIONS = frozenset(
    "tsp tbsp tbs tbl tb oz lb lbs pt qt gal pkg pkgs doz sm med lg kg mg ml approx no nos vol fig st dr "
    "mr mrs ms vs etc ea env sq ft deg temp cf ca esp e.g i.e".split()
)
# Single-letter units after a number, case-sensitive: "1 c. sugar", "2 T. butter"; but "350 F." and
# "180 C." are temperatures that usually end a sentence.
SINGLE_LETTER_UNITS = frozenset("c t T g".split())
# A sentence ends at . ! ? (optionally followed by a closing quote or bracket) before whitespace and an
# uppercase letter, digit or opening quote/bracket. Lowercase continuation never splits, so YouCook2's
# lowercase step sentences and "1/2 cup" style text stay whole.
_BOUNDARY_RE = re.compile(r"([.!?]+[\"')\]]*)\s+(?=[A-Z0-9\"'(\[])")
_NUMBER_RE = re.compile(r"^[\d/.,-]+$")


def _ends_with_abbreviation(chunk: str) -> bool:
    tokens = chunk.split()
    word = tokens[-1].rstrip("\"')]").rstrip(".!?").lstrip("\"'([")
    after_number = len(tokens) > 1 and bool(_NUMBER_RE.match(tokens[-2]))
    if len(word) == 1 and word.isalpha():
        # A lone letter is a unit after a number, else an initial ("Mrs. A. Smith").
        return word in SINGLE_LETTER_UNITS if after_number else True
    return word.lower() in ABBREVIATIONS


def split_sentences(text: str) -> list[str]:
    """Split normalised text into sentences; abbreviations, decimals and fractions never end one."""
    text = normalize(text)
    if not text:
        return []
    sentences: list[str] = []
    start = 0
    for match in _BOUNDARY_RE.finditer(text):
        chunk = text[start : match.end(1)]
        if match.group(1).startswith(".") and _ends_with_abbreviation(chunk):
            continue
        sentences.append(chunk.strip())
        start = match.end()
    tail = text[start:].strip()
    if tail:
        sentences.append(tail)
    return [s for s in sentences if s]


def count_words(text: str) -> int:
    """Whitespace-delimited word count, the unit of every words/s figure."""
    return len(text.split())


def singular_forms(word: str) -> tuple[str, ...]:
    """The singulars English spelling can give a plural noun, the inverse of `plural_forms` and of -ves:
    carrots -> carrot, dishes -> dish, patties -> patty, knives -> knife, each with the other strippings
    (dishes -> dishe too: which of them is a word is for the caller's counts to say); none for a word
    without a plural ending."""
    endings = (("s", ""), ("es", ""), ("ies", "y"), ("ves", "f"), ("ves", "fe"))
    return tuple(word[: -len(end)] + base for end, base in endings if word.endswith(end) and len(word) > len(end))


def counted_form(label: str, counts: Mapping[str, float]) -> str:
    """The form of an object's label its corpus counts name it by: its last word in the singular where the
    counts know that form better ("eggs" -> egg, "kettle chips" -> "kettle chip"), else the label itself.
    The frame corpus keeps a filler's head as its lemma, so an object labelled in the plural would read as
    a filler hardly ever seen."""
    *name, last = label.split() or [""]
    forms = [" ".join([*name, f]) for f in singular_forms(last)]
    return max([label, *forms], key=lambda f: counts.get(f, 0.0))


def plural_forms(word: str) -> tuple[str, ...]:
    """The plurals English spelling can give a singular noun: carrot -> carrots, dish -> dishes, patty
    -> patties (which of them is a word is for the caller's counts to say)."""
    forms = (f"{word}s", f"{word}es")
    return (*forms, f"{word[:-1]}ies") if word.endswith("y") else forms
