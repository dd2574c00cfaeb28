"""Fixed compounds learned from the corpus: which adjective-tagged modifiers are part of a name.

The small tagger calls many noun modifiers adjectives ("olive/JJ oil", "cinnamon/JJ sugar"), so the
tag cannot tell "olive oil" (a name) from "hot oil" (oil that is hot). Two corpus statistics can:
- head rate: how often the word itself heads a noun phrase ("add the cinnamon," "with the tart.")
  among its uses after a determiner; nouns do this often, adjectives almost never;
- NPMI of the bigram: fixed phrases of adjective-like words ("olive oil", "black pepper") stick
  together far more than chance.
A modifier is part of the name when either is high. Both come from `sentences`, nothing by hand.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import duckdb

from lmcr.files import atomic_path

HEAD_RATE_MIN = 0.10  # nouns measured 0.10-0.49, adjectives/participles 0.00-0.08 (closing note)
NPMI_MIN = 0.65  # "black pepper" 0.75, "olive oil" 0.84; "salted water" 0.61, "melted butter" 0.52
MIN_DETERMINED = 20  # uses after a determiner before a head rate is trusted
MIN_BIGRAM = 5

_TOKENS = """
create temp table _cmp_tokens as
select list_filter(string_split_regex(lower(text), '[^a-z]+|([.,;])'), lambda x: x <> '') as w
from sentences where kind in ('instruction', 'ingredient') and (? = 'all' or corpus = ?)
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
with uni as (select w1 as w, count(*) as n from (select unnest(w) as w1 from _cmp_tokens) group by 1),
total as (select sum(n) as n from uni),
bi as (
    select w[i] as a, w[i + 1] as b, count(*) as n
    from (select w, unnest(range(1, len(w))) as i from _cmp_tokens)
    group by all having count(*) >= ?
)
select a || ' ' || b, ln(bi.n * total.n / (ua.n * ub.n)) / -ln(bi.n / total.n) as npmi
from bi, total join uni ua on ua.w = a join uni ub on ub.w = b
where a not in ('.', ',', ';') and b not in ('.', ',', ';')
"""


@dataclass
class Compounds:
    """Head rates of words and NPMI-strong bigrams; empty means "trust the tagger only"."""

    head_rates: dict[str, float] = field(default_factory=dict)
    strong_bigrams: frozenset[str] = frozenset()

    def joins(self, modifier: str, head: str) -> bool:
        """Whether `modifier head` is a fixed compound by the corpus statistics."""
        return (self.head_rates.get(modifier, 0.0) >= HEAD_RATE_MIN
                or f"{modifier} {head}" in self.strong_bigrams)

    def save(self, path: Path) -> None:
        with atomic_path(path) as tmp:
            tmp.write_text(json.dumps({"head_rates": self.head_rates, "strong_bigrams": sorted(self.strong_bigrams)}))

    @classmethod
    def load(cls, path: Path) -> Compounds:
        data = json.loads(Path(path).read_text("utf-8"))
        return cls(data["head_rates"], frozenset(data["strong_bigrams"]))


def learn_compounds(con: duckdb.DuckDBPyConnection, corpus: str = "all") -> Compounds:
    """Compute head rates and strong bigrams over the ingested sentences of a corpus setting."""
    con.execute(_TOKENS, [corpus, corpus])
    try:
        rates = {w: round(r, 4) for w, r in con.execute(_HEAD_RATES, [MIN_DETERMINED]).fetchall()
                 if r >= HEAD_RATE_MIN}
        bigrams = frozenset(b for b, npmi in con.execute(_STRONG_BIGRAMS, [MIN_BIGRAM]).fetchall()
                            if npmi >= NPMI_MIN)
    finally:
        con.execute("drop table _cmp_tokens")
    return Compounds(rates, bigrams)
