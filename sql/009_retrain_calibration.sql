-- The completion calibration made for a promoted candidate (JSON: method -> temperature, threshold,
-- fingerprint), so `lmcr complete` after a promotion uses a calibration of the promoted checkpoint.
alter table retrain_decisions add column calibration varchar;
