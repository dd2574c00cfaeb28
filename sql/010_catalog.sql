-- The catalog documents itself: a comment on every table, view and column (what `lmcr schema` prints),
-- and MTurk's text fields stored as the types they are. Each table comment starts with the stage that
-- writes it. Columns that read ambiguously (`position`, `source` vs `source_file`, `known`, spans, `item`)
-- are explained here rather than renamed, so queries written against earlier stores keep working.

-- MTurk writes times as 'Tue Nov 17 10:02:00 PST 2026' and rewards as '$0.30'. Loading converts with
-- these macros; a value they cannot read becomes NULL (the raw row stays in the results file).
create macro mturk_time(s) as timezone('UTC', try_strptime(s, '%a %b %d %H:%M:%S %Z %Y'));
create macro mturk_reward(s) as try_cast(ltrim(trim(s), '$') as decimal(9, 2));

alter table assignments alter submit_time set data type timestamp using mturk_time(submit_time);
alter table hits alter reward set data type decimal(9, 2) using mturk_reward(reward);

comment on table schema_migrations is 'store: one row per applied migration file of sql/ (append-only; a changed applied file is refused).';
comment on column schema_migrations.version is 'Number prefix of the migration file.';
comment on column schema_migrations.name is 'File name of the migration.';
comment on column schema_migrations.sha256 is 'SHA-256 of the file as applied.';
comment on column schema_migrations.applied_at is 'When it was applied (local time of the machine).';

comment on table ingested_files is 'ingest: one row per loaded input file with its record counts (records_in = records_loaded + records_quarantined).';
comment on column ingested_files.source_file is 'Path of the input file as given to `lmcr ingest`.';
comment on column ingested_files.sha256 is 'SHA-256 of the file content: with format and encoding, what makes a re-ingest a no-op.';
comment on column ingested_files.format is 'Adapter that read it: youcook2, recipe_json, mealmaster or feeding_america.';
comment on column ingested_files.corpus is 'Corpus the file belongs to: youcook2 or recipes.';
comment on column ingested_files.records_in is 'Records read (recipes, videos, XML documents).';
comment on column ingested_files.records_loaded is 'Records that became documents.';
comment on column ingested_files.records_quarantined is 'Records rejected into quarantine.';
comment on column ingested_files.documents is 'Documents loaded from the file.';
comment on column ingested_files.sentences is 'Sentences loaded from the file.';
comment on column ingested_files.words is 'Words in those sentences.';
comment on column ingested_files.loaded_at is 'When the file was loaded (local time).';
comment on column ingested_files.encoding is 'Text encoding forced with --encoding; empty when detected.';

comment on table documents is 'ingest: one row per recipe or video.';
comment on column documents.corpus is 'youcook2 or recipes.';
comment on column documents.source is 'Collection the document comes from, finer than the file: youcook2, web:<site> or json:<file> (recipe JSON), mealmaster:<file>, feeding_america:<book>.';
comment on column documents.doc_id is 'Identifier of the document, unique within (corpus, source).';
comment on column documents.title is 'Recipe title, if any.';
comment on column documents.category is 'Recipe category or YouCook2 recipe type, if any.';
comment on column documents.subset is 'YouCook2 split (training, validation) or the source''s own subset, if any.';
comment on column documents.url is 'Link to the original, if any.';
comment on column documents.source_file is 'The input file it was read from (ingested_files.source_file).';
comment on column documents.position is 'Where the document starts in source_file, 1-based: its line (Meal-Master, Feeding America XML) or record number (JSONL line, YouCook2 video, JSON file of a folder).';

comment on table sentences is 'ingest: one row per sentence of a document (instructions, ingredients, titles, comments).';
comment on column sentences.corpus is 'youcook2 or recipes.';
comment on column sentences.source is 'As documents.source.';
comment on column sentences.doc_id is 'The document (documents.doc_id).';
comment on column sentences.sent_id is 'Sentence number within the document, 0-based.';
comment on column sentences.kind is 'instruction, ingredient, title or comment.';
comment on column sentences.text is 'Normalised sentence text.';
comment on column sentences.n_words is 'Words in text.';
comment on column sentences.source_file is 'As documents.source_file.';
comment on column sentences.position is 'As documents.position: where the sentence''s document starts in source_file.';
comment on column sentences.seg_start is 'YouCook2 only: start of the video segment, seconds.';
comment on column sentences.seg_end is 'YouCook2 only: end of the video segment, seconds.';

