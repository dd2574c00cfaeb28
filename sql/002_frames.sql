-- Verb-frame corpora: one row per predicate occurrence, one per role of it (missing roles of the
-- robot predicates kept with a null value), and one per build of the corpus.
create table frames (
    corpus varchar not null,
    doc_id varchar not null,
    sent_id integer not null,
    frame_no integer not null,
    predicate varchar not null,
    known boolean not null,
    pred_start integer not null,
    pred_end integer not null,
    ambiguous_role varchar,
    resolved_by_prior boolean not null default false
);

create table frame_roles (
    corpus varchar not null,
    doc_id varchar not null,
    sent_id integer not null,
    frame_no integer not null,
    role varchar not null,
    value varchar,
    span_start integer,
    span_end integer
);

create table frame_builds (
    fingerprint varchar primary key,
    kinds varchar not null,
    shards integer not null,
    sentences bigint not null,
    words bigint not null,
    frames bigint not null,
    known_frames bigint not null,
    reparsed bigint not null,
    reparse_kept bigint not null,
    wall_s double not null,
    words_per_s double not null,
    built_at timestamp not null default current_timestamp
);
