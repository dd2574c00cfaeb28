-- Scheduled retraining: what the inputs were, how candidate and current scored, and the decision.
create table retrain_decisions (
    decided_at timestamp not null default current_timestamp,
    setting varchar not null,
    inputs_sha256 varchar not null,   -- corpus files + frame build + rating files
    decision varchar not null,        -- 'promoted' | 'kept' | 'unchanged'
    reason varchar not null,
    candidate varchar,
    current varchar,
    candidate_accuracy double,
    current_accuracy double
);
