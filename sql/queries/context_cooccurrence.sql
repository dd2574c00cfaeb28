-- sentences (recipe steps, titles and ingredient lines, narrations, program steps) that hold each word,
-- that name each object phrase, and that do both: what the context term (lmcr/scorers/context_pmi.py) learns
-- from. A sentence is its unit: a purpose and the object it needs are named in one ("boil the pasta in a
-- pot"), where a whole recipe names every tool it uses for every purpose.
-- $phrases: a regex alternation of escaped, lowercase object phrases (longest first; the last word may
-- take -s or -es); $corpus: a corpus or 'all'; $min_sentences: words in fewer sentences are left out.
-- A sentence is (corpus, source, doc_id, sent_id): a document id is unique within its source.
-- Rows: (kind, object, word, n) with kind 'sentences' (n sentences), 'word', 'object' or 'pair'.
with units as (
    select corpus, source, doc_id, sent_id, lower(text) as t
    from sentences
    where $corpus = 'all' or corpus = $corpus
),
words as (
    select corpus, source, doc_id, sent_id, unnest(list_distinct(regexp_extract_all(t, '[a-z]+(?:''[a-z]+)?'))) as word
    from units
),
objects as (
    select corpus, source, doc_id, sent_id, unnest(list_distinct(regexp_extract_all(t, '\b(' || $phrases || ')(?:s|es)?\b', 1))) as object
    from units
),
word_sentences as (
    select word, count(*) as n from words group by word having count(*) >= $min_sentences
)
select 'sentences' as kind, null as object, null as word, count(*) as n from units
union all
select 'word', null, word, n from word_sentences
union all
select 'object', object, null, count(*) from objects group by object
union all
select 'pair', o.object, w.word, count(*)
from objects o join words w using (corpus, source, doc_id, sent_id) semi join word_sentences using (word)
group by all
order by all
