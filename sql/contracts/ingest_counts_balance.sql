-- counts in = loaded + quarantined for every ingested file, and the stored rows match the recorded counts
with stored as (
    select source_file, count(*) as n_sentences from sentences group by source_file
),
quarantined as (
    select source_file, count(*) as n_rejected from quarantine where stage = 'ingest' group by source_file
)
select f.source_file
from ingested_files f
left join stored s using (source_file)
left join quarantined q using (source_file)
where f.records_in <> f.records_loaded + f.records_quarantined
   or coalesce(s.n_sentences, 0) <> f.sentences
   or coalesce(q.n_rejected, 0) <> f.records_quarantined
