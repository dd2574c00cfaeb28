-- fillers expressed together in one robot-predicate frame, both orders ($corpus: a corpus name or 'all')
with filled as (
    select f.corpus, f.doc_id, f.sent_id, f.frame_no, f.predicate, r.role, r.value
    from frames f
    join frame_roles r using (corpus, doc_id, sent_id, frame_no)
    where f.known
      and r.value is not null
      and ($corpus = 'all' or f.corpus = $corpus)
)
select a.predicate, a.role as given_role, a.value as given_value, b.role, b.value, count(*) as n
from filled a
join filled b using (corpus, doc_id, sent_id, frame_no)
where a.role <> b.role
group by all
order by all
