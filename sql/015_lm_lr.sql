-- The learning rate each epoch ended at: training decays it linearly over its last epochs
-- (lmcr/lm/hyperparams.py, TrainConfig.decay_epochs). Epochs recorded before this migration have none.
alter table lm_epochs add column lr_end double;

comment on column lm_epochs.lr_end is 'Adam learning rate at the epoch''s last step (the rate decays linearly over the last epochs of a run).';
comment on column lm_epochs.val_ppl is 'Validation perplexity, full softmax, computed in the epoch''s precision (the loss accumulated in fp32).';
