-- Language-model training runs and their per-epoch metrics.
create table lm_runs (
    run_id varchar primary key,
    linearization varchar not null,
    corpus varchar not null,
    train_sequences bigint not null,
    val_sequences bigint not null,
    vocab_size integer not null,
    best_val_ppl double,
    checkpoint varchar,
    started_at timestamp not null default current_timestamp
);

create table lm_epochs (
    run_id varchar not null,
    epoch integer not null,
    train_ppl double not null,
    val_ppl double not null,
    tokens_per_s double not null,
    seconds double not null,
    device varchar not null,
    objective varchar not null, -- 'full' softmax or 'sampled' (then train_ppl is the sampled objective's)
    primary key (run_id, epoch)
);
