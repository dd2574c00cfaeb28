-- how often each value fills each role of each robot predicate ($corpus: a corpus name or 'all')
select f.predicate, r.role, r.value, count(*) as n
from frames f
join frame_roles r using (corpus, doc_id, sent_id, frame_no)
where f.known
  and r.value is not null
  and ($corpus = 'all' or f.corpus = $corpus)
group by all
order by all
