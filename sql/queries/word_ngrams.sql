-- word n-grams of the corpus sentences (1 to $max_words words), counted per corpus: the words are the
-- runs of [a-z0-9_] in the lowercased text, the words a phrase scan's \b bounds (phrase_counts.sql)
with words as (
    select corpus, regexp_extract_all(lower(text), '[a-z0-9_]+') as w
    from sentences
),
positions as (
    select corpus, w, unnest(generate_series(1, len(w))) as i
    from words
)
select corpus, array_to_string(w[i:i + k - 1], ' ') as ngram, count(*) as n
from positions, range(1, cast($max_words as integer) + 1) as sizes(k)
where i + k - 1 <= len(w)
group by all
