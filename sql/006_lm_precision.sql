-- Arithmetic precision of each training epoch: 'bf16' (autocast on hardware that multiplies bf16
-- natively) or 'fp32'. Epochs recorded before this migration were all fp32.
alter table lm_epochs add column precision varchar not null default 'fp32';
