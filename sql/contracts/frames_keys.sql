-- frame keys are unique, every role row belongs to a frame, robot predicates have exactly two roles
with dupes as (
    select doc_id, sent_id, frame_no from frames group by all having count(*) > 1
),
orphans as (
    select r.doc_id, r.sent_id, r.frame_no from frame_roles r
    anti join frames f using (corpus, doc_id, sent_id, frame_no)
),
known_roles as (
    select f.doc_id, f.sent_id, f.frame_no
    from frames f left join frame_roles r using (corpus, doc_id, sent_id, frame_no)
    where f.known
    group by all
    having count(r.role) <> 2
)
select *, 'duplicate frame' as problem from dupes
union all select *, 'role without frame' from orphans
union all select *, 'robot predicate without its two roles' from known_roles
