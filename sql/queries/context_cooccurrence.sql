-- documents (a recipe, a narrated video, a household program) that hold each word, that name each
-- object phrase, and that do both: what the context term (lmcr/context_pmi.py) learns from.
-- $phrases: a regex alternation of escaped, lowercase object phrases (longest first; the last word may
-- take -s or -es); $corpus: a corpus or 'all'; $min_docs: words in fewer documents are left out.
-- Rows: (kind, object, word, n) with kind 'docs' (n documents), 'word', 'object' or 'pair'.
with docs as (
    select corpus, doc_id, string_agg(lower(text), ' ') as t
    from sentences
    where $corpus = 'all' or corpus = $corpus
    group by all
),
words as (
    select corpus, doc_id, unnest(list_distinct(regexp_extract_all(t, '[a-z]+(?:''[a-z]+)?'))) as word
    from docs
),
objects as (
    select corpus, doc_id, unnest(list_distinct(regexp_extract_all(t, '\b(' || $phrases || ')(?:s|es)?\b', 1))) as object
    from docs
),
word_docs as (
    select word, count(*) as n from words group by word having count(*) >= $min_docs
)
select 'docs' as kind, null as object, null as word, count(*) as n from docs
union all
select 'word', null, word, n from word_docs
union all
select 'object', object, null, count(*) from objects group by object
union all
select 'pair', o.object, w.word, count(*)
from objects o join words w using (corpus, doc_id) semi join word_docs using (word)
group by all
order by all
