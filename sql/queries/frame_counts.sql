-- frames per corpus and robot predicate, with how many have each role expressed
with known as (
    select f.corpus, f.predicate, f.doc_id, f.sent_id, f.frame_no,
           count(r.value) as roles_expressed
    from frames f
    join frame_roles r using (corpus, doc_id, sent_id, frame_no)
    where f.known
    group by all
)
select corpus, predicate, count(*) as frames,
       count(*) filter (where roles_expressed = 2) as complete,
       count(*) filter (where roles_expressed = 1) as one_role,
       count(*) filter (where roles_expressed = 0) as no_role
from known
group by all
order by corpus, predicate
