# Every job a user runs. `make run` and `make test` work on a fresh machine with only Python:
# they create .venv and install the project into it first.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
INSTALLED := $(VENV)/.installed
OUT ?= runs
# The exact versions `make run` and `make test` install (pyproject.toml keeps ranges for people
# installing the package into their own environment); `make lock` regenerates it.
LOCK := constraints.txt

.PHONY: install install-rl lock run test test-slow lint format bench voice-model experiment compare video replicate replicate-diva comparison comparison-diva contact-ablations contact-ladder contact-unbundled held-pose-returns contact-factorial ablations rl-baseline rl-control rl-race clean

$(INSTALLED): pyproject.toml $(LOCK)
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade --constraint $(LOCK) pip
	$(BIN)/python -m pip install --quiet --constraint $(LOCK) -e ".[dev]"
	touch $(INSTALLED)

## lock: regenerate constraints.txt: the newest versions pyproject.toml's ranges allow today,
## resolved by pip in a fresh virtual environment of this Python (the dev and cluster extras
## installed; the rl extra resolved without installing)
lock:
	rm -rf .lock-venv
	$(PYTHON) -m venv .lock-venv
	.lock-venv/bin/python -m pip install --quiet --upgrade pip
	.lock-venv/bin/python -m pip install --quiet ".[dev,cluster]"
	{ echo "# Exact versions for make run / make test, written by make lock on $$(date -u +%Y-%m-%d)"; \
	  echo "# with $$(.lock-venv/bin/python -c 'import platform; print(platform.python_implementation(), platform.python_version(), platform.machine())')."; \
	  .lock-venv/bin/python -m pip freeze --all --exclude playroom; } > $(LOCK).new
	.lock-venv/bin/python -m pip install --quiet --dry-run --ignore-installed \
		--extra-index-url $(TORCH_INDEX) --report .lock-venv/rl.json --constraint $(LOCK).new \
		".[rl]"
	{ echo "# The rl extra's own (make test-slow): resolved by make lock against the versions above,"; \
	  echo "# without installing them (pip install --dry-run --report); torch's CPU build, from"; \
	  echo "# TORCH_INDEX (Makefile): the default one brings gigabytes of CUDA libraries."; \
	  .lock-venv/bin/python .ci/lock_extra.py .lock-venv/rl.json $(LOCK).new; } >> $(LOCK).new
	mv $(LOCK).new $(LOCK)
	rm -rf .lock-venv

install: $(INSTALLED)

DEMO := $(OUT)/demo

## run: the main job: the demo batch (both backends), its report and the comparison
run: experiment
	$(BIN)/playroom compare $(DEMO) $(DEMO) --out $(OUT)/compare

## experiment: the demo profile's batch and its report
experiment: $(INSTALLED)
	$(BIN)/playroom batch --profile demo --out $(DEMO)
	$(BIN)/playroom report $(DEMO)

## compare: the demo profile's two backends and their comparison
compare: $(INSTALLED)
	$(BIN)/playroom batch --profile demo --out $(DEMO)
	$(BIN)/playroom compare $(DEMO) $(DEMO) --out $(OUT)/compare

## video: the highlights of the demo batch's first physical trial
video: $(INSTALLED)
	$(BIN)/playroom batch --profile demo --out $(DEMO)
	$(BIN)/playroom render $(DEMO)/physical-random-seed0000 --highlights --out $(OUT)/highlights.mp4

## replicate: the replication profile (kinematic, study preset, 100 seeds x 80000) and its report;
## rerunning resumes where it stopped
replicate: $(INSTALLED)
	$(BIN)/playroom batch --profile replication --out $(OUT)/replication
	$(BIN)/playroom report $(OUT)/replication

## replicate-diva: the replication with the study's vocal tract, DIVA (the replication-diva
## profile); needs DIVA's data installed once: `$(BIN)/playroom voice-data diva PATH`
replicate-diva: $(INSTALLED)
	$(BIN)/playroom batch --profile replication-diva --out $(OUT)/replication-diva
	$(BIN)/playroom report $(OUT)/replication-diva

