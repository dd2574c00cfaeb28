-- Predicates learned from the frame corpus (lmcr/frame_corpus/predicates.py): every verb and phrasal
-- verb with enough evidence, its roles and which slot of its generic frames fills each. The count model
-- reads the frames of learned predicates through robot_fillers, their slots named by role.
create table learned_predicates (
    predicate varchar primary key,
    base varchar not null,
    particle varchar,
    frames bigint not null,
    role1 varchar not null,
    role2 varchar not null,
    role2_rate double not null,
    theme_prep varchar,
    sentence varchar not null,
    build varchar not null
);

create table learned_predicate_slots (
    predicate varchar not null,
    slot varchar not null,
    role varchar not null,
    primary key (predicate, slot)
);

comment on table learned_predicates is 'frames: one row per predicate learned from the frame corpus of the last build (the hand-written lexicon''s eleven are not listed).';
comment on column learned_predicates.predicate is 'Verb lemma with its particle where it has one: put away, throw out, bake.';
comment on column learned_predicates.base is 'The verb lemma alone: put.';
comment on column learned_predicates.particle is 'Its particle (away, out, up), if any.';
comment on column learned_predicates.frames is 'Frames of it in the corpus: its evidence.';
comment on column learned_predicates.role1 is 'First role (always Theme), as in rating files.';
comment on column learned_predicates.role2 is 'Second role: the most often stated besides the Theme, what a request leaves missing when unsaid.';
comment on column learned_predicates.role2_rate is 'Share of its frames that state role2 (smoothed towards the base verb for a phrasal verb).';
comment on column learned_predicates.theme_prep is 'Preposition that introduces the Theme of a prepositional verb (dispose of it), if any.';
comment on column learned_predicates.sentence is 'Template the sentence LM scores: put {Theme} away into the {Destination}.';
comment on column learned_predicates.build is 'Fingerprint of the frame build it was learned from.';
comment on table learned_predicate_slots is 'frames: which slot of a learned predicate''s generic frames (the object as Theme, or a preposition) fills which role.';
comment on column learned_predicate_slots.predicate is 'The learned predicate.';
comment on column learned_predicate_slots.slot is 'Theme (the direct object) or the preposition as stored in frame_roles.role.';
comment on column learned_predicate_slots.role is 'The role it fills: Theme, Destination, Instrument or Source.';

create or replace view robot_fillers as
select f.corpus, f.doc_id, f.sent_id, f.frame_no, f.predicate, r.role, r.value
from frames f
join frame_roles r using (corpus, doc_id, sent_id, frame_no)
where f.known
  and r.value is not null
union all
select f.corpus, f.doc_id, f.sent_id, f.frame_no, f.predicate, s.role, r.value
from frames f
join frame_roles r using (corpus, doc_id, sent_id, frame_no)
join learned_predicate_slots s on s.predicate = f.predicate and s.slot = r.role
where not f.known
  and r.value is not null;
comment on view robot_fillers is 'One row per role value stated in a frame of a robot predicate, hand-written or learned (a learned one''s slots named by role): what the count model counts.';
comment on column robot_fillers.corpus is 'As frames.corpus.';
comment on column robot_fillers.doc_id is 'As frames.doc_id.';
comment on column robot_fillers.sent_id is 'As frames.sent_id.';
comment on column robot_fillers.frame_no is 'As frames.frame_no.';
comment on column robot_fillers.predicate is 'A robot predicate: one of the hand-written eleven or a learned one (learned_predicates).';
comment on column robot_fillers.role is 'Role name.';
comment on column robot_fillers.value is 'Stated filler (never NULL here).';
