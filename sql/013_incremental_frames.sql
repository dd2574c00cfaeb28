-- Incremental frame builds (lmcr/frame_corpus/build.py): parse results are kept per text and parser
-- setup, so a build parses only the texts that are new to its setup; it records which setup, whether it
-- kept the last build's compounds and first words, and what it parsed.
alter table frame_builds add column parser_setup varchar;
alter table frame_builds add column resources_reused boolean;
alter table frame_builds add column texts bigint;
alter table frame_builds add column texts_parsed bigint;
alter table frame_builds add column words_parsed bigint;

comment on column frame_builds.fingerprint is 'Hash of what the build depends on: ingested files, sentence kinds, shard size, spaCy model, first-word sample, SRL code and the parser setup.';
comment on column frame_builds.shards is 'Worker shards this build parsed (0 when every text was parsed before).';
comment on column frame_builds.sentences is 'Sentences of the frame corpus: every sentence of the kinds, whether its text was parsed by this build or before.';
comment on column frame_builds.words is 'Words of those sentences.';
comment on column frame_builds.reparsed is 'Texts this build re-parsed as commands (imperative prefix).';
comment on column frame_builds.reparse_kept is 'Of those re-parses, the ones whose frames were kept.';
comment on column frame_builds.wall_s is 'Wall-clock seconds of the build up to the load: resources, export and parsing.';
comment on column frame_builds.words_per_s is 'Throughput: words_parsed per wall-clock second.';
comment on column frame_builds.parser_setup is 'Hash of the parser setup the frames come from: SRL code, spaCy model, learned compounds and first-word table, and the kinds and sample these were learned from; staging/frames/parsed/ keeps its parsed texts under the hash''s first 16 characters.';
comment on column frame_builds.resources_reused is 'True when the build kept the last build''s compounds and first-word table (few texts new to them: lmcr/frame_corpus/config.py REUSE_SHARE), false when it learned them anew and so parsed every text.';
comment on column frame_builds.texts is 'Distinct sentence texts of the frame corpus (a text is parsed once, whatever its number of sentences).';
comment on column frame_builds.texts_parsed is 'Distinct texts this build parsed: those no earlier build parsed under its parser setup.';
comment on column frame_builds.words_parsed is 'Words of the texts parsed (each text once).';
