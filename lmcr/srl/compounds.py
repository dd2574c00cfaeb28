"""Fixed compounds learned from the corpus: which modifiers are part of a name.

The small tagger calls many noun modifiers adjectives ("olive/JJ oil", "cinnamon/JJ sugar") and
some adjectives proper nouns ("leftover/NNP rice"), so the tag cannot tell "olive oil" (a name) from
"hot oil" (oil that is hot). Corpus statistics can:
- head rate: how often the word itself heads a noun phrase ("add the cinnamon," "with the tart.")
  among its uses after a determiner; nouns do this often, adjectives almost never. A noun said mostly as
  a modifier in the singular ("the vegetable stock", "a mushroom risotto") heads its phrases in the
  plural ("add the vegetables."), so a word whose plural has a noun's head rate is a noun too;
- unit strength of the bigram: fixed phrases ("olive oil", "black pepper", "sesame oil", "frying
  pan") stick together far more than chance (NPMI), or the modifier mostly comes with this head;
- predicative use: adjectives of state ("hot", "warm", "softened") follow "until", "is", "very"...
  often; a modifier used that way describes the thing and is never part of its name.
- proper adjectives: a word written capitalised inside sentences most of the time ("French toast",
  "Dijon mustard") names a kind, so it is part of the name;
Past participles ("chopped", "boiled") are never part of a name either (`arguments`), whatever the
statistics say. Everything here comes from `sentences`, nothing by hand.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import duckdb
from spacy.lang.en.stop_words import STOP_WORDS

from lmcr.files import atomic_path, read_resource
from lmcr.text import plural_forms

HEAD_RATE_MIN = 0.10  # nouns measured 0.10-0.49, adjectives/participles 0.00-0.08 (closing note)
NPMI_MIN = 0.65  # "black pepper" 0.75, "olive oil" 0.84; "salted water" 0.61, "melted butter" 0.52
# A weaker NPMI is enough when the modifier mostly comes with this head: "sesame oil" (NPMI 0.54,
# P(oil | sesame) 0.55), "frying pan" (0.54, 0.44); "large bowl" (0.56, 0.22) stays out.
NPMI_WITH_HEAD = 0.5
HEAD_GIVEN_MODIFIER_MIN = 0.3
# Predicative adjectives: share of a word's uses right after "until", "is", "very", ... ("hot" 0.15,
# "softened" 0.23, "cold" 0.12; "sesame" 0.00, "brown" 0.06, "large" 0.01).
PREDICATIVE_MIN = 0.1
MIN_PREDICATIVE_USES = 50
# Proper adjectives: share of a word's uses after a sentence's first word written capitalised.
PROPER_MIN = 0.8
MIN_PROPER_USES = 20
MIN_DETERMINED = 20  # uses after a determiner before a head rate is trusted
MIN_BIGRAM = 5
MIN_SINGULAR = 3  # uses after a singular determiner before a word's count is kept (`singular_counts`)

_TOKENS = """
create temp table _cmp_tokens as
select list_filter(string_split_regex(lower(text), '[^a-z]+|([.,;])'), lambda x: x <> '') as w
from sentences where kind in ('instruction', 'ingredient') and (? = 'all' or corpus = ?)
"""
_UNIGRAMS = """
create temp table _cmp_uni as select w1 as w, count(*) as n from (select unnest(w) as w1 from _cmp_tokens) group by 1
"""
_HEAD_RATES = """
with tri as (
    select w[i - 1] as d, w[i] as x, w[i + 1] as f
    from (select w, unnest(range(2, len(w))) as i from _cmp_tokens)
),
counts as (
    select x,
           count(*) filter (where f in ('.', ',', ';', 'and', 'or', 'to', 'in', 'into', 'with', 'on',
                                        'over', 'until', 'for', 'from')) as heads,
           count(*) as determined
    from tri
    where d in ('the', 'a', 'an', 'some', 'of', 'with', 'and')
    group by x
)
select x, heads / determined as rate from counts where determined >= ?
"""
_STRONG_BIGRAMS = """
with total as (select sum(n) as n from _cmp_uni),
bi as (
    select w[i] as a, w[i + 1] as b, count(*) as n
    from (select w, unnest(range(1, len(w))) as i from _cmp_tokens)
    group by all having count(*) >= ?
)
select a || ' ' || b, ln(bi.n * total.n / (ua.n * ub.n)) / -ln(bi.n / total.n) as npmi, bi.n / ua.n as p_head
from bi, total join _cmp_uni ua on ua.w = a join _cmp_uni ub on ub.w = b
where a not in ('.', ',', ';') and b not in ('.', ',', ';')
"""
_PREDICATIVE = """
with after as (
    select w[i] as x, count(*) as n
    from (select w, unnest(range(2, len(w) + 1)) as i from _cmp_tokens)
    where w[i - 1] in ('until', 'is', 'are', 'be', 'very', 'too', 'so', 'become', 'becomes', 'remain', 'remains',
                       'stay', 'stays', 'still', 'get', 'gets', 'keep', 'slightly', 'quite', 'rather', 'fairly')
    group by x
)
select x from after join _cmp_uni uni on uni.w = x where uni.n >= ? and after.n / uni.n >= ?
"""


_SINGULAR_USES = """
select w[i] as x, count(*) as n
from (select w, unnest(range(2, len(w) + 1)) as i from _cmp_tokens)
where w[i - 1] in ('a', 'an', 'each', 'every', 'another', 'this', 'that') and w[i] not in ('.', ',', ';')
group by x having count(*) >= ?
"""


_PROPER = """
with words as (
    select unnest(list_filter(string_split_regex(text, '[^A-Za-z]+'), lambda x: x <> '')[2:]) as word
    from sentences where kind = 'instruction' and (? = 'all' or corpus = ?)
)
select lower(word) as x from words where length(word) > 1
group by x having count(*) >= ? and avg((word[1] between 'A' and 'Z' and word[2:] = lower(word[2:]))::int) >= ?
"""


@dataclass
class Compounds:
    """Head rates of words and NPMI-strong bigrams; empty means "trust the tagger only"."""

    head_rates: dict[str, float] = field(default_factory=dict)
    strong_bigrams: frozenset[str] = frozenset()
    predicative: frozenset[str] = frozenset()
    proper: frozenset[str] = frozenset()
    # How often each word follows a singular determiner ("a cookie"): which lemma of a plural is the
    # noun the corpus uses (`lemmas.LazyLemmas`); None in files written before it was learned.
    singular_counts: dict[str, int] | None = None

    def joins(self, modifier: str, head: str) -> bool:
        """Whether `modifier head` is a fixed compound by the corpus statistics."""
        if modifier in self.predicative:
            return False
        return (
            modifier in self.proper
            or self.head_rates.get(modifier, 0.0) >= HEAD_RATE_MIN
            # "the other bowl": "others" heads phrases, "other" names nothing
            or (
                modifier not in STOP_WORDS
                and any(self.head_rates.get(f, 0.0) >= HEAD_RATE_MIN for f in plural_forms(modifier))
            )
            or f"{modifier} {head}" in self.strong_bigrams
        )

    def save(self, path: Path) -> None:
        """Write as JSON with sorted keys: the frame corpus's fingerprint hashes this file, and the
        statistics come out of DuckDB in no fixed order."""
        with atomic_path(path) as tmp:
            tmp.write_text(
                json.dumps(
                    {
                        "head_rates": self.head_rates,
                        "strong_bigrams": sorted(self.strong_bigrams),
                        "predicative": sorted(self.predicative),
                        "proper": sorted(self.proper),
                        "singular_counts": self.singular_counts,
                    },
                    sort_keys=True,
                )
            )

    @classmethod
    def load(cls, path: Path) -> Compounds:
        """The statistics `save` wrote; a damaged file is a ResourceError naming it."""
        return read_resource(path, "learned compounds", cls._from_json)

    @classmethod
    def _from_json(cls, data: dict) -> Compounds:
        singular = data.get("singular_counts")
        return cls(
            {_word(w): float(r) for w, r in data["head_rates"].items()},
            _words(data["strong_bigrams"]),
            _words(data.get("predicative", [])),
            _words(data.get("proper", [])),
            None if singular is None else {_word(w): int(n) for w, n in singular.items()},
        )


def _word(value: object) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{value!r} is not a word")
    return value


def _words(values: object) -> frozenset[str]:
    if not isinstance(values, list):
        raise TypeError(f"{str(values)[:40]!r} is not a list of words")
    return frozenset(_word(v) for v in values)


def learn_compounds(con: duckdb.DuckDBPyConnection, corpus: str = "all") -> Compounds:
    """Compute the statistics (head rates, strong bigrams, predicative and proper adjectives, singular
    uses) over the ingested sentences of a corpus setting."""
    con.execute(_TOKENS, [corpus, corpus])
    try:
        con.execute(_UNIGRAMS)
        rates = {w: round(r, 4) for w, r in con.execute(_HEAD_RATES, [MIN_DETERMINED]).fetchall() if r >= HEAD_RATE_MIN}
        bigrams = frozenset(
            b
            for b, npmi, p_head in con.execute(_STRONG_BIGRAMS, [MIN_BIGRAM]).fetchall()
            if npmi >= NPMI_MIN or npmi >= NPMI_WITH_HEAD and p_head >= HEAD_GIVEN_MODIFIER_MIN
        )
        predicative = frozenset(
            w for (w,) in con.execute(_PREDICATIVE, [MIN_PREDICATIVE_USES, PREDICATIVE_MIN]).fetchall()
        )
        singular = dict(con.execute(_SINGULAR_USES, [MIN_SINGULAR]).fetchall())
        proper = frozenset(w for (w,) in con.execute(_PROPER, [corpus, corpus, MIN_PROPER_USES, PROPER_MIN]).fetchall())
    finally:
        con.execute("drop table if exists _cmp_uni")
        con.execute("drop table _cmp_tokens")
    return Compounds(rates, bigrams, predicative, proper, singular)
