-- Retraining by kind of change (lmcr/retrain.py): what changed since the setting's last decision, what
-- was done about it, and what that cost.
alter table retrain_decisions add column change varchar;
alter table retrain_decisions add column action varchar;
alter table retrain_decisions add column seconds double;
alter table retrain_decisions add column tokens_trained bigint;
alter table retrain_decisions add column inputs_json varchar;

comment on column retrain_decisions.decision is 'promoted, kept, unchanged or recalibrated (new ratings only: the current checkpoint stays and is calibrated again).';
comment on column retrain_decisions.change is 'What changed since the last decision: first, unchanged, ratings, corpus_added, corpus_changed or corpus_removed (the strongest corpus change, with or without new ratings).';
comment on column retrain_decisions.action is 'What was done: none, recalibrate, warm_start (the current LM continued on the new text with a replay of the old) or full (trained from random weights).';
comment on column retrain_decisions.seconds is 'Wall seconds of the decision: training, gate and calibration (not ingest or frames).';
comment on column retrain_decisions.tokens_trained is 'Tokens the training steps went through (0 when nothing was trained).';
comment on column retrain_decisions.inputs_json is 'JSON of the inputs the decision saw: corpus files (path -> sha256), rating file hashes, frame build; the next decision compares against it.';
