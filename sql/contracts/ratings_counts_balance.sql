-- items in = loaded + quarantined + duplicate for every rating file path, and stored rows match the counts
with files as (
    select source_file, sum(items_in) as items_in, sum(items_loaded) as items_loaded,
           sum(items_quarantined) as items_quarantined, sum(items_duplicate) as items_duplicate
    from rating_files group by source_file
),
stored as (
    select a.source_file, count(*) as n from ratings r join assignments a using (assignment_id) group by 1
),
quarantined as (
    select source_file, count(*) as n from quarantine where stage = 'ratings' group by 1
)
select f.source_file
from files f
left join stored s using (source_file)
left join quarantined q using (source_file)
where f.items_in <> f.items_loaded + f.items_quarantined + f.items_duplicate
   or coalesce(s.n, 0) <> f.items_loaded
   or coalesce(q.n, 0) <> f.items_quarantined
