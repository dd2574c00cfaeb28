-- documents, sentences, words and quarantined records per corpus
with files as (
    select corpus,
           sum(records_in) as records_in,
           sum(records_loaded) as records_loaded,
           sum(records_quarantined) as quarantined,
           sum(documents) as documents,
           sum(sentences) as sentences,
           sum(words) as words
    from ingested_files
    group by corpus
)
select corpus, records_in, records_loaded, quarantined, documents, sentences, words
from files
order by corpus