## comparison: both backends at the study's scale per trial (the comparison profile: 16 seeds x
## 80000 each, study preset) and their comparison page; about an hour on 2 cores, resumes
comparison: $(INSTALLED)
	$(BIN)/playroom batch --profile comparison --out $(OUT)/comparison
	$(BIN)/playroom compare $(OUT)/comparison $(OUT)/comparison --out $(OUT)/comparison-report

## comparison-diva: both backends with the study's vocal tract, DIVA, at the study's scale (the
## comparison-diva profile: 64 seeds x 80000 each, study preset) and their comparison page, its
## per-trial data (comparison-trials.csv) copied into docs/data/ (docs/comparison.md quotes it);
## needs DIVA's data (`playroom voice-data diva PATH`); hours on 2 cores, resumes
comparison-diva: $(INSTALLED)
	$(BIN)/playroom batch --profile comparison-diva --out $(OUT)/comparison-diva
	$(BIN)/playroom compare $(OUT)/comparison-diva $(OUT)/comparison-diva \
		--out $(OUT)/comparison-diva-report
	mkdir -p docs/data
	cp $(OUT)/comparison-diva-report/comparison-trials.csv docs/data/comparison-diva-trials.csv

## contact-ablations: each switch of experiments/batches/contact-ablations/ on the physical
## backend with DIVA (32 seeds x 80000), against the same seeds of comparison-diva's physical
## trials (`playroom ablations`), its per-trial data copied into docs/data/
CONTACT_ABLATIONS := $(basename $(notdir $(wildcard experiments/batches/contact-ablations/*.json)))
contact-ablations: comparison-diva
	for name in $(CONTACT_ABLATIONS); do \
		$(BIN)/playroom batch --config experiments/batches/contact-ablations/$$name.json \
			--out $(OUT)/contact-ablation-$$name || exit 1; \
	done
	$(BIN)/playroom ablations $(OUT)/comparison-diva \
		$(addprefix $(OUT)/contact-ablation-,$(CONTACT_ABLATIONS)) --out $(OUT)/contact-ablations
	mkdir -p docs/data
	cp $(OUT)/contact-ablations/ablations-trials.csv docs/data/contact-ablations-trials.csv

## contact-ladder: the rungs from the study's kinematic rules to the physical backend, one
## rule changed per rung (experiments/batches/contact-ladder/NN-name.json, 32 seeds x 80000 with
## DIVA, every agent tested in both worlds; rungs 0 and 5 are comparison-diva's halves); a
## rung that is a contact ablation (the same batch) runs into that ablation's directory. Then
## `playroom ladder`: each step (its rule given the rules before it) paired by seed, with the
## paired t's and the signed-rank p, the cross-evaluation's split, Holm over the page's declared
## family, a completeness check (ladder.md/.csv/.json/.png, ladder-trials.csv, copied into
## docs/data/). Resumes
CONTACT_LADDER := $(basename $(notdir $(wildcard experiments/batches/contact-ladder/*.json)))
contact-ladder: comparison-diva
	for rung in $(CONTACT_LADDER); do \
		name=$${rung#*-}; out=$(OUT)/contact-ladder-$$rung; \
		if [ -f experiments/batches/contact-ablations/$$name.json ]; then \
			out=$(OUT)/contact-ablation-$$name; fi; \
		$(BIN)/playroom batch --config experiments/batches/contact-ladder/$$rung.json \
			--out $$out || exit 1; \
	done
	$(BIN)/playroom ladder kinematic=$(OUT)/comparison-diva:kinematic \
		held-stick-catch=$(OUT)/contact-ladder-01-held-stick-catch \
		servo-arm=$(OUT)/contact-ladder-02-servo-arm \
		contact-aligned=$(OUT)/contact-ladder-03-contact-aligned \
		no-push=$(OUT)/contact-ablation-no-push \
		physical=$(OUT)/comparison-diva:physical \
		--beside settle=$(OUT)/contact-ablation-settle --out $(OUT)/contact-ladder
	mkdir -p docs/data
	cp $(OUT)/contact-ladder/ladder-trials.csv docs/data/contact-ladder-trials.csv

## contact-unbundled: after `make contact-ladder`, the ladder's contact step in four rungs
## (experiments/batches/contact-unbundled/*.json, 32 seeds x 80000 with DIVA, both eval worlds:
## clear placements, the contact's reach alone, obstruction; then the ladder's contact-aligned
## rung, whose step is the caregiver's welded carrying), then `playroom ladder` of the whole
## ladder with them into $(OUT)/contact-unbundled, its per-trial data copied into docs/data/.
## Resumes
CONTACT_UNBUNDLED := $(basename $(notdir $(wildcard experiments/batches/contact-unbundled/*.json)))
contact-unbundled: contact-ladder
	for rung in $(CONTACT_UNBUNDLED); do \
		$(BIN)/playroom batch --config experiments/batches/contact-unbundled/$$rung.json \
			--out $(OUT)/contact-unbundled-$$rung || exit 1; \
	done
	$(BIN)/playroom ladder kinematic=$(OUT)/comparison-diva:kinematic \
		held-stick-catch=$(OUT)/contact-ladder-01-held-stick-catch \
		servo-arm=$(OUT)/contact-ladder-02-servo-arm \
		clear-placements=$(OUT)/contact-unbundled-01-clear-placements \
		contact-reach=$(OUT)/contact-unbundled-02-contact-reach \
		obstruction=$(OUT)/contact-unbundled-03-obstruction \
		contact-aligned=$(OUT)/contact-ladder-03-contact-aligned \
		no-push=$(OUT)/contact-ablation-no-push \
		physical=$(OUT)/comparison-diva:physical \
		--beside settle=$(OUT)/contact-ablation-settle --out $(OUT)/contact-unbundled
	mkdir -p docs/data
	cp $(OUT)/contact-unbundled/ladder-trials.csv docs/data/contact-unbundled-trials.csv

## held-pose-returns: the ladder's held-pose step with the stick returned at the contact limit
## on both sides (experiments/batches/held-pose-returns/, 32 seeds), its two-rung page, its
## per-trial data copied into docs/data/
held-pose-returns: $(INSTALLED)
	for side in aligned touch; do \
		$(BIN)/playroom batch --config experiments/batches/held-pose-returns/$$side.json \
			--out $(OUT)/held-pose-returns-$$side || exit 1; \
	done
	$(BIN)/playroom ladder aligned=$(OUT)/held-pose-returns-aligned \
		touch=$(OUT)/held-pose-returns-touch --out $(OUT)/held-pose-returns
	mkdir -p docs/data
	cp $(OUT)/held-pose-returns/ladder-trials.csv docs/data/held-pose-returns-trials.csv

## contact-factorial: after `make contact-ladder`, the cells the ladder lacks of three 2 x 2
## designs (experiments/batches/contact-factorial/*.json, 16 seeds x 80000 with DIVA), then
## `playroom factorial` of each: held pose x pushing, catch rule x servo arm, catch rule x the
## contact's catch distance, into $(OUT)/contact-factorial-*, each page's per-trial data copied
## into docs/data/. Resumes
CONTACT_FACTORIAL := $(basename $(notdir $(wildcard experiments/batches/contact-factorial/*.json)))
contact-factorial: contact-ladder
	for cell in $(CONTACT_FACTORIAL); do \
		$(BIN)/playroom batch --config experiments/batches/contact-factorial/$$cell.json \
			--out $(OUT)/contact-factorial-$$cell || exit 1; \
	done
	$(BIN)/playroom factorial aligned=$(OUT)/contact-ladder-03-contact-aligned \
		touch=$(OUT)/contact-ablation-no-push aligned-push=$(OUT)/contact-factorial-aligned-push \
		physical=$(OUT)/comparison-diva:physical --factors "held pose of the touch" pushing \
		--out $(OUT)/contact-factorial-held-pose-pushing
	$(BIN)/playroom factorial kinematic=$(OUT)/comparison-diva:kinematic \
		held-stick-catch=$(OUT)/contact-ladder-01-held-stick-catch \
		study-catch-servo=$(OUT)/contact-factorial-study-catch-servo \
		servo-arm=$(OUT)/contact-ladder-02-servo-arm \
		--factors "held-stick catch" "servo arm" --out $(OUT)/contact-factorial-catch-servo
	$(BIN)/playroom factorial kinematic=$(OUT)/comparison-diva:kinematic \
		held-stick-catch=$(OUT)/contact-ladder-01-held-stick-catch \
		study-catch-near=$(OUT)/contact-factorial-study-catch-near \
		held-catch-near=$(OUT)/contact-factorial-held-catch-near \
		--factors "held-stick catch" "catch distance 0.055 m" \
		--out $(OUT)/contact-factorial-catch-distance
	mkdir -p docs/data
	cp $(OUT)/contact-factorial-held-pose-pushing/factorial-trials.csv \
		docs/data/contact-factorial-held-pose-pushing-trials.csv
	cp $(OUT)/contact-factorial-catch-servo/factorial-trials.csv \
		docs/data/contact-factorial-catch-servo-trials.csv
	cp $(OUT)/contact-factorial-catch-distance/factorial-trials.csv \
		docs/data/contact-factorial-catch-distance-trials.csv

## ablations: each departure from the study switched back alone (against the replication's
## seeds 0-31), and each study setting switched into the project preset alone (against the
## project preset), 32 seeds x 80000 each, then both tables (`playroom ablations`), their
## per-trial data copied into docs/data/ (docs/replication.md quotes them)
ABLATIONS := $(basename $(notdir $(wildcard experiments/batches/ablations/*.json)))
FROM_STUDY := $(filter-out project%,$(ABLATIONS))
FROM_PROJECT := $(filter project-plus-%,$(ABLATIONS))
ablations: replicate
	for name in $(ABLATIONS); do \
		$(BIN)/playroom batch --config experiments/batches/ablations/$$name.json \
			--out $(OUT)/ablation-$$name || exit 1; \
	done
	$(BIN)/playroom ablations $(OUT)/replication $(addprefix $(OUT)/ablation-,$(FROM_STUDY)) \
		--out $(OUT)/ablations-from-study
	$(BIN)/playroom ablations $(OUT)/ablation-project $(addprefix $(OUT)/ablation-,$(FROM_PROJECT)) \
		--out $(OUT)/ablations-from-project
	mkdir -p docs/data
	cp $(OUT)/ablations-from-study/ablations-trials.csv docs/data/ablations-from-study-trials.csv
	cp $(OUT)/ablations-from-project/ablations-trials.csv \
		docs/data/ablations-from-project-trials.csv

# The suite runs in as many processes as the machine has cores (pytest-xdist), a test file
# to a process, so that each file's fixtures are made once.
PYTEST := $(BIN)/python -m pytest -q -n auto --dist loadfile

## test: lint, then the test suite (its current time: README.md; every timing: docs/speed.md)
test: lint
	$(PYTEST)

# Another x86-64 CPU class, emulated on this one (docs/cpu-classes.md): on a CPU with AVX-512,
# NumPy's AVX-512 kernels off, OpenBLAS's Haswell kernel and numba compiling for Haswell (an
# AVX2 machine); without it, the same one class older (an AVX machine). The settings come from
# experiments/bench/cpu_classes.py, which `playroom bench emulated` uses too.
OTHER_CPU = $(shell $(BIN)/python -m experiments.bench.cpu_classes)

# The `rl` extra (stable-baselines3, which brings torch) for the slow checks of sim/envs/ in a
# real reinforcement-learning library; `make test` never installs it.
RL_INSTALLED := $(VENV)/.installed-rl

# torch's CPU build, pinned in constraints.txt: PyPI's default build brings CUDA libraries
# (5.2 GB on a CPU-only machine); for a GPU, install the torch you need into .venv yourself.
TORCH_INDEX := https://download.pytorch.org/whl/cpu

# torch alone from there first, so that only its few lookups go to that index.
$(RL_INSTALLED): $(INSTALLED)
	$(BIN)/python -m pip install --quiet --constraint $(LOCK) --extra-index-url $(TORCH_INDEX) torch
	$(BIN)/python -m pip install --quiet --constraint $(LOCK) -e ".[rl]"
	touch $(RL_INSTALLED)

## install-rl: the `rl` extra (stable-baselines3, torch's CPU build, MoviePy) into .venv, at the
## versions of constraints.txt (its size and time: docs/rl-baseline.md)
install-rl: $(RL_INSTALLED)

## rl-baseline: Model Babbling against deep RL on the same test, given the same movements: the
## batch of experiments/batches/rl-baseline/comparison.json (both backends, 8 seeds x 20000
## iterations), then for each of its trials SAC + HER (stable-baselines3's defaults) given as
## many movements and tested the same way (`playroom rl-baseline --config`, on every core;
## docs/rl-baseline.md), then the page pairing the two by seed (`playroom rl-compare`);
## installs the `rl` extra; rerunning resumes
RL_BASELINE := experiments/batches/rl-baseline/comparison.json
rl-baseline: $(RL_INSTALLED)
	$(BIN)/playroom batch --config $(RL_BASELINE) --out $(OUT)/rl-baseline/model-babbling
	$(BIN)/playroom report $(OUT)/rl-baseline/model-babbling
	$(BIN)/playroom rl-baseline --config $(RL_BASELINE) --out $(OUT)/rl-baseline/sac-her
	$(BIN)/playroom rl-compare $(OUT)/rl-baseline/model-babbling $(OUT)/rl-baseline/sac-her \
		--out $(OUT)/rl-baseline/page

## rl-control: the RL baseline's positive control: SAC + HER (the RL Zoo's FetchReach settings)
## on the hand and stick goals with the arm, 3 seeds x 20000 movements, tested on 200 held-out
## goals every 2000 (`playroom rl-control`; about 10 minutes a run on 2 cores; runs done are
## skipped), then its table, record and figure copied into docs/ (docs/rl-baseline.md);
## installs the `rl` extra
RL_CONTROL := $(OUT)/rl-control
rl-control: $(RL_INSTALLED)
	$(BIN)/playroom rl-control --out $(RL_CONTROL)
	mkdir -p docs/data
	cp $(RL_CONTROL)/rl-control.csv $(RL_CONTROL)/rl-control.json docs/data/
	cp $(RL_CONTROL)/rl-control.png docs/rl-control.png

## rl-race: Model Babbling against SAC + HER (stable-baselines3's defaults, and the control's
## settings), one policy of the three toys, on the trials of experiments/batches/rl-baseline/
## comparison.json (both backends, 8 seeds x 20000 movements), all tested on the same 300
## held-out toy goals every 2000 (`playroom rl-race`, on every core; docs/rl-race.md: its
## cost), then Model Babbling's trials asked again by the toy's start and end
## (`playroom rl-race-lookup`), then the tables, record and figure copied into docs/; rerunning
## resumes
RL_RACE := $(OUT)/rl-race
rl-race: $(RL_INSTALLED)
	$(BIN)/playroom rl-race --out $(RL_RACE) --config $(RL_BASELINE)
	$(BIN)/playroom rl-race-lookup $(RL_RACE)
	mkdir -p docs/data
	cp $(RL_RACE)/rl-race-lookup.csv $(RL_RACE)/rl-race-lookup-summary.csv docs/data/
	cp $(RL_RACE)/rl-race.csv $(RL_RACE)/rl-race-claims.csv $(RL_RACE)/rl-race.json docs/data/
	cp $(RL_RACE)/rl-race.png docs/rl-race.png

## test-slow: the longer checks marked `slow` (with the `rl` extra installed: those checks fail
## rather than skip without it), then the whole suite with another CPU emulated
test-slow: $(RL_INSTALLED)
	PLAYROOM_RL_REQUIRED=1 $(PYTEST) -m slow
	env $(OTHER_CPU) $(PYTEST)

## lint: ruff's checks and format, mypy on the packages ([tool.mypy] in pyproject.toml;
## its cache in .mypy_cache makes a second run a few seconds), then the import contracts of
## the stages ([tool.importlinter])
lint: $(INSTALLED)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	$(BIN)/mypy
	$(BIN)/lint-imports

format: $(INSTALLED)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

## bench: speed figures, one `name: value unit` per line
bench: $(INSTALLED)
	$(BIN)/playroom bench

## voice-model: regenerate the vocal tract's articulators and fitted formant map (tens of minutes)
voice-model: $(INSTALLED)
	$(BIN)/python -m sim.vocal.vtl.fitting.fit_voice_model

clean:
	rm -rf $(VENV) .lock-venv .pytest_cache .ruff_cache .mypy_cache