comment on table quarantine is 'ingest and annotate ingest: records that failed validation, with the reason.';
comment on column quarantine.stage is 'Stage that rejected it: ingest or ratings.';
comment on column quarantine.corpus is 'Corpus of the input file (NULL for ratings).';
comment on column quarantine.source_file is 'The input file.';
comment on column quarantine.position is 'Where in source_file, 1-based: as documents.position (ingest) or the CSV line (ratings).';
comment on column quarantine.reason is 'Why it was rejected.';
comment on column quarantine.record is 'The rejected record (raw text or JSON), possibly truncated.';
comment on column quarantine.quarantined_at is 'When (local time).';

comment on table frames is 'frames: one row per predicate occurrence found by SRL in a sentence.';
comment on column frames.corpus is 'Corpus of the sentence.';
comment on column frames.doc_id is 'Document of the sentence.';
comment on column frames.sent_id is 'Sentence (sentences.sent_id).';
comment on column frames.frame_no is 'Number of the frame within the sentence, 0-based, in text order.';
comment on column frames.predicate is 'Verb lemma.';
comment on column frames.known is 'True for the 11 robot predicates (roles from the lexicon, missing roles kept as NULL values); false for generic frames of other verbs.';
comment on column frames.pred_start is 'Character offset of the verb in the sentence text, 0-based.';
comment on column frames.pred_end is 'Character offset just past the verb (exclusive).';
comment on column frames.ambiguous_role is 'Role a lone object of an alternating verb got by default, before role priors.';
comment on column frames.resolved_by_prior is 'True when learned role priors decided that role.';

comment on table frame_roles is 'frames: one row per role of a frame; a missing role of a robot predicate has a NULL value.';
comment on column frame_roles.corpus is 'As frames.corpus.';
comment on column frame_roles.doc_id is 'As frames.doc_id.';
comment on column frame_roles.sent_id is 'As frames.sent_id.';
comment on column frame_roles.frame_no is 'As frames.frame_no.';
comment on column frame_roles.role is 'Role name (Theme, Destination, Instrument, ... or a generic role).';
comment on column frame_roles.value is 'Head noun phrase filling the role, lemmatised; NULL when not stated.';
comment on column frame_roles.span_start is 'Character offset of the filler in the sentence text, 0-based; NULL when not stated.';
comment on column frame_roles.span_end is 'Character offset just past the filler (exclusive).';

comment on table frame_builds is 'frames: one row per build of the frame corpus (what was parsed, how fast).';
comment on column frame_builds.fingerprint is 'Hash of what the build depends on: ingested files, sentence kinds, shard size, spaCy model, SRL code, learned compounds.';
comment on column frame_builds.kinds is 'Sentence kinds parsed, comma-separated.';
comment on column frame_builds.shards is 'Worker shards parsed.';
comment on column frame_builds.sentences is 'Sentences parsed.';
comment on column frame_builds.words is 'Words parsed.';
comment on column frame_builds.frames is 'Frames found.';
comment on column frame_builds.known_frames is 'Frames of robot predicates.';
comment on column frame_builds.reparsed is 'Sentences re-parsed as commands (imperative prefix).';
comment on column frame_builds.reparse_kept is 'Re-parses whose frames were kept.';
comment on column frame_builds.wall_s is 'Wall-clock seconds of the build.';
comment on column frame_builds.words_per_s is 'Throughput, words per second.';
comment on column frame_builds.built_at is 'When (local time).';

comment on table lm_runs is 'train: one row per language-model training run.';
comment on column lm_runs.run_id is 'Random run identifier (12 hex digits), also in the checkpoint''s provenance.';
comment on column lm_runs.linearization is 'sentence or frame.';
comment on column lm_runs.corpus is 'Training corpus setting: youcook2, recipes or all.';
comment on column lm_runs.train_sequences is 'Training sequences.';
comment on column lm_runs.val_sequences is 'Validation sequences.';
comment on column lm_runs.vocab_size is 'Vocabulary size including special tokens.';
comment on column lm_runs.best_val_ppl is 'Best validation perplexity over the epochs.';
comment on column lm_runs.checkpoint is 'Folder of the published checkpoint.';
comment on column lm_runs.started_at is 'When (local time).';

