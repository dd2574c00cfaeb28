-- Household corpora (EPIC-KITCHENS narrations, VirtualHome programs): a third corpus and two adapters.
-- Only the catalog changes: the tables already take any corpus and format name.
comment on column ingested_files.format is 'Adapter that read it: youcook2, recipe_json, mealmaster, feeding_america, epic_kitchens or virtualhome.';
comment on column ingested_files.corpus is 'Corpus the file belongs to: youcook2, recipes or household.';
comment on column documents.corpus is 'youcook2, recipes or household.';
comment on column documents.source is 'Collection the document comes from, finer than the file: youcook2, web:<site> or json:<file> (recipe JSON), mealmaster:<file>, feeding_america:<book>, epic_kitchens (a video), virtualhome (a program).';
comment on column sentences.corpus is 'youcook2, recipes or household.';
comment on column lm_runs.corpus is 'Training corpus setting: youcook2, recipes, household or all.';
comment on column documents.category is 'Recipe category, YouCook2 recipe type or EPIC-KITCHENS participant, if any.';
comment on column documents.subset is 'YouCook2 split (training, validation), EPIC-KITCHENS release (epic-100, epic-55) or the source''s own subset, if any.';
