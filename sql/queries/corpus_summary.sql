-- documents, sentences, words and quarantined records per corpus
with files as (
    select corpus,
           sum(records_in)::bigint as records_in,
           sum(records_loaded)::bigint as records_loaded,
           sum(records_quarantined)::bigint as quarantined,
           sum(documents)::bigint as documents,
           sum(sentences)::bigint as sentences,
           sum(words)::bigint as words
    from ingested_files
    group by corpus
)
select corpus, records_in, records_loaded, quarantined, documents, sentences, words
from files
order by corpus
