-- Crowd plausibility ratings (MTurk batch results): files, HITs, workers, assignments, one row per rated item.
-- Rejected assignments are stored but never aggregated; a conflicting re-download flags its assignment.
create table rating_files (
    sha256 varchar primary key,       -- a file is known by its content; a changed file is a new one
    source_file varchar not null,
    layout varchar not null,          -- 'single' (Input.verb) or 'multi' (Input.verb_1 .. _N)
    rows_in integer not null,
    assignments_loaded integer not null,
    assignments_duplicate integer not null, -- identical re-downloads, ignored
    assignments_conflicting integer not null,
    items_in integer not null,
    items_loaded integer not null,
    items_quarantined integer not null,
    items_duplicate integer not null,
    loaded_at timestamp not null default current_timestamp
);

create table hits (
    hit_id varchar primary key,
    hit_type_id varchar,
    title varchar,
    reward varchar,
    max_assignments integer,
    source_file varchar not null
);

create table workers (
    worker_id varchar primary key,
    first_file varchar not null
);

create table assignments (
    assignment_id varchar primary key,
    hit_id varchar not null,
    worker_id varchar not null,
    status varchar not null,
    work_seconds integer,
    submit_time varchar,
    source_file varchar not null,
    line integer not null,
    content_sha256 varchar not null,
    conflict varchar                  -- why a later download of this assignment disagreed, else null
);

create table ratings (
    assignment_id varchar not null,
    item integer not null,
    frame_id varchar,
    verb varchar not null,
    role1 varchar not null,
    arg1 varchar not null,
    role2 varchar not null,
    arg2 varchar not null,
    sentence varchar,
    rating integer not null check (rating between 1 and 5),
    primary key (assignment_id, item)
);

-- Gold check items written by `lmcr annotate tasks`: the answer a careful worker gives.
create table gold_items (
    frame_id varchar primary key,
    expected_min integer not null,
    expected_max integer not null,
    batch varchar not null
);

-- Ratings that count: not rejected, not from a conflicting assignment.
create view valid_ratings as
select r.*, a.worker_id, a.hit_id
from ratings r
join assignments a using (assignment_id)
where a.status <> 'Rejected' and a.conflict is null;

-- Per frame: n, mean, median, std over valid ratings (gold check items excluded).
create view frame_ratings as
with rated as (
    select * from valid_ratings where frame_id is null or frame_id not in (select frame_id from gold_items)
)
select verb, role1, arg1, role2, arg2,
       count(*) as n, avg(rating) as mean, median(rating) as median, stddev_samp(rating) as std
from rated
group by verb, role1, arg1, role2, arg2;

-- The paper's lambda split: positive if mean > 5 - lambda, negative if mean < 1 + lambda.
create macro frame_labels(lam) as table
select *,
       case when mean > 5 - lam then 'positive' when mean < 1 + lam then 'negative' else 'ambiguous' end as label
from frame_ratings;
