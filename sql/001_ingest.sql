-- Ingested corpus: one row per input file, per document, per sentence; rejected records go to quarantine.
create table ingested_files (
    source_file varchar primary key,
    sha256 varchar not null,
    format varchar not null,
    corpus varchar not null,
    records_in integer not null,
    records_loaded integer not null,
    records_quarantined integer not null,
    documents integer not null,
    sentences integer not null,
    words bigint not null,
    loaded_at timestamp not null default current_timestamp
);

create table documents (
    corpus varchar not null,
    source varchar not null,
    doc_id varchar not null,
    title varchar,
    category varchar,
    subset varchar,
    url varchar,
    source_file varchar not null,
    position integer not null
);

create table sentences (
    corpus varchar not null,
    source varchar not null,
    doc_id varchar not null,
    sent_id integer not null,
    kind varchar not null,
    text varchar not null,
    n_words integer not null,
    source_file varchar not null,
    position integer not null,
    seg_start double,
    seg_end double
);

create table quarantine (
    stage varchar not null,
    corpus varchar,
    source_file varchar not null,
    position integer,
    reason varchar not null,
    record varchar,
    quarantined_at timestamp not null default current_timestamp
);
