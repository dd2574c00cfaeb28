-- occurrences of filler phrases in the corpus sentences: $phrases is a regex alternation of escaped,
-- lowercase phrases (longest first); a phrase's last word may take -s or -es; $corpus: a corpus or 'all'
select phrase, count(*) as n
from (
    select unnest(regexp_extract_all(lower(text), '\b(' || $phrases || ')(?:s|es)?\b', 1)) as phrase
    from sentences
    where $corpus = 'all' or corpus = $corpus
)
group by all
order by all