comment on table lm_epochs is 'train: one row per epoch of a run.';
comment on column lm_epochs.run_id is 'The run (lm_runs.run_id).';
comment on column lm_epochs.epoch is 'Epoch number, 1-based.';
comment on column lm_epochs.train_ppl is 'Training perplexity (of the sampled objective when objective = sampled).';
comment on column lm_epochs.val_ppl is 'Validation perplexity, full softmax.';
comment on column lm_epochs.tokens_per_s is 'Training throughput, tokens per second.';
comment on column lm_epochs.seconds is 'Wall-clock seconds of the epoch.';
comment on column lm_epochs.device is 'cpu or cuda.';
comment on column lm_epochs.objective is 'full softmax or sampled softmax.';
comment on column lm_epochs.precision is 'bf16 (autocast) or fp32.';

comment on table rating_files is 'annotate ingest: one row per MTurk batch-results file loaded (items_in = items_loaded + items_quarantined + items_duplicate).';
comment on column rating_files.sha256 is 'SHA-256 of the file content; a changed file is a new one.';
comment on column rating_files.source_file is 'Path as given to `lmcr annotate ingest`.';
comment on column rating_files.layout is 'single (Input.verb) or multi (Input.verb_1 .. _N).';
comment on column rating_files.rows_in is 'CSV rows (assignments) read.';
comment on column rating_files.assignments_loaded is 'New assignments loaded.';
comment on column rating_files.assignments_duplicate is 'Identical re-downloads, ignored (their status is updated).';
comment on column rating_files.assignments_conflicting is 'Re-downloads with different answers: the stored assignment is flagged.';
comment on column rating_files.items_in is 'Rated items (slots) read.';
comment on column rating_files.items_loaded is 'Items loaded into ratings.';
comment on column rating_files.items_quarantined is 'Items rejected into quarantine.';
comment on column rating_files.items_duplicate is 'Items of duplicate or conflicting assignments.';
comment on column rating_files.loaded_at is 'When (local time).';

comment on table hits is 'annotate ingest: one row per MTurk HIT seen in a results file.';
comment on column hits.hit_id is 'MTurk HITId.';
comment on column hits.hit_type_id is 'MTurk HITTypeId.';
comment on column hits.title is 'HIT title shown to workers.';
comment on column hits.reward is 'Reward per assignment, US dollars.';
comment on column hits.max_assignments is 'Assignments requested per HIT.';
comment on column hits.source_file is 'Results file it was first seen in.';

comment on table workers is 'annotate ingest: one row per MTurk worker.';
comment on column workers.worker_id is 'MTurk WorkerId.';
comment on column workers.first_file is 'Results file the worker first appeared in.';

comment on table assignments is 'annotate ingest: one row per MTurk assignment (one worker doing one HIT).';
comment on column assignments.assignment_id is 'MTurk AssignmentId.';
comment on column assignments.hit_id is 'The HIT (hits.hit_id).';
comment on column assignments.worker_id is 'The worker (workers.worker_id).';
comment on column assignments.status is 'Submitted, Approved or Rejected; Rejected assignments are never aggregated.';
comment on column assignments.work_seconds is 'WorkTimeInSeconds.';
comment on column assignments.submit_time is 'SubmitTime, UTC.';
comment on column assignments.source_file is 'Results file it was loaded from.';
comment on column assignments.line is 'CSV line of the assignment in source_file, 1-based (header = line 1).';
comment on column assignments.content_sha256 is 'Hash of its answers: tells an identical re-download from a conflicting one.';
comment on column assignments.conflict is 'Why a later download of this assignment disagreed, else NULL.';

