-- The text encoding a file was decoded with ('' = detected): part of what makes a re-ingest a no-op,
-- so re-ingesting an unchanged file with another --encoding replaces its rows instead of doing nothing.
alter table ingested_files add column encoding varchar not null default '';
