-- One row per role value stated in a frame of a robot predicate: what the count model
-- (lmcr/scorers/frame_counts.py, queries frame_fillers and frame_filler_pairs) counts.
create view robot_fillers as
select f.corpus, f.doc_id, f.sent_id, f.frame_no, f.predicate, r.role, r.value
from frames f
join frame_roles r using (corpus, doc_id, sent_id, frame_no)
where f.known
  and r.value is not null;
