-- fillers expressed together in one robot-predicate frame, both orders ($corpus: a corpus name or 'all')
with filled as (
    select * from robot_fillers where $corpus = 'all' or corpus = $corpus
)
select a.predicate, a.role as given_role, a.value as given_value, b.role, b.value, count(*) as n
from filled a
join filled b using (corpus, doc_id, sent_id, frame_no)
where a.role <> b.role
group by all
order by all