comment on table ratings is 'annotate ingest: one row per rated frame of an assignment.';
comment on column ratings.assignment_id is 'The assignment (assignments.assignment_id).';
comment on column ratings.item is 'Slot of the frame in the HIT: the N of Input.verb_N, 1-based (1 in the single layout).';
comment on column ratings.frame_id is 'Input.frame_id of the slot: identifies gold check items; NULL when the batch had none.';
comment on column ratings.verb is 'Predicate of the rated frame.';
comment on column ratings.role1 is 'First role name.';
comment on column ratings.arg1 is 'First role filler.';
comment on column ratings.role2 is 'Second role name.';
comment on column ratings.arg2 is 'Second role filler.';
comment on column ratings.sentence is 'The sentence the worker read.';
comment on column ratings.rating is 'Plausibility 1 (implausible) .. 5 (plausible).';

comment on table gold_items is 'annotate tasks: gold check items placed in a batch, with the range a careful worker answers.';
comment on column gold_items.frame_id is 'Input.frame_id of the gold item.';
comment on column gold_items.expected_min is 'Lowest acceptable rating.';
comment on column gold_items.expected_max is 'Highest acceptable rating.';
comment on column gold_items.batch is 'Batch name given to `lmcr annotate tasks --batch`.';

comment on table retrain_decisions is 'retrain: one row per scheduled retrain decision.';
comment on column retrain_decisions.decided_at is 'When (local time).';
comment on column retrain_decisions.setting is 'Checkpoint setting, e.g. sentence-all.';
comment on column retrain_decisions.inputs_sha256 is 'Hash of corpus files + frame build + rating files the decision saw.';
comment on column retrain_decisions.decision is 'promoted, kept or unchanged.';
comment on column retrain_decisions.reason is 'Why, in words.';
comment on column retrain_decisions.candidate is 'Version of the newly trained checkpoint.';
comment on column retrain_decisions.current is 'Version that was LATEST before.';
comment on column retrain_decisions.candidate_accuracy is 'Table I accuracy of the candidate on the ratings.';
comment on column retrain_decisions.current_accuracy is 'Table I accuracy of the current checkpoint.';
comment on column retrain_decisions.calibration is 'JSON of the completion calibration made for a promoted candidate.';

comment on view valid_ratings is 'Ratings that count: not rejected, not from a conflicting assignment.';
comment on view frame_ratings is 'Per rated frame: n, mean, median, std of valid ratings, gold items excluded.';
comment on view robot_fillers is 'One row per stated role value of a robot-predicate frame: what the count model counts.';
comment on column valid_ratings.assignment_id is 'As ratings.assignment_id.';
comment on column valid_ratings.item is 'As ratings.item.';
comment on column valid_ratings.frame_id is 'As ratings.frame_id.';
comment on column valid_ratings.verb is 'As ratings.verb.';
comment on column valid_ratings.role1 is 'As ratings.role1.';
comment on column valid_ratings.arg1 is 'As ratings.arg1.';
comment on column valid_ratings.role2 is 'As ratings.role2.';
comment on column valid_ratings.arg2 is 'As ratings.arg2.';
comment on column valid_ratings.sentence is 'As ratings.sentence.';
comment on column valid_ratings.rating is 'As ratings.rating.';
comment on column valid_ratings.worker_id is 'Worker of the assignment.';
comment on column valid_ratings.hit_id is 'HIT of the assignment.';
comment on column frame_ratings.verb is 'Predicate of the rated frame.';
comment on column frame_ratings.role1 is 'First role name.';
comment on column frame_ratings.arg1 is 'First role filler.';
comment on column frame_ratings.role2 is 'Second role name.';
comment on column frame_ratings.arg2 is 'Second role filler.';
comment on column frame_ratings.n is 'Valid ratings of the frame.';
comment on column frame_ratings.mean is 'Mean rating, 1..5.';
comment on column frame_ratings.median is 'Median rating.';
comment on column frame_ratings.std is 'Sample standard deviation (NULL for one rating).';
comment on column robot_fillers.corpus is 'As frames.corpus.';
comment on column robot_fillers.doc_id is 'As frames.doc_id.';
comment on column robot_fillers.sent_id is 'As frames.sent_id.';
comment on column robot_fillers.frame_no is 'As frames.frame_no.';
comment on column robot_fillers.predicate is 'One of the 11 robot predicates.';
comment on column robot_fillers.role is 'Role name.';
comment on column robot_fillers.value is 'Stated filler (never NULL here).';
